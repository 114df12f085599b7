"""The 3D straight-legged walker with hip width and hip-roll joints driven by a lateral
foot-placement law (``walker.hip_roll``; ``configs/hip_width_stabilised.yaml``, Kuo 1999)
against a model written here that shares no code with its generated equations: Newton's law
for the three point masses with each body's own roll (the rotation matrices' derivatives by
hand, d'Alembert's principle projected on the coordinates), the law's torques as couples
whose generalised forces come from the bodies' angular velocities (virtual work), and the
impact solved with the impulse at the new foot as an unknown (a Lagrange multiplier)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from tests.independent.mirror_stride import stride_against, to_heel_strike
from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config.schema import Scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
SCENE = "hip_width_stabilised.yaml"
# state indices: lean (stance leg's roll), swing, stance (pitches), pelvis roll, swing roll
LEAN, SWING, STANCE, PELVIS, SWROLL = range(5)


def _raw(law=None) -> dict:
    raw = yaml.safe_load((ROOT / "configs" / SCENE).read_text())
    if law is not None:
        raw["walker"]["hip_roll"].update(law)
    return raw


def _guess(scene: Scene, names) -> np.ndarray:
    g = scene.fixedpoint.initial_guess.model_extra
    return np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")] for n in names])


class Reference:
    """The walker of ``configs/hip_width_stabilised.yaml`` from Newton's law (module
    docstring).  State ``[lean, swing, stance, pelvis roll, swing roll, rates]``: each body's
    roll about the fall line (the stance leg's is the lean), each leg's pitch from the
    vertical in its rolled sagittal plane; ``w`` the swing hip's offset along the pelvis'
    hip axis (its sign: the side); ``I_pelvis`` the pelvis' inertia about the fall line,
    ``law`` the six gains of ``walker.hip_roll``."""

    def __init__(self, g, L, gamma, M, m, a, I_pelvis, law):
        self.g, self.L, self.gamma, self.M, self.m, self.a = g, L, gamma, M, m, a
        self.I_pelvis, self.law = I_pelvis, law
        self.s = np.array([math.cos(gamma), -math.sin(gamma), 0.0])   # the fall line
        self.n = np.array([math.sin(gamma), math.cos(gamma), 0.0])    # the slope's normal
        self.z = np.array([0.0, 0.0, 1.0])
        self.S, self.Z = self._skew(self.s), self._skew(self.z)

    @staticmethod
    def _skew(v):
        return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

    def _R(self, phi):
        return Rotation.from_rotvec(phi * self.s).as_matrix()

    def _T(self, th):
        return Rotation.from_rotvec(th * self.z).as_matrix()

    def terms(self, w):
        """Each point as terms ``(roll index, pitch index or None, c)``: ``R(q_roll)
        T(q_pitch) c``; the masses (pelvis, stance leg's, swing leg's), then the swing foot,
        the stance hip."""
        L, a = self.L, self.a
        hip_st = [(LEAN, STANCE, np.array([0.0, L, 0.0]))]
        pelvis = hip_st + [(PELVIS, None, w / 2 * self.z)]
        m_st = [(LEAN, STANCE, np.array([0.0, a, 0.0]))]
        hip_sw = hip_st + [(PELVIS, None, w * self.z)]
        m_sw = hip_sw + [(SWROLL, SWING, np.array([0.0, -(L - a), 0.0]))]
        foot = hip_sw + [(SWROLL, SWING, np.array([0.0, -L, 0.0]))]
        return [(self.M, pelvis), (self.m, m_st), (self.m, m_sw)], foot, hip_st

    def kin(self, terms, q, dq):
        """Position (3,), Jacobian (3, 5) and the velocity-product term ``Jdot dq`` (3,)."""
        r, J, h = np.zeros(3), np.zeros((3, 5)), np.zeros(3)
        for ro, leg, c in terms:
            R = self._R(q[ro])
            T = self._T(q[leg]) if leg is not None else np.eye(3)
            p = R @ T @ c
            r += p
            J[:, ro] += self.S @ p
            h += self.S @ self.S @ p * dq[ro] ** 2
            if leg is not None:
                d_th = R @ self.Z @ T @ c
                J[:, leg] += d_th
                h += (2 * self.S @ d_th * dq[ro] * dq[leg]
                      + R @ self.Z @ self.Z @ T @ c * dq[leg] ** 2)
        return r, J, h

    def _omega_jacobian(self, roll, pitch, q):
        """Angular velocity Jacobian (3, 5) of a body ``R(q_roll) T(q_pitch)``."""
        W = np.zeros((3, 5))
        W[:, roll] = self.s
        if pitch is not None:
            W[:, pitch] = self._R(q[roll]) @ self.z
        return W

    def law_forces(self, q, dq):
        """Generalised forces (5,) of the hip-roll torques: a couple ``tau s`` on a leg and
        ``-tau s`` on the pelvis at each hip (the roll joint's axis is the fall line), its
        virtual work ``tau s . (omega_leg - omega_pelvis)``."""
        k_p, c_p, k_s, c_s, g_l, g_r = self.law
        tau_st = k_p * q[PELVIS] + c_p * dq[PELVIS]
        ref = g_l * q[LEAN] + g_r * dq[LEAN]
        tau_sw = -k_s * (q[SWROLL] - ref) - c_s * (dq[SWROLL] - dq[PELVIS])
        W_p = self._omega_jacobian(PELVIS, None, q)
        W_st = self._omega_jacobian(LEAN, STANCE, q)
        W_sw = self._omega_jacobian(SWROLL, SWING, q)
        return tau_st * self.s @ (W_st - W_p) + tau_sw * self.s @ (W_sw - W_p)

    def rhs(self, w):
        masses = self.terms(w)[0]
        grav = np.array([0.0, -self.g, 0.0])

        def f(t, x):
            q, dq = x[:5], x[5:]
            Mq, rhs = np.zeros((5, 5)), self.law_forces(q, dq)
            Mq[PELVIS, PELVIS] = self.I_pelvis  # its rotation: omega = dphi_p s
            for m, terms in masses:
                _, J, h = self.kin(terms, q, dq)
                Mq += m * J.T @ J
                rhs += m * J.T @ (grav - h)
            return np.concatenate([dq, np.linalg.solve(Mq, rhs)])
        return f

    def energy(self, w, x):
        q, dq = x[:5], x[5:]
        e = 0.5 * self.I_pelvis * dq[PELVIS] ** 2
        for m, terms in self.terms(w)[0]:
            r, J, _ = self.kin(terms, q, dq)
            v = J @ dq
            e += 0.5 * m * v @ v + m * self.g * r[1]
        return e

    def foot_height(self, w, x):
        return float(self.n @ self.kin(self.terms(w)[1], x[:5], x[5:])[0])

    def step(self, w, x):
        """One step from just after a heel strike: ``(x just after the next one, period)``;
        ``w`` this step's swing-hip offset (the next step's is ``-w``)."""
        y, t2 = to_heel_strike(self.rhs(w), x, SWING, STANCE,
                               lambda y: self.foot_height(w, y), 5.0)
        return self.impact(w, y), t2

    def impact_rates(self, w, y):
        """The rates just after the plastic impact, before the roles swap: extended
        coordinates ``[q, p]`` (``p`` the old stance foot), ``M_e (dq+ - dq-) = E^T F``,
        ``E dq+ = 0`` (the new foot at rest; the hip-roll torques are finite: no
        impulse)."""
        q, dq = y[:5], y[5:]
        sol = self.plastic_impact(w, q, dq, np.concatenate([dq, np.zeros(3)]))
        return sol[:5], sol[5:8]

    def extended_mass(self, w, q, dq):
        """The mass matrix (8, 8) of the extended coordinates ``[q, p]``, ``p`` the stance
        foot's position (free)."""
        Me = np.zeros((8, 8))
        for m, terms in self.terms(w)[0]:
            Je = np.hstack([self.kin(terms, q, dq)[1], np.eye(3)])
            Me += m * Je.T @ Je
        Me[PELVIS, PELVIS] += self.I_pelvis
        return Me

    def plastic_impact(self, w, q, dq, dqe_minus):
        """``[dq+ (5), dp+ (3), F (3)]`` of the plastic heel strike from the extended rates
        ``dqe_minus`` (8,): ``M_e (dq+ - dq-) = E^T F``, ``E dq+ = 0``."""
        Me = self.extended_mass(w, q, dq)
        E = np.hstack([self.kin(self.terms(w)[1], q, dq)[1], np.eye(3)])
        K = np.block([[Me, -E.T], [E, np.zeros((3, 3))]])
        return np.linalg.solve(K, np.concatenate([Me @ dqe_minus, np.zeros(3)]))

    def impact(self, w, y):
        """The heel strike: the impact, then the legs' roles swap (the swing leg's roll is
        the new lean, the old stance leg's the new swing roll)."""
        q = y[:5]
        dqp = self.impact_rates(w, y)[0]
        order = [SWROLL, STANCE, SWING, PELVIS, LEAN]
        return np.concatenate([q[order], dqp[order]])

    def on_surface(self, w, z):
        """The state just after a heel strike of section coordinates ``z = [lean, stance,
        pelvis roll, swing roll, rates (5)]``: the swing foot (just lifted) on the slope
        behind, by Brent's method."""
        def h(th_sw):
            return self.foot_height(w, np.array([z[0], th_sw, *z[1:4], *np.zeros(5)]))
        th_sw = brentq(h, -z[1] - 2 * self.gamma - 0.3, -z[1] - 2 * self.gamma + 0.05)
        return np.array([z[0], th_sw, *z[1:]])


def _walker_and_reference(law=None):
    scene = Scene.model_validate(_raw(law))
    walker = build_walker(Plant.from_scene(scene))
    return scene, walker, reference_of(scene), scene.walker.hip_width_m


def reference_of(scene, cls=None, **more) -> Reference:
    """The independent Newton model of a hip-roll scene's walker (its masses, slope and
    law gains): :class:`Reference`, or ``cls`` built with the same numbers and ``more``."""
    wc, h = scene.walker, scene.walker.hip_roll
    gains = (h.pelvis_stiffness_n_m_per_rad, h.pelvis_damping_n_m_s_per_rad,
             h.swing_stiffness_n_m_per_rad, h.swing_damping_n_m_s_per_rad, h.lean_gain,
             h.lean_rate_gain_s)
    return (cls or Reference)(wc.gravity_m_per_s2, wc.leg_length_m, scene.slope.angle_rad,
                              wc.hip_mass_kg, wc.leg_mass_kg, wc.leg_mass_from_foot_m,
                              h.pelvis_roll_inertia_kg_m2, gains, **more)


@pytest.fixture(scope="module")
def stabilised():
    return _walker_and_reference()


def _states(seed: int, count: int) -> np.ndarray:
    """States with every roll different (each body on its own) near the gait's."""
    rng = np.random.default_rng(seed)
    x = np.array([0.03, -0.19, 0.16, -0.01, -0.04, 0.1, -0.9, -0.9, 3.0, -0.2])
    return x + 0.05 * rng.standard_normal((count, 10))


def test_hip_roll_walker_flow_and_impact_match_newtons_law(stabilised):
    """The generated flow (with the law's torques) and heel-strike map against the
    reference's on states whose five angles all differ, both hip sides: relative to
    max(1, |value|), 1e-11 (the stiff hips' accelerations reach 1e3 rad/s^2 off the gait;
    both solve a 5x5 system, roundoff ~1e-13 relative)."""
    _scene, walker, ref, w = stabilised
    flow, reset = flow_and_impact_errors(walker, ref, w, _states(3, 4))
    assert flow < 1e-11
    assert reset < 1e-11


def flow_and_impact_errors(walker, ref, w: float, states) -> tuple[float, float]:
    """The largest differences of the generated flow (relative to max(1, |value|)) and
    heel-strike map from a reference's (``ref.rhs(w)``, ``ref.impact(w, x)``) over
    ``states``, on both hip sides (``w`` and the mirror walker's ``-w``)."""
    flow = reset = 0.0
    for side, phase in ((w, walker), (-w, walker.mirror)):
        for x in states:
            theirs = ref.rhs(side)(0.0, x)
            err = np.abs(phase.phases[0].flow(0.0, x) - theirs) / np.maximum(1, np.abs(theirs))
            flow = max(flow, float(np.max(err)))
            reset = max(reset, float(np.max(np.abs(phase.reset(x) - ref.impact(side, x)))))
    return flow, reset


def test_hip_roll_walker_without_its_law_conserves_energy():
    """With every gain 0 the joints are free and the walker passive: its total energy
    (generated) stays constant along 0.3 s of the flow to 1e-9 J (the integrator's
    tolerance 1e-13 over ~1e3 steps), and equals the reference's energy."""
    zero = dict.fromkeys(("pelvis_stiffness_n_m_per_rad", "pelvis_damping_n_m_s_per_rad",
                          "swing_stiffness_n_m_per_rad", "swing_damping_n_m_s_per_rad",
                          "lean_gain", "lean_rate_gain_s"), 0.0)
    _scene, walker, ref, w = _walker_and_reference(zero)
    x0 = _states(5, 1)[0]
    sol = solve_ivp(walker.phases[0].flow, (0, 0.3), x0, method="DOP853", rtol=1e-13,
                    atol=1e-13, dense_output=True)
    xs = sol.sol(np.linspace(0, 0.3, 40))
    ke, pe = walker.energies(xs)
    total = np.asarray(ke) + np.asarray(pe)
    assert np.max(np.abs(total - total[0])) < 1e-9
    theirs = np.array([ref.energy(w, x) for x in xs.T])
    assert np.max(np.abs((theirs - theirs[0]) - (total - total[0]))) < 1e-9


def test_hip_roll_walker_impact_conserves_angular_momenta(stabilised):
    """Through the plastic impact (reference's rates, the generated ones equal them by
    the test above): the walker's angular momentum about the fall line through the new
    foot is conserved (the no-twist impulse does no work on a roll about it), and the old
    stance leg's (its mass's absolute momentum) about its hip along the fall line and its
    pitch axis (its hip joint, free in roll and pitch, transmits a force through the hip and
    a torque normal to both); 1e-12: roundoff of a linear solve."""
    _scene, _walker, ref, w = stabilised
    for x in _states(7, 3):
        q, dq = x[:5], x[5:]
        dqp, dp = ref.impact_rates(w, x)
        masses, foot, hip_st = ref.terms(w)
        r_new = ref.kin(foot, q, dq)[0]
        before = ref.I_pelvis * dq[PELVIS] * ref.s   # the pelvis' own spin about s
        after = ref.I_pelvis * dqp[PELVIS] * ref.s
        for m, terms in masses:
            r, J, _ = ref.kin(terms, q, dq)
            before = before + m * np.cross(r - r_new, J @ dq)
            after = after + m * np.cross(r - r_new, J @ dqp + dp)
        assert abs(ref.s @ (after - before)) < 1e-12
        r_hip = ref.kin(hip_st, q, dq)[0]
        r_m, J_m, _ = ref.kin(masses[1][1], q, dq)
        lv = [np.cross(r_m - r_hip, J_m @ v + p) * ref.m for v, p in ((dq, 0), (dqp, dp))]
        pitch_axis = ref._R(q[LEAN]) @ ref.z
        for axis in (ref.s, pitch_axis):
            assert abs(axis @ (lv[1] - lv[0])) < 1e-12


@pytest.fixture(scope="module")
def stabilised_gait(stabilised):
    scene, walker, _ref, _w = stabilised
    res = find_fixed_point(walker, _guess(scene, walker.state_names()), SOLVER,
                           fd_check=False)
    return res


@pytest.mark.slow  # ~15 s: the generated walker's fixed point
def test_hip_roll_law_makes_the_hip_width_gait_stable(stabilised_gait):
    """The shipped law stabilises the gait whose passive twin (configs/hip_width.yaml) has a
    lateral multiplier of 99.9: every multiplier of the stride inside the unit circle (none
    is neutral: the foot neither slips nor twists, so no heading family)."""
    mult = np.abs(np.asarray(stabilised_gait.multipliers_variational))
    assert mult.max() < 0.95


@pytest.mark.slow  # ~15 s: the generated walker's fixed point (shared with the above)
def test_hip_roll_gait_lifts_the_old_stance_foot_off_the_ground(stabilised, stabilised_gait):
    """Just after a heel strike the trailing foot (the old stance foot, on the slope) moves
    away from the slope (the reference's kinematics): a gait whose impact drove it into
    the ground would need the ground to pull.  The margin: 0.185 m/s measured, > 0.1 m/s
    asked (a pelvis without roll inertia gives -0.10 m/s)."""
    _scene, _walker, ref, w = stabilised
    x = np.asarray(stabilised_gait.x)
    _r, J, _h = ref.kin(ref.terms(w)[1], x[:5], x[5:])
    assert ref.n @ (J @ x[5:]) > 0.1


@pytest.mark.slow  # ~15 s: the generated walker's fixed point (shared with the above)
def test_hip_roll_walkers_energy_ledger_closes_with_the_laws_work(stabilised, stabilised_gait):
    """A stride from the fixed point: each step's energy change is the law's work (its power
    ``dV/dt - G . dq``, walkerlab.analysis.gait.energy) minus the heel strike's loss, to
    1e-9 J (the ledger's quadrature; measured 1e-12 J; without the law's work it is
    -0.20 J); the law
    both drives and brakes (+0.51 J, -0.71 J a step measured) and each step of the
    periodic gait ends with the kinetic energy it began with (the energy change is the
    slope's potential drop, to 1e-9 J)."""
    from walkerlab.analysis.gait.energy import trajectory_ledger
    from walkerlab.integrate.rigid import simulate_steps

    _scene, walker, _ref, _w = stabilised
    traj = simulate_steps(walker, np.asarray(stabilised_gait.x), 2, SOLVER)
    ledger = trajectory_ledger(traj)
    assert len(ledger["closure"]) == 2
    assert np.max(np.abs(ledger["closure"])) < 1e-9
    assert np.all(np.asarray(ledger["actuator_work_positive"]) > 0.1)
    assert np.all(np.asarray(ledger["actuator_work_negative"]) < -0.1)
    assert np.max(np.abs(ledger["energy_change"] + ledger["potential_work"])) < 1e-9


@pytest.mark.slow  # ~60 s: the reference's own fixed point and central differences
def test_hip_roll_gait_and_multipliers_match_an_independent_model(stabilised,
                                                                   stabilised_gait):
    """The stabilised gait's fixed point to 1e-8 and its multipliers to 1e-6 against the
    reference's (hybr on its stride, central differences with h = 1e-6: truncation ~h^2,
    roundoff ~1e-13 / h = 1e-7)."""
    _scene, _walker, ref, w = stabilised
    res = stabilised_gait

    dx, dt, dmu = stride_against(ref, w, res, [0, 2, 3, 4, 5, 6, 7, 8, 9])
    assert dx < 1e-8
    assert dt < 1e-8
    assert dmu < 1e-6
