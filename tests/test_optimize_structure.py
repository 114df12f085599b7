"""The structure of ``walkerlab optimize`` (read from the source, never run): one driver
(:mod:`walkerlab.optimal.driver`) whose optimum is numbers (:class:`~walkerlab.optimal.
driver.Optimum`), the stage building ``optimize.h5``'s records from it
(:func:`walkerlab.io.schemas.optimize.optimize_record`), and one step of straight legs
collocated as a sequence of one phase by the multi-phase transcription."""

from __future__ import annotations

import ast
from dataclasses import fields
from pathlib import Path

import numpy as np

PKG = Path(__file__).resolve().parents[1] / "walkerlab"

#: the names of optimize.h5's records
RECORDS = {"OptimizeData", "PhaseReplayData", "optimize_record", "phase_replay_records"}


def _imported_names(path: Path) -> set:
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            names.update(a.name for a in node.names)
    return names


def test_optimal_builds_no_artifact_records_the_stage_does():
    """No module of ``walkerlab/optimal/`` imports a record of ``optimize.h5``; the stage
    builds them (``optimize_record``); one driver module, no ``drivers/`` package."""
    mods = sorted((PKG / "optimal").rglob("*.py"))
    assert len(mods) > 10
    bad = {str(p.relative_to(PKG)): sorted(n & RECORDS) for p in mods
           if (n := _imported_names(p)) & RECORDS}
    assert not bad, bad
    assert "optimize_record" in (PKG / "stages" / "optimize.py").read_text()
    assert (PKG / "optimal" / "driver.py").is_file()
    assert not (PKG / "optimal" / "drivers").exists()
    assert not (PKG / "optimal" / "records.py").exists()


def test_an_optimum_becomes_the_artifacts_record_field_for_field():
    """Every field of ``OptimizeData`` but the energy's unit (the scene's, given by the
    stage) is a field of the driver's ``Optimum``; the phase replays become
    ``PhaseReplayData``."""
    from types import SimpleNamespace

    from walkerlab.io.schemas.optimize import OptimizeData, PhaseReplayData, optimize_record
    from walkerlab.optimal.driver import Optimum

    want = {f.name for f in fields(OptimizeData)} - {"energy_unit"}
    assert want <= {f.name for f in fields(Optimum)}
    replay = SimpleNamespace(collocated_start_error=1e-5, start_shift=2e-5,
                             return_error=3e-12, step_period_s=0.7, torque_error=0.02,
                             multipliers=np.array([0.4 + 0j]), closed=True, x0=np.zeros(2))
    o = Optimum(np.zeros(3), {"a": np.zeros(3)}, np.zeros(3), 0.7, 0.5, 0.0, 1.0, 1e-9,
                np.zeros(2, complex), True, "Solve_Succeeded", 5, 0.1, {"a": "rad"},
                phase_replays={"feedback": replay})
    d = optimize_record(o, "kJ")
    assert isinstance(d, OptimizeData) and d.energy_unit == "kJ"
    assert isinstance(d.phase_replays["feedback"], PhaseReplayData)
    assert d.phase_replays["feedback"].return_error == 3e-12 and d.step_period_s == 0.7


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
