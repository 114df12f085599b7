"""Parameter sweeps: parsing, typed outcomes, resume, Dask parity, bifurcation onset."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.io.sweep_store import load_sweep, partial_path
from walkerlab.stages import sweep as sweep_stage
from walkerlab.studies import points as points_mod
from walkerlab.studies.outcomes import COLUMNS, OUTCOMES
from walkerlab.studies.params import SweepError, apply_point, parse_param
from walkerlab.studies.points import evaluate
from walkerlab.studies.sweep_plan import plan_chunks
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "configs" / "goswami1996.yaml"
FAR_STATE = {"swing_angle_rad": -0.33, "stance_angle_rad": 0.22,
             "swing_rate_rad_per_s": -0.38, "stance_rate_rad_per_s": -0.3}


def _plant(base: dict) -> Plant:
    """The plant of a scene mapping (the study's, as its stage builds it)."""
    return Plant.from_scene(scene_from_dict(base))


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


def test_a_sweeps_rows_are_the_fixed_points_from_the_scenes_guess_bit_for_bit(scene, tmp_path):
    """Every point is solved on its own, from the scene's initial guess (no neighbour's
    gait): its state, period and multipliers are those of a plain root finder's run from
    that guess, to the last bit (the same MINPACK run)."""
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker
    from walkerlab.studies.outcomes import state_column

    slopes = np.round(np.arange(3.0, 3.21, 0.1), 10)
    rows = _rows(sweep_stage.run(scene, ["slope.angle_deg=3:3.2:0.1"], "fixedpoint",
                                 workers=1, runs_root=tmp_path, progress=False))
    assert list(rows["param/slope.angle_deg"]) == list(slopes)
    assert list(rows["outcome"]) == ["ok"] * 3
    assert list(rows["guess_source"]) == ["scene"] * 3
    # every row carries its gait's ground verdict: Goswami's walker needs mu ~ 0.27 < 0.9
    assert set(rows["inside_friction_cone"]) == {1.0} and set(rows["friction_coefficient"]) \
        == {0.9} and np.all((0.2 < rows["max_friction_ratio"]) & (rows["max_friction_ratio"]
                                                                   < 0.35))
    for k, v in enumerate(slopes):
        sc = apply_point(scene.model_dump(mode="json"), ["slope.angle_deg"], (float(v),))
        w = build_walker(Plant.from_scene(sc))
        ref = find_fixed_point(w, sc.fixedpoint.initial_guess.as_array(w.state_names()),
                               Solver.from_settings(sc.solver), xtol=sc.fixedpoint.tolerance,
                               fd_check=False)
        x = [rows[state_column(n, u)][k] for n, u in zip(w.state_names(), w.state_units())]
        assert np.array_equal(np.array(x), ref.x)
        assert rows["step_period_s"][k] == ref.period_s
        assert rows["max_abs_multiplier"][k] == np.max(np.abs(ref.multipliers_variational))


def test_a_point_ignores_any_neighbours_gait(base):
    """A point's row is a function of the point alone: a (wrong) guess handed to it changes
    nothing (what keeps a sweep's rows independent of how its points are dealt out)."""
    row, _ = evaluate("fixedpoint", base, ["slope.angle_deg"], (3.1,), 0, None, {},
                      plant=_plant(base))
    far, _ = evaluate("fixedpoint", base, ["slope.angle_deg"], (3.1,), 0,
                      np.array([-0.33, 0.22, -0.38, -0.3]), {}, plant=_plant(base))
    assert row["outcome"] == far["outcome"] == "ok"
    for k in row:
        if k != "wall_time_s":
            assert row[k] == far[k] or (row[k] != row[k] and far[k] != far[k]), k


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
    row, _ = evaluate("fixedpoint", base, ["slope.angle_deg"], (0.0,), 0, None, {},
                      plant=_plant(base))
    assert row["outcome"] == "no_fixed_point" and np.isfinite(row["residual"])
    assert row["residual"] > 1e-6
    row, x = evaluate("fixedpoint", base, ["slope.angle_deg"], (5.0,), 1, None, {},
                      plant=_plant(base))
    assert row["outcome"] == "ok" and row["stable"] == 0.0
    assert row["multiplier_0_re"] < -1.0 and abs(row["multiplier_0_im"]) < 1e-12


def test_far_initial_state_falls(base):
    b = dict(base, simulate={**base["simulate"], "initial_state": FAR_STATE})
    row, _ = evaluate("simulate", b, ["slope.angle_deg"], (3.0,), 0, None, {}, plant=_plant(b))
    assert row["outcome"] == "fall"
    assert row["fall_leg"] in ("leg1", "leg2") and 0 < row["fall_time_s"] < 5
    assert row["steps_completed"] == 0


def test_max_steps_scuffing_solver_failure_error(base, monkeypatch):
    row, _ = evaluate("simulate", base, ["simulate.max_step_time_s"], (0.05,), 0, None, {},
                      plant=_plant(base))
    assert row["outcome"] == "max_steps"
    b = dict(base, simulate={**base["simulate"], "strides": 1})
    row, _ = evaluate("simulate", b, ["slope.angle_deg"], (3.0,), 0, None,
                      {"scuff_limit_m": 1e-4}, plant=_plant(b))
    assert row["outcome"] == "scuff" and row["scuff_depth_m"] > 1e-3  # ideal gait dips ~3.6 mm
    row, _ = evaluate("simulate", b, ["slope.angle_deg"], (3.0,), 0, None, {}, plant=_plant(b))
    assert row["outcome"] == "ok" and row["steps_completed"] == 2
    bad = dict(base, simulate={**base["simulate"],
                               "initial_state": {**FAR_STATE,
                                                 "swing_rate_rad_per_s": float("nan")}})
    row, _ = evaluate("simulate", bad, ["slope.angle_deg"], (3.0,), 0, None, {}, plant=_plant(b))
    # a NaN initial state is refused by the scene's validation, naming the field
    assert row["outcome"] == "invalid_config" and "initial_state" in row["message"]

    def boom(*a, **k):
        raise RuntimeError("kaboom")

    monkeypatch.setitem(points_mod.POINT_FUNCTIONS, "fixedpoint", boom)
    row, _ = evaluate("fixedpoint", base, ["slope.angle_deg"], (3.0,), 0, None, {},
                      plant=_plant(base))
    assert row["outcome"] == "error" and "kaboom" in row["message"]


def test_tolerances_from_1e_3_to_1e_12(base):
    xs = {}
    for tol in (1e-3, 1e-6, 1e-9, 1e-12):
        row, _ = evaluate("fixedpoint", base, ["solver.rtol", "solver.atol"], (tol, tol), 0,
                          None, {}, plant=_plant(base))
        assert row["outcome"] in ("ok", "no_fixed_point"), row["message"]
        names = [k for k in row if k.endswith(("_angle_rad", "_rate_rad_per_s"))]
        xs[tol] = np.array([row[k] for k in names]) if row["outcome"] == "ok" else None
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
    params = ["slope.angle_deg=2.8:3.1:0.1"]  # two runs of 2 points each
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
                              xtol_deg=1e-3, plant=Plant.from_scene(scene))
    m = np.array([min_real_multiplier(z) for z in res.multipliers])
    lo, hi = res.onset["bracket_deg"]
    k = int(np.flatnonzero(res.slopes_deg == lo)[0])
    assert m[k] > -1.0 >= m[k + 1]
    assert lo < res.onset["onset_deg"] < hi
    assert abs(res.onset["multiplier_at_onset"] + 1.0) < 1e-2
    assert all(o == "ok" for o in res.fp_outcome)


def test_a_sweeps_rows_are_the_same_in_process_and_on_a_pool_of_two(scene, tmp_path):
    """One worker, two (the work is small: run here) and a forced pool of two, whose
    chunks deal the points out otherwise: the same rows, bit for bit."""
    params = ["slope.angle_deg=2.5,3,3.5"]
    runs = [_rows(sweep_stage.run(scene, params, "fixedpoint", workers=w, runs_root=tmp_path,
                                  name=f"w{w}_{pool}", progress=False, pool=pool,
                                  figure=False))
            for w, pool in ((1, None), (2, None), (2, True))]
    for b in runs[1:]:
        for col in [*COLUMNS["fixedpoint"], "outcome", "guess_source", "message"]:
            np.testing.assert_array_equal(runs[0][col], b[col], err_msg=col)


def test_a_small_sweep_on_two_workers_starts_no_pool(scene, tmp_path, monkeypatch):
    """Eight points whose time does not pay a pool's start-up: two workers run them in
    this process (the first piece, timed, decides, :func:`walkerlab.studies.runner.pool_pays`;
    the start-up set out of reach here, so that a loaded machine's slow points cannot
    change the decision)."""
    from walkerlab.studies import runner

    monkeypatch.setattr(runner, "POOL_START_S", 1e9)
    asked = []
    real = runner.sweep_executor

    def spy(workers=2, scheduler=None, pool=None):
        asked.append(pool)
        return real(workers, scheduler, pool)

    monkeypatch.setattr(runner, "sweep_executor", spy)
    rows = _rows(sweep_stage.run(scene, ["slope.angle_deg=2.6:3.3:0.1"], "fixedpoint",
                                 workers=2, runs_root=tmp_path, progress=False, figure=False))
    assert rows["index"].size == 8 and set(rows["outcome"]) == {"ok"}
    assert asked == [False, False]  # the timed first piece, then the rest: both here
    monkeypatch.setattr(runner, "POOL_START_S", 1.0)
    monkeypatch.setattr("os.cpu_count", lambda: 2)
    assert not runner.pool_pays(32 * 0.01, 2)  # 32 points of 10 ms: no pool
    assert runner.pool_pays(32 * 0.1, 2)        # of 100 ms: the pool pays
    assert not runner.pool_pays(32 * 0.1, 1)


#: issue 64's walker: level ground, hip 10 kg, one 3 kg mass at 0.5 m on each leg, push-off
#: 3 N s and a hip spring; its initial guess (configs/powered_compass.yaml's, for 5 kg legs)
#: does not converge at k = 0 and leads to the unstable short-period gait at k = 1 N m/rad
HIP_SPRING_PUSH_OFF = {
    "walker": {"model": "biped", "gravity_m_per_s2": 9.81, "hip_mass_kg": 10.0,
               "leg": {"length_m": 1.0, "bodies": [{"kind": "point_mass", "name": "leg_mass",
                                                    "mass_kg": 3.0, "from_hip_m": 0.5}]},
               "actuation": {"push_off": {"impulse_n_s": 3.0},
                             "torques": [{"joint": "hip", "law": {
                                 "stiffness_n_m_per_rad": 0.0,
                                 "damping_n_m_s_per_rad": 0.0}}]}},
    "slope": {"angle_rad": 0.0},
    "solver": {"method": "DOP853", "rtol": 1e-12, "atol": 1e-12},
    "fixedpoint": {"initial_guess": {"swing_angle_rad": -0.1735, "stance_angle_rad": 0.1735,
                                     "swing_rate_rad_per_s": -0.7654,
                                     "stance_rate_rad_per_s": -0.8690},
                   "tolerance": 1e-12, "gait": "stable"},
}


@pytest.mark.slow  # 11 points of a seeded search (~0.3 s each), twice, and the stage
def test_a_hip_spring_sweep_is_one_stable_branch_on_any_worker_count(tmp_path):
    """Issue 64: the sweep over the hip spring's stiffness alternated between the stable
    and the unstable gait with two workers.  Now one worker and a pool of two give the same
    rows, every point the stable gait (fixedpoint.gait: stable), and the first point (the
    scene itself) is the gait ``walkerlab fixedpoint`` writes, to the last bit."""
    import yaml

    from walkerlab.config import load_scene
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.stages import fixedpoint as fixedpoint_stage

    path = tmp_path / "hip_spring_push_off.yaml"
    path.write_text(yaml.safe_dump(HIP_SPRING_PUSH_OFF))
    sc = load_scene(path)
    param = ["walker.actuation.torques.0.law.stiffness_n_m_per_rad=0:5:0.5"]
    one, two = (_rows(sweep_stage.run(sc, param, "fixedpoint", workers=w, pool=pool,
                                      runs_root=tmp_path, name=f"w{w}", progress=False,
                                      figure=False)) for w, pool in ((1, None), (2, True)))
    for col in [*COLUMNS["fixedpoint"], "outcome", "guess_source"]:
        np.testing.assert_array_equal(one[col], two[col], err_msg=col)
    assert set(one["outcome"]) == {"ok"} and set(one["stable"]) == {1.0}
    mult = one["max_abs_multiplier"]
    assert np.all(mult < 0.86) and np.all(np.diff(mult) > 0)  # 0.782 ... 0.850, smooth
    fixedpoint_stage.run(sc, runs_root=tmp_path)
    fp = load_fixedpoint(tmp_path / sc.name / "fixedpoint.h5")
    from walkerlab.studies.outcomes import state_column

    names = ("swing_angle", "stance_angle", "swing_rate", "stance_rate")
    units = ("rad", "rad", "rad/s", "rad/s")
    x = [one[state_column(n, u)][0] for n, u in zip(names, units)]
    assert np.array_equal(np.array(x), fp.x)
    assert one["step_period_s"][0] == fp.step_period_s


@pytest.mark.slow  # a Dask cluster and 4 seeded points twice
def test_a_hip_spring_sweep_on_dask_has_the_rows_of_one_worker(tmp_path, dask_cluster):
    """Issue 64 on Dask (``--scheduler``): the rows of a cluster of two workers are those of
    one local worker, bit for bit, and every point is the stable gait."""
    import yaml

    from walkerlab.config import load_scene

    path = tmp_path / "hip_spring_push_off.yaml"
    path.write_text(yaml.safe_dump(HIP_SPRING_PUSH_OFF))
    sc = load_scene(path)
    param = ["walker.actuation.torques.0.law.stiffness_n_m_per_rad=0:1.5:0.5"]
    addr, _workers = dask_cluster
    one = _rows(sweep_stage.run(sc, param, "fixedpoint", workers=1, runs_root=tmp_path,
                                name="one", progress=False, figure=False))
    dask = _rows(sweep_stage.run(sc, param, "fixedpoint", scheduler=addr, runs_root=tmp_path,
                                 name="dask", progress=False, figure=False))
    for col in [*COLUMNS["fixedpoint"], "outcome", "guess_source"]:
        np.testing.assert_array_equal(one[col], dask[col], err_msg=col)
    assert set(one["stable"]) == {1.0} and one["index"].size == 4


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


# ----------------------------------------------------------------------------- one map
def test_a_studys_map_is_a_stride_when_any_point_needs_one():
    """Issue 82 item 1: the map is decided for the whole study before any point is solved:
    a 3D walker's hip width from 0 (a step map) to 0.1 m (a stride) makes it a stride; a
    study of zero widths alone, or of the slope of a planar walker, keeps the step."""
    from walkerlab.studies.map_length import study_steps_per_map

    hip = load_scene(ROOT / "configs" / "hip_width.yaml").model_dump(mode="json")
    path = ["walker.hip_width_m"]
    assert study_steps_per_map(hip, path, [(0.0,), (0.1,)], plant=_plant(hip)) == 2
    assert study_steps_per_map(hip, path, [(0.1,), (0.0,)], plant=_plant(hip)) == 2
    assert study_steps_per_map(hip, path, [(0.0,)], plant=_plant(hip)) == 1
    goswami = load_scene(SCENE).model_dump(mode="json")
    assert study_steps_per_map(goswami, ["slope.angle_deg"], [(1.0,), (3.0,)],
                               plant=_plant(goswami)) == 1
    # a point whose scene does not validate is left out (its row says why)
    assert study_steps_per_map(hip, path, [(-1.0,), (0.0,)], plant=_plant(hip)) == 1


def test_a_3d_sweep_reports_every_point_per_stride(tmp_path):
    """Issue 82 item 1: ``walkerlab sweep`` of the hip-width walker over 0 and 0.1 m gave
    11.23 at zero width (a step map) beside 99.93 at 0.1 m (a stride map).  Now every point
    is on the study's one map, a stride: at zero width the multipliers are those of the
    walker's own step map squared - checked against the zero-width 3D paper walker
    (configs/paper_3d.yaml) on its own step map, an independent run - the artifact records
    the map (``steps_per_map``), and the summary and the figure say "per stride"."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.plotting.sweep_figures import sweep_figure
    from walkerlab.report.sweep_text import sweep_text

    sc = load_scene(ROOT / "configs" / "hip_width.yaml")
    out = sweep_stage.run(sc, ["walker.hip_width_m=0,0.1"], "fixedpoint", workers=1,
                          runs_root=tmp_path, progress=False, figure=False)
    data = load_sweep(out)
    rows = data["points"]
    assert list(rows["outcome"]) == ["ok", "ok"]
    assert int(data["attrs"]["steps_per_map"]) == 2
    sc1 = load_scene(ROOT / "configs" / "paper_3d.yaml")
    walker, search = solve_scene(sc1,
                                 fd_check=False, plant=Plant.from_scene(sc1))
    assert walker.steps_per_map == 1  # zero width: the walker's own map is a step
    step = np.abs(search.result.multipliers_variational)
    assert step.max() == pytest.approx(11.23, abs=0.01)  # the old sweep's row at w = 0
    # per stride = per step squared (legs that are mirror images), to the integration's and
    # the root finder's error (rtol 1e-12: ~1e-9 relative; 1e-7 leaves a margin)
    assert rows["max_abs_multiplier"][0] == pytest.approx(step.max() ** 2, rel=1e-7)
    stride = np.array([rows[f"multiplier_{k}_re"][0] + 1j * rows[f"multiplier_{k}_im"][0]
                       for k in range(step.size)])
    assert np.sort(np.abs(stride)) == pytest.approx(np.sort(step ** 2), rel=1e-7, abs=1e-8)
    assert rows["max_abs_multiplier"][1] == pytest.approx(99.93, abs=0.01)
    # the instability falls with the hip width (126 -> 100 per stride), as continuation says
    assert rows["max_abs_multiplier"][0] > rows["max_abs_multiplier"][1]
    # the step period stays a step's on the stride map (the stride's halved)
    assert rows["step_period_s"][0] == pytest.approx(search.result.period_s, rel=1e-9)
    text = sweep_text(data)
    assert "max_abs_multiplier" in text and "(per stride, every point)" in text
    fig = sweep_figure(data)
    assert any("per stride" in ax.get_ylabel() for ax in fig.axes)


def test_a_sweep_artifact_without_its_map_makes_no_claim():
    """An artifact written before the map was recorded (no ``steps_per_map``) is summarised
    without "per step" or "per stride": it does not say what it does not know."""
    from walkerlab.report.sweep_text import sweep_text

    deg = np.array([1.0, 2.0])
    data = {"attrs": {"sweep_stage": "fixedpoint", "scene_units": "SI"},
            "axes": [("slope.angle_deg", deg)],
            "points": {"outcome": np.array(["ok", "ok"]), "param/slope.angle_deg": deg,
                       "step_period_s": np.array([0.7, 0.72]),
                       "max_abs_multiplier": np.array([0.5, 0.6])}}
    assert "per st" not in sweep_text(data)
    data["attrs"]["steps_per_map"] = 1
    assert "(per step, every point)" in sweep_text(data)


@pytest.mark.slow  # ~40 s: the hip-roll walker's and the zero-width walker's gaits
def test_a_stable_3d_gait_and_the_planar_embedding_sweep_on_their_own_maps(tmp_path):
    """Issue 82 item 1's checks on a stable 3D gait and on the planar embedding: the
    stabilised hip-width walker (configs/hip_width_stabilised.yaml, its map a stride at
    every width) sweeps per stride, every point stable, its scene's point the documented
    0.5463; the zero-width walker (configs/paper_3d.yaml) over the slope stays on its own
    step map (per step: 11.23 at the paper's slope), its planar multipliers among them."""
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.report.sweep_text import sweep_text

    stab = load_scene(ROOT / "configs" / "hip_width_stabilised.yaml")
    data = load_sweep(sweep_stage.run(stab, ["walker.hip_width_m=0.1,0.12"], "fixedpoint",
                                      workers=1, runs_root=tmp_path, progress=False,
                                      figure=False))
    rows = data["points"]
    assert int(data["attrs"]["steps_per_map"]) == 2 and set(rows["stable"]) == {1.0}
    assert rows["max_abs_multiplier"][0] == pytest.approx(0.5463, abs=1e-4)
    assert "(per stride, every point)" in sweep_text(data)
    flat = load_scene(ROOT / "configs" / "paper_3d.yaml")
    data = load_sweep(sweep_stage.run(flat, ["slope.angle_rad=0.0174"], "fixedpoint",
                                      workers=1, runs_root=tmp_path, progress=False,
                                      figure=False))
    assert int(data["attrs"]["steps_per_map"]) == 1
    assert data["points"]["max_abs_multiplier"][0] == pytest.approx(11.23, abs=0.01)
    assert "(per step, every point)" in sweep_text(data)
    sc = load_scene(ROOT / "configs" / "paper.yaml")
    _w, planar = solve_scene(sc, fd_check=False, plant=Plant.from_scene(sc))
    mult = np.array([data["points"][f"multiplier_{k}_re"][0]
                     + 1j * data["points"][f"multiplier_{k}_im"][0] for k in range(6)])
    for m in planar.result.multipliers_variational:  # the planar ones among the 3D ones
        assert np.min(np.abs(mult - m)) < 1e-7
