"""``walkerlab export SCENE --format osim`` of a walker in 3D (issue 98 item 4, issue 97 item
4): the OpenSim model written from the walker's body tree
(:mod:`walkerlab.export.opensim_3d`), loaded by OpenSim and walked by its Manager with
walkerlab's stepping loop applying the hip-roll law.

The XML checks need no OpenSim; loading and walking skip without it (the ``osim`` extra),
and run OpenSim in a process of its own (its CasADi clashes with walkerlab's:
tests/test_export_opensim.py).  Measured (OpenSim 4.6): configs/hip_width_stabilised.yaml
walks 11 alternating heel strikes in 7.95 s, mean step period 0.7048 s against the rigid
gait's 0.703242 s (+0.22 %).
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.stages import export as export_stage

needs_opensim = pytest.mark.skipif(importlib.util.find_spec("opensim") is None,
                                   reason="opensim (the osim extra) not installed")

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def stabilised(tmp_path_factory):
    """configs/hip_width_stabilised.yaml's OpenSim model at the state of its scene's initial
    guess (its fixed point to 1e-6: no gait search, the checks are of the file's
    kinematics, not of the gait): (scene, the file's path, that state x (10,))."""
    from walkerlab.export.opensim_3d import osim3d_gait, osim3d_text
    from walkerlab.walker.description import state_names, walker_data
    from walkerlab.walker.plant import Plant

    scene = load_scene(ROOT / "configs" / "hip_width_stabilised.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    g = scene.fixedpoint.initial_guess
    x = np.array([getattr(g, f"{n}_rad" if n.endswith("_angle") else f"{n}_rad_per_s")
                  for n in state_names(data.structure.roles)], float)
    ideal = SimpleNamespace(x=x, period_s=0.703242, step_lengths_m=())
    path = tmp_path_factory.mktemp("osim3d") / "walker.osim"
    plant = Plant.from_scene(scene)
    path.write_text(osim3d_text(data, osim3d_gait(plant, ideal), "stabilised"))
    return scene, path, x


def _bodies(path) -> dict:
    """Each ``Body`` of the file: name -> (mass [kg], centre of mass (3,) [m], inertia
    ``Ixx Iyy Izz Ixy Ixz Iyz`` (6,) [kg m^2])."""
    root = ET.fromstring(Path(path).read_text().replace("::", "__"))
    return {b.get("name"): (float(b.findtext("mass")),
                            np.array(b.findtext("mass_center").split(), float),
                            np.array(b.findtext("inertia").split(), float))
            for b in root.iter("Body")}


def test_the_3d_osim_carries_the_walkers_masses_and_hips(stabilised):
    """The stabilised walker's bodies as the scene gives them, not as the tree writer
    computes them: the pelvis the hip mass (10 kg) with the law's roll inertia (0.3 kg m^2)
    about its roll axis; each leg 5 kg at L - a = 0.5 m below its hip, the hips 0.1 m apart
    along z (walkerlab's pitch axis), leg1 on the +z side (the first swing hip's); 20 kg in
    all (the walker description's total)."""
    from walkerlab.walker.description import walker_data

    scene, path, _ = stabilised
    w = scene.walker
    bodies = _bodies(path)
    assert set(bodies) == {"pelvis", "leg1", "leg2"}
    total = sum(m for m, _, _ in bodies.values())
    assert total == pytest.approx(walker_data(w, scene.slope.phi_rad).total_mass_kg, rel=1e-12)
    m, com, inertia = bodies["pelvis"]
    assert m == w.hip_mass_kg and not com.any()
    assert inertia[:3] == pytest.approx([w.hip_roll.pelvis_roll_inertia_kg_m2] * 3, abs=1e-12)
    for leg in ("leg1", "leg2"):
        m, com, _ = bodies[leg]
        assert m == w.leg_mass_kg
        assert com == pytest.approx([0.0, -(w.leg_length_m - w.leg_mass_from_foot_m), 0.0],
                                    abs=1e-12)
    root = ET.fromstring(Path(path).read_text().replace("::", "__"))
    hips = {f.get("name"): np.array(f.findtext("translation").split(), float)
            for f in root.iter("PhysicalOffsetFrame") if "_parent_at_" in f.get("name")}
    assert hips["leg1_parent_at_leg1_joint"] == pytest.approx([0, 0, w.hip_width_m / 2])
    assert hips["leg2_parent_at_leg2_joint"] == pytest.approx([0, 0, -w.hip_width_m / 2])


_LOAD = """
import json, sys
import opensim as osim
osim.Logger.setLevelString("error")
m = osim.Model(sys.argv[1]); s = m.initSystem()
out = {"total": m.getTotalMass(s), "bodies": {}, "stations": {}}
for i in range(m.getBodySet().getSize()):
    b = m.getBodySet().get(i)
    J = b.getInertia()
    moments = list(J.getMoments().to_numpy()) + list(J.getProducts().to_numpy())
    out["bodies"][b.getName()] = [b.getMass(), list(b.getMassCenter().to_numpy()), moments]
for name, body, y in json.loads(sys.argv[2]):
    p = m.getBodySet().get(body).findStationLocationInGround(s, osim.Vec3(0, y, 0))
    out["stations"][name] = list(p.to_numpy())
print(json.dumps(out))
"""


def _opensim(path, stations) -> dict:
    """The file loaded by OpenSim in a process of its own: its total mass, each body's mass,
    centre of mass and inertia, and the ground positions at the default state of
    ``stations`` ((name, body, y along the body's axis [m]))."""
    proc = subprocess.run([sys.executable, "-c", _LOAD, str(path), json.dumps(stations)],
                          capture_output=True, text=True, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


@needs_opensim
def test_opensim_loads_the_3d_osim_with_the_trees_bodies_at_the_rigid_gait(stabilised):
    """OpenSim reads the file's bodies as the body tree has them (mass, centre of mass and
    inertia of :func:`walkerlab.export.opensim_3d.osim3d_bodies`, to 1e-12), and its default
    state is the rigid gait: the pelvis and both feet (the point ``L`` down each leg) where
    the rigid model's generated points put the hip and the feet, moved by the foot
    sphere's shift ``r (e + n)`` (``e`` the stance leg's direction, ``n`` the slope's
    normal: the stance sphere's lowest point at the origin), to 1e-9 m: the CustomJoints
    turn each leg about its roll, then its pitch, as the rigid model does."""
    from walkerlab.codegen.cache import functions
    from walkerlab.export.opensim_3d import osim3d_bodies
    from walkerlab.export.opensim_tree import osim_axis, osim_inertia
    from walkerlab.walker.description import walker_data

    scene, path, x = stabilised
    data = walker_data(scene.walker, scene.slope.phi_rad)
    L, r = scene.walker.leg_length_m, scene.walker.leg_length_m / 1000
    got = _opensim(path, [["hip", "pelvis", 0.0], ["leg1_foot", "leg1", -L],
                              ["leg2_foot", "leg2", -L]])
    assert got["total"] == pytest.approx(data.total_mass_kg, rel=1e-12)
    root, _ = osim3d_bodies(data)
    for b in root.walk():
        m, com, inertia = got["bodies"][b.name]
        J = osim_inertia(b.inertia_kg_m2)
        assert m == pytest.approx(b.mass_kg, abs=1e-12)
        assert com == pytest.approx(osim_axis(b.com_m), abs=1e-12)
        assert inertia == pytest.approx([J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2]],
                                        abs=1e-12)
    pts = {k: np.ravel(np.asarray(v, float)) for k, v in functions(data)["points"](x).items()}
    phi = scene.slope.phi_rad
    n = np.array([math.sin(phi), math.cos(phi), 0.0])
    e = -pts["stance_hip"] / np.linalg.norm(pts["stance_hip"])
    shift = r * (e + n)
    assert got["stations"]["hip"] == pytest.approx(pts["hip"] + shift, abs=1e-9)
    assert got["stations"]["leg2_foot"] == pytest.approx(shift, abs=1e-9)
    assert got["stations"]["leg1_foot"] == pytest.approx(pts["swing_foot"] + shift, abs=1e-9)


def _walks_within_3_percent(name: str, tmp_path, capsizes: bool = False):
    """The shipped scene's .osim walked by OpenSim (``export --walk``): at least 10
    alternating heel strikes without a fall, the mean step period within 3 % of the rigid
    gait's (the capability table's OpenSim tolerance); returns the walk's check.
    ``capsizes``: a laterally unstable gait, whose roll grows from what the engine's
    integrator lets into it until it capsizes: the 10 heel strikes before any fall."""
    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    w = export_stage.write(scene, tmp_path, "osim", walk=True, walk_steps=10).walk
    assert w.walked and (capsizes or not w.fell) and w.alternating, w.line
    assert w.strikes >= 10, w.line
    assert abs(w.relative) <= 0.03, w.line
    return w


@pytest.mark.slow
@needs_opensim
@pytest.mark.parametrize("name", ["hip_width_stabilised", "hip_width_powered"])
def test_the_stabilised_3d_walkers_walk_in_opensim_within_3_percent(tmp_path, name):
    """The scene's .osim stepped by OpenSim's Manager, walkerlab's loop applying the
    hip-roll law between its windows (and configs/hip_width_powered.yaml's hip spring and
    its push-off at each heel strike): at least 10 alternating heel strikes without a fall,
    the mean step period within 3 % of the rigid gait's (the capability table's OpenSim
    tolerance; measured: hip_width_stabilised +0.22 %; hip_width_powered 11 strikes, mean
    step period 0.646 s against 0.644452 s, +0.24 %).  Before the loop kept its own state
    (the rolls of earlier windows, the test below) the powered walker struck once, at
    0.579 s against 0.6445 s, and fell."""
    _walks_within_3_percent(name, tmp_path)


_ROLLS = """
import json, sys
import numpy as np
from walkerlab.export import opensim_walk as ow
seen, read, init = [], ow._HipRoll.rolls, ow._HipRoll.__init__
def __init__(self, model, law, phi):
    init(self, model, law, phi)
    self.coords = model.getCoordinateSet()
def rolls(self, state):
    phi, dphi = read(self, state)
    c = {n: self.coords.get(n) for n in ("pelvis_roll", "leg1_roll", "leg2_roll")}
    q = {n: k.getValue(state) for n, k in c.items()}
    u = {n: k.getSpeedValue(state) for n, k in c.items()}
    want = [q["pelvis_roll"], q["pelvis_roll"] + q["leg1_roll"], q["pelvis_roll"] + q["leg2_roll"]]
    rate = [u["pelvis_roll"], u["pelvis_roll"] + u["leg1_roll"], u["pelvis_roll"] + u["leg2_roll"]]
    seen.append([np.abs(phi - want).max(), np.abs(dphi - rate).max()])
    return phi, dphi
ow._HipRoll.__init__, ow._HipRoll.rolls = __init__, rolls
ow.walk_here(sys.argv[1], 0.1)
print(json.dumps({"windows": len(seen), "worst": np.max(seen, axis=0).tolist()}))
"""


@needs_opensim
def test_the_stepping_loop_reads_the_bodies_rolls_of_the_present_window(stabilised):
    """The hip-roll law reads each body's roll about the fall line and its rate from the
    frames' orientations and angular velocities in the loop's state; the pelvis' roll is its
    coordinate ``pelvis_roll`` and a leg's is ``pelvis_roll + leg<i>_roll`` (its roll axis
    is the fall line in the rolled pelvis, its pitch axis normal to it), so over the first
    0.1 s (200 windows) the two agree to round-off.  A state copied from the Manager's
    (``opensim.State(manager.integrate(t))``, the loop before this check) read the frames
    of earlier windows in 89 of these 200 (up to 9.4 mrad and 0.089 rad/s off), and the
    powered walker (configs/hip_width_powered.yaml) struck 65 ms early and fell."""
    _, path, _ = stabilised
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-c", _ROLLS, str(path)], capture_output=True,
                          text=True, check=True, env=env)
    got = json.loads(proc.stdout.strip().splitlines()[-1])
    assert got["windows"] == 200
    assert got["worst"][0] < 1e-12 and got["worst"][1] < 1e-12, got


# ---------------------------------------------------------------- round feet (discs)
_DISC_REST = """
import json, math, sys
import opensim as osim
R, rg, stiff, diss, vt, W = map(float, sys.argv[1:7])
m = osim.Model()
m.setGravity(osim.Vec3(0, -9.81, 0))
body = osim.Body("disc", W / 9.81, osim.Vec3(0), osim.Inertia(1e-3, 1e-3, 1e-3))
m.addBody(body)
j = osim.SliderJoint("slide", m.getGround(), osim.Vec3(0), osim.Vec3(0, 0, math.pi / 2),
                     body, osim.Vec3(0), osim.Vec3(0, 0, math.pi / 2))
m.addJoint(j)
m.addContactGeometry(osim.ContactSphere(rg, osim.Vec3(0, -rg, 0), m.getGround(), "patch"))
m.addContactGeometry(osim.ContactEllipsoid(osim.Vec3(R, R, R / 10), osim.Vec3(0),
                                           osim.Vec3(0), body, "foot"))
hc = osim.HuntCrossleyForce()
hc.addGeometry("patch")
hc.addGeometry("foot")
hc.setStiffness(stiff); hc.setDissipation(diss); hc.setStaticFriction(0.9)
hc.setDynamicFriction(0.7); hc.setViscousFriction(0.0); hc.setTransitionVelocity(vt)
m.addForce(hc)
s = m.initSystem()
j.getCoordinate().setValue(s, R)
mgr = osim.Manager(m)
mgr.setIntegratorAccuracy(1e-9)
s.setTime(0)
mgr.initialize(s)
s = mgr.integrate(3.0)
print(json.dumps({"depth": R - j.getCoordinate().getValue(s)}))
"""


@needs_opensim
@pytest.mark.parametrize(("R", "rg"), [(0.2, 1.0), (0.1, 0.05)])
def test_a_round_foots_ellipsoid_rests_in_opensim_at_the_impact_laws_depth(R, rg):
    """The round foot's ellipsoid (semi-axes R, R, R/10) on a patch sphere of radius ``rg``
    with the Hunt-Crossley parameters the 3D writer derives from the scene's IMPACT law
    through :func:`walkerlab.export.opensim_3d.disc_contact_radius`: OpenSim's Manager lets
    a body of the walker's weight sink to the IMPACT law's rest depth ``(W / k)^(1/e)``
    (the translation's fixed point) within 1e-6 (measured 2e-10: the integration's
    accuracy), a check by OpenSim itself of the effective radius Simbody takes for the
    pair."""
    from walkerlab.config.contact import ContactSettings
    from walkerlab.export.opensim_3d import disc_contact_radius
    from walkerlab.export.opensim_contact import hunt_crossley
    from walkerlab.models.contact.rigid_limit import contact_si

    c, _ = contact_si(ContactSettings())
    W = 200.0
    stiff, diss, vt, _ = hunt_crossley(c, W, disc_contact_radius(R, rg))
    proc = subprocess.run([sys.executable, "-c", _DISC_REST, *map(str, (R, rg, stiff, diss, vt,
                                                                        W))],
                          capture_output=True, text=True, check=True)
    depth = json.loads(proc.stdout.strip().splitlines()[-1])["depth"]
    assert depth == pytest.approx((W / c.k) ** (1.0 / c.e), rel=1e-6)


def test_the_round_feet_osim_writes_each_disc_as_a_thin_ellipsoid_on_its_leg(tmp_path):
    """configs/round_feet_3d.yaml's file: each foot a ContactEllipsoid of semi-axes (R, R,
    R/10) on its leg, centred L - R down it (the disc's centre), no foot sphere."""
    scene = load_scene(ROOT / "configs" / "round_feet_3d.yaml")
    path = export_stage.write(scene, tmp_path, "osim").path
    root = ET.fromstring(Path(path).read_text().replace("::", "__"))
    feet = root.findall(".//ContactEllipsoid")
    assert sorted(f.get("name") for f in feet) == ["leg1_foot", "leg2_foot"]
    R, L = scene.walker.foot_radius_m, scene.walker.leg_length_m
    for f in feet:
        assert [float(v) for v in f.find("radii").text.split()] == pytest.approx(
            [R, R, R / 10], abs=1e-12)
        assert [float(v) for v in f.find("location").text.split()] == pytest.approx(
            [0.0, -(L - R), 0.0], abs=1e-12)
    assert not [s for s in root.findall(".//ContactSphere") if s.get("name").endswith("_foot")]


def test_a_push_off_on_round_feet_is_refused_in_the_osim_in_one_line(tmp_path):
    """The file's push-off force acts at a point fixed on the leg, the rigid model's at the
    disc's rolling contact: refused in one line naming walker.actuation.push_off."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app

    d = yaml.safe_load((ROOT / "configs" / "round_feet_3d.yaml").read_text())
    d["walker"]["actuation"] = {"push_off": {"impulse_n_s": 0.05}}
    scene = tmp_path / "discs.yaml"
    scene.write_text(yaml.safe_dump(d))
    r = CliRunner().invoke(app, ["export", str(scene), "--format", "osim", "--runs-dir",
                                 str(tmp_path / "r")])
    assert r.exit_code != 0 and r.output.count("error:") == 1, r.output
    assert "walker.actuation.push_off" in r.output and "Traceback" not in r.output
    assert not list((tmp_path / "r").rglob("*.osim"))


@pytest.mark.slow
@needs_opensim
@pytest.mark.parametrize(("name", "measured", "capsizes"),
                         [("round_feet_3d", 0.0038, True), ("kneed_round_feet_3d", 0.0179, False)])
def test_the_3d_round_feet_walk_in_opensim_within_3_percent(tmp_path, name, measured,
                                                             capsizes):
    """The discs as thin ellipsoids (straight legs; the kneed walker's on its shanks, its knee
    latch switched by walkerlab's loop) stepped by OpenSim's Manager: at least 10
    alternating heel strikes without a fall, the mean step period within 3 % of the rigid
    gait's (the capability table's OpenSim tolerance; measured +0.38 % and +1.79 %, the
    MJCF's -0.02 % and -0.11 %, the contact model's +0.09 % and +0.93 %).
    ``round_feet_3d`` has no hip width: its gait is laterally unstable, its roll growing x11
    a step from what the integrator lets into it (configs/round_feet_3d.yaml), so its walk
    capsizes some steps after that seed, which is the machine's round-off (measured: after
    heel strike 10 at +0.84 %, 24.9 s, on one machine, later on another): the 10 strikes
    are asked for before any fall."""
    w = _walks_within_3_percent(name, tmp_path, capsizes)
    assert w.relative == pytest.approx(measured, abs=0.005), w.line
