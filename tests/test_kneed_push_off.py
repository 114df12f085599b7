"""A push-off on the kneed walker (Kuo 2002's pre-emptive impulse along the trailing leg,
then the plastic heel strike, the swing knee locked through both), against the independent
kneed prototype (``tests/independent/kneed_reference.py``: its own Lagrangian, extended
impact system and root finder), on a slope gentler than the passive gait's.

Tolerances: both models integrate at rtol = atol = 1e-12 and find the fixed point to xtol
1e-13, so states agree to ~1e-10; the reference's multipliers are central differences of
step 1e-6 of a map integrated at 1e-12 (error ~1e-6 at worst, ~1e-8 seen)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import walkerlab as wl
from tests.independent.kneed_reference import KneedReference
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
GAMMA = 0.045           # rad: gentler than the shipped asin(7.25/144) = 0.0504
P = 0.01                # N s along the trailing (stance) leg


@dataclass
class _PushedKneed(KneedReference):
    """The prototype with a push-off ``P`` [N s] before its heel strike: the extended system
    ``Me (dqe' - dqe-) = Ef^T P e + Jk^T lam``, ``Jk dqe' = 0`` (the swing knee held), ``e``
    the stance leg's direction from its foot to the hip; then its own heel strike from
    ``dqe'`` (the trailing foot free)."""

    P: float = 0.0

    def heel_strike(self, x, return_extra=False):
        q, dq = x[:3], x[3:]
        Me = self._f["Me"](q, self._par())
        E = self._f["E"](q, self._par())
        Jk = np.array([[0.0, -1.0, 1.0, 0.0, 0.0]])
        e = np.array([-np.sin(q[0]), np.cos(q[0])])  # the stance leg, foot -> hip
        A = np.zeros((6, 6))
        A[:5, :5], A[:5, 5:], A[5:, :5] = Me, -Jk.T, Jk
        force = np.concatenate([np.zeros(3), self.P * e])
        dqe_po = np.linalg.solve(A, np.concatenate([Me @ np.concatenate([dq, [0.0, 0.0]])
                                                    + force, [0.0]]))[:5]
        C = np.vstack([E, Jk])
        K = np.zeros((8, 8))
        K[:5, :5], K[:5, 5:], K[5:, :5] = Me, -C.T, C
        dqp = np.linalg.solve(K, np.concatenate([Me @ dqe_po, np.zeros(3)]))[:5]
        return np.array([q[1], q[0], q[0], dqp[1], dqp[0], dqp[0]])


def _scene(push_off: dict | None, gamma: float = GAMMA) -> dict:
    d = load_scene(CONFIGS / "kneed.yaml").model_dump(exclude_none=True)
    if push_off is not None:
        d["walker"]["actuation"] = {"push_off": push_off}
    d["slope"] = {"angle_rad": gamma}
    return d


def _to_ours(xr):
    """The prototype's (stance, swing thigh, swing shank) order to walkerlab's roles."""
    return np.array([xr[1], xr[2], xr[0], xr[4], xr[5], xr[3]])


def test_a_push_off_of_zero_is_the_passive_heel_strike():
    sc = scene_from_dict(_scene(None))
    w0 = build_walker(Plant.from_scene(sc))
    sc1 = scene_from_dict(_scene({"impulse_n_s": 0.0}))
    w = build_walker(Plant.from_scene(sc1))
    rng = np.random.default_rng(2)
    for _ in range(5):
        q = np.array([0.2, 0.2, -0.25]) + rng.normal(0, 0.02, 3)
        q[1] = q[0]
        dq = rng.normal(size=3)
        dq[1] = dq[0]  # the knee locked
        x = np.concatenate([q, dq])
        np.testing.assert_allclose(w.reset(x), w0.reset(x), rtol=0, atol=1e-13)


def test_the_pushed_heel_strike_is_the_independent_one():
    sc = scene_from_dict(_scene({"impulse_n_s": P}))
    w = build_walker(Plant.from_scene(sc))
    ref = _PushedKneed(P=P)
    ref.p["gamma"] = GAMMA
    rng = np.random.default_rng(3)
    for _ in range(5):
        q1 = 0.2 + rng.normal(0, 0.02)
        xr = np.array([q1, -q1 - 2 * GAMMA, -q1 - 2 * GAMMA, *rng.normal(size=2), 0.0])
        xr[5] = xr[4]
        np.testing.assert_allclose(w.reset(_to_ours(xr)), _to_ours(ref.heel_strike(xr)),
                                   rtol=0, atol=1e-12)
        J = w.reset_jacobian(_to_ours(xr))  # the complex step through the transition
        h = 1e-6
        Jfd = np.stack([(w.reset(_to_ours(xr) + h * e) - w.reset(_to_ours(xr) - h * e))
                        / (2 * h) for e in np.eye(6)], axis=1)
        np.testing.assert_allclose(J, Jfd, rtol=0, atol=1e-7)


@pytest.mark.slow
def test_the_kneed_push_off_gait_is_the_independent_one():
    """Fixed point, step period and Floquet multipliers on a slope of 0.045 rad (the passive
    gait's is 0.0504) with a push-off of 0.01 N s."""
    ref = _PushedKneed(P=P)
    ref.p["gamma"] = GAMMA
    xs = ref.fixed_point()
    T = ref.step(xs)["t_heel"]
    mult = ref.multipliers(xs)
    d = _scene({"impulse_n_s": P})
    ours = _to_ours(xs)
    d["fixedpoint"]["initial_guess"] = {f"{n}_{'rad' if k < 3 else 'rad_per_s'}": float(v)
                                        for k, (n, v) in enumerate(zip(
                                            ("swing_thigh_angle", "swing_shank_angle",
                                             "stance_angle", "swing_thigh_rate",
                                             "swing_shank_rate", "stance_rate"), ours))}
    gait = wl.Walker.from_scene(d).fixed_point()
    np.testing.assert_allclose(gait.x, ours, rtol=0, atol=1e-9)
    assert abs(gait.step_period - T) < 1e-9
    got = np.sort_complex(gait.multipliers[np.abs(gait.multipliers) > 1e-8])
    np.testing.assert_allclose(got, np.sort_complex(mult[np.abs(mult) > 1e-8]), atol=1e-6)
