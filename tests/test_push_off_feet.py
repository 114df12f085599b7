"""Push-off (Kuo 2002's impulse before the plastic heel strike) at every foot kind's contact
point, through the generated impact maps (:mod:`walkerlab.models.hybrid.push_off`).

Arc feet: the impulse on the stance arc's material point at the rolling contact, from that
point to the hip; against the independent round-foot prototype with its own push-off
(``tests/independent/round_feet_push_off.py``: its own Lagrangian, extended coordinates and
material-point Jacobians).  Tolerances: the transitions are linear solves (round-off,
1e-12 with margin); both gaits integrate at rtol = atol = 1e-12 and solve the fixed point to
xtol 1e-13 (states ~1e-10); the reference's multipliers are central differences of step 1e-6
of a map integrated at 1e-12 (error ~1e-8)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import walkerlab as wl
from tests.independent.round_feet_push_off import PushedRoundFeet
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.models.registry import build_walker

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
GAMMA = 0.005  # rad: half the round-foot walker's passive slope (0.01)
P = 0.04       # N s (nondimensional: M sqrt(g l)); the gait's step period 2.4297


def _scene(name: str, push_off: dict | None, gamma: float | None = None) -> dict:
    d = load_scene(CONFIGS / f"{name}.yaml").model_dump(exclude_none=True)
    if push_off is not None:
        d["walker"]["actuation"] = {"push_off": push_off}
    if gamma is not None:
        d["slope"] = {"angle_rad": gamma}
    return d


def _kneed_arc() -> dict:
    """The kneed walker on arc feet (radius 0.1 m)."""
    d = _scene("kneed", None)
    d["walker"]["leg"]["foot"] = {"kind": "arc", "radius_m": 0.1}
    return d


@pytest.mark.parametrize("scene", ["round_feet", "kneed_arc", "torso_bhm", "paper",
                                   "kneed"])
def test_a_push_off_of_zero_is_the_generated_heel_strike(scene):
    """``P = 0``: the extended impact system (stance foot free, leading foot's material
    contact point pinned) is the generated passive heel strike, to round-off."""
    d = _kneed_arc() if scene == "kneed_arc" else _scene(scene, None)
    w0 = build_walker(scene_from_dict(d))
    d["walker"]["actuation"] = {"push_off": {"impulse_n_s": 0.0}}
    w = build_walker(scene_from_dict(d))
    n = len(w.roles)
    rng = np.random.default_rng(4)
    for _ in range(4):
        x = rng.normal(0.0, 0.2, 2 * n)
        if n == 3:  # the swing knee locked at heel strike
            x[1], x[4] = x[0], x[3]
        np.testing.assert_allclose(w.reset(x), w0.reset(x), rtol=0, atol=1e-13)


def test_the_arc_foot_push_off_is_the_independent_one():
    """The pushed transition (impulse at the rolling contact, towards the hip) equals the
    prototype's, and its complex-step Jacobian the central differences."""
    w = build_walker(scene_from_dict(_scene("round_feet", {"impulse_n_s": P}, GAMMA)))
    ref = PushedRoundFeet(P=P)
    ref.p["gamma"] = GAMMA
    rng = np.random.default_rng(5)
    for _ in range(4):
        st = 0.17 + rng.normal(0, 0.02)
        x = np.array([-st - 2 * GAMMA, st, *rng.normal(-0.2, 0.05, 2)])
        np.testing.assert_allclose(w.reset(x), ref.impact(x), rtol=0, atol=1e-12)
        J, h = w.reset_jacobian(x), 1e-6
        Jfd = np.stack([(w.reset(x + h * e) - w.reset(x - h * e)) / (2 * h)
                        for e in np.eye(4)], axis=1)
        np.testing.assert_allclose(J, Jfd, rtol=0, atol=1e-7)
        tr = w.actuators.transition(x)
        assert tr["ke_push_off"] > tr["ke_minus"] > tr["ke_plus"] - 1.0  # work done, then lost


@pytest.mark.slow
def test_the_arc_foot_push_off_gait_is_the_independent_one():
    """Fixed point, step period and Floquet multipliers of the round-foot walker with a
    push-off of 0.04 on a slope of 0.005 rad (its passive gait's is 0.01)."""
    ref = PushedRoundFeet(P=P)
    ref.p["gamma"] = GAMMA
    xs = ref.fixed_point(np.array([-0.189, 0.179, -0.199, -0.237]))
    T = ref.step(xs)["t_heel"]
    mult = ref.multipliers(xs)
    d = _scene("round_feet", {"impulse_n_s": P}, GAMMA)
    d["fixedpoint"]["initial_guess"] = {
        k: float(v) for k, v in zip(("swing_angle_rad", "stance_angle_rad",
                                     "swing_rate_rad_per_s", "stance_rate_rad_per_s"), xs)}
    gait = wl.Walker.from_scene(d).fixed_point()
    np.testing.assert_allclose(gait.x, xs, rtol=0, atol=1e-9)
    assert abs(gait.step_period - T) < 1e-9
    got = np.sort_complex(gait.multipliers[np.abs(gait.multipliers) > 1e-8])
    np.testing.assert_allclose(got, np.sort_complex(mult[np.abs(mult) > 1e-8]), atol=1e-7)
