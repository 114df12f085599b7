"""The compliant-contact view of flat feet on ankle springs (issue 22; Wisse et al. 2006):
the floating view against an independent hand-written reference, energy balance of a
contact run, the static heel/toe load split, and the contact section's one-line error."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tests.independent import flat_feet_floating_reference as ref
from walkerlab.codegen.floating import FLAT_FOOT_MESSAGE
from walkerlab.config import scene_from_dict
from walkerlab.models.contact.model import ContactWalker
from walkerlab.models.contact.scene import ContactSceneError, build
from walkerlab.models.hybrid.floating_view import FloatingView
from walkerlab.walker.description import walker_data
from walkerlab.walker.layout import StateIndex
from walkerlab.walker.plant import Plant

FOOT = {"kind": "flat", "heel_m": 0.05, "toe_m": 0.10,
        "ankle": {"stiffness_n_m_per_rad": 90.0, "rest_angle_rad": 0.03,
                  "damping_n_m_s_per_rad": 0.0}}
SCENE = {"name": "flat_contact_test",
         "walker": {"model": "biped", "coordinates": "absolute", "hip_mass_kg": 10.0,
                    "leg": {"length_m": 1.0, "foot": FOOT,
                            "bodies": [{"kind": "point_mass", "name": "mass",
                                        "mass_kg": 5.0, "from_hip_m": 0.5}]}},
         "slope": {"angle_rad": 0.04},
         "contact": {"flat_foot_mass_kg": 0.1, "flat_foot_inertia_kg_m2": 5e-4},
         "terrain": {"kind": "continuous"}}
MF, IF = 0.1, 5e-4


def _scene(slope=0.04, damping=0.0, contact=True, rest=None):
    d = copy.deepcopy(SCENE)
    d["slope"]["angle_rad"] = slope
    d["walker"]["leg"]["foot"]["ankle"]["damping_n_m_s_per_rad"] = damping
    if rest is not None:
        d["walker"]["leg"]["foot"]["ankle"]["rest_angle_rad"] = rest
    if not contact:
        d["contact"] = {}
    return scene_from_dict(d, "flat_contact_test.yaml")


def _ref_params(sc) -> dict:
    a = FOOT["ankle"]
    return {"MH": 10.0, "m": 5.0, "d": 0.5, "L": 1.0, "mf": MF, "If": IF, "g": 9.81,
            "k": a["stiffness_n_m_per_rad"], "r": a["rest_angle_rad"], "h": FOOT["heel_m"],
            "tt": FOOT["toe_m"]}


def _walker(slope=0.04, damping=0.0, rest=None, **kw) -> ContactWalker:
    sc = _scene(slope, damping, rest=rest)
    return ContactWalker(data=walker_data(sc.walker, sc.slope.phi_rad), flat_foot=(MF, IF),
                         **kw)


# --------------------------------------------------------------------------- floating view
def test_floating_view_matches_the_independent_reference():
    """Mass matrix, kinetic and potential energy (ankle springs included), gravity + spring
    forces and the heel/toe kinematics against tests/independent/flat_feet_floating_reference
    (hand-written numpy, no sympy).  M, T, V and the points are sums of a few products of
    O(1) numbers: 1e-12 relative is round-off; G = dV/dq by central differences (h = 1e-6:
    truncation ~h^2 V''' ~ 1e-10, round-off ~1e-16 V / h ~ 1e-8 N on |G| ~ 100 N)."""
    sc = _scene()
    view = FloatingView(walker_data(sc.walker, sc.slope.phi_rad), MF, IF)
    assert view.coordinate_names() == ("hip_x", "hip_y", "leg1_angle", "leg2_angle",
                                       "leg1_foot_angle", "leg2_foot_angle")
    assert view.contact_names() == ("leg1_heel", "leg1_toe", "leg2_heel", "leg2_toe")
    p = _ref_params(sc)
    rng = np.random.default_rng(22)
    for _ in range(5):
        q = rng.normal(size=6) * np.array([0.3, 0.3, 0.4, 0.4, 0.6, 0.6]) + [0, 1, 0, 0, 0, 0]
        dq = rng.normal(size=6)
        M = view.mass_matrix(q)
        np.testing.assert_allclose(M, ref.mass_matrix(q, p), rtol=0, atol=1e-12 * 20)
        T, V = view.energies(np.concatenate([q, dq]))
        assert float(T) == pytest.approx(ref.kinetic(q, dq, p), rel=1e-12)
        assert float(V) == pytest.approx(ref.potential(q, p), rel=1e-12, abs=1e-10)
        G = np.array([(ref.potential(q + 1e-6 * e, p) - ref.potential(q - 1e-6 * e, p)) / 2e-6
                      for e in np.eye(6)])
        np.testing.assert_allclose(view.gravity(q), G, rtol=0, atol=1e-6)
        P, Vel, J = view.contact_points(q, dq)
        for i, name in enumerate(view.contact_names()):
            pos, vel = ref.heel_toe(q, dq, p)[name]
            np.testing.assert_allclose(P[i], pos, atol=1e-14)
            np.testing.assert_allclose(Vel[i], vel, atol=1e-13)
            np.testing.assert_allclose(J[i] @ dq, vel, atol=1e-13)


def test_free_flight_conserves_the_reference_energy():
    """High above the ground (no contact) with undamped ankles the flow conserves the
    reference's T + V: checks the generated bias h (Coriolis, gravity, ankle springs) against
    an energy written by hand.  DOP853 at rtol 1e-12 over 0.4 s keeps a conserved quantity to
    ~1e-11 of its ~300 J scale; 1e-8 J leaves room and still catches any wrong term
    (a 1 % error in one Coriolis term moves E by ~1e-2 J here)."""
    w = _walker()
    p = _ref_params(None)
    q0 = np.array([0.0, 3.0, 0.3, -0.2, 0.5, -0.4])
    dq0 = np.array([0.5, 0.2, -1.5, 2.0, 8.0, -6.0])
    sol = solve_ivp(lambda t, x: w.rhs(t, x), (0.0, 0.4), np.concatenate([q0, dq0]),
                    method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True)
    assert sol.status == 0
    E = [ref.kinetic(x[:6], x[6:], p) + ref.potential(x[:6], p)
         for x in sol.sol(np.linspace(0, 0.4, 9)).T]
    assert np.ptp(E) < 1e-8
    # the feet's angles really moved against their springs (the check is not vacuous)
    assert np.ptp(sol.y[4]) > 0.2


# --------------------------------------------------------------------------- contact run
def test_contact_run_energy_balance():
    """A contact run from heel contact through the foot slap (0.05 s): the walker's mechanical
    energy (kinetic + gravity + ankle springs, ``walker.energies``) changes by exactly the
    work of the contact forces at the heel and toe points (``power`` = F . v of each material
    point from the contact table: elastic + damping + friction) minus the ankle dampers'
    dissipation ``c ddelta^2``.  The work is integrated as an extra state beside the walker's
    (LSODA, rtol 1e-10), so the balance is exact up to the integrator: measured residual
    1.3e-9 J at rtol 1e-10 (4e-7 J at 1e-8: it follows rtol) on 5.1 J given to the ground and
    0.18 J to the dampers; 1e-7 J is ~75x that and far below the damper's own share, which
    the balance must contain."""
    from walkerlab.analysis.contact.sim import initial_state_from_ideal

    c = 0.02  # N m s/rad: I_foot / c = 25 ms, the foot still slaps at ~0.02 s
    # the trailing foot (leg1) at its rest angle reaches below the slope (the rigid view's
    # massless foot snapped to rest): as on the checkerboard, leg1's lane has ground only ahead
    w = _walker(damping=c, lane1=np.array([0.85]), lane2=np.array([0.075]), continuous=False,
                patch_half_width=0.2)
    x0 = initial_state_from_ideal(w, -0.45, 0.34, 0.0, -1.79, -1.47, -19.3)
    idx = StateIndex(w)
    n = w.nq
    ankles = [(idx.rate_of(f"theta{i}_foot"), idx.rate_of(f"theta{i}")) for i in (1, 2)]

    def rates(t, y):
        x = y[:2 * n]
        cq = w.contact_quantities(x[None])
        power = sum(q["power"][0] for q in cq.values())
        damper = c * sum((x[a] - x[b]) ** 2 for a, b in ankles)
        return np.concatenate([w.rhs(t, x), [power - damper, damper]])

    def jac(t, y):
        J = np.zeros((2 * n + 2, 2 * n + 2))
        J[:2 * n, :2 * n] = w.jac(t, y[:2 * n])
        return J

    sol = solve_ivp(rates, (0.0, 0.05), np.concatenate([x0, [0.0, 0.0]]), method="LSODA",
                    jac=jac, rtol=1e-10, atol=1e-12)
    assert sol.status == 0
    X = sol.y[:2 * n].T
    assert w.contact_quantities(X)["leg2_toe"]["normal_force"].max() > 0  # the foot slapped
    E = w.energies(X)["total"]
    work, damped = sol.y[2 * n, -1], sol.y[2 * n + 1, -1]
    assert abs((E[-1] - E[0]) - work) < 1e-7
    assert damped > 0.1
    assert abs(work) > 1.0


def test_step_modes_match_the_rigid_view():
    """One step from the rigid view's fixed point of the flat-footed walker of
    configs/flat_feet.yaml (k = 120 N m/rad, c = 3 N m s/rad, slope 0.04 rad; fixed point as
    found by ``walkerlab fixedpoint``): the contact table's modes of the stance foot (leg2)
    come in the rigid view's order, heel contact -> foot flat -> heel off, ended by leg1's
    heel strike, each switch within 25 ms of the rigid one (measured 3, 17 and 16 ms: the
    compliant heel and toe and the regularised foot delay the switches; a wrong lever arm or
    spring sign moves them by 100 ms or changes the order)."""
    from walkerlab.analysis.contact.gait import foot_modes, gait_events
    from walkerlab.analysis.contact.sim import initial_state_from_ideal
    from walkerlab.integrate.contact import ContactLimits, integrate_contact
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.hybrid.rigid_foot_modes import make_flat_walker, mode_of, mode_sequence

    d = copy.deepcopy(SCENE)
    d["walker"]["leg"]["foot"]["ankle"].update(
        {"stiffness_n_m_per_rad": 120.0, "rest_angle_rad": 0.0, "damping_n_m_s_per_rad": 3.0})
    sc = scene_from_dict(d, "flat_contact_test.yaml")
    data = walker_data(sc.walker, sc.slope.phi_rad)
    x_fp = np.array([-0.34737908341078194, 0.2559008258426576, 0.0, -1.3354750163219804,
                     -1.19097630756149, -11.344377412280023])
    seg = integrate_step(make_flat_walker(data, double_support=False), x_fp,  # the old gait
                         Solver("DOP853", 1e-10, 1e-10))
    assert mode_sequence(seg.phase_log) == ["heel_contact", "foot_flat", "heel_off"]
    rigid = [(mode_of(name), ta) for name, ta, _tb, _end in seg.phase_log]
    switches = [ta for (m, ta), (m0, _) in zip(rigid[1:], rigid[:-1]) if m != m0]
    w = ContactWalker(data=data, flat_foot=(MF, IF), lane1=np.array([0.598 + 0.075]),
                      lane2=np.array([0.075]), continuous=False, patch_half_width=0.3)
    x0 = initial_state_from_ideal(w, *x_fp)
    run = integrate_contact(w, x0, 0.0, 0.8, Solver(method="cyrk_bdf", rtol=1e-8, atol=1e-10),
                            ContactLimits(sample_rate_hz=2000.0))
    ev = gait_events(w, run.t, run.X)
    assert ev["hs_leg"][:1] == ["leg1"]
    t_hs = float(ev["hs_t"][0])
    modes = [(m, a) for m, a, b in foot_modes(run.t, ev["points"], "leg2", 0.0, t_hs)
             if b - a > 2e-3]  # a toe's first millisecond on the ground is not a mode
    assert [m for m, _ in modes] == ["heel_contact", "foot_flat", "heel_off"]
    # the step's record (contact_sim.h5 steps/stance_foot_modes) says the same
    assert [p.split(" (")[0] for p in ev["steps"][0].foot_modes.split(" > ")] == \
        ["heel_contact", "foot_flat", "heel_off"]
    contact_switches = [a for _, a in modes[1:]] + [t_hs]
    assert len(switches) == 2
    np.testing.assert_allclose(contact_switches, switches + [seg.t_end], atol=0.025)


def test_standing_foot_carries_its_load_by_moment_balance():
    """A walker at rest (not in equilibrium) on leg2's flat foot (leg1 hanging over a gap):
    the heel and toe forces of the contact table carry the load as Newton-Euler says.  The
    ground's total force is ``sum_i m_i (a_i - g)`` over the point masses (hip, legs, feet
    at the ankles), and the toe's share follows from the moment balance about the heel:
    ``(r_toe - r_heel) x F_toe = sum_i (r_i - r_heel) x m_i (a_i - g) + I_f (psi1'' +
    psi2'')`` (the heel force has no moment there; friction, along the sole, none either).
    Positions and Jacobians come from the independent reference (finite differences,
    ~1e-9), accelerations ``a_i = J_i qdd`` at rest from the contact model's ``rhs``; the
    forces agree to 1e-6 relative (the FD Jacobians' error times qdd)."""
    w = _walker(slope=0.02, lane1=np.array([50.0]), lane2=np.array([0.075]),
                continuous=False, patch_half_width=0.3)
    p = _ref_params(None)
    idx = StateIndex(w)
    n = w.nq
    gamma = 0.02
    # leg2 leaning slightly forward, its foot flat on the slope at static-like depth, leg1
    # hanging; the ankle spring deflected (its torque is internal: it must not matter)
    q = np.zeros(n)
    q[[idx["theta1"], idx["theta2"], idx["theta1_foot"], idx["theta2_foot"]]] = \
        [0.05, -0.03, 0.08, -gamma - 1e-4]  # the toe 1.5e-5 m deeper than the heel
    heel0 = ref.heel_toe(q, np.zeros(n), p)["leg2_heel"][0]
    depth = w.static_penetration(0.5 * w.total_mass * w.g)
    target = np.array([0.0, 0.0]) - depth * np.array([np.sin(gamma), np.cos(gamma)])
    q[idx["hip_x"]], q[idx["hip_y"]] = target - heel0
    x = np.concatenate([q, np.zeros(n)])
    qdd = w.rhs(0.0, x)[n:]
    cq = w.contact_quantities(x[None])
    Fh, Ft = (cq[f"leg2_{e}"]["normal_force"][0] for e in ("heel", "toe"))
    assert Fh > 10 and Ft > 1.3 * Fh  # both ends loaded, unequally
    assert cq["leg1_heel"]["normal_force"][0] == cq["leg1_toe"]["normal_force"][0] == 0.0

    def pos(qq):  # the point masses: (mass, position) from the reference's geometry
        x_, y_, th1, th2 = qq[:4]
        hip = np.array([x_, y_])
        out = [(p["MH"], hip)]
        for th in (th1, th2):
            e = np.array([np.sin(th), -np.cos(th)])
            out += [(p["m"], hip + p["d"] * e), (p["mf"], hip + p["L"] * e)]
        return out

    def accel(k):  # a_k = J_k qdd at rest, J_k by central differences of the positions
        J = np.stack([(pos(q + 1e-6 * e)[k][1] - pos(q - 1e-6 * e)[k][1]) / 2e-6
                      for e in np.eye(n)], axis=1)
        return J @ qdd

    def cross(a, b):
        return float(a[0] * b[1] - a[1] * b[0])

    g = np.array([0.0, -p["g"]])
    pts = ref.heel_toe(q, np.zeros(n), p)
    rh, rt = pts["leg2_heel"][0], pts["leg2_toe"][0]
    F = np.zeros(2)
    mom = 0.0
    for k, (m, r) in enumerate(pos(q)):
        f = m * (accel(k) - g)
        F += f
        mom += cross(r - rh, f)
    mom += p["If"] * (qdd[idx["theta1_foot"]] + qdd[idx["theta2_foot"]])
    normal = np.array([np.sin(gamma), np.cos(gamma)])
    assert F @ normal == pytest.approx(Fh + Ft, rel=1e-6)
    # toe force along the normal (friction is 0 at rest: mu(0) = 0)
    assert cross(rt - rh, Ft * normal) == pytest.approx(mom, rel=1e-6)


# --------------------------------------------------------------------------- settings
def test_flat_feet_need_their_mass_in_the_contact_section():
    sc = _scene(contact=False)
    with pytest.raises(ContactSceneError) as exc:
        build(sc, np.array([-0.45, 0.34, 0.0, -1.79, -1.47, -19.3]), 4, plant=Plant.from_scene(sc))
    msg = str(exc.value)
    assert "\n" not in msg and "contact.flat_foot_mass_kg" in msg
    with pytest.raises(ValueError, match="flat_foot_mass_kg"):
        ContactWalker(data=walker_data(sc.walker, sc.slope.phi_rad))
    assert FLAT_FOOT_MESSAGE in msg


def test_a_flat_stance_foot_cannot_be_pinned():
    d = copy.deepcopy(SCENE)
    d["contact_sim"] = {"pin_stance_until": "first_touchdown"}
    with pytest.raises(ContactSceneError, match="pin_stance_until: pinning the stance foot "
                       "needs point feet") as exc:
        sc = scene_from_dict(d, "f.yaml")
        build(sc,
              np.array([-0.35, 0.26, 0.0, -1.3, -1.2, -11.3]), 4, plant=Plant.from_scene(sc))
    assert "\n" not in str(exc.value)


def test_point_feet_keep_one_contact_point_per_leg():
    """The paper walker's contact table keeps its rows ``leg1``, ``leg2``."""
    w = ContactWalker()
    assert w.contact_names() == ("leg1", "leg2")
    x = np.zeros(2 * w.nq)
    x[1] = 1.0
    assert tuple(w.contact_quantities(x[None])) == ("leg1", "leg2")
    assert w.foot_quantities(x[None]).keys() == w.contact_quantities(x[None]).keys()


def test_floating_view_matches_pinocchio():
    """The flat-footed floating view's mass matrix and bias against Pinocchio's CRBA and RNEA
    on a model built here (hip sliding in x and z, legs and feet on revolute joints about -y,
    the feet's joints relative to their legs: ``q_pin = [x, z, th1, d1, th2, d2]``, ours
    ``T q_pin`` with ``psi = th + d``; so ``M_pin = T^T M T`` and ``rnea = T^T (M T a + h)``
    minus the ankle springs, which Pinocchio does not model).  Round-off agreement: 1e-10."""
    pin = pytest.importorskip("pinocchio")
    sc = _scene()
    view = FloatingView(walker_data(sc.walker, sc.slope.phi_rad), MF, IF)
    p = _ref_params(None)
    model = pin.Model()
    model.gravity.linear = np.array([0.0, 0.0, -p["g"]])
    axis = np.array([0.0, -1.0, 0.0])  # a positive angle puts the foot ahead (+x)

    def inertia(m, c, I_y=0.0):
        return pin.Inertia(m, np.asarray(c, float), np.diag([0.0, I_y, 0.0]))

    jx = model.addJoint(0, pin.JointModelPX(), pin.SE3.Identity(), "hip_x")
    jz = model.addJoint(jx, pin.JointModelPZ(), pin.SE3.Identity(), "hip_z")
    model.appendBodyToJoint(jz, inertia(p["MH"], [0, 0, 0]), pin.SE3.Identity())
    for leg in ("leg1", "leg2"):
        jl = model.addJoint(jz, pin.JointModelRevoluteUnaligned(axis), pin.SE3.Identity(), leg)
        model.appendBodyToJoint(jl, inertia(p["m"], [0, 0, -p["d"]]), pin.SE3.Identity())
        ja = model.addJoint(jl, pin.JointModelRevoluteUnaligned(axis),
                            pin.SE3(np.eye(3), np.array([0.0, 0.0, -p["L"]])), f"{leg}_ankle")
        model.appendBodyToJoint(ja, inertia(p["mf"], [0, 0, 0], p["If"]), pin.SE3.Identity())
    data = model.createData()
    T = np.zeros((6, 6))  # ours = T pin; pin order [x, z, th1, d1, th2, d2]
    T[0, 0] = T[1, 1] = 1.0
    T[2, 2] = T[3, 4] = 1.0
    T[4, 2] = T[4, 3] = 1.0
    T[5, 4] = T[5, 5] = 1.0
    rng = np.random.default_rng(7)
    for _ in range(4):
        qp, vp, ap = rng.normal(size=(3, 6)) * 0.5
        q, dq = T @ qp, T @ vp
        M = view.mass_matrix(q)
        np.testing.assert_allclose(pin.crba(model, data, qp), T.T @ M @ T, atol=1e-10)
        spring = np.zeros(6)
        for th, ps in ((2, 4), (3, 5)):
            tau = p["k"] * (q[ps] - q[th] - p["r"])
            spring[ps] += tau
            spring[th] -= tau
        rhs = T.T @ (M @ (T @ ap) + view.bias(q, dq) - spring)
        np.testing.assert_allclose(pin.rnea(model, data, qp, vp, ap), rhs, atol=1e-10)
