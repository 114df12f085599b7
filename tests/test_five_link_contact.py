"""The five-link biped (free knees, hinged torso) in the compliant-contact view: its floating
mechanics and its joint torques against the independent derivation
(tests/independent/five_link.py: relative joint coordinates, stance foot pinned or free, no
walkerlab code), and RABBIT (configs/rabbit.yaml) walking on compliant contact against its
rigid gait."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.independent import five_link as ref
from tests.test_five_link import SCENE, P, states, to_ref
from walkerlab.config import scene_from_dict
from walkerlab.models.contact.model import ContactWalker
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

#: every test here shares the independent sympy model (tests/independent/five_link.py, ~8 s
#: of CPU to build): one worker builds it once
pytestmark = pytest.mark.xdist_group("five_link_reference")

ROOT = Path(__file__).resolve().parents[1]
#: RABBIT's rigid step period [s] (tests/test_rabbit.py, walkerlab fixedpoint)
RIGID_PERIOD_S = 0.37093
#: floating coordinate of each rigid role (leg2 in stance: the rigid step's first roles)
ROLE_COORD = {"stance_shank": "leg2_shank_angle", "stance_thigh": "leg2_thigh_angle",
              "swing_thigh": "leg1_thigh_angle", "swing_shank": "leg1_shank_angle",
              "torso": "torso_angle"}
ROLES = tuple(ROLE_COORD)


def _scene(actuated: bool):
    cfg = copy.deepcopy(SCENE)
    if actuated:  # RABBIT's PD laws on their phase references, unsaturated
        torques = yaml.safe_load((ROOT / "configs" / "rabbit.yaml").read_text())[
            "walker"]["actuation"]["torques"]
        for t in torques:
            t["max_torque_n_m"] = None
        cfg["walker"]["actuation"] = {"torques": torques}
    return scene_from_dict(cfg)


@pytest.fixture(scope="module")
def walker():
    """The contact walker of the test biped (hip mass, slope 0.05) with no ground under
    either foot (lanes without patches), so only the mechanics act."""
    data = walker_data(_scene(False).walker, 0.05)
    return ContactWalker(data=data, continuous=False)


def _floating(walker, x_role):
    """Full floating state (leg1 swinging, leg2's foot at the origin and at rest) of a rigid
    role state (ss, st, wt, ws, t, rates)."""
    z = walker.link_state_from_ideal(x_role)
    return walker.pinned_to_full(z, np.zeros(2))


def _role_of(walker, v):
    """Floating link values (nq,) -> the rigid role order (5,)."""
    coords = walker.coordinate_names()
    return np.array([v[coords.index(ROLE_COORD[r])] for r in ROLES])


def test_floating_coordinates_name_the_torso(walker):
    assert walker.coordinate_names() == ("hip_x", "hip_y", "leg1_thigh_angle",
                                         "leg1_shank_angle", "leg2_thigh_angle",
                                         "leg2_shank_angle", "torso_angle")
    assert walker.state_names()[6] == "theta_torso"
    assert walker.state_names()[13] == "dtheta_torso"
    assert walker.knee_stop_quantities(np.zeros(14)) == {}  # free knees: no stop


def test_mass_matrix_is_the_independent_extended_one(walker):
    """The floating mass matrix, carried to the independent model's extended coordinates
    ``(th, h1, h2, k1, k2, x_f, y_f)`` (stance foot free) by the Jacobian of the map between
    them, is the independent ``De`` (the kinetic energy is the same function)."""
    lt, ls = P["lt"], P["ls"]
    # absolute link angles (leg1_thigh, leg1_shank, leg2_thigh, leg2_shank, torso) of the
    # relative ones: the swing leg is leg1 (h2, k2), the stance leg leg2 (h1, k1)
    A = np.array([[1, 0, 1, 0, 0], [1, 0, 1, 0, 1], [1, 1, 0, 0, 0], [1, 1, 0, 1, 0],
                  [1, 0, 0, 0, 0]], float)
    for x in states(6, seed=11):
        r, dr = to_ref(x)
        xf = _floating(walker, x)
        a = A @ r
        # hip = foot - ls u(stance shank) - lt u(stance thigh), u(a) = (sin a, -cos a)
        dhip = np.zeros((2, 5))
        dhip[:, 3] = -ls * np.array([np.cos(a[3]), np.sin(a[3])])
        dhip[:, 2] = -lt * np.array([np.cos(a[2]), np.sin(a[2])])
        Jf = np.zeros((7, 7))
        Jf[:2, :5], Jf[:2, 5:] = dhip @ A, np.eye(2)
        Jf[2:, :5] = A
        De = np.asarray(ref._model()[2](list(r), list(dr), [P[k] for k in ref.PARAMS]), float)
        got = Jf.T @ walker.mass_matrix(xf) @ Jf
        np.testing.assert_allclose(got, De, rtol=0, atol=1e-12 * np.abs(De).max())


def _pinned_acceleration(walker, x, Q):
    """Link accelerations (nq,) of the floating walker with leg2's foot held still (no
    ground), generalised force ``Q`` (nq,) added: the KKT system of ``M qdd + h = Q + J^T
    lambda``, ``J qdd + (dJ/dt) dq = 0`` (J, dJ/dt dq from the generated ``feet``,
    ``feet_jac``)."""
    n, k = walker.nq, walker.kernels
    M, h = np.empty((n, n)), np.empty(n)
    k.dyn(x, walker.walker_params, M, h)
    P_, V, J = np.empty((2, 2)), np.empty((2, 2)), np.empty((2, 2, n))
    k.feet(x, walker.walker_params, P_, V, J)
    dV, dJtF = np.empty((2, 2, n)), np.empty((n, n))
    k.feet_jac(x, np.zeros((2, 2)), walker.walker_params, dV, dJtF)
    pin = k.PIN
    K = np.zeros((n + 2, n + 2))
    K[:n, :n], K[:n, n:], K[n:, :n] = M, -J[pin].T, J[pin]
    rhs = np.concatenate([Q - h, -dV[pin] @ x[n:]])
    return np.linalg.solve(K, rhs)[:n]


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_pinned_dynamics_match_the_independent_lagrangian(walker):
    """Passive: the floating equations with the stance foot pinned (generated ``rhs_pinned``
    and the KKT system alike) give the independent accelerations."""
    for x in states(6, seed=5):
        r, dr = to_ref(x)
        want = ref.acceleration(r, dr, P)
        xf = _floating(walker, x)
        n = walker.nq
        z = walker.pinned_state(xf)
        got_rhs = _role_of(walker, np.concatenate([[0, 0], walker.rhs_pinned(
            0.0, z, np.zeros(2))[n - 2:]]))
        got_kkt = _role_of(walker, _pinned_acceleration(walker, xf, np.zeros(n)))
        tol = 1e-9 * max(1.0, np.abs(want).max())
        for got in (got_rhs, got_kkt):
            np.testing.assert_allclose(to_ref(np.concatenate([got, got]))[0], want,
                                       rtol=0, atol=tol)


def test_joint_torques_act_as_the_independent_joint_torques():
    """RABBIT's PD laws in the contact view (:class:`JointTorqueActuators`): their
    generalised force on the floating coordinates moves the pinned walker as the same
    torques on the independent model's relative joints do (``Q = (0, tau_stance_hip,
    tau_swing_hip, tau_stance_knee, tau_swing_knee)``); the joint angles are the independent
    relative coordinates and the phase variable its hip-to-stance-foot angle; with the legs'
    roles swapped (leg1 in stance) the same torques land on the other leg."""
    from walkerlab.models.contact.actuation import powered_rhs
    from walkerlab.models.contact.joint_torques import JointTorqueActuators

    sc = _scene(True)
    data = walker_data(sc.walker, 0.05)
    acts = JointTorqueActuators(data, sc.walker.actuation, ContactWalker(
        data=data).coordinate_names())
    w = ContactWalker(data=data, continuous=False, actuators=acts)
    order = [t.joint for t in sc.walker.actuation.torques]
    for x in states(4, seed=7):
        r, dr = to_ref(x)
        xf = _floating(w, x)
        deltas, ddeltas, s, ds = acts.rigid.joint_angles(acts.role_state(xf, 1))
        rel = dict(zip(("stance_hip", "swing_hip", "stance_knee", "swing_knee"), r[1:]))
        assert np.allclose([deltas[order.index(j)] for j in rel], list(rel.values()),
                           atol=1e-14)
        foot, hip = (np.asarray(v, float).ravel() for v in ref._model()[5](
            list(r), [0.0] * 5, [P[k] for k in ref.PARAMS]))
        assert s == pytest.approx(np.arctan(-hip[0] / hip[1]), abs=1e-14)
        tau = acts.torques(xf, 1, 0.0)
        Q, power = acts.hip_torque(xf, 1, 0.0)
        assert power == pytest.approx(float(tau @ np.asarray(ddeltas)), rel=1e-12)
        Qr = np.zeros(5)
        for j, v in zip(order, tau):
            Qr[1 + list(rel).index(j)] = v
        want = ref.acceleration(r, dr, P, Qr)
        got = _role_of(w, _pinned_acceleration(w, xf, Q))
        np.testing.assert_allclose(to_ref(np.concatenate([got, got]))[0], want, rtol=0,
                                   atol=1e-9 * max(1.0, np.abs(want).max()))
        # the legs' roles swapped: leg1 in stance, the state mirrored onto the other leg
        coords = w.coordinate_names()
        swap = [coords.index(c) for c in ("hip_x", "hip_y", "leg2_thigh_angle",
                                           "leg2_shank_angle", "leg1_thigh_angle",
                                           "leg1_shank_angle", "torso_angle")]
        xs = np.concatenate([xf[:w.nq][swap], xf[w.nq:][swap]])
        np.testing.assert_allclose(acts.torques(xs, 0, 0.0), tau, rtol=1e-14)
        np.testing.assert_allclose(acts.hip_torque(xs, 0, 0.0)[0], Q[swap], rtol=1e-14)
        # the powered right-hand side the contact runs integrate: the same acceleration,
        # the ledger's hip powers split by sign (point feet: no flat feet's dampers)
        dx, powers = powered_rhs(w, xf, 1)
        passive = np.array(w.rhs(0.0, xf), float)[w.nq:]
        np.testing.assert_allclose(dx[w.nq:], passive + np.linalg.solve(w.mass_matrix(xf), Q),
                                   rtol=1e-12, atol=1e-12)
        assert powers[:2] == pytest.approx([max(power, 0.0), min(power, 0.0)], rel=1e-12)


def test_contact_view_carries_a_push_off_on_a_five_link_biped():
    """A push-off on a five-link biped (refused before issue 48's contact actuation) is
    carried: the pulse at the trailing foot along the line to the hip."""
    from walkerlab.models.contact.scene import contact_setup

    cfg = yaml.safe_load((ROOT / "configs" / "rabbit.yaml").read_text())
    cfg["walker"]["actuation"]["push_off"] = {"impulse_n_s": 1.0}
    sc = scene_from_dict(cfg)
    acts = contact_setup(sc, plant=Plant.from_scene(sc)).actuators
    assert acts.spec.push_off is not None and acts.pulse_s > 0.0


@pytest.mark.parametrize("start", [{"start": "periodic_gait"}, {"periodic_gait": True}])
def test_a_five_link_contact_periodic_gait_is_refused_in_one_line(start):
    """The contact periodic gait's step map carries straight legs' hip torques and
    push-off, not a five-link biped's joint torques: its start (or ``periodic_gait``,
    ``wl.ContactWalker.periodic_gait``) is refused in one line naming the field; it was an
    internal error ('JointTorqueActuators' object has no attribute 'laws')."""
    from walkerlab.models.contact.scene import ContactSceneError, contact_setup

    cfg = yaml.safe_load((ROOT / "configs" / "rabbit.yaml").read_text())
    cfg["contact_sim"].update(start)
    with pytest.raises(ContactSceneError, match="contact_sim.start / periodic_gait") as e:
        sc = scene_from_dict(cfg)
        contact_setup(sc, plant=Plant.from_scene(sc))
    assert "\n" not in str(e.value)
    sc = scene_from_dict(cfg | {"contact_sim": {}})
    contact_setup(sc, plant=Plant.from_scene(sc))  # the rigid start: carried


@pytest.mark.slow  # 80-130 s: 11 heel strikes of RABBIT on compliant contact (solve_ivp,
#                   ~27000 right-hand sides with the PD laws evaluated in Python)
def test_rabbit_walks_on_contact_at_its_rigid_step_period():
    """configs/rabbit.yaml on the compliant contact from its rigid fixed point (the scene's
    initial guess, the fixed point to 10 digits): 5 strides (11 heel strikes, the strides cap
    of contact-sim), alternating legs, every
    step period within 3 % of the rigid one (measured: within 0.3 %), the energy ledger
    closing to 1e-4 of the kinetic energy (measured ~1e-6) with the contact forces' work
    negative (their dissipation: damping and friction) and no push-off."""
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.config import load_scene
    from walkerlab.models.contact.actuation import WORK_NAMES
    from walkerlab.models.contact.scene import contact_setup
    from walkerlab.models.registry import build_walker

    sc = load_scene(ROOT / "configs" / "rabbit.yaml")
    x = sc.fixedpoint.initial_guess.as_array(build_walker(Plant.from_scene(sc)).state_names())
    walker, res, _x0, _sl = simulate_from(contact_setup(sc,
            plant=Plant.from_scene(sc)), x, RIGID_PERIOD_S, strides=5)
    assert res.outcome.kind == "heel_strike", res.message
    hs = res.heel_strike_times
    assert len(hs) >= 11  # >= 10 step periods
    assert list(res.heel_strike_legs[:4]) == ["leg1", "leg2", "leg1", "leg2"]
    periods = np.diff(hs)
    assert np.all(np.abs(periods / RIGID_PERIOD_S - 1) < 0.03), periods
    E = walker.energies(res.x)
    resid = (E["total"] - E["total"][0]) - res.work.sum(axis=1)
    assert np.abs(resid).max() <= 1e-4 * E["kinetic"].mean()
    w = dict(zip(WORK_NAMES, res.work[-1]))
    assert w["contact"] < 0 and w["push_off"] == 0.0
    assert w["hip_torque_positive"] > 0 > w["hip_torque_negative"]
