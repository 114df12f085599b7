"""The exported MJCF walks in MuJoCo from its ``gait`` keyframe (issue 25 item 3), and the
export refuses or handles inputs MuJoCo cannot take (issue 26).

MuJoCo runs the exported file with its own soft contact (solref/solimp mapped from the
scene's IMPACT law), the scene's terrain and, for the kneed walker, the knee latch switched by
:func:`walkerlab.export.mujoco_walk.latch_rule`.  A MuJoCo run is an outside check of the
whole export (masses, geometry, keyframe, ground placement, contact): a wrong keyframe sign, a
ground at the wrong height or a contact too soft makes the walker fall or change its gait.
Measured (12 s): paper 17 alternating heel strikes, mean step period 0.70342 s against the
rigid 0.70360 s (-0.03 %), step length 0.3722 m against 0.3714 m; kneed 22 strikes,
0.5434 s against 0.54585 s (-0.4 %, the 2 mm latch release; a step-to-step oscillation of
+-0.5 %).  Tolerance 1 % (issue 25): MuJoCo's contact is soft and linear.  Issue 22:
hip_spring (spring as a tendon) 12 strikes in 6.5 s, 0.52184 s against 0.522193 s; torso_bhm
(bisecting hip as a tendon equality) 11 strikes in 9.5 s, 0.85055 s against 0.850906 s;
asymmetric_legs 17 strikes in 12 s, leg A's / leg B's steps 0.71420 / 0.67823 s against
0.71442 / 0.67839 s (the checkerboard laid out with both step lengths).
"""

from __future__ import annotations

import json
import xml.dom.minidom
from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config import load_scene
from walkerlab.stages import export as export_stage

ROOT = Path(__file__).resolve().parents[1]
mujoco = pytest.importorskip("mujoco")


def _scene(name):
    return load_scene(ROOT / "configs" / f"{name}.yaml")


@pytest.mark.parametrize("name, t_final, rigid_period", [("paper", 8.5, 0.703597),
                                                        ("kneed", 6.5, 0.545846),
                                                        ("hip_spring", 6.5, 0.522193),
                                                        ("torso_bhm", 9.5, 0.850906)])
def test_exported_walker_walks_in_mujoco_at_the_rigid_period(name, t_final, rigid_period,
                                                             tmp_path):
    from walkerlab.export.mujoco_walk import walk

    scene = _scene(name)
    run = walk(export_stage.run(scene, tmp_path, "mjcf"), t_final)
    assert not run.fell
    assert len(run.times_s) >= 10 and run.alternating, run.legs
    assert run.step_periods_s.mean() == pytest.approx(rigid_period, rel=0.01)
    # the first footfall is leg1's (leg2 stands at the keyframe)
    assert run.legs[0] == "leg1"


def test_powered_export_walks_in_mujoco_with_its_push_off(tmp_path):
    """configs/powered_compass.yaml on level ground: the hip motor on the tendon leg1_hip -
    leg2_hip and the push-off applied by the stepping loop (PoweredLoop) at each heel strike.
    Measured (10 s): 14 alternating strikes, mean step period 0.671 s against the rigid
    0.6916 s (-3 %: MuJoCo's contact is soft and linear, and the 5 ms push-off starts at a
    soft touchdown; walkerlab's own contact model gives +1.5 %), steps 0.344-0.354 m against
    0.345 m.  Tolerance 5 %.  Without the push-off the walker stops on level ground."""
    from walkerlab.export.mujoco_walk import walk

    scene = _scene("powered_compass")
    path = export_stage.run(scene, tmp_path, "mjcf")
    run = walk(path, 10.0)
    assert not run.fell
    assert len(run.times_s) >= 10 and run.alternating, run.legs
    assert run.step_periods_s.mean() == pytest.approx(0.6916, rel=0.05)
    text = Path(path).read_text()
    assert '<motor name="hip" tendon="hip_actuation"' in text
    passive = tmp_path / "passive.xml"
    passive.write_text(text.replace('<text name="walkerlab_actuation"', '<text name="off"'))
    still = walk(passive, 4.0)
    assert still.fell or len(still.times_s) < 5
    export_stage.run(scene, tmp_path, "urdf")
    side = json.loads((tmp_path / "powered_compass" / export_stage.SIDECAR).read_text())
    assert side["actuation"]["push_off"]["impulse_n_s"] == 3.0


def test_gait_keyframe_is_the_rigid_fixed_point_and_urdf_sidecar_carries_it(tmp_path):
    """The keyframe's hip_x/hip_z put the stance foot (leg2) at the origin; the URDF's sidecar
    has the same numbers under the URDF's joint names; the rates of the legs are the fixed
    point's (paper Eq. (11) neighbourhood: stance rate ~ -0.84 rad/s)."""
    from walkerlab.analysis.contact.periodic import ideal_gait

    scene = _scene("paper")
    m = mujoco.MjModel.from_xml_path(str(export_stage.run(scene, tmp_path, "mjcf")))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("gait").id)
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(d.site("leg2_foot").xpos, [0, 0, 0], atol=1e-12)
    x = ideal_gait(scene).x  # [th_swing, th_stance, w_swing, w_stance]
    assert d.qpos[m.joint("leg1_hip").qposadr[0]] == pytest.approx(x[0], abs=1e-12)
    assert d.qpos[m.joint("leg2_hip").qposadr[0]] == pytest.approx(x[1], abs=1e-12)
    assert d.qvel[m.joint("leg2_hip").dofadr[0]] == pytest.approx(x[3], abs=1e-12)
    export_stage.run(scene, tmp_path, "urdf")
    side = json.loads((tmp_path / "paper" / export_stage.SIDECAR).read_text())
    assert side["joints"] == ["hip_x", "hip_z", "leg1_hip", "leg2_hip"]
    np.testing.assert_array_equal(side["qpos"], d.qpos)
    np.testing.assert_array_equal(side["qvel"], d.qvel)


def _edited(tmp_path, base, edit):
    d = yaml.safe_load((ROOT / "configs" / f"{base}.yaml").read_text())
    edit(d)
    p = tmp_path / f"{base}.yaml"
    p.write_text(yaml.safe_dump(d))
    return p


def test_double_dash_name_gives_well_formed_xml(tmp_path):
    """issue 26: ``name: a--b`` (allowed) put "--" inside an XML comment (XML 1.0 s. 2.5)."""
    scene = load_scene(_edited(tmp_path, "paper", lambda d: d.update(name="a--b")))
    for fmt, attr in (("urdf", "name"), ("mjcf", "model")):
        doc = xml.dom.minidom.parse(str(export_stage.run(scene, tmp_path / "runs", fmt)))
        assert doc.documentElement.getAttribute(attr) == "a--b"
    mujoco.MjModel.from_xml_path(str(tmp_path / "runs" / "a--b" / "walker.xml"))


def test_round_feet_radius_zero_exports_point_feet(tmp_path):
    """issue 26: R = 0 gave a cylinder of size 0 (MuJoCo: "size 0 must be positive"); R = 0
    is the point foot (NOTES.md), exported as the point foot's sphere."""
    def zero(d):
        d["walker"]["leg"]["foot"]["radius_m"] = 0.0
    scene = load_scene(_edited(tmp_path, "round_feet", zero))
    m = mujoco.MjModel.from_xml_path(str(export_stage.run(scene, tmp_path / "runs", "mjcf")))
    assert m.geom("leg1_foot").type[0] == mujoco.mjtGeom.mjGEOM_SPHERE


@pytest.mark.parametrize("base, edit, field", [
    ("paper", lambda d: d["walker"].update(leg_mass_kg=1e-300), "walker.leg_mass_kg"),
    ("paper", lambda d: d["walker"].update(leg_length_m=1e-300, leg_mass_from_foot_m=5e-301),
     "walker.leg_length_m"),
    ("paper_rods", lambda d: d["walker"]["leg"]["bodies"][0].update(mass_kg=1e-300),
     "walker.leg.bodies[0].mass_kg"),
])
def test_tiny_mass_or_length_refused_in_one_line(base, edit, field, tmp_path):
    """issue 26: leg mass or length 1e-300 gave an MJCF MuJoCo refuses ("mass and inertia of
    moving bodies must be larger than mjMINVAL", "fromto points too close"): one line naming
    the field, exit code 1, nothing written."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    path = _edited(tmp_path, base, edit)
    r = CliRunner().invoke(app, ["export", str(path), "--format", "mjcf",
                                 "--runs-dir", str(tmp_path / "runs")])
    assert r.exit_code == 1, r.output
    assert r.output.strip().count("\n") == 0 and field in r.output, r.output
    assert not list((tmp_path / "runs").rglob("walker.*"))


def test_asymmetric_legs_walk_both_steps_in_mujoco(tmp_path):
    """Legs that differ: MuJoCo walks the stride's two steps at the rigid stride's step
    periods (1 %), on a checkerboard laid out with both step lengths (one length for both
    lets footfalls drift 8.6 mm per stride off the 10 cm patches: a fall after 10 strikes)."""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.export.mujoco_walk import walk

    scene = _scene("asymmetric_legs")
    rigid = ideal_gait(scene)
    run = walk(export_stage.run(scene, tmp_path, "mjcf"), 12.0)
    assert not run.fell and len(run.times_s) >= 12 and run.alternating
    # strike i -> i + 1 after a leg1 strike is leg2's step (rigid step 2), and vice versa
    by_leg = {leg: run.step_periods_s[[i for i, x in enumerate(run.legs[:-1]) if x == leg]]
              for leg in ("leg1", "leg2")}
    assert by_leg["leg1"].mean() == pytest.approx(rigid.step_periods_s[1], rel=0.01)
    assert by_leg["leg2"].mean() == pytest.approx(rigid.step_periods_s[0], rel=0.01)
    assert abs(rigid.step_periods_s[1] - rigid.step_periods_s[0]) > 0.02  # they differ
