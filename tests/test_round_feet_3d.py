"""The 3D straight-legged walker on round feet (``model: compass_gait``, ``space: 3d``,
``foot_radius_m``, ``leg_inertia_kg_m2``; McGeer 1990's round feet on Kuo 1999's walker)
against references that share no code with its generated equations:

- the planar round-feet walker of ``configs/round_feet.yaml`` (``model: biped``, its own
  generator, the planar tree, checked against the leg-vector sums of
  ``tests/independent/planar_link_sums.py``): the planar embedding;
- a model written here from Newton-Euler's laws: each leg a rigid body (its point mass and a
  slender rod's inertia), the pelvis a point mass, the velocities and accelerations
  propagated from the stance disc's centre, which moves by the no-slip condition
  ``v_c = omega_st x (c - contact)`` (the rolling written as a velocity constraint, not as
  the generator's holonomic offset), Kane's equations (partial velocities) for the flow, and
  the plastic impact with the impulse at the new foot's material contact point as an unknown
  (the old stance disc's centre free).
"""

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
#: configs/round_feet_3d.yaml's walker (nondimensional, g = 1)
ROUND = dict(g=1.0, L=1.2, gamma=0.01, M=1.0, m=0.5, a=0.7, I_leg=0.02, R=0.2)
#: the hip width of the reference's walker [l]
WIDTH = 0.1


def _scene(name: str, **walker) -> Scene:
    raw = yaml.safe_load((ROOT / "configs" / name).read_text())
    raw["walker"].update(walker)
    return Scene.model_validate(raw)


def _guess(scene: Scene, names) -> np.ndarray:
    g = scene.fixedpoint.initial_guess.model_extra
    return np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")] for n in names])


class Reference:
    """Newton-Euler's walker (module docstring); state ``[lean, swing, stance, rates]`` as
    walkerlab's, ``w`` the swing hip's offset along the hip axis (its sign: the side)."""

    def __init__(self, g, L, gamma, M, m, a, I_leg, R):
        self.g, self.L, self.gamma, self.M, self.m, self.a, self.I, self.R = (
            g, L, gamma, M, m, a, I_leg, R)
        self.s = np.array([math.cos(gamma), -math.sin(gamma), 0.0])   # the fall line
        self.n = np.array([math.sin(gamma), math.cos(gamma), 0.0])    # the slope's normal
        self.z = np.array([0.0, 0.0, 1.0])

    def _frames(self, q):
        """The roll (about the fall line) and each leg's axis (foot to hip, unit)."""
        roll = Rotation.from_rotvec(q[0] * self.s).as_matrix()

        def up(th):
            return roll @ Rotation.from_rotvec(th * self.z).as_matrix() @ [0.0, 1.0, 0.0]
        return roll, up(q[1]), up(q[2])

    def kinematics(self, w, q, dq, ddq, v_centre=None):
        """Positions (from the stance contact point), velocities and accelerations of the
        points, each leg's angular velocity and acceleration.  ``v_centre``: the stance
        disc centre's velocity given (the impact's free old foot), else rolling."""
        L, R, a = self.L, self.R, self.a
        roll, u_sw, u_st = self._frames(q)
        e2, e3 = roll @ self.n, roll @ self.z         # the rolled normal and hip axis
        w_p, al_p = dq[0] * self.s, ddq[0] * self.s
        w_st = w_p + dq[2] * e3
        w_sw = w_p + dq[1] * e3
        de3 = np.cross(w_p, e3)
        al_st = al_p + ddq[2] * e3 + dq[2] * de3
        al_sw = al_p + ddq[1] * e3 + dq[1] * de3
        pos, vel, acc = {}, {}, {}
        pos["centre"] = R * e2
        if v_centre is None:   # no slip: the contact's material point at rest
            vel["centre"] = np.cross(w_st, R * e2)
            acc["centre"] = np.cross(al_st, R * e2) + np.cross(w_st, R * np.cross(w_p, e2))
        else:
            vel["centre"], acc["centre"] = np.asarray(v_centre), np.zeros(3)

        def rigid(name, base, r, omega, alpha):
            pos[name] = pos[base] + r
            vel[name] = vel[base] + np.cross(omega, r)
            acc[name] = acc[base] + np.cross(alpha, r) + np.cross(omega, np.cross(omega, r))

        rigid("contact", "centre", -R * e2, w_st, al_st)   # the stance disc's material point
        rigid("hip", "centre", (L - R) * u_st, w_st, al_st)
        rigid("stance_mass", "centre", (a - R) * u_st, w_st, al_st)
        rigid("pelvis", "hip", w / 2 * e3, w_p, al_p)
        rigid("swing_hip", "hip", w * e3, w_p, al_p)
        rigid("swing_mass", "swing_hip", -(L - a) * u_sw, w_sw, al_sw)
        rigid("swing_centre", "swing_hip", -(L - R) * u_sw, w_sw, al_sw)
        rigid("swing_contact", "swing_centre", -R * e2, w_sw, al_sw)   # its material point
        legs = [(w_st, al_st, u_st), (w_sw, al_sw, u_sw)]
        return pos, vel, acc, legs

    def bodies(self):
        return [("pelvis", self.M), ("stance_mass", self.m), ("swing_mass", self.m)]

    def _partials(self, w, q, v_centre=False):
        """Partial velocities (3, k) of the points and angular velocities of the legs, with
        ``v_centre`` the stance centre's velocity three more rates (k = 6), else k = 3."""
        k = 6 if v_centre else 3
        cols = []
        for j in range(k):
            e = np.zeros(k)
            e[j] = 1.0
            cols.append(self.kinematics(w, q, e[:3], np.zeros(3),
                                        e[3:] if v_centre else None))
        vel = {p: np.column_stack([c[1][p] for c in cols]) for p in cols[0][1]}
        om = [np.column_stack([c[3][i][0] for c in cols]) for i in range(2)]
        return vel, om

    def _inertia(self, u):
        return self.I * (np.eye(3) - np.outer(u, u))

    def rhs(self, w):
        grav = np.array([0.0, -self.g, 0.0])

        def f(t, x):
            q, dq = x[:3], x[3:]
            vel, om = self._partials(w, q)
            _, _, acc, legs = self.kinematics(w, q, dq, np.zeros(3))   # the bias
            Mq, rhs = np.zeros((3, 3)), np.zeros(3)
            for p, m in self.bodies():
                Mq += m * vel[p].T @ vel[p]
                rhs += vel[p].T @ (m * (grav - acc[p]))
            for W, (omega, alpha, u) in zip(om, legs):
                Ib = self._inertia(u)
                Mq += W.T @ Ib @ W
                rhs -= W.T @ (Ib @ alpha + np.cross(omega, Ib @ omega))
            return np.concatenate([dq, np.linalg.solve(Mq, rhs)])
        return f

    def energy(self, w, x):
        """Kinetic plus potential energy (the stance contact at height 0)."""
        pos, vel, _, legs = self.kinematics(w, x[:3], x[3:], np.zeros(3))
        e = 0.0
        for p, m in self.bodies():
            e += 0.5 * m * vel[p] @ vel[p] + m * self.g * pos[p][1]
        for omega, _, u in legs:
            e += 0.5 * omega @ self._inertia(u) @ omega
        return e

    def foot_height(self, w, x):
        return float(self.n @ self.kinematics(w, x[:3], x[3:], np.zeros(3))[0]["swing_contact"])

    def impact_rates(self, w, y, push=0.0):
        """The plastic impact: extended rates ``[dq, v_centre]`` (the old stance disc's
        centre free), ``M_e (v+ - v-) = E^T F`` and ``E v+ = 0`` (the new foot's material
        contact point at rest); returns ``dq+`` (before the roles swap) and ``v_centre+``.

        ``push`` [N s]: a push-off first, the impulse ``push e`` at the old stance disc's
        material contact point along ``e`` from it to its leg's hip (Kuo 2002's push-off,
        the trailing foot free): ``M_e (v_po - v-) = J_c^T push e``; the extended rates
        after it are ``v_po``, and the third value the kinetic energy it adds [J]."""
        q, dq = y[:3], y[3:]
        vel, om = self._partials(w, q, v_centre=True)
        pos, vel0, _, legs = self.kinematics(w, q, dq, np.zeros(3))
        Me = np.zeros((6, 6))
        for p, m in self.bodies():
            Me += m * vel[p].T @ vel[p]
        for W, (_, _, u) in zip(om, legs):
            Me += W.T @ self._inertia(u) @ W
        E = vel["swing_contact"]
        v_minus = np.concatenate([dq, vel0["centre"]])
        e = pos["hip"] - pos["contact"]
        v_po = v_minus + np.linalg.solve(Me, vel["contact"].T @ (push * e / np.linalg.norm(e)))
        K = np.block([[Me, -E.T], [E, np.zeros((3, 3))]])
        sol = np.linalg.solve(K, np.concatenate([Me @ v_po, np.zeros(3)]))
        added = 0.5 * (v_po @ Me @ v_po - v_minus @ Me @ v_minus)
        return sol[:3], sol[3:6], added

    def impact(self, w, y, push=0.0):
        dqp = self.impact_rates(w, y, push)[0]
        q = y[:3]
        return np.array([q[0], q[2], q[1], dqp[0], dqp[2], dqp[1]])

    def momentum_about(self, w, q, dq, point, v_centre=None):
        """Angular momentum (3,) about ``point`` (from the stance contact)."""
        pos, vel, _, legs = self.kinematics(w, q, dq, np.zeros(3), v_centre)
        h = np.zeros(3)
        for p, m in self.bodies():
            h += m * np.cross(pos[p] - point, vel[p])
        for omega, _, u in legs:
            h += self._inertia(u) @ omega
        return h

    def step(self, w, x):
        """One step from just after a heel strike: ``(x just after the next one, period)``."""
        y, t2 = to_heel_strike(self.rhs(w), x, 1, 2, lambda y: self.foot_height(w, y), 10.0)
        return self.impact(w, y), t2

    def on_surface(self, w, z):
        """The state just after a heel strike from ``z = [lean, stance, rates]``: the swing
        foot on the slope behind (Brent's method)."""
        def h(th_sw):
            return self.foot_height(w, np.array([z[0], th_sw, z[1], 0, 0, 0]))
        th_sw = brentq(h, -z[1] - 2 * self.gamma - 0.3, -z[1] - 2 * self.gamma + 0.05)
        return np.array([z[0], th_sw, z[1], *z[2:]])


def _states(seed, k=5):
    rng = np.random.default_rng(seed)
    return [np.array([0.05, -0.2, 0.17, 0.3, -0.2, -0.25]) + 0.05 * rng.standard_normal(6)
            for _ in range(k)]


@pytest.fixture(scope="module")
def walkers():
    """The walker of configs/round_feet_3d.yaml, upright, and with a hip width of 0.1 l."""
    sc = _scene("round_feet_3d.yaml")
    sc1 = _scene("round_feet_3d.yaml", hip_width_m=WIDTH)
    return (build_walker(Plant.from_scene(sc)),
            build_walker(Plant.from_scene(sc1)))


# ---- the planar embedding ---------------------------------------------------------------

@pytest.mark.slow  # ~3 s: two fixed points and their variational equations
def test_round_feet_walker_in_3d_with_zero_hip_width_walks_as_the_planar_one(walkers):
    """Started upright, configs/round_feet_3d.yaml is configs/round_feet.yaml (the
    planar tree's arc feet, a rod's inertia): the same
    fixed point and step period to 1e-9 (measured 1.0e-12 and 6.5e-12: the fixed points'
    tolerance 1e-12), its planar multipliers among the 3D ones to 1e-7 (the variational
    equations' accuracy)."""
    flat_scene = _scene("round_feet.yaml")
    flat = build_walker(Plant.from_scene(flat_scene))
    f = find_fixed_point(flat, _guess(flat_scene, flat.state_names()), SOLVER, fd_check=False)
    sp_scene = _scene("round_feet_3d.yaml")
    w3 = walkers[0]
    s = find_fixed_point(w3, _guess(sp_scene, w3.state_names()), SOLVER, fd_check=False)
    x3 = dict(zip(w3.state_names(), s.x))
    for name, value in zip(flat.state_names(), f.x):
        assert abs(x3[name] - value) < 1e-9, name
    assert abs(x3["lean_angle"]) < 1e-12 and abs(x3["lean_rate"]) < 1e-12
    assert abs(s.period_s - f.period_s) < 1e-9
    for m in f.multipliers_variational:
        assert np.min(np.abs(s.multipliers_variational - m)) < 1e-7


# ---- Newton-Euler's walker ---------------------------------------------------------------

@pytest.mark.parametrize("width", [0.0, WIDTH])
def test_round_feet_flow_and_impact_match_newton_euler(walkers, width):
    """The generated flow and heel-strike map against the reference's at rolled states, with
    and without hip width; 1e-11: roundoff of two independent evaluations (rates ~1)."""
    walker = walkers[1 if width else 0]
    ref = Reference(**ROUND)
    for x in _states(5):
        assert np.max(np.abs(walker.phases[0].flow(0.0, x) - ref.rhs(width)(0.0, x))) < 1e-11
        assert np.max(np.abs(walker.reset(x) - ref.impact(width, x))) < 1e-11


@pytest.mark.parametrize("width", [0.0, WIDTH])
def test_round_feet_push_off_and_heel_strike_match_newton_euler(width):
    """The rigid model's push-off on disc feet (walker.actuation.push_off: the impulse at
    the trailing disc's material contact point along the trailing leg to its own hip, then
    the heel strike, on the generated extended impact system) against the reference's, the
    trailing disc's centre free, at rolled states, with and without hip width, three
    impulses: the post-impact state to 1e-11 (roundoff of two independent linear solves)
    and the push-off's kinetic energy gain to 1e-12 J."""
    from walkerlab.config.actuation import Actuation, PushOff
    from walkerlab.models.hybrid.actuated import actuate

    plant = Plant.from_scene(_scene("round_feet_3d.yaml", hip_width_m=width))
    passive = build_walker(plant)
    ref = Reference(**ROUND)
    for P in (0.0, 0.05, 0.2):
        acts = actuate(passive, plant.data, Actuation(push_off=PushOff(impulse_n_s=P)))
        for x in _states(13, 3):
            out = acts.actuators.transition(x)
            assert np.max(np.abs(out["x_plus"] - ref.impact(width, x, P))) < 1e-11
            gain = out["ke_push_off"] - out["ke_minus"]
            assert abs(gain - ref.impact_rates(width, x, P)[2]) < 1e-12


def test_round_feet_points_are_the_rolling_discs(walkers):
    """The named points (contacts, discs' centres, hips, masses) are the reference's (its
    positions from the stance contact point; the generator's from the step's reference point,
    R (theta_st + gamma) up the fall line from it); 1e-13: roundoff."""
    walker = walkers[1]
    ref = Reference(**ROUND)
    names = {"stance_contact": None, "stance_foot_centre": "centre", "stance_hip": "hip",
             "swing_hip": "swing_hip", "hip": "pelvis", "stance_mass": "stance_mass",
             "swing_mass": "swing_mass", "swing_foot_centre": "swing_centre",
             "swing_contact": "swing_contact"}
    for x in _states(11, 3):
        pts = walker.points(x)
        contact = np.ravel(pts["stance_contact"])
        pos = ref.kinematics(WIDTH, x[:3], x[3:], np.zeros(3))[0]
        assert np.max(np.abs(contact + ROUND["R"] * (x[2] + ROUND["gamma"]) * ref.s)) < 1e-13
        for ours, theirs in names.items():
            r = np.zeros(3) if theirs is None else pos[theirs]
            assert np.max(np.abs(np.ravel(pts[ours]) - contact - r)) < 1e-13, ours


def test_round_feet_walker_conserves_energy_in_a_passive_swing(walkers):
    """The generated flow over 1.5 time units (about 0.6 of a step), rolled and with hip
    width: the reference's energy constant to 1e-9 (M g l ~ 2.4; the integration's
    tolerance 1e-13 over ~100 steps): its kinetic and potential energies from its own
    kinematics, the rolling contact's height integrated alongside from its velocity (the
    disc centre's less R times the roll's turning of the rolled normal); the generated
    energies constant too, and the generated kinetic energy the reference's to 1e-12."""
    walker = walkers[1]
    ref = Reference(**ROUND)
    R, total = ROUND["R"], ROUND["M"] + 2 * ROUND["m"]

    def flow(t, y):
        _, vel, _, _ = ref.kinematics(WIDTH, y[:3], y[3:6], np.zeros(3))
        roll = Rotation.from_rotvec(y[0] * ref.s).as_matrix()
        v_contact = vel["centre"] - R * np.cross(y[3] * ref.s, roll @ ref.n)
        return np.concatenate([walker.phases[0].flow(t, y[:6]), [v_contact[1]]])

    x0 = np.array([0.03, -0.2, 0.17, 0.1, -0.2, -0.25, 0.0])
    sol = solve_ivp(flow, (0, 1.5), x0, method="DOP853", rtol=1e-13, atol=1e-13,
                    dense_output=True)
    ys = sol.sol(np.linspace(0, 1.5, 40))
    theirs = np.array([ref.energy(WIDTH, y[:6]) + total * ROUND["g"] * y[6] for y in ys.T])
    ke, pe = walker.energies(ys[:6])
    ours = np.asarray(ke) + np.asarray(pe)
    assert np.ptp(theirs) < 1e-9 and np.ptp(ours) < 1e-9
    ke_ref = [ref.energy(WIDTH, y[:6]) - ref.energy(WIDTH, np.r_[y[:3], 0.0, 0.0, 0.0])
              for y in ys.T]
    assert np.max(np.abs(np.asarray(ke) - ke_ref)) < 1e-12


def test_round_feet_impact_conserves_angular_momentum_about_the_new_contact(walkers):
    """Through the generated impact the walker's angular momentum about the new contact
    point is conserved along the fall line and the rolled hip axis (the whole walker rolled
    or pitched about the new contact is a motion the impulse does no work on; the normal
    component is the no-twist constraint's), and the old stance leg's about its hip along
    its pitch axis (a free hinge); computed by the reference's kinematics from the
    generated rates (the old stance disc's centre from the impact's solution); 1e-12:
    roundoff of a linear solve."""
    walker = walkers[1]
    ref = Reference(**ROUND)
    for x in _states(7, 4):
        q, dq = x[:3], x[3:]
        xp = walker.reset(x)
        dqp = np.array([xp[3], xp[5], xp[4]])            # back in the pre-swap roles
        v_centre = ref.impact_rates(WIDTH, x)[1]
        pos = ref.kinematics(WIDTH, q, dq, np.zeros(3))[0]
        roll = Rotation.from_rotvec(q[0] * ref.s).as_matrix()
        e3 = roll @ ref.z
        before = ref.momentum_about(WIDTH, q, dq, pos["swing_contact"])
        after = ref.momentum_about(WIDTH, q, dqp, pos["swing_contact"], v_centre)
        for axis in (ref.s, e3):
            assert abs(axis @ (after - before)) < 1e-12
        # the old stance leg about its hip, along e3: its mass and rod
        _, vb, _, legs_b = ref.kinematics(WIDTH, q, dq, np.zeros(3))
        _, va, _, legs_a = ref.kinematics(WIDTH, q, dqp, np.zeros(3), v_centre)

        def leg_h(v, legs, pos=pos, e3=e3):
            u = legs[0][2]
            return e3 @ (ref.m * np.cross(pos["stance_mass"] - pos["hip"], v["stance_mass"])
                         + ref._inertia(u) @ legs[0][0])
        assert abs(leg_h(va, legs_a) - leg_h(vb, legs_b)) < 1e-12


@pytest.mark.slow  # ~60 s: the reference's own fixed point and central differences
def test_round_feet_hip_width_gait_and_multipliers_match_newton_euler(walkers):
    """With 0.1 l of hip width: the generated stride's fixed point and period against the
    reference's (found by scipy's root on its own stride) to 1e-8 (both roots to ~1e-12,
    the integrations' tolerance 1e-13 over a stride), and the multipliers against the
    reference's by central differences (h = 1e-6: truncation ~1e-10 relative, roundoff
    1e-13 / 1e-6) to 1e-6 relative to max(1, |multiplier|)."""
    walker = walkers[1]
    res = _hip_width_gait(walker)
    ref = Reference(**ROUND)

    dx, dt, dmu = stride_against(ref, WIDTH, res, [0, 2, 3, 4, 5])
    assert dx < 1e-8
    assert dt < 1e-8
    assert dmu < 1e-6


def _hip_width_gait(walker):
    """The stride's fixed point with 0.1 l of hip width, from the upright gait's legs with a
    lean and lean rate of the point-footed configs/hip_width.yaml's sign and scale (the
    search from the upright gait itself does not converge, even at 2.5 mm of hip width)."""
    guess = np.array([-0.0035, -0.19943828, 0.17943828, -0.04, -0.18761398, -0.23901099])
    return find_fixed_point(walker, guess, SOLVER, fd_check=False)


@pytest.mark.parametrize(("name", "walker", "says"), [
    ("round_feet_3d.yaml", {"space": "2d"}, "walker.foot_radius_m: needs space: 3d"),
    ("round_feet_3d.yaml", {"foot_radius_m": 1.5}, "walker.foot_radius_m must be smaller"),
    ("hip_width_stabilised.yaml", {"leg_inertia_kg_m2": 0.1},
     "walker.leg_inertia_kg_m2: not with walker.hip_roll"),
])
def test_round_feet_bad_input_is_refused_naming_its_field(name, walker, says):
    from pydantic import ValidationError

    with pytest.raises(ValidationError, match=says):
        _scene(name, **walker)
