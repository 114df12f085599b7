"""``walkerlab export --format osim`` of the planar spoked wheel (configs/rimless_wheel.yaml:
Drake's RimlessWheel defaults, mass 1 kg, spoke 1 m, 8 spokes, slope 0.08 rad), its file's
numbers checked against the scene here (no walkerlab export code), and its walk in OpenSim
(skips without the ``osim`` extra), and the 3D wheel's (configs/rimless_wheel_3d_disc.yaml).
Measured (OpenSim 4.6, CPodes): the planar wheel 11 spoke strikes, each by the next spoke,
in 11.69 s, mean step period 1.02895 s against the rigid gait's 1.03455 s (-0.54 %); the 3D
disc wheel 11 in 4.477 s, 0.39575 s against 0.396183 s (-0.11 %), down its stairs
(configs/rimless_wheel_3d_disc_stairs.yaml, a sphere per footfall) 11 in 4.478 s, 0.39575 s
against 0.396268 s (-0.13 %).  On stairs and footholds the ground spheres' tops are checked
against the footfalls computed here from the treads and the spoke tips' chord.
"""

from __future__ import annotations

import importlib.util
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.stages import export as export_stage

needs_opensim = pytest.mark.skipif(importlib.util.find_spec("opensim") is None,
                                   reason="opensim (the osim extra) not installed")

SCENE = "configs/rimless_wheel.yaml"
G, L, M, N, PHI = 9.81, 1.0, 1.0, 8, 0.08   # the scene's numbers
HUB_INERTIA = 1e-3                           # its contact.hub_inertia_kg_m2


def _floats(text: str) -> list[float]:
    return [float(v) for v in text.split()]


@pytest.fixture(scope="module")
def wheel_osim(tmp_path_factory):
    """The planar wheel's .osim (its rigid gait searched) and its parsed model."""
    runs = tmp_path_factory.mktemp("wheel_osim")
    out = export_stage.write(load_scene(SCENE), runs, "osim")
    # OpenSim's element names hold "::" (not XML names): read as "__"
    text = out.path.read_text().replace("::", "__")
    return out, ET.fromstring(text).find("Model")


def test_wheel_osim_has_the_scenes_hub_spokes_and_gait(wheel_osim):
    """One body ``hub`` of the scene's mass with the contact section's hub inertia about
    every axis, a contact sphere of radius ``L/1000`` per spoke ``L - r`` along it (spoke k
    at ``2 pi k / n`` ahead of spoke 0, which hangs down at wheel angle 0), each with its own
    Hunt-Crossley force against the ground half-space; gravity along -y; the default state
    the closed-form gait (spoke 0's tip at the origin, ``q = pi/n - phi``, rate ``-w+``)."""
    out, model = wheel_osim
    assert _floats(model.find("gravity").text) == pytest.approx([0.0, -G, 0.0], abs=1e-15)
    bodies = model.find("BodySet").find("objects").findall("Body")
    assert [b.get("name") for b in bodies] == ["hub"]
    hub = bodies[0]
    assert float(hub.find("mass").text) == pytest.approx(M, rel=1e-15)
    assert _floats(hub.find("mass_center").text) == [0.0, 0.0, 0.0]
    assert _floats(hub.find("inertia").text) == pytest.approx(
        [HUB_INERTIA] * 3 + [0.0] * 3, abs=1e-15)
    r = L / 1000
    spheres = {s.get("name"): s for s in model.iter("ContactSphere")}
    assert sorted(spheres) == sorted(f"spoke{k}_foot" for k in range(N))
    for k in range(N):
        s = spheres[f"spoke{k}_foot"]
        psi = 2 * math.pi * k / N
        assert s.find("socket_frame").text == "/bodyset/hub"
        assert float(s.find("radius").text) == pytest.approx(r, rel=1e-15)
        assert _floats(s.find("location").text) == pytest.approx(
            [(L - r) * math.sin(psi), -(L - r) * math.cos(psi), 0.0], abs=1e-15)
    forces = {f.get("name"): f.find(".//geometry").text.split()
              for f in model.iter("HuntCrossleyForce")}
    assert forces == {f"spoke{k}_contact": [f"spoke{k}_foot", "ground"] for k in range(N)}
    half = model.find(".//ContactHalfSpace")
    assert _floats(half.find("location").text) == [0.0, 0.0, 0.0]
    assert _floats(half.find("orientation").text) == pytest.approx(
        [0.0, 0.0, -math.pi / 2 - PHI], abs=1e-15)
    # the closed-form fixed point (a point-mass hub: the rigid gait's)
    a = math.pi / N
    w = 1.0 / math.tan(2 * a) * math.sqrt(4 * G / L * math.sin(a) * math.sin(PHI))
    q = a - PHI
    coords = {c.get("name"): (float(c.find("default_value").text),
                              float(c.find("default_speed_value").text))
              for c in model.iter("Coordinate")}
    want = {"hip_x": (-L * math.sin(q), L * math.cos(q) * w),
            "hip_y": (L * math.cos(q), L * math.sin(q) * w), "wheel": (q, -w)}
    assert set(coords) == set(want)
    for c, (qv, vv) in want.items():
        assert coords[c] == pytest.approx((qv, vv), abs=1e-9), c
    assert out.step_period_s == pytest.approx(1.03455, rel=1e-5)


def test_wheel3d_osim_has_the_disc_wheels_inertia_spokes_and_upright_gait(tmp_path):
    """configs/rimless_wheel_3d_disc.yaml's .osim: the hub's mass, its diametral inertia
    about the body's x and y and its axle inertia about z, the spokes' spheres as the planar
    wheel's, and its default state the upright gait: no heading, lean or sideways motion,
    spin ``pi/n - phi``, the stance sphere's lowest point at the origin (its centre ``L - r``
    along the spoke, ``r`` above the slope along its normal)."""
    out = export_stage.write(load_scene("configs/rimless_wheel_3d_disc.yaml"), tmp_path, "osim")
    model = ET.fromstring(out.path.read_text().replace("::", "__")).find("Model")
    hub = model.find("BodySet").find("objects").find("Body")
    assert float(hub.find("mass").text) == pytest.approx(1.0, rel=1e-15)
    assert _floats(hub.find("inertia").text) == pytest.approx([0.25, 0.25, 0.5, 0, 0, 0],
                                                              abs=1e-15)
    r, phi = L / 1000, 0.2
    for s in model.iter("ContactSphere"):
        k = int(s.get("name").removeprefix("spoke").removesuffix("_foot"))
        psi = 2 * math.pi * k / N
        assert _floats(s.find("location").text) == pytest.approx(
            [(L - r) * math.sin(psi), -(L - r) * math.cos(psi), 0.0], abs=1e-15)
    coords = {c.get("name"): (float(c.find("default_value").text),
                              float(c.find("default_speed_value").text))
              for c in model.iter("Coordinate")}
    q = math.pi / N - phi
    assert coords["spin"][0] == pytest.approx(q, abs=1e-9)
    for c in ("hip_z", "heading", "lean"):
        assert coords[c] == pytest.approx((0.0, 0.0), abs=1e-12), c
    assert coords["hip_x"][0] == pytest.approx(-(L - r) * math.sin(q) + r * math.sin(phi),
                                               abs=1e-12)
    assert coords["hip_y"][0] == pytest.approx((L - r) * math.cos(q) + r * math.cos(phi),
                                               abs=1e-12)
    # turning about the stance sphere's lowest point (the origin) at the spin rate
    w = coords["spin"][1]
    assert coords["hip_x"][1] == pytest.approx(-w * coords["hip_y"][0], rel=1e-9)
    assert coords["hip_y"][1] == pytest.approx(w * coords["hip_x"][0], rel=1e-9)
    assert out.step_period_s == pytest.approx(0.396183, rel=1e-5)


def test_wheel3d_state_angles_compose_the_keyframes_orientation_and_spin():
    """:func:`walkerlab.export.opensim_wheel.osim_wheel3d_state` of a leaning, turned
    keyframe: the body-fixed rotations heading (y), lean (x), spin (z) compose the
    keyframe's orientation (MuJoCo's axes: OpenSim's x, -z, y), and their rates give its
    angular velocity (OpenSim's CustomJoint, checked against OpenSim 4.6 when this was
    written: its rotations are body-fixed in order, its speeds the angles' rates)."""
    from scipy.spatial.transform import Rotation

    from walkerlab.export.opensim_wheel import osim_wheel3d_state

    C = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])   # OpenSim -> MuJoCo axes
    R = Rotation.from_euler("yxz", [0.3, -0.2, 2.5])          # any orientation (OpenSim)
    Rm = C @ R.as_matrix() @ C.T
    x, y, z, w = Rotation.from_matrix(Rm).as_quat()
    omega_body = np.array([0.4, -1.1, 0.7])                   # MuJoCo body axes
    st = dict((n, (q, v)) for n, q, v in osim_wheel3d_state(
        (0.1, 0.2, 0.9, w, x, y, z), (1.0, 2.0, 3.0, *omega_body)))
    a, b, c = (st[n][0] for n in ("heading", "lean", "spin"))
    got = Rotation.from_rotvec([0, a, 0]) * Rotation.from_rotvec([b, 0, 0]) \
        * Rotation.from_rotvec([0, 0, c])
    assert np.allclose(got.as_matrix(), R.as_matrix(), atol=1e-12)
    Ra = Rotation.from_rotvec([0, a, 0]).as_matrix()
    Rab = Ra @ Rotation.from_rotvec([b, 0, 0]).as_matrix()
    e = np.eye(3)
    omega = st["heading"][1] * e[1] + st["lean"][1] * Ra @ e[0] + st["spin"][1] * Rab @ e[2]
    assert np.allclose(C @ omega, Rm @ omega_body, atol=1e-12)
    assert [st[n][0] for n in ("hip_x", "hip_y", "hip_z")] == pytest.approx([0.1, 0.9, -0.2])
    assert [st[n][1] for n in ("hip_x", "hip_y", "hip_z")] == pytest.approx([1.0, 3.0, -2.0])


def _patches(model) -> dict[str, tuple[np.ndarray, float]]:
    """Each ground sphere's (centre (2,), radius) by name."""
    return {s.get("name"): (np.array(_floats(s.find("location").text)[:2]),
                            float(s.find("radius").text))
            for s in model.iter("ContactSphere") if "_patch" in s.get("name")}


def _lane_checks(model, tops: list[np.ndarray], nrm: np.ndarray) -> float:
    """The spheres ``spoke<k>_patch<m>`` are the footfalls ``tops`` (from the one behind
    the first stance tip), footfall ``j`` spoke ``j mod N``'s ``m``-th, their tops at the
    footfalls along ``nrm``; each spoke's force touches its own lane only, no half-space.
    Returns the spheres' one radius."""
    got = _patches(model)
    seen = dict.fromkeys(range(N), 0)
    radii = set()
    for j, top in enumerate(tops, start=-1):
        k = j % N
        centre, rg = got.pop(f"spoke{k}_patch{seen[k]}")
        seen[k] += 1
        assert centre + rg * nrm == pytest.approx(top, abs=1e-12), j
        radii.add(rg)
    assert not got and len(radii) == 1
    assert model.find(".//ContactHalfSpace") is None
    forces = {f.get("name"): f.find(".//geometry").text.split()
              for f in model.iter("HuntCrossleyForce")}
    assert forces == {f"spoke{k}_contact": [f"spoke{k}_foot"]
                      + [f"spoke{k}_patch{m}" for m in range(seen[k])] for k in range(N)}
    return radii.pop()


def test_wheel_osim_on_stairs_puts_a_sphere_top_on_each_footfall_of_its_tread(tmp_path):
    """configs/rimless_wheel_3d_disc_stairs.yaml (0.152 m risers, 0.750 m treads, the
    first stance tip mid-tread 0): footfall ``j`` lies ``j`` chords ``2 L sin(pi/N)`` from the
    first along the line that drops one riser per ``sqrt(c^2 - riser^2)`` of run, its
    height tread ``j``'s (``-j riser``, the tread that holds its x); a sphere's top at
    each; the radius the legs' rule ``d^2 / (2 (riser + 2 r))``, ``d = c / 3``."""
    out = export_stage.write(load_scene("configs/rimless_wheel_3d_disc_stairs.yaml"),
                             tmp_path, "osim")
    model = ET.fromstring(out.path.read_text().replace("::", "__")).find("Model")
    riser, tread, c = 0.152, 0.750, 2 * L * math.sin(math.pi / N)
    run = math.sqrt(c * c - riser * riser)
    tops = []
    for j in range(-1, 61):
        x = j * run
        i = math.floor((x + tread / 2) / tread)      # the tread under it (0: [-D/2, D/2))
        assert i == j
        tops.append(np.array([x, -i * riser]))
    assert all(np.linalg.norm(b - a) == pytest.approx(c, rel=1e-12)
               for a, b in zip(tops, tops[1:]))
    rg = _lane_checks(model, tops, np.array([0.0, 1.0]))
    assert rg == pytest.approx((c / 3) ** 2 / (2 * (riser + 2 * L / 1000)), rel=1e-12)


def test_wheel_osim_on_footholds_puts_a_sphere_top_on_each_footfall(tmp_path):
    """The planar wheel's footholds cell (configs/rimless_wheel.yaml, footholds 5 mm below
    and above its 0.08 rad slope in turn, 0.3 m patches): footfall ``j + 1`` a chord from
    footfall ``j``, ``h_j`` (-5 mm, +5 mm, ...) above its level along the vertical, i.e.
    ``h_j cos(phi)`` along the slope's normal; a sphere's top at each along the normal."""
    from walkerlab.walker.reference_cases import reference_scene

    scene = scene_from_dict(reference_scene("rolling_polygon", "footholds", "osim")[1])
    out = export_stage.write(scene, tmp_path, "osim")
    model = ET.fromstring(out.path.read_text().replace("::", "__")).find("Model")
    c = 2 * L * math.sin(math.pi / N)
    t, nrm = np.array([math.cos(PHI), -math.sin(PHI)]), np.array([math.sin(PHI), math.cos(PHI)])
    heights = (-0.005, 0.005)

    def step(j):
        up = heights[j % 2] * math.cos(PHI)
        return math.sqrt(c * c - up * up) * t + up * nrm
    tops = [-step(-1), np.zeros(2)]
    for j in range(60):
        tops.append(tops[-1] + step(j))
    rg = _lane_checks(model, tops, nrm)
    assert rg == pytest.approx((c / 3) ** 2 / (2 * (0.005 * math.cos(PHI) + 2 * L / 1000)),
                               rel=1e-12)


def test_wheel_osim_refuses_a_profile_in_one_line(tmp_path):
    """The planar wheel on a profile: one line naming the field (the capability table's
    cell, the legs' OpenSim profile refusal), nothing written."""
    from walkerlab.walker.reference_cases import reference_scene

    scene = scene_from_dict(reference_scene("rolling_polygon", "profile", "mjcf")[1])
    with pytest.raises(ValueError) as err:
        export_stage.run(scene, tmp_path, "osim")
    msg = str(err.value)
    assert msg.startswith("terrain.kind: profile") and "\n" not in msg
    assert "polyline" in msg
    assert not any(tmp_path.rglob("*.osim"))


@pytest.mark.slow
@needs_opensim
@pytest.mark.parametrize("name", ["rimless_wheel", "rimless_wheel_3d_disc",
                                  "rimless_wheel_3d_disc_stairs"])
def test_wheel_osim_rolls_in_opensim_within_3_percent(name, tmp_path):
    """OpenSim's Manager rolls the wheel from its default state (walkerlab's loop reading
    each spoke's Hunt-Crossley force): 10 or more spoke strikes, each by the next spoke, no
    fall, the mean step period within 3 % of the rigid gait's (the capability table's
    OpenSim tolerance; measured -0.54 %, -0.11 % and down the stairs, on a sphere per
    footfall, -0.13 %)."""
    from walkerlab.export.engine_walk import walk_export

    out = export_stage.write(load_scene(f"configs/{name}.yaml"), tmp_path, "osim")
    w = walk_export(out.path, "osim", out.step_period_s, 10, tolerance=0.03, spokes=True)
    assert w.walked and not w.fell, w.line
    assert w.strikes >= 10 and w.rolling and w.first_leg == "spoke1", w.line
    assert w.alternating and abs(w.relative) <= 0.03, w.line
