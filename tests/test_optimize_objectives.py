"""Objectives and constraints of the collocation (``optimize:``): Kuo's (2002) least push-off
against his closed form and the pendulum's own quadrature, the weighted sum and the cost of
transport as their definitions say, and each path constraint active where it binds (the
compass walker's passive gait breaks it; the optimum sits on it)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from walkerlab.codegen import legged
from walkerlab.config import load_scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.optimal.driver import collocation_spec
from walkerlab.optimal.guess import simulated_step
from walkerlab.optimal.transcription.mode_sequence import collocate_step
from walkerlab.optimal.transcription.step import CollocationSpec, replay, step_functions
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

pytest.importorskip("casadi")
CONFIGS = Path(__file__).resolve().parents[1] / "configs"


class _Case:
    """A scene's walker, its CasADi step functions and one step of its gait as the guess."""

    def __init__(self, name: str, period_s: float):
        """One step from the scene's ``fixedpoint.initial_guess`` if it has one (a guess,
        not the gait: the collocation finds its own; Kuo's fixed point with its Python
        torque law costs ~15 s), else from its gait; ``period_s`` [s] about the step's."""
        import walkerlab as wl
        from walkerlab.io.schemas.continuation import initial_state

        self.scene = load_scene(CONFIGS / f"{name}.yaml")
        walker = build_walker(Plant.from_scene(self.scene))
        guess = self.scene.fixedpoint.initial_guess
        self.x0 = (initial_state(guess, walker.state_names()) if guess is not None
                   else wl.Walker.from_scene(self.scene).fixed_point().x)
        self.period = period_s
        self.data = walker_data(self.scene.walker, self.scene.slope.phi_rad)
        self.eq = legged.derive_legged(self.data.structure)
        self.fns = step_functions(self.data, self.eq)
        self.t, self.x = simulated_step(walker, self.x0, period_s, Solver("DOP853", 1e-12,
                                                                           1e-12))

    def solve(self, spec):
        return collocate_step(self.data, self.eq, spec, self.t, self.x, fns=self.fns)

    def along(self, res, name):
        return np.array([np.asarray(self.fns[name](x)).ravel() for x in res.x])


@pytest.fixture(scope="module")
def kuo():
    case = _Case("kuo2002", 3.6)
    return case, case.solve(collocation_spec(case.scene))


@pytest.fixture(scope="module")
def compass():
    case = _Case("compass_optimal", 0.73)
    return case, case.solve(CollocationSpec(intervals=40))


def _pendulum_speed(alpha: float, period: float) -> float:
    """The stance leg's speed |dtheta| at heel strike of an inverted pendulum (theta'' =
    sin theta, g = l = 1) swinging symmetrically from -alpha to alpha in ``period``: energy
    conservation gives theta'^2 = v^2 + 2 (cos alpha - cos theta), slowest upright (it must
    pass: v > sqrt(2 (1 - cos alpha)))."""
    def time(v):
        return 2 * quad(lambda th: 1 / math.sqrt(v * v + 2 * (math.cos(alpha) - math.cos(th))),
                        0, alpha, epsabs=0.0, epsrel=1e-11)[0] - period
    lowest = math.sqrt(2 * (1 - math.cos(alpha)))
    return brentq(time, 1.2 * lowest, 10.0, xtol=1e-15, rtol=1e-15)  # 2.4 s .. 0.06 s


def test_kuo_least_push_off_is_his_closed_form(kuo):
    """configs/kuo2002.yaml's optimize section (speed 0.4, step length 0.55, level ground):
    the push-off equals P = v tan(alpha) with v from the pendulum's quadrature of the target
    step (independent of the collocation; Hermite-Simpson's O(h^4) error at 40 intervals:
    ~1e-10 relative, asserted 1e-8) and with v, alpha read from the optimum's own heel strike
    (exact to round-off), its work P^2 / 2 = v^2 tan^2(alpha) / 2 (M = 1); the replay closes."""
    case, res = kuo
    assert res.status == "Solve_Succeeded"
    alpha = math.asin(0.55 / 2)
    v = _pendulum_speed(alpha, 0.55 / 0.4)
    assert res.push_off_n_s == pytest.approx(v * math.tan(alpha), rel=1e-8)
    th, dth = res.x[-1][0], res.x[-1][2]  # stance angle and rate just before heel strike
    assert abs(th) == pytest.approx(alpha, rel=1e-12)
    assert res.push_off_n_s == pytest.approx(abs(dth) * math.tan(abs(th)), rel=1e-12)
    work = 0.5 * dth ** 2 * math.tan(th) ** 2
    assert res.terms["push_off_work"] == pytest.approx(work, rel=1e-12)
    assert replay(case.data, res)[0] <= 1e-6


def test_kuo_weighted_sum_and_cost_of_transport_as_defined(kuo):
    """The weighted objective is the sum of its weighted terms; the massless swing leg's
    torque does no work, so the cost of transport is the push-off's work per weight and
    step length, v^2 tan^2(alpha) / (2 g s), exactly (its positive work max(p, 0) at the
    points, no smoothing width: the smoothed form added eps / 2 over the step period,
    8 % of it here)."""
    _, res = kuo
    assert res.objective == pytest.approx(res.terms["push_off_work"]
                                          + 1e-4 * res.terms["effort"], rel=1e-14)
    th, dth = res.x[-1][0], res.x[-1][2]
    cot = 0.5 * dth ** 2 * math.tan(th) ** 2 / (1.0 * 0.55)
    assert res.terms["cost_of_transport"] == pytest.approx(cot, rel=1e-12)


def test_kuo_least_cost_of_transport_alone_is_the_closed_form(kuo):
    """objective: cost_of_transport alone (the push-off free, the targets of
    configs/kuo2002.yaml: 0.4 m/s, 0.55 m; the positive work by slack variables, the
    swing torque made unique by the default 1e-4 effort weight): IPOPT succeeds in < 60
    iterations (19 seen; the smoothed form stopped 8 % above the optimum, at the smoothing's
    bias) and the least cost of transport is Kuo's push-off work per weight and step
    length, v^2 tan^2(alpha) / (2 M g s), v from the pendulum's quadrature of the target
    step (collocation error ~1e-10 relative, slack complementarity ~1e-11 absolute:
    asserted 1e-8); the objective adds 1e-4 of the effort and nothing else."""
    case, _ = kuo
    spec = replace(collocation_spec(case.scene), objective="cost_of_transport", weights=())
    res = case.solve(spec)
    assert res.status == "Solve_Succeeded" and res.iterations < 60
    alpha = math.asin(0.55 / 2)
    v = _pendulum_speed(alpha, 0.55 / 0.4)
    assert res.push_off_n_s == pytest.approx(v * math.tan(alpha), rel=1e-8)
    closed = 0.5 * (v * math.tan(alpha)) ** 2 / (1.0 * 1.0 * 0.55)
    assert res.terms["cost_of_transport"] == pytest.approx(closed, rel=1e-8)
    assert res.objective == pytest.approx(res.terms["cost_of_transport"]
                                          + 1e-4 * res.terms["effort"], rel=1e-12)
    assert replay(case.data, res)[0] <= 1e-6


def test_cost_of_transport_alone_on_a_slope_is_a_passive_gait(compass):
    """The compass walker on its 0.0525 rad slope with a hip torque, objective
    cost_of_transport alone, started from its passive step with a 2 N m torque bump:
    IPOPT succeeds in < 100 iterations (46 seen; the smoothed form: 331 iterations to a
    gait with a 116 N m torque, and 500 without converging from zero torque) at the
    optimum 0 (the slack variables' complementarity leaves ~1e-11), at a passive gait: the
    torque vanishes to the effort weight's resolution (|u| ~ sqrt(tol / w): 5e-4 N m
    at w = 1e-4, asserted 1e-2, against ~30 N m of the level-ground optimum) and the step
    is the passive walker's own, found by shooting from it (`find_fixed_point`), to 1e-3 s
    (2e-4 s seen, the residual torque's effect).  CoT = 0 has two passive gaits at this
    slope (0.734 s and 0.582 s); either is an optimum."""
    from walkerlab.analysis.gait.poincare import find_fixed_point

    case, _ = compass
    bump = 2.0 * np.sin(np.pi * case.t / case.t[-1])
    res = collocate_step(case.data, case.eq, CollocationSpec(intervals=40,
                                                             objective="cost_of_transport"),
                         case.t, case.x, bump, case.fns)
    assert res.status == "Solve_Succeeded" and res.iterations < 100
    assert 0.0 <= res.terms["cost_of_transport"] <= 1e-10 and res.objective <= 1e-10
    assert np.max(np.abs(res.u)) < 1e-2
    passive = find_fixed_point(build_walker(Plant.from_scene(case.scene)), res.x[0],
                               Solver("DOP853", 1e-12, 1e-12))
    assert res.step_period_s == pytest.approx(passive.period_s, abs=1e-3)


def test_no_scuffing_bound_is_active(compass):
    """The passive gait's swing foot dips 3.6 mm below the slope (straight legs must touch
    it where they pass each other); allowed at most 2 mm, the optimum's deepest point is at
    the bound (1e-8 m: IPOPT's bound push) and it costs effort."""
    case, passive = compass
    assert case.along(passive, "clearance")[1:-1].min() < -0.003
    res = case.solve(CollocationSpec(intervals=40, min_clearance_m=-0.002))
    assert res.status == "Solve_Succeeded"
    assert case.along(res, "clearance")[1:-1].min() == pytest.approx(-0.002, abs=1e-7)
    assert res.objective > 1e-3


def test_friction_cone_is_active(compass):
    """The passive gait needs a friction coefficient of 0.274; with 0.2 the optimum's
    largest |F_t| / F_n is 0.2 (the cone's edge), its normal force positive throughout."""
    case, passive = compass
    F0 = np.array([np.asarray(case.fns["grf"](x, u)).ravel() for x, u in zip(passive.x,
                                                                               passive.u)])
    assert np.max(np.abs(F0[:, 1] / F0[:, 0])) > 0.27
    res = case.solve(CollocationSpec(intervals=40, friction_coefficient=0.2))
    assert res.status == "Solve_Succeeded"
    F = np.array([np.asarray(case.fns["grf"](x, u)).ravel() for x, u in zip(res.x, res.u)])
    assert np.all(F[:, 0] > 0)
    assert np.max(np.abs(F[:, 1] / F[:, 0])) == pytest.approx(0.2, abs=1e-8)


def test_ground_reaction_balances_the_weight_at_rest():
    """The ground reaction is m_total (a_com + g): a compass walker standing still and
    upright on level ground carries its weight, 20 kg * 9.81 N along the normal, none
    along the slope."""
    import walkerlab as wl

    d = load_scene(CONFIGS / "compass_optimal.yaml").model_dump(mode="json", exclude_none=True)
    d["slope"] = {"angle_rad": 0.0}
    scene = wl.Walker.from_scene(d).scene
    data = walker_data(scene.walker, 0.0)
    fns = step_functions(data, legged.derive_legged(data.structure))
    F = np.asarray(fns["grf"](np.zeros(4), 0.0)).ravel()
    np.testing.assert_allclose(F, [20.0 * 9.81, 0.0], atol=1e-12)


def test_hip_limit_and_peak_torque_epigraph(compass):
    """The hip's range [-0.6, 0.5] rad (the passive gait opens to 0.55) binds at the step's
    end; the least peak torque within it (epigraph: -s <= u <= s, minimise s) has
    max |u| = s and is below the least-effort gait's peak there."""
    case, passive = compass
    assert case.along(passive, "hip_angle").max() > 0.55
    lim = CollocationSpec(intervals=40, hip_angle_range_rad=(-0.6, 0.5))
    effort = case.solve(lim)
    assert effort.status == "Solve_Succeeded"
    assert case.along(effort, "hip_angle").max() == pytest.approx(0.5, abs=1e-7)
    peak = case.solve(replace(lim, objective="peak_torque"))
    assert peak.status == "Solve_Succeeded"
    assert np.max(np.abs(peak.u)) == pytest.approx(peak.objective, rel=1e-8)
    assert peak.objective < np.max(np.abs(effort.u)) - 0.1
    assert case.along(peak, "hip_angle").max() <= 0.5 + 1e-7


def test_a_guess_from_another_optimisation(kuo, tmp_path):
    """optimize.initial_guess from another optimize.h5: its states, torque, period and
    push-off start the collocation, which then needs fewer iterations than from the
    passive gait and ends at the same push-off."""
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.schemas import optimize as schema
    from walkerlab.optimal.guess import starting_step

    case, res = kuo
    names = list(build_walker(Plant.from_scene(case.scene)).state_names())
    d = schema.OptimizeData(res.t, {n: res.x[:, k] for k, n in enumerate(names)}, res.u,
                            res.step_period_s, res.step_length_m, res.push_off_n_s,
                            res.objective, 0.0, np.zeros(4, complex), True, res.status,
                            res.iterations, 0.0, {n: "rad" for n in names})
    path = tmp_path / "optimize.h5"
    write_artifact(path, schema.STAGE, case.scene, "x", lambda f: schema.write(f, d), 0.0)
    dd = case.scene.model_dump(mode="json", exclude_none=True)
    dd["optimize"]["initial_guess"] = {"from": str(path)}
    scene = load_scene(CONFIGS / "kuo2002.yaml").model_validate(dd)
    t, x, u, p = starting_step(scene, build_walker(Plant.from_scene(scene)), case.x0, case.period)
    np.testing.assert_array_equal(x, res.x)
    again = collocate_step(case.data, case.eq, replace(collocation_spec(scene),
                                                       push_off_n_s=p), t, x, u, case.fns)
    assert again.status == "Solve_Succeeded" and again.iterations < res.iterations
    assert again.push_off_n_s == pytest.approx(res.push_off_n_s, rel=1e-12)


def test_bad_optimize_sections_say_which_field(tmp_path):
    """Weights without a weighted objective, an empty hip range, a guess from a missing
    file or from another stage's artifact: one line naming the field."""
    from walkerlab.config.errors import SceneError
    from walkerlab.optimal.guess import starting_step

    base = load_scene(CONFIGS / "compass_optimal.yaml").model_dump(mode="json",
                                                                    exclude_none=True)
    for bad, field in (({"weights": {"effort": 1.0}}, "optimize.weights"),
                       ({"objective": "weighted"}, "optimize.weights"),
                       ({"hip_angle_range_rad": [0.5, 0.1]},
                        r"hip_angle_range_rad: \[lo, hi\] with lo < hi")):
        d = {**base, "optimize": {**base["optimize"], **bad}}
        with pytest.raises((SceneError, ValueError), match=field):
            type(load_scene(CONFIGS / "compass_optimal.yaml")).model_validate(d)
    # a YAML list is the hip range's form (as basin.x_range): the limits reach the spec
    d = {**base, "optimize": {**base["optimize"], "hip_angle_range_rad": [-0.5, 0.5]}}
    ok = type(load_scene(CONFIGS / "compass_optimal.yaml")).model_validate(d)
    assert ok.optimize.hip_angle_range_rad == (-0.5, 0.5)
    from walkerlab.optimal.driver import collocation_spec

    assert collocation_spec(ok).hip_angle_range_rad == (-0.5, 0.5)
    scene = load_scene(CONFIGS / "compass_optimal.yaml")
    for path, msg in ((tmp_path / "none.h5", "not found"),):
        d = {**base, "optimize": {**base["optimize"], "initial_guess": {"from": str(path)}}}
        sc = type(scene).model_validate(d)
        with pytest.raises(ValueError, match="optimize.initial_guess: .*" + msg):
            starting_step(sc, build_walker(Plant.from_scene(sc)), np.zeros(4), 0.7)


def test_a_guess_from_a_continuation_branch(compass, tmp_path):
    """optimize.initial_guess from a continuation artifact (a branch over the slope with
    the gaits at 0.05 and 0.055 rad) at the scene's 0.0525: the branch's state there
    (linear between its points) starts one simulated step, and the collocation ends at the
    scene's passive gait all the same."""
    import walkerlab as wl
    from walkerlab.io.artifacts import put, write_artifact
    from walkerlab.io.schemas.continuation import STAGE
    from walkerlab.optimal.guess import starting_step

    case, passive = compass
    names = list(build_walker(Plant.from_scene(case.scene)).state_names())
    slopes = [0.05, 0.055]
    gaits = [wl.Walker.from_scene(case.scene).with_changes({"slope.angle_rad": s}
                                                           ).fixed_point() for s in slopes]
    X = np.array([g.x for g in gaits])

    def writer(f):
        f.attrs.update(parameter_path="slope.angle_rad", parameter_unit="rad",
                       state_names=names, parameter_start=0.0525)
        g = f.create_group("branches/0")
        g.attrs["branch_period"] = 1
        put(g, "param", np.array(slopes), "rad")
        for k, n in enumerate(names):
            put(g, f"state/{n}", X[:, k], "rad")
            put(g, f"orbit/{n}", X[:, k:k + 1], "rad")
        put(g, "period", np.array([g_.step_period for g_ in gaits]), "s")
        put(g, "multipliers/real", np.zeros((2, 4)), "-")
        put(g, "multipliers/imag", np.zeros((2, 4)), "-")
        put(g, "stable", np.ones(2, int), "-")
        s = f.create_group("special_points")
        for k in ("kind", "cause"):
            put(s, k, np.zeros(0, "S1"), "-")
        for k in ("param", "period", "branch"):
            put(s, k, np.zeros(0), "-")
        for n in names:
            put(s, f"state/{n}", np.zeros(0), "rad")
        put(s, "multipliers/real", np.zeros((0, 4)), "-")
        put(s, "multipliers/imag", np.zeros((0, 4)), "-")

    path = tmp_path / "continuation_slope.h5"
    write_artifact(path, STAGE, case.scene, "x", writer, 0.0)
    d = case.scene.model_dump(mode="json", exclude_none=True)
    d["optimize"]["initial_guess"] = {"from": str(path), "at": 0.0525}
    scene = type(case.scene).model_validate(d)
    t, x, u, p = starting_step(scene, build_walker(Plant.from_scene(scene)), np.zeros(4), 0.73)
    np.testing.assert_allclose(x[0], X.mean(axis=0), rtol=0, atol=1e-14)
    assert u is None and p is None
    res = collocate_step(case.data, case.eq, CollocationSpec(intervals=40), t, x, fns=case.fns)
    assert res.status == "Solve_Succeeded" and res.objective <= 1e-10
    assert res.step_period_s == pytest.approx(passive.step_period_s, abs=1e-9)


def test_step_functions_cached_on_disk_are_the_same_graph(tmp_path, monkeypatch):
    """The straight-leg collocation's CasADi functions are built once per walker and read
    back from the code cache (no symbolic derivation on a warm start: the build is not
    called), and the functions read back compute bit for bit what the built ones do; a
    damaged file is rebuilt."""
    import walkerlab.optimal.transcription.step as collocation
    from walkerlab.codegen import casadi_functions
    from walkerlab.optimal.transcription import step_cache

    monkeypatch.setenv("WALKERLAB_CACHE_DIR", str(tmp_path))
    scene = load_scene(CONFIGS / "compass_optimal.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    monkeypatch.setattr(casadi_functions, "_memo", {})
    built = step_cache.cached_step_functions(data)
    files = list((tmp_path / "models").glob("*-steps-*.casadi"))
    assert len(files) == 1
    monkeypatch.setattr(casadi_functions, "_memo", {})

    def no_build(*_a, **_k):
        raise AssertionError("derived again")

    build = collocation.step_functions
    monkeypatch.setattr(collocation, "step_functions", no_build)
    read = step_cache.cached_step_functions(data)
    x = np.array([0.31, -0.22, -1.1, 0.4])
    for name, args in (("flow", (x, 0.7)), ("reset", (x, 0.3)), ("grf", (x, 0.7)),
                       ("guard_rate", (x, 0.7)), ("push_off_work", (x, 0.3))):
        np.testing.assert_array_equal(np.asarray(read[name](*args)),
                                      np.asarray(built[name](*args)))
    assert read["n"] == 2 and read["total_mass_kg"] == built["total_mass_kg"]
    files[0].write_text("damaged")
    monkeypatch.setattr(casadi_functions, "_memo", {})
    monkeypatch.setattr(collocation, "step_functions", build)
    again = step_cache.cached_step_functions(data)
    np.testing.assert_array_equal(np.asarray(again["flow"](x, 0.7)),
                                  np.asarray(built["flow"](x, 0.7)))


def test_cost_of_transport_at_a_target_speed_is_a_gait_with_the_defaults(compass):
    """The compass walker at 0.6 m/s, objective cost_of_transport with the section's
    defaults (40 intervals): a braking gait (CoT ~0: the torque does no positive work at
    the points) whose torque stays a few N m and whose replay closes (<= 1e-6; 2.7e-7
    seen, 17 N m).  With the former defaults (effort weight 1e-6, IPOPT's initial barrier
    0.1) IPOPT ended at 180 N m chattering between the points and a replay error of 1.7e-3;
    with the weight 1e-6 and the small barrier 149 N m and 1.6e-4."""
    from walkerlab.config.optimize import OptimizeSettings

    case, _ = compass
    weight = OptimizeSettings.model_fields["cost_of_transport_effort_weight"].default
    assert CollocationSpec.cost_of_transport_effort_weight == weight
    res = case.solve(CollocationSpec(intervals=40, objective="cost_of_transport",
                                     target_speed_m_per_s=0.6))
    assert res.status == "Solve_Succeeded"
    assert res.step_length_m / res.step_period_s == pytest.approx(0.6, rel=1e-9)
    assert res.terms["cost_of_transport"] <= 1e-8
    assert np.max(np.abs(res.u)) < 40.0
    assert replay(case.data, res)[0] <= 1e-6
