"""``walkerlab export``: the walker as URDF (Pinocchio) and MJCF (MuJoCo), checked against an
independent numpy floating walker, the hand-written compass-gait kernel and (once merged) the
generated floating view.

Every library's joint coordinates map to walkerlab's floating coordinates
``q = (hip_x, hip_y, link angles...)`` by a constant linear map ``q_lib = T q``: hip
joints = absolute thigh/leg angles (the base does not rotate), knee = shank - thigh.  Then
``M = T^T M_lib T`` and ``bias = T^T bias_lib`` (kinetic energy and virtual work are the same
in either set of coordinates).  Agreement ``<= 1e-10`` relative to the largest entry: the
exports carry every number with 17 significant digits, so the differences are round-off
(~1e-15), except MuJoCo's inertia floor (1e-12 kg m^2, ``MJCF_MIN_INERTIA_KG_M2``) on links
whose bodies are point masses on a line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.independent import floating_reference as ref
from walkerlab.config import load_scene
from walkerlab.export.mjcf_scene import MJCF_MIN_INERTIA_KG_M2
from walkerlab.models.hybrid.floating_view import FloatingView
from walkerlab.stages import export as export_stage
from walkerlab.walker.description import walker_data

ROOT = Path(__file__).resolve().parents[1]
#: Every shipped walker with masses (simplest.yaml and schwab_wisse2001.yaml: massless legs).
SCENES = ("paper", "paper_rods", "kneed", "round_feet", "goswami1996", "hip_spring",
          "torso_bhm", "asymmetric_legs")
#: Compass-gait scenes the hand-written contact kernel describes.
TOL = 1e-10
N_STATES = 5


def _scene(name):
    return load_scene(ROOT / "configs" / f"{name}.yaml")


def _data(scene):
    return walker_data(scene.walker, scene.slope.phi_rad)


def _states(n_q, seed):
    """Random floating states: hip anywhere, link angles within +-1 rad, rates within +-3."""
    rng = np.random.default_rng(seed)
    for _ in range(N_STATES):
        q = np.concatenate([rng.uniform(-2, 2, 2), rng.uniform(-1, 1, n_q - 2)])
        yield q, rng.uniform(-3, 3, n_q)


def _joint_map(names, torso=False):
    """``T`` as {joint name: row over our coordinates}: q_joint = row . q (the torso's joint,
    eliminated in our coordinates, is the mean of the leg angles: the bisecting hip)."""
    rows = {}
    for j, c in enumerate(names):
        row = np.zeros(len(names))
        if c in ("hip_x", "hip_y"):  # the slide joints are named by their axis: hip_x, hip_z
            row[j] = 1.0
            rows["hip_z" if c == "hip_y" else c] = row
        elif c.endswith("_shank_angle"):
            leg = c.split("_")[0]
            row[j], row[names.index(f"{leg}_thigh_angle")] = 1.0, -1.0
            rows[f"{leg}_knee"] = row
        else:  # leg<i>_angle or leg<i>_thigh_angle
            row[j] = 1.0
            rows[c.split("_")[0] + "_hip"] = row
    if torso:
        rows["torso_hip"] = (rows["leg1_hip"] + rows["leg2_hip"]) / 2
    return rows


class Pinocchio:
    """The exported URDF in Pinocchio: CRBA mass matrix and RNEA bias in our coordinates."""

    def __init__(self, path, names, g, torso=False):
        pin = pytest.importorskip("pinocchio")
        self.pin = pin
        self.model = pin.buildModelFromUrdf(str(path))
        self.model.gravity.linear = np.array([0.0, 0.0, -g])
        self.data = self.model.createData()
        rows = _joint_map(names, torso)
        assert set(rows) == set(self.model.names[1:])
        self.T = np.zeros((self.model.nv, len(names)))
        self.joints = []
        for name, row in rows.items():
            jm = self.model.joints[self.model.getJointId(name)]
            self.T[jm.idx_v] = row
            self.joints.append((jm.idx_q, jm.nq, row))

    def __call__(self, q, dq):
        ql = np.zeros(self.model.nq)
        for iq, nq, row in self.joints:
            a = row @ q
            # a continuous (unbounded revolute) joint is stored as (cos, sin)
            ql[iq:iq + nq] = (np.cos(a), np.sin(a)) if nq == 2 else (a,)
        vl = self.T @ dq
        self.last_q = ql
        Ml = self.pin.crba(self.model, self.data, ql)
        Ml = np.triu(Ml) + np.triu(Ml, 1).T  # CRBA fills the upper triangle
        bl = self.pin.rnea(self.model, self.data, ql, vl, np.zeros(self.model.nv))
        return self.T.T @ Ml @ self.T, self.T.T @ bl


class MuJoCo:
    """The exported MJCF in MuJoCo: ``mj_fullM`` (dense ``qM``) and ``qfrc_bias`` in our
    coordinates."""

    def __init__(self, path, names, torso=False):
        mujoco = pytest.importorskip("mujoco")
        self.mj = mujoco
        self.model = mujoco.MjModel.from_xml_path(str(path))
        self.data = mujoco.MjData(self.model)
        rows = _joint_map(names, torso)
        assert set(rows) == {self.model.joint(i).name for i in range(self.model.njnt)}
        self.T = np.zeros((self.model.nv, len(names)))
        self.Tq = np.zeros((self.model.nq, len(names)))
        for name, row in rows.items():
            jt = self.model.joint(name)
            self.T[jt.dofadr[0]] = row
            self.Tq[jt.qposadr[0]] = row

    def __call__(self, q, dq):
        d = self.data
        d.qpos[:] = self.Tq @ q
        d.qvel[:] = self.T @ dq
        self.mj.mj_forward(self.model, d)
        Ml = np.zeros((self.model.nv, self.model.nv))
        try:  # MuJoCo >= 4: mj_fullM(m, d, dst); before: mj_fullM(m, dst, d.qM)
            self.mj.mj_fullM(self.model, d, Ml)
        except TypeError:
            self.mj.mj_fullM(self.model, Ml, d.qM)
        return self.T.T @ Ml @ self.T, self.T.T @ d.qfrc_bias


def _libraries(scene, tmp_path):
    data = _data(scene)
    names = ref.coordinate_names(data)
    urdf = export_stage.run(scene, tmp_path, "urdf")
    mjcf = export_stage.run(scene, tmp_path, "mjcf")
    torso = bool(data.structure.torso)
    return data, names, {"pinocchio": Pinocchio(urdf, names, data.gravity_m_per_s2, torso),
                         "mujoco": MuJoCo(mjcf, names, torso)}


def agreement(scene_name, tmp_path, other=None):
    """Largest differences of each library's M and bias from the independent reference
    (``other(q, dq) -> (M, bias)`` instead, if given): {library: (abs M, rel M, abs bias,
    rel bias)}, relative to the reference's largest entry."""
    scene = _scene(scene_name)
    data, names, libs = _libraries(scene, tmp_path)
    other = other or (lambda q, dq: ref.mass_matrix_and_bias(data, q, dq))
    out = {}
    for lib, f in libs.items():
        worst = np.zeros(4)
        for q, dq in _states(len(names), seed=17):
            M, b = f(q, dq)
            Mr, br = other(q, dq)
            dM, db = np.abs(M - Mr).max(), np.abs(b - br).max()
            worst = np.maximum(worst, [dM, dM / np.abs(Mr).max(), db, db / np.abs(br).max()])
        out[lib] = tuple(worst)
    return out


@pytest.mark.parametrize("name", SCENES)
def test_libraries_match_independent_reference(name, tmp_path):
    """Pinocchio (CRBA, RNEA) and MuJoCo (qM, qfrc_bias) on the exported files give the mass
    matrix and bias of the independent numpy walker built body by body, to <= 1e-10."""
    for lib, (_, rel_m, _, rel_b) in agreement(name, tmp_path).items():
        assert rel_m <= TOL and rel_b <= TOL, (lib, rel_m, rel_b)


@pytest.mark.parametrize("name", SCENES)
def test_pinocchio_and_mujoco_agree(name, tmp_path):
    """The two libraries agree with each other at random states (MuJoCo's inertia floor is
    the only modelling difference: it bounds the mass-matrix difference)."""
    scene = _scene(name)
    data, names, libs = _libraries(scene, tmp_path)
    for q, dq in _states(len(names), seed=3):
        Mp, bp = libs["pinocchio"](q, dq)
        Mm, bm = libs["mujoco"](q, dq)
        assert np.abs(Mp - Mm).max() <= 2 * MJCF_MIN_INERTIA_KG_M2 + 1e-13 * np.abs(Mp).max()
        assert np.abs(bp - bm).max() <= 1e-12 * np.abs(bp).max()


def test_reference_is_not_trivially_equal(tmp_path):
    """The check can fail: a URDF with the leg mass moved by 1 mm disagrees with the reference
    far beyond the tolerance."""
    scene = _scene("paper")
    data, names, libs = _libraries(scene, tmp_path)
    urdf = tmp_path / "paper" / "walker.urdf"
    text = urdf.read_text()
    assert 'xyz="0.0 0.0 -0.5"' in text
    urdf.write_text(text.replace('xyz="0.0 0.0 -0.5"', 'xyz="0.0 0.0 -0.501"'))
    lib = Pinocchio(urdf, names, data.gravity_m_per_s2)
    q, dq = next(_states(len(names), seed=1))
    M, _ = lib(q, dq)
    Mr, _ = ref.mass_matrix_and_bias(data, q, dq)
    assert np.abs(M - Mr).max() > 1e-4


# ---- the generated floating view (walkerlab.codegen.floating, issue 17 part 1)
@pytest.mark.parametrize("name", SCENES)
def test_libraries_match_floating_view(name, tmp_path):
    """Pinocchio and MuJoCo equal the generated floating view: same coordinate names, mass
    matrix and bias at random states."""
    scene = _scene(name)
    view = FloatingView(_data(scene))
    assert tuple(view.coordinate_names()) == ref.coordinate_names(_data(scene))

    def generated(q, dq):  # without its springs (URDF has none; MuJoCo's are passive forces,
        # checked by test_mujoco_springs_are_ours)
        return (np.asarray(view.mass_matrix(q), float),
                np.asarray(view.bias(q, dq), float) + ref.spring_force(_data(scene), q, dq))

    for lib, (_, rel_m, _, rel_b) in agreement(name, tmp_path, generated).items():
        assert rel_m <= TOL and rel_b <= TOL, (lib, rel_m, rel_b)


# ---- the command
def test_export_writes_files_in_run_folder(tmp_path):
    """``walkerlab export`` writes runs/<scene>/walker.urdf and walker.xml (atomic: no
    temporary file left), with the joints named as documented."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    for fmt, fname in (("urdf", "walker.urdf"), ("mjcf", "walker.xml")):
        r = CliRunner().invoke(app, ["export", str(ROOT / "configs" / "kneed.yaml"),
                                     "--format", fmt, "--runs-dir", str(tmp_path)])
        assert r.exit_code == 0, r.output
        path = tmp_path / "kneed" / fname
        assert f"wrote {path}" in r.output
        text = path.read_text()
        for joint in ("hip_x", "hip_z", "leg1_hip", "leg1_knee", "leg2_hip", "leg2_knee"):
            assert f'name="{joint}"' in text
    assert not list((tmp_path / "kneed").glob(".*.tmp"))


@pytest.mark.parametrize("args, message", [
    (["configs/simplest.yaml"], "needs positive masses"),
    (["configs/paper.yaml", "--format", "stl"], "--format: unknown format 'stl'"),
])
def test_export_refuses_in_one_line(args, message, tmp_path):
    """Massless legs (the simplest walker) and an unknown format: one line, exit code 1."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    args = [str(ROOT / args[0]), *args[1:]]
    r = CliRunner().invoke(app, ["export", *args, "--runs-dir", str(tmp_path)])
    assert r.exit_code == 1
    assert r.output.strip().count("\n") == 0 and message in r.output


def test_arc_feet_and_knee_limit_in_files(tmp_path):
    """Arc feet are spheres of radius R at the arc's centre (L - R from the hip) in the MJCF
    (in the x-z plane the arc; the URDF's are cylinders); the knee's straight-leg stop is the
    upper limit 0 of a [-pi, 0] range."""
    mujoco = pytest.importorskip("mujoco")
    scene = _scene("round_feet")
    m = mujoco.MjModel.from_xml_path(str(export_stage.run(scene, tmp_path, "mjcf")))
    foot = m.geom("leg1_foot")
    assert foot.type[0] == mujoco.mjtGeom.mjGEOM_SPHERE and foot.size[0] == 0.2
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("standing").id)
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(d.site("leg1_foot").xpos, [0.0, 0.0, 0.2], atol=1e-15)
    kneed = mujoco.MjModel.from_xml_path(str(export_stage.run(_scene("kneed"), tmp_path,
                                                              "mjcf")))
    knee = kneed.joint("leg1_knee")
    assert knee.limited[0] and knee.range[1] == 0.0 and knee.range[0] == pytest.approx(-np.pi)


@pytest.mark.parametrize("name", SCENES)
def test_feet_where_the_walker_puts_them(name, tmp_path):
    """The ``leg<i>_foot`` frame (Pinocchio) and site (MuJoCo) lie at the foot point, or the
    arc's centre, ``hip + l_t e(thigh) + (L - l_t - R) e(shank)`` with
    ``e(psi) = (sin psi, -cos psi)`` in (x, up): the sign convention of the joint axes."""
    scene = _scene(name)
    data, names, libs = _libraries(scene, tmp_path)
    p = dict(zip(data.structure.param_names, data.params))
    lt = p.get("L_thigh", 0.0)
    to_centre = p["L"] - p.get("R_foot", 0.0) - lt
    pin, mj = libs["pinocchio"], libs["mujoco"]
    for q, dq in _states(len(names), seed=5):
        pin(q, dq)  # sets the configuration
        mj(q, dq)
        pin.pin.framesForwardKinematics(pin.model, pin.data, pin.last_q)
        for leg in ("leg1", "leg2"):
            thigh = q[names.index(f"{leg}_thigh_angle" if lt else f"{leg}_angle")]
            shank = q[names.index(f"{leg}_shank_angle")] if lt else thigh
            x, y = q[:2] + lt * np.array([np.sin(thigh), -np.cos(thigh)]) \
                + to_centre * np.array([np.sin(shank), -np.cos(shank)])
            fid = pin.model.getFrameId(f"{leg}_foot", pin.pin.FrameType.BODY)
            frame = pin.data.oMf[fid].translation
            np.testing.assert_allclose(frame, [x, 0.0, y], atol=1e-13)
            np.testing.assert_allclose(mj.data.site(f"{leg}_foot").xpos, [x, 0.0, y],
                                       atol=1e-13)


# ---- issue 22: springs as tendons, the bisecting hip as an equality, off-axis bodies
def _edited_scene(tmp_path, base, edit):
    d = yaml.safe_load((ROOT / "configs" / f"{base}.yaml").read_text())
    edit(d)
    d.pop("fixedpoint")  # another walker: exported walker_only (no gait keyframe)
    path = tmp_path / f"{base}_edited.yaml"
    path.write_text(yaml.safe_dump(d))
    return load_scene(path)


def _sprung_variants():
    def rest_and_damping(d):  # rest angle -1: MuJoCo reads springlength="-1" as "qpos0"
        d["walker"]["springs"][0].update(rest_angle_rad=-1.0, damping_n_m_s_per_rad=0.7)

    def torso_spring(d):  # a spring between the torso and one leg, with a rest angle
        d["walker"]["springs"] = [{"between": ["torso", "leg1"], "stiffness_n_m_per_rad": 5.0,
                                   "rest_angle_rad": 0.1, "damping_n_m_s_per_rad": 0.3}]
    def kneed_spring(d):  # a hip spring on a kneed walker acts on the thighs' hip joints;
        # a knee spring (joint stiffness, springref, damping) on each knee
        d["walker"]["springs"] = [{"between": ["leg1", "leg2"], "stiffness_n_m_per_rad": 2.0,
                                   "rest_angle_rad": 0.2, "damping_n_m_s_per_rad": 0.3}]
        d["walker"]["leg"]["knee"]["spring"] = {"stiffness_n_m_per_rad": 1.5,
                                                "rest_angle_rad": -0.3,
                                                "damping_n_m_s_per_rad": 0.2}
    return {"hip_spring": ("hip_spring", None), "rest_and_damping": ("hip_spring",
                                                                     rest_and_damping),
            "torso_spring": ("torso_bhm", torso_spring), "kneed_spring": ("kneed", kneed_spring)}


@pytest.mark.parametrize("variant", list(_sprung_variants()))
def test_mujoco_springs_are_ours(variant, tmp_path):
    """A spring exported as a MuJoCo fixed tendon (stiffness, springlength, damping) is ours:
    at random states MuJoCo's potential energy (``mjData.energy[0]`` with the energy flag:
    gravity + tendon springs) equals the independent reference's (gravity + ``k (delta -
    r)^2 / 2``), MuJoCo's passive force ``qfrc_passive`` (mapped to our coordinates) equals
    the reference's spring-damper force, and the generated floating view's full bias
    ``h`` (springs included) equals MuJoCo's ``qfrc_bias - qfrc_passive``.  Tolerance 1e-10
    relative: 17-digit numbers in the file, round-off only.  The rest angle -1 checks the
    writer's orientation of the tendon (MuJoCo reads springlength -1 as "the length at
    qpos0", which would silently give rest 0)."""
    mujoco = pytest.importorskip("mujoco")
    base, edit = _sprung_variants()[variant]
    scene = _scene(base) if edit is None else _edited_scene(tmp_path, base, edit)
    data = _data(scene)
    names = ref.coordinate_names(data)
    mj = MuJoCo(export_stage.run(scene, tmp_path, "mjcf", walker_only=edit is not None), names,
                bool(data.structure.torso))
    mj.model.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    view = FloatingView(data)
    assert data.structure.springs
    for q, dq in _states(len(names), seed=11):
        mj(q, dq)
        V = ref.potential(data, q)
        assert mj.data.energy[0] == pytest.approx(V, rel=1e-10, abs=1e-10)
        Q = ref.spring_force(data, q, dq)
        assert np.abs(Q).max() > 0.1  # the springs act at these states
        np.testing.assert_allclose(mj.T.T @ mj.data.qfrc_passive, Q, rtol=0,
                                   atol=1e-10 * np.abs(Q).max())
        h = view.bias(q, dq)
        np.testing.assert_allclose(mj.T.T @ (mj.data.qfrc_bias - mj.data.qfrc_passive), h,
                                   rtol=0, atol=1e-10 * np.abs(h).max())


def test_spring_check_can_fail(tmp_path):
    """The spring check is not vacuous: the hip spring's tendon with its coefficients'
    signs swapped on one joint (delta = leg1 + leg2) has another passive force."""
    mujoco = pytest.importorskip("mujoco")
    scene = _scene("hip_spring")
    data = _data(scene)
    names = ref.coordinate_names(data)
    path = export_stage.run(scene, tmp_path, "mjcf")
    text = path.read_text()
    assert '<joint joint="leg1_hip" coef="-1.0"/>' in text
    path.write_text(text.replace('<joint joint="leg1_hip" coef="-1.0"/>',
                                 '<joint joint="leg1_hip" coef="1.0"/>'))
    mj = MuJoCo(path, names)
    q, dq = next(_states(len(names), seed=11))
    mj(q, dq)
    assert mujoco is mj.mj
    assert np.abs(mj.T.T @ mj.data.qfrc_passive - ref.spring_force(data, q, dq)).max() > 1.0


def _off_axis(d):
    """asymmetric_legs with each leg's mass off the axis (+-3 cm) and a rod ahead of it."""
    for leg, e in zip(d["walker"]["legs"], (0.03, -0.02)):
        leg["bodies"][0]["off_axis_m"] = e
        leg["bodies"].append({"kind": "rod", "name": "rod", "mass_kg": 1.0,
                              "com_from_hip_m": 0.4, "inertia_about_com_kg_m2": 0.02,
                              "com_off_axis_m": 0.01})


def _torso_off_axis(d):
    """torso_bhm with a rigid body ahead of the torso's axis beside its point mass."""
    d["walker"]["torso"]["bodies"].append({"kind": "rigid_body", "name": "box", "mass_kg": 2.0,
                                           "com_from_hip_m": 0.3, "com_off_axis_m": 0.05,
                                           "inertia_about_com_kg_m2": 0.04})


def _kneed_legs_differ(d):
    """kneed with leg2's thigh mass 0.55 kg and its shank mass 2 cm lower."""
    leg = d["walker"].pop("leg")
    other = yaml.safe_load(yaml.safe_dump(leg))
    other["bodies"][0]["mass_kg"] = 0.55
    other["bodies"][1]["from_hip_m"] = 0.67
    d["walker"]["legs"] = [leg, other]


def _kneed_torso(d):
    """kneed with an upper body on the thighs' bisector, a rigid body off its axis."""
    d["walker"]["torso"] = {"bodies": [{"kind": "rigid_body", "name": "box", "mass_kg": 0.2,
                                        "com_from_hip_m": 0.2, "com_off_axis_m": 0.03,
                                        "inertia_about_com_kg_m2": 0.004}]}


@pytest.mark.parametrize("base, edit", [("asymmetric_legs", _off_axis),
                                        ("torso_bhm", _torso_off_axis),
                                        ("kneed", _kneed_legs_differ),
                                        ("kneed", _kneed_torso)])
def test_off_axis_bodies_exported_in_place(base, edit, tmp_path):
    """Bodies off a link's axis (legs and torso) are exported in place (the link's inertial
    origin off its axis, the parallel-axis inertia about it), and kneed legs that differ
    carry each leg's numbers: Pinocchio and MuJoCo give the independent reference's mass
    matrix and bias (body by body) to 1e-10 relative."""
    scene = _edited_scene(tmp_path, base, edit)
    data = _data(scene)
    s = data.structure
    assert any(b.off_axis for b in (*s.bodies, *s.torso)) or s.asymmetric
    names = ref.coordinate_names(data)
    torso = bool(s.torso)
    libs = {"pinocchio": Pinocchio(export_stage.run(scene, tmp_path, "urdf", walker_only=True),
                                   names, data.gravity_m_per_s2, torso),
            "mujoco": MuJoCo(export_stage.run(scene, tmp_path, "mjcf", walker_only=True), names,
                             torso)}
    for lib, f in libs.items():
        for q, dq in _states(len(names), seed=19):
            M, b = f(q, dq)
            Mr, br = ref.mass_matrix_and_bias(data, q, dq)
            assert np.abs(M - Mr).max() <= TOL * np.abs(Mr).max(), lib
            assert np.abs(b - br).max() <= TOL * np.abs(br).max(), lib


def test_bisecting_hip_holds_in_a_mujoco_run(tmp_path):
    """The bisecting hip mechanism (tendon equality ``torso_hip - (leg1_hip + leg2_hip)/2 =
    0``) holds along 1 s of MuJoCo walking from the gait keyframe (contact, heel strikes) to
    1e-6 rad: MuJoCo's constraints are soft, the export makes this one as stiff as MuJoCo
    allows (measured: 2e-8 rad over 2 s)."""
    mujoco = pytest.importorskip("mujoco")
    m = mujoco.MjModel.from_xml_path(str(export_stage.run(_scene("torso_bhm"), tmp_path,
                                                          "mjcf")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("gait").id)
    torso, leg1, leg2 = (m.joint(j).qposadr[0] for j in ("torso_hip", "leg1_hip", "leg2_hip"))
    assert d.qpos[torso] == pytest.approx((d.qpos[leg1] + d.qpos[leg2]) / 2, abs=1e-15)
    worst, contacts = 0.0, 0
    while d.time < 1.0:
        mujoco.mj_step(m, d)
        worst = max(worst, abs(d.qpos[torso] - (d.qpos[leg1] + d.qpos[leg2]) / 2))
        contacts += d.ncon > 0
    assert contacts > 0 and abs(d.qpos[leg1] - d.qpos[leg2]) > 0.1  # it moved, on the ground
    assert worst < 1e-6, worst


# -------------------- the export reads an up-to-date fixedpoint.h5
POWERED = ROOT / "configs" / "powered_compass.yaml"


# ------------------------------------------------ 8: export reads a fresh fixedpoint.h5
def test_export_reads_the_gait_of_an_up_to_date_fixedpoint_artifact(tmp_path, monkeypatch):
    """With fixedpoint.h5 up to date the export searches no gait (RABBIT: 94 s of search ->
    2 s), and writes the very file the search gives (bit for bit); a stale artifact is not
    read (the search runs)."""
    from walkerlab.analysis.gait import search
    from walkerlab.stages import export, fixedpoint

    scene = load_scene(POWERED)
    searched = export.run(scene, tmp_path / "a", "mjcf").read_text()  # no artifact: search
    fixedpoint.run(scene, tmp_path / "b")
    calls = []
    real = search.find_gaits
    monkeypatch.setattr(search, "find_gaits", lambda *a, **k: calls.append(1) or real(*a, **k))
    assert export.run(scene, tmp_path / "b", "mjcf").read_text() == searched
    assert export.run(scene, tmp_path / "b", "adm").is_file()
    assert calls == []  # read, not searched (the adm export searched twice before)
    other = scene.model_copy(update={"solver": scene.solver.model_copy(update={"rtol": 1e-11})})
    assert fixedpoint.fresh_artifact(other, tmp_path / "b") is None  # stale for this scene
    export.run(other, tmp_path / "b", "mjcf")
    assert calls  # searched again


# ------------------------------------------------------- the formats as a registry of writers
def test_a_format_is_one_writer_in_the_registry(tmp_path, monkeypatch):
    """A writer added to :data:`walkerlab.export.writers.WRITERS` alone is a format of
    ``export``: its file written where the registry says, in its capability table's column
    (a 3D spoked wheel refused in that column's words: the gym's column, one rigid body has
    no joint to drive; the OpenSim column takes the wheels now), with what the writer says
    it leaves out."""
    from walkerlab.export import writers
    from walkerlab.walker.kinds import KINDS

    def write(job, w):
        return writers.Written(((w.file, f"{job.name} {job.kind.name}"),), ("a: b",), 1.5)

    monkeypatch.setitem(writers.WRITERS, "txt", writers.Writer("txt", "walker.txt",
                                                               "gym", write))
    out = export_stage.write(load_scene(ROOT / "configs" / "paper.yaml"), tmp_path, "txt")
    assert out.path == tmp_path / "paper" / "walker.txt"
    assert out.path.read_text() == "paper straight_legs"
    assert (out.left_out, out.step_period_s) == (("a: b",), 1.5)
    with pytest.raises(ValueError) as exc:  # the gym column refuses the 3D wheel
        export_stage.write(load_scene(ROOT / "configs" / "rimless_wheel_3d.yaml"), tmp_path,
                           "txt")
    kind = KINDS["rolling_polygon_3d"]
    assert kind.cell("walk", "gym")
    assert str(exc.value) == f"{kind.field}: " + kind.cell("walk", "gym")


def test_mjcf_options_are_refused_for_either_spoked_wheel_in_one_line(tmp_path):
    """The MJCF's contact time constant and timestep are a legged walker's options: the
    3D rimless wheel refuses them as the planar one does (it used to reach the leg-link
    writer and fail there with a line about the planar wheel's writers), before any gait
    search."""
    from walkerlab.export.mjcf_scene import MjcfOptions

    for name in ("rimless_wheel", "rimless_wheel_3d"):
        with pytest.raises(ValueError, match=r"^--mjcf-contact-time-constant-s, "
                           r"--mjcf-timestep-s: options of a legged walker's MJCF"):
            export_stage.write(load_scene(ROOT / "configs" / f"{name}.yaml"), tmp_path,
                               "mjcf", mjcf=MjcfOptions(timestep_s=5e-5))
    assert not list(tmp_path.rglob("walker.*"))
