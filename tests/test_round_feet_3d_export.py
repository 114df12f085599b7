"""The 3D straight-legged walker on round feet (``configs/round_feet_3d.yaml``: a disc foot
in each leg's plane, each leg a slender rod) as MJCF and URDF
(:mod:`walkerlab.export.legs_3d_mjcf`, :func:`walkerlab.export.urdf.legs_urdf_text`), against
numbers that share no code with the export's body tree:

- the bodies' masses, centres of mass and inertias written by hand from the scene's YAML;
- the discs (radius, centre, axis) in MuJoCo's and Pinocchio's kinematics at the rigid gait's
  start against the rigid model's named points ``stance_foot_centre``, ``swing_foot_centre``
  (its generated code, :func:`walkerlab.codegen.cache.functions`);
- MuJoCo's joint-space mass matrix (``mj_fullM``) carried to the rigid coordinates ``lean,
  swing, stance`` by the rolling walker's partial velocities written from Newton-Euler's
  kinematics (``tests/test_round_feet_3d.py``'s :class:`Reference`) against the rigid
  model's mass matrix.

Tolerances: the files carry every number with 17 significant digits, so positions agree to
round-off (1e-9 is the task's bound, met by ~1e-15); the mass matrix differs by the export's
inertia floor (:data:`walkerlab.export.mjcf_scene.MJCF_MIN_INERTIA_KG_M2`, 1e-12 about the
point-mass pelvis' axes and each rod's own axis): at most a few 1e-12, bounded by 1e-10.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.test_round_feet_3d import Reference
from walkerlab.cli.options import load
from walkerlab.stages import export
from walkerlab.walker.plant import Plant

mujoco = pytest.importorskip("mujoco")

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "configs" / "round_feet_3d.yaml"
#: the export's inertia floor [kg m^2] (a point mass's, a rod's about its own axis)
FLOOR = 1e-12


def _walker() -> dict:
    """The scene's walker numbers, read from its YAML."""
    return yaml.safe_load(SCENE.read_text())["walker"]


def _rotation(axis, angle):
    from scipy.spatial.transform import Rotation

    return Rotation.from_rotvec(angle * np.asarray(axis, float)).as_matrix()


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """The scene exported with its gait as MJCF and URDF, its rigid gait's start ``x`` and
    the rigid model's generated functions."""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.codegen.cache import functions
    from walkerlab.walker.description import walker_data

    scene = load(str(SCENE))
    runs = tmp_path_factory.mktemp("round_feet_3d")
    mjcf = export.write(scene, runs, "mjcf")
    urdf = export.write(scene, runs, "urdf")
    x = np.asarray(ideal_gait(scene, plant=Plant.from_scene(scene)).x, float)
    f = functions(walker_data(scene.walker, scene.slope.phi_rad))
    return scene, mjcf, urdf, x, f


def test_the_round_feet_mjcf_carries_the_scenes_masses_centres_of_mass_and_rod_inertias(
        exported):
    """MuJoCo loads the MJCF: a free pelvis carrying the hip mass (1) at the hips, each leg
    its mass (0.5) ``L - a = 1.2 - 0.7 = 0.5`` below its hip with the rod's inertia 0.02
    about both axes normal to the leg (the floor about the leg's own), total 2; each foot
    a cylinder of radius ``R = 0.2`` (half-height 0.01 L) centred ``L - R = 1.0`` down its
    leg, its axis the hip axis.  Exact: the file's numbers read back."""
    _, mjcf, *_ = exported
    w = _walker()
    L, R, a = w["leg_length_m"], w["foot_radius_m"], w["leg_mass_from_foot_m"]
    model = mujoco.MjModel.from_xml_path(str(mjcf.path))
    assert (model.nq, model.nv) == (9, 8)
    assert model.body("pelvis").mass[0] == w["hip_mass_kg"]
    assert np.array_equal(model.body("pelvis").ipos, [0.0, 0.0, 0.0])
    assert np.all(model.body("pelvis").inertia == FLOOR)
    assert float(model.body_mass.sum()) == w["hip_mass_kg"] + 2 * w["leg_mass_kg"]
    I_leg = w["leg_inertia_kg_m2"]
    for leg in ("leg1", "leg2"):
        b = model.body(leg)
        assert b.mass[0] == w["leg_mass_kg"]
        assert np.array_equal(b.ipos, [0.0, 0.0, -(L - a)])
        # the inertia in the body's frame (MuJoCo's principal axes turned back)
        Q = np.zeros(9)
        mujoco.mju_quat2Mat(Q, b.iquat)
        Q = Q.reshape(3, 3)
        J = Q @ np.diag(b.inertia) @ Q.T
        assert np.max(np.abs(J - np.diag([I_leg, I_leg, FLOOR]))) < 1e-15
        g = model.geom(f"{leg}_foot")
        assert g.type[0] == mujoco.mjtGeom.mjGEOM_CYLINDER
        assert np.array_equal(g.size, [R, 0.01 * L, 0.0])
        assert np.array_equal(g.pos, [0.0, 0.0, -(L - R)])
        Qg = np.zeros(9)
        mujoco.mju_quat2Mat(Qg, g.quat)
        assert np.max(np.abs(np.abs(Qg.reshape(3, 3)[:, 2]) - [0.0, 1.0, 0.0])) < 1e-15
        assert model.joint(f"{leg}_hip").axis.tolist() == [0.0, -1.0, 0.0]
    assert model.numeric("foot_height_offset_m").data[0] == R


def test_the_round_feet_mjcf_keyframe_puts_the_discs_where_the_rigid_model_has_them(exported):
    """At the ``gait`` keyframe (``mj_forward``) each disc's centre (``geom_xpos``) is the
    rigid model's ``stance_foot_centre`` (leg2) / ``swing_foot_centre`` (leg1) to 1e-9,
    its axis the rigid legs' pitch axis ``Rot(s, lean) z``, the stance disc touches the
    slope (its lowest point ``R`` below its centre along the rolled normal on the plane
    through the origin) and its material contact point is at rest (rolling)."""
    from walkerlab.export.axes_3d import TO_MUJOCO

    scene, mjcf, _, x, f = exported
    R, phi = _walker()["foot_radius_m"], scene.slope.phi_rad
    model = mujoco.MjModel.from_xml_path(str(mjcf.path))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("gait").id)
    mujoco.mj_forward(model, data)
    C = np.array(TO_MUJOCO)
    pts = {k: C @ np.ravel(v) for k, v in f["points"](x).items()}
    s = np.array([math.cos(phi), -math.sin(phi), 0.0])          # walkerlab's fall line
    n = np.array([math.sin(phi), math.cos(phi), 0.0])           # ... and slope normal
    axis = C @ _rotation(s, x[0]) @ [0.0, 0.0, 1.0]
    n_rolled = C @ _rotation(s, x[0]) @ n
    for leg, point in (("leg2", "stance_foot_centre"), ("leg1", "swing_foot_centre")):
        g = model.geom(f"{leg}_foot").id
        assert model.geom_size[g][0] == R
        assert np.max(np.abs(data.geom_xpos[g] - pts[point])) < 1e-9
        z = data.geom_xmat[g].reshape(3, 3)[:, 2]
        assert abs(abs(z @ axis) - 1.0) < 1e-12
    g = model.geom("leg2_foot").id
    lowest = data.geom_xpos[g] - R * n_rolled
    assert abs(lowest @ (C @ n)) < 1e-12
    # the stance disc's material contact point: v_centre + omega x (-R n_rolled) = 0
    v = np.zeros(6)
    mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_GEOM, g, v, 0)
    assert np.linalg.norm(v[3:] + np.cross(v[:3], -R * n_rolled)) < 1e-12


def test_mujocos_mass_matrix_is_the_rigid_round_feet_walkers_on_its_coordinates(exported):
    """At a non-trivial configuration (lean 0.1, swing -0.3, stance 0.25 rad) MuJoCo's
    joint-space mass matrix ``M`` (8 x 8: free pelvis, two hinges), carried to the rigid
    coordinates by the rolling walker's partial velocities ``J`` (8 x 3: the pelvis'
    velocity from Newton-Euler's rolling kinematics, its angular velocity ``lean' s`` in
    its own frame, the hinges the legs' pitches), ``J^T M J``, is the rigid model's mass
    matrix to 1e-10 of its largest entry (the inertia floor: module docstring)."""
    from walkerlab.export.axes_3d import TO_MUJOCO

    scene, mjcf, _, _, f = exported
    w = _walker()
    ref = Reference(w["gravity_m_per_s2"], w["leg_length_m"], scene.slope.phi_rad,
                    w["hip_mass_kg"], w["leg_mass_kg"], w["leg_mass_from_foot_m"],
                    w["leg_inertia_kg_m2"], w["foot_radius_m"])
    q = np.array([0.1, -0.3, 0.25])
    C = np.array(TO_MUJOCO)
    Rp = C @ _rotation(ref.s, q[0]) @ C.T                     # the pelvis' orientation
    model = mujoco.MjModel.from_xml_path(str(mjcf.path))
    data = mujoco.MjData(model)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, Rp.ravel())
    data.qpos[:] = [0.3, 0.0, 1.1, *quat, q[1], q[2]]
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    try:  # MuJoCo >= 4: mj_fullM(m, d, dst); before: mj_fullM(m, dst, d.qM)
        mujoco.mj_fullM(model, data, M)
    except TypeError:
        mujoco.mj_fullM(model, M, data.qM)
    J = np.zeros((8, 3))
    for j in range(3):
        e = np.eye(3)[j]
        _, vel, _, _ = ref.kinematics(0.0, q, e, np.zeros(3))
        J[:3, j] = C @ vel["pelvis"]
        J[3:6, j] = Rp.T @ (C @ (e[0] * ref.s))
        J[6:, j] = e[1:]
    M_rigid = np.asarray(f["matrices"](np.concatenate([q, np.zeros(3)]))[0], float)
    assert np.max(np.abs(J.T @ M @ J - M_rigid)) < 1e-10 * np.abs(M_rigid).max()


def test_the_round_feet_urdf_loads_in_pinocchio_with_the_discs_as_cylinder_collisions(
        exported):
    """Pinocchio loads the URDF on a free-flyer root: the scene's masses (1, 0.5, 0.5), each
    leg's centre of mass ``L - a`` below its hip and its rod inertia; each leg's collision
    a cylinder of radius R, its axis the hip axis; put in the rigid gait's start (the pelvis
    at the rigid hip rolled by the lean, the hinges at the leg angles) the cylinders'
    centres are the rigid model's disc centres to 1e-9."""
    pin = pytest.importorskip("pinocchio")
    from walkerlab.export.axes_3d import TO_MUJOCO

    scene, _, urdf, x, f = exported
    w = _walker()
    L, R, a = w["leg_length_m"], w["foot_radius_m"], w["leg_mass_from_foot_m"]
    pm = pin.buildModelFromUrdf(str(urdf.path), pin.JointModelFreeFlyer())
    geom = pin.buildGeomFromUrdf(pm, str(urdf.path), pin.GeometryType.COLLISION)
    assert [float(i.mass) for i in pm.inertias] == [0.0, w["hip_mass_kg"], w["leg_mass_kg"],
                                                    w["leg_mass_kg"]]
    I_leg = w["leg_inertia_kg_m2"]
    for leg in ("leg1", "leg2"):
        inertia = pm.inertias[pm.getJointId(f"{leg}_hip")]
        assert np.array_equal(inertia.lever, [0.0, 0.0, -(L - a)])
        assert np.max(np.abs(inertia.inertia - np.diag([I_leg, I_leg, FLOOR]))) < 1e-15
    discs = {pm.names[o.parentJoint]: o for o in geom.geometryObjects}
    assert sorted(discs) == ["leg1_hip", "leg2_hip"]
    for o in discs.values():
        assert type(o.geometry).__name__ == "Cylinder" and o.geometry.radius == R
        assert abs(abs(o.placement.rotation[:, 2] @ [0.0, 1.0, 0.0]) - 1.0) < 1e-15
    C = np.array(TO_MUJOCO)
    phi = scene.slope.phi_rad
    s = np.array([math.cos(phi), -math.sin(phi), 0.0])
    pts = {k: C @ np.ravel(v) for k, v in f["points"](x).items()}
    pose = pin.SE3(C @ _rotation(s, x[0]) @ C.T, pts["hip"])
    qv = np.zeros(pm.nq)
    qv[:7] = pin.SE3ToXYZQUAT(pose)
    for name, angle in (("leg1_hip", x[1]), ("leg2_hip", x[2])):
        j = pm.joints[pm.getJointId(name)]
        qv[j.idx_q:j.idx_q + 2] = math.cos(angle), math.sin(angle)   # continuous joint
    pd, gd = pm.createData(), geom.createData()
    pin.forwardKinematics(pm, pd, qv)
    pin.updateGeometryPlacements(pm, pd, geom, gd)
    for name, point in (("leg2_hip", "stance_foot_centre"), ("leg1_hip", "swing_foot_centre")):
        k = geom.getGeometryId(discs[name].name)
        assert np.max(np.abs(gd.oMg[k].translation - pts[point])) < 1e-9


@pytest.mark.parametrize("fmt, file", [("mjcf", "walker.xml"), ("urdf", "walker.urdf")])
def test_walkerlab_export_writes_the_round_feet_3d_walker_without_a_traceback(tmp_path, fmt,
                                                                              file):
    """``walkerlab export configs/round_feet_3d.yaml --format mjcf|urdf`` exits 0 and
    writes its file, each foot a cylinder in it."""
    from tests.cli_run import run_cli

    code, err, _ = run_cli("export", SCENE, "--format", fmt, "--runs-dir", tmp_path)
    assert code == 0, err
    assert "Traceback" not in err
    text = (tmp_path / "round_feet_3d" / file).read_text()
    assert text.count('type="cylinder"' if fmt == "mjcf" else "<cylinder radius=\"0.2\"") == 2
