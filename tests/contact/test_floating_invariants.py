"""The rigid hybrid view and the floating (contact) view of every shipped walker with masses
are one walker (issue 17, part 6): both are generated from the same description, by two
different derivations (the rigid one with the stance foot pinned from the start,
:mod:`walkerlab.codegen.legged`; the floating one with hip coordinates,
:mod:`walkerlab.codegen.floating`).

Tolerances: the exact identities (pinned mass matrix, impact projections) compare the same
closed forms reached by different algebra, in double precision: 1e-12 relative leaves ~1e3 x
round-off.  Dynamic checks state their own tolerance next to them.
"""

import re
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from walkerlab.codegen.cache import functions
from walkerlab.codegen.floating import MASSLESS_MESSAGE
from walkerlab.config import load_scene
from walkerlab.config.contact import ContactSettings
from walkerlab.models.contact.assembly import NINFO
from walkerlab.models.contact.laws import contact_params_si, knee_stop_si
from walkerlab.models.contact.model import ContactWalker
from walkerlab.models.hybrid.floating_view import FloatingView
from walkerlab.walker.description import walker_data

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
WALKERS = ("paper", "paper_rods", "kneed", "round_feet", "goswami1996")


def _data(name):
    sc = load_scene(CONFIGS / f"{name}.yaml")
    return walker_data(sc.walker, sc.slope.phi_rad)


def _walker(data, **kw):
    """Contact walker of ``data`` with no ground under either foot (free flight)."""
    return ContactWalker(contact=contact_params_si(ContactSettings()), data=data,
                         lane1=np.array([1e3]), lane2=np.array([-1e3]), continuous=False, **kw)


def _link_map(structure):
    """A (nq - 2, n_rigid): link angles (leg1 = swing, leg2 = stance) from the rigid
    coordinates (absolute; kneed: swing thigh, swing shank, stance with a straight knee)."""
    if structure.knee:
        return np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [0, 0, 1.0]])
    return np.eye(2)


def _pinned_jacobian(w, q_links):
    """Jp (nq, nq - 2): floating rates from link rates with leg2's material contact point
    at rest (the rigid model's stance foot; rolling for arc feet)."""
    x = np.zeros(2 * w.nq)
    x[2:w.nq] = q_links
    P, V, J = np.empty((2, 2)), np.empty((2, 2)), np.empty((2, 2, w.nq))
    w.kernels.feet(x, w.walker_params, P, V, J)
    Jp = np.zeros((w.nq, w.nq - 2))
    Jp[:2] = -J[1, :, 2:]
    Jp[2:] = np.eye(w.nq - 2)
    return Jp, J


def _rigid_states(structure, rng, n):
    """Random rigid states (role order), kneed ones with the swing knee straight."""
    k = 3 if structure.knee else 2
    for _ in range(n):
        q = rng.uniform(-0.4, 0.4, k)
        dq = rng.normal(0, 1.5, k)
        if structure.knee:
            q[1], dq[1] = q[0], dq[0]
        yield q, dq


@pytest.mark.parametrize("name", WALKERS)
def test_pinned_floating_mass_matrix_is_the_rigid_one(name):
    """J^T M J over the rigid coordinates (stance foot pinned, stance knee straight)."""
    data = _data(name)
    w = _walker(data)
    rigid = functions(data)
    A = _link_map(data.structure)
    worst = 0.0
    for q, dq in _rigid_states(data.structure, np.random.default_rng(1), 20):
        if data.structure.knee:  # a bent swing knee is fine for the (unlocked) flow matrix
            q[1] += 0.3
        Jp, _ = _pinned_jacobian(w, A @ q)
        T = Jp @ A
        Mf = w.mass_matrix(np.concatenate([[0.0, 0.0], A @ q]))
        Mr = rigid["matrices"](np.concatenate([q, dq]))[0]
        worst = max(worst, np.max(np.abs(T.T @ Mf @ T - Mr)) / np.max(np.abs(Mr)))
    assert worst <= 1e-12


def _project(M, C, v):
    """Plastic impulse projection: v+ = v- + M^-1 C^T L with C v+ = 0 (Drake's collision
    dynamics for an inelastic contact)."""
    Minv_Ct = np.linalg.solve(M, C.T)
    lam = -np.linalg.solve(C @ Minv_Ct, C @ v)
    return v + Minv_Ct @ lam


@pytest.mark.parametrize("name", WALKERS)
def test_heel_strike_is_the_floating_impulse_projection(name):
    """The rigid reset (impact and role swap) equals the plastic impulse at the swing foot's
    material contact point of the floating model (knees locked through the impact)."""
    data = _data(name)
    st = data.structure
    w = _walker(data)
    rigid = functions(data)
    A = _link_map(st)
    worst = 0.0
    for q, dq in _rigid_states(st, np.random.default_rng(2), 20):
        Jp, J = _pinned_jacobian(w, A @ q)
        v = Jp @ (A @ dq)
        M = w.mass_matrix(np.concatenate([[0.0, 0.0], A @ q]))
        C = J[0]  # leg1 (the swing leg) strikes
        if st.knee:  # both knees locked during the impact (rigid model's assumption)
            C = np.vstack([C, [0, 0, -1, 1, 0, 0], [0, 0, 0, 0, -1, 1]])
        vp = _project(M, C, v)
        after = rigid["reset"](np.concatenate([q, dq]))
        n = len(q)
        if st.knee:  # new roles: swing thigh, swing shank = old stance (leg2); stance = leg1
            want = np.array([vp[4], vp[5], vp[2]])
        else:
            want = np.array([vp[3], vp[2]])
        worst = max(worst, np.max(np.abs(after[n:] - want)) / np.max(np.abs(want)))
    assert worst <= 1e-12


def test_knee_strike_is_the_floating_impulse_projection():
    """The rigid knee strike (kneed walker) equals the plastic impulse that locks the swing
    knee, with the stance foot pinned and the stance knee locked."""
    data = _data("kneed")
    w = _walker(data)
    rigid = functions(data)
    A = _link_map(data.structure)
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(20):
        q = rng.uniform(-0.4, 0.4, 3)
        dq = rng.normal(0, 1.5, 3)
        Jp, J = _pinned_jacobian(w, A @ q)
        v = Jp @ (A @ dq)
        M = w.mass_matrix(np.concatenate([[0.0, 0.0], A @ q]))
        C = np.vstack([J[1], [0, 0, -1, 1, 0, 0], [0, 0, 0, 0, -1, 1]])
        vp = _project(M, C, v)
        after = rigid["knee_reset"](np.concatenate([q, dq]))
        want = np.array([vp[2], vp[3], vp[4]])
        worst = max(worst, np.max(np.abs(after[3:] - want)) / np.max(np.abs(want)))
    assert worst <= 1e-12


def _com_and_mass(w, X):
    """Centre of mass (2, k) [m] and total mass [kg] from the named points."""
    st, p = w.structure, dict(zip(w.structure.param_names, w.walker_params))
    pts = w.points(X)
    num = p.get("M_hip", 0.0) * pts["hip"]
    mass = p.get("M_hip", 0.0)
    for b in st.bodies:
        for leg in ("leg1", "leg2"):
            num = num + p[f"m_{b.name}"] * pts[f"{leg}_{b.name}"]
            mass += p[f"m_{b.name}"]
    return num / mass, mass


@pytest.mark.parametrize("name", WALKERS)
def test_free_flight_conserves_energy_and_momenta(name):
    """No contact: total energy, horizontal momentum and angular momentum about the centre of
    mass are conserved.  DOP853 at rtol 1e-11 over 0.4 s (~100 steps): the global error of
    each invariant stays below ~1e-9 of its scale; 1e-8 leaves margin and still fails for a
    missing bias term (O(1e-2) drift)."""
    data = _data(name)
    w = _walker(data)
    rng = np.random.default_rng(4)
    nq = w.nq
    x0 = np.zeros(2 * nq)
    x0[1] = 5.0  # hip 5 m up, no ground under the feet anyway
    x0[2:nq] = rng.uniform(-0.5, 0.5, nq - 2)
    x0[nq:] = rng.normal(0, 1.0, nq)
    if data.structure.knee:  # knees bent: the stops stay open
        x0[3], x0[5] = x0[2] - 0.6, x0[4] - 0.6
        x0[nq + 3], x0[nq + 5] = x0[nq + 2] - 1.0, x0[nq + 4] - 1.0
    sol = solve_ivp(w.rhs, (0, 0.4), x0, method="DOP853", rtol=1e-11, atol=1e-12,
                    dense_output=True)
    X = sol.sol(np.linspace(0, 0.4, 41)).T
    if data.structure.knee:
        assert all(q["torque"].max() == 0 for q in w.knee_stop_quantities(X).values())
    E = w.energies(X)["total"]
    p = np.array([w.mass_matrix(x) @ x[nq:] for x in X])  # generalised momenta
    com, _ = _com_and_mass(w, X)
    # angular momentum about c = p . (generalised velocity of a unit rigid rotation about c)
    xi = np.zeros((len(X), nq))
    xi[:, 0] = -(X[:, 1] - com[1])
    xi[:, 1] = X[:, 0] - com[0]
    xi[:, 2:] = 1.0
    Lc = np.sum(p * xi, axis=1)
    scale_E = np.max(np.abs(w.energies(X)["kinetic"]))
    assert np.max(np.abs(E - E[0])) <= 1e-8 * scale_E
    assert np.max(np.abs(p[:, 0] - p[0, 0])) <= 1e-8 * np.max(np.abs(p))
    assert np.max(np.abs(Lc - Lc[0])) <= 1e-8 * np.max(np.abs(p))
    assert np.ptp(Lc) < np.ptp(p[:, 2])  # the invariant, not a constant by construction


def test_massless_legs_have_no_floating_view():
    sc = load_scene(CONFIGS / "simplest.yaml")
    data = walker_data(sc.walker, sc.slope.phi_rad)
    with pytest.raises(ValueError, match=re.escape(MASSLESS_MESSAGE)):
        FloatingView(data)
    with pytest.raises(ValueError, match=re.escape(MASSLESS_MESSAGE)):
        ContactWalker(data=data)


@pytest.mark.parametrize("name", WALKERS)
def test_floating_view_api(name):
    """The agreed public API: coordinate names, M symmetric positive definite, the bias at
    rest is gravity (total weight on hip_y)."""
    data = _data(name)
    v = FloatingView(data)
    names = v.coordinate_names()
    if data.structure.knee:
        assert names == ("hip_x", "hip_y", "leg1_thigh_angle", "leg1_shank_angle",
                         "leg2_thigh_angle", "leg2_shank_angle")
    else:
        assert names == ("hip_x", "hip_y", "leg1_angle", "leg2_angle")
    q = np.concatenate([[0.3, 1.0], np.linspace(-0.3, 0.2, len(names) - 2)])
    M = v.mass_matrix(q)
    np.testing.assert_allclose(M, M.T, rtol=0, atol=1e-15)
    assert np.all(np.linalg.eigvalsh(M) > 0)
    h = v.bias(q, np.zeros(len(names)))
    assert h[0] == 0.0
    assert h[1] == pytest.approx(data.total_mass_kg * data.gravity_m_per_s2, rel=1e-14)


def _kneed_on_one_leg(knee_stop=None):
    """The kneed walker of configs/kneed.yaml standing upright on leg2 (its patch at s = 0),
    leg1 hanging over a gap, at rest."""
    data = _data("kneed")
    cs = ContactSettings() if knee_stop is None else ContactSettings(knee_stop=knee_stop)
    w = ContactWalker(contact=contact_params_si(cs), data=data,
                      knee_stop=knee_stop_si(cs.knee_stop), lane1=np.array([1e3]),
                      lane2=np.array([0.0]), patch_half_width=0.5, continuous=False)
    x0 = w.pinned_to_full(np.zeros(8), -w.static_penetration() * w.normal)
    sol = solve_ivp(w.rhs, (0, 0.3), x0, method="Radau", jac=w.jac, rtol=1e-8, atol=1e-10,
                    dense_output=True)
    assert sol.status == 0
    return w, sol.sol(np.linspace(0, 0.3, 301)).T


# the quick suite's CPU budget (README): a longer run, in `pytest -m slow`
@pytest.mark.slow
def test_kneed_walker_standing_holds_its_knee_straight_with_the_stop():
    """Standing on its stance leg (0.3 s, the inverted pendulum barely starts to fall), the
    load pushes the stance knee into hyperextension; the stop holds it within 1e-5 rad of
    straight (its static deflection under ~0.05 N m is ~(0.05 / 1e5)^(1/1.5) = 6e-6 rad),
    pressing throughout (torque > 0 at every sample after the first millisecond), and its
    torque slows the hyperextension (sign).  Without the stop the same knee hyperextends 10x
    farther."""
    w, X = _kneed_on_one_leg()
    kq = w.knee_stop_quantities(X)["leg2"]
    assert np.all(np.abs(kq["extension"]) <= 1e-5)
    assert np.all(kq["torque"][1:] > 0)
    # sign: the stop's torque decelerates the hyperextension (d/dt of shank - thigh rate)
    free = ContactWalker(contact=w.contact, data=w.data, knee_stop=type(w.knee_stop)(
        1e-12, 1.0, 0.0, 1e-5), lane1=w.lane1, lane2=w.lane2, patch_half_width=0.5,
        continuous=False)
    for x in X[10::30]:
        a_stop, a_free = w.rhs(0, x), free.rhs(0, x)
        assert (a_stop[11] - a_stop[10]) < (a_free[11] - a_free[10])
    wf, Xf = _kneed_on_one_leg({"stiffness_n_m_per_rad_pow_e": 1e-12,
                                "max_damping_n_m_s_per_rad": 0.0})
    assert wf.knee_stop_quantities(Xf)["leg2"]["extension"].max() > 10 * kq["extension"].max()


@pytest.mark.parametrize("rate", [0.5, pytest.param(2.0, marks=pytest.mark.slow), 5.0])
def test_compliant_knee_strike_loses_the_rigid_knee_strike_energy(rate):
    """A knee closing at ``rate`` [rad/s] on its stop in free flight loses the energy of the
    plastic impulse that locks it (the rigid knee strike, projected with the floating M at
    the instant of first contact).  The overdamped stop closes within ~0.5 ms, over which the
    links turn by < 3e-3 rad: the distributed impulse differs from the instantaneous one by
    O(1e-3) relative (measured 2e-5..5e-5); tolerance 5e-3.  The stop's elastic energy
    k ext^(e+1) / (e+1) is counted with the walker's."""
    data = _data("kneed")
    w = _walker(data)
    free = _walker(data, knee_stop=type(w.knee_stop)(1e-12, 1.0, 0.0, 1e-5))
    x0 = np.zeros(12)
    x0[1] = 5.0
    x0[2:6] = [0.2, 0.2 - 2e-3, 0.1, -0.5]  # leg1's knee 2e-3 rad from straight, leg2 bent
    x0[6:] = [0.3, -0.2, 0.1, 0.1 + rate, 0.0, 0.0]

    def closes(t, x):
        return x[3] - x[2]

    closes.terminal, closes.direction = True, 1
    s0 = solve_ivp(free.rhs, (0, 1), x0, method="DOP853", rtol=1e-12, atol=1e-14,
                   events=closes)
    xc = s0.y_events[0][0]
    M = w.mass_matrix(xc)
    v = xc[6:]
    vp = _project(M, np.array([[0, 0, -1.0, 1, 0, 0]]), v)
    loss_rigid = 0.5 * v @ M @ v - 0.5 * vp @ M @ vp
    t_end = s0.t_events[0][0] + 0.01
    s = solve_ivp(w.rhs, (0, t_end), x0, method="Radau", jac=w.jac, rtol=1e-10, atol=1e-12)
    x1 = s.y[:, -1]
    ks = w.knee_stop
    ext = max(x1[3] - x1[2], 0.0)
    E0 = w.energies(x0)["total"][0]
    E1 = w.energies(x1)["total"][0] + ks.k * ext ** (ks.e + 1) / (ks.e + 1)
    assert (E0 - E1) == pytest.approx(loss_rigid, rel=5e-3)


@pytest.mark.parametrize("name", WALKERS)
def test_straight_line_rhs_is_the_floating_view(name):
    """The contact walker's generated straight-line right-hand side (unrolled Cholesky)
    solves M qdd = -h of the floating view (feet in the air, knees open); 1e-12 relative."""
    data = _data(name)
    w = _walker(data)
    v = FloatingView(data)
    rng = np.random.default_rng(6)
    for _ in range(10):
        x = np.concatenate([[0.1, 3.0], rng.uniform(-0.4, 0.4, w.nq - 2),
                            rng.normal(0, 1.0, w.nq)])
        if data.structure.knee:
            x[3], x[5] = x[2] - 0.5, x[4] - 0.5
        q, dq = x[:w.nq], x[w.nq:]
        want = np.linalg.solve(v.mass_matrix(q), -v.bias(q, dq))
        np.testing.assert_allclose(w.rhs(0, x)[w.nq:], want, rtol=1e-12,
                                   atol=1e-12 * np.max(np.abs(want)))


def _constrained(w, q_links, dq_links, lock_leg1_knee):
    """Floating accelerations and multipliers with leg2's material contact point held
    (J qdd + d(J dq)/dt = 0) and the knees locked as in the rigid phase (M qdd + h = C^T L)."""
    nq = w.nq
    x = w.pinned_to_full(np.concatenate([q_links, dq_links]), np.zeros(2))
    M = w.mass_matrix(x)
    P, V, J = np.empty((2, 2)), np.empty((2, 2)), np.empty((2, 2, nq))
    w.kernels.feet(x, w.walker_params, P, V, J)
    dV, dJtF = np.empty((2, 2, nq)), np.empty((nq, nq))
    w.kernels.feet_jac(x, np.zeros((2, 2)), w.walker_params, dV, dJtF)
    h = FloatingView(w.data).bias(x[:nq], x[nq:])
    rows, rhs = [J[1]], [-(dV[1] @ x[nq:])]
    if w.structure.knee:
        rows.append(np.array([[0, 0, 0, 0, -1.0, 1]]))  # stance knee locked
        rhs.append(np.zeros(1))
        if lock_leg1_knee:
            rows.append(np.array([[0, 0, -1.0, 1, 0, 0]]))
            rhs.append(np.zeros(1))
    C = np.vstack(rows)
    m = len(C)
    K = np.block([[M, -C.T], [C, np.zeros((m, m))]])
    sol = np.linalg.solve(K, np.concatenate([-h, *rhs]))
    return sol[:nq], sol[nq:]


@pytest.mark.parametrize("name", WALKERS)
def test_pinned_floating_dynamics_are_the_rigid_flow(name):
    """With the stance foot's material point held (rolling for arc feet) and the knees locked
    as in each rigid phase, the floating dynamics (M, bias, contact Jacobians and their
    rates) give the rigid flow's accelerations: the bias term and the contact kinematics
    are the rigid walker's too, not only the mass matrix.  1e-10 relative: a 2n x 2n KKT
    solve with condition number ~1e4 on round-off-level data."""
    data = _data(name)
    w = _walker(data)
    rigid = functions(data)
    A = _link_map(data.structure)
    flows = [("flow", False)] + ([("flow_locked", True)] if data.structure.knee else [])
    for fname, locked in flows:
        worst = 0.0
        for q, dq in _rigid_states(data.structure, np.random.default_rng(7), 10):
            if data.structure.knee and not locked:
                q[1] -= 0.3
                dq[1] += 0.5
            qdd, _ = _constrained(w, A @ q, A @ dq, locked)
            want = rigid[fname](0.0, np.concatenate([q, dq]))[len(q):]
            got = qdd[2:][[0, 1, 2]] if data.structure.knee else qdd[2:]
            worst = max(worst, np.max(np.abs(got - want)) / np.max(np.abs(want)))
        assert worst <= 1e-10, fname


def test_kneed_rigid_gait_pulls_on_the_stance_knee_early_in_stance():
    """Why the kneed walker of configs/kneed.yaml buckles on compliant ground: at the start of
    its step (Tedrake's initial condition, near the fixed point) the rigid gait's locked
    stance knee needs a torque that resists *flexion* (~0.08 N m), which a one-sided stop
    (it only resists hyperextension) cannot give.  The multiplier's sign is read in the
    stop's convention: the stop adds +T to the thigh's and -T to the shank's equation."""
    data = _data("kneed")
    w = _walker(data)
    sc = load_scene(CONFIGS / "kneed.yaml")
    x = sc.fixedpoint.initial_guess.as_array(
        ["swing_thigh_angle", "swing_shank_angle", "stance_angle", "swing_thigh_rate",
         "swing_shank_rate", "stance_rate"])
    A = _link_map(data.structure)
    _, lam = _constrained(w, A @ x[:3], A @ x[3:], True)
    stop_torque_needed = -lam[2]  # C row (0, 0, 0, 0, -1, 1): Q_thigh = -lam, Q_shank = +lam
    assert stop_torque_needed < -0.05


def _latched(data, **kw):
    from walkerlab.config.contact import KneeStopSettings

    ks = knee_stop_si(KneeStopSettings(latch=True, **kw))
    return ContactWalker(contact=contact_params_si(ContactSettings()), data=data, knee_stop=ks)


def test_straight_line_rhs_is_the_array_assembly_with_contact_and_latch():
    """With both feet in the ground and both knees flexed within the latch's capture angle,
    the generated straight-line rhs (forces and latch torques printed inline) equals the
    array assembly (``_force``, which the Jacobian, the pinned dynamics and the knee table
    use) solved with M: 1e-9 relative (the contact forces reach ~1e2 N)."""
    data = _data("kneed")
    w = _latched(data)
    rng = np.random.default_rng(3)
    nq = w.nq
    for _ in range(8):
        z = np.concatenate([[-0.2, -0.2 - rng.uniform(0, 4e-3), 0.2, 0.2 - rng.uniform(0, 4e-3)],
                            rng.normal(0, 0.5, nq - 2)])
        z[5], z[7] = z[4] - 0.01, z[6] - 0.01  # knees flexing slowly: the latch pushes back
        x = w.pinned_to_full(z, -2e-4 * w.normal)  # leg2's foot 0.2 mm deep
        x[1] -= 1e-4  # both feet a little deeper
        M, P, V, J = (np.empty((nq, nq)), np.empty((2, 2)), np.empty((2, 2)),
                      np.empty((2, 2, nq)))
        info, knees = np.zeros((2, NINFO)), np.zeros((2, 5))
        Q = w.kernels._force(x, *w._args(), True, True, M, P, V, J, info, knees)
        assert np.all(knees[:, 2] < 0) and np.all(info[:, 4] > 0)  # latches hold, feet loaded
        want = np.linalg.solve(M, Q)
        np.testing.assert_allclose(w.rhs(0, x)[nq:], want, rtol=1e-9,
                                   atol=1e-9 * np.max(np.abs(want)))


def test_the_array_assembly_refuses_buffers_narrower_than_its_rows():
    """``_force`` writes each point's NINFO-entry row and each knee's 5 entries into the
    caller's arrays: narrower arrays are refused with ValueError, never written past their
    end (a 12-column ``info``, the planar kernel's width before the two dimensions merged,
    had each row's last three entries land past the buffer: heap corruption that aborted
    the process later, elsewhere)."""
    w = _latched(_data("kneed"))
    nq = w.nq
    x = np.zeros(2 * nq)
    bufs = (np.empty((nq, nq)), np.empty((2, 2)), np.empty((2, 2)), np.empty((2, 2, nq)))
    for info, knees in ((np.zeros((2, NINFO - 3)), np.zeros((2, 5))),
                        (np.zeros((2, NINFO)), np.zeros((2, 4)))):
        with pytest.raises(ValueError, match="info must be"):
            w.kernels._force(x, *w._args(), True, True, *bufs, info, knees)
    Q = w.kernels._force(x, *w._args(), True, True, *bufs, np.zeros((2, NINFO)),
                         np.zeros((2, 5)))
    assert Q.shape == (nq,) and np.all(np.isfinite(Q))


def test_knee_latch_holds_a_loaded_knee_against_flexion_and_releases_in_the_air():
    """A flexed knee (2e-3 rad, inside the capture angle) of a leg whose foot is on the
    ground gets a torque that extends it (< 0 in the stop's sign convention) and a larger
    extending acceleration than without the latch; the same leg with its foot 5 mm above the
    ground (past the 2 mm release height) is free (torque 0); a knee bent 0.1 rad (past the
    capture angle) is not snapped straight (torque 0)."""
    data = _data("kneed")
    w, off = _latched(data), _walker(data)
    on = ContactWalker(contact=w.contact, data=data)  # same ground, latch off
    z = np.array([-0.2, -0.2, 0.1, 0.1 - 2e-3, 0, 0, 0, 0], float)
    x = w.pinned_to_full(z, -w.static_penetration() * w.normal)
    T = w.knee_stop_quantities(x)["leg2"]["torque"][0]
    assert T < 0
    ext_acc = (w.rhs(0, x)[11] - w.rhs(0, x)[10]), (on.rhs(0, x)[11] - on.rhs(0, x)[10])
    assert ext_acc[0] > ext_acc[1]
    up = x.copy()
    up[:2] += 5e-3 * w.normal
    assert w.knee_stop_quantities(up)["leg2"]["torque"][0] == 0.0
    bent = w.pinned_to_full(np.array([-0.2, -0.2, 0.1, 0.0, 0, 0, 0, 0]),
                            -w.static_penetration() * w.normal)
    assert w.knee_stop_quantities(bent)["leg2"]["torque"][0] == 0.0
    assert off.knee_stop_quantities(x)["leg2"]["torque"][0] == 0.0
