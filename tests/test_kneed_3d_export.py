"""configs/kneed_3d.yaml (the kind ``locking_knees_3d``) exported as MJCF and URDF by the 3D
legs' writers (:func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf`,
:func:`walkerlab.export.urdf.legs_urdf_text`):

- the MJCF in MuJoCo: each body's mass, centre of mass and inertia the scene's numbers,
  computed here from the scene's YAML (hip mass on the pelvis, each thigh's and shank's point
  mass ``from_hip_m`` down its leg, the knee ``thigh_length_m`` below the hip, the hips
  ``hip_width_m`` apart; a point mass's inertia the export's floor, 1e-12 kg m^2, but the
  pelvis': the hip mass as a rod between the hips, ``M_hip w^2 / 12`` about the roll and
  yaw axes); each knee a hinge about the pitch axis with the straight-leg stop ``[-pi, 0]``
  as its range; with the gait, the planar kneed MJCF's latch equalities and thresholds;
- MuJoCo's joint-space mass matrix (``mj_fullM``) pulled back to the rigid model's
  coordinates (``lean, swing_thigh, swing_shank, stance``; the stance foot pinned) is the
  rigid model's ``M`` with the pelvis rod's roll inertia on the lean;
- walked in MuJoCo, the latch holds the stance knee through the first step and the first
  stride's mean step period is the rigid gait's within 3 %;
- the URDF in Pinocchio: its total mass and its knees' limits;
- ``walkerlab export`` of the scene as mjcf and urdf writes the files without a traceback.

The pull-back: a rigid state ``x`` put in MuJoCo's coordinates by
:func:`walkerlab.export.legs_3d_mjcf.legs3d_keyframe` with a foot of radius 0 (the pelvis
where the rigid hip is), ``qvel = J dq`` linear in the rigid rates, so that the kinetic
energy ``dq^T M dq / 2 = qvel^T M_mj qvel / 2`` for every ``dq`` gives ``M = J^T M_mj J``.
Tolerance 1e-10 of the largest entry: the file carries 17 significant digits and the point
masses the inertia floor (at most ~1e-12 kg m^2 on an entry of ~1 kg m^2).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.cli_run import run_cli
from walkerlab.cli.options import load
from walkerlab.stages import export

mujoco = pytest.importorskip("mujoco")

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "configs" / "kneed_3d.yaml"
FLOOR = 1e-12   # MJCF_MIN_INERTIA_KG_M2: a point mass's inertia in the exports


def _by_hand() -> dict:
    """The scene's bodies from its YAML alone: MuJoCo body -> (mass [kg], position in its
    parent [m], centre of mass in its frame [m]) in MuJoCo's axes (z up, leg1 on -y),
    every frame the world's at the reference pose (legs vertical)."""
    w = yaml.safe_load(SCENE.read_text())["walker"]
    thigh = w["leg"]["knee"]["thigh_length_m"]
    parts = {b["link"]: b for b in w["leg"]["bodies"]}
    half = w["hip_width_m"] / 2
    out = {"pelvis": (w["hip_mass_kg"], (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))}
    for leg, side in (("leg1", -1.0), ("leg2", 1.0)):
        out[leg] = (parts["thigh"]["mass_kg"], (0.0, side * half, 0.0),
                    (0.0, 0.0, -parts["thigh"]["from_hip_m"]))
        out[f"{leg}_shank"] = (parts["shank"]["mass_kg"], (0.0, 0.0, -thigh),
                               (0.0, 0.0, -(parts["shank"]["from_hip_m"] - thigh)))
    return out


@pytest.fixture(scope="module")
def kneed_3d(tmp_path_factory):
    """The scene and its MJCF exported with the rigid gait (the gait's search: seconds)."""
    scene = load(str(SCENE))
    out = export.write(scene, tmp_path_factory.mktemp("kneed_3d"), "mjcf")
    return scene, out


def _pelvis_rod() -> float:
    """The pelvis rod's inertia about the roll and yaw axes from the YAML: the hip mass over
    the hip width, ``M w^2 / 12`` [kg m^2]."""
    w = yaml.safe_load(SCENE.read_text())["walker"]
    return w["hip_mass_kg"] * w["hip_width_m"] ** 2 / 12


def test_the_kneed_3d_mjcf_has_the_scenes_masses_centres_of_mass_and_inertias(kneed_3d):
    """Each MuJoCo body's mass, position, centre of mass and inertia are the scene's (the
    hand computation of :func:`_by_hand`; 1e-15 m: the file's shank centre 0.15 m is
    0.65 - 0.5 in floating point), the pelvis' inertia the rod's (:func:`_pelvis_rod`,
    4.2e-4 kg m^2 about x and z, the floor about the hip axis), the total 1.6 kg; a free
    pelvis (7 + 4 hinges of coordinates, 6 + 4 of velocities)."""
    _scene, out = kneed_3d
    model = mujoco.MjModel.from_xml_path(str(out.path))
    assert (model.nq, model.nv) == (11, 10)
    assert model.jnt_type[model.joint("free").id] == mujoco.mjtJoint.mjJNT_FREE
    want = _by_hand()
    names = {model.body(i).name for i in range(1, model.nbody)}
    assert names == set(want)
    for name, (mass, pos, com) in want.items():
        b = model.body(name)
        assert float(model.body_mass[b.id]) == mass, name
        assert np.max(np.abs(b.pos - pos)) < 1e-15, name
        assert np.max(np.abs(b.ipos - com)) < 1e-15, name
        want_i = ([_pelvis_rod(), FLOOR, _pelvis_rod()] if name == "pelvis"
                  else [FLOOR] * 3)
        assert np.allclose(b.inertia, want_i, rtol=1e-15, atol=0), name
        assert np.max(np.abs(b.iquat - [1, 0, 0, 0])) == 0.0, name
    assert float(model.body_mass.sum()) == pytest.approx(1.6, abs=1e-15)


def test_the_kneed_3d_mjcfs_knees_are_hinges_with_the_straight_leg_stop_and_the_latch(
        kneed_3d):
    """Each knee ``leg<i>_knee`` a limited hinge about the leg's pitch axis (``0 -1 0``, the
    hip's) in ``[-pi, 0]``, in the shank body; the planar kneed MJCF's latch: equalities
    ``leg<i>_latch`` on the knees, leg2's (in stance at the keyframe) active, the custom
    thresholds (the contact model's knee stop: 2 mm, 0.01 rad); the keyframe's knees
    straight (the rigid gait after its heel strike), its switching listed as left out."""
    _scene, out = kneed_3d
    model = mujoco.MjModel.from_xml_path(str(out.path))
    for leg in ("leg1", "leg2"):
        j = model.joint(f"{leg}_knee")
        assert model.jnt_type[j.id] == mujoco.mjtJoint.mjJNT_HINGE
        assert np.array_equal(j.axis, [0.0, -1.0, 0.0])
        assert bool(model.jnt_limited[j.id])
        assert tuple(j.range) == (-math.pi, 0.0)
        assert model.body(int(j.bodyid[0])).name == f"{leg}_shank"
        e = model.equality(f"{leg}_latch")
        assert model.eq_type[e.id] == mujoco.mjtEq.mjEQ_JOINT
        assert int(model.eq_obj1id[e.id]) == j.id
        assert bool(model.eq_active0[e.id]) == (leg == "leg2")

    def numeric(name):
        i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name)
        return float(model.numeric_data[model.numeric_adr[i]])
    assert numeric("latch_release_height_m") == 0.002
    assert numeric("latch_capture_rad") == 0.01
    key = model.key("gait")
    for leg in ("leg1", "leg2"):
        assert key.qpos[model.jnt_qposadr[model.joint(f"{leg}_knee").id]] == 0.0
    assert any(line.startswith("the knee latch's switching") for line in out.left_out)


def _full_m(model, data) -> np.ndarray:
    M = np.zeros((model.nv, model.nv))
    try:  # MuJoCo >= 4: mj_fullM(m, d, dst); before: mj_fullM(m, dst, d.qM)
        mujoco.mj_fullM(model, data, M)
    except TypeError:
        mujoco.mj_fullM(model, M, data.qM)
    return M


def test_mujocos_mass_matrix_is_the_rigid_kneed_walkers_in_its_coordinates(kneed_3d):
    """At a configuration with lean, a bent swing knee and legs apart (every entry of the
    4 x 4 ``M`` non-zero), ``J^T M_mj J`` (module docstring) equals the rigid model's
    ``M`` with the pelvis rod's inertia about the fall line on the lean's entry (the pelvis
    rolls with the lean, about its x and z axes alike: ``I (cos^2 + sin^2)``) to 1e-10 of
    its largest entry; the check sees a mistaken map (the swing knee's column read as its
    relative rate) far beyond it."""
    from walkerlab.codegen.cache import functions
    from walkerlab.export.legs_3d_mjcf import legs3d_keyframe
    from walkerlab.walker.description import walker_data

    scene, out = kneed_3d
    d = walker_data(scene.walker, scene.slope.phi_rad)
    f = functions(d)
    model = mujoco.MjModel.from_xml_path(str(out.path))
    data = mujoco.MjData(model)
    q = np.array([0.07, -0.31, -0.74, 0.22])     # lean, swing thigh and shank, stance
    M_rigid = np.asarray(f["matrices"](np.r_[q, np.zeros(4)])[0], float)
    assert np.all(np.abs(M_rigid) > 1e-4)

    def state(dq):
        return legs3d_keyframe(f["points"], f["point_velocities"], np.r_[q, dq],
                               d.slope_rad, 0.0)
    qpos, _ = state(np.zeros(4))
    J = np.column_stack([state(e)[1] for e in np.eye(4)])
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    M_mj = _full_m(model, data)
    M = J.T @ M_mj @ J
    M_rigid = M_rigid + np.diag([_pelvis_rod(), 0.0, 0.0, 0.0])   # the rod rolls with lean
    scale = np.abs(M_rigid).max()
    assert np.abs(M - M_rigid).max() <= 1e-10 * scale, np.abs(M - M_rigid).max()
    wrong = J.copy()
    wrong[:, 2] = J[:, 2] - J[:, 1]   # a relative knee rate where the absolute one belongs
    assert np.abs(wrong.T @ M_mj @ wrong - M_rigid).max() > 1e-3 * scale


def test_mujoco_walks_the_kneed_3d_mjcfs_first_stride_with_the_stance_knee_latched(
        kneed_3d):
    """From the keyframe (the rigid gait's heel strike, t = 0) MuJoCo's stepping loop
    (:func:`walkerlab.export.mujoco_walk.walk`, the latch switched by its rule) holds the
    stance knee (leg2's) within the latch's capture angle (0.01 rad) until the first heel
    strike (measured 1e-5 rad; before the pelvis rod the latch slipped and the walker fell
    at 0.448 s), and the first stride's two step periods average the rigid gait's within
    3 % (measured +0.30 %); the lateral mode (x6 a step) leaves the gait after it, so only
    the first stride is held (walkerlab.walker.reference_cases.FIRST_STEPS)."""
    from walkerlab.export.mujoco_walk import walk

    _scene, out = kneed_3d
    period = float(out.step_period_s)
    knee = []

    def each(model, data):
        knee.append((data.time, float(data.qpos[model.jnt_qposadr[
            model.joint("leg2_knee").id]])))

    run = walk(out.path, 2.3 * period, each=each)
    assert run.legs[:2] == ["leg1", "leg2"]
    t, k = np.array(knee).T
    assert np.max(np.abs(k[t < run.times_s[0]])) < 0.01
    assert abs(run.times_s[1] / 2 / period - 1.0) < 0.03


def test_the_kneed_3d_urdf_in_pinocchio_has_the_scenes_mass_and_knee_stops(tmp_path):
    """The URDF (walker only) in Pinocchio on a free-flyer root: 1.6 kg in all (the
    scene's hip, thigh and shank masses summed by hand), the knees ``leg<i>_knee``
    revolute joints limited to ``[-pi, 0]`` (the straight-leg stop), the hips continuous."""
    pin = pytest.importorskip("pinocchio")
    urdf = export.write(load(str(SCENE)), tmp_path, "urdf", walker_only=True).path
    pm = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    names = [pm.names[i] for i in range(1, pm.njoints)]
    assert names == ["root_joint", "leg1_hip", "leg1_knee", "leg2_hip", "leg2_knee"]
    total = sum(m for m, _, _ in _by_hand().values())
    assert abs(sum(float(i.mass) for i in pm.inertias) - total) < 1e-12
    assert total == pytest.approx(1.6, abs=1e-15)
    for leg in ("leg1", "leg2"):
        knee = pm.joints[pm.getJointId(f"{leg}_knee")]
        assert knee.nq == 1   # revolute (a continuous joint has 2: cos, sin)
        assert pm.lowerPositionLimit[knee.idx_q] == -math.pi
        assert pm.upperPositionLimit[knee.idx_q] == 0.0
        assert pm.joints[pm.getJointId(f"{leg}_hip")].nq == 2


@pytest.mark.parametrize(("fmt", "file"), [("mjcf", "walker.xml"), ("urdf", "walker.urdf")])
def test_walkerlab_export_writes_the_kneed_3d_walker(fmt, file, tmp_path):
    """``walkerlab export configs/kneed_3d.yaml --format mjcf|urdf`` exits 0 without a
    traceback and writes its file, naming the knee latch as left out."""
    code, err, outp = run_cli("export", SCENE, "--format", fmt, "--runs-dir", tmp_path)
    assert code == 0, err
    assert "Traceback" not in err + outp
    path = tmp_path / "kneed_3d" / file
    assert path.is_file() and "leg1_knee" in path.read_text()
    assert "knee latch" in err + outp
