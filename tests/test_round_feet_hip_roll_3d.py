"""The 3D straight-legged walker on round feet with hip-roll joints and their lateral
foot-placement law (``walker.foot_radius_m`` with ``walker.hip_roll``: McGeer 1990's discs
on Kuo 1999's stabilised walker) against a model written here that shares no code with its
generated equations: Newton-Euler's laws for the three point masses and the pelvis' roll,
each leg its own roll (the lean, the swing roll) and the pelvis its own, the velocities and
accelerations propagated from the stance disc's centre, which moves by the no-slip condition
``v_c = omega_st x (c - contact)`` (the rolling as a velocity constraint, not as the
generator's holonomic offset), Kane's equations (partial velocities) for the flow, the law's
torques as couples (virtual work, as ``tests/test_hip_roll_3d.py``'s reference), and the
plastic impact with the impulse at the new disc's material contact point as an unknown (the
old stance disc's centre free).

The generator's section (the swing leg's pitch solved from the heel-strike surface after
the roles swap) once left out the discs' radius with hip-roll joints: the gait search then
stopped at a residual proportional to the radius (8.1e-5 at R = 0.01 m)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.independent.mirror_stride import stride_against
from tests.test_hip_roll_3d import LEAN, PELVIS, STANCE, SWING, SWROLL, flow_and_impact_errors
from tests.test_hip_roll_3d import Reference as HipRollReference
from tests.test_hip_roll_3d import reference_of as hip_roll_reference_of
from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config.schema import Scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
#: the disc's radius on configs/hip_width_stabilised.yaml's walker (L = 1 m) [m]
RADIUS_M = 0.05


def _scene(radius: float = RADIUS_M) -> Scene:
    raw = yaml.safe_load((ROOT / "configs" / "hip_width_stabilised.yaml").read_text())
    raw["walker"]["foot_radius_m"] = radius
    return Scene.model_validate(raw)


def _cross(a, b):
    """a x b of two 3-vectors (np.cross's general path costs ~20 times more)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


class Reference(HipRollReference):
    """Newton-Euler's walker (module docstring), its state ``[lean, swing, stance, pelvis
    roll, swing roll, rates]`` as walkerlab's; the law's couples from the hip-roll
    reference (orientations only, which the discs do not change)."""

    def __init__(self, g, L, gamma, M, m, a, I_pelvis, law, R):
        super().__init__(g, L, gamma, M, m, a, I_pelvis, law)
        self.R = R

    def _roll(self, phi):
        """Rot(s, phi) by Rodrigues' formula."""
        return np.eye(3) + np.sin(phi) * self.S + (1 - np.cos(phi)) * self.S @ self.S

    def _frames(self, q):
        """Each leg's hip axis ``e3``, its axis up from the foot ``up`` and its rolled normal
        ``e2``; the pelvis' hip axis."""
        frames = {}
        for body, roll, pitch in (("stance", LEAN, STANCE), ("swing", SWROLL, SWING)):
            Rr = self._roll(q[roll])
            c, s_ = np.cos(q[pitch]), np.sin(q[pitch])
            frames[body] = (Rr @ self.z, Rr @ np.array([-s_, c, 0.0]), Rr @ self.n)
        return frames, self._roll(q[PELVIS]) @ self.z

    def _chain(self, w, q):
        """The points as ``(name, base, offset, body)``, each ``base + offset`` moving
        with ``body``, from the stance disc's centre."""
        L, R, a = self.L, self.R, self.a
        frames, hip_axis = self._frames(q)
        (_, u_st, e2_st), (_, u_sw, e2_sw) = frames["stance"], frames["swing"]
        return [("contact", "centre", -R * e2_st, "stance"),   # the stance disc's material point
                ("hip", "centre", (L - R) * u_st, "stance"),
                ("stance_mass", "centre", (a - R) * u_st, "stance"),
                ("pelvis", "hip", w / 2 * hip_axis, "pelvis"),
                ("swing_hip", "hip", w * hip_axis, "pelvis"),
                ("swing_mass", "swing_hip", -(L - a) * u_sw, "swing"),
                ("swing_centre", "swing_hip", -(L - R) * u_sw, "swing"),
                ("swing_contact", "swing_centre", -R * e2_sw, "swing")]   # its material point

    def kinematics(self, w, q, dq, ddq):
        """Positions (from the stance disc's contact point), velocities and accelerations
        of the points (the stance disc rolling); ``omega``, each body's angular velocity."""
        s, R = self.s, self.R
        frames, _ = self._frames(q)
        rates = {}
        for body, roll, pitch in (("stance", LEAN, STANCE), ("swing", SWROLL, SWING)):
            e3 = frames[body][0]
            rates[body] = (dq[roll] * s + dq[pitch] * e3, ddq[roll] * s + ddq[pitch] * e3
                           + dq[pitch] * _cross(dq[roll] * s, e3))
        rates["pelvis"] = (dq[PELVIS] * s, ddq[PELVIS] * s)
        w_st, al_st = rates["stance"]
        e2_st = frames["stance"][2]
        de2 = _cross(dq[LEAN] * s, e2_st)
        pos = {"centre": R * e2_st}
        vel = {"centre": _cross(w_st, R * e2_st)}   # no slip: the contact at rest
        acc = {"centre": _cross(al_st, R * e2_st) + _cross(w_st, R * de2)}
        for name, base, r, body in self._chain(w, q):
            omega, alpha = rates[body]
            pos[name] = pos[base] + r
            vel[name] = vel[base] + _cross(omega, r)
            acc[name] = acc[base] + _cross(alpha, r) + _cross(omega, _cross(omega, r))
        return pos, vel, acc, {b: r[0] for b, r in rates.items()}

    def jacobians(self, w, q, free_centre=False):
        """Kane's partial velocities: each point's ``d v / d dq`` (3, 5) from the bodies'
        ``d omega / d dq`` (``v = v_base + omega x r``), the stance disc's centre rolling;
        with ``free_centre`` (3, 8), its velocity three more rates (the impact's old foot)."""
        k = 8 if free_centre else 5
        frames, _ = self._frames(q)
        W = {b: np.zeros((3, k)) for b in ("stance", "swing", "pelvis")}
        W["stance"][:, LEAN], W["stance"][:, STANCE] = self.s, frames["stance"][0]
        W["swing"][:, SWROLL], W["swing"][:, SWING] = self.s, frames["swing"][0]
        W["pelvis"][:, PELVIS] = self.s
        J = {"centre": np.zeros((3, k))}
        if free_centre:
            J["centre"][:, 5:] = np.eye(3)
        else:
            J["centre"] = -self._skew(self.R * frames["stance"][2]) @ W["stance"]
        for name, base, r, body in self._chain(w, q):
            J[name] = J[base] - self._skew(r) @ W[body]
        return J

    def bodies(self):
        return [("pelvis", self.M), ("stance_mass", self.m), ("swing_mass", self.m)]

    def rhs(self, w):
        grav = np.array([0.0, -self.g, 0.0])

        def f(t, x):
            q, dq = x[:5], x[5:]
            vel = self.jacobians(w, q)
            acc = self.kinematics(w, q, dq, np.zeros(5))[2]   # the bias
            Mq, rhs = np.zeros((5, 5)), self.law_forces(q, dq)
            Mq[PELVIS, PELVIS] = self.I_pelvis    # the pelvis' roll about the fall line
            for p, m in self.bodies():
                Mq += m * vel[p].T @ vel[p]
                rhs += vel[p].T @ (m * (grav - acc[p]))
            return np.concatenate([dq, np.linalg.solve(Mq, rhs)])
        return f

    def energy(self, w, x):
        """Kinetic plus potential energy [J], the heights from a point fixed on the slope:
        the stance contact has rolled ``-R (stance + gamma)`` along the fall line from the
        point where its leg stood normal to the slope (the integral of ``v_contact = -R
        stance'`` along ``s``), ``R (stance + gamma) sin(gamma)`` above it."""
        pos, vel, _, _ = self.kinematics(w, x[:5], x[5:], np.zeros(5))
        e = 0.5 * self.I_pelvis * x[5 + PELVIS] ** 2
        rolled = -self.R * (x[STANCE] + self.gamma) * self.s[1]
        for p, m in self.bodies():
            e += 0.5 * m * vel[p] @ vel[p] + m * self.g * (pos[p][1] + rolled)
        return e

    def foot_height(self, w, x):
        return float(self.n @ self.kinematics(w, x[:5], x[5:], np.zeros(5))[0]["swing_contact"])

    def impact_rates(self, w, y):
        """The plastic impact: extended rates ``[dq, v_centre]``, ``M_e (v+ - v-) = E^T F``,
        ``E v+ = 0`` (the new disc's material contact point at rest; the law's torques
        finite: no impulse); ``dq+`` before the roles swap and ``v_centre+``."""
        q, dq = y[:5], y[5:]
        vel = self.jacobians(w, q, free_centre=True)
        Me = np.zeros((8, 8))
        Me[PELVIS, PELVIS] = self.I_pelvis
        for p, m in self.bodies():
            Me += m * vel[p].T @ vel[p]
        E = vel["swing_contact"]
        v_minus = np.concatenate([dq, self.kinematics(w, q, dq, np.zeros(5))[1]["centre"]])
        K = np.block([[Me, -E.T], [E, np.zeros((3, 3))]])
        sol = np.linalg.solve(K, np.concatenate([Me @ v_minus, np.zeros(3)]))
        return sol[:5], sol[5:8]


def reference_of(scene: Scene) -> Reference:
    """The Newton-Euler model of the scene's walker on its discs."""
    return hip_roll_reference_of(scene, Reference, R=scene.walker.foot_radius_m)


@pytest.fixture(scope="module")
def discs():
    scene = _scene()
    return scene, build_walker(Plant.from_scene(scene)), reference_of(scene)


def _states(seed: int, count: int) -> np.ndarray:
    """States with every roll different near the gait's."""
    rng = np.random.default_rng(seed)
    x = np.array([0.03, -0.19, 0.16, -0.01, -0.04, 0.1, -0.9, -0.9, 3.0, -0.2])
    return x + 0.05 * rng.standard_normal((count, 10))


def test_round_feet_hip_roll_flow_and_impact_match_newton_euler(discs):
    """The generated flow (the law's torques with it) and heel-strike map against the
    reference's, both hip sides, on states whose five angles all differ: relative to
    max(1, |value|), 1e-10 (stiff hips: accelerations to 1e3 rad/s^2; both solve a 5x5
    system, roundoff ~1e-13 relative)."""
    scene, walker, ref = discs
    flow, reset = flow_and_impact_errors(walker, ref, scene.walker.hip_width_m, _states(3, 4))
    assert flow < 1e-10
    assert reset < 1e-10


def test_round_feet_hip_roll_energies_are_the_rolling_walkers(discs):
    """The generated energies against the reference's, up to the potential's zero: their
    differences between states agree to 1e-12 J (the discs' rolling moves the hip by R
    times the stance leg's pitch, which a point foot's energy would leave out: 0.05 m x
    0.1 rad x 200 N = 1 J here)."""
    scene, walker, ref = discs
    w = scene.walker.hip_width_m
    xs = _states(11, 5)
    ke, pe = walker.energies(xs.T)
    ours = np.asarray(ke) + np.asarray(pe)
    theirs = np.array([ref.energy(w, x) for x in xs])
    assert np.max(np.abs((ours - ours[0]) - (theirs - theirs[0]))) < 1e-12


def test_round_feet_hip_roll_section_lands_the_swing_disc_on_the_slope(discs):
    """Every state the section rebuilds (the swing leg's pitch solved from the heel-strike
    surface) has the swing disc's lowest point on the slope by the reference's geometry,
    to 1e-14 m; a point foot's solution there leaves it R (cos(lean) - cos(swing roll))
    off, 1e-5 m at these rolls."""
    scene, walker, ref = discs
    w = scene.walker.hip_width_m
    for x in _states(5, 5):
        y = walker.from_section(walker.section(x))
        assert abs(ref.foot_height(w, y)) < 1e-14
        assert y[SWING] != x[SWING]


@pytest.mark.slow  # ~110 s: the generated gait and the reference's own, central differences
def test_round_feet_hip_roll_gait_and_multipliers_match_newton_euler(discs):
    """The gait of the stabilised walker on 5 cm discs: found to 1e-12 (it stopped at a
    residual of R x 8e-3 before the section's fix), stable, and equal to the reference's
    (fixed point 1e-8, stride period 1e-8 s, multipliers 1e-6: central differences with
    h = 1e-6)."""
    scene, walker, ref = discs
    g = scene.fixedpoint.initial_guess.model_extra
    names = walker.state_names()
    guess = np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                      for n in names])
    res = find_fixed_point(walker, guess, SOLVER, fd_check=False)
    assert res.residual < 1e-11
    assert max(abs(np.asarray(res.multipliers_variational))) < 1
    dx, dt, dmu = stride_against(ref, scene.walker.hip_width_m, res,
                                 [0, 2, 3, 4, 5, 6, 7, 8, 9])
    assert dx < 1e-8
    assert dt < 1e-8
    assert dmu < 1e-6


def test_round_feet_hip_roll_adams_dataset_moves_as_the_rigid_model(discs):
    """The Adams dataset of the walker at a state (every roll different, not a gait),
    read back by walkerlab's reader: its parts' kinetic energy equals the rigid model's
    ``dq^T M dq / 2`` (relative 1e-9: 17 digits in mm and degrees).  The pelvis' roll hinge
    once took the stance disc's rolling travel for a turn about the same axis (a KeyError
    on ``R_foot``)."""
    from types import SimpleNamespace

    from walkerlab.codegen.cache import functions
    from walkerlab.export.adams_3d import adams3d_start, adm3d_text
    from walkerlab.export.adams_reader import read_adm

    scene, _walker, _ref = discs
    plant = Plant.from_scene(scene)
    x = _states(13, 1)[0]
    start = adams3d_start(plant, SimpleNamespace(x=x, period_s=1.4, step_lengths_m=(0.34,)),
                          2)
    model = read_adm(adm3d_text(scene, plant.data, start, "walker"))
    M = np.asarray(functions(plant.data)["matrices"](x)[0], float).reshape(5, 5)
    got = 0.0
    for pid in (p for p in model.by_kind["PART"] if p != 1):
        v, om = model.part_velocity(pid)
        got += 0.5 * model.part_mass(pid) * v @ v + 0.5 * om @ model.part_inertia(pid) @ om
    assert got == pytest.approx(0.5 * x[5:] @ M @ x[5:], rel=1e-9)


@pytest.mark.slow  # ~60 s: the gait, the MJCF and MuJoCo's 11 steps
def test_round_feet_hip_roll_walks_in_mujoco_within_one_percent(tmp_path):
    """The exported MJCF (cylinder feet, the hip-roll law run by the stepping loop) walks
    11 alternating heel strikes from the rigid gait's keyframe, its mean step period within
    1 % of the rigid one (measured +0.14 %)."""
    pytest.importorskip("mujoco")
    from walkerlab.stages import export as export_stage

    check = export_stage.write(_scene(), tmp_path, "mjcf", walk=True).walk
    assert check.walked and not check.fell, check.line
    assert check.strikes >= 10 and check.alternating, check.line
    assert check.period_s == pytest.approx(check.rigid_period_s, rel=0.01), check.line
