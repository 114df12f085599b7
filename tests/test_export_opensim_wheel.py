"""``walkerlab export --format osim`` of the planar spoked wheel (configs/rimless_wheel.yaml:
Drake's RimlessWheel defaults, mass 1 kg, spoke 1 m, 8 spokes, slope 0.08 rad), its file's
numbers checked against the scene here (no walkerlab export code), and its walk in OpenSim
(skips without the ``osim`` extra).  Measured (OpenSim 4.6, CPodes): 11 spoke strikes, each
by the next spoke, in 11.69 s, mean step period 1.02895 s against the rigid gait's
1.03455 s (-0.54 %).
"""

from __future__ import annotations

import importlib.util
import math
import xml.etree.ElementTree as ET

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


@pytest.mark.parametrize("scene, field", [
    ("configs/rimless_wheel_3d_disc.yaml", "walker.space: 3d"),
    ({}, "terrain.kind: stairs")])
def test_wheel_osim_refuses_the_3d_wheel_and_other_grounds_in_one_line(scene, field,
                                                                       tmp_path):
    """The 3D wheel and the planar wheel on stairs: one line naming the field (the
    capability table's cells), nothing written."""
    if isinstance(scene, dict):  # the capability table's reference case of the cell
        from walkerlab.walker.reference_cases import reference_scene

        scene = scene_from_dict(reference_scene("rolling_polygon", "stairs", "osim")[1])
    else:
        scene = load_scene(scene)
    with pytest.raises(ValueError) as err:
        export_stage.run(scene, tmp_path, "osim")
    msg = str(err.value)
    assert msg.startswith(field) and "\n" not in msg
    assert not any(tmp_path.rglob("*.osim"))


@pytest.mark.slow
@needs_opensim
def test_wheel_osim_rolls_in_opensim_within_3_percent(wheel_osim):
    """OpenSim's Manager rolls the wheel from its default state (walkerlab's loop reading
    each spoke's Hunt-Crossley force): 10 or more spoke strikes, each by the next spoke, no
    fall, the mean step period within 3 % of the rigid gait's (the capability table's
    OpenSim tolerance; measured -0.54 %)."""
    from walkerlab.export.engine_walk import walk_export

    out, _ = wheel_osim
    w = walk_export(out.path, "osim", out.step_period_s, 10, tolerance=0.03, spokes=True)
    assert w.walked and not w.fell, w.line
    assert w.strikes >= 10 and w.rolling and w.first_leg == "spoke1", w.line
    assert w.alternating and abs(w.relative) <= 0.03, w.line
