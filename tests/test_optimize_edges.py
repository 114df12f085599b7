"""``walkerlab optimize`` at its edges (issue 51, items 4, 7 and 15): a five-link biped
without a target is refused at once, a failure keeps its origin for the debug trace, the
contact replay's solver failure is the replay's outcome (not the optimisation's end), a
level-ground optimum starts from its targets when the walker has no gait, and a result
that is not a gait is not replayed on the contact model (``--require-gait``)."""

from __future__ import annotations

import traceback
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.walker.plant import Plant

pytest.importorskip("casadi")
CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def test_a_five_link_biped_without_a_target_is_refused_at_once(tmp_path):
    """configs/rabbit.yaml has no ``optimize`` section: before, the default section (no
    target) ran ~50 s into a 1 mm shuffle and then stopped on scipy's root finder ("f(a)
    and f(b) must have different signs") in the contact replay; now one line at once, naming
    the targets to give, and nothing written.  The StageError is chained to its origin (the
    debug trace shows where it came from)."""
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.stages import optimize as stage
    from walkerlab.stages.common import StageError

    r = CliRunner().invoke(app, ["optimize", str(CONFIGS / "rabbit.yaml"), "--runs-dir",
                                 str(tmp_path)])
    assert r.exit_code == 1 and r.output.count("error:") == 1, r.output
    assert "has no 'optimize' section" in r.output
    assert "optimize.target_step_length_m" in r.output and "more characters" not in r.output
    assert not list(tmp_path.rglob("optimize.h5"))
    scene = load_scene(CONFIGS / "rabbit.yaml")
    d = scene.model_dump(mode="json", exclude_none=True)
    d["optimize"] = {"intervals": 20}  # a section without a target: refused alike
    with pytest.raises(StageError, match="optimize: a five-link biped's optimal step "
                       "needs a target") as exc:
        stage.run(type(scene).model_validate(d), tmp_path)
    origin = "".join(traceback.format_tb(exc.value.__cause__.__traceback__))
    assert "optimal/driver.py" in origin


def test_a_contact_replay_whose_solver_fails_is_an_outcome(monkeypatch):
    """The contact replay is a report on the optimum: its solver's failure (scipy's event
    location raising "f(a) and f(b) must have different signs", as RABBIT's feed-forward + PD
    law did on the contact model without a target) becomes its outcome, one line saying
    what failed and what to try, and the optimisation stands."""
    from walkerlab.analysis.contact import sim
    from walkerlab.config import SolverSettings
    from walkerlab.optimal.replay import contact as contact_replay

    def fail(*a, **k):
        raise ValueError("f(a) and f(b) must have different signs")

    monkeypatch.setattr(sim, "simulate_from", fail)
    solver = SolverSettings.for_contact(method="LSODA", rtol=1e-8, atol=1e-10)
    period, outcome = contact_replay._run(None, np.zeros(4), 0.7, 1, solver)
    assert np.isnan(period)
    assert outcome.startswith("not replayed: the contact model's solver (LSODA, rtol 1e-08)")
    assert "f(a) and f(b) must have different signs" in outcome and "contact_solver" in outcome
    assert "\n" not in outcome


def test_the_contact_replay_runs_the_scenes_contact_solver_it_advises_changing(monkeypatch):
    """Issue 56 item 16: the contact replay of a straight-legged optimum ran LSODA at rtol
    1e-6 whatever the scene's contact_solver, yet its failure advised changing
    contact_solver.  It now runs the scene's; a stride's replay, whose solver stays fixed
    (the shipped asymmetric_optimal's replay unchanged), says so instead."""
    from types import SimpleNamespace

    from walkerlab.analysis.contact import sim
    from walkerlab.optimal.replay import contact as contact_replay
    from walkerlab.optimal.transcription import step

    used = []

    def fail(*a, **k):
        used.append(k.get("solver"))
        raise ValueError("f(a) and f(b) must have different signs")

    monkeypatch.setattr(sim, "simulate_from", fail)
    monkeypatch.setattr(step, "torque_of_time", lambda res: (lambda t: 0.0))
    d = load_scene(CONFIGS / "compass_optimal.yaml").model_dump(mode="json", exclude_none=True)
    d["contact_solver"] = {"method": "Radau", "rtol": 1e-7, "atol": 1e-9}
    scene = type(load_scene(CONFIGS / "compass_optimal.yaml")).model_validate(d)
    res = SimpleNamespace(push_off_n_s=0.0, x=np.zeros((1, 4)), step_period_s=0.7)
    period, outcome = contact_replay.contact_replay(scene, res, plant=Plant.from_scene(scene))
    assert np.isnan(period) and used[-1].method == "Radau" and used[-1].rtol == 1e-7
    assert "solver (Radau, rtol 1e-07) failed" in outcome
    assert outcome.endswith("set another contact_solver (method, rtol) in the scene: the "
                            "replay runs it")
    fixed = contact_replay.replay_failure(ValueError("x"), used[-1], fixed=True)
    assert "this replay's solver is fixed (the scene's contact_solver is not used here)" in \
        fixed and "set another contact_solver" not in fixed


def _interrupted_in_a_ctypes_callback(signum):
    """What a Ctrl-C (or SIGTERM) during a cold contact replay does: numba compiles the
    contact model through llvmlite, whose object cache calls back into Python through
    ctypes; the signal's handler runs there and its ``KeyboardInterrupt`` is printed and
    dropped by ctypes ("Exception ignored on calling ctypes callback function").  Here the
    process's own handler is called inside a ctypes callback (deterministic: no real
    signal, whose handler runs at the interpreter's next check), then the run fails as the
    compile's aftermath did (scipy's event location, which the replay reports as its
    solver's failure)."""
    import ctypes
    import signal

    from walkerlab.cli.process import _interrupt

    def body():
        signal.getsignal(signum)(signum, None)

    handler = signal.getsignal(signum)
    assert handler is _interrupt, f"the command's handler is not installed: {handler!r}"
    ctypes.CFUNCTYPE(None)(body)()  # the exception cannot cross the C frame: dropped
    raise ValueError("f(a) and f(b) must have different signs")


@pytest.mark.parametrize("signum", ["SIGINT", "SIGTERM"])
def test_an_interrupt_swallowed_in_the_contact_replay_exits_130_and_writes_nothing(
        tmp_path, monkeypatch, signum, default_signals):
    """Before, an interrupt swallowed by a ctypes callback in a cold ``optimize``'s
    contact replay went unnoticed: exit 0 and an ``optimize.h5`` with a NaN contact replay
    blaming the solver, which the rerun reused.  Now the command's signal handler records
    the interrupt, the command ends ``interrupted`` with code 130, no traceback, and no
    ``optimize.h5`` is written (nothing for a rerun to reuse).

    The signals start at Python's defaults (``default_signals``): a suite started in the
    background inherits SIGINT ignored, which the command rightly keeps ignored, and this
    test then called ``SIG_IGN`` as the handler (exit 0 and an unraisable ``TypeError``
    at teardown, whatever the user cache held)."""
    import signal

    from typer.testing import CliRunner

    from walkerlab.analysis.contact import sim
    from walkerlab.cli import app

    monkeypatch.setattr(sim, "simulate_from",
                        lambda *a, **k: _interrupted_in_a_ctypes_callback(
                            getattr(signal, signum)))
    r = CliRunner().invoke(app, ["optimize", str(CONFIGS / "compass_optimal.yaml"),
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 130, r.output
    assert r.output.strip().splitlines()[-1] == "interrupted", r.output
    assert "Traceback" not in r.output and "error:" not in r.output
    assert not list(tmp_path.rglob("optimize.h5"))
    assert not list(tmp_path.rglob(".optimize*"))  # no temporary file or lock left
    from walkerlab.safefs import interrupted

    assert not interrupted()  # reported, then forgotten: the next command starts clean
    # outside a command (a Python session that ran one) an interrupt is the plain
    # KeyboardInterrupt and nothing is recorded to stop a later write
    handler = signal.getsignal(getattr(signal, signum))
    if callable(handler):
        with pytest.raises(KeyboardInterrupt):
            handler(getattr(signal, signum), None)
    assert not interrupted()


def test_an_inherited_ignored_sigint_stays_ignored_by_the_command():
    """A command started in the background (SIGINT ignored, as a non-interactive shell's
    ``&`` leaves it to its children) keeps SIGINT ignored and still handles SIGTERM."""
    import signal

    from walkerlab.cli.process import _interrupt, terminate_as_interrupt

    old = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        terminate_as_interrupt()
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        assert signal.getsignal(signal.SIGTERM) is _interrupt
    finally:
        for s, h in old.items():
            signal.signal(s, h)


def test_under_the_default_signals_fixture_the_command_handles_both(default_signals):
    import signal

    from walkerlab.cli.process import _interrupt, terminate_as_interrupt

    terminate_as_interrupt()
    assert signal.getsignal(signal.SIGINT) is _interrupt
    assert signal.getsignal(signal.SIGTERM) is _interrupt


@pytest.mark.slow  # a pytest of its own in a child process
def test_the_interrupt_test_passes_in_a_suite_that_inherited_sigint_ignored(tmp_path):
    """The quick suite started in the background (``pytest ... &`` from a script: SIGINT
    ignored in pytest and its xdist workers) failed the SIGINT case of the interrupt test
    (exit 0 instead of 130, and a teardown error: ctypes dropped a ``TypeError`` from
    calling ``SIG_IGN``).  It passes there now."""
    import os
    import subprocess
    import sys

    code = ("import signal, sys, pytest\n"
            "signal.signal(signal.SIGINT, signal.SIG_IGN)\n"
            "sys.exit(pytest.main(['-q', '-n', '0', '-p', 'no:cacheprovider', "
            "'-m', 'slow or not slow', "  # the test may be slow by its cost (slow_by_cost.txt)
            f"'{Path(__file__).resolve()}', '-k', "
            "'interrupt_swallowed_in_the_contact_replay and SIGINT']))")
    r = subprocess.run([sys.executable, "-c", code], cwd=Path(__file__).resolve().parents[1],
                       env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])},
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-3000:]
    assert "1 passed" in r.stdout and "error" not in r.stdout.splitlines()[-1]


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_an_infeasible_target_is_not_replayed_on_contact_and_require_gait_fails(tmp_path):
    """compass_optimal at 0.6 m/s with |u| <= 0.5 N m: IPOPT reports the problem infeasible
    and the rigid replay returns 0.03 away - NOT a gait.  Before, the command exited 0 and
    replayed the contact model on it anyway; now the contact replay is skipped ("not a
    gait"), ``--require-gait`` exits 1 with one line (as ``fixedpoint --require-stable``,
    optimize.h5 stays, and a reused one is judged alike)."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.io.schemas.optimize import load

    d = yaml.safe_load((CONFIGS / "compass_optimal.yaml").read_text())
    d["optimize"].update(target_speed_m_per_s=0.6, max_torque_n_m=0.5)
    scene = tmp_path / "tight.yaml"
    scene.write_text(yaml.safe_dump(d))
    args = ["optimize", str(scene), "--runs-dir", str(tmp_path / "runs")]
    r = CliRunner().invoke(app, [*args, "--require-gait"])
    assert r.exit_code == 1 and r.output.count("error:") == 1, r.output
    assert "error: --require-gait: the optimum is NOT a gait: IPOPT did not converge" \
        in r.output
    out = load(tmp_path / "runs" / "tight" / "optimize.h5")
    assert not out.gait and np.isfinite(out.replay_error)  # the old code replayed it
    assert np.isnan(out.contact_step_period_s)
    assert out.contact_outcome.startswith("not replayed: not a gait (IPOPT: ")
    r = CliRunner().invoke(app, [*args, "--require-gait"])  # reused: read back
    assert r.exit_code == 1 and "reused" in r.output and "--require-gait" in r.output


def _level_compass(**optimize):
    """compass_optimal.yaml on level ground (a passive walker there has no gait)."""
    scene = load_scene(CONFIGS / "compass_optimal.yaml")
    d = scene.model_dump(mode="json", exclude_none=True)
    d["slope"] = {"angle_rad": 0.0}
    d["optimize"] = {**d["optimize"], **optimize}
    return type(scene).model_validate(d)


def test_a_level_ground_optimal_gait_starts_from_its_targets():
    """The Srinivasan-Ruina / OptimTraj task: the compass walker on level ground, push-off
    free, 0.6 m/s with 0.5 m steps.  It has no gait of its own (before: "no period-1 gait
    found; a passive walker needs a downhill slope"), so no fixedpoint runs and the start
    is built from the targets; IPOPT converges (8 iterations seen) to a gait whose rigid
    replay returns to its start within the scene's 1e-6 (4.5e-8 seen), at the targets
    (equality constraints: 1e-9), powered by a push-off > 0 (5.27 N s seen; Kuo's
    ``M v tan(alpha)`` for this step is 3.1 N s, the hip torque doing the rest)."""
    from walkerlab.models.registry import build_walker
    from walkerlab.optimal.driver import collocation_spec
    from walkerlab.optimal.guess import starting_step
    from walkerlab.optimal.transcription.mode_sequence import collocate_step
    from walkerlab.optimal.transcription.step import replay
    from walkerlab.optimal.transcription.step_cache import cached_step_functions
    from walkerlab.stages import pipeline
    from walkerlab.walker.description import walker_data

    scene = _level_compass(push_off="free", target_speed_m_per_s=0.6,
                           target_step_length_m=0.5)
    assert pipeline.order("optimize", scene) == ["optimize"]  # no gait to find first
    walker = build_walker(Plant.from_scene(scene))
    t, x, u, p = starting_step(scene, walker, None, None)
    assert u is None and p > 0 and t[-1] == pytest.approx(0.5 / 0.6, rel=1e-12)
    data = walker_data(scene.walker, 0.0)
    from dataclasses import replace

    spec = replace(collocation_spec(scene), push_off_n_s=p)
    res = collocate_step(data, None, spec, t, x, None, cached_step_functions(data))
    assert res.status == "Solve_Succeeded"
    err, _ = replay(data, res)
    assert err <= scene.optimize.replay_tolerance
    assert res.step_length_m == pytest.approx(0.5, abs=1e-9)
    assert res.step_length_m / res.step_period_s == pytest.approx(0.6, abs=1e-9)
    assert res.push_off_n_s > 1.0


def test_a_level_ground_walker_without_targets_is_refused_at_once(tmp_path):
    """No gait and no target to build a start from: one line naming the targets, before
    anything runs (no fixedpoint.h5, no optimize.h5)."""
    from walkerlab.stages import optimize as stage
    from walkerlab.stages.common import StageError

    with pytest.raises(StageError, match="optimize: the walker has no gait of its own .*"
                       "optimize.target_speed_m_per_s"):
        stage.run(_level_compass(push_off="free"), tmp_path)
    with pytest.raises(StageError, match="needs two of target_step_length_m"):
        stage.run(_level_compass(push_off="free", target_step_length_m=0.5), tmp_path)
    assert not list(tmp_path.rglob("*.h5"))


@pytest.mark.slow
def test_the_level_ground_optimum_from_the_command(tmp_path):
    """``walkerlab optimize`` of the level-ground compass with a free push-off: exit 0, a
    gait, no fixedpoint.h5 (the start came from the targets); its rigid replay periodic."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.io.schemas.optimize import load

    d = yaml.safe_load((CONFIGS / "compass_optimal.yaml").read_text())
    d["slope"] = {"angle_rad": 0.0}
    d["optimize"].update(push_off="free", target_speed_m_per_s=0.6, target_step_length_m=0.5)
    scene = tmp_path / "level.yaml"
    scene.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["optimize", str(scene), "--require-gait", "--runs-dir",
                                 str(tmp_path / "runs")])
    assert r.exit_code == 0 and "a gait (the replay closes)" in r.output, r.output
    assert not (tmp_path / "runs" / "level" / "fixedpoint.h5").exists()
    out = load(tmp_path / "runs" / "level" / "optimize.h5")
    assert out.gait and out.replay_error <= 1e-6 and out.push_off_n_s > 1.0
    assert out.step_length_m == pytest.approx(0.5, abs=1e-9)


def _scene_file(tmp_path, base: str, name: str, **optimize) -> Path:
    """``configs/<base>.yaml`` with ``optimize`` fields added, written as ``<name>.yaml``."""
    import yaml

    d = yaml.safe_load((CONFIGS / f"{base}.yaml").read_text())
    d.setdefault("optimize", {}).update(optimize)
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(d))
    return path


def test_a_positive_clearance_on_straight_legs_is_refused_before_any_stage_runs(tmp_path):
    """Straight legs' swing foot is level with the stance foot when the legs cross
    (clearance l (cos theta - cos phi) = 0 at phi = theta), so ``min_clearance_m > 0``
    cannot hold at every point: before, IPOPT "converged" on the mesh (the crossing fell
    between two points) to a 3.7 s step with 48 N m of hip torque that does not replay
    (return error inf); now one line naming the field and the reason, before fixedpoint
    runs, nothing written."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    scene = _scene_file(tmp_path, "compass_optimal", "clear", min_clearance_m=0.01)
    r = CliRunner().invoke(app, ["optimize", str(scene), "--runs-dir", str(tmp_path / "r")])
    assert r.exit_code == 1 and r.output.count("error:") == 1, r.output
    assert "error: optimize.min_clearance_m: straight legs" in r.output
    assert "when the legs cross" in r.output and "Traceback" not in r.output
    assert not list((tmp_path / "r").rglob("*.h5"))  # refused before fixedpoint ran


def test_a_kneed_walker_on_arc_feet_is_refused_before_any_stage_runs(tmp_path):
    """The phased step (knees) pins its stance foot: arc feet, which roll, are refused in
    one line naming the field before the gait search runs (it used to end in the search's
    "no gait" after fixedpoint)."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app

    d = yaml.safe_load((CONFIGS / "kneed_optimal.yaml").read_text())
    d["walker"]["leg"]["foot"] = {"kind": "arc", "radius_m": 0.2}
    d["walker"]["actuation"] = {"push_off": {"impulse_n_s": 0.05}}
    scene = tmp_path / "kneed_arc.yaml"
    scene.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["optimize", str(scene), "--runs-dir", str(tmp_path / "r")])
    assert r.exit_code == 1 and r.output.count("error:") == 1, r.output
    assert "walker.leg.foot.kind: arc feet on a walker with knees" in r.output
    assert "Traceback" not in r.output
    assert not list((tmp_path / "r").rglob("*.h5"))  # refused before fixedpoint ran


def test_every_phased_walker_takes_a_push_off_and_a_five_link_biped_is_refused_in_one_line():
    """Before, a kneed or flat-footed walker's push-off was refused (the phased
    transcription had none); now every heel strike of the phased transcription takes one
    (tests/test_optimize_phases.py, tests/test_optimize_3d.py); the five-link collocation
    has none: one line naming the field."""
    from walkerlab.walker.kinds import KINDS, KindRefused

    for kind in ("locking_knees", "locking_knees_3d", "flat_feet"):
        assert KINDS[kind].supports("push_off", "optimize"), kind
    with pytest.raises(KindRefused) as err:
        KINDS["free_joints"].require("push_off", "optimize", "optimize.push_off")
    assert str(err.value).startswith("optimize.push_off: ") and "\n" not in str(err.value)


def test_an_infeasible_optimum_names_the_constraint_that_cannot_hold(tmp_path):
    """A step length of 0.8 m with the hip angle within +-0.3 rad cannot be: a straight
    leg's step is 2 l sin(|hip| / 2) <= 0.299 m.  Before, IPOPT's "Infeasible_Problem_
    Detected" was all that was said; now the constraint groups with the largest violation
    at its last iterate are named (the target step length first: 0.8 - 0.299 = 0.5 m),
    in the output and in optimize.h5."""
    from typer.testing import CliRunner

    from walkerlab.cli import app
    from walkerlab.io.schemas.optimize import load

    scene = _scene_file(tmp_path, "compass_optimal", "far", intervals=10,
                        target_step_length_m=0.8, hip_angle_range_rad=[-0.3, 0.3])
    r = CliRunner().invoke(app, ["optimize", str(scene), "--runs-dir", str(tmp_path)])
    assert r.exit_code == 0, r.output
    d = load(tmp_path / "far" / "optimize.h5")
    assert d.status != "Solve_Succeeded" and not d.gait
    assert d.violations.startswith("the target step length "), d.violations
    # the bound's gap, 0.8 - 2 sin(0.15) = 0.501 m, to IPOPT's tolerance at its last
    # iterate (it stops at the hip bound; 0.01 m covers where it stops on the mesh)
    assert float(d.violations.split(",")[0].split()[-1]) == pytest.approx(0.501, abs=0.01)
    assert f"largest constraint violations: {d.violations}" in r.output
