"""One stability verdict: the Floquet multipliers of the variational equations (with the
reset's Jacobian by the complex step) agree with central differences of the Poincaré map for
every shipped scene and powered variants of them, and with an independent model of Kuo's
(2002) powered simplest walker (``tests/independent/kuo_simplest.py``: Garcia et al. 1998's
equations, Kuo's transition, its own integrator and root finder); a disagreement in a run is
an error (:class:`walkerlab.analysis.gait.poincare.MultipliersDisagree`), not a footnote.

Tolerances: central differences of a map integrated at rtol = atol = 1e-12 with a step of
1e-7 carry an error of ~1e-12/1e-7 = 1e-5 at worst (observed 1e-9 to 1e-6), so the variational
and the difference multipliers must agree to 1e-5; the reset Jacobian, which involves no
integration, to 1e-8 (central differences of step 1e-6 on the closed form: ~1e-10).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import walkerlab as wl
from tests.independent import kuo_simplest as kuo_ref
from walkerlab.analysis.gait import poincare
from walkerlab.analysis.gait.scene import solve_scene
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
GUESS_FIELDS = ("stance_angle_rad", "hip_angle_rad", "stance_rate_rad_per_s",
                "hip_rate_rad_per_s")


def _kuo(k: float, P: float, slope: float, guess) -> wl.Walker:
    changes = {"walker.actuation.push_off.impulse_n_s": P,
               "walker.actuation.torques.0.law.stiffness_n_m_per_rad": k,
               "slope.angle_rad": slope}
    changes.update({f"fixedpoint.initial_guess.{n}": float(v)
                    for n, v in zip(GUESS_FIELDS, guess)})
    return wl.Walker.from_scene(CONFIGS / "kuo2002.yaml").with_changes(changes)


@pytest.mark.parametrize("P", [0.0, 0.0427445, 0.1])
def test_kuo_reset_jacobian_equals_the_closed_form_on_the_guard(P):
    """The massless-leg push-off + heel strike: its Jacobian (the complex step the variational
    equations use) along the heel-strike surface ``phi = 2 theta`` equals the derivative of
    Kuo's closed form (central differences of the independent transition).  On the code
    before this test the position column was (0.058, 0.020) against (0, -0.03)."""
    w = _kuo(0.08, P, 0.0, (0.2, 0.4, -0.21, -0.017)).model
    rng = np.random.default_rng(4)
    for _ in range(5):
        th = -rng.uniform(0.1, 0.3)  # pre-impact: the swing foot ahead, theta < 0
        x = np.array([th, 2 * th, -rng.uniform(0.1, 0.5), rng.uniform(-0.5, 0.5)])
        np.testing.assert_allclose(w.reset(x), kuo_ref.transition(x, P), rtol=0, atol=1e-12)
        J = w.reset_jacobian(x)
        h = 1e-6
        for t in (np.array([1.0, 2.0, 0, 0]), np.eye(4)[2], np.eye(4)[3]):  # guard tangents
            want = (kuo_ref.transition(x + h * t, P) - kuo_ref.transition(x - h * t, P)) / (2 * h)
            np.testing.assert_allclose(J @ t, want, rtol=0, atol=1e-8)


def test_kuo2002_is_stable_and_matches_the_independent_model():
    """The shipped scene (k = 0.08, P = 0.0427445, level): stable, |lambda| 0.695 (it was
    called UNSTABLE, 1.330485, from a wrong reset Jacobian)."""
    x, T, mult = kuo_ref.fixed_point(0.08, 0.0427445)
    gait = wl.Walker.from_scene(CONFIGS / "kuo2002.yaml").fixed_point()
    np.testing.assert_allclose(gait.x, x, rtol=0, atol=1e-8)
    assert abs(gait.step_period - T) < 1e-8
    np.testing.assert_allclose(gait.multipliers, mult, rtol=0, atol=1e-6)
    assert gait.stable and abs(np.max(np.abs(gait.multipliers)) - 0.695231) < 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("k, P, slope", [(0.05, 0.03, 0.0), (0.15, 0.06, 0.0),
                                         (0.08, 0.02, 0.002)])
def test_kuo_walker_multipliers_at_other_gaits(k, P, slope):
    x, T, mult = kuo_ref.fixed_point(k, P, slope)
    gait = _kuo(k, P, slope, x).fixed_point()
    np.testing.assert_allclose(gait.x, x, rtol=0, atol=1e-8)
    assert abs(gait.step_period - T) < 1e-8
    np.testing.assert_allclose(gait.multipliers, mult, rtol=0, atol=1e-6)


# the quick suite's CPU budget (README): a longer run, in `pytest -m slow`
@pytest.mark.slow
def test_target_and_fixedpoint_give_one_verdict():
    """``walkerlab target`` prints the multipliers of the gait it finds from the same
    computation as ``fixedpoint``: at the shipped scene's own speed the two agree."""
    w = wl.Walker.from_scene(CONFIGS / "kuo2002.yaml")
    gait = w.fixed_point()
    _, again = w.find_gait_for("walker.actuation.push_off.impulse_n_s",
                               step_period_s=gait.step_period)
    np.testing.assert_allclose(again.multipliers, gait.multipliers, rtol=0, atol=1e-7)
    assert again.stable == gait.stable is True


def test_a_disagreement_is_an_error():
    """A wrong reset Jacobian (as the massless-leg one was) stops the run with one line."""
    scene = load_scene(CONFIGS / "paper.yaml")
    w = build_walker(Plant.from_scene(scene))
    right = w.reset_jacobian
    wrong = replace(w, reset_jacobian=lambda x: right(x) + 0.05)
    from walkerlab.integrate.solver import Solver

    solver = Solver.from_settings(scene.solver)
    guess = w.from_section(w.section(np.array([-0.3238, 0.2187, -0.3777, -1.0924])))
    poincare.find_fixed_point(w, guess, solver)  # the right one agrees
    with pytest.raises(poincare.MultipliersDisagree, match="one Jacobian of the map is wrong"):
        poincare.find_fixed_point(wrong, guess, solver)


def test_convergence_is_judged_by_the_residual():
    """MINPACK's "not making good progress" at a residual 18x below the tolerance is a gait;
    a residual above it is not."""
    sc = load_scene(CONFIGS / "paper.yaml")
    w = build_walker(Plant.from_scene(sc))
    x = np.array([-0.3238, 0.2187, -0.3777, -1.0924])
    stalled = SimpleNamespace(success=False, message="The iteration is not making good "
                                                     "progress")
    poincare._check_walking(w, x, stalled, 5.67e-12, 1e-10)
    with pytest.raises(poincare.FixedPointNotFound, match="not making good progress"):
        poincare._check_walking(w, x, stalled, 1e-8, 1e-10)


def _variant(name: str, actuation: dict | None = None, **changes) -> dict:
    scene = load_scene(CONFIGS / f"{name}.yaml").model_dump(exclude_none=True)
    if actuation is not None:
        scene["walker"]["actuation"] = actuation
    for key, value in changes.items():
        scene[key] = value
    return scene


SHIPPED = sorted(p.stem for p in CONFIGS.glob("*.yaml") if not p.stem.startswith("rabbit"))
# a saturated law: the actuated flow (a linear law alone becomes a generated hip spring)
LAW = {"stiffness_n_m_per_rad": 0.5, "damping_n_m_s_per_rad": 0.05, "rest_angle_rad": 0.3}
VARIANTS = {
    "paper+push_off": _variant("paper", {"push_off": {"impulse_n_s": 0.3}}),
    "paper+speed_gain": _variant("paper", {"push_off": {
        "impulse_n_s": 0.2, "speed_gain_n_s2_per_m": 0.3, "reference_speed_m_per_s": 1.5}}),
    "paper+hip_pd": _variant("paper", {"torques": [{"joint": "hip", "law": LAW,
                                                    "max_torque_n_m": 5.0}]}),
    "powered_compass+hip_pd": _variant("powered_compass", {
        "push_off": {"impulse_n_s": 3.0}, "torques": [{"joint": "hip", "law": LAW,
                                                       "max_torque_n_m": 5.0}]}),
    "kuo2002+P0_slope": None,  # a push-off of impulse 0 on a slope (the trigger)
    "kneed+hip_pd": _variant("kneed", {"torques": [{"joint": "hip", "law": {
        "damping_n_m_s_per_rad": 0.001}}]}),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", SHIPPED + sorted(VARIANTS))
def test_every_scene_variational_and_difference_multipliers_agree(name):
    if name in VARIANTS:
        if VARIANTS[name] is None:
            x, _, mult = kuo_ref.fixed_point(0.08, 0.0, 0.005, guess=(0.15, 0.3, -0.15, -0.01))
            scene = _kuo(0.08, 0.0, 0.005, x).scene
            gait = wl.Walker.from_scene(scene).fixed_point()
            np.testing.assert_allclose(gait.multipliers, mult, rtol=0, atol=1e-6)
        else:
            scene = scene_from_dict(VARIANTS[name])
    else:
        scene = load_scene(CONFIGS / f"{name}.yaml")
    _, search = solve_scene(scene, plant=Plant.from_scene(scene))
    r = search.gaits[search.selected].result
    # central differences of step 1e-7 of a map integrated at the scene's rtol: ~rtol / 1e-7
    # at worst (1e-5 at 1e-12; the three-link scenes integrate at LSODA's 1e-11: 1e-4,
    # measured 4.7e-5 on configs/threelink.yaml)
    tol = max(1e-5, float(scene.solver.rtol) / 1e-7)
    assert r.multiplier_difference < tol, (r.multipliers_variational, r.multipliers_fd)
    assert np.all(np.isfinite(r.multipliers_fd))
