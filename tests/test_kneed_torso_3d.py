"""The kneed walker in 3D with an upper body (``configs/kneed_torso_powered_3d.yaml``):
configs/kneed_3d_stabilised.yaml's locking knees (McGeer 1990) with hip-roll joints and
Kuo's (1999) lateral foot placement, carrying an upper body on the bisecting hip (Wisse,
Hobbelen & Schwab 2007, IEEE Trans. Robotics 23(1)) driven by a torque between the upper
body and the stance leg (``joint: stance_hip``), derived from its body tree by
:func:`walkerlab.codegen.legged.derive_legged`, against:

- Newton's law for its six point masses and the pelvis' roll inertia, written here with no
  code shared with that derivation (each point a sum of rotated offsets, its Jacobian and
  velocity-product term by hand; the upper body's pitch the mean of the stance leg's and
  the swing thigh's; the laws' torques as couples whose generalised forces are their virtual
  work): the knee-free flow ``M qdd + C dq + G`` of both mirror steps, and the torso
  torque's accelerations ``M^-1 Q_torso``;
- the same law with a wrong upper body (its mass or its height off by 10 %): the check can
  fail;
- the rigid gait itself: the scene's fixed point maps to itself over a stride and every
  Floquet multiplier lies inside the unit circle.

Tolerances: the flow terms are of order 0.1-10 and both sides solve nothing (products and
sums of 3-vectors): 1e-11 absolute (measured 7e-15).  The torque's accelerations solve a
6 x 6 system (condition number ~2e3) for a torque of ~0.1 N m: 1e-10 (measured 8e-14).  A
wrong upper body (0.04 kg, 2 cm) moves the terms by 0.23-0.27 and 0.024-0.047 (measured):
far above the check's 1e-11.  The fixed point is stored to 10 decimals and the stride map
(DOP853 at 1e-12) returns it to ~3e-10; 1e-7 leaves room for the map's conditioning.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from tests.test_kneed_3d_stabilised import KneedNewton
from walkerlab.config import scene_from_dict
from walkerlab.config.schema import Scene
from walkerlab.integrate.solver import Solver
from walkerlab.walker.description import walker_data
from walkerlab.walker.kinds import KINDS, kind_of

ROOT = Path(__file__).resolve().parents[1]
SCENE = "kneed_torso_powered_3d.yaml"
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
# coordinates: lean (the stance leg's roll), swing thigh, swing shank, stance (pitches),
# pelvis roll, swing roll
LEAN, THIGH, SHANK, STANCE, PELVIS, SWROLL = range(6)
N = 6


def _raw() -> dict:
    return yaml.safe_load((ROOT / "configs" / SCENE).read_text())


def _unit(i: int) -> np.ndarray:
    e = np.zeros(N)
    e[i] = 1.0
    return e


class KneedTorsoNewton(KneedNewton):
    """The stabilised kneed walker from Newton's law (:class:`tests.test_kneed_3d_stabilised.
    KneedNewton`: world axes, the stance foot at the origin, each body's roll about the fall
    line ``s``, each link's pitch about its rolled ``z``) with the upper body, which rolls
    with the pelvis and pitches by the mean of the stance leg's and the swing thigh's pitch
    (the bisecting hip).  ``torso_mass``, ``torso_height``: the upper body's, overriding the
    scene's (a wrong model)."""

    def __init__(self, scene: Scene, torso_mass: float | None = None,
                 torso_height: float | None = None):
        super().__init__(scene)
        wc = scene.walker
        (torso,) = wc.torso.bodies
        self.m_torso = torso.mass_kg if torso_mass is None else torso_mass
        self.d_torso = torso.from_hip_m if torso_height is None else torso_height
        (t,) = wc.actuation.torques
        self.torso_law = (t.law.constant_n_m, t.law.stiffness_n_m_per_rad,
                          t.law.damping_n_m_s_per_rad, t.law.rest_angle_rad)

    def masses(self, w: float) -> list:
        """The kneed walker's points and the upper body's, up the bisector of the legs'
        pitches (its pitch a term's coefficients of the coordinates, (6,): :meth:`kin`)."""
        mid = [(LEAN, STANCE, np.array([0.0, self.L, 0.0])), (PELVIS, None, w / 2 * self.z)]
        bisector = (_unit(STANCE) + _unit(THIGH)) / 2
        return [*super().masses(w),
                (self.m_torso, mid + [(PELVIS, bisector, np.array([0.0, self.d_torso, 0.0]))])]

    def kin(self, terms, q, dq):
        """Position (3,), Jacobian (3, 6) and ``Jdot dq`` (3,) of a point whose terms'
        pitches are a coordinate's index or coefficients of the coordinates (6,)."""
        r, J, h = np.zeros(3), np.zeros((3, N)), np.zeros(3)
        for ro, pitch, c in terms:
            if isinstance(pitch, int):
                pitch = _unit(pitch)
            R = Rotation.from_rotvec(q[ro] * self.s).as_matrix()
            b, db = (0.0, 0.0) if pitch is None else (pitch @ q, pitch @ dq)
            T = Rotation.from_rotvec(b * self.z).as_matrix()
            p = R @ T @ c
            r += p
            J[:, ro] += self.S @ p
            h += self.S @ self.S @ p * dq[ro] ** 2
            if pitch is not None:
                d = R @ self.Z @ T @ c
                J += np.outer(d, pitch)
                h += 2 * self.S @ d * dq[ro] * db + R @ self.Z @ self.Z @ T @ c * db ** 2
        return r, J, h

    def torso_forces(self, q, dq) -> np.ndarray:
        """The torso torque's generalised forces (6,): ``tau`` on the stance leg about its
        pitch axis ``R_s(lean) z``, ``-tau`` on the upper body about its own ``R_s(phi_p)
        z`` and the difference on the pelvis (about a direction normal to ``s``, which the
        pelvis, rolling about ``s`` alone, does no work against): virtual work ``tau
        (delta theta_st - delta theta_torso)``, ``tau = c - k (alpha - r) - d alpha'`` on
        ``alpha = theta_st - theta_torso``."""
        c, k, d, r = self.torso_law
        grad = _unit(STANCE) - (_unit(STANCE) + _unit(THIGH)) / 2
        alpha, dalpha = grad @ q, grad @ dq
        return (c - k * (alpha - r) - d * dalpha) * grad


# --- the scene and its kind (quick) -----------------------------------------------------


def test_the_kneed_walker_in_3d_carries_an_upper_body_on_the_bisecting_hip():
    """The scene validates (an upper body on locking knees in 3D, with hip-roll joints and a
    torso torque), is the kind ``locking_knees_3d``, whose rigid and gym cells take the
    torso torque, its roles the stabilised kneed walker's (the upper body has no
    coordinate of its own) and its parameters carry the upper body's."""
    scene = scene_from_dict(_raw())
    data = walker_data(scene.walker, scene.slope.angle_rad)
    kind = kind_of(data.structure)
    assert kind is KINDS["locking_knees_3d"]
    assert kind.supports("torso_torque", "rigid") and kind.supports("torso_torque", "gym")
    assert data.structure.roles == ("lean", "swing_thigh", "swing_shank", "stance",
                                    "pelvis_roll", "swing_roll")
    assert {"m_torso_mass", "d_torso_mass"} <= set(data.structure.param_names)


# --- against the independent model and the gait (slow: the derivation) ------------------


@pytest.fixture(scope="module")
def powered():
    from walkerlab.models.registry import build_walker
    from walkerlab.walker.plant import Plant

    scene = Scene.model_validate(_raw())
    passive = _raw()
    passive["walker"].pop("actuation")
    return (build_walker(Plant.from_scene(scene)),
            build_walker(Plant.from_scene(Scene.model_validate(passive))), scene)


def _states(seed: int, count: int = 5):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        yield rng.uniform(-0.4, 0.4, N), rng.uniform(-2, 2, N), rng.uniform(-5, 5, N)


@pytest.mark.slow   # ~13 min cold: the kneed walker's derivation with hip rolls and a torso
def test_the_kneed_torso_flow_is_newtons_law_with_the_laws_couples(powered, capsys):
    """At random states (every roll and pitch different, rates nonzero) and
    accelerations, ``M qdd + C dq + G`` of the generated passive knee-free flow (the
    hip-roll law's forces in ``G``) equals :class:`KneedTorsoNewton`'s inverse dynamics to
    1e-11, and the torso torque's accelerations (the driven flow's less the passive
    one's) its ``M^-1 Q_torso`` to 1e-10, on both mirror steps (the swing hip at +w and at
    -w).  (The accelerations themselves agree to ~1e-7 only: ``M``'s smallest eigenvalue,
    ~1e-3 kg m^2 (the swing shank's), turns the terms' 1e-11 into 1e-8 of qdd ~500 rad/s^2
    at these states.)"""
    walker, passive, scene = powered
    ref = KneedTorsoNewton(scene)
    w = scene.walker.hip_width_m
    worst = [0.0, 0.0]
    for (step, free), side in (((walker, passive), w), ((walker.mirror, passive.mirror), -w)):
        for q, dq, qdd in _states(7):
            x = np.concatenate([q, dq])
            M, C, G = free.matrices(x)
            ours = M @ qdd + C @ dq + np.ravel(G)
            theirs = ref.inverse_dynamics(side, q, dq, qdd)
            driven = (np.asarray(step.phases[0].flow(0.0, x))[N:]
                      - np.asarray(free.phases[0].flow(0.0, x))[N:])
            bias = ref.inverse_dynamics(side, q, dq, np.zeros(N))
            M_ref = np.column_stack([ref.inverse_dynamics(side, q, dq, _unit(i)) - bias
                                     for i in range(N)])
            torque = np.linalg.solve(M_ref, ref.torso_forces(q, dq))
            assert np.max(np.abs(torque)) > 1e-2   # the torque does act
            worst = [max(worst[0], np.max(np.abs(ours - theirs))),
                     max(worst[1], np.max(np.abs(driven - torque)))]
            assert np.max(np.abs(ours - theirs)) < 1e-11, (side, ours, theirs)
            assert np.max(np.abs(driven - torque)) < 1e-10, (side, driven, torque)
    with capsys.disabled():
        print(f"\nkneed_torso: |M qdd + C dq + G - Newton| {worst[0]:.1e}, "
              f"|qdd_torque - Newton's| {worst[1]:.1e}")


@pytest.mark.slow   # the derivation (the fixture's)
def test_a_wrong_upper_body_misses_the_kneed_torso_flow(powered):
    """The check can fail: the same Newton's law with the upper body's mass or height 10 %
    off (0.04 kg, 2 cm) misses the generated flow by more than 1e-3 at every state
    (measured: at least 0.23 and 0.024)."""
    _, passive, scene = powered
    (torso,) = scene.walker.torso.bodies
    w = scene.walker.hip_width_m
    for wrong in (KneedTorsoNewton(scene, torso_mass=1.1 * torso.mass_kg),
                  KneedTorsoNewton(scene, torso_height=1.1 * torso.from_hip_m)):
        for q, dq, qdd in _states(11, 3):
            M, C, G = passive.matrices(np.concatenate([q, dq]))
            ours = M @ qdd + C @ dq + np.ravel(G)
            assert np.max(np.abs(ours - wrong.inverse_dynamics(w, q, dq, qdd))) > 1e-3


@pytest.mark.slow   # the derivation and a stride's variational equations
def test_the_kneed_torso_gait_is_a_fixed_point_and_every_multiplier_inside_the_circle(
        powered, capsys):
    """The scene's initial guess (the gait, ``walkerlab fixedpoint``) maps to itself over a
    stride (both steps: a knee strike, then the heel strike) to 1e-7, and the stride map's
    Jacobian (the variational equations with saltation) has every multiplier inside the
    unit circle."""
    from walkerlab.analysis.gait.poincare import poincare_map

    walker, _, scene = powered
    g = scene.fixedpoint.initial_guess.model_extra
    x = np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                  for n in walker.state_names()])
    x_next, period, DP, _ = poincare_map(walker, x, SOLVER, jacobian=True)
    mu = np.linalg.eigvals(DP)
    with capsys.disabled():
        print(f"\nkneed_torso_powered_3d: stride period {period:.8f} s, |P(x) - x| "
              f"{np.max(np.abs(x_next - x)):.1e}, multipliers "
              f"{np.round(mu[np.argsort(-np.abs(mu))][:6], 4)}")
    assert np.max(np.abs(x_next - x)) < 1e-7
    assert np.max(np.abs(mu)) < 1.0


# --- the MJCF (issue 98): the upper body's hinge on the thighs' mean ---------------------


def test_the_kneed_mjcfs_keyframe_sets_the_upper_body_on_the_thighs_mean():
    """The 3D MJCF's keyframe puts the upper body's hinge on the bisecting hip's pitch: on
    knees the mean of the swing thigh's and the stance leg's pitch and rates (the equality
    couples the thighs' hinges leg<i>_hip), not the swing shank's (a state with the swing
    knee bent by 0.3 rad); on straight legs the legs' mean.  Before, the kneed walker's had
    no ``swing_angle`` (the export refused it)."""
    from walkerlab.export.legs_3d_parts import bisector_keyframe

    roles = walker_data(scene_from_dict(_raw()).walker, 0.05).structure.roles
    names = [f"{r}_angle" for r in roles] + [f"{r}_rate" for r in roles]
    x = np.linspace(-0.5, 0.7, len(names))
    s = dict(zip(names, x))
    s["swing_shank_angle"] = s["swing_thigh_angle"] - 0.3
    q, v = bisector_keyframe(roles, [s[n] for n in names])
    assert q == pytest.approx((s["swing_thigh_angle"] + s["stance_angle"]) / 2, abs=1e-15)
    assert v == pytest.approx((s["swing_thigh_rate"] + s["stance_rate"]) / 2, abs=1e-15)
    straight = ("lean", "swing", "stance", "pelvis_roll", "swing_roll")
    q, v = bisector_keyframe(straight, [0.1, 0.4, -0.2, 0.0, 0.0, 1.0, 3.0, -1.0, 0.0, 0.0])
    assert (q, v) == pytest.approx((0.1, 1.0), abs=1e-15)


@pytest.mark.slow  # ~14 min on a shared machine cold (the gait and its derivation); ~2 warm
def test_the_kneed_torso_walkers_mjcf_walks_at_its_rigid_period(tmp_path):
    """The kneed upper-body walker's MJCF (its torso on the hinge held to the thighs' mean
    by an equality, the knee latch, the hip-roll law and the torso torque run by walkerlab's
    walk loop) walked in MuJoCo: >= 10 alternating heel strikes without a fall, the mean
    step period within 1 % of the rigid gait's (measured: 11 heel strikes, 0.716828 s
    against 0.715272 s, +0.22 %)."""
    pytest.importorskip("mujoco")
    from walkerlab.cli.options import load
    from walkerlab.stages import export

    scene = load(str(ROOT / "configs" / SCENE))
    out = export.write(scene, tmp_path, "mjcf", walk=True)
    w = out.walk
    assert not w.fell and w.alternating and w.strikes >= 10, w.line
    assert abs(w.period_s / w.rigid_period_s - 1.0) < 0.01, w.line
