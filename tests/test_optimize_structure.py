"""The structure of ``walkerlab optimize`` (read from the source, never run): one driver
(:mod:`walkerlab.optimal.driver`) returning the one record type of an optimum
(:class:`~walkerlab.io.schemas.optimize.OptimizeData`), the stage completing its records
(:func:`walkerlab.io.schemas.optimize.optimize_record`), the transcription reached through
the walker's kind, and one step of straight legs collocated as a sequence of one phase by
the multi-phase transcription."""

from __future__ import annotations

import ast
from dataclasses import fields
from pathlib import Path

import numpy as np

from walkerlab.walker.plant import Plant

PKG = Path(__file__).resolve().parents[1] / "walkerlab"

#: what builds or writes optimize.h5's records (the stage's, never optimal/'s)
RECORDS = {"PhaseReplayData", "optimize_record", "phase_replay_records", "write"}


def _imported_names(path: Path) -> set:
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            names.update(a.name for a in node.names)
    return names


def test_optimal_builds_no_artifact_records_the_stage_does():
    """No module of ``walkerlab/optimal/`` imports what builds or writes ``optimize.h5``'s
    records; the stage does (``optimize_record``); one driver module, no ``drivers/``
    package."""
    mods = sorted((PKG / "optimal").rglob("*.py"))
    assert len(mods) > 10
    bad = {str(p.relative_to(PKG)): sorted(n & RECORDS) for p in mods
           if (n := _imported_names(p)) & RECORDS}
    assert not bad, bad
    assert "optimize_record" in (PKG / "stages" / "optimize.py").read_text()
    assert (PKG / "optimal" / "driver.py").is_file()
    assert not (PKG / "optimal" / "drivers").exists()
    assert not (PKG / "optimal" / "records.py").exists()


def test_one_record_type_per_optimum():
    """The driver returns ``OptimizeData`` itself (no record type of its own repeating
    its fields: no dataclass in the driver but its kinds' parts); the stage's
    ``optimize_record`` turns the replays into ``PhaseReplayData`` and sets the scene's
    energy unit, field for field otherwise."""
    from types import SimpleNamespace

    from walkerlab.io.schemas.optimize import OptimizeData, PhaseReplayData, optimize_record
    from walkerlab.optimal import driver

    tree = ast.parse((PKG / "optimal" / "driver.py").read_text())
    classes = {n.name for n in tree.body if isinstance(n, ast.ClassDef)}
    assert classes == {"Collocation"}, classes
    assert driver.optimize_scene.__annotations__["return"] in ("OptimizeData", OptimizeData)
    replay = SimpleNamespace(collocated_start_error=1e-5, start_shift=2e-5,
                             return_error=3e-12, step_period_s=0.7, torque_error=0.02,
                             multipliers=np.array([0.4 + 0j]), closed=True, x0=np.zeros(2))
    o = OptimizeData(np.zeros(3), {"a": np.zeros(3)}, np.zeros(3), 0.7, 0.5, 0.0, 1.0, 1e-9,
                     np.zeros(2, complex), True, "Solve_Succeeded", 5, 0.1, {"a": "rad"},
                     phase_replays={"feedback": replay})
    d = optimize_record(o, "kJ")
    assert isinstance(d, OptimizeData) and d.energy_unit == "kJ"
    assert isinstance(d.phase_replays["feedback"], PhaseReplayData)
    assert d.phase_replays["feedback"].return_error == 3e-12 and d.step_period_s == 0.7
    same = {f.name for f in fields(OptimizeData)} - {"energy_unit", "phase_replays"}
    assert all(getattr(d, k) is getattr(o, k) for k in same)


def _switch_reads(tree) -> list:
    """The lines of ``tree`` that read a switch of the walker's description choosing its
    kind (:func:`tests.test_layers._kind_switch_reads`; here ``knee.lock`` or any ``.lock``
    too) or ``getattr(..., "actuation")``."""
    from tests.test_layers import _kind_switch_reads

    out = _kind_switch_reads(tree)
    for n in ast.walk(tree):
        if isinstance(n, ast.Attribute) and n.attr == "lock" and n.lineno not in out:
            out.append(n.lineno)
        elif (isinstance(n, ast.Call) and getattr(n.func, "id", "") == "getattr"
              and len(n.args) > 1 and getattr(n.args[1], "value", None) == "actuation"):
            out.append(n.lineno)
    return out


def test_the_transcription_is_reached_through_the_walker_kind():
    """The driver gives its behaviour to the collocation part of every walker kind it takes
    (:attr:`walkerlab.walker.kinds.Kind.collocation`:
    every kind whose ``walk`` the capability table supports in ``optimize``); no module of
    ``walkerlab/optimal/`` reads a switch of the description to choose its code (nor
    ``getattr`` for the walker's actuation); the spoked wheel and the torso hinged on
    straight legs are refused from the capability table."""
    from walkerlab.optimal import driver  # noqa: F401  (gives the collocation parts theirs)
    from walkerlab.walker.kinds import KINDS

    taken = {k for k, kind in KINDS.items()
             if kind.collocation is not None and kind.collocation.provided}
    assert taken == {k for k, kind in KINDS.items() if kind.supports("walk", "optimize")}
    assert set(KINDS) - taken == {"rolling_polygon", "rolling_polygon_3d", "hinged_torso"}
    assert not KINDS["rolling_polygon"].supports("walk", "optimize")
    mods = sorted((PKG / "optimal").rglob("*.py")) + [PKG / "stages" / "optimize.py"]
    bad = {str(p.relative_to(PKG)): got for p in mods
           if (got := _switch_reads(ast.parse(p.read_text())))}
    assert not bad, bad
    probe = 'if st.foot == "flat" or s.free_knees: pass\na = getattr(w, "actuation", None)'
    assert sorted(_switch_reads(ast.parse(probe))) == [1, 1, 2]  # the reader sees them


def test_a_spoked_wheel_is_refused_from_the_table():
    """``walkerlab optimize`` on a rimless wheel: the capability table's one line, naming
    the walker, before any stage runs."""
    import pytest

    from walkerlab.config import load_scene
    from walkerlab.optimal.driver import check_scene, needs_gait
    from walkerlab.stages.common import with_defaults
    from walkerlab.walker.kinds import KindRefused

    scene = with_defaults(load_scene(PKG.parent / "configs" / "rimless_wheel.yaml"),
                          "optimize", "optimize")
    assert not needs_gait(scene, Plant.from_scene(scene))  # refused at once: no fixed point first
    with pytest.raises(KindRefused, match=r"^walker: a spoked wheel is one rigid body"):
        check_scene(scene, Plant.from_scene(scene).data)


def _calls(path: Path, name: str) -> set:
    tree = ast.parse(path.read_text())
    body = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == name)
    return {c.func.id for c in ast.walk(body) if isinstance(c, ast.Call)
            and isinstance(c.func, ast.Name)}


def test_one_step_is_a_sequence_of_one_phase():
    """The one-step transcription has no defects, objective or constraints of its own: its
    ``collocate_step`` is the multi-phase transcription's, over the step as one phase; a
    five-link biped's step is one phase of it too, with its four joint torques."""
    step = (PKG / "optimal" / "transcription" / "step.py").read_text()
    tree = ast.parse(step)
    defs = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    assert not defs & {"collocate_step", "_transcribe", "_path_constraints", "_terms"}
    tx = PKG / "optimal" / "transcription"
    assert {"collocate_phases", "step_phase"} <= _calls(tx / "mode_sequence.py",
                                                        "collocate_step")
    assert {"collocate_phases", "step_sequence"} <= _calls(tx / "free_joints.py",
                                                           "collocate_five_link")
    assert "ca.Opti()" not in (tx / "free_joints.py").read_text()
