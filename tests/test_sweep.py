"""Parameter sweeps: parsing, typed outcomes, resume, Dask parity, bifurcation onset."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.io.sweep_store import load_sweep, partial_path
from walkerlab.stages import sweep as sweep_stage
from walkerlab.studies import points as points_mod
from walkerlab.studies.outcomes import COLUMNS, OUTCOMES
from walkerlab.studies.params import SweepError, apply_point, parse_param
from walkerlab.studies.points import evaluate
from walkerlab.studies.runner import plan_chunks

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "configs" / "goswami1996.yaml"
FAR_STATE = {"swing_angle_rad": -0.33, "stance_angle_rad": 0.22,
             "swing_rate_rad_per_s": -0.38, "stance_rate_rad_per_s": -0.3}


@pytest.fixture(scope="module")
def scene():
    return load_scene(SCENE)


@pytest.fixture(scope="module")
def base(scene):
    return scene.model_dump(mode="json")


def _rows(path):
    return load_sweep(path)["points"]


# ----------------------------------------------------------------------------- parsing
def test_parse_param_range_inclusive_and_rounded():
    ax = parse_param("slope.angle_deg=0.5:5:0.05")
    assert ax.path == "slope.angle_deg" and len(ax) == 91
    assert ax.values[0] == 0.5 and ax.values[-1] == 5.0 and ax.values[2] == 0.6
    assert parse_param("x.y=1:0:-0.25").values == (1.0, 0.75, 0.5, 0.25, 0.0)
    assert parse_param("x.y=0:1:0.3").values == (0.0, 0.3, 0.6, 0.9)  # stop not reached
    assert parse_param("x.y=0:0.3:0.1").values[-1] == 0.3               # float noise kept


def test_parse_param_lists_and_errors():
    assert parse_param("solver.rtol=1e-3,1e-6").values == (1e-3, 1e-6)
    assert parse_param("solver.method=RK45, DOP853").values == ("RK45", "DOP853")
    assert parse_param("simulate.strides=1,2").values == (1, 2)
    assert parse_param("a.b=true,null").values == (True, None)
    for bad in ("slope.angle_deg", "=1,2", "a.b=", "a.b=1:2", "a.b=0:1:0", "a.b=1:0:0.1",
                "a.b=x:1:0.1", "a b=1", "a.b=0:1e9:1e-3"):
        with pytest.raises(SweepError):
            parse_param(bad)


def test_apply_point_swaps_exclusive_slope_fields(base):
    b = dict(base, slope={"angle_rad": 0.05, "angle_deg": None})
    sc = apply_point(b, ["slope.angle_deg"], (2.0,))
    assert sc.slope.angle_rad is None and math.isclose(sc.slope.phi_rad, math.radians(2.0))


def test_plan_chunks_runs_from_scene_value_and_skips_done(base):
    ax = [parse_param("slope.angle_deg=2:4:0.5"), parse_param("walker.hip_mass_kg=5,10")]
    chunks = plan_chunks(ax, base)  # scene slope 3 deg -> runs up from 3 and down from 2.5
    vals = sorted([[v[0] for _, v in c] for c in chunks])
    assert vals == [[2.5, 2.0], [2.5, 2.0], [3.0, 3.5, 4.0], [3.0, 3.5, 4.0]]
    idx = {i for c in chunks for i, _ in c}
    assert idx == set(range(10))
    left = plan_chunks(ax, base, done={0, 1, 2, 3})
    assert {i for c in left for i, _ in c} == set(range(4, 10))


def test_plan_chunks_deals_a_long_run_out_interleaved(base):
    ax = [parse_param("slope.angle_deg=2:5:0.25")]  # scene slope 3: runs 3..5 (9) and 2.75..2 (4)
    chunks = plan_chunks(ax, base, workers=2)
    vals = [[v[0] for _, v in c] for c in chunks]
    # no chain longer than half the work: the 9-point run becomes 3, 3.5, ... and 3.25, 3.75, ...
    assert vals == [[3.0, 3.5, 4.0, 4.5, 5.0], [3.25, 3.75, 4.25, 4.75], [2.75, 2.5, 2.25, 2.0]]
    assert sorted(i for c in chunks for i, _ in c) == list(range(13))


def test_continuation_matches_independent_fixed_points(scene, tmp_path):
    """Secant predictor + the previous point's Jacobian (MINPACK hybrj) converge to the
    fixed points and Floquet multipliers of independent searches from the scene's guess,
    to well below the sweep's use (1e-9 rad, 1e-7), with fewer Poincare maps."""
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker
    from walkerlab.studies.outcomes import state_column

    slopes = np.round(np.arange(3.0, 3.31, 0.05), 10)
    rows = _rows(sweep_stage.run(scene, ["slope.angle_deg=3:3.3:0.05"], "fixedpoint",
                                 workers=1, runs_root=tmp_path, progress=False))
    assert list(rows["param/slope.angle_deg"]) == list(slopes)
    assert list(rows["outcome"]) == ["ok"] * 7
    assert list(rows["guess_source"]) == ["scene"] + ["neighbour"] * 6
    maps = []
    for k, v in enumerate(slopes):
        sc = apply_point(scene.model_dump(mode="json"), ["slope.angle_deg"], (float(v),))
        w = build_walker(sc)
        ref = find_fixed_point(w, sc.fixedpoint.initial_guess.as_array(w.state_names()),
                               Solver.from_settings(sc.solver), xtol=sc.fixedpoint.tolerance,
                               fd_check=False)
        maps.append(ref.iterations)
        x = [rows[state_column(n, u)][k] for n, u in zip(w.state_names(), w.state_units())]
        assert np.max(np.abs(np.array(x) - ref.x)) < 1e-9
        mult = rows["multiplier_0_re"][k] + 1j * rows["multiplier_0_im"][k]
        assert abs(mult - ref.multipliers_variational[0]) < 1e-7
        assert abs(rows["max_abs_multiplier"][k]
                   - np.max(np.abs(ref.multipliers_variational))) < 1e-7
    # from the third point on the predictor + Jacobian path runs: fewer maps than a cold start
    assert np.median(rows["map_evaluations"][2:]) < np.median(maps[2:])


def test_failed_point_and_bad_jacobian_do_not_poison_the_continuation(base):
    from walkerlab.studies.points import Continuation

    cont = None
    for v in (2.9, 3.0):
        _, cont = evaluate("fixedpoint", base, ["slope.angle_deg"], (v,), 0, cont, {})
    row, nxt = evaluate("fixedpoint", base, ["slope.angle_deg"], (0.0,), 0, cont, {})
    assert row["outcome"] == "no_fixed_point" and nxt is None  # the caller keeps `cont`
    ok, _ = evaluate("fixedpoint", base, ["slope.angle_deg"], (3.1,), 0, None, {})
    row, nxt = evaluate("fixedpoint", base, ["slope.angle_deg"], (3.1,), 0, cont, {})
    assert row["outcome"] == "ok" and row["guess_source"] == "neighbour"
    assert nxt.values == (3.0, 3.1) and abs(row["residual"]) < 1e-9
    assert abs(row["step_period_s"] - ok["step_period_s"]) < 1e-9
    # a useless Jacobian guess (zeros): hybrj fails or recovers, the plain search still wins
    bad = Continuation(cont.values, cont.states, tuple(np.zeros_like(j) for j in cont.jacobians))
    row, _ = evaluate("fixedpoint", base, ["slope.angle_deg"], (3.1,), 0, bad, {})
    assert row["outcome"] == "ok" and abs(row["step_period_s"] - ok["step_period_s"]) < 1e-9


# ----------------------------------------------------------------------------- outcomes
def test_bad_value_is_an_invalid_config_row(scene, tmp_path):
    """Values valid one by one but not together (a = 0.8 m on a 0.6 m leg): that point is an
    invalid_config row; a value invalid on its own is refused before the sweep starts
    (tests/test_gaits.py::test_sweep_over_an_unknown_field_is_refused)."""
    p = sweep_stage.run(scene, ["walker.leg_length_m=1.0,0.6",
                                "walker.leg_mass_from_foot_m=0.8"],
                        "fixedpoint", workers=1, runs_root=tmp_path, progress=False)
    rows = _rows(p)
    assert p.name.startswith("sweep_fixedpoint_") and p.is_file()
    assert not partial_path(p).exists()
    out = dict(zip(rows["param/walker.leg_length_m"], rows["outcome"]))
    assert out[1.0] in ("ok", "no_fixed_point")
    assert out[0.6] == "invalid_config"
    msg = rows["message"][list(rows["outcome"]).index("invalid_config")]
    assert "\n" not in msg and "leg_mass_from_foot_m" in msg


def test_slope_zero_no_fixed_point_and_past_period_doubling(base):
    row, _ = evaluate("fixedpoint", base, ["slope.angle_deg"], (0.0,), 0, None, {})
    assert row["outcome"] == "no_fixed_point" and np.isfinite(row["residual"])
    assert row["residual"] > 1e-6
    row, x = evaluate("fixedpoint", base, ["slope.angle_deg"], (5.0,), 1, None, {})
    assert row["outcome"] == "ok" and row["stable"] == 0.0
    assert row["multiplier_0_re"] < -1.0 and abs(row["multiplier_0_im"]) < 1e-12
    assert x.x.shape == (4,)  # the continuation carries the fixed point on


def test_far_initial_state_falls(base):
    b = dict(base, simulate={**base["simulate"], "initial_state": FAR_STATE})
    row, _ = evaluate("simulate", b, ["slope.angle_deg"], (3.0,), 0, None, {})
    assert row["outcome"] == "fall"
    assert row["fall_leg"] in ("leg1", "leg2") and 0 < row["fall_time_s"] < 5
    assert row["steps_completed"] == 0


def test_max_steps_scuffing_solver_failure_error(base, monkeypatch):
    row, _ = evaluate("simulate", base, ["simulate.max_step_time_s"], (0.05,), 0, None, {})
    assert row["outcome"] == "max_steps"
    b = dict(base, simulate={**base["simulate"], "strides": 1})
    row, _ = evaluate("simulate", b, ["slope.angle_deg"], (3.0,), 0, None,
                      {"scuff_limit_m": 1e-4})
    assert row["outcome"] == "scuff" and row["scuff_depth_m"] > 1e-3  # ideal gait dips ~3.6 mm
    row, _ = evaluate("simulate", b, ["slope.angle_deg"], (3.0,), 0, None, {})
    assert row["outcome"] == "ok" and row["steps_completed"] == 2
    bad = dict(base, simulate={**base["simulate"],
                               "initial_state": {**FAR_STATE,
                                                 "swing_rate_rad_per_s": float("nan")}})
    row, _ = evaluate("simulate", bad, ["slope.angle_deg"], (3.0,), 0, None, {})
    # a NaN initial state is refused by the scene's validation, naming the field
    assert row["outcome"] == "invalid_config" and "initial_state" in row["message"]

    def boom(*a, **k):
        raise RuntimeError("kaboom")

    monkeypatch.setitem(points_mod.POINT_FUNCTIONS, "fixedpoint", boom)
    row, _ = evaluate("fixedpoint", base, ["slope.angle_deg"], (3.0,), 0, None, {})
    assert row["outcome"] == "error" and "kaboom" in row["message"]


def test_tolerances_from_1e_3_to_1e_12(base):
    xs = {}
    for tol in (1e-3, 1e-6, 1e-9, 1e-12):
        row, x = evaluate("fixedpoint", base, ["solver.rtol", "solver.atol"], (tol, tol), 0,
                          None, {})
        assert row["outcome"] in ("ok", "no_fixed_point"), row["message"]
        xs[tol] = x.x if row["outcome"] == "ok" else None
    assert xs[1e-12] is not None and xs[1e-9] is not None
    assert np.max(np.abs(xs[1e-9] - xs[1e-12])) < 1e-6
    if xs[1e-3] is not None:
        assert np.max(np.abs(xs[1e-3] - xs[1e-12])) < 0.05


def test_outcome_columns_declared():
    assert set(OUTCOMES) >= {"ok", "no_fixed_point", "fall", "scuff", "solver_failure",
                             "max_steps", "invalid_config"}
    assert set(COLUMNS) == {"fixedpoint", "simulate", "contact-sim"}


# ----------------------------------------------------------------------------- resume
def test_resume_after_interruption_keeps_finished_rows(scene, tmp_path):
    params = ["slope.angle_deg=2.5:3.5:0.5", "walker.hip_mass_kg=8,10"]

    def stop(done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sweep_stage.run(scene, params, "fixedpoint", workers=1, runs_root=tmp_path,
                        name="resume_me", progress=False, on_chunk=stop)
    final = tmp_path / scene.name / "resume_me.h5"
    part = partial_path(final)
    assert part.is_file() and not final.exists()
    first = _rows(part)
    n_first = first["index"].size
    assert 0 < n_first < 6
    p = sweep_stage.run(scene, params, "fixedpoint", workers=1, runs_root=tmp_path,
                        name="resume_me", progress=False, resume=True)
    rows = _rows(p)
    assert list(rows["index"]) == list(range(6)) and not part.exists()
    for k, i in enumerate(first["index"]):  # finished rows kept untouched (same wall time)
        assert rows["wall_time_s"][i] == first["wall_time_s"][k]
    assert set(rows["outcome"]) == {"ok"}
    with pytest.raises(KeyboardInterrupt):  # interrupt again, then resume another sweep
        sweep_stage.run(scene, params, "fixedpoint", workers=1, runs_root=tmp_path,
                        name="resume_me", progress=False, on_chunk=stop)
    with pytest.raises(SweepError, match="different sweep"):
        sweep_stage.run(scene, ["slope.angle_deg=1,2"], "fixedpoint", workers=1,
                        runs_root=tmp_path, name="resume_me", resume=True, progress=False)


# ----------------------------------------------------------------------------- dask
def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def dask_cluster():
    """A Dask cluster as users start it: ``dask scheduler`` + two ``dask worker`` processes
    (one process, one thread each) on 127.0.0.1; every process is killed at teardown."""
    pytest.importorskip("distributed")
    import os
    import shutil
    import signal
    import subprocess
    import sys

    dask = shutil.which("dask", path=str(Path(sys.executable).parent)) or shutil.which("dask")
    if dask is None:
        pytest.skip("the dask command is not installed")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "DASK_DISTRIBUTED__WORKER__DAEMON": "False"}
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    procs = []

    def start(*args):
        p = subprocess.Popen([dask, *args], env=env, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL, start_new_session=True)
        procs.append(p)
        return p

    try:
        start("scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard")
        workers = [start("worker", addr, "--nworkers", "1", "--nthreads", "1",
                         "--host", "127.0.0.1", "--no-dashboard", "--name", f"w{i}")
                   for i in range(2)]
        from distributed import Client

        with Client(addr, timeout=60, set_as_default=False) as c:
            c.wait_for_workers(2, timeout=60)
        yield addr, workers
    finally:
        for p in procs:
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            p.wait()


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_dask_cluster_matches_local_runner_and_survives_a_lost_worker(scene, tmp_path,
                                                                      dask_cluster,
                                                                      monkeypatch):
    import os
    import signal

    from walkerlab.studies import runner

    addr, workers = dask_cluster
    monkeypatch.setattr(runner, "PIECE_POINTS", 1)  # 4 pieces: work left after the kill
    params = ["slope.angle_deg=2.8:3.1:0.1"]  # two continuation runs of 2 points each
    p_local = sweep_stage.run(scene, params, "fixedpoint", workers=1, runs_root=tmp_path,
                              name="local", progress=False)
    killed = []

    def kill_one_worker(done, total):
        if not killed:  # rows arrived: a worker dies mid-sweep, Dask recomputes its piece
            os.killpg(workers[0].pid, signal.SIGKILL)
            killed.append(done)

    p_dask = sweep_stage.run(scene, params, "fixedpoint", scheduler=addr, runs_root=tmp_path,
                             name="dask", progress=False, on_chunk=kill_one_worker)
    assert killed and killed[0] == 1 and workers[0].poll() is not None
    a, b = _rows(p_local), _rows(p_dask)
    assert list(a["outcome"]) == list(b["outcome"]) == ["ok"] * 4
    for col in COLUMNS["fixedpoint"]:
        np.testing.assert_array_equal(a[col], b[col], err_msg=col)


# ----------------------------------------------------------------------------- bifurcation
def test_bifurcation_onset_where_multiplier_crosses_minus_one(scene):
    from walkerlab.studies.bifurcation import bifurcation_diagram, min_real_multiplier

    res = bifurcation_diagram(scene, [3.5, 4.0, 4.5, 5.0], workers=1, steady_state=False,
                              xtol_deg=1e-3)
    m = np.array([min_real_multiplier(z) for z in res.multipliers])
    lo, hi = res.onset["bracket_deg"]
    k = int(np.flatnonzero(res.slopes_deg == lo)[0])
    assert m[k] > -1.0 >= m[k + 1]
    assert lo < res.onset["onset_deg"] < hi
    assert abs(res.onset["multiplier_at_onset"] + 1.0) < 1e-2
    assert all(o == "ok" for o in res.fp_outcome)


def test_process_pool_matches_in_process_runner(scene, tmp_path):
    params = ["slope.angle_deg=2.5,3,3.5"]
    a = _rows(sweep_stage.run(scene, params, "fixedpoint", workers=1, runs_root=tmp_path,
                              name="inproc", progress=False))
    b = _rows(sweep_stage.run(scene, params, "fixedpoint", workers=2, runs_root=tmp_path,
                              name="pool", progress=False))
    for col in COLUMNS["fixedpoint"]:
        np.testing.assert_array_equal(a[col], b[col], err_msg=col)


def test_a_sweeps_summary_names_its_failed_points_by_their_parameters():
    """Issue 64 item 10: the summary counted failed points without naming them."""
    from walkerlab.report.sweep_text import sweep_text

    deg = np.array([1.0, 1.5, 2.0, 2.5])
    data = {"attrs": {"sweep_stage": "fixedpoint", "scene_units": "SI"},
            "axes": [("slope.angle_deg", deg)],
            "points": {"outcome": np.array(["ok", "no_fixed_point", "ok", "no_fixed_point"]),
                       "param/slope.angle_deg": deg,
                       "step_period_s": np.array([0.7, np.nan, 0.72, np.nan]),
                       "max_abs_multiplier": np.array([0.5, np.nan, 0.6, np.nan])}}
    text = sweep_text(data)
    assert "  no_fixed_point at slope.angle_deg = 1.500; slope.angle_deg = 2.500" in text
