"""Double support of a flat-footed walker (issue 48 item 2): at heel strike the trailing toe
stays on the ground while its normal force pushes (Wisse et al. 2006's walker on ankle
springs, configs/flat_feet.yaml), checked against a two-contact impact solved here in other
coordinates and against energy conservation in the closed chain."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp

from walkerlab.codegen.cache import functions
from walkerlab.config import scene_from_dict
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
#: configs/flat_feet.yaml's gait with double support (walkerlab fixedpoint, residual 2e-11)
X_STAR = np.array([-0.36548470557401586, 0.26927561289219265, 0.0, -1.3533821452836272,
                   -1.1872901756684866, -12.630842746366493])
PERIOD_S = 0.8101592422


def _scene(damping=None):
    d = yaml.safe_load((ROOT / "configs/flat_feet.yaml").read_text())
    if damping is not None:
        d = copy.deepcopy(d)
        d["walker"]["leg"]["foot"]["ankle"]["damping_n_m_s_per_rad"] = damping
    return scene_from_dict(d, "flat_feet.yaml")


@pytest.fixture(scope="module")
def flat():
    sc = _scene()
    w = build_walker(Plant.from_scene(sc))
    traj = simulate_steps(w, X_STAR, 1, Solver.from_settings(sc.solver))
    return sc, w, functions(walker_data(sc.walker, sc.slope.angle_rad)), traj.segments[0], traj


def test_the_trailing_toe_stays_down_after_heel_strike(flat):
    """The step begins in double support (the leading heel and the trailing toe down) for
    10-25 ms (the contact model keeps that toe down 16-20 ms: the scene's notes) until the
    toe's normal force reaches 0; then the single-support modes; the gait is the fixed
    point's (period to 1e-8 s: the fixed point's residual is 2e-11)."""
    _sc, _w, _f, seg, _traj = flat
    name, t0, t1, ended = seg.phase_log[0]
    assert name == "double_support:heel_contact" and ended == "toe_off"
    assert 0.010 < t1 - t0 < 0.025
    assert seg.phase_log[1][0] == "heel_contact:early_swing"
    assert seg.termination == "heel_strike"
    assert abs((seg.t_end - seg.t_start) - PERIOD_S) < 1e-8
    assert np.max(np.abs(seg.x_next - X_STAR)) < 1e-8


def _direct_impact(f, x, p):
    """The heel strike as one plastic impact with both contacts, in coordinates of its own:
    ``z = (hip x, hip y, leading leg, trailing leg, leading sole, trailing sole)`` (absolute
    angles), the hip and leg point masses, massless feet; ``M (v+ - v-) = J^T Lam``,
    ``J v+ = 0`` with the leading heel's and trailing toe's rows.  Returns ``v+`` and the
    impulses ``(heel (2,), toe (2,))`` [N s] in world axes."""
    L, d, m, mh = p["L"], p["d"], p["m"], p["mh"]
    hs, ts = p["heel"], p["toe"]
    e = lambda a: np.array([np.sin(a), -np.cos(a)])  # noqa: E731  hip -> foot
    u = lambda a: np.array([np.cos(a), np.sin(a)])  # noqa: E731  heel -> toe along a sole
    sw, st, a = x[:3]
    dsw, dst, da = x[3:]
    # the pre-impact state: the stance (trailing) foot on its toe (heel off), the points
    # from the generated kinematics only for the hip's position and velocity (finite
    # differences along the motion)
    h = 1e-6
    hip = lambda y: f["points"](y)["hip"]  # noqa: E731
    xv = np.asarray(x, float)
    vh = (hip(xv + h * np.r_[xv[3:], 0, 0, 0]) - hip(xv - h * np.r_[xv[3:], 0, 0, 0])) / (2 * h)
    z = np.array([*hip(xv), sw, st, sw + p["r"], st + a])
    v = np.array([*vh, dsw, dst, dsw, dst + da])

    def masses(z):
        H = z[:2]
        return [(mh, H), (m, H + d * e(z[2])), (m, H + d * e(z[3]))]

    def contacts(z):
        H = z[:2]
        heel = H + L * e(z[2]) - hs * u(z[4])
        toe = H + L * e(z[3]) + ts * u(z[5])
        return np.concatenate([heel, toe])

    def jac(fun, z):
        cols = []
        for k in range(z.size):
            dz = np.zeros(z.size)
            dz[k] = 1e-7
            cols.append((fun(z + dz) - fun(z - dz)) / 2e-7)
        return np.stack(cols, axis=-1)
    M = np.zeros((6, 6))
    for i, (mass, _r) in enumerate(masses(z)):
        Jr = jac(lambda zz, i=i: masses(zz)[i][1], z)
        M += mass * Jr.T @ Jr
    J = jac(contacts, z)
    K = np.block([[M, -J.T], [J, np.zeros((4, 4))]])
    sol = np.linalg.solve(K, np.r_[M @ v, np.zeros(4)])
    return sol[:6], sol[6:8], sol[8:10]


def test_the_double_support_impulse_against_a_direct_two_contact_impact(flat):
    """The heel strike from heel off, then the step's entry (the toe-pinning impulse, the
    second stage of the two-contact impact), against the two-contact impact solved at once
    in hip-and-absolute-angle coordinates (massless feet: the impulses pass through the
    ankles): the leg rates, the leading foot's rate and the toe's impulse agree to 1e-6
    (the direct solve's finite-difference Jacobians, step 1e-7); both impulses compressive.
    """
    sc, _w, f, seg, _traj = flat
    x_end = seg.x_end
    assert seg.phase_log[-1][0] == "heel_off:late_swing"
    x_plus, (imp_n, imp_t) = f["double_support_heel_contact_entry"](
        f["reset_heel_strike_toe"](x_end))
    ps = {"L": 1.0, "d": 0.5, "m": 5.0, "mh": 10.0, "heel": 0.05, "toe": 0.10, "r": 0.0}
    v, heel, toe = _direct_impact(f, x_end, ps)
    gam = sc.slope.angle_rad
    n, t = np.array([np.sin(gam), np.cos(gam)]), np.array([np.cos(gam), -np.sin(gam)])
    # roles swap: the new swing leg is the trailing one, the new stance the leading one
    assert x_plus[3] == pytest.approx(v[3], abs=1e-6)
    assert x_plus[4] == pytest.approx(v[2], abs=1e-6)
    assert x_plus[4] + x_plus[5] == pytest.approx(v[4], abs=1e-5)
    assert imp_n == pytest.approx(toe @ n, abs=1e-6)
    assert imp_t == pytest.approx(toe @ t, abs=1e-6)
    assert toe @ n > 0 and heel @ n > 0


def test_double_support_conserves_energy_without_damping():
    """Without ankle damping the closed chain (leading heel and trailing toe pinned, the
    trailing foot's spring loaded) conserves kinetic + gravity + both springs' energy: to
    1e-9 J over 10 ms of double support (rtol 1e-12)."""
    sc = _scene(damping=0.0)
    f = functions(walker_data(sc.walker, sc.slope.angle_rad))
    x0, (imp_n, _t) = f["double_support_heel_contact_entry"](X_STAR)
    assert imp_n > 0

    def energy(x):
        e = f["energies_heel"](x)
        return float(e["kinetic"] + e["potential"] + f["double_support_trailing"](x)[2])
    fl = f["flow_double_support_heel_contact"]
    sol = solve_ivp(fl, (0, 0.01), x0, method="DOP853", rtol=1e-12, atol=1e-12,
                    dense_output=True)
    assert sol.success
    forces = [f["double_support_heel_contact_forces"](0, sol.sol(t))[0]
              for t in np.linspace(0, 0.01, 11)]
    assert min(forces) > 0  # the toe still pushes: a double support throughout
    e = [energy(sol.sol(t)) for t in np.linspace(0, 0.01, 11)]
    assert max(e) - min(e) < 1e-9
    assert f["double_support_trailing"](x0)[2] > 0.5  # the spring holds ~0.9 J


def test_the_energy_ledger_closes_through_the_double_support(flat):
    """The walker's ledger (walkerlab.analysis.gait.energy.trajectory_ledger) with the
    double support: the trailing ankle's damper in the damper work, its spring's energy
    given back before toe off and the toe-pinning impulse's loss in the heel strike's; the
    closure to 1e-9 of the step's kinetic energy (measured 5e-12 J; 0.15 J a step when the
    double support was read with the single-support terms)."""
    from walkerlab.analysis.gait.energy import trajectory_ledger

    _sc, w, f, seg, traj = flat
    led = trajectory_ledger(traj)
    ke = w.energies(seg.x_start)[0]
    assert abs(led["closure"][0]) < 1e-9 * ke
    # heel strike: kinetic 0.079 J + the spring's 0.883 J - the 0.420 J it gives back
    # + the toe impulse's 0.0005 J
    _ph, dense, (ta, tb) = seg.pieces[0]
    given = (f["double_support_trailing"](np.ravel(dense(ta))[:6])[2]
             - f["double_support_trailing"](np.ravel(dense(tb))[:6])[2])
    assert 0.3 < given < 0.6
    assert led["heel_strike_loss"][0] == pytest.approx(0.542, abs=2e-3)


def _actuated(torques, ankle_push_off=None):
    d = yaml.safe_load((ROOT / "configs/flat_feet.yaml").read_text())
    d["walker"]["actuation"] = {k: v for k, v in (("torques", torques),
                                                  ("ankle_push_off", ankle_push_off)) if v}
    sc = scene_from_dict(d, "flat_feet.yaml")
    return build_walker(Plant.from_scene(sc)), Solver.from_settings(sc.solver)


@pytest.mark.parametrize("joint", ["hip", "stance_ankle"])
def test_a_zero_torque_keeps_the_double_support(flat, joint):
    """A joint torque law of zero gains on flat feet (its flow the passive one's plus an
    exact 0) keeps the double support after heel strike: the passive gait's step from its
    fixed point, the same phases, period and next state to 1e-9 (the single-support modes
    run the Python flows instead of the compiled ones: round-off, measured 1e-13).  Before,
    an actuated walker released the trailing toe at heel strike: period 0.7576 s, not
    0.8102 s."""
    _sc, _w, _f, seg, _traj = flat
    w, solver = _actuated([{"joint": joint, "law": {}}])
    s = simulate_steps(w, X_STAR, 1, solver).segments[0]
    assert [p[0] for p in s.phase_log] == [p[0] for p in seg.phase_log]
    assert s.phase_log[0][0] == "double_support:heel_contact"
    assert abs((s.t_end - s.t_start) - (seg.t_end - seg.t_start)) < 1e-9
    assert np.max(np.abs(s.x_next - seg.x_next)) < 1e-9
    assert np.max(np.abs(s.x_next - X_STAR)) < 1e-9  # the passive fixed point is the map's


def test_a_zero_torque_with_an_ankle_push_off_keeps_the_double_support():
    """An ankle push-off (0.5 N m in heel off) with a zero-gain hip torque: the step of the
    ankle push-off alone (which keeps the double support), the same phases and next state
    to 1e-9."""
    po = {"constant_n_m": 0.5}
    ref, solver = _actuated([], po)
    w, _ = _actuated([{"joint": "hip", "law": {}}], po)
    a, b = (simulate_steps(m, X_STAR, 1, solver).segments[0] for m in (ref, w))
    assert a.phase_log[0][0] == "double_support:heel_contact"
    assert [p[0] for p in b.phase_log] == [p[0] for p in a.phase_log]
    assert abs((b.t_end - b.t_start) - (a.t_end - a.t_start)) < 1e-9
    assert np.max(np.abs(b.x_next - a.x_next)) < 1e-9


def test_the_ledger_closes_with_a_hip_torque_in_double_support(flat):
    """A hip torque (0.3 N m + 1 N m/rad) through a step that begins in double support: the
    closed chain carries the torque's generalised force (``[M -J^T; J 0] [qdd; lam] =
    [-h + B tau; -dJ dq]``), so the ledger (the torque's work ``int tau d(delta)`` in every
    phase, double support's included) closes to 1e-9 of the kinetic energy (rtol 1e-12:
    measured 3e-12 J); the torque's work in double support alone (6e-4 J) is far above
    that, so a closed chain without the torque would not close."""
    from scipy.integrate import quad

    from walkerlab.analysis.gait.energy import trajectory_ledger

    w, solver = _actuated([{"joint": "hip", "law": {"constant_n_m": 0.3,
                                                    "stiffness_n_m_per_rad": 1.0}}])
    traj = simulate_steps(w, X_STAR, 1, solver)
    seg = traj.segments[0]
    assert seg.termination == "heel_strike"
    assert seg.phase_log[0][0] == "double_support:heel_contact"
    assert seg.phase_log[0][3] == "toe_off"
    led = trajectory_ledger(traj)
    assert abs(led["closure"][0]) < 1e-9 * w.energies(seg.x_start)[0]
    _ph, dense, (ta, tb) = seg.pieces[0]
    work = quad(lambda t: w.actuators.power(t, np.ravel(dense(t))[:6]), ta, tb)[0]
    assert abs(work) > 1e-4


#: configs/flat_feet_stairs.yaml's gait (walkerlab fixedpoint, residual 1e-12): a double
#: support of 0.089 s
X_STAIRS = np.array([-0.2085977875988514, 0.19788858329242512, 0.0, -0.678053594293201,
                     -0.6909968032500822, -3.626474337081283])
#: its three largest Floquet multipliers, from the variational equations with every row at
#: DOP853's rtol = atol = 1e-12 (63,883 right-hand sides, 51 s)
MULT_STAIRS = np.array([-0.9463292629637, 0.6084184220007, -6.247620381946e-04])


def test_the_variational_map_through_double_support_costs_as_much_as_the_map():
    """The double support's Jacobian is central differences (round-off ~2e-10): its
    variational rows integrated at the scene's 1e-12 made DOP853 chase that noise (48x the
    map's right-hand sides, 51 s, past the gait search's 60 s CPU budget on a busy
    machine); at the floor ``Phase.jacobian_rtol`` the variational map costs about what
    the map does, and its multipliers equal the tight integration's to 1e-8 and the
    map's central differences to their own error bound."""
    import walkerlab as wl
    from walkerlab.analysis.gait.poincare import (
        map_fd_jacobian,
        multiplier_check_tolerance,
        poincare_map,
    )

    w = wl.Walker.from_scene(ROOT / "configs/flat_feet_stairs.yaml")
    _x, _T, nfev_plain = poincare_map(w.model, X_STAIRS, w.solver)
    _x, _T, DP, nfev_var = poincare_map(w.model, X_STAIRS, w.solver, jacobian=True)
    assert nfev_var < 2 * nfev_plain, (nfev_var, nfev_plain)
    mult = np.linalg.eigvals(DP)
    mult = mult[np.argsort(-np.abs(mult))][:3]
    assert np.max(np.abs(mult.imag)) == 0.0
    np.testing.assert_allclose(mult.real, MULT_STAIRS, rtol=0, atol=1e-8)
    J_fd, _nfev = map_fd_jacobian(w.model, X_STAIRS, w.solver)
    assert np.max(np.abs(DP - J_fd)) < multiplier_check_tolerance(w.solver, 1e-7) * (
        1 + np.max(np.abs(DP)))


def test_lsoda_walks_the_stairs_gait_through_heel_off():
    """configs/flat_feet_stairs.yaml's gait on LSODA at the scene's 1e-12 returns to
    itself (it fell as heel off began: a guard at 0 there counted as crossed)."""
    import dataclasses

    import walkerlab as wl
    from walkerlab.analysis.gait.poincare import poincare_map

    w = wl.Walker.from_scene(ROOT / "configs/flat_feet_stairs.yaml")
    lsoda = dataclasses.replace(w.solver, method="LSODA", backend="scipy")
    x_next, period, _nfev = poincare_map(w.model, X_STAIRS, lsoda)
    assert np.max(np.abs(x_next - X_STAIRS)) < 1e-9
    assert abs(period - 0.9005215793) < 1e-9
