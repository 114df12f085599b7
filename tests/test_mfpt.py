"""Metastability on per-step random slopes: the batched step map, the Monte Carlo estimator,
the mesh machinery and the mfpt stage (Byl & Tedrake 2009)."""

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from tests.cli_run import IDEAL
from tests.cli_run import run_cli as _cli
from walkerlab.analysis.robustness import mfpt as M
from walkerlab.cli import app
from walkerlab.config import load_scene
from walkerlab.integrate.batch_step import HEEL_STRIKE, BatchStepMap
from walkerlab.integrate.rigid import Solver, integrate_step
from walkerlab.models.registry import build_walker
from walkerlab.studies.mfpt import scene_walker_at
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
TIGHT = Solver("DOP853", 1e-12, 1e-12)


@pytest.fixture(scope="module")
def paper_map(paper_scene):
    return BatchStepMap(build_walker(plant := Plant.from_scene(paper_scene)),
                        scene_walker_at(paper_scene, plant), 1e-10, 1e-10)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_batched_step_matches_one_step_integration(paper_scene, paper_map, paper_fixed_point):
    """Each row of the stacked system equals integrate_step of the walker on that row's slope
    (scipy DOP853 at 1e-12 with solve_ivp's event location): the rows' tolerances are
    1e-10, so agreement to 1e-8 in state and step time checks the row-wise event location,
    the per-row slope and the reset; a wrong slope (1e-3 rad apart) moves x_next by ~1e-3."""
    rng = np.random.default_rng(3)
    X = paper_fixed_point.x + 0.01 * rng.standard_normal((8, 4))
    gam = paper_scene.slope.phi_rad + 0.004 * rng.standard_normal(8)
    names = paper_map.walker.state_names()
    X[6:, names.index("stance_rate")] *= [0.5, 1.8]  # too slow (falls back), too fast
    r = paper_map.step(X, gam)
    at = scene_walker_at(paper_scene, plant=Plant.from_scene(paper_scene))
    ends = []
    for i in range(8):
        seg = integrate_step(at(gam[i]), X[i], TIGHT)
        ends.append(seg.termination)
        assert (r.outcome[i] == HEEL_STRIKE) == (seg.termination == "heel_strike")
        if seg.termination == "heel_strike":
            np.testing.assert_allclose(r.x_next[i], seg.x_next, rtol=0, atol=1e-8)
            assert abs(r.step_time_s[i] - seg.period) < 1e-8
        else:  # the same fall guard at the same time
            np.testing.assert_allclose(r.x_pre[i], seg.x_end, rtol=0, atol=1e-8)
    assert ends.count("heel_strike") >= 4 and ends.count("fall") >= 1


def test_heel_strike_on_each_steps_own_slope(paper_scene, paper_map, paper_fixed_point):
    """The compass walker's heel strike lands on theta_swing + theta_stance = -2 gamma_n of
    the row's own slope (the guard of the line through the stance foot at gamma_n)."""
    names = paper_map.walker.state_names()
    gam = paper_scene.slope.phi_rad + np.array([-0.004, 0.0, 0.003])
    r = paper_map.step(np.tile(paper_fixed_point.x, (3, 1)), gam)
    s = r.x_pre[:, names.index("swing_angle")] + r.x_pre[:, names.index("stance_angle")]
    np.testing.assert_allclose(s, -2 * gam, rtol=0, atol=1e-12)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_kneed_walker_two_phases_and_knee_strike(paper_scene):
    """The kneed walker (unlocked swing, knee strike reset, locked swing) through the batched
    map equals integrate_step on two slopes."""
    sc = load_scene(ROOT / "configs" / "kneed.yaml")
    w = build_walker(Plant.from_scene(sc))
    from walkerlab.analysis.gait.poincare import find_fixed_point

    g = sc.fixedpoint.initial_guess.as_array(w.state_names())
    x = find_fixed_point(w, g, TIGHT, fd_check=False).x
    bm = BatchStepMap(w, scene_walker_at(sc, plant=Plant.from_scene(sc)), 1e-10, 1e-10)
    gam = sc.slope.phi_rad + np.array([-0.002, 0.002])
    r = bm.step(np.tile(x, (2, 1)), gam)
    at = scene_walker_at(sc, plant=Plant.from_scene(sc))
    for i in range(2):
        seg = integrate_step(at(gam[i]), x, TIGHT)
        np.testing.assert_allclose(r.x_next[i], seg.x_next, rtol=0, atol=1e-8)


def test_censored_geometric_mle_recovers_known_mfpt():
    """Walks with a known per-step fall probability p (MFPT (1 - p) / p = 99), censored at 60
    steps (most walks are censored): the estimate lies within 3 standard errors of 99, and
    the naive mean of the steps (censoring ignored) does not (it is < 60)."""
    rng = np.random.default_rng(11)
    p, cap, n = 0.01, 60, 20000
    k = rng.geometric(p, n) - 1  # heel strikes before the fall
    fell = k < cap
    steps = np.minimum(k, cap)
    m, se = M.geometric_mle(int(steps.sum()), int(fell.sum()))
    assert abs(m - 99.0) < 3 * se
    assert se < 5.0
    assert steps.mean() < 60 < m - 3 * se


def test_slope_draws_do_not_depend_on_grouping():
    a = M.draw_slopes(5, 17, 100, 0.01, 0.002)
    b = M.draw_slopes(5, 17, 40, 0.01, 0.002)
    np.testing.assert_array_equal(a[:40], b)
    u = M.draw_slopes(5, 17, 20000, 0.0, 0.002, "uniform")
    assert abs(u.std() - 0.002) < 5e-5 and np.all(np.abs(u) <= math.sqrt(3) * 0.002)


def test_no_noise_no_fall_and_unstable_gait_falls(paper_scene, paper_map):
    """sigma -> 0: walks on the stable long-period gait (|lambda| 0.586) never fall (MFPT
    infinite); from the unstable short-period gait (|lambda| 2.44) the same noise makes
    walks fall within a few steps (those that do not fall drift to the stable gait)."""
    from walkerlab.analysis.gait.scene import solve_scene

    _, search = solve_scene(paper_scene, fd_check=False, plant=Plant.from_scene(paper_scene))
    gaits = {g.label: g.result for g in search.gaits}
    stable, unstable = gaits["long_period"], gaits["short_period"]
    assert np.max(np.abs(unstable.multipliers_variational)) > 1 > \
        np.max(np.abs(stable.multipliers_variational))
    r = M.monte_carlo(paper_map, stable.x, 1e-6, range(20), 40, seed=1)
    assert not r.fell.any() and r.mfpt[0] == math.inf
    r = M.monte_carlo(paper_map, unstable.x, 1e-6, range(20), 40, seed=1)
    assert r.fell.sum() >= 5
    assert np.median(r.steps[r.fell]) < 20


def _ar1_chain(a, sd, c, walks, steps, seed, distribution="normal"):
    """An AR(1) map x' = a x + gamma (gamma ~ N(0, sd^2), or uniform with standard deviation
    sd), falling when |x'| > c, carried as the 2-D state (x, x / 2) (a linear constraint,
    like a locked knee's, that the mesh's metric must drop).  Returns the evaluator of the
    map, the states visited by ``walks`` walks of ``steps`` steps from 0, and the Monte
    Carlo MFPT of those walks."""
    rng = np.random.default_rng(seed)
    x, alive, n = np.zeros(walks), np.ones(walks, bool), np.zeros(walks, int)
    seen = []
    for _ in range(steps):
        z = (rng.uniform(-math.sqrt(3), math.sqrt(3), walks) if distribution == "uniform"
             else rng.standard_normal(walks))
        x = a * x + sd * z
        ok = alive & (np.abs(x) <= c)
        n += ok
        alive = ok
        seen.append(x[alive])
    v = np.concatenate(seen)

    def evaluate(X, gamma):
        y = a * X[:, 0] + gamma
        return np.stack([y, 0.5 * y], 1), np.abs(y) <= c
    return evaluate, np.stack([v, 0.5 * v], 1), M.geometric_mle(int(n.sum()),
                                                               int((~alive).sum()))


def test_mesh_converges_to_monte_carlo_on_a_known_chain():
    """AR(1) with a = 0.6 and the boundary at 2.6 stationary sd's (MFPT ~ 100 steps), a
    chain with no walker in it: the mesh machinery (visited-state nodes thinned by voxels,
    whitened metric, Gauss-Hermite transitions to the nearest node, sparse solve) refines
    until the MFPT changes < 5 %, and agrees with 40,000 independent Monte Carlo walks
    within 2 standard errors + that 5 %.  The coarsest mesh is off by more than 5 % (the
    check can fail), and the quasi-stationary MFPT 1/(1 - lambda_2) - 1 is close to the
    MFPT from the start (a chain that forgets its start quickly)."""
    import types

    a, sd = 0.6, 1.0
    c = 2.6 * sd / math.sqrt(1 - a * a)
    evaluate, seen, (m, se) = _ar1_chain(a, sd, c, 40000, 400, 0)
    fake = types.SimpleNamespace(slope_rad=0.0)
    last, meshes = M.mesh_mfpt_converged(fake, seen[::400], np.zeros(2), sd, cells=5,
                                         max_cells=2000, quadrature=41, evaluate=evaluate)
    assert last.converged and last.change < 0.05
    assert abs(last.mfpt_steps - m) < 2 * se + 0.05 * last.mfpt_steps
    assert abs(meshes[0].mfpt_steps - m) > 0.05 * m
    assert abs(last.mfpt_quasi_stationary_steps - last.mfpt_steps) < 0.05 * m


def test_uniform_slope_quadrature_mesh_agrees_with_monte_carlo():
    """Uniform per-step noise (support -/+ sqrt(3) sd): Gauss-Legendre nodes on the support
    integrate polynomials exactly (the 2nd and 4th moments 1 and 9/5 sd^4 to 1e-12), and the
    converged mesh of the AR(1) chain (a = 0.6, boundary at 2.2 stationary sd's) agrees
    with 40,000 Monte Carlo walks with uniform noise within 2 standard errors + the 5 %
    refinement change.  The normal quadrature (Gauss-Hermite) on the same chain is off by
    more than that (the uniform's bounded support makes falls rarer here), so the check
    sees which distribution the mesh integrates."""
    import types

    g, w = M.slope_quadrature(21, 0.0, 1.0, "uniform")
    assert abs(w.sum() - 1) < 1e-13 and np.all(np.abs(g) < math.sqrt(3))
    assert abs(w @ g**2 - 1) < 1e-12 and abs(w @ g**4 - 9 / 5) < 1e-12
    with pytest.raises(ValueError, match="normal or uniform"):
        M.slope_quadrature(5, 0.0, 1.0, "lognormal")
    a, sd = 0.6, 1.0
    c = 2.2 * sd / math.sqrt(1 - a * a)
    evaluate, seen, (m, se) = _ar1_chain(a, sd, c, 40000, 400, 0, "uniform")
    fake = types.SimpleNamespace(slope_rad=0.0)
    kw = dict(cells=20, max_cells=2000, quadrature=41, evaluate=evaluate)
    last, _ = M.mesh_mfpt_converged(fake, seen[::200], np.zeros(2), sd,
                                    distribution="uniform", **kw)
    assert last.converged
    assert abs(last.mfpt_steps - m) < 2 * se + 0.05 * last.mfpt_steps, (last.mfpt_steps, m)
    normal, _ = M.mesh_mfpt_converged(fake, seen[::200], np.zeros(2), sd, **kw)
    assert abs(normal.mfpt_steps - m) > 2 * se + 0.05 * normal.mfpt_steps, (normal, m)


def test_voxel_rows_packed_as_one_key_equal_numpy_unique_rows():
    """``first_of_each_row`` (rows packed into one int64 key, 1-D stable unique) gives the
    indices of ``np.unique(V, axis=0, return_index=True)`` exactly, in its order: small and
    negative voxel indices in 4 and 7 columns, repeats, one row, and ranges too wide for 62
    bits (the ``axis=0`` fallback)."""
    rng = np.random.default_rng(3)
    cases = [rng.integers(-4, 4, (3000, 4)), rng.integers(-50, 3, (2000, 7)),
             np.zeros((5, 3), np.int64), rng.integers(0, 9, (1, 4)),
             rng.integers(-2**40, 2**40, (400, 3))]
    for V in cases:
        np.testing.assert_array_equal(M.first_of_each_row(V),
                                      np.unique(V, axis=0, return_index=True)[1])


def test_visited_states_of_all_sigmas_stepped_together_equal_one_sigma_at_a_time(
        paper_map, paper_fixed_point):
    """The walks of every sigma step in one batch; each sigma's states are those of its own
    walks stepped alone (its own random stream ``[seed, 24, i]``; a row's step does not
    depend on its batch), in the same order: the pool of (sd, 1.5 sd) is bit for bit the
    one of sigmas walked one after the other (the shuffle of ``[seed, 25]`` after)."""
    x0, sd, walks, steps, seed = paper_fixed_point.x, 0.004, 6, 5, 2
    pts = []
    for i, s in enumerate((sd, 1.5 * sd)):
        rng = np.random.default_rng([seed, 24, i])
        X = np.tile(x0, (walks, 1))
        for k in range(steps):
            r = paper_map.step(X, paper_map.slope_rad + s * rng.standard_normal(walks))
            ok = r.outcome == HEEL_STRIKE
            if k >= 1:
                pts.append(r.x_next[ok])
            X = np.where(ok[:, None], r.x_next, x0)
    P = np.concatenate(pts)
    ref = P[np.random.default_rng([seed, 25]).permutation(len(P))]
    got = M.visited_states(paper_map, x0, (sd, 1.5 * sd), walks, steps, seed=seed)
    np.testing.assert_array_equal(got, ref)


@pytest.mark.slow
def test_mesh_agrees_with_monte_carlo_on_the_paper_walker(paper_fixed_point, paper_map):
    """The paper walker at sigma = 0.004 rad (MFPT ~ 32 steps: 4,000 walks give 32.4 +- 0.5):
    one small mesh of visited states (600 nodes, 15 slope nodes) agrees with 300 seeded
    Monte Carlo walks (standard error ~ 1.9 steps) within 2 standard errors + 20 %, the
    bias allowed a mesh this coarse (the stage's meshes of 2,000 / 4,000 / 8,000 nodes give
    29.3 / 32.6 / 33.3).  The mesh that counted leaving a sigma-scaled box as a fall gave
    ~10 steps here and fails by far; the probability of landing off the mesh stays below
    1 % per step."""
    sd, x0 = 0.004, paper_fixed_point.x
    pool = M.visited_states(paper_map, x0, (sd, 1.5 * sd), 40, 25, seed=0)
    last, _ = M.mesh_mfpt_converged(paper_map, pool, x0, sd, cells=600, max_cells=600,
                                    quadrature=15)
    mc = M.monte_carlo(paper_map, x0, sd, range(300), 400, seed=5)
    m, se = mc.mfpt
    assert last.escaped < 0.01
    assert abs(last.mfpt_steps - m) < 2 * se + 0.2 * last.mfpt_steps, (last.mfpt_steps, m, se)


def test_terrain_per_step_validates_and_keeps_old_hashes(tmp_path):
    """A shipped scene's terrain serialises exactly as before (no per_step key: content
    hashes unchanged); per_step validates with units in its names."""
    sc = load_scene(ROOT / "configs" / "paper.yaml")
    assert "per_step" not in sc.section_json("terrain")
    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    d["terrain"]["per_step"] = {"slope_sd_rad": 0.003, "seed": 4}
    p = tmp_path / "rough.yaml"
    p.write_text(yaml.safe_dump(d))
    s2 = load_scene(p)
    assert s2.terrain.per_step.slope_sd_rad == 0.003
    d["terrain"]["per_step"] = {"slope_sd": 0.003}
    p.write_text(yaml.safe_dump(d))
    with pytest.raises(Exception, match="slope_sd"):
        load_scene(p)


@pytest.mark.slow
def test_mfpt_stage_artifact_and_figure(tmp_path):
    """walkerlab mfpt (Monte Carlo, one sigma, a few walks) writes mfpt.h5 with the schema's
    coordinate and variables, read back by its loader, and the figure."""
    from walkerlab.io.schemas.mfpt import VARIABLES, load
    from walkerlab.stages import mfpt as stage
    from walkerlab.stages import pipeline

    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    for k in ("contact", "terrain", "contact_sim", "contact_solver", "workprecision",
              "simulate"):
        d.pop(k, None)
    d["mfpt"] = {"walks": 30, "max_steps": 60, "method": "montecarlo"}
    p = tmp_path / "paper_mfpt.yaml"
    p.write_text(yaml.safe_dump(d))
    sc = load_scene(p)
    out = pipeline.run("mfpt", sc, tmp_path / "runs", sigma_rad=[0.008], workers=1)
    data = load(out.path)
    assert list(data.sigma_rad) == [0.008]
    assert set(VARIABLES) <= set(data.values)
    m = data["mfpt_steps_montecarlo"][0]
    assert 0 <= m < 60 and data["montecarlo_falls"][0] > 0
    assert np.isnan(data["mfpt_steps_mesh"][0])
    assert stage.figure_path(sc, tmp_path / "runs").is_file()
    assert not out.path.with_name("mfpt.h5.partial").exists()  # the resume file is gone
    again = pipeline.run("mfpt", sc, tmp_path / "runs", sigma_rad=[0.008], workers=1)
    assert again.reused


def test_step_down_guard_agrees_with_heel_strike_guard(paper_map, paper_fixed_point):
    """The step-down guard (swing-foot clearance reaching -drop, armed once the foot has
    risen) with a 1 nm drop lands where the heel-strike guard does (the two guards share
    their zero set; 1 nm moves the state by ~1e-8); a 10 mm step-down lands the foot 10 mm
    below the slope line through the stance foot."""
    X = np.tile(paper_fixed_point.x, (2, 1))
    a = paper_map.step(X)
    b = paper_map.step(X, drop_m=np.array([1e-9, 0.01]))
    np.testing.assert_allclose(b.x_next[0], a.x_next[0], rtol=0, atol=1e-7)
    assert np.max(np.abs(b.x_next[0] - a.x_next[0])) > 0  # the clearance guard was used
    foot = paper_map.walker.points(b.x_pre[1])["swing_foot"]
    below = -(foot[1] + foot[0] * math.tan(paper_map.slope_rad))
    assert abs(below - 0.01) < 1e-4  # vertical drop; clearance ~ perpendicular (cos 1 deg)


@pytest.mark.slow
@pytest.mark.parametrize("disturbance", ["slope", "floor_height"])
def test_gait_sensitivity_norm_linear_equals_nonlinear(paper_scene, paper_fixed_point,
                                                       disturbance):
    """Hobbelen & Wisse's GSN from the linearised step-to-step map (A from the variational
    equations) equals the nonlinear map's response to a 1e-5 impulse to 1e-3 relative
    (measured ~1e-6: central differences with steps 1e-6, impulse response O(e^2))."""
    from walkerlab.analysis.robustness import measures as R

    sm = BatchStepMap(build_walker(plant := Plant.from_scene(paper_scene)),
                        scene_walker_at(paper_scene, plant), 1e-12, 1e-12)
    lin = R.linearise(sm, paper_fixed_point.x, paper_fixed_point.jacobian_variational,
                      disturbance)
    g_lin = lin.gsn()
    g_nl = R.gsn_nonlinear(sm, paper_fixed_point.x, disturbance, 1e-5, steps=60)
    assert g_lin > 1.0
    assert abs(g_lin - g_nl) / g_lin < 1e-3


def test_state_norm_depends_on_coordinates_multipliers_do_not(paper_fixed_point, paper_scene):
    """Jin et al. 2021: the multipliers are the same in absolute and relative angles
    (similar Jacobians, to 1e-12), a state-indicator norm is not (differs by > 0.1 %)."""
    from walkerlab.analysis.robustness import measures as R

    A = paper_fixed_point.jacobian_variational
    names = build_walker(Plant.from_scene(paper_scene)).state_names()
    T = R.relative_coordinates(names)
    ev = np.sort(np.abs(np.linalg.eigvals(A)))
    evT = np.sort(np.abs(np.linalg.eigvals(T @ A @ np.linalg.inv(T))))
    np.testing.assert_allclose(ev, evT, rtol=0, atol=1e-12)
    lin = R.Linearisation(A, np.array([-0.96, -1.04, -1.19, -2.43]), np.zeros((3, 4)),
                          np.zeros(3))
    a, b = R.state_gsn(lin), R.state_gsn(lin, T)
    assert abs(a - b) / a > 1e-3


def test_largest_step_down_and_up_of_the_paper_walker(paper_map, paper_fixed_point):
    """The paper walker survives a single step-down of a few millimetres only (measured 5 mm
    down, 3 mm up on a 1 mm grid): survival is monotone on the grid (every value below the
    answer survives 40 steps, the next one falls), and the answer is between 1 and 20 mm."""
    from walkerlab.analysis.robustness import measures as R

    for sign in (1.0, -1.0):
        h = R.largest_tolerable(paper_map, paper_fixed_point.x, "floor_height", 0.02, 0.001,
                                sign=sign)
        assert 0.001 <= h < 0.02


def test_the_mfpt_lines_give_the_standard_error_and_the_falls_and_no_mesh_nan(tmp_path,
                                                                             monkeypatch):
    """Issue 56 item 16: the terminal printed "MFPT Monte Carlo 1234, mesh nan steps" for a
    Monte-Carlo-only study, without the standard error or the number of walks that fell."""

    from walkerlab.io.schemas.mfpt import VARIABLES, MfptData
    from walkerlab.stages import common, pipeline
    from walkerlab.studies.mfpt import mfpt_summary

    vals = {k: np.array([np.nan, np.nan]) for k in VARIABLES}
    vals.update(mfpt_steps_montecarlo=np.array([1234.0, np.inf]),
                mfpt_steps_montecarlo_stderr=np.array([56.0, np.nan]),
                montecarlo_walks=np.array([100.0, 100.0]),
                montecarlo_falls=np.array([37.0, 0.0]))
    summary = mfpt_summary(MfptData(np.array([0.004, 0.001]), vals, "montecarlo",
                                    ["a", "b", "c", "d"], []))
    out = common.StageOutcome("mfpt", tmp_path / "mfpt.h5", False, 1.0, summary)
    monkeypatch.setattr(pipeline, "run", lambda *a, **k: out)
    r = CliRunner().invoke(app, ["mfpt", str(ROOT / "configs" / "paper.yaml"), "--runs-dir",
                                 str(tmp_path / "runs")])
    lines = [ln for ln in r.stdout.splitlines() if ln.startswith("sigma")]
    assert lines[0] == "sigma 0.004 rad: MFPT Monte Carlo 1234 ± 56 steps (37 of 100 walks fell)"
    assert lines[1].startswith("sigma 0.001 rad: MFPT Monte Carlo: none of 100 walks fell")
    assert not any("nan" in ln or "mesh" in ln for ln in lines), lines


def test_mfpt_says_it_does_not_use_the_scenes_per_step_slope_spread(tmp_path, monkeypatch):
    """Issue 56 item 16: ``mfpt`` swept mfpt.sigma_rad and silently ignored the scene's
    terrain.per_step.slope_sd_rad; it now says so in one line (and nothing without it)."""
    from walkerlab import progress
    from walkerlab.config import scene_from_dict
    from walkerlab.stages import common
    from walkerlab.stages import mfpt as stage

    notes = []
    monkeypatch.setattr(progress, "note", notes.append)
    monkeypatch.setattr(stage, "run_cached", lambda *a, **k: common.StageOutcome(
        "mfpt", tmp_path / "mfpt.h5", True, 0.0, {}))
    monkeypatch.setattr(stage, "draw", lambda *a, **k: [])
    data = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    stage.run(scene_from_dict(data, "p.yaml"), tmp_path, sigma_rad=[0.002, 0.004])
    assert notes == []
    data["terrain"] = {**data.get("terrain", {}), "per_step": {"slope_sd_rad": 0.003}}
    stage.run(scene_from_dict(data, "p.yaml"), tmp_path, sigma_rad=[0.002, 0.004])
    assert len(notes) == 1 and "terrain.per_step.slope_sd_rad (0.003 rad) is not used" in \
        notes[0] and "mfpt.sigma_rad (--sigma-rad) 0.002, 0.004 rad" in notes[0], notes


# -------------------- an unconverged mesh


def _scene(tmp_path: Path, name: str = "paper", **sections) -> Path:
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump({**IDEAL, **sections}))
    return path


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


@pytest.fixture(scope="module")
def hip_roll_walk():
    """The stabilised 3D walker with hip width (configs/hip_width_stabilised.yaml: steps on
    alternate sides, largest multiplier 0.546), its step map for per-step slopes and its
    initial guess (the gait to 6 decimals: post-impact, step 0 with leg1 swinging)."""
    from walkerlab.integrate.python_step import make_step_map

    scene = load_scene(ROOT / "configs" / "hip_width_stabilised.yaml")
    walker = build_walker(Plant.from_scene(scene))
    g = scene.fixedpoint.initial_guess.model_extra
    x0 = np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                   for n in walker.state_names()])
    return scene, walker, make_step_map(walker, scene_walker_at(scene,
            plant=Plant.from_scene(scene)), 1e-12, 1e-12), x0


@pytest.mark.slow  # ~2 min on a cold numba cache (the hip-roll walker's batched flow)
@pytest.mark.xdist_group("hip_roll_walk")  # one worker compiles the map for both tests
def test_a_3d_monte_carlo_walk_matches_simulate_on_the_same_slopes(hip_roll_walk):
    """A 3D walker with hip width steps on alternate sides: the mirror step's walker has
    ``w_hip -> -w_hip``.  The per-step map walks it in reflected coordinates (``y_k = S^k
    x_k``, :class:`~walkerlab.integrate.python_step.ReflectedStepMap`); reflected back, its
    post-impact states equal the rigid integrator's walk of each step's own walker
    (``walker.for_step(k)`` on that step's slope, as ``simulate`` walks it; DOP853 at
    1e-12, both) to 1e-9 over 12 steps at sigma 0.002 rad.  The old map walked every step
    as the first step's walker: it fell at the second step."""
    from walkerlab.analysis.robustness.slope_stream import slope_rows
    from walkerlab.integrate.python_step import ReflectedStepMap

    scene, walker, sm, x0 = hip_roll_walk
    assert isinstance(sm, ReflectedStepMap)
    n = 12
    gam = slope_rows(3, [0], 0, n, scene.slope.phi_rad, 0.002)[0]
    at = scene_walker_at(scene, plant=Plant.from_scene(scene))
    y, x = x0.copy(), x0.copy()
    for k in range(n):
        r = sm.step(y[None], gam[k:k + 1])
        seg = integrate_step(at(float(gam[k])).for_step(k), x, TIGHT, max_step_time=5.0)
        assert r.outcome[0] == HEEL_STRIKE and seg.termination == "heel_strike", k
        y, x = r.x_next[0], seg.x_next
        x_from_y = walker.reflect(y) if k % 2 == 0 else y  # x_{k+1} = S^(k+1) y_{k+1}
        np.testing.assert_allclose(x_from_y, x, rtol=0, atol=1e-9)
        assert abs(r.step_time_s[0] - seg.period) < 1e-9


@pytest.mark.slow  # shares the compiled map of the test above
@pytest.mark.xdist_group("hip_roll_walk")
def test_a_stable_3d_walker_does_not_fall_at_a_vanishing_sigma(hip_roll_walk):
    """configs/hip_width_stabilised.yaml (largest multiplier 0.546) on slopes of sigma
    1e-9 rad: every Monte Carlo walk reaches the step cap (the issue's run: '10 of 10 walks
    fell', 2 steps each, all of them the mirrored second step)."""
    scene, walker, sm, x0 = hip_roll_walk
    res = M.monte_carlo(sm, x0, 1e-9, range(4), 40, 0)
    assert not res.fell.any() and (res.steps == 40).all()


def test_the_mirror_of_a_3d_step_is_its_reflection():
    """The 3D walker with hip width: its mirror is the reflection across the sagittal plane
    (lean and hip rolls negated, pitches kept); planar legs that differ have none."""
    scene = load_scene(ROOT / "configs" / "hip_width_stabilised.yaml")
    walker = build_walker(Plant.from_scene(scene))
    names = walker.state_names()
    assert set(walker.mirror_reflection) == {f"{r}_{k}" for r in ("lean", "pelvis_roll",
                                                                  "swing_roll")
                                             for k in ("angle", "rate")}
    x = np.arange(1.0, len(names) + 1)
    s = walker.reflect(x)
    for i, n in enumerate(names):
        assert s[i] == (-x[i] if ("lean" in n or "roll" in n) else x[i])
    sc = load_scene(ROOT / "configs" / "paper_3d.yaml")
    assert build_walker(Plant.from_scene(sc)).mirror is None


@pytest.mark.slow
def test_a_3d_walker_without_a_contact_periodic_gait_ends_contact_mfpt_in_one_line(tmp_path):
    """``mfpt.model: contact`` walks the compliant-contact walker from its own periodic
    gait; configs/paper_3d.yaml (zero hip width) has none the stride map reaches: its
    inertia about the stance foot's normal vanishes as the legs pass each other, and its
    contact run stalls at mid-stance. The study ends in one line naming the field before
    any walk, no study artifact written (the rigid gait's, upstream, is)."""
    from walkerlab.config import scene_from_dict
    from walkerlab.stages import pipeline
    from walkerlab.stages.common import StageError

    raw = yaml.safe_load((ROOT / "configs" / "paper_3d.yaml").read_text())
    raw["mfpt"] = {"model": "contact", "method": "montecarlo"}

    with pytest.raises(StageError, match=r"^mfpt\.model: contact: ") as exc:
        pipeline.run("mfpt", scene_from_dict(raw), tmp_path)
    assert "\n" not in str(exc.value)
    assert not list(tmp_path.rglob("mfpt*"))
