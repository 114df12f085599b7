"""Flat feet exported to MJCF (issue 48 item 2): foot bodies on ankle hinges carrying the
ankle springs, heel and toe contact spheres, the gait keyframe in double support, and the
exported walker walking in MuJoCo (configs/flat_feet.yaml: Wisse et al. 2006's walker on
flat feet with ankle springs)."""

from __future__ import annotations

import xml.dom.minidom
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.stages import export as export_stage

ROOT = Path(__file__).resolve().parents[1]
mujoco = pytest.importorskip("mujoco")


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    scene = load_scene(ROOT / "configs" / "flat_feet.yaml")
    return scene, export_stage.run(scene, tmp_path_factory.mktemp("flat"), "mjcf")


def test_flat_feet_have_ankle_hinges_with_the_springs_and_heel_and_toe_contacts(exported):
    """Each leg's foot is a body on a hinge ``leg<i>_ankle`` with the scene's ankle spring
    (120 N m/rad about rest 0, 3 N m s/rad) and the contact model's foot mass (0.01 kg);
    spheres at the heel (0.05 m behind the ankle: geom ``leg<i>_foot``, the stepping loop's
    heel strike) and toe (0.10 m ahead); the ``gait`` keyframe puts leg2's heel and leg1's
    toe on the slope (the double support as it begins) with leg2's heel at the origin."""
    scene, path = exported
    doc = xml.dom.minidom.parse(str(path))
    model = mujoco.MjModel.from_xml_path(str(path))
    for leg in ("leg1", "leg2"):
        j = model.joint(f"{leg}_ankle")
        assert float(model.jnt_stiffness[j.id]) == 120.0
        assert float(model.qpos_spring[j.qposadr[0]]) == 0.0
        assert float(model.dof_damping[j.dofadr[0]]) == 3.0
        assert float(model.body(f"{leg}_sole").mass[0]) == pytest.approx(0.01)
        assert model.geom(f"{leg}_foot").pos[0] == pytest.approx(-0.05)
        assert model.geom(f"{leg}_toe").pos[0] == pytest.approx(0.10)
    assert len(doc.getElementsByTagName("joint")) == 6
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("gait").id)
    mujoco.mj_forward(model, data)
    phi = scene.slope.angle_rad
    n = np.array([np.sin(phi), 0.0, np.cos(phi)])

    def height(geom):
        return float(data.geom_xpos[model.geom(geom).id] @ n)
    assert height("leg2_foot") == pytest.approx(0.0, abs=1e-9)
    assert height("leg1_toe") == pytest.approx(0.0, abs=1e-9)
    # leg2's toe up by (heel + toe) sin(stance + gamma) = 0.0456 m, leg1's heel up
    assert height("leg2_toe") > 0.04 and height("leg1_foot") > 0.01
    assert data.geom_xpos[model.geom("leg2_foot").id][0] == pytest.approx(0.0, abs=1e-9)
    # the trailing toe does not move (pinned in the double support): to round-off
    vel = np.zeros(6)
    mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_GEOM,
                             model.geom("leg1_toe").id, vel, 0)
    assert np.max(np.abs(vel[3:])) < 1e-9


@pytest.mark.slow
def test_the_exported_flat_footed_walker_walks_in_mujoco_within_one_percent(exported):
    """>= 10 alternating heel strikes from the keyframe; mean step period and length
    against the rigid gait's (0.81016 s, 0.6286 m with its double support).  Measured
    (9.2 s): 11 strikes, 0.80764 s (-0.31 %) with the scene's 0.01 kg regularising feet;
    with 0.1 kg ones (the scene before) 0.8259 s (+1.94 %): the foot at the end of the
    swing leg lengthens its swing (the same share as in walkerlab's contact model,
    scripts/flat_feet_contact_gap.py).  Within 1 %: the regularising mass's share is a
    few tenths of a percent at 0.01 kg."""
    from walkerlab.export.mujoco_walk import walk

    _scene, path = exported
    run = walk(path, 9.2)
    assert not run.fell
    assert len(run.times_s) >= 10 and run.alternating and run.legs[0] == "leg1"
    assert run.step_periods_s.mean() == pytest.approx(0.8101592422, rel=0.01)
    assert run.step_lengths_m.mean() == pytest.approx(0.6286, rel=0.02)


def test_heel_off_latch_and_ankle_law_of_the_stepping_loop(tmp_path):
    """configs/flat_feet_push_off.yaml's MJCF: motors on both ankle hinges (refused before:
    "ankle_push_off: not exported yet"); PoweredLoop's stance-ankle torque is 0 until the
    stance heel has been out of contact HEEL_OFF_STEPS steps running with its toe on the
    ground, then the contact view's law ``-k (a - rest) - tau0`` (25 N m here: -25 N m on
    the stance ankle motor, the swing ankle's 0)."""
    from types import SimpleNamespace

    from walkerlab.export.mujoco_walk import HEEL_OFF_STEPS, PoweredLoop

    scene = load_scene(ROOT / "configs" / "flat_feet_push_off.yaml")
    path = export_stage.run(scene, tmp_path, "mjcf")
    model = mujoco.MjModel.from_xml_path(str(path))
    loop = PoweredLoop(model)
    heel, toe = model.geom("leg2_foot").id, model.geom("leg2_toe").id
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("gait").id)

    def contacts(*geoms):
        return SimpleNamespace(geom=np.array([[g, 0] for g in geoms] or np.zeros((0, 2))))
    fake = SimpleNamespace(qpos=data.qpos, ncon=0, contact=contacts())
    fake.ncon, fake.contact = 2, contacts(heel, toe)  # foot flat: nothing
    assert loop.ankle_torque(fake) == 0.0
    fake.ncon, fake.contact = 1, contacts(toe)
    for _ in range(HEEL_OFF_STEPS - 1):  # a flicker of the soft contact: still nothing
        assert loop.ankle_torque(fake) == 0.0
    assert loop.ankle_torque(fake) == -25.0  # heel off: latched
    fake.ncon, fake.contact = 2, contacts(heel, toe)
    assert loop.ankle_torque(fake) == -25.0
    loop.heel_strike(data, 0)  # leg1 strikes: off until leg1's heel leaves
    assert loop.ankle_torque(fake) == 0.0


@pytest.mark.slow
def test_the_exported_ankle_push_off_walks_on_level_ground(tmp_path):
    """configs/flat_feet_push_off.yaml (level ground, 25 N m from heel off): 11 alternating
    heel strikes in 8.6 s, mean step period within 3 % of the rigid gait's 0.7524 s
    (measured 0.7719 s, +2.59 %: the 0.1 kg regularising feet, as flat_feet's +1.94 %) and
    step length 0.4152 m against 0.4130 m; the same file walked without its stepping loop's
    push-off stops on level ground (< 5 strikes).  (A 12th step's swing heel clips the next
    patch's edge: the footfalls drift 2 mm a step from the rigid gait's patches, as in the
    contact view; configs/flat_feet_push_off.yaml.)"""
    from walkerlab.export.mujoco_walk import walk

    scene = load_scene(ROOT / "configs" / "flat_feet_push_off.yaml")
    path = export_stage.run(scene, tmp_path, "mjcf")
    run = walk(path, 8.6)
    assert not run.fell
    assert len(run.times_s) >= 11 and run.alternating and run.legs[0] == "leg1"
    assert run.step_periods_s.mean() == pytest.approx(0.7524, rel=0.03)
    assert run.step_lengths_m.mean() == pytest.approx(0.4130, rel=0.02)
    passive = tmp_path / "passive.xml"
    passive.write_text(Path(path).read_text().replace('<text name="walkerlab_actuation"',
                                                      '<text name="off"'))
    still = walk(passive, 4.0)
    assert still.fell or len(still.times_s) < 5
