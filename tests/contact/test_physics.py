"""Physics checks of the compliant-contact walker (statics, friction, energy, rigid limit)."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from walkerlab.analysis.contact.sim import initial_state_from_ideal, simulate_contact
from walkerlab.bench.contact import leg_angle_columns
from walkerlab.config import ContactSettings, SolverSettings, TerrainSettings
from walkerlab.models.contact import ContactWalker
from walkerlab.models.contact.laws import contact_params_si, coulomb_friction_coefficient

PAPER_FP = (-0.2042, 0.1694, -0.6058, -0.8610)  # ideal fixed point after heel strike
L, m, MH, a, g = 1.0, 5.0, 10.0, 0.5, 9.81


def _standing(phi, settings=None, both_feet=False, t_final=0.5):
    """Walker with both legs vertical, leg2's foot at s=0 at its static penetration.

    leg1's lane has no ground (unless both_feet), so leg1 hangs and leg2 carries everything.
    """
    cs = settings or ContactSettings()
    lane1 = np.array([0.0]) if both_feet else np.array([100.0])
    w = ContactWalker(phi=phi, contact=contact_params_si(cs), lane1=lane1, lane2=np.array([0.0]),
                      patch_half_width=1.0, continuous=False)
    x0 = initial_state_from_ideal(w, 0.0, 0.0, 0.0, 0.0)
    x0[1] += 1e-5  # start 10 µm higher: it has to settle, not just sit
    return w, simulate_contact(w, x0, t_final, SolverSettings.for_contact(rtol=1e-10, atol=1e-13))


@pytest.mark.parametrize("both_feet", [False, True])
def test_static_penetration_level_ground(both_feet):
    w, r = _standing(0.0, both_feet=both_feet)
    load = w.total_mass * g / (2 if both_feet else 1)  # [N] per foot
    expected = (load / w.contact.k) ** (1 / w.contact.e)  # IMPACT: k d^e = F
    pen = r.feet["leg2"].penetration[-1]
    # 1%: the damped transient (slowest mode ~ k_lin/c ~ 130 /s) is gone after 0.5 s
    assert pen == pytest.approx(expected, rel=0.01)
    assert r.feet["leg2"].normal_force[-1] == pytest.approx(load, rel=0.01)


def test_slope_steeper_than_friction_angle_slides():
    phi = np.arctan(0.9) + np.radians(5)  # 5 deg steeper than atan(mu_s)
    w, r = _standing(phi, t_final=0.6)
    v = r.feet["leg2"].slip_velocity
    assert v[-1] > w.contact.v_d  # in the dynamic-friction regime
    assert r.feet["leg2"].s[-1] > 0.1  # slid more than 10 cm in 0.6 s


@pytest.mark.parametrize("phi_deg", [10.0, 30.0, 40.0])
def test_slope_shallower_than_friction_angle_sticks(phi_deg):
    phi = np.radians(phi_deg)  # atan(0.9) = 42 deg
    w, r = _standing(phi, t_final=0.1)
    c = w.contact
    # ADAMS "stiction" is regularized: the foot creeps at the v* where mu(v*) = -tan(phi)
    vstar = brentq(lambda v: coulomb_friction_coefficient(v, c.mu_s, c.mu_d, c.v_s, c.v_d)
                   + np.tan(phi), 0.0, c.v_s)
    v = r.feet["leg2"].slip_velocity
    assert np.all(np.abs(v[r.t > 0.01]) < c.v_s)  # below the stiction velocity: "sticks"
    # The creep settles within ~10 ms (tangential time constant M / (1.5 mu_s Fn / v_s)
    # = 7.5 ms); the upright stance leg is an inverted pendulum that slowly tips after the
    # settling transient (~0.1 rad/s), which changes the friction demand by < 1% before 30 ms.
    win = (r.t >= 0.015) & (r.t <= 0.03)
    np.testing.assert_allclose(v[win], vstar, rtol=0.01)


def test_energy_balance_equals_contact_work():
    """E(t) - E(0) = integral of sum_feet F . v_foot (gravity is in E)."""
    w = ContactWalker.from_settings(ContactSettings(), TerrainSettings(patch_width_m=0.3),
                                    step_length=0.372, n_steps=4)
    x0 = initial_state_from_ideal(w, *PAPER_FP)

    def f(t, y):
        cq = w.contact_quantities(y[:8])
        return np.append(w.rhs(t, y[:8]), cq["leg1"]["power"][0] + cq["leg2"]["power"][0])

    t = np.linspace(0, 0.9, 901)  # one step incl. the heel strike at ~0.71 s
    sol = solve_ivp(f, (0, 0.9), np.append(x0, 0.0), method="LSODA", t_eval=t,
                    rtol=1e-10, atol=1e-13)
    assert sol.success
    E = w.energies(sol.y[:8].T)["total"]
    W = sol.y[8]
    assert W[-1] < -0.1  # the contacts dissipate (heel strike, damping, friction)
    # states are accurate to ~1e-10 relative; E ~ 200 J -> errors ~1e-8 J; allow 1e-6 J
    np.testing.assert_allclose(E - E[0], W, atol=1e-6)


def _ideal_rhs(t, x):
    """Rigid compass gait in swing (leg1 swing, leg2 stance, foot pinned)."""
    b = L - a
    t1, t2, w1, w2 = x
    c, s = np.cos(t2 - t1), np.sin(t2 - t1)
    D = np.array([[m * b * b, -m * L * b * c], [-m * L * b * c, MH * L * L + m * (L * L + a * a)]])
    C = np.array([[0.0, m * L * b * s * w2], [-m * L * b * s * w1, 0.0]])
    G = np.array([m * g * b * np.sin(t1), -(MH * L + m * (a + L)) * g * np.sin(t2)])
    return np.concatenate([[w1, w2], np.linalg.solve(D, -C @ [w1, w2] - G)])


def test_rigid_limit_as_stiffness_grows():
    """High friction + growing stiffness: one step approaches the rigid ideal trajectory.

    mu_s = mu_d = 5.  The ADAMS friction is regularized (no true stiction); its creep
    (~ v_s * F_t / (1.5 mu_s F_n)) would put a stiffness-independent floor under the error
    (1.2e-3 rad with v_s = 100 mm/s), so v_s = 0.01 mm/s here to expose the stiffness effect.
    """
    t = np.linspace(0, 0.6, 601)  # swing phase before the heel strike at 0.7036 s
    ideal = solve_ivp(_ideal_rhs, (0, 0.6), PAPER_FP, t_eval=t, method="DOP853",
                      rtol=1e-12, atol=1e-12).y.T
    errs = []
    for k in (1e1, 1e2, 1e3, 1e4, 1e5):  # N/mm^2.2
        cs = ContactSettings(stiffness_n_per_mm_pow_e=k, mu_static=5, mu_dynamic=5,
                             stiction_velocity_mm_per_s=0.01, friction_velocity_mm_per_s=0.1)
        w = ContactWalker.from_settings(cs, TerrainSettings(), step_length=0.372, n_steps=4)
        r = simulate_contact(w, initial_state_from_ideal(w, *PAPER_FP), 0.6,
                             SolverSettings.for_contact(rtol=1e-10, atol=1e-13))
        errs.append(np.abs(r.x[:, leg_angle_columns(w)] - ideal[:, :2]).max())
    errs = np.array(errs)
    assert np.all(np.diff(errs) < 0), errs  # monotone decrease
    assert errs[-1] < 0.15 * errs[0] and errs[-1] < 1e-5, errs
