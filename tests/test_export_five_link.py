"""``walkerlab export`` of a five-link biped (free knees, hinged torso): URDF in Pinocchio and
MJCF in MuJoCo against walkerlab's floating view and the independent derivation
(tests/independent/five_link.py) at random states; the motors on the actuated joints; and
RABBIT (configs/rabbit.yaml) walking in MuJoCo from its gait keyframe under its own
controller (slow)."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.independent import five_link as ref
from tests.test_five_link import SCENE, P
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.models.hybrid.floating_view import FloatingView
from walkerlab.stages import export as export_stage
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

#: every test here shares the independent sympy model (tests/independent/five_link.py, ~8 s
#: of CPU to build): one worker builds it once
pytestmark = pytest.mark.xdist_group("five_link_reference")

ROOT = Path(__file__).resolve().parents[1]
#: joint of the export -> its row over walkerlab's floating coordinates (hip_x, hip_y,
#: leg1_thigh, leg1_shank, leg2_thigh, leg2_shank, torso): q_joint = row . q
JOINT_ROWS = {"hip_x": [1, 0, 0, 0, 0, 0, 0], "hip_z": [0, 1, 0, 0, 0, 0, 0],
              "leg1_hip": [0, 0, 1, 0, 0, 0, 0], "leg1_knee": [0, 0, -1, 1, 0, 0, 0],
              "leg2_hip": [0, 0, 0, 0, 1, 0, 0], "leg2_knee": [0, 0, 0, 0, -1, 1, 0],
              "torso_hip": [0, 0, 0, 0, 0, 0, 1]}
TOL = 1e-10


def _states(seed, n=5):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        q = np.concatenate([rng.uniform(-2, 2, 2), rng.uniform(-1, 1, 5)])
        yield q, rng.uniform(-3, 3, 7)


def _actuated_scene():
    cfg = copy.deepcopy(SCENE)
    cfg["name"] = "five_link"
    cfg["walker"]["actuation"] = yaml.safe_load((ROOT / "configs" / "rabbit.yaml").read_text(
        ))["walker"]["actuation"]
    return scene_from_dict(cfg)


def _known_gait(x, period_s):
    """A stand-in for the rigid gait search (:func:`walkerlab.analysis.contact.periodic.
    ideal_gait`), returning the post-impact state ``x`` (role order) and its period."""
    from types import SimpleNamespace

    return lambda scene, plant=None: SimpleNamespace(x=np.asarray(x, float), period_s=period_s)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """The actuated test biped (hip mass, slope 0.05, RABBIT's laws) exported; its keyframe
    from a stand-in gait (any state: the files' dynamics do not depend on it)."""
    tmp = tmp_path_factory.mktemp("export")
    scene = _actuated_scene().model_copy(update={"fixedpoint": load_scene(
        ROOT / "configs" / "rabbit.yaml").fixedpoint})
    x = scene.fixedpoint.initial_guess.as_array(tuple(
        f"{r}_{k}" for k in ("angle", "rate") for r in ("stance_shank", "stance_thigh",
                                                          "swing_thigh", "swing_shank", "torso")))
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr("walkerlab.analysis.contact.periodic.ideal_gait", _known_gait(x, 0.4))
        return (scene, export_stage.run(scene, tmp, "urdf"), export_stage.run(scene, tmp, "mjcf"))


def _pinocchio(path, g):
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(path))
    model.gravity.linear = np.array([0.0, 0.0, -g])
    data = model.createData()
    assert set(model.names[1:]) == set(JOINT_ROWS)
    T = np.zeros((model.nv, 7))
    joints = []
    for name, row in JOINT_ROWS.items():
        jm = model.joints[model.getJointId(name)]
        T[jm.idx_v] = row
        joints.append((jm.idx_q, jm.nq, np.asarray(row, float)))

    def f(q, dq):
        ql = np.zeros(model.nq)
        for iq, nq, row in joints:
            a = row @ q
            ql[iq:iq + nq] = (np.cos(a), np.sin(a)) if nq == 2 else (a,)
        M = pin.crba(model, data, ql)
        M = np.triu(M) + np.triu(M, 1).T
        b = pin.rnea(model, data, ql, T @ dq, np.zeros(model.nv))
        return T.T @ M @ T, T.T @ b

    return f


def _mujoco(path):
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    assert {model.joint(i).name for i in range(model.njnt)} == set(JOINT_ROWS)
    T, Tq = np.zeros((model.nv, 7)), np.zeros((model.nq, 7))
    for name, row in JOINT_ROWS.items():
        jt = model.joint(name)
        T[jt.dofadr[0]], Tq[jt.qposadr[0]] = row, row

    def f(q, dq):
        data.qpos[:], data.qvel[:] = Tq @ q, T @ dq
        mujoco.mj_forward(model, data)
        M = np.zeros((model.nv, model.nv))
        try:
            mujoco.mj_fullM(model, data, M)
        except TypeError:
            mujoco.mj_fullM(model, M, data.qM)
        return T.T @ M @ T, T.T @ data.qfrc_bias

    return f, model


def test_urdf_and_mjcf_dynamics_are_the_floating_views(exported):
    """Pinocchio (CRBA, RNEA) on the URDF and MuJoCo (qM, qfrc_bias) on the MJCF give
    walkerlab's floating mass matrix and bias (the contact model's mechanics) at random
    states, to 1e-10 of the largest entry (MuJoCo: plus its 1e-12 kg m^2 inertia floor)."""
    scene, urdf, mjcf = exported
    view = FloatingView(walker_data(scene.walker, scene.slope.phi_rad))
    assert view.coordinate_names()[-1] == "torso_angle"
    libs = {"pinocchio": _pinocchio(urdf, 9.81), "mujoco": _mujoco(mjcf)[0]}
    for lib, f in libs.items():
        for q, dq in _states(17):
            M, b = f(q, dq)
            Mr, br = view.mass_matrix(q), view.bias(q, dq)
            assert np.abs(M - Mr).max() <= TOL * np.abs(Mr).max() + 4e-12, lib
            assert np.abs(b - br).max() <= TOL * np.abs(br).max(), lib


def test_urdf_mass_matrix_is_the_independent_one(exported):
    """The URDF in Pinocchio against the independent derivation (no walkerlab code): its
    mass matrix, carried to the independent extended coordinates ``(th, h1, h2, k1, k2,
    x_f, y_f)`` (leg2 the stance leg), is the independent ``De``."""
    scene, urdf, _ = exported
    f = _pinocchio(urdf, 9.81)
    lt, ls = P["lt"], P["ls"]
    A = np.array([[1, 0, 1, 0, 0], [1, 0, 1, 0, 1], [1, 1, 0, 0, 0], [1, 1, 0, 1, 0],
                  [1, 0, 0, 0, 0]], float)  # (leg1_thigh, leg1_shank, leg2_..., torso)
    rng = np.random.default_rng(4)
    for _ in range(5):
        r = np.array([0.1, 0.3, -0.2, -0.3, -0.5]) + rng.normal(0, 0.3, 5)
        a = A @ r
        hip = -ls * np.array([np.sin(a[3]), -np.cos(a[3])]) - lt * np.array(
            [np.sin(a[2]), -np.cos(a[2])])
        dhip = np.zeros((2, 5))
        dhip[:, 3] = -ls * np.array([np.cos(a[3]), np.sin(a[3])])
        dhip[:, 2] = -lt * np.array([np.cos(a[2]), np.sin(a[2])])
        Jf = np.zeros((7, 7))
        Jf[:2, :5], Jf[:2, 5:], Jf[2:, :5] = dhip @ A, np.eye(2), A
        M, _ = f(np.concatenate([hip, a]), np.zeros(7))
        De = np.asarray(ref._model()[2](list(r), [0.0] * 5, [P[k] for k in ref.PARAMS]),
                        float)
        np.testing.assert_allclose(Jf.T @ M @ Jf, De, rtol=0, atol=TOL * np.abs(De).max())


def test_motors_on_the_actuated_joints(exported):
    """Four motors on the physical joints (both legs' hips against the torso, both knees),
    their control range the laws' saturation (150 N m), no knee limits (free knees), no
    coupling of the torso; a motor's control acts on the joint as the law's torque (MuJoCo's
    actuator force mapped to walkerlab's coordinates is +u on the thigh, -u on the torso; +u
    on the shank, -u on the thigh), clamped at the saturation."""
    mujoco = pytest.importorskip("mujoco")
    scene, urdf, mjcf = exported
    text = Path(mjcf).read_text()
    for leg in ("leg1", "leg2"):
        lim = 'ctrllimited="true" ctrlrange="-150.0 150.0"'
        assert (f'<motor name="{leg}_hip_motor" tendon="{leg}_hip_torso" gear="1" {lim}/>'
                in text)
        assert f'<motor name="{leg}_knee_motor" joint="{leg}_knee" gear="1" {lim}/>' in text
    assert " range=" not in text and "<equality>" not in text
    assert 'name="hip_actuation"' not in text
    assert "Left out: motor leg1_hip_motor: URDF has no actuator" in Path(urdf).read_text()
    assert 'type="revolute"' not in Path(urdf).read_text()  # free knees: continuous
    f, model = _mujoco(mjcf)
    data = mujoco.MjData(model)
    T = np.zeros((model.nv, 7))
    for name, row in JOINT_ROWS.items():
        T[model.joint(name).dofadr[0]] = row
    coords = ("hip_x", "hip_y", "leg1_thigh", "leg1_shank", "leg2_thigh", "leg2_shank",
              "torso")
    want = {"leg1_hip_motor": ("leg1_thigh", "torso"), "leg2_knee_motor": ("leg2_shank",
                                                                           "leg2_thigh")}
    for motor, (plus, minus) in want.items():
        for u, tau in ((7.0, 7.0), (-400.0, -150.0)):  # beyond the saturation: clamped
            data.ctrl[:] = 0.0
            data.ctrl[model.actuator(motor).id] = u
            mujoco.mj_forward(model, data)
            Q = T.T @ data.qfrc_actuator
            expect = np.zeros(7)
            expect[coords.index(plus)], expect[coords.index(minus)] = tau, -tau
            np.testing.assert_allclose(Q, expect, atol=1e-12)


@pytest.mark.slow  # 40-90 s: 4.3 s of MuJoCo (20000 steps of 0.22 ms), the PD laws evaluated
#                   in Python at every step
def test_rabbit_walks_in_mujoco_with_its_controller(tmp_path, monkeypatch):
    """configs/rabbit.yaml exported to MJCF (its keyframe the rigid fixed point: the scene's
    initial guess, the fixed point to 1e-8, tests/test_rabbit.py; the gait search itself is
    the export's, left out here for time) walks in MuJoCo from the ``gait`` keyframe under
    PoweredLoop: 11 alternating heel strikes in 4.3 s, mean step period within 1 % of
    the rigid 0.37093 s (measured 0.3716 s, +0.2 %), steps 0.3385-0.3388 m against the rigid
    0.33847 m."""
    from walkerlab.export.mujoco_walk import walk
    from walkerlab.models.registry import build_walker

    scene = load_scene(ROOT / "configs" / "rabbit.yaml")
    x = scene.fixedpoint.initial_guess.as_array(build_walker(Plant.from_scene(scene)).state_names())
    monkeypatch.setattr("walkerlab.analysis.contact.periodic.ideal_gait",
                        _known_gait(x, 0.37093))
    path = export_stage.run(scene, tmp_path, "mjcf")
    run = walk(path, 4.3)  # 11 heel strikes (the first at 0.37 s)
    assert not run.fell
    assert len(run.times_s) >= 11 and run.alternating, run.legs
    assert run.legs[0] == "leg1"
    assert run.step_periods_s.mean() == pytest.approx(0.37093, rel=0.01)
    np.testing.assert_allclose(run.step_lengths_m, 0.33847, rtol=0.01)
    side = export_stage.run(scene, tmp_path, "urdf")
    note = json.loads((Path(side).parent / export_stage.SIDECAR).read_text())
    assert [t["joint"] for t in note["actuation"]["torques"]] == [
        "stance_hip", "swing_hip", "stance_knee", "swing_knee"]


def test_gait_keyframe_is_the_rigid_state(exported):
    """The ``gait`` keyframe of the MJCF and the URDF's sidecar: leg2's foot (stance) at the
    origin, ``torso_hip`` the rigid torso angle, ``leg<i>_hip`` the absolute thigh angles,
    ``leg<i>_knee`` shank - thigh, rates likewise (leg1 swinging)."""
    mujoco = pytest.importorskip("mujoco")
    scene, urdf, mjcf = exported
    names = tuple(f"{r}_{k}" for k in ("angle", "rate") for r in (
        "stance_shank", "stance_thigh", "swing_thigh", "swing_shank", "torso"))
    x = dict(zip(names, scene.fixedpoint.initial_guess.as_array(names)))
    m = mujoco.MjModel.from_xml_path(str(mjcf))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("gait").id)
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(d.site("leg2_foot").xpos, [0, 0, 0], atol=1e-12)
    for k, kind in (("angle", d.qpos), ("rate", d.qvel)):
        adr = "qposadr" if k == "angle" else "dofadr"

        def at(j, kind=kind, adr=adr):
            return kind[getattr(m.joint(j), adr)[0]]

        assert at("torso_hip") == pytest.approx(x[f"torso_{k}"], abs=1e-12)
        assert at("leg1_hip") == pytest.approx(x[f"swing_thigh_{k}"], abs=1e-12)
        assert at("leg2_knee") == pytest.approx(x[f"stance_shank_{k}"]
                                                - x[f"stance_thigh_{k}"], abs=1e-12)
    side = json.loads((Path(urdf).parent / export_stage.SIDECAR).read_text())
    assert side["joints"] == ["hip_x", "hip_z", "leg1_hip", "leg1_knee", "leg2_hip",
                              "leg2_knee", "torso_hip"]
    np.testing.assert_array_equal(side["qpos"], d.qpos)
    assert "five-link" in side["actuation_note"]
