"""Flat-footed planar walkers exported without their MuJoCo scene: the URDF (the rigid model:
soles on the ankle hinges, massless as the rigid model's feet or with the walker's foot mass,
heel and toe collision spheres, the ankle springs stated in the header) loaded by Pinocchio,
and the MJCF of the walker alone (``--walker-only``: the soles carry the contact section's
regularising mass, the ankle springs are joint springs) loaded by MuJoCo.

References are the scenes' own numbers read by hand from the YAML (configs/flat_feet.yaml:
hip 10 kg, 5 kg per leg, massless feet, contact.flat_foot_mass_kg 0.01 kg and
flat_foot_inertia_kg_m2 5e-5; configs/flat_feet_foot_mass.yaml: 0.1 kg feet with 5e-4 kg m^2
about the ankle; both: leg 1 m, heel 0.05 m, toe 0.10 m, ankle 120 N m/rad about rest 0,
3 N m s/rad, slope 0.04 rad).  The files carry every number with 17 significant digits:
equalities to round-off (1e-12)."""

from __future__ import annotations

import json
import math
import xml.dom.minidom
from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.stages import export as export_stage

ROOT = Path(__file__).resolve().parents[1]
TOL = 1e-12
#: scene -> (total mass [kg], each sole's mass in the URDF [kg], in the walker-only MJCF [kg],
#: the MJCF sole's moment about the ankle [kg m^2]), from the YAML
SCENES = {"flat_feet": (20.0, 0.0, 0.01, 5e-5),
          "flat_feet_foot_mass": (20.2, 0.1, 0.1, 5e-4)}
HEEL, TOE, LEG = 0.05, 0.10, 1.0


def _scene(name):
    return load_scene(ROOT / "configs" / f"{name}.yaml")


@pytest.mark.parametrize("name", sorted(SCENES))
def test_flat_feet_urdf_in_pinocchio_has_the_scenes_mass_soles_heels_and_toes(name,
                                                                             tmp_path):
    """Pinocchio's model of the URDF: total mass the scene's (massless feet: 20 kg, no sole
    mass; 0.1 kg feet: 20.2 kg, each sole 0.1 kg at its ankle with 5e-4 kg m^2 about the
    pitch axis); each sole on its hinge ``leg<i>_ankle`` at the leg's end (1 m below the
    hip, axis -y); the heel and toe collision spheres (radius L/1000, the point feet's) at
    0.05 m behind and 0.10 m ahead of the ankle."""
    pin = pytest.importorskip("pinocchio")
    total, sole_kg, _, _ = SCENES[name]
    path = export_stage.run(_scene(name), tmp_path, "urdf")
    model = pin.buildModelFromUrdf(str(path))
    assert sum(i.mass for i in model.inertias) == pytest.approx(total, rel=TOL)
    data = model.createData()
    pin.computeJointJacobians(model, data, pin.neutral(model))
    geom = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.COLLISION)
    # Pinocchio names a link's collisions <link>_<i> in the file's order: heel, then toe
    names = [c.getAttribute("name") for c in
             xml.dom.minidom.parse(str(path)).getElementsByTagName("collision")]
    assert names == ["leg1_heel", "leg1_toe", "leg2_heel", "leg2_toe"]
    spheres = dict(zip(names, geom.geometryObjects))
    for leg in ("leg1", "leg2"):
        j = model.getJointId(f"{leg}_ankle")
        assert model.names[model.parents[j]] == f"{leg}_hip"
        np.testing.assert_allclose(model.jointPlacements[j].translation, [0, 0, -LEG],
                                   atol=TOL)
        axis = pin.getJointJacobian(model, data, j, pin.LOCAL)[3:, model.joints[j].idx_v]
        np.testing.assert_allclose(axis, [0, -1, 0], atol=TOL)  # about -y, as every hinge
        inertia = model.inertias[j]
        assert inertia.mass == pytest.approx(sole_kg, abs=TOL)
        if sole_kg:
            np.testing.assert_allclose(inertia.lever, 0.0, atol=TOL)  # at the ankle
            assert inertia.inertia[1, 1] == pytest.approx(5e-4, rel=TOL)
        for point, x in (("heel", -HEEL), ("toe", TOE)):
            g = spheres[f"{leg}_{point}"]
            assert g.parentJoint == j
            np.testing.assert_allclose(g.placement.translation, [x, 0, 0], atol=TOL)
            assert g.geometry.radius == pytest.approx(LEG / 1000, rel=TOL)
    text = path.read_text()
    assert "Ankle spring leg1_ankle" in text and "k = 120.0 N m/rad" in text
    assert "Left out: ankle spring leg2_ankle: URDF has no spring element" in text
    assert ("massless (no inertial) as the rigid model's feet are" in text) == (not sole_kg)


def test_flat_feet_urdf_keyframe_puts_the_leading_heel_and_trailing_toe_on_the_slope(
        tmp_path):
    """The sidecar's keyframe (hip_x, hip_z, leg1_hip, leg1_ankle, leg2_hip, leg2_ankle:
    MuJoCo's order, the MJCF's ``gait`` keyframe) in Pinocchio: leg2's heel at the origin and
    leg1's toe on the slope line (the rigid heel strike's double support as it begins), as
    tests/test_export_flat_feet.py has it in MuJoCo; the keyframe equals the scene MJCF's."""
    pin = pytest.importorskip("pinocchio")
    mujoco = pytest.importorskip("mujoco")
    scene = _scene("flat_feet")
    path = export_stage.run(scene, tmp_path, "urdf")
    key = json.loads((path.parent / export_stage.SIDECAR).read_text())
    assert key["joints"] == ["hip_x", "hip_z", "leg1_hip", "leg1_ankle", "leg2_hip",
                             "leg2_ankle"]
    mj = mujoco.MjModel.from_xml_path(str(export_stage.run(scene, tmp_path, "mjcf")))
    np.testing.assert_array_equal(mj.key("gait").qpos, key["qpos"])
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    geom = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.COLLISION)
    gdata = pin.GeometryData(geom)
    q = np.zeros(model.nq)
    for name, a in zip(key["joints"], key["qpos"]):
        jm = model.joints[model.getJointId(name)]
        q[jm.idx_q:jm.idx_q + jm.nq] = (math.cos(a), math.sin(a)) if jm.nq == 2 else (a,)
    pin.forwardKinematics(model, data, q)
    pin.updateGeometryPlacements(model, data, geom, gdata)
    phi = scene.slope.angle_rad
    n = np.array([math.sin(phi), 0.0, math.cos(phi)])  # the slope's normal

    ids = {"leg1_heel": 0, "leg1_toe": 1, "leg2_heel": 2, "leg2_toe": 3}  # the file's order

    def at(g):
        return gdata.oMg[ids[g]].translation
    np.testing.assert_allclose(at("leg2_heel"), 0.0, atol=1e-9)
    assert at("leg1_toe") @ n == pytest.approx(0.0, abs=1e-9)
    assert at("leg2_toe") @ n > 0.04 and at("leg1_heel") @ n > 0.01


@pytest.mark.parametrize("name", sorted(SCENES))
def test_flat_feet_walker_only_mjcf_carries_the_sole_mass_and_ankle_springs(name, tmp_path):
    """``--walker-only``: the MJCF of the walker alone loads in MuJoCo; each sole on its
    ankle hinge with the scene's spring (120 N m/rad about rest 0, 3 N m s/rad) and mass
    (massless feet: the contact section's 0.01 kg and 5e-5 kg m^2; 0.1 kg feet: theirs),
    heel and toe spheres at -0.05 m and 0.10 m, the ``standing`` keyframe only; the total
    mass the scene's plus the regularising soles'."""
    mujoco = pytest.importorskip("mujoco")
    total, _, sole_kg, moment = SCENES[name]
    path = export_stage.run(_scene(name), tmp_path, "mjcf", walker_only=True)
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.nkey == 1 and model.key("standing").id == 0
    assert model.nq == 6
    for leg in ("leg1", "leg2"):
        j = model.joint(f"{leg}_ankle")
        assert float(model.jnt_stiffness[j.id]) == 120.0
        assert float(model.qpos_spring[j.qposadr[0]]) == 0.0
        assert float(model.dof_damping[j.dofadr[0]]) == 3.0
        body = model.body(f"{leg}_sole")
        assert float(body.mass[0]) == pytest.approx(sole_kg, rel=TOL)
        assert float(body.inertia[1]) == pytest.approx(moment, rel=TOL)  # about y
        assert model.geom(f"{leg}_foot").pos[0] == pytest.approx(-HEEL, rel=TOL)
        assert model.geom(f"{leg}_toe").pos[0] == pytest.approx(TOE, rel=TOL)
    regularising = 2 * sole_kg if name == "flat_feet" else 0.0
    # the hip's and legs' inertia floors are no mass; MJCF_MIN_MASS_KG nowhere (a massive hip)
    assert float(model.body_mass.sum()) == pytest.approx(total + regularising, rel=TOL)
    assert "the contact model's regularising foot mass" in path.read_text() or (
        name == "flat_feet_foot_mass")


def test_flat_feet_walker_only_mjcf_without_foot_mass_refused_in_one_line(tmp_path):
    """Massless feet and no contact section (ContactSettings().flat_foot(): none): the
    walker alone's MJCF has no mass for its soles; refused in one line naming the fields,
    as the scene's MJCF is; the URDF (massless soles) is written."""
    raw = yaml.safe_load((ROOT / "configs" / "flat_feet.yaml").read_text())
    raw.pop("contact")
    scene = scene_from_dict(raw)
    with pytest.raises(ValueError, match=r"^contact.flat_foot_mass_kg and "
                       r"contact.flat_foot_inertia_kg_m2: ") as exc:
        export_stage.run(scene, tmp_path, "mjcf", walker_only=True)
    assert "\n" not in str(exc.value)
    assert export_stage.run(scene, tmp_path, "urdf", walker_only=True).is_file()


def test_flat_feet_urdf_and_walker_only_mjcf_written_by_the_cli(tmp_path):
    """``walkerlab export configs/flat_feet.yaml --format urdf`` and ``--format mjcf
    --walker-only`` (both refused before): exit 0, no traceback, the files written (the
    URDF with its keyframe sidecar) and the ankle springs among what the URDF leaves out."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    runs = tmp_path / "runs"
    cfg = str(ROOT / "configs" / "flat_feet.yaml")
    for args in (["--format", "urdf"], ["--format", "mjcf", "--walker-only"]):
        r = CliRunner().invoke(app, ["export", cfg, *args, "--runs-dir", str(runs)])
        assert r.exit_code == 0, r.output
        assert "Traceback" not in r.output
    assert "left out of walker.urdf: ankle spring leg1_ankle" in CliRunner().invoke(
        app, ["export", cfg, "--format", "urdf", "--runs-dir", str(runs)]).output
    for f in ("walker.urdf", export_stage.SIDECAR, "walker.xml"):
        assert (runs / "flat_feet" / f).is_file()


def test_flat_feet_push_off_urdf_states_its_ankle_motors_and_their_laws(tmp_path):
    """configs/flat_feet_push_off.yaml to URDF: the hip and both ankle motors among what the
    file leaves out, each ankle motor's sense the ankle's (+u turns the sole toe up, the
    hinge's positive angle; before: "+u extends the knee", a knee motor's words), the
    actuation's laws in the keyframe sidecar."""
    from walkerlab.export.urdf_omitted import urdf_omissions
    from walkerlab.walker.description import walker_data
    from walkerlab.walker.multibody import multibody

    scene = _scene("flat_feet_push_off")
    lines = [o.line for o in urdf_omissions(multibody(walker_data(scene.walker,
                                                                  scene.slope.phi_rad)),
                                             scene.walker.actuation)]
    for leg in ("leg1", "leg2"):
        assert any(f"motor {leg}_ankle_motor" in ln and f"the joint {leg}_ankle (+u turns "
                   "the sole toe up)" in ln for ln in lines), lines
    path = export_stage.run(scene, tmp_path, "urdf")
    key = json.loads((path.parent / export_stage.SIDECAR).read_text())
    assert "actuation" in key and len(key["joints"]) == len(key["qpos"]) == 6
