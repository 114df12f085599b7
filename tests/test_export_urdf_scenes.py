"""The shipped scenes' URDFs (one writer for planar and 3D legged walkers,
:func:`walkerlab.export.urdf.legs_urdf_text`) loaded by Pinocchio (Carpentier et al. 2019,
its own articulated-body algorithms) against walkerlab's own rigid model, for the scenes
``tests/test_export.py`` (the independent floating walker), ``tests/test_export_five_link.py``
(a five-link test biped), ``tests/test_walker_3d.py`` (``hip_width``) and
``tests/test_legs_3d_urdf.py`` (``hip_width_powered``) do not load:

- planar: the mass matrix (CRBA), the gravity torques and the bias (RNEA) of the URDF, carried
  to walkerlab's floating coordinates (``tests/test_export.py``'s :class:`Pinocchio`), equal the
  generated floating view's (:class:`walkerlab.models.hybrid.floating_view.FloatingView`) at
  the gait keyframe of the file's sidecar (``walker.gait.json``) and at random states;
- 3D: the URDF on a free-flyer root put in the rigid walker's state (its pelvis where the
  generated model's hip is, turned by its roll; each hinge at its angle, the bisecting hip's
  torso at the legs' mean): Pinocchio's kinetic and potential energies equal the generated
  model's (:func:`walkerlab.codegen.cache.functions`, ``energies``) at random states.

Tolerance 1e-12 of the largest entry: the files carry every number with 17 significant
digits (round-off only); the 3D point masses carry the export's inertia floor
(:data:`walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`, 1e-12 kg m^2 about every axis),
which adds at most ``1e-12 |omega|^2`` to the kinetic energy: the 3D bound is 1e-12 of the
energy plus that.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from tests.test_export import Pinocchio
from walkerlab.config import load_scene
from walkerlab.stages import export as export_stage
from walkerlab.walker.description import walker_data

pin = pytest.importorskip("pinocchio")

ROOT = Path(__file__).resolve().parents[1]
TOL = 1e-12

#: the shipped planar scenes whose URDF no other test loads (the gait search of the
#: five-link scenes takes longest: slow)
PLANAR = ("compass_optimal", "asymmetric_optimal", "kneed_optimal", "powered_compass",
          "torso_powered", "threelink", "threelink_hzd",
          pytest.param("rabbit", marks=pytest.mark.slow),
          pytest.param("rabbit_hzd", marks=pytest.mark.slow),
          pytest.param("rabbit_hzd_optimal", marks=pytest.mark.slow))
#: ... and 3D scenes
SPATIAL = ("paper_3d", "torso_bhm_3d", "hip_width_stabilised")


def _scene_and_data(name):
    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    return scene, walker_data(scene.walker, scene.slope.phi_rad)


def _close(what, got, want):
    scale = np.abs(want).max()
    assert np.abs(got - want).max() <= TOL * scale, (what, np.abs(got - want).max(), scale)


@pytest.mark.parametrize("name", PLANAR)
def test_a_planar_scenes_urdf_has_the_floating_views_dynamics(name, tmp_path):
    """Pinocchio's mass matrix, gravity torques and bias on the exported URDF equal the
    floating view's at the sidecar's keyframe and at random states (module docstring)."""
    from walkerlab.models.hybrid.floating_view import FloatingView

    scene, data = _scene_and_data(name)
    assert not data.structure.springs  # URDF has no springs; the view's bias has them
    view = FloatingView(data)
    names = tuple(view.coordinate_names())
    coupled = bool(data.structure.torso) and "torso_angle" not in names  # bisecting hip
    urdf = export_stage.run(scene, tmp_path, "urdf")
    lib = Pinocchio(urdf, names, data.gravity_m_per_s2, coupled)
    key = json.loads((urdf.parent / "walker.gait.json").read_text())
    rows = np.zeros((len(key["joints"]), len(names)))
    for i, j in enumerate(key["joints"]):   # the sidecar's joints in walkerlab's coordinates
        jm = lib.model.joints[lib.model.getJointId(j)]
        rows[i] = lib.T[jm.idx_v]
    q0 = np.linalg.lstsq(rows, np.asarray(key["qpos"]), rcond=None)[0]
    dq0 = np.linalg.lstsq(rows, np.asarray(key["qvel"]), rcond=None)[0]
    assert np.abs(rows @ q0 - key["qpos"]).max() < 1e-12   # the keyframe is one of ours
    rng = np.random.default_rng(sum(map(ord, name)))
    states = [(q0, dq0)] + [
        (np.concatenate([rng.uniform(-2, 2, 2), rng.uniform(-1, 1, len(names) - 2)]),
         rng.uniform(-3, 3, len(names))) for _ in range(3)]
    zero = np.zeros(len(names))
    for q, dq in states:
        M, b = lib(q, dq)
        _, g = lib(q, zero)
        _close("mass matrix", M, np.asarray(view.mass_matrix(q), float))
        _close("gravity", g, np.asarray(view.bias(q, zero), float))
        _close("bias", b, np.asarray(view.bias(q, dq), float))


def _pinocchio_state(model, data, x, coupled: bool):
    """Pinocchio's ``q, v`` of the 3D walker at the rigid state ``x`` (its keyframe map
    :func:`walkerlab.export.legs_3d_mjcf.legs3d_keyframe` at foot radius 0: MuJoCo's
    coordinates, whose free joint's angular velocity is in the body's axes as Pinocchio's;
    Pinocchio's linear velocity is in the body's axes too)."""
    from scipy.spatial.transform import Rotation

    from walkerlab.codegen.cache import functions
    from walkerlab.export.axes_3d import TO_MUJOCO
    from walkerlab.export.legs_3d_mjcf import legs3d_keyframe

    f = functions(data)
    qpos, qvel = legs3d_keyframe(f["points"], f["point_velocities"], x, data.slope_rad, 0.0)
    if len(qpos) == 9:   # a free pelvis: position, quaternion (w, x, y, z), the two hinges
        R = Rotation.from_quat([*qpos[4:7], qpos[3]]).as_matrix()
        hinges = dict(zip(("leg1_hip", "leg2_hip"), zip(qpos[7:], qvel[6:])))
        omega = np.asarray(qvel[3:6])
    else:                # hip-roll joints: slides, the pelvis' roll, each leg's roll, pitch
        C = np.array(TO_MUJOCO)
        fall = C @ np.array([math.cos(data.slope_rad), -math.sin(data.slope_rad), 0.0])
        R = Rotation.from_rotvec(qpos[3] * fall).as_matrix()
        hinges = dict(zip(("leg1_roll", "leg1_hip", "leg2_roll", "leg2_hip"),
                          zip(qpos[4:], qvel[4:])))
        omega = fall * qvel[3]    # about the roll axis: the same in the body's axes
    if coupled:   # the bisecting hip: the torso at the legs' mean
        (a1, r1), (a2, r2) = hinges["leg1_hip"], hinges["leg2_hip"]
        hinges["torso_pitch"] = ((a1 + a2) / 2, (r1 + r2) / 2)
    quat = Rotation.from_matrix(R).as_quat()   # x, y, z, w: Pinocchio's order
    q, v = np.zeros(model.nq), np.zeros(model.nv)
    q[:7] = np.concatenate([qpos[:3], quat])
    v[:6] = np.concatenate([R.T @ np.asarray(qvel[:3]), omega])
    assert set(model.names[2:]) == set(hinges)
    for name, (angle, rate) in hinges.items():
        jm = model.joints[model.getJointId(name)]
        q[jm.idx_q:jm.idx_q + 2] = math.cos(angle), math.sin(angle)
        v[jm.idx_v] = rate
    return q, v, f


@pytest.mark.parametrize("name", SPATIAL)
def test_a_3d_scenes_urdf_has_the_rigid_walkers_energies(name, tmp_path):
    """Pinocchio's kinetic and potential energies of the exported URDF (a free-flyer root)
    in the rigid walker's state equal the generated model's at random states (module
    docstring)."""
    from walkerlab.export.mjcf_scene import MJCF_MIN_INERTIA_KG_M2

    scene, data = _scene_and_data(name)
    path = export_stage.run(scene, tmp_path, "urdf", walker_only=True)
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    model.gravity.linear = np.array([0.0, 0.0, -data.gravity_m_per_s2])
    pdata = model.createData()
    assert sum(i.mass for i in model.inertias) == pytest.approx(data.total_mass_kg, rel=1e-15)
    n = len(data.structure.roles)
    rng = np.random.default_rng(sum(map(ord, name)))
    for _ in range(4):
        x = np.concatenate([rng.uniform(-0.3, 0.3, n), rng.uniform(-2, 2, n)])
        q, v, f = _pinocchio_state(model, data, x, bool(data.structure.torso))
        ke, pe = (float(e) for e in f["energies"](x))
        floor = MJCF_MIN_INERTIA_KG_M2 * model.njoints * float(v[3:] @ v[3:] + 1)
        assert abs(pin.computeKineticEnergy(model, pdata, q, v) - ke) <= TOL * ke + floor
        assert abs(pin.computePotentialEnergy(model, pdata, q) - pe) <= TOL * abs(pe) + 1e-12
