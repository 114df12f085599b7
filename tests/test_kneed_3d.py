"""A walker with locking knees in three dimensions (``model: biped``, ``space: 3d``, a knee
with ``lock: plastic``; McGeer 1990, "Passive walking with knees"; Kuo 1999's hip width),
derived from its body tree (:func:`walkerlab.walker.trees.legs_tree`) by
:func:`walkerlab.codegen.legged.derive_legged`, against references that share no
kinematics with that tree:

- the planar kneed walker (configs/kneed.yaml: the planar tree, whose equations equal the
  leg-vector sums of ``tests/independent/planar_link_sums.py``): with zero hip width and
  started upright the 3D walker walks its gait;
- Pinocchio's recursive Newton-Euler algorithm on a model built here by hand (the pelvis
  welded to the stance leg, each joint's angle relative to its parent: another
  parametrisation than the tree's absolute pitches) for the flow ``M qdd + C dq + G``;
- the angular momenta a plastic knee strike conserves, computed here from the point
  masses' positions and velocities (``sum m r x v``).

Tolerances: fixed points are solved to 1e-12 with DOP853 at 1e-12, so one gait by two
derivations agrees to ~1e-11 (1e-9 relative leaves room for the lateral multiplier's
conditioning, ~7 a step); the flow and momenta of one walker by two models agree to
round-off (1e-10 on terms of order 1-10).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.test_parts_3d import (  # the same walker, guess and planar-embedding checks
    _guess,
    _planar_embedding,
    _walker,
)
from walkerlab.config import scene_from_dict
from walkerlab.config.schema import Scene
from walkerlab.integrate.solver import Solver
from walkerlab.walker.kinds import KINDS, kind_of

ROOT = Path(__file__).resolve().parents[1]
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
#: configs/kneed.yaml's numbers (Hsu Chen 2007): hip, thigh and shank masses [kg], the
#: masses' distances from the hip and the thigh's length [m]
M_HIP, M_THIGH, M_SHANK = 0.5, 0.5, 0.05
D_THIGH, D_SHANK, L_THIGH, LEG = 0.3, 0.65, 0.5, 1.0


def _raw(name: str) -> dict:
    return yaml.safe_load((ROOT / "configs" / name).read_text())


def _kneed_in_3d(width: float) -> dict:
    raw = _raw("kneed.yaml")
    for key in ("contact", "terrain", "contact_sim", "contact_solver"):
        raw.pop(key, None)
    raw["walker"] = {**raw["walker"], "space": "3d", "hip_width_m": width}
    return raw


# --- the scene's check and the kind (quick) -------------------------------------------------


def test_a_kneed_walker_in_3d_is_the_locking_knees_3d_kind_of_the_rigid_view_and_exports():
    """``space: 3d`` with a plastic knee validates and is the kind ``locking_knees_3d``
    (knees ``locking``, the 3D legs' body); its roles are the planar kneed walker's with
    the lean first; every view takes it: the rigid view, the contact model
    (tests/test_kneed_3d_contact.py), the MJCF, the URDF, the gym
    (tests/test_kneed_3d_export.py), the Adams dataset (tests/test_export_adams_3d_knees.py)
    and the collocation (a stride of phased steps: tests/test_optimize_3d.py), its
    push-off included (the extended impact with the swing knee held)."""
    from walkerlab.walker.description import walker_data

    scene = scene_from_dict(_kneed_in_3d(0.1))
    data = walker_data(scene.walker, scene.slope.angle_rad)
    kind = kind_of(data.structure)
    assert kind is KINDS["locking_knees_3d"] and kind.knees_lock and kind.in_3d
    assert data.structure.roles == ("lean", "swing_thigh", "swing_shank", "stance")
    assert data.structure.mirror_odd_roles == ("lean",)   # steps on alternate sides
    assert all(kind.supports("walk", v)
               for v in ("rigid", "contact", "mjcf", "urdf", "gym", "adams", "osim",
                         "optimize"))
    kind.require("push_off", "optimize", "walker.actuation.push_off")  # taken
    assert not kind.supports("profile", "rigid")
    # round feet on the shanks: configs/kneed_round_feet_3d.yaml (the slow test below)
    assert kind.supports("round_feet_3d", "rigid") and kind.supports("round_feet_3d", "contact")
    # an upper body on the bisecting hip: configs/kneed_torso_powered_3d.yaml
    # (tests/test_kneed_torso_3d.py)
    assert kind.supports("torso_torque", "rigid")
    # hip-roll joints: configs/kneed_3d_stabilised.yaml (tests/test_kneed_3d_stabilised.py)
    assert kind.supports("hip_roll", "rigid")
    # the planar kneed walker's torques and push-off (tests/test_kneed_3d_powered.py)
    for feature in ("hip_torque", "knee_torque", "push_off"):
        assert kind.supports(feature, "rigid"), feature
    # stairs and footholds: the straight legs' landing (tests/test_stairs_3d.py)
    assert kind.supports("stairs", "rigid") and kind.supports("footholds", "rigid")


@pytest.mark.parametrize(("change", "field"), [
    (lambda w: w["leg"]["knee"].update(lock="free"), "walker.leg.knee"),
    (lambda w: w["leg"]["knee"].update(spring={"stiffness_n_m_per_rad": 1.0}),
     "walker.leg.knee"),
])
def test_what_a_kneed_walker_in_3d_does_not_take_is_refused_in_one_line_naming_the_field(
        change, field):
    """Free knees and a knee spring on locking knees in 3D: one line naming the field
    (the tree would carry them; their derivations are not checked).  An upper body
    on the bisecting hip is taken (tests/test_kneed_torso_3d.py)."""
    raw = _kneed_in_3d(0.1)
    change(raw["walker"])
    with pytest.raises(Exception) as err:
        scene_from_dict(raw)
    msg = str(err.value)
    assert f"{field}:" in msg and ("space: 3d" in msg or "in 3D" in msg), msg


def test_the_knee_lock_conserves_the_projected_momenta_and_stops_the_knee():
    """:func:`walkerlab.codegen.lagrange.knee_lock` (shared by the planar and the 3D
    kneed walkers) on a random symmetric positive mass matrix: after the knee strike the
    knee's relative rate is 0 and ``S^T M dq`` (the momenta along the motions the lock
    allows) is unchanged; the locked flow's accelerations keep the knee straight."""
    import sympy as sp

    from walkerlab.codegen.lagrange import knee_lock

    rng = np.random.default_rng(3)
    n, thigh, shank = 4, 1, 2
    a = rng.normal(size=(n, n))
    M = a @ a.T + n * np.eye(n)
    C, G = rng.normal(size=(n, n)), rng.normal(size=(n, 1))
    lock = knee_lock(sp.Matrix(M), sp.Matrix(C), sp.Matrix(G), sp.Matrix(M), sp.Matrix(M),
                     thigh, shank)
    Mk, Bk = (np.array(m, float) for m in lock.knee_impact)
    dq = rng.normal(size=n)
    dq_plus = np.linalg.solve(Mk, Bk @ dq)
    assert abs(dq_plus[shank] - dq_plus[thigh]) < 1e-13
    S = np.delete(np.eye(n), shank, axis=1)
    S[shank, thigh] = 1.0
    assert np.allclose(S.T @ M @ dq_plus, S.T @ M @ dq, rtol=0, atol=1e-12)
    Ml, Cl, Gl = (np.array(m, float) for m in lock.locked)
    qdd = np.linalg.solve(Ml, -Cl @ dq_plus - Gl[:, 0])
    assert abs(qdd[shank] - qdd[thigh]) < 1e-12


# --- against independent references (slow: the 3D kneed walker's derivation) ---------------


@pytest.mark.slow   # ~1.5 min cold: the 3D kneed derivation (zero hip width)
def test_the_kneed_walker_in_3d_with_zero_hip_width_walks_the_planar_kneed_gait():
    """configs/kneed.yaml with ``space: 3d`` and ``hip_width_m: 0``, started upright from
    the planar gait (configs/kneed.yaml's generator, leg-vector sums in the plane: no
    kinematics shared with the tree): the same fixed point and step period to 1e-9
    relative, the lean and its rate 0, the planar multipliers among the 3D ones (the
    others: the roll's unstable lateral mode, and 0s)."""
    from walkerlab.analysis.gait.poincare import find_fixed_point

    flat_scene = Scene.model_validate({k: v for k, v in _raw("kneed.yaml").items()
                                       if k not in ("contact", "terrain", "contact_sim",
                                                    "contact_solver")})
    flat = _walker(flat_scene)
    f = find_fixed_point(flat, _guess(flat_scene, flat.state_names()), SOLVER,
                         fd_check=False)
    s = _planar_embedding(flat, f, _walker(Scene.model_validate(_kneed_in_3d(0.0))),
                          tiny=1e-6)
    print(f"planar step period {f.period_s:.12f} s, 3D {s.period_s:.12f} s; multipliers "
          f"3D {np.round(np.abs(s.multipliers_variational), 6)}")


@pytest.mark.slow   # ~1 min cold: the planar and the 3D kneed derivations on round feet
def test_the_kneed_walker_on_round_feet_in_3d_walks_the_planar_kneed_gait_on_arc_feet():
    """configs/kneed_round_feet_3d.yaml (each shank's foot a disc of radius 0.1 m in its
    leg's plane, zero hip width), started upright from the gait of configs/kneed.yaml on
    arc feet of that radius (the planar tree's arc foot rolling on the slope, leg-vector
    sums in the plane; the 3D tree's disc, its lowest point on the slope's normal): the
    same fixed point and step period to 1e-9 relative, the lean and its rate 0, the planar
    multipliers among the 3D ones.  The same feet on straight legs:
    tests/test_round_feet_3d.py."""
    from walkerlab.analysis.gait.poincare import find_fixed_point

    raw = _raw("kneed.yaml")
    raw["walker"]["leg"]["foot"] = {"kind": "arc", "radius_m": 0.1}
    flat_scene = Scene.model_validate({k: v for k, v in raw.items()
                                       if k not in ("contact", "terrain", "contact_sim",
                                                    "contact_solver")})
    shipped = Scene.model_validate(_raw("kneed_round_feet_3d.yaml"))
    flat = _walker(flat_scene)
    start = _guess(shipped, _walker(shipped).state_names())[[1, 2, 3, 5, 6, 7]]
    f = find_fixed_point(flat, start, SOLVER, fd_check=False)
    s = _planar_embedding(flat, f, _walker(shipped), tiny=1e-6)
    assert abs(s.period_s - 0.53683) < 1e-5      # the scene's comment
    assert np.max(np.abs(s.multipliers_variational)) > 6.0   # the unstable lean


@pytest.mark.slow   # ~1 min: the round-feet gait's MJCF walked in MuJoCo
def test_the_kneed_walker_on_round_feet_walks_in_mujoco_at_the_rigid_step_period(tmp_path):
    """configs/kneed_round_feet_3d.yaml's MJCF (each shank's disc a MuJoCo cylinder, the
    knee latch stiffer under discs: walkerlab.export.legs_3d_mjcf.DISC_LATCH_SOLREF, no patch
    under the trailing disc at the keyframe) walked by MuJoCo: >= 10 alternating heel
    strikes without falling, the mean step period within 3 % of the rigid gait's (measured
    11 strikes, -0.11 %; with MuJoCo's default latch the stance knee buckles and the walker
    falls before its first heel strike)."""
    pytest.importorskip("mujoco")
    from walkerlab.stages import export as export_stage

    scene = Scene.model_validate(_raw("kneed_round_feet_3d.yaml"))
    check = export_stage.write(scene, tmp_path, "mjcf", walk=True).walk
    assert check.walked and not check.fell and check.alternating, check.line
    assert check.strikes >= 10, check.line
    assert check.period_s == pytest.approx(check.rigid_period_s, rel=0.03), check.line


@pytest.mark.slow   # ~1 min: the rigid gait, then twelve heel strikes of the contact walk
def test_the_kneed_walker_on_round_feet_pushes_off_in_contact_at_the_rigid_step_period(
        tmp_path):
    """configs/kneed_round_feet_3d.yaml with a 0.1 N s push-off (walker.actuation.push_off:
    the rigid impulse, and the contact pulse, at the trailing disc's material contact point
    along the line to its hip; the swing knee held): ``walkerlab contact-sim`` walks 10
    heel strikes or more, its mean step period over steps 3-9 within 1 % of the rigid
    gait's (measured +0.66 %; the rigid step 1.8 % longer than the passive one)."""
    import h5py

    from walkerlab.stages import pipeline

    raw = _raw("kneed_round_feet_3d.yaml")
    raw["walker"]["actuation"] = {"push_off": {"impulse_n_s": 0.1}}
    scene = Scene.model_validate(raw)
    fp = pipeline.run("fixedpoint", scene, tmp_path).path
    cs = pipeline.run("contact-sim", scene, tmp_path).path
    with h5py.File(cs) as f, h5py.File(fp) as g:
        h = np.asarray(f["events/heel_strike_times"][()], float)
        assert h.size >= 10, f.attrs.get("outcome_message", "")
        rigid = float(np.ravel(g["step_period"][()])[0])
    period = float(np.mean(np.diff(h[2:10])))  # steps 3-9: the start's transient settled
    assert period == pytest.approx(rigid, rel=0.01), (period, rigid)


@pytest.fixture(scope="module")
def kneed_3d():
    """configs/kneed_3d.yaml's walker (0.1 m hip width) and its scene."""
    scene = Scene.model_validate(_raw("kneed_3d.yaml"))
    return _walker(scene), scene


def _pinocchio_flow(q, dq, qdd, w: float, gamma: float, g: float):
    """``M qdd + C dq + G`` (4,) of the kneed walker in 3D in walkerlab's coordinates
    ``(lean, swing_thigh, swing_shank, stance)`` from Pinocchio's RNEA on a model built
    here: in the slope's frame (x the fall line, y its normal, z across), the stance leg on
    a roll joint about x then a pitch joint about the rolled z at the stance foot, the
    pelvis welded to it (its point mass on the hip axis: the pelvis' pitch moves nothing),
    the swing leg on a pitch joint ``w`` along the hip axis, the shank on a pitch joint at
    the knee.  Its joint angles are relative (``th_st + gamma``, ``th_sw - th_st``,
    ``th_sh - th_sw``), so walkerlab's equations are ``T^T RNEA(T q + c, T dq, T qdd)``."""
    import pinocchio as pin

    def point(m, c):  # a point mass at c in its joint's frame
        return pin.Inertia(m, np.asarray(c, float), np.zeros((3, 3)))

    model = pin.Model()
    roll = model.addJoint(0, pin.JointModelRX(), pin.SE3.Identity(), "ankle_roll")
    model.appendBodyToJoint(roll, point(0.0, [0, 0, 0]), pin.SE3.Identity())
    stance = model.addJoint(roll, pin.JointModelRZ(), pin.SE3.Identity(), "ankle_pitch")
    for m, d in ((M_THIGH, D_THIGH), (M_SHANK, D_SHANK)):   # the straight stance leg
        model.appendBodyToJoint(stance, point(m, [0, LEG - d, 0]), pin.SE3.Identity())
    model.appendBodyToJoint(stance, point(M_HIP, [0, LEG, w / 2]), pin.SE3.Identity())
    swing = model.addJoint(stance, pin.JointModelRZ(),
                           pin.SE3(np.eye(3), np.array([0.0, LEG, w])), "swing_hip")
    model.appendBodyToJoint(swing, point(M_THIGH, [0, -D_THIGH, 0]), pin.SE3.Identity())
    knee = model.addJoint(swing, pin.JointModelRZ(),
                          pin.SE3(np.eye(3), np.array([0.0, -L_THIGH, 0.0])), "knee")
    model.appendBodyToJoint(knee, point(M_SHANK, [0, -(D_SHANK - L_THIGH), 0]),
                            pin.SE3.Identity())
    model.gravity = pin.Motion(np.array([g * np.sin(gamma), -g * np.cos(gamma), 0.0]),
                               np.zeros(3))
    data = model.createData()
    # relative joint angles from walkerlab's (lean, thigh, shank, stance): q_pin = T q + c
    T = np.array([[1, 0, 0, 0], [0, 0, 0, 1], [0, 1, 0, -1], [0, -1, 1, 0]], float)
    c = np.array([0.0, gamma, 0.0, 0.0])
    tau = pin.rnea(model, data, T @ q + c, T @ dq, T @ qdd)
    return T.T @ tau


@pytest.mark.slow   # ~2 min cold: the 3D kneed derivation with hip width
def test_the_kneed_walkers_flow_in_3d_is_pinocchios_on_a_hand_built_model(kneed_3d):
    """At random states (lean and rates nonzero) and accelerations, ``M qdd + C dq + G`` of
    the generated equations (hip width 0.1 m, the mirror step's -0.1 m too) is Pinocchio's
    inverse dynamics of the hand-built model (:func:`_pinocchio_flow`) to 1e-10."""
    pytest.importorskip("pinocchio")
    walker, scene = kneed_3d
    gamma, g = scene.slope.angle_rad, scene.walker.gravity_m_per_s2
    rng = np.random.default_rng(7)
    for step, w in ((walker, 0.1), (walker.mirror, -0.1)):
        for _ in range(5):
            q = rng.uniform(-0.4, 0.4, 4)
            dq, qdd = rng.uniform(-2, 2, 4), rng.uniform(-5, 5, 4)
            M, C, G = step.matrices(np.concatenate([q, dq]))
            ours = M @ qdd + C @ dq + np.ravel(G)
            ref = _pinocchio_flow(q, dq, qdd, w, gamma, g)
            assert np.max(np.abs(ours - ref)) < 1e-10, (w, ours, ref)


def _momenta(walker, x, gamma: float) -> tuple[float, float, float]:
    """The angular momenta a knee strike conserves, from the point masses (``sum m r x v``,
    velocities by a central difference of the named points along the rates, step 1e-6:
    error ~1e-12): the whole walker's about the stance foot along the fall line and along
    the stance leg's pitch axis (the rolled slope-normal ``Rot(s, lean) z``), and the swing
    leg's about its hip along that axis (world axes)."""
    n = x.size // 2
    masses = {"hip": M_HIP, "stance_thigh_mass": M_THIGH, "stance_shank_mass": M_SHANK,
              "swing_thigh_mass": M_THIGH, "swing_shank_mass": M_SHANK}
    h = 1e-6

    def at(xx):
        return {k: np.asarray(v, float).ravel() for k, v in walker.points(xx).items()}

    p = at(x)
    shift = np.concatenate([x[n:], np.zeros(n)]) * h
    ahead, behind = at(x + shift), at(x - shift)
    v = {k: (ahead[k] - behind[k]) / (2 * h) for k in masses}
    lean = x[0]
    s = np.array([np.cos(gamma), -np.sin(gamma), 0.0])
    nrm = np.array([np.sin(gamma), np.cos(gamma), 0.0])
    pitch = -np.sin(lean) * nrm + np.cos(lean) * np.array([0.0, 0.0, 1.0])
    H = sum(m * np.cross(p[k], v[k]) for k, m in masses.items())
    hip = p["swing_hip"]  # about the (moving) hip with absolute velocities, as McGeer's
    H_swing = sum(m * np.cross(p[k] - hip, v[k]) for k, m in masses.items()
                  if k.startswith("swing"))
    return H @ s, H @ pitch, H_swing @ pitch


@pytest.mark.slow   # uses the 3D kneed derivation with hip width (cached by the flow test)
def test_the_knee_strike_in_3d_conserves_the_swing_legs_and_the_whole_walkers_momenta(
        kneed_3d):
    """The plastic knee strike (the generated ``knee_reset`` of the 3D kneed walker) at
    random states with the knee straight and still extending: the shank's rate becomes the
    thigh's, the angles do not change, and the angular momenta about the stance foot (along the fall
    line and the stance leg's pitch axis) and the swing leg's about its hip (along the
    pitch axis) are conserved to 1e-9 relative (the impulse acts at the knee, inside the
    swing leg, and at the stance foot; McGeer 1990)."""
    walker, scene = kneed_3d
    knee_reset = walker.phases[0].guards[0].reset
    gamma = scene.slope.angle_rad
    rng = np.random.default_rng(11)
    for _ in range(5):
        lean, thigh, stance = rng.uniform(-0.1, 0.1), rng.uniform(-0.5, 0.5), rng.uniform(
            -0.3, 0.3)
        # the knee straight (the guard's zero), the shank still swinging forward
        x = np.array([lean, thigh, thigh, stance, *rng.uniform(-1.5, 1.5, 4)])
        x[6] = x[5] + abs(x[6])
        before = _momenta(walker, x, gamma)
        y = np.asarray(knee_reset(x), float)
        assert np.array_equal(y[:4], x[:4])
        assert abs(y[6] - y[5]) < 1e-12
        after = _momenta(walker, y, gamma)
        for b, a in zip(before, after):
            assert abs(a - b) <= 1e-9 * max(1.0, abs(b)), (before, after)


@pytest.mark.slow   # uses the 3D kneed derivation with hip width
def test_the_kneed_walker_with_hip_width_has_a_period_one_stride_its_five_strides_close(
        kneed_3d, capsys):
    """configs/kneed_3d.yaml (0.1 m hip width): the fixed point of the stride map (steps on
    alternate sides, the lean odd), found from the scene's guess (continued from the planar
    gait), its Floquet multipliers printed; simulated five strides from it, each stride's
    end state is the fixed point to ``2 * residual * |mu_max|^k`` (k strides: an error
    grows at most by the largest multiplier a stride; at least 1e-11), and each stride's
    two steps have one period (a mirrored pair), their sum the stride's, to the same
    bound [s]."""
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.integrate.rigid import simulate_steps

    walker, scene = kneed_3d
    s = find_fixed_point(walker, _guess(scene, walker.state_names()), SOLVER, fd_check=False)
    mu = np.asarray(s.multipliers_variational)
    res = max(float(s.residual), 1e-13)
    with capsys.disabled():
        print(f"\nkneed_3d: x* = {np.round(s.x, 10)}, stride period {s.period_s:.10f} s, "
              f"residual {res:.1e}\n  Floquet multipliers per stride: "
              f"{np.round(mu[np.argsort(-np.abs(mu))], 6)}")
    assert res < 1e-11 and 30 < np.max(np.abs(mu)) < 50   # Kuo's unstable lateral mode
    assert abs(s.x[0]) > 1e-3 and abs(s.x[1] - s.x[2]) < 1e-12
    traj = simulate_steps(walker, np.asarray(s.x), 10, SOLVER)
    assert len(traj.segments) == 10
    big = float(np.max(np.abs(mu)))
    errors = []
    for k in range(1, 6):
        seg_a, seg_b = traj.segments[2 * k - 2], traj.segments[2 * k - 1]
        assert seg_a.termination == seg_b.termination == "heel_strike"
        err = float(np.max(np.abs(np.asarray(seg_b.x_next) - np.asarray(s.x))))
        errors.append(err)
        bound = max(2 * res * big ** k, 1e-11)
        assert err <= bound, (k, err)
        ta, tb = seg_a.t_end - seg_a.t_start, seg_b.t_end - seg_b.t_start
        assert abs(ta - tb) <= bound and abs(ta + tb - s.period_s) <= bound
    with capsys.disabled():
        print(f"  strides' distance from x*: {[f'{e:.1e}' for e in errors]}")
