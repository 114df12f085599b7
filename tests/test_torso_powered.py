"""The torso walker powered on level ground (issue 48's check; ``configs/torso_powered.yaml``):
the paper walker with a 5 kg upper body on a bisecting hip, a push-off impulse before heel
strike (Kuo 2002) and a PD hip torque.

- Its gait is stable, its multipliers those of central differences, and fixed point, step
  period and multipliers are those of an independent model: ``tests/independent/
  parts_reference.py`` (the torso's coupling kept as a constraint with a multiplier) with
  the hip torque and Kuo's push-off added here (the push-off and the heel strike in extended
  coordinates, the coupling held through both impulses), sharing no code with the
  generator.  Tolerances: the two maps integrate the same flow (DOP853, 1e-12) along
  different formulations (measured: fixed points 1.6e-11 apart, periods 4e-13 relative,
  multipliers 5e-9, the last from central differences of step 1e-6 of the reference's map,
  error ~1e-8): fixed points at 1e-9, periods at 1e-10 relative, multipliers at 1e-7.
- The energy ledger closes: the push-off's and the hip torque's work equal the heel strike's
  loss (level ground: no gravity work), to 1e-9 of the kinetic energy, also on a step off
  the gait.
- The contact view walks with a step period within 3 % of the rigid gait's (slow).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from independent.parts_reference import Parts, PartsReference
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

import walkerlab as wl
from walkerlab.analysis.gait.energy import trajectory_ledger
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.walker.plant import Plant

SCENE = Path(__file__).resolve().parents[1] / "configs" / "torso_powered.yaml"
#: the scene's push-off [N s] and hip PD law [N m/rad, N m s/rad, rad]
P, K, C, REST = 3.0, 5.0, 0.5, 0.3


@pytest.fixture(scope="module")
def torso_powered():
    w = wl.Walker.from_scene(SCENE)
    return w, w.fixed_point()


class _PoweredTorso:
    """The independent torso walker (:class:`PartsReference`, no hip spring, level ground)
    with the role-based hip torque ``tau = -K (delta - REST) - C ddelta``, ``delta = psi_sw -
    psi_st`` (``+tau`` on the swing leg, ``-tau`` on the stance leg), and Kuo's push-off: an
    impulse ``P`` at the trailing (stance) foot towards the hip, that foot free, then the
    plastic heel strike; the bisecting coupling ``th = (sw + st) / 2`` held by a multiplier in
    the flow and through both impulses.  The legs are equal: leg A stays the stance leg's
    numbers every step (the reset returns role-ordered states)."""

    def __init__(self):
        self.ref = PartsReference(Parts(torso=(5.0, 0.2, 0.0, 0.0), gamma=0.0))
        self.f = self.ref._fns["A"]
        self.a = np.array([-0.5, -0.5, 1.0])  # the coupling's row in (sw, st, th)

    def flow(self, x):
        f, args = self.f, self.ref._full(x)
        M, h = np.asarray(f["M"](*args), float), np.asarray(f["h"](*args), float).ravel()
        tau = -K * (x[0] - x[1] - REST) - C * (x[2] - x[3])
        Q = tau * np.array([1.0, -1.0, 0.0])
        A = np.zeros((4, 4))
        A[:3, :3], A[:3, 3], A[3, :3] = M, self.a, self.a
        sol = np.linalg.solve(A, np.concatenate([Q - h, [0.0]]))
        return np.array([x[2], x[3], sol[0], sol[1]])

    def transition(self, x):
        args = self.ref._full(x)
        De = np.asarray(self.f["De"](*args), float)  # (x, y, sw, st, th): stance foot free
        E = np.asarray(self.f["E"](*args), float)    # the swing foot's Jacobian (2, 5)
        a = np.concatenate([[0.0, 0.0], self.a])[None, :]
        e = np.array([-np.sin(x[1]), np.cos(x[1])])  # stance foot -> hip
        dq = np.array([0.0, 0.0, x[2], x[3], 0.5 * (x[2] + x[3])])
        Ef = np.zeros((2, 5))
        Ef[:, :2] = np.eye(2)

        def impulse(rows, rhs):  # De (dq+ - dq) = rows^T lambda + applied, rows dq+ = 0
            m = len(rows)
            A = np.zeros((5 + m, 5 + m))
            A[:5, :5], A[:5, 5:], A[5:, :5] = De, -rows.T, rows
            return np.linalg.solve(A, np.concatenate([rhs, np.zeros(m)]))[:5]

        dq_po = impulse(a, De @ dq + Ef.T @ (P * e))
        dq_plus = impulse(np.vstack([E, a]), De @ dq_po)
        T = [0.5 * v @ De @ v for v in (dq, dq_po, dq_plus)]
        return np.array([x[1], x[0], dq_plus[3], dq_plus[2]]), T

    def step(self, x0):
        def ev(t, x):
            return self.ref.guard(x, "A") if self.ref.swing_foot(x, "A")[0] > 0 else 1.0
        ev.terminal, ev.direction = True, -1
        sol = solve_ivp(lambda t, x: self.flow(x), (0, 3), x0, method="DOP853", rtol=1e-12,
                        atol=1e-12, events=ev)
        xm = sol.y_events[0][0]
        return float(sol.t_events[0][0]), xm, self.transition(xm)[0]

    def fixed_point(self, guess):
        # on the heel-strike surface (level ground: sw = -st): unknowns st, dsw, dst
        def full(z):
            return np.array([-z[0], z[0], z[1], z[2]])
        z = fsolve(lambda z: self.step(full(z))[2][1:] - z, guess[1:], xtol=1e-13)
        return full(z)


def test_the_gait_is_stable_and_its_multipliers_are_central_differences(torso_powered):
    w, g = torso_powered
    assert g.residual < 1e-10
    assert g.x[0] == pytest.approx(-g.x[1], abs=1e-12)  # level ground: heel strike at sw = -st
    assert np.max(np.abs(g.multipliers)) < 0.5           # stable (0.4205), with a margin
    # the variational Jacobian against central differences of the map (step 1e-6: error
    # ~1e-8 from truncation and the map's 1e-12 integration; measured 6.5e-9)
    h, x = 1e-6, g.x
    fd = np.column_stack([(w.step(x + h * e).x_next - w.step(x - h * e).x_next) / (2 * h)
                          for e in np.eye(4)])
    np.testing.assert_allclose(g.jacobian, fd, atol=1e-7)


def test_the_gait_is_the_independent_models(torso_powered):
    w, g = torso_powered
    ref = _PoweredTorso()
    x = ref.fixed_point(g.x + 1e-3)
    np.testing.assert_allclose(x, g.x, atol=1e-9)
    t, _, x_next = ref.step(x)
    assert t == pytest.approx(g.step_period, rel=1e-10)
    assert x_next == pytest.approx(x, abs=1e-9)
    h = 1e-6
    J = np.column_stack([(ref.step(x + h * e)[2] - ref.step(x - h * e)[2]) / (2 * h)
                         for e in np.eye(4)])
    mu_ref = np.sort(np.abs(np.linalg.eigvals(J)))[::-1]
    np.testing.assert_allclose(np.abs(g.multipliers), mu_ref, atol=1e-7)


def test_the_ledger_closes_on_and_off_the_gait(torso_powered):
    w, g = torso_powered
    led = g.ledger
    ke = float(w.model.energies(g.x)[0])
    # the push-off's and the hip torque's work take what the heel strike loses; no gravity
    assert abs(led["closure"][0]) <= 1e-9 * ke
    assert led["slope_energy"][0] == 0.0 and abs(led["potential_work"][0]) <= 1e-12 * ke
    work = (led["push_off_work"] + led["actuator_work_positive"]
            + led["actuator_work_negative"])[0]
    assert work == pytest.approx(led["heel_strike_loss"][0], rel=1e-9)
    assert led["push_off_work"][0] > 0 and led["push_off_impulse"][0] == P
    # a step off the gait: the energy changes, the ledger still closes
    x0 = g.x + np.array([0.0, 0.0, 0.05, -0.03])
    traj = simulate_steps(w.model, x0, 2, w.solver, max_step_time=w.max_step_time)
    off = trajectory_ledger(traj)
    ke0 = np.array([w.model.energies(s.x_start)[0] for s in traj.segments])
    assert np.all(np.abs(off["energy_change"]) > 1e-3)
    assert np.all(np.abs(off["closure"]) <= 1e-9 * ke0)


def test_the_contact_view_carries_the_torso_walkers_actuators():
    # the bisecting hip adds bodies, not coordinates: the floating view's are the straight
    # legs' and the hip torque acts on the two leg angles as on a walker without a torso
    from walkerlab.config import load_scene
    from walkerlab.models.contact.actuation import ContactActuators
    from walkerlab.models.contact.scene import contact_setup

    sc = load_scene(SCENE)
    acts = contact_setup(sc, plant=Plant.from_scene(sc)).actuators
    assert isinstance(acts, ContactActuators) and acts.spec.push_off.impulse_n_s == P
    x = np.array([0.0, 0.97, -0.1, 0.2, 0.4, 0.0, 0.3, -0.5])  # leg2 in stance
    Q, power = acts.hip_torque(x, stance=1)
    tau = -K * (-0.1 - 0.2 - REST) - C * (0.3 + 0.5)
    np.testing.assert_allclose(Q, [0.0, 0.0, tau, -tau], rtol=1e-15)
    assert power == pytest.approx(tau * 0.8, rel=1e-15)


@pytest.mark.slow  # the contact model's own periodic gait: about a minute
def test_the_contact_view_steps_within_3_percent_of_the_rigid_gait(torso_powered, tmp_path):
    from walkerlab.api import contact_simulate

    _, g = torso_powered
    ds = contact_simulate(SCENE, runs_dir=tmp_path)
    assert int(ds["summary_heel_strikes"]) >= 12 and bool(ds["periodic_gait_stable"])
    assert float(ds["periodic_gait_step_period"]) == pytest.approx(g.step_period, rel=0.03)
    walked = ds["steps_period"].values[1:-1]  # the first step starts mid-stance
    np.testing.assert_allclose(walked, g.step_period, rtol=0.03)
