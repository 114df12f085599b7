"""Studies under faults and wrong or missing results (issue 36, round four).

Each test names its item (``i1`` ... ``i12``) and fails on the code before the fix
(commit 4cd702b).  Processes are checked by behaviour only (exit code, lines on stderr,
files left), never by timings.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from walkerlab.cli import app
from walkerlab.config import scene_from_dict

ROOT = Path(__file__).resolve().parents[1]
PAPER = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
IDEAL = {k: v for k, v in PAPER.items() if k in ("walker", "slope", "solver", "fixedpoint",
                                                  "simulate")}
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def _cli(*args, env=None):
    r = CliRunner().invoke(app, [str(a) for a in args], env=env)
    return r.exit_code, r.stderr.strip(), r.stdout


def _scene(tmp_path: Path, name: str = "paper", **sections) -> Path:
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump({**IDEAL, **sections}))
    return path


# ------------------------------------------------------------------ 1: full disk
STUDIES = {
    "mfpt": (["mfpt", "--method", "montecarlo"],
             {"mfpt": {"sigma_rad": [0.008], "walks": 12, "max_steps": 8}}),
    "sweep": (["sweep", "--param", "slope.angle_rad=0.012:0.02:0.001"], {}),
    "basin": (["basin", "--grid", "8x8"], {"basin": {"max_steps": 5}}),
}


@pytest.mark.slow
@pytest.mark.parametrize("study", sorted(STUDIES))
def test_full_disk_while_a_study_writes_its_partial_file_is_one_line(tmp_path, study):
    args, sections = STUDIES[study]
    scene = _scene(tmp_path, **sections)
    runs = tmp_path / "runs"
    code, err, _ = _cli("fixedpoint", scene, "--runs-dir", runs)
    assert code == 0, err
    limit = 4096  # an HDF5 file of a few pieces is larger: the partial file's writes fail
    script = f"""
        import resource, sys
        resource.setrlimit(resource.RLIMIT_FSIZE, ({limit}, {limit}))
        from walkerlab.cli import app
        sys.argv = ["walkerlab", *{args!r}, {str(scene)!r}, "--workers", "1",
                    "--runs-dir", {str(runs)!r}]
        app()
        """
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], cwd=tmp_path,
                       env=ENV, capture_output=True, text=True, timeout=300)
    err = r.stderr.strip().splitlines()
    assert r.returncode == 1 and len(err) == 1 and err[0].startswith("error: disk full"), \
        (r.returncode, err[:5])
    left = [p for p in runs.rglob("*") if p.is_file() and p.name != ".scene"
            and p.name != "fixedpoint.h5"]
    assert not [p for p in left if p.name.endswith(".tmp")]
    for p in left:  # what is left is a whole file (the work saved before the disk filled)
        assert p.name.endswith(".partial"), p
        with h5py.File(p, "r") as f:
            assert "input_hash" in f.attrs


# ------------------------------------------------------------------ 2, 3: mfpt's partial file
@pytest.fixture
def chunked_walks(monkeypatch):
    """Walks in chunks of 3; ``calls["lose_after"]`` chunks, then the Dask cluster is lost
    (as :class:`walkerlab.execution.dask.DaskExecutor` reports it)."""
    from walkerlab.execution.dask import DaskLost
    from walkerlab.studies import mfpt as work

    monkeypatch.setattr(work, "WALKS_PER_TASK", 3)
    calls = {"walks": 0, "lose_after": None}
    walks = work.run_walks

    def counted(task):
        if calls["lose_after"] is not None and calls["walks"] >= calls["lose_after"]:
            raise DaskLost("Dask scheduler tcp://x:1 has had no worker for 60 s (2 task(s) "
                           "waiting); the work finished so far is kept: start workers and "
                           "{rerun}")
        calls["walks"] += 1
        return walks(task)

    monkeypatch.setattr(work, "run_walks", counted)
    return calls


def _mc(scene, x, part, key="key"):
    from walkerlab.config import MfptSettings
    from walkerlab.studies import mfpt as work

    st = MfptSettings(sigma_rad=[0.008], method="montecarlo", walks=12, max_steps=10)
    return work.resumable_mfpt_study(scene, x, st, part, key, workers=1)


def test_lost_dask_worker_keeps_finished_mfpt_chunks_and_advises_a_rerun(
        tmp_path, paper_scene, paper_fixed_point, chunked_walks):
    from walkerlab.execution.dask import DaskLost

    part = tmp_path / "mfpt.h5.partial"
    chunked_walks["lose_after"] = 2
    with pytest.raises(DaskLost) as info:  # before: MfptStudyError, the partial file removed
        _mc(paper_scene, paper_fixed_point.x, part)
    msg = str(info.value)
    assert "no worker for 60 s" in msg and "--resume" not in msg  # mfpt has no --resume
    assert "rerun the same command" in msg
    assert part.is_file()
    chunked_walks.update(walks=0, lose_after=None)
    _mc(paper_scene, paper_fixed_point.x, part)
    assert chunked_walks["walks"] == 2  # 4 chunks of 3 walks; the 2 finished ones kept


def _damage_a_group(part: Path, which: int) -> None:
    """Overwrite the signature of the ``which``-th HDF5 symbol-table node (a group's list
    of links): opening the group fails ("bad symbol table node signature")."""
    data = bytearray(part.read_bytes())
    at = [i for i in range(len(data) - 3) if data[i:i + 4] == b"SNOD"][which]
    data[at:at + 4] = b"XXXX"
    part.write_bytes(bytes(data))


@pytest.mark.parametrize("which", [0, -1])  # the sigma group (every chunk), one chunk's group
def test_damaged_mfpt_partial_pieces_are_dropped_and_computed_again(
        tmp_path, paper_scene, paper_fixed_point, chunked_walks, which):
    part = tmp_path / "mfpt.h5.partial"
    ref = _mc(paper_scene, paper_fixed_point.x, part)[0]
    assert chunked_walks["walks"] == 4 and part.is_file()  # the stage removes it, not the study
    _damage_a_group(part, which)
    chunked_walks["walks"] = 0
    # before: "Unable to synchronously check link existence" on every rerun
    data, p = _mc(paper_scene, paper_fixed_point.x, part)
    assert p.dropped >= 1 and 1 <= chunked_walks["walks"] <= 4
    assert np.array_equal(data["mfpt_steps_montecarlo"], ref["mfpt_steps_montecarlo"])


# ------------------------------------------------------------------ 5: a link, before computing
@pytest.mark.parametrize("stage", ["continuation", "robustness"])
def test_link_in_place_of_an_artifact_is_refused_before_computing(tmp_path, monkeypatch,
                                                                     stage):
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.freshness import write_if_stale
    from walkerlab.io.runpaths import RunPathError

    sc = scene_from_dict({**IDEAL, "name": "paper"})
    runs = tmp_path / "runs"
    elsewhere = tmp_path / "elsewhere.h5"  # a valid artifact of another run
    write_artifact(elsewhere, stage, sc, "other inputs", lambda f: None, 0.0)
    link = runs / "paper" / f"{stage}.h5"
    link.parent.mkdir(parents=True)
    link.symlink_to(elsewhere)
    computed, told = [], []

    def compute():
        computed.append(1)
        return (lambda f: None), {}

    with pytest.raises(RunPathError, match="symbolic link"):
        write_if_stale(stage, sc, runs, ("walker",), (), compute, tell=told.append)
    assert not computed and not told  # before: "recomputing ... changed" and the computation


# ------------------------------------------------------------------ 7: flat-foot edges
FLAT = yaml.safe_load((ROOT / "configs" / "flat_feet.yaml").read_text())


@pytest.mark.parametrize("field, value", [("heel_m", 0), ("toe_m", 1e-9)])
def test_flat_foot_without_a_heel_or_toe_is_one_line_naming_the_field(tmp_path, field,
                                                                         value):
    data = yaml.safe_load(yaml.safe_dump(FLAT))
    data["walker"]["leg"]["foot"][field] = value
    scene = tmp_path / "flat.yaml"
    scene.write_text(yaml.safe_dump(data))
    # before: internal error (ZeroDivisionError) / (OverflowError, after 103 s)
    code, err, _ = _cli("fixedpoint", scene, "--runs-dir", tmp_path / "runs")
    lines = err.splitlines()
    assert code == 1 and len(lines) == 1, lines
    assert f"foot.{field}" in lines[0] and "internal error" not in lines[0], lines


# ------------------------------------------------------------------ 8: a bounded gait search
@pytest.mark.parametrize("search", ["find_fixed_point", "find_gaits"])
def test_gait_search_gives_up_when_its_budget_is_spent_and_says_why(
        paper_walker, monkeypatch, search):
    """A spring and damper at their caps (1e6) make one step map take ~40 s, and the search
    went on for 12+ maps (459 s, silent) before "no gait found".  Here every step is made
    0.25 s slower and the budget is 0.6 s: the search stops after a few maps (MINPACK alone
    needs ~20), says why, and a slow map is said in one notice."""
    import time as _time

    from walkerlab import progress
    from walkerlab.analysis.gait import poincare
    from walkerlab.analysis.gait import search as gait_search
    from walkerlab.integrate.solver import Solver
    from walkerlab.published import paper

    monkeypatch.setattr(poincare, "ROOT_BUDGET_S", 0.6, raising=False)
    monkeypatch.setattr(poincare, "SLOW_MAP_S", 0.2, raising=False)
    steps, notes = [], []
    real = poincare.integrate_step

    def slow_step(*a, **k):
        steps.append(1)
        t = _time.thread_time()  # the budget counts this thread's CPU time, so burn it
        while _time.thread_time() - t < 0.25:
            pass
        return real(*a, **k)

    monkeypatch.setattr(poincare, "integrate_step", slow_step)
    monkeypatch.setattr(progress, "note", notes.append)
    solver, guess = Solver("DOP853", 1e-12, 1e-12), np.array(paper.EQ11_STATE)
    with pytest.raises(poincare.FixedPointNotFound, match="gave up after [1-4] step map"):
        if search == "find_fixed_point":
            poincare.find_fixed_point(paper_walker, guess, solver)
        else:
            gait_search.find_gaits(paper_walker, solver, guess)
    assert 1 <= len(steps) <= 4, len(steps)
    assert len(notes) == 1 and "step map took" in notes[0], notes


# ------------------------------------------------------------------ 9: an unconverged mesh
def _mfpt_data(converged: float):
    from walkerlab.io.schemas.mfpt import VARIABLES, MfptData

    vals = {k: np.array([np.nan]) for k in VARIABLES}
    vals.update(mfpt_steps_montecarlo=np.array([6.0]), mfpt_steps_mesh=np.array([5.606]),
                mesh_cells=np.array([80.0]), mesh_change=np.array([0.106]),
                mesh_converged=np.array([converged]))
    return MfptData(np.array([0.008]), vals, "both", ["a", "b", "c", "d"], [])


def test_mesh_mfpt_that_did_not_converge_is_said_on_the_cli_and_in_the_report(
        tmp_path, monkeypatch):
    from walkerlab.report.robustness_section import mfpt_section
    from walkerlab.stages import common, pipeline
    from walkerlab.studies.mfpt import mfpt_summary

    data = _mfpt_data(0.0)
    summary = mfpt_summary(data)
    out = common.StageOutcome("mfpt", tmp_path / "mfpt.h5", False, 1.0, summary)
    monkeypatch.setattr(pipeline, "run", lambda *a, **k: out)
    code, err, stdout = _cli("mfpt", _scene(tmp_path), "--runs-dir", tmp_path / "runs")
    line = [ln for ln in stdout.splitlines() if ln.startswith("sigma 0.008")]
    assert line and "mesh 5.606 steps" in line[0], stdout
    assert "NOT converged" in line[0] and "10.6 %" in line[0], line  # before: not said
    report = "\n".join(mfpt_section({"mfpt": data}))
    assert "NOT converged" in report and "10.6 %" in report
    assert "NOT converged" not in "\n".join(mfpt_section({"mfpt": _mfpt_data(1.0)}))


# ------------------------------------------------------------------ 10: the gait simulate uses
@pytest.mark.slow
def test_report_of_a_scene_without_fixedpoint_section_shows_the_gait_simulate_starts_from(
        tmp_path):
    scene = tmp_path / "nofp.yaml"
    scene.write_text(yaml.safe_dump({k: v for k, v in IDEAL.items() if k != "fixedpoint"}))
    runs = tmp_path / "runs"
    code, err, _ = _cli("simulate", scene, "--runs-dir", runs)  # runs the fixed point first
    assert code == 0, err
    code, err, _ = _cli("report", scene, "--runs-dir", runs)
    assert code == 0, err
    md = (runs / "nofp" / "report" / "report.md").read_text()
    # before: left out ("an earlier standalone run: the scene has no 'fixedpoint' section")
    assert "## Fixed point of the Poincaré map" in md and "Floquet multipliers" in md
    assert "fixedpoint.h5 (an earlier standalone run" not in md


# ------------------------------------------------------------------ 11: a damper is not drift
def test_a_dampers_loss_is_named_and_the_balance_checked_with_it():
    """Hip spring 20 N m/rad with a 0.05 N m s/rad damper: the report called the damper's
    0.026 J "energy drift between impacts" (3.7e-9 J without the damper).  The energy ledger
    of the run (``simulate.h5``, ledger/) has the damper's work and the balance's closure."""
    from types import SimpleNamespace

    from walkerlab.report.sections import energy_check
    from walkerlab.units import Units

    def sim(damper):
        n = 3
        return SimpleNamespace(ledger={
            "damper_work": np.full(n, damper), "actuator_work_positive": np.zeros(n),
            "actuator_work_negative": np.zeros(n), "closure": np.array([-2e-13, 2.5e-13, 0])})

    text, rows = energy_check(sim(-0.0527), (0.026, 1.7e-4), Units())
    assert "drift" not in text and "dampers dissipate 0.0527 J per step" in text, text
    assert "closes to 2.5e-13 J" in text, text
    assert [r[0] for r in rows] == ["damper work per step (energy ledger)",
                                    "energy balance closure, largest per step (ledger)"]
    text, rows = energy_check(sim(0.0), (3.7e-9, 1e-11), Units())  # no damper: drift is the check
    assert text.startswith("energy drift between impacts 3.7e-09 J"), text


# ------------------------------------------------------------------ 12: the upper body drawn
def test_animation_draws_the_upper_body(tmp_path):
    """torso_bhm: a 5 kg upper body 0.2 m above the hip on a bisecting hip.  Every frame
    draws a line from the hip to it (before: only the legs and the hip were drawn)."""
    from walkerlab.config import load_scene
    from walkerlab.io.artifacts import open_artifact
    from walkerlab.io.trajectory import read_samples
    from walkerlab.plotting.animation import walker_animation
    from walkerlab.stages import pipeline

    scene = load_scene(ROOT / "configs" / "torso_bhm.yaml")
    with open_artifact(pipeline.run("simulate", scene, tmp_path).path, "simulate") as f:
        tr = read_samples(f)
    frames = walker_animation({"rigid": tr}, scene.slope.phi_rad, max_frames=8)
    try:
        for j in range(len(frames.times)):
            frames.draw(j)
            i = np.clip(np.searchsorted(tr.time, frames.times[j]), 0, tr.time.size - 1)
            hip, body = tr.points["hip"][:, i], tr.points["torso_mass"][:, i]
            assert body[1] > hip[1] and abs(np.hypot(*(body - hip)) - 0.2) < 1e-9
            lines = [np.column_stack(ln.get_data()) for ln in frames.fig.axes[0].lines]
            assert any(len(xy) == 2 and np.allclose(xy, [hip, body], atol=1e-12)
                       for xy in lines), "no line from the hip to the upper body"
    finally:
        import matplotlib.pyplot as plt

        plt.close(frames.fig)


# ------------------------------------------------------------------ 6: a stride map on a branch
@pytest.mark.slow
def test_continuation_where_the_legs_start_to_differ_writes_its_artifact(tmp_path):
    """A hip spring's rest angle from 0 (legs alike: a one-step map) to 0.01 rad (legs that
    differ: a stride) - before: 9-15 s of work, then "setting an array element with a
    sequence" while writing (orbits of 1 and 2 heel strikes on one branch).  The branch has
    one map, a stride, throughout; the fixed points at 0 are the gait's, as before."""
    from walkerlab.io.schemas.continuation import load_continuation

    code, err, _ = _cli("continuation", ROOT / "configs" / "hip_spring.yaml", "--param",
                        "walker.springs.0.rest_angle_rad=0:0.01", "--runs-dir", tmp_path)
    assert code == 0, err
    path = tmp_path / "hip_spring" / "continuation_walker.springs.0.rest_angle_rad.h5"
    with h5py.File(path, "r") as f:
        orbit = f["branches/0/orbit/swing_angle"][()]
    assert orbit.ndim == 2 and orbit.shape[1] == 2  # two heel strikes a map at every point
    d = load_continuation(path)
    assert np.all(np.isfinite(d.branches[0]["param"]))


# ------------------------------------------------------------------ 4: every Dask wait bounded
class _NoWorkerClient:
    """A client whose scheduler answers but has no worker (the only one was killed)."""

    status = "running"
    scheduler = type("S", (), {"address": "tcp://127.0.0.1:1", "identity": None})()

    def sync(self, fn, callback_timeout=None):
        return {"workers": {}}


class _LostDataFuture:
    """A finished future whose data died with its worker: Dask computes it again, and its
    ``result()`` waits - for ever, with no worker, unless given a timeout."""

    key = "piece-1"
    status = "finished"

    def result(self, timeout=None):
        if timeout is None:
            raise AssertionError("an unbounded wait on a Dask future")
        import time as _time

        _time.sleep(min(timeout, 0.05))
        raise TimeoutError


def test_waiting_for_a_dask_result_is_bounded_and_says_why(monkeypatch):
    """A sweep's chains wait on each finished piece's result (its continuation guess):
    with the worker that held it killed, that wait never ended (170 s+, while mfpt's wait
    for finished futures ended at 60 s).  Both waits are now one: no worker for
    $WALKERLAB_DASK_WORKER_WAIT_S seconds ends it in one line."""
    pytest.importorskip("distributed")
    from walkerlab.execution import dask as D

    monkeypatch.setattr(D, "CHECK_S", 0.05)
    monkeypatch.setenv(D.WAIT_ENV, "0.3")
    with pytest.raises(D.DaskLost, match="has had no worker for 0.3 s") as info:
        D.result(_NoWorkerClient(), _LostDataFuture())
    assert "--resume" in str(info.value) and "{rerun}" not in str(info.value)


def test_search_budgets_nest_and_end_with_their_search():
    """A fixed point inside a gait search keeps the search's earlier deadline and adds its
    maps to the search's count; after the search no map is bounded (per thread)."""
    import threading

    from walkerlab.analysis.gait import poincare as P

    with P.search_budget(1000.0):
        outer = P._BUDGET.deadline
        with P.search_budget(2000.0):
            assert P._BUDGET.deadline == outer
            P._map_started()
        with P.search_budget(0.0):
            with pytest.raises(P.SearchGaveUp, match="gave up after 1 step map"):
                P._map_started()
        assert P._BUDGET.deadline == outer
        seen = []
        t = threading.Thread(target=lambda: seen.append(P._BUDGET.deadline))
        t.start()
        t.join()
        assert seen == [float("inf")]  # another thread's search has its own budget
    assert P._BUDGET.deadline == float("inf")
