"""The stabilised 3D kneed walker (``configs/kneed_3d_stabilised.yaml``): configs/kneed_3d.yaml's
locking knees (McGeer 1990) with hip-roll joints and Kuo's (1999) lateral foot-placement law
(``walker.hip_roll``), derived from its body tree by
:func:`walkerlab.codegen.legged.derive_legged`, against:

- Newton's law for its five point masses and the pelvis' roll inertia, written here with no
  code shared with that derivation (each point a sum of rotated offsets, its Jacobian and
  velocity-product term by hand, the law's torques as couples whose generalised forces are
  their virtual work): the knee-free flow ``M qdd + C dq + G`` of both mirror steps;
- the rigid gait itself: the scene's fixed point maps to itself over a stride and every
  Floquet multiplier lies inside the unit circle (the passive walker's lateral one is about
  40 a stride, configs/kneed_3d.yaml).

Tolerances: the flow terms are of order 1-10 and both sides solve nothing (products and
sums of 3-vectors): 1e-10 absolute.  The fixed point is stored to 10 decimals and the
stride map (DOP853 at 1e-12) returns it to ~1e-10; 1e-8 leaves room for the map's
conditioning (its multipliers are below 1, so an error does not grow over the stride).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from walkerlab.config import scene_from_dict
from walkerlab.config.schema import Scene
from walkerlab.integrate.solver import Solver
from walkerlab.walker.description import walker_data
from walkerlab.walker.kinds import KINDS, kind_of

ROOT = Path(__file__).resolve().parents[1]
SCENE = "kneed_3d_stabilised.yaml"
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
# coordinates: lean (the stance leg's roll), swing thigh, swing shank, stance (pitches),
# pelvis roll, swing roll
LEAN, THIGH, SHANK, STANCE, PELVIS, SWROLL = range(6)
N = 6


def _raw() -> dict:
    return yaml.safe_load((ROOT / "configs" / SCENE).read_text())


def _guess(scene: Scene, names) -> np.ndarray:
    g = scene.fixedpoint.initial_guess.model_extra
    return np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")] for n in names])


class KneedNewton:
    """The walker from Newton's law (module docstring) in world axes (``y`` up, ``z``
    across the slope, the fall line ``s = (cos gamma, -sin gamma, 0)``), the stance foot at
    the origin.  Each body's roll is about ``s``, each leg link's pitch (from the vertical)
    about its rolled ``z``; ``w`` the swing hip's offset along the pelvis' hip axis (its
    sign: the side)."""

    def __init__(self, scene: Scene):
        wc, law = scene.walker, scene.walker.hip_roll
        leg = wc.leg
        bodies = {b.name: b for b in leg.bodies}
        self.g, self.gamma = wc.gravity_m_per_s2, scene.slope.angle_rad
        self.L, self.L_thigh = leg.length_m, leg.knee.thigh_length_m
        self.M_hip = wc.hip_mass_kg
        self.m_thigh, self.d_thigh = (bodies["thigh_mass"].mass_kg,
                                      bodies["thigh_mass"].from_hip_m)
        self.m_shank, self.d_shank = (bodies["shank_mass"].mass_kg,
                                      bodies["shank_mass"].from_hip_m)
        self.I_pelvis = law.pelvis_roll_inertia_kg_m2
        self.law = (law.pelvis_stiffness_n_m_per_rad, law.pelvis_damping_n_m_s_per_rad,
                    law.swing_stiffness_n_m_per_rad, law.swing_damping_n_m_s_per_rad,
                    law.lean_gain, law.lean_rate_gain_s)
        self.s = np.array([math.cos(self.gamma), -math.sin(self.gamma), 0.0])
        self.z = np.array([0.0, 0.0, 1.0])
        self.S = np.array([[0, -self.s[2], self.s[1]], [self.s[2], 0, -self.s[0]],
                           [-self.s[1], self.s[0], 0]])
        self.Z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])

    def masses(self, w: float) -> list:
        """``(mass, terms)``: each point a sum of terms ``(roll, pitch or None, c)``, the
        term ``R_s(q_roll) R_z(q_pitch) c``."""
        L, Lt = self.L, self.L_thigh
        hip_st = [(LEAN, STANCE, np.array([0.0, L, 0.0]))]
        hip_sw = hip_st + [(PELVIS, None, w * self.z)]
        knee_sw = hip_sw + [(SWROLL, THIGH, np.array([0.0, -Lt, 0.0]))]
        return [
            (self.M_hip, hip_st + [(PELVIS, None, w / 2 * self.z)]),
            (self.m_thigh, [(LEAN, STANCE, np.array([0.0, L - self.d_thigh, 0.0]))]),
            (self.m_shank, [(LEAN, STANCE, np.array([0.0, L - self.d_shank, 0.0]))]),
            (self.m_thigh, hip_sw + [(SWROLL, THIGH, np.array([0.0, -self.d_thigh, 0.0]))]),
            (self.m_shank, knee_sw + [(SWROLL, SHANK,
                                       np.array([0.0, -(self.d_shank - Lt), 0.0]))]),
        ]

    def kin(self, terms, q, dq):
        """Position (3,), Jacobian (3, 6) and ``Jdot dq`` (3,) of a point."""
        r, J, h = np.zeros(3), np.zeros((3, N)), np.zeros(3)
        for ro, pitch, c in terms:
            R = Rotation.from_rotvec(q[ro] * self.s).as_matrix()
            T = np.eye(3) if pitch is None else Rotation.from_rotvec(q[pitch] * self.z).as_matrix()
            p = R @ T @ c
            r += p
            J[:, ro] += self.S @ p
            h += self.S @ self.S @ p * dq[ro] ** 2
            if pitch is not None:
                d = R @ self.Z @ T @ c
                J[:, pitch] += d
                h += 2 * self.S @ d * dq[ro] * dq[pitch] + R @ self.Z @ self.Z @ T @ c * dq[
                    pitch] ** 2
        return r, J, h

    def law_forces(self, q, dq) -> np.ndarray:
        """The law's generalised forces (6,): a couple ``tau s`` on the leg and ``-tau s``
        on the pelvis at each hip, whose virtual work is ``tau s . (omega_leg -
        omega_pelvis)``; ``s . omega`` of a body rolled by ``q_roll`` then pitched about its
        rolled ``z`` is ``dq_roll`` (``s . R_s z = 0``)."""
        k_p, c_p, k_s, c_s, g_l, g_r = self.law
        tau_st = k_p * q[PELVIS] + c_p * dq[PELVIS]
        tau_sw = -k_s * (q[SWROLL] - g_l * q[LEAN] - g_r * dq[LEAN]) - c_s * (
            dq[SWROLL] - dq[PELVIS])
        Q = np.zeros(N)
        Q[LEAN] += tau_st
        Q[SWROLL] += tau_sw
        Q[PELVIS] -= tau_st + tau_sw
        return Q

    def inverse_dynamics(self, w, q, dq, qdd) -> np.ndarray:
        """``sum m J^T (a - g) + I_p ddphi_p e_p - Q_law`` (6,): what ``M qdd + C dq + G``
        of the generated flow (the law's forces in ``G``) must equal."""
        grav = np.array([0.0, -self.g, 0.0])
        out = -self.law_forces(q, dq)
        out[PELVIS] += self.I_pelvis * qdd[PELVIS]
        for m, terms in self.masses(w):
            _, J, h = self.kin(terms, q, dq)
            out += m * J.T @ (J @ qdd + h - grav)
        return out


# --- the scene and its kind (quick) -----------------------------------------------------


def test_the_stabilised_kneed_walker_is_the_locking_knees_3d_kind_with_both_rolls():
    """The scene validates (hip-roll joints on locking knees in 3D), is the kind
    ``locking_knees_3d``, whose rigid cell takes the hip-roll law, and its roles are the
    kneed walker's with the pelvis' and the swing leg's rolls last."""
    scene = scene_from_dict(_raw())
    data = walker_data(scene.walker, scene.slope.angle_rad)
    kind = kind_of(data.structure)
    assert kind is KINDS["locking_knees_3d"]
    assert kind.supports("hip_roll", "rigid") and kind.supports("hip_roll", "gym")
    assert data.structure.roles == ("lean", "swing_thigh", "swing_shank", "stance",
                                    "pelvis_roll", "swing_roll")


# --- against the independent model and the gait (slow: the derivation) ------------------


@pytest.fixture(scope="module")
def stabilised():
    from walkerlab.models.registry import build_walker
    from walkerlab.walker.plant import Plant

    scene = Scene.model_validate(_raw())
    return build_walker(Plant.from_scene(scene)), scene


@pytest.mark.slow   # ~3 min cold: the kneed walker's derivation with hip-roll joints
def test_the_stabilised_kneed_flow_is_newtons_law_with_the_laws_couples(stabilised):
    """At random states (every roll and pitch different, rates nonzero) and
    accelerations, ``M qdd + C dq + G`` of the generated knee-free flow (the law's forces
    in ``G``) equals :class:`KneedNewton`'s inverse dynamics to 1e-10, on both mirror steps
    (the swing hip at +w and at -w)."""
    walker, scene = stabilised
    ref = KneedNewton(scene)
    w = scene.walker.hip_width_m
    rng = np.random.default_rng(5)
    for step, side in ((walker, w), (walker.mirror, -w)):
        for _ in range(5):
            q = rng.uniform(-0.4, 0.4, N)
            dq, qdd = rng.uniform(-2, 2, N), rng.uniform(-5, 5, N)
            M, C, G = step.matrices(np.concatenate([q, dq]))
            ours = M @ qdd + C @ dq + np.ravel(G)
            theirs = ref.inverse_dynamics(side, q, dq, qdd)
            assert np.max(np.abs(ours - theirs)) < 1e-10, (side, ours, theirs)


@pytest.mark.slow   # ~3 min cold: the kneed walker's derivation with hip-roll joints
def test_the_stabilised_kneed_gait_is_a_fixed_point_and_every_multiplier_inside_the_circle(
        stabilised, capsys):
    """The scene's initial guess (the gait, ``walkerlab fixedpoint``) maps to itself over a
    stride (both steps: a knee strike, then the heel strike) to 1e-8, and the stride map's
    Jacobian (the variational equations with saltation) has every multiplier inside the
    unit circle: the lateral mode of about 40 a stride (configs/kneed_3d.yaml) made stable
    by the foot-placement law.  The stride period is within 2 % of the passive one's
    (1.0905 s): the law steers the rolls, not the sagittal gait."""
    from walkerlab.analysis.gait.poincare import poincare_map

    walker, scene = stabilised
    x = _guess(scene, walker.state_names())
    x_next, period, DP, _ = poincare_map(walker, x, SOLVER, jacobian=True)
    mu = np.linalg.eigvals(DP)
    with capsys.disabled():
        print(f"\nkneed_3d_stabilised: stride period {period:.8f} s, |P(x) - x| "
              f"{np.max(np.abs(x_next - x)):.1e}, multipliers "
              f"{np.round(mu[np.argsort(-np.abs(mu))][:6], 4)}")
    assert np.max(np.abs(x_next - x)) < 1e-8
    assert np.max(np.abs(mu)) < 0.95
    assert abs(period - 1.0905) < 0.02 * 1.0905


@pytest.mark.slow   # ~1.5 min: the rigid gait's search, the export and 11 steps in MuJoCo
def test_the_stabilised_kneed_mjcf_walks_ten_steps_within_1_percent_of_the_rigid_period(
        tmp_path):
    """The scene's MJCF (the pelvis on slides and a roll, each leg's roll, hip and knee
    hinges, the knee latch and the hip-roll law run by walkerlab's walk loop) makes >= 10
    alternating heel strikes in MuJoCo without falling (the passive kneed walker's leaves
    its gait within its first stride), every step period within 3 % (the table's MJCF
    tolerance) and the mean within 1 % of the rigid one (the issue's target; measured
    -0.55 %)."""
    pytest.importorskip("mujoco")
    from walkerlab.cli.options import load
    from walkerlab.export.mujoco_walk import walk
    from walkerlab.stages import export

    out = export.write(load(str(ROOT / "configs" / SCENE)), tmp_path, "mjcf", walk=True)
    assert not out.walk.fell and out.walk.alternating and out.walk.strikes >= 10, out.walk.line
    run = walk(out.path, 11.3 * out.step_period_s)
    periods = np.asarray(run.step_periods_s)
    assert len(run.times_s) >= 10 and not run.fell
    assert np.max(np.abs(periods / out.step_period_s - 1.0)) < 0.03
    assert abs(np.mean(periods) / out.step_period_s - 1.0) < 0.01
