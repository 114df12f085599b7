"""Physics of the independent reference prototypes (kneed walker, round feet).

The prototypes in ``tests/independent/`` share no code with ``walkerlab.models``; they are the
yardstick the generic framework's kneed and round-foot walkers are compared with
(``tests/test_kneed_round_feet.py``), so their own physics is checked here.
"""

import numpy as np
import pytest
from independent.kneed_reference import TEDRAKE_X0, KneedReference
from independent.round_feet_reference import RoundFeetReference

# Fixed point of the prototype (root of the 3-D Poincaré map from Tedrake's x0, xtol 1e-13,
# DOP853 rtol = atol = 1e-12): stance, swing thigh, swing shank angles [rad] and rates [rad/s].
KNEED_FIXED_POINT = np.array([0.189273479629782, -0.290010513437277, -0.290010513437277,
                              -1.133816586447852, -0.10872933848111, -0.10872933848111])


@pytest.fixture(scope="module")
def kneed():
    return KneedReference()


@pytest.fixture(scope="module")
def kneed_step(kneed):
    return kneed.step(KNEED_FIXED_POINT, dense=True)


def _angular_momentum(walker, x, about, subset=None):
    total = 0.0
    for name, (m, p, v) in walker.positions_velocities(x).items():
        if subset is None or name in subset:
            r = p - about
            total += m * (r[0] * v[1] - r[1] * v[0])
    return total


def test_kneed_fixed_point_is_periodic(kneed, kneed_step):
    # the stored fixed point maps to itself (integration tolerance 1e-12, 0.55 s step)
    assert np.max(np.abs(kneed_step["x_next"] - KNEED_FIXED_POINT)) < 1e-9


def test_kneed_energy_conserved_in_both_swing_phases(kneed, kneed_step):
    s = kneed_step
    for sol, (a, b) in ((s["sol_unlocked"], (0.0, s["t_knee"])),
                        (s["sol_locked"], (s["t_knee"], s["t_heel"]))):
        E = np.array([sum(kneed.energies(sol(t))) for t in np.linspace(a, b, 60)])
        # 12.7 J total; rtol = atol = 1e-12 per step, some hundred steps
        assert np.ptp(E) < 1e-9 * abs(E[0])


def test_knee_strike_conserves_momenta_and_loses_energy(kneed, kneed_step):
    xm, xp = kneed_step["x_knee_minus"], kneed_step["x_knee_plus"]
    assert xp[2] == xp[1] and xp[5] == pytest.approx(xp[4], abs=1e-14)  # knee locked
    L0 = _angular_momentum(kneed, xm, np.zeros(2))
    assert _angular_momentum(kneed, xp, np.zeros(2)) == pytest.approx(L0, rel=1e-12)
    hip = kneed.point("hip", xm)
    swing = {"swing_thigh", "swing_shank"}
    Ls = _angular_momentum(kneed, xm, hip, swing)
    assert _angular_momentum(kneed, xp, hip, swing) == pytest.approx(Ls, rel=1e-12)
    dE = kneed.energies(xp)[0] - kneed.energies(xm)[0]
    assert dE < -1e-3   # plastic: loses 0.025 J of 12.7 J


def test_heel_strike_conserves_momenta_old_foot_lifts(kneed, kneed_step):
    xm = kneed_step["x_heel_minus"]
    xn, extra = kneed.heel_strike(xm, return_extra=True)
    foot = kneed.point("swing_foot", xm)
    # whole walker about the new contact; new stance foot is the origin after the swap
    assert _angular_momentum(kneed, xn, np.zeros(2)) == pytest.approx(
        _angular_momentum(kneed, xm, foot), rel=1e-12)
    # old stance leg about the hip (it becomes the swing leg)
    assert _angular_momentum(kneed, xn, kneed.point("hip", xn), {"swing_thigh", "swing_shank"}) \
        == pytest.approx(_angular_momentum(kneed, xm, kneed.point("hip", xm),
                                           {"stance_shank", "stance_thigh"}), rel=1e-12)
    assert kneed.energies(xn)[0] < kneed.energies(xm)[0]
    gm = kneed.p["gamma"]
    v = extra["old_stance_foot_velocity"]
    assert v[0] * np.sin(gm) + v[1] * np.cos(gm) > 0      # lifts off the slope
    assert extra["impulse"][1] > 0                          # ground pushes, never pulls


def test_kneed_swing_foot_clears_ground_and_stop_holds(kneed, kneed_step):
    s = kneed_step
    for sol, (a, b) in ((s["sol_unlocked"], (0.0, s["t_knee"])),
                        (s["sol_locked"], (s["t_knee"], s["t_heel"]))):
        ts = np.linspace(a, b, 200)[1:-1]
        assert min(kneed.swing_foot_clearance(sol(t)) for t in ts) > 0
    # with the knee locked, the knee stop pushes (lam < 0): no latch needed
    ts = np.linspace(s["t_knee"], s["t_heel"], 20)
    assert max(kneed.locked_accel(s["sol_locked"](t))[1] for t in ts) < 0


def test_tedrake_initial_condition_is_only_a_guess(kneed):
    # printed from an explicit-Euler run: close to, but not on, the periodic gait
    x1 = kneed.step(TEDRAKE_X0)["x_next"]
    assert 1e-3 < np.max(np.abs(x1 - TEDRAKE_X0)) < 0.1


def test_round_feet_with_zero_radius_is_the_paper_walker(paper_fixed_point):
    # paper Table 1 walker (point masses, R = 0) through the round-foot prototype
    w = RoundFeetReference(p=dict(g=9.81, L=1.0, R=0.0, M=10.0, m=5.0, c=0.5, I=0.0,
                                  gamma=0.0174))
    x = paper_fixed_point.x
    assert np.max(np.abs(w.step(x)["x_next"] - x)) < 1e-9
