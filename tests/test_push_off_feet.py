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
from walkerlab.walker.plant import Plant

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
    sc = scene_from_dict(d)
    w0 = build_walker(Plant.from_scene(sc))
    d["walker"]["actuation"] = {"push_off": {"impulse_n_s": 0.0}}
    sc1 = scene_from_dict(d)
    w = build_walker(Plant.from_scene(sc1))
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
    sc = scene_from_dict(_scene("round_feet", {"impulse_n_s": P}, GAMMA))
    w = build_walker(Plant.from_scene(sc))
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


# ------------------------------------------------------------------ flat feet: the toe
def _cross(a, b) -> float:
    """z component of the planar cross product ``a x b``."""
    return float(a[0] * b[1] - a[1] * b[0])


def _flat_states(rng, mode: str, k: int, gamma: float):
    """``k`` states (6,) in ``mode`` (heel: foot turned toe up; toe: heel up)."""
    X = np.column_stack([rng.uniform(-0.3, 0.3, (k, 2)), np.zeros(k),
                         rng.uniform(-1.5, 1.5, (k, 3))])
    phi = rng.uniform(0.02, 0.2, k) * (1.0 if mode == "heel" else -1.0)
    X[:, 2] = phi - gamma - X[:, 1]
    return X


def test_a_toe_push_off_of_zero_is_the_generated_heel_strike():
    """Every flat-foot phase's heel-strike guard: ``P = 0`` gives its generated passive
    heel strike (heel- or toe-pinned kinematics) to round-off."""
    d = _scene("flat_feet", None)
    sc = scene_from_dict(d)
    w0 = build_walker(Plant.from_scene(sc))
    d["walker"]["actuation"] = {"push_off": {"impulse_n_s": 0.0}}
    sc1 = scene_from_dict(d)
    w = build_walker(Plant.from_scene(sc1))
    rng = np.random.default_rng(6)
    gamma = float(w.slope_rad)
    for ph0, ph in zip(w0.phases, w.phases):
        mode = "toe" if ph.name.startswith("heel_off") else "heel"
        for g0, g in zip(ph0.guards, ph.guards):
            if g.outcome != "heel_strike":
                continue
            for x in _flat_states(rng, mode, 3, gamma):
                np.testing.assert_allclose(g.reset(x), g0.reset(x), rtol=0, atol=1e-13)


@pytest.mark.slow  # builds the reference with sympy (~5 s)
def test_the_toe_push_off_is_the_independent_one_and_balances_momentum():
    """The pushed transition (impulse at the trailing toe towards the hip, the ankle held,
    then the heel strike) equals the Newton-Euler prototype
    (``tests/independent/flat_feet_push_off.py``), in heel-off and heel-contact states;
    the angular momentum about the leading heel changes by ``(toe - heel) x P e`` (the
    heel strike's impulse acts at the heel, the ankle's is internal); the kinetic energies
    before, after the push-off and after the heel strike are the prototype's (the heel
    strike removes energy).  Tolerances: linear solves of O(1) systems (1e-11 with
    margin); the reset's complex-step Jacobian against central differences of step 1e-6."""
    from tests.independent.flat_feet_push_off import pushed_heel_strike
    from tests.independent.flat_feet_reference import FlatFeetReference

    Pf = 3.0  # N s: the walker weighs ~ 8 kg
    d = _scene("flat_feet", {"impulse_n_s": Pf})
    scene = scene_from_dict(d)
    w = build_walker(Plant.from_scene(scene))
    wk, leg = scene.walker, scene.walker.leg
    ankle = leg.foot.ankle
    ref = FlatFeetReference(dict(
        M=wk.hip_mass_kg, m=leg.bodies[0].mass_kg, b=leg.bodies[0].from_hip_m,
        L=leg.length_m, h=leg.foot.heel_m, t=leg.foot.toe_m,
        k=ankle.stiffness_n_m_per_rad, r=ankle.rest_angle_rad,
        c=ankle.damping_n_m_s_per_rad, gamma=scene.slope.angle_rad, g=wk.gravity_m_per_s2))
    rng = np.random.default_rng(7)
    for mode in ("toe", "heel"):
        for x in _flat_states(rng, mode, 3, float(w.slope_rad)):
            tr = w.actuators.transition(x)
            want = pushed_heel_strike(ref, mode, x, Pf)
            np.testing.assert_allclose(tr["x_plus"], want["x_plus"], rtol=0, atol=1e-11)
            np.testing.assert_allclose([tr["ke_minus"], tr["ke_push_off"], tr["ke_plus"]],
                                       want["ke"], rtol=1e-12)
            assert tr["ke_plus"] < tr["ke_push_off"]  # the heel strike is plastic
            pos, v0 = ref.positions(mode, x[:3]), ref.velocities(mode, x)
            heel = pos["swing_heel"]
            m = want["mass"]
            h0 = sum(m[k] * _cross(pos[k] - heel, v0[k]) for k in m)
            qn = tr["x_plus"][:3]
            pn, vn = ref.positions("heel", qn), ref.velocities("heel", tr["x_plus"])
            h1 = sum(m[k] * _cross(pn[k], vn[k]) for k in m)  # new heel at 0
            lever = _cross(want["toe"] - heel, Pf * want["e"])
            assert h1 - h0 == pytest.approx(lever, abs=1e-12 * max(1.0, abs(h0)))
            J, h = w.reset_jacobian(x), 1e-6
            Jfd = np.stack([(w.reset(x + h * e) - w.reset(x - h * e)) / (2 * h)
                            for e in np.eye(6)], axis=1)
            np.testing.assert_allclose(J[3:], Jfd[3:], rtol=0, atol=1e-6)


# ------------------------------------------------------------------ gaits and their ledgers
#: scene, gentler slope [rad], push-off [N s], gait guess (a continuation from the passive)
GAITS = {
    "torso_bhm": (0.0087, 1.0, (-0.1988, 0.1814, -0.6137, -0.7444)),
    "round_feet": (GAMMA, P, (-0.1888, 0.1788, -0.1987, -0.2371)),
    "flat_feet": (0.032, 0.5, (-0.3019, 0.2400, 0.0, -1.1712, -1.0909, -7.9268)),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(GAITS))
def test_pushed_gaits_are_stable_and_their_ledgers_close(name):
    """A torso on the bisecting hip (half the passive slope), arc feet (half) and flat feet
    (0.8 of it) walk with a push-off: a stable period-1 gait; over two steps the energy
    ledger closes to 1e-9 of the kinetic energy (push-off work + slope = collision losses +
    dampers; the integrator runs at 1e-12)."""
    from walkerlab.analysis.gait.energy import trajectory_ledger
    from walkerlab.integrate.rigid import simulate_steps

    gamma, impulse, guess = GAITS[name]
    d = _scene(name, {"impulse_n_s": impulse}, gamma)
    d["fixedpoint"]["initial_guess"] = dict(zip(d["fixedpoint"]["initial_guess"], guess))
    w = wl.Walker.from_scene(d)
    g = w.fixed_point()
    assert np.max(np.abs(g.multipliers)) < 1.0
    traj = simulate_steps(w.model, g.x, 2, w.solver, max_step_time=w.max_step_time)
    led = trajectory_ledger(traj)
    ke = np.array([w.model.energies(s.x_start)[0] for s in traj.segments])
    assert np.all(np.abs(led["closure"]) / ke <= 1e-9)
    assert np.all(led["push_off_work"] > 0.0)
    np.testing.assert_allclose(led["push_off_impulse"], impulse, rtol=0, atol=0)


def test_a_push_off_on_massless_arc_legs_is_refused_in_one_line():
    """Massless legs on arc feet: the limit m -> 0 of the push-off depends on where the
    vanishing mass sits on the arc (Kuo's closed form is the point foot's); one line."""
    d = _scene("simplest", {"impulse_n_s": 0.01})
    d["walker"]["coordinates"] = "absolute"
    d["walker"]["leg"]["foot"] = {"kind": "arc", "radius_m": 0.1}
    with pytest.raises(ValueError, match="give the legs mass") as e:
        sc = scene_from_dict(d)
        build_walker(Plant.from_scene(sc))
    assert "\n" not in str(e.value) and "walker.actuation.push_off" in str(e.value)
