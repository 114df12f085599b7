"""The 3D straight-legged walker's URDF with hip-roll joints and actuators
(:func:`walkerlab.export.urdf.legs_urdf_text`; ``configs/hip_width_powered.yaml``):
loaded by Pinocchio (Carpentier et al. 2019, an engine of its own), its joints, masses and
kinematics against the MJCF's in MuJoCo, and what it leaves out."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.cli.options import load
from walkerlab.stages import export

pin = pytest.importorskip("pinocchio")
mujoco = pytest.importorskip("mujoco")

ROOT = Path(__file__).resolve().parents[1]
HINGES = ("leg1_roll", "leg1_hip", "leg2_roll", "leg2_hip")


def test_the_hip_roll_urdf_is_the_mjcfs_walker_in_pinocchio(tmp_path):
    """configs/hip_width_powered.yaml's URDF (walker only: no gait search) in Pinocchio: a
    free pelvis and, per leg, a roll joint then a pitch joint (through a massless link),
    20 kg in all (10 + 5 + 5); at random configurations (pelvis position and roll, every
    leg roll and pitch different) each leg's foot and centre of mass where MuJoCo puts the
    MJCF's (its pelvis on three slides and a roll hinge about the fall line), to 1e-12 m
    (round-off of two kinematic chains)."""
    scene = load(str(ROOT / "configs" / "hip_width_powered.yaml"))
    urdf = export.write(scene, tmp_path / "u", "urdf", walker_only=True).path
    mjcf = export.write(scene, tmp_path / "m", "mjcf", walker_only=True).path
    pm = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    assert [pm.names[i] for i in range(1, pm.njoints)] == ["root_joint", *HINGES]
    assert abs(sum(float(i.mass) for i in pm.inertias) - 20.0) < 1e-12
    pd = pm.createData()
    mm = mujoco.MjModel.from_xml_path(str(mjcf))
    md = mujoco.MjData(mm)
    axis = np.array(mm.joint("pelvis_roll").axis, float)
    rng = np.random.default_rng(3)
    for _ in range(5):
        pos, roll = rng.uniform(-0.3, 0.3, 3), rng.uniform(-0.2, 0.2)
        hinges = rng.uniform(-0.4, 0.4, 4)
        md.qpos[:] = [*pos, roll, *hinges]
        mujoco.mj_kinematics(mm, md)
        q = np.zeros(pm.nq)
        q[:7] = pin.SE3ToXYZQUAT(pin.SE3(pin.AngleAxis(roll, axis).toRotationMatrix(), pos))
        for name, v in zip(HINGES, hinges):  # a continuous joint: (cos, sin) of its angle
            j = pm.joints[pm.getJointId(name)]
            assert j.nq == 2
            q[j.idx_q:j.idx_q + 2] = np.cos(v), np.sin(v)
        pin.forwardKinematics(pm, pd, q)
        for leg in ("leg1", "leg2"):
            M = pd.oMi[pm.getJointId(f"{leg}_hip")]
            foot = M.act(np.array([0.0, 0.0, -0.999]))
            assert np.max(np.abs(foot - md.site_xpos[mm.site(f"{leg}_foot").id])) < 1e-12
            com = M.act(pm.inertias[pm.getJointId(f"{leg}_hip")].lever)
            assert np.max(np.abs(com - md.xipos[mm.body(leg).id])) < 1e-12


def test_the_powered_3d_urdf_lists_its_actuators_and_hip_roll_law_as_left_out(tmp_path):
    """The URDF has no actuator, force or law element: the motor ``hip`` (on ``leg1_hip -
    leg2_hip``), the push-off, the hip-roll law and the pelvis' held pitch and yaw are
    listed as left out after the ground (file comments and the export's lines alike), the
    scene's actuation and law in comments; the passive walker without hip roll lists the
    ground alone (issue 96: it printed nothing)."""
    scene = load(str(ROOT / "configs" / "hip_width_powered.yaml"))
    out = export.write(scene, tmp_path / "u", "urdf", walker_only=True)
    text = Path(out.path).read_text()
    assert [ln.split(":")[0] for ln in out.left_out] == [
        "the ground (slope, terrain and contact law)", "the hip-roll law (walker.hip_roll)",
        "the pelvis' held pitch and yaw", "motor hip", "the push-off (walker.actuation.push_off)"]
    assert all(f"<!-- Left out: {ln} -->" in text for ln in out.left_out)
    assert "leg1_hip - leg2_hip" in out.left_out[3]
    assert "<!-- walkerlab_actuation: {" in text and "<!-- walkerlab_hip_roll: {" in text
    passive = export.write(load(str(ROOT / "configs" / "paper_3d.yaml")), tmp_path / "p",
                           "urdf", walker_only=True)
    assert [ln.split(":")[0] for ln in passive.left_out] == [
        "the ground (slope, terrain and contact law)"]
