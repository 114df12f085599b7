"""The exported MJCF walks in MuJoCo from its ``gait`` keyframe (issue 25 item 3), and the
export refuses or handles inputs MuJoCo cannot take (issue 26).

MuJoCo runs the exported file with its own soft contact (solref/solimp mapped from the
scene's IMPACT law), the scene's terrain and, for the kneed walker, the knee latch switched by
:func:`walkerlab.export.mujoco_walk.latch_rule`.  A MuJoCo run is an outside check of the
whole export (masses, geometry, keyframe, ground placement, contact): a wrong keyframe sign, a
ground at the wrong height or a contact too soft makes the walker fall or change its gait.
Measured: test_every_shipped_scene_walks_in_mujoco_or_is_refused's docstring (every shipped
scene, 11.3 rigid steps).  Over 30.3 rigid steps: 30 alternating strikes for all but
compass_optimal (17, then a foot misses its 10 cm patch: MuJoCo's steps are 3 mm longer than
the rigid 0.536 m, the footfalls drift 4.9 cm; the scene keeps the default terrain);
powered_compass -1.5 % over 30.  Tolerance 1 % (issue 25): MuJoCo's contact is soft and
linear.
"""

from __future__ import annotations

import json
import re
import xml.dom.minidom
from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config import load_scene
from walkerlab.stages import export as export_stage
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
mujoco = pytest.importorskip("mujoco")


def _scene(name):
    return load_scene(ROOT / "configs" / f"{name}.yaml")


#: Shipped scenes the MJCF export refuses, and the field its one line names: massless legs
#: have no multibody form (flat feet and their ankle push-off are exported:
#: tests/test_export_flat_feet.py).  Arms coupled to the opposite legs and feet curved in
#: both directions are exported (shoulder hinges held to the legs' by tendon equalities,
#: spheroid feet: walkerlab.export.legs_3d_mjcf; configs/collins2001_stable.yaml walks).
REFUSED = {"kuo2002": "walker.leg.bodies", "schwab_wisse2001": "walker.leg.bodies",
           "simplest": "walker.leg.bodies"}
#: rabbit_optimal: no gait of its own (its step is optimised with open-loop torques:
#: tests/test_optimize_five_link.py): the export refuses it in one line (no rigid gait);
#: rimless_wheel: its steps are spoke strikes, spoke 0 standing at the keyframe.
NO_GAIT = {"rabbit_optimal": "no rigid gait"}
#: Shipped scenes whose rigid gait is unstable faster than a walk of 10 steps, and the heel
#: strikes their MJCF makes in turn before it falls: hip_width's lateral mode (x 99.9 a stride, Kuo
#: 1999) takes it after 3 (paper_3d, its upright twin, walks: its roll starts at 0), the
#: torso walker's (x 206 a stride) after 3 too, kneed_3d's (x 39.9 a stride) after 3 (its
#: latch holds the stance knee with the pelvis a rod between the hips:
#: walkerlab.export.legs_3d_mjcf; its first stride is held to the rigid gait in
#: tests/test_kneed_3d_export.py), kneed_3d_stairs (the same walker down stairs) after 4
#: (+0.99 %; its hip-roll law steadies it: kneed_3d_stabilised_stairs walks, -0.72 %),
#: kneed_3d_powered (the same walker with a push-off, hip and knee laws: x39 a stride) after
#: 3 (-1.77 %; on the hip-roll walker they walk: kneed_3d_powered_stabilised, -0.63 %).
#: The Collins-style walker on knees (x2.12 a stride: tests/test_collins_knees.py) makes 11
#: heel strikes in turn (its first step +0.09 %), then fell where it was first measured and
#: shuffles out of turn on this machine (14 strikes); the straight-legged ones walk though
#: laterally unstable (x1.47 a stride collins2001 -0.04 %, toroidal_feet_3d +0.12 %,
#: toroidal_arms_3d +0.20 %: their pelvis held from yawing as the rigid model's),
#: collins2001_stable +0.11 %.
FALLS = {"hip_width": 3, "torso_bhm_3d": 3, "kneed_3d": 3, "kneed_3d_stairs": 4,
         "kneed_3d_powered": 3, "collins2001_knees": 10}
FIRST = {"rimless_wheel": "spoke1", "rimless_wheel_3d": "spoke1",
         "rimless_wheel_3d_disc": "spoke1", "rimless_wheel_3d_disc_stairs": "spoke1"}
SHIPPED = sorted(p.stem for p in (ROOT / "configs").glob("*.yaml"))
#: Step-period tolerance against the rigid gait: 1 % (MuJoCo's contact is soft and linear,
#: walkerlab's own contact model differs from the rigid one by 0.1-1 % on these walkers).
#: powered_compass too: the export applies the push-off over one MuJoCo timestep (the rigid
#: model's impulse); with the contact model's 5 ms pulse MuJoCo's walker steps 2.06 % faster,
#: 0.39 % with 1 ms (test_powered_export_reaches_the_rigid_gait_as_the_pulse_shortens).
#: flat_feet: the foot bodies carry the contact model's regularising 0.01 kg (the rigid
#: view's feet are massless): -0.31 % (1 %; tests/test_export_flat_feet.py);
#: flat_feet_optimal, the same walker with 0.1 kg: +1.94 %.
#: flat_feet_foot_mass: 0.1 kg feet in every view, the rigid one too: -0.41 % (1 %).
#: flat_feet_push_off: the same 0.1 kg feet, +2.59 % (0.7719 s against 0.7524 s; the ankle
#: push-off from heel off to heel strike driven by PoweredLoop).
#: flat_feet_stairs, flat_feet_footholds: the same walker and feet on stairs (+1.77 %) and
#: footholds of three heights (+1.46 %; tests/test_flat_feet_terrain.py).
PERIOD_RTOL: dict[str, float] = {"flat_feet_optimal": 0.025,
                                 "flat_feet_push_off": 0.03, "flat_feet_stairs": 0.025,
                                 "flat_feet_footholds": 0.025}


@pytest.mark.slow
@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_scene_walks_in_mujoco_or_is_refused(name, tmp_path):
    """Every shipped scene's MJCF, walked by the export's own check (``walkerlab export
    --walk``: :func:`walkerlab.export.engine_walk.walk_export`, the latch rule for the kneed
    walkers, PoweredLoop for the powered ones), makes >= 10 alternating heel strikes from
    its ``gait`` keyframe, its mean step period within 1 % of the rigid gait's; or the
    export refuses in one line naming the field (massless legs, no rigid gait), writing
    nothing.  The rimless wheel rolls: 11 spoke strikes, -0.49 %.
    Measured (11.3 rigid steps each; step period against the rigid one; the export's
    default contact, the linearised time constant shrunk 4 times with the timestep):
    asymmetric_legs -0.02 %, compass_optimal +0.86 %, goswami1996 +0.77 %, hip_spring
    -0.04 %, kneed and kneed_optimal -0.46 %, profile -0.54 %, paper -0.03 %, paper_rods
    -0.03 %, powered_compass -0.02 % (its push-off over one timestep: see
    test_powered_export_reaches_the_rigid_gait_as_the_pulse_shortens), round_feet +0.00 %,
    torso_bhm -0.03 %, torso_powered -0.03 %, stairs +0.04 % (patches at the footholds,
    each a riser lower), footholds +0.17 %, footholds_two +0.09 %, threelink +0.14 %,
    threelink_footholds +0.16 %, threelink_hzd +0.21 %, rabbit +0.05 %, rabbit_footholds
    +0.20 %, rabbit_hzd and rabbit_hzd_optimal +0.20 %, paper_3d (the free pelvis in 3D)
    -0.005 %, round_feet_3d (its disc feet: MuJoCo cylinders) +0.01 %, hip_width_stairs
    (patches at the treads' heights) +0.01 %, hip_width_footholds (patches at the rigid
    walk's footfalls, each at its foothold's height) -0.00 %, kneed_3d_stabilised_stairs
    -0.72 %,
    kneed_3d_powered_stabilised -0.63 %, rimless_wheel_3d_disc_stairs (the treads as
    boxes) -0.36 %; hip_width falls
    after 3 heel strikes (:data:`FALLS`).  About 5-40 s each under load."""
    scene = _scene(name)
    if name in REFUSED or name in NO_GAIT:
        with pytest.raises(ValueError) as err:
            export_stage.write(scene, tmp_path, "mjcf", walk=True)
        assert {**REFUSED, **NO_GAIT}[name] in str(err.value) and "\n" not in str(err.value)
        assert not list(tmp_path.rglob("walker.*"))
        return
    check = export_stage.write(scene, tmp_path, "mjcf", walk=True).walk
    assert check.engine == "MuJoCo" and check.walked, check.line
    if name in FALLS:  # its first strikes in turn, then its lateral mode ends the walk: a
        # fall, or feet striking out of turn (which of the two is the engine's round-off)
        assert check.strikes_in_turn >= FALLS[name], check.line
        assert check.fell or not check.alternating, check.line
        return
    assert not check.fell, check.line
    assert check.strikes >= 10 and check.alternating, check.line
    assert check.first_leg == FIRST.get(name, "leg1")  # leg2 stands at the keyframe
    assert check.period_s == pytest.approx(check.rigid_period_s,
                                           rel=PERIOD_RTOL.get(name, 0.01)), check.line


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_walk_check_reports_the_step_period_against_the_rigid_gait(tmp_path):
    """``walkerlab export --walk`` on the paper's MJCF prints one line: 11 alternating heel
    strikes, the mean step period against the rigid 0.703597 s within 1 % (measured
    -0.05 %); the period is the strikes' own (independent of the check: MuJoCo run by
    mujoco_walk.walk here); on the URDF and the Adams dataset one line why there is no walk;
    on the OpenSim model, where OpenSim is not importable, one line saying so."""
    import importlib.util

    from tests.cli_run import run_cli
    from walkerlab.export.mujoco_walk import walk

    code, err, out = run_cli("export", ROOT / "configs" / "paper.yaml", "--format", "mjcf",
                             "--runs-dir", tmp_path, "--walk")
    assert code == 0, err
    (line,) = [ln for ln in out.splitlines() if "walked in MuJoCo" in ln]
    m = re.search(r"(\d+) heel strikes \(alternating\).*mean step period (\S+) s against "
                  r"the rigid gait's (\S+) s \(([-+0-9.]+) %, within 1 %\)", line)
    assert m, line
    assert int(m.group(1)) >= 10
    assert float(m.group(3)) == pytest.approx(0.703597, abs=1e-6)
    run = walk(tmp_path / "paper" / "walker.xml", 11.3 * float(m.group(3)))
    assert float(m.group(2)) == pytest.approx(run.step_periods_s.mean(), abs=1e-6)
    for fmt, why in (("urdf", "a URDF has no ground"), ("adm", "Adams Solver"),
                     ("osim", "OpenSim is not importable")):
        if fmt == "osim" and importlib.util.find_spec("opensim") is not None:
            continue
        code, err, out = run_cli("export", ROOT / "configs" / "paper.yaml", "--format", fmt,
                                 "--runs-dir", tmp_path, "--walk")
        assert code == 0, err
        (line,) = [ln for ln in out.splitlines() if "not walked" in ln]
        assert why in line


def test_walk_with_walker_only_is_refused_in_one_line(tmp_path):
    """``--walk --walker-only``: the walker alone has no gait to walk from: one line,
    nothing written."""
    from tests.cli_run import run_cli

    code, err, _ = run_cli("export", ROOT / "configs" / "paper.yaml", "--format", "mjcf",
                           "--runs-dir", tmp_path, "--walk", "--walker-only")
    assert code == 1 and "--walk" in err and "\n" not in err
    assert not list(tmp_path.rglob("walker.*"))


def test_powered_export_walks_in_mujoco_with_its_push_off(tmp_path):
    """configs/powered_compass.yaml on level ground: the hip motor on the tendon leg1_hip -
    leg2_hip and the push-off applied by the stepping loop (PoweredLoop) at each heel strike.
    Its walk is in test_every_shipped_scene_walks_in_mujoco_or_is_refused (11 strikes, step
    period -2.06 % against the rigid 0.6916 s, steps 0.344-0.352 m against 0.345 m).  Without
    the push-off the walker stops on level ground."""
    from walkerlab.export.mujoco_walk import walk

    scene = _scene("powered_compass")
    path = export_stage.run(scene, tmp_path, "mjcf")  # walks: the shipped-scene test above
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
    x = ideal_gait(scene,
                   plant=Plant.from_scene(scene)).x  # [th_swing, th_stance, w_swing, w_stance]
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
    rigid = ideal_gait(scene, plant=Plant.from_scene(scene))
    run = walk(export_stage.run(scene, tmp_path, "mjcf"), 12.0)
    assert not run.fell and len(run.times_s) >= 12 and run.alternating
    # strike i -> i + 1 after a leg1 strike is leg2's step (rigid step 2), and vice versa
    by_leg = {leg: run.step_periods_s[[i for i, x in enumerate(run.legs[:-1]) if x == leg]]
              for leg in ("leg1", "leg2")}
    assert by_leg["leg1"].mean() == pytest.approx(rigid.step_periods_s[1], rel=0.01)
    assert by_leg["leg2"].mean() == pytest.approx(rigid.step_periods_s[0], rel=0.01)
    assert abs(rigid.step_periods_s[1] - rigid.step_periods_s[0]) > 0.02  # they differ


def _without_fixedpoint(tmp_path, base, name):
    d = yaml.safe_load((ROOT / "configs" / f"{base}.yaml").read_text())
    d.pop("fixedpoint")
    d["name"] = name
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(d))
    return load_scene(p)


def test_scene_without_fixedpoint_section_exports_its_gait(tmp_path):
    """A scene without a ``fixedpoint:`` section: the gait is found as ``walkerlab
    fixedpoint`` finds it (its defaults: an automatic search) and the MJCF carries the gait
    keyframe, the checkerboard and the contact as with the section (before: no keyframe, a
    plane and MuJoCo's default contact, exit 0).  The search lands on the scene's own gait
    (1e-9: two root finds to xtol 1e-12 from different starts); without a gait, or with
    ``walker_only``, the walker alone."""
    bare = _without_fixedpoint(tmp_path, "paper", "paper_bare")
    runs = tmp_path / "runs"
    m = mujoco.MjModel.from_xml_path(str(export_stage.run(bare, runs, "mjcf")))
    ref = mujoco.MjModel.from_xml_path(str(export_stage.run(_scene("paper"), runs, "mjcf")))
    assert m.nkey == 2 and m.key("gait").id >= 0
    np.testing.assert_allclose(m.key("gait").qpos, ref.key("gait").qpos, atol=1e-9)
    np.testing.assert_allclose(m.key("gait").qvel, ref.key("gait").qvel, atol=1e-9)
    assert m.ngeom == ref.ngeom and m.geom("leg2_patch3").id >= 0  # the checkerboard
    np.testing.assert_array_equal(m.geom_solref, ref.geom_solref)
    np.testing.assert_array_equal(m.opt.timestep, ref.opt.timestep)
    export_stage.run(bare, runs, "urdf")
    assert (runs / "paper_bare" / export_stage.SIDECAR).exists()
    alone = mujoco.MjModel.from_xml_path(str(export_stage.run(bare, runs / "alone", "mjcf",
                                                              walker_only=True)))
    assert alone.nkey == 1


def test_flat_feet_without_fixedpoint_written_alone_or_refused_in_one_line(tmp_path):
    """Flat feet without a ``fixedpoint`` section (before: the shipped scene asked for
    contact fields it sets; without the section a point-footed walker was written, exit 0):
    the walker alone goes to a URDF and an MJCF (its soles on ankle hinges,
    tests/test_flat_feet_urdf.py); OpenSim's model without its scene is refused in one line
    (its default state is the rigid gait)."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    _without_fixedpoint(tmp_path, "flat_feet", "flat_bare")
    runs = tmp_path / "runs"
    for fmt in ("urdf", "mjcf"):
        r = CliRunner().invoke(app, ["export", str(tmp_path / "flat_bare.yaml"), "--format",
                                     fmt, "--walker-only", "--runs-dir", str(runs)])
        assert r.exit_code == 0, r.output
    assert {p.name for p in (runs / "flat_bare").glob("walker.*")} == {"walker.urdf",
                                                                      "walker.xml"}
    r = CliRunner().invoke(app, ["export", str(tmp_path / "flat_bare.yaml"), "--format",
                                 "osim", "--walker-only", "--runs-dir", str(runs)])
    assert r.exit_code == 1 and r.output.strip().count("\n") == 0, r.output
    assert "--walker-only" in r.output


def test_arc_feet_get_ground_for_their_roll_with_a_warning(tmp_path, capsys):
    """The paper walker on 0.3 m arc feet with the paper's 0.10 m patches: the stance foot
    rolls its contact point R (psi_start - psi_end) = 0.3 x 0.457 = 0.137 m ahead of its
    footfall, past the patch's 0.05 m (before: it rolled off the edge and fell at 1.9 s, no
    warning).  The export warns on stderr and in the file, and every patch runs from 0.05 m
    behind the footfall to 0.05 m past the roll's end; the feet are spheres of radius R (in
    the x-z plane the arc: MuJoCo's cylinder-box collision walked round_feet 11 % short)."""
    from walkerlab.export.scene import arc_roll_m

    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    for key in ("ideal", "published", "workprecision"):
        d.pop(key, None)
    d["name"] = "paper_arc"
    d["walker"] = {"model": "biped", "coordinates": "absolute", "gravity_m_per_s2": 9.81,
                   "hip_mass_kg": 10.0,
                   "leg": {"length_m": 1.0, "foot": {"kind": "arc", "radius_m": 0.3},
                           "bodies": [{"kind": "point_mass", "name": "mass", "mass_kg": 5.0,
                                       "from_hip_m": 0.5}]}}
    # the gait the paper's guess leads to (0.6296 s, interleg 0.457 rad); the deflated
    # search may also find a stable long-period one (0.7193 s, 0.520 rad, roll 0.156 m;
    # found here with scipy 1.17.1 / numpy 2.4.6), which ``gait: stable`` would select
    d["fixedpoint"]["gait"] = "nearest_guess"
    (tmp_path / "paper_arc.yaml").write_text(yaml.safe_dump(d))
    scene = load_scene(tmp_path / "paper_arc.yaml")
    path = export_stage.run(scene, tmp_path, "mjcf")
    err = capsys.readouterr().err
    assert "warning: paper_arc: terrain.patch_width_m = 0.1 m" in err
    assert "roll their contact point" in Path(path).read_text()
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("gait").id)
    mujoco.mj_forward(m, d)
    from walkerlab.walker.description import walker_data
    from walkerlab.walker.multibody import multibody

    roll = arc_roll_m(multibody(walker_data(scene.walker, scene.slope.phi_rad)), d.qpos)
    assert roll == pytest.approx(0.137, abs=1e-3)
    # leg2's first patch (its footfall at s = 0), in the slope's frame
    phi = scene.slope.phi_rad
    t = np.array([np.cos(phi), 0.0, -np.sin(phi)])
    centre, half = d.geom("leg2_patch0").xpos @ t, m.geom("leg2_patch0").size[0]
    assert centre - half == pytest.approx(-0.05, abs=1e-12)
    assert centre + half == pytest.approx(roll + 0.05, abs=1e-12)
    assert m.geom("leg1_foot").type[0] == mujoco.mjtGeom.mjGEOM_SPHERE
    assert m.geom("leg1_foot").size[0] == 0.3


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_powered_export_reaches_the_rigid_gait_as_the_pulse_shortens(tmp_path):
    """The rigid model's push-off is an impulse with the heel strike; the export applies it
    over one MuJoCo timestep (its ``push_off_duration_s``; the pulse's last step carries only
    its share, so the impulse is P exactly) and walks the rigid gait's step period to 1 %
    (measured -0.02 %).  A longer pulse than the heel strike's contact misses: the same
    file with 5 ms steps 5.1 % fast, 1 ms 2.6 % (with the contact's linearised time
    constant, 4 times the export's default: 2.06 % and 0.39 %); the miss shrinks with the
    pulse."""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.export.mujoco_walk import walk

    scene = _scene("powered_compass")
    path = Path(export_stage.run(scene, tmp_path, "mjcf"))
    m = mujoco.MjModel.from_xml_path(str(path))
    text = path.read_text()
    step_s = ideal_gait(scene, plant=Plant.from_scene(scene)).period_s
    assert m.numeric("push_off_duration_s").data[0] == pytest.approx(m.opt.timestep, rel=1e-9)
    run = walk(path, 11.3 * step_s)
    assert not run.fell and len(run.times_s) >= 10 and run.alternating
    assert run.step_periods_s.mean() == pytest.approx(step_s, rel=0.01)
    ratio = []
    for pulse in ("0.005", "0.001"):
        p = tmp_path / f"pulse_{pulse}.xml"
        p.write_text(re.sub(r'<numeric name="push_off_duration_s" data="[^"]*"/>',
                            f'<numeric name="push_off_duration_s" data="{pulse}"/>', text))
        r = walk(p, 11.3 * step_s)
        assert not r.fell and len(r.times_s) >= 10
        ratio.append(r.step_periods_s.mean() / step_s - 1)
    assert ratio[0] < ratio[1] < 0 and ratio[1] > 0.75 * ratio[0]  # shrinks with the pulse


@pytest.mark.slow
def test_no_rigid_gait_refused_in_one_line_and_walker_only_writes_the_walker(tmp_path):
    """The paper walker on level ground without a ``fixedpoint`` section: the automatic
    search (its seeds: ~30 s wall under load, 3 s CPU) finds no passive gait, so the export
    refuses in one line saying how to go on and writes nothing (before: a file without
    keyframe, terrain or contact, exit 0);
    ``--walker-only`` writes the walker alone, as asked."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    for key in ("ideal", "published", "workprecision", "fixedpoint"):
        d.pop(key)
    d["slope"]["angle_rad"] = 0.0
    d["name"] = "level"
    (tmp_path / "level.yaml").write_text(yaml.safe_dump(d))
    args = ["export", str(tmp_path / "level.yaml"), "--format", "mjcf",
            "--runs-dir", str(tmp_path / "runs")]
    r = CliRunner().invoke(app, args)
    lines = r.output.strip().splitlines()  # the refusal; what was tried, whole, on a second
    assert r.exit_code == 1 and len(lines) in (1, 2) and lines[-1].startswith(
        ("error:", "  [")), r.output
    assert "no rigid gait" in r.output and "--walker-only" in r.output
    assert not list((tmp_path / "runs").rglob("walker.*"))
    r = CliRunner().invoke(app, [*args, "--walker-only"])
    assert r.exit_code == 0, r.output
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "runs" / "level" / "walker.xml"))
    assert m.nkey == 1  # "standing" only


def test_the_mjcf_contact_time_constant_and_timestep_are_export_options():
    """By default the IMPACT law's linearised time constant is shrunk 4 times and the
    timestep is a quarter of it (at most 1 ms); given, each is written as given; a time
    constant below two timesteps (MuJoCo's floor) is refused in one line naming the flag."""
    from walkerlab.config.contact import ContactSettings
    from walkerlab.export.mjcf_scene import MJCF_CONTACT_SHRINK, MjcfOptions
    from walkerlab.export.scene import mujoco_contact
    from walkerlab.models.contact.rigid_limit import contact_si

    c, _knee = contact_si(ContactSettings())
    W, M = 9.81 * 10.0, 10.0
    ds = (W / c.k) ** (1 / c.e)
    kl = c.e * W / ds
    s = min(ds / c.dmax, 1.0)
    z = c.cmax * s * s * (3 - 2 * s) / (2 * np.sqrt(kl * M))
    tau_lin = 1 / (z * np.sqrt(kl / M))
    dt, (tau, zz), *_ = mujoco_contact(c, M, 9.81, 0.0)
    assert tau == pytest.approx(tau_lin / MJCF_CONTACT_SHRINK, rel=1e-12)
    assert dt == pytest.approx(min(tau / 4, 1e-3), rel=1e-12) and zz == pytest.approx(z)
    dt, (tau, _z), *_ = mujoco_contact(c, M, 9.81, 0.0, MjcfOptions(0.004, 0.0005))
    assert (tau, dt) == (0.004, 0.0005)
    dt, (tau, _z), *_ = mujoco_contact(c, M, 9.81, 0.0, MjcfOptions(0.004))
    assert dt == pytest.approx(0.001)
    with pytest.raises(ValueError) as err:
        mujoco_contact(c, M, 9.81, 0.0, MjcfOptions(0.001, 0.001))
    assert "--mjcf-contact-time-constant-s" in str(err.value)
    assert "\n" not in str(err.value)


def test_an_engine_walk_is_set_against_the_contact_model_too():
    """The walk's line names the contact model's step period and the walk's difference
    from it when there is one, and not otherwise."""
    from walkerlab.export.engine_walk import EngineWalk

    w = EngineWalk("MuJoCo", strikes=11, alternating=True, t_end_s=10.0, period_s=0.88,
                   rigid_period_s=0.89)
    assert "contact model" not in w.line
    w = EngineWalk("MuJoCo", strikes=11, alternating=True, t_end_s=10.0, period_s=0.88,
                   rigid_period_s=0.89, contact_period_s=0.9)
    assert "the contact model's 0.9 s (-2.22 %)" in w.line


def test_a_wheels_walk_line_says_spokes_not_alternating_legs_and_its_own_tolerance():
    """A spoked wheel has no legs to alternate: its strikes are "each by the next spoke";
    the line's verdict is against the tolerance the walk is held to (the capability cell's
    3 %: +2.63 % is within it, not "outside 1 %")."""
    from walkerlab.export.engine_walk import EngineWalk

    wheel = EngineWalk("MuJoCo", strikes=11, alternating=True, t_end_s=11.69, period_s=1.02947,
                       rigid_period_s=1.03455, rolling=True)
    assert "(each by the next spoke)" in wheel.line and "alternating" not in wheel.line
    legs = EngineWalk("MuJoCo", strikes=11, alternating=True, t_end_s=8.502,
                      period_s=0.772177, rigid_period_s=0.752381, tolerance=0.03)
    assert "(alternating)" in legs.line and "(+2.63 %, within 3 %)" in legs.line
