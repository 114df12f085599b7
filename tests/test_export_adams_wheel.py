"""A spoked wheel's Adams dataset (:mod:`walkerlab.export.adams_wheel`), planar
(configs/rimless_wheel.yaml) and 3D (configs/rimless_wheel_3d_disc.yaml), read back by
walkerlab's reader (:mod:`walkerlab.export.adams_reader`) and set against the rigid model at
a state.

References the writer does not compute: the mass and inertias are the scene's numbers; the
spoke tips, the hub and their velocities are the rigid model's generated ``points`` and
``point_velocities`` (in the exports' axes, z up: ``X = x, Y = -z, Z = y``, written out
here); the kinetic energy is the rigid model's ``0.5 dq^T M(q) dq``.  The state is not a
gait (the file's statements are functions of the state): no gait search.  Tolerance 1e-9
(m, m/s, relative): the file writes 17 significant digits in mm and degrees.
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from walkerlab.codegen.cache import functions
from walkerlab.config import load_scene
from walkerlab.export.adams_reader import read_adm
from walkerlab.export.adams_wheel import adm_wheel_text, wheel_start
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
TOL = 1e-9
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
#: states (heading, lean, stance and rates; a planar wheel's stance and rate)
STATES = {"rimless_wheel": [0.3127, -1.0],
          "rimless_wheel_3d_disc": [0.05, 0.03, 0.1927, 0.2, -0.1, -1.9]}
#: the rigid model's point of each of the tree's contact points
POINT = {"next_foot": "swing_foot"}


@pytest.fixture(scope="module", params=list(STATES))
def wheel(request):
    scene = load_scene(ROOT / "configs" / f"{request.param}.yaml")
    data = Plant.from_scene(scene).data
    x = np.asarray(STATES[request.param], float)
    hub = scene.contact.hub_inertia_kg_m2 if scene.contact is not None else None
    start = wheel_start(data, SimpleNamespace(x=x, period_s=1.0), 2, hub)
    text = adm_wheel_text(scene, data, start, "wheel")
    return scene, data, x, read_adm(text), text


def _pad(v):
    v = np.ravel(np.asarray(v, float))
    return C @ np.concatenate([v, np.zeros(3 - v.size)])


def test_a_wheels_dataset_is_one_part_on_the_rigid_spoke_tips(wheel):
    """One PART of the wheel's mass; its CM at the rigid hub moving at its velocity; a
    marker and a sphere of radius L / 1000 on every spoke tip, each at the rigid tip and
    moving as it does (the part's angular velocity), each with a CONTACT on the ground
    box; the stance tip (the pin's marker) at the origin."""
    scene, data, x, model, _text = wheel
    f = functions(data)
    pts = {k: _pad(v) for k, v in f["points"](x).items()}
    vel = {k: _pad(v) for k, v in f["point_velocities"](x).items()}
    assert sorted(model.by_kind["PART"]) == [1, 2]
    assert model.part_mass(2) == pytest.approx(data.total_mass_kg, rel=1e-15)
    cm, _ = model.marker_pose(model.get("PART", 2).integer("CM"))
    np.testing.assert_allclose(cm, pts["hip"], atol=TOL)
    v, w = model.part_velocity(2)
    np.testing.assert_allclose(v, vel["hip"], atol=TOL)
    tips = {}
    for mid, m in model.by_kind["MARKER"].items():
        if 210 <= mid < 300:
            tips[mid] = m
    spokes = data.structure.spokes
    assert len(tips) == spokes
    names = [ln.strip("! ").strip() for ln in _text.splitlines() if ln.startswith("! ") and
             ln.strip("! ").endswith("_foot")]
    assert len(names) == spokes
    r = scene.walker.spoke_length_m / 1000
    for mid, name in zip(sorted(tips), names):
        p, _ = model.marker_pose(mid)
        key = POINT.get(name, name)
        np.testing.assert_allclose(p, pts[key], atol=TOL)
        np.testing.assert_allclose(v + np.cross(w, p - cm), vel[key], atol=TOL)
        g = model.get("GRAPHICS", mid)
        assert "ELLIPSOID" in g.flags and g.number("XSCALE") * model.length == pytest.approx(
            2 * r, rel=1e-15)
    contacts = model.by_kind["CONTACT"].values()
    assert sorted(c.integer("IGEOM") for c in contacts) == sorted(tips)
    assert model.joints()[99][0] == "SPHERICAL"
    np.testing.assert_allclose(model.marker_pose(model.joints()[99][1])[0], 0.0, atol=TOL)


def test_a_wheels_tips_touch_or_clear_the_slope_box(wheel):
    """The ground box's top lies r below the slope's plane through the origin: each tip's
    sphere centre lies r plus the rigid tip's height above the slope over the box's top
    (the stance tip's sphere touches it; the others clear it by their rigid heights)."""
    scene, data, x, model, text = wheel
    phi = data.slope_rad
    normal = np.array([math.sin(phi), 0.0, math.cos(phi)])
    pts = {k: _pad(v) for k, v in functions(data)["points"](x).items()}
    names = [ln.strip("! ").strip() for ln in text.splitlines() if ln.startswith("! ") and
             ln.strip("! ").endswith("_foot")]
    box = model.get("GRAPHICS", 1001)
    o, Rb = model.marker_pose(box.integer("CORNER"))
    size = np.array([box.number(k) for k in "XYZ"]) * model.length
    r = scene.walker.spoke_length_m / 1000
    heights = {}
    for mid in (m for m in model.by_kind["MARKER"] if 210 <= m < 300):
        local = Rb.T @ (model.marker_pose(mid)[0] - o)
        assert 0 < local[0] < size[0] and 0 < local[1] < size[1]
        heights[mid] = local[2] - size[2]
    for mid, name in zip(sorted(heights), names):
        want = r + normal @ pts[POINT.get(name, name)]
        assert heights[mid] == pytest.approx(want, abs=TOL), name
    assert heights[210] == pytest.approx(r, abs=TOL)


def test_a_wheels_inertia_and_kinetic_energy_are_the_rigid_models(wheel):
    """The 3D wheel's inertia is the scene's (I_hub about the axle, I_diam across it) and
    its kinetic energy the rigid model's 0.5 dq^T M(q) dq; the planar wheel's point-mass
    hub carries contact.hub_inertia_kg_m2 about the axle (the MJCF's), so its energy is the
    rigid one plus 0.5 I w^2 (relative 1e-9), and a PLANAR joint keeps it in the x-z
    plane (both markers' z along y)."""
    scene, data, x, model, _text = wheel
    f = functions(data)
    n = x.size // 2
    M = np.asarray(f["matrices"](x)[0], float).reshape(n, n)
    want = 0.5 * x[n:] @ M @ x[n:]
    v, w = model.part_velocity(2)
    J = model.part_inertia(2)
    got = 0.5 * model.part_mass(2) * v @ v + 0.5 * w @ J @ w
    pts = {k: _pad(val) for k, val in f["points"](x).items()}
    if data.structure.in_3d:
        axle = pts["axle_tip"] - pts["hip"]
        axle /= np.linalg.norm(axle)
        wl = scene.walker
        np.testing.assert_allclose(J, wl.diametral_inertia_kg_m2 * (np.eye(3) - np.outer(
            axle, axle)) + wl.hub_inertia_kg_m2 * np.outer(axle, axle), atol=1e-12)
        assert got == pytest.approx(want, rel=TOL)
        assert 98 not in model.joints()
        return
    hub = scene.contact.hub_inertia_kg_m2
    assert J[1, 1] == pytest.approx(hub, rel=1e-15)
    assert got == pytest.approx(want + 0.5 * hub * x[1] ** 2, rel=TOL)
    kind, i, j = model.joints()[98]
    assert kind == "PLANAR"
    for m in (i, j):
        assert abs(model.marker_pose(m)[1][:, 2] @ np.array([0.0, 1.0, 0.0]) - 1) < TOL


def _ground_case(feature):
    """The planar wheel's reference case on ``feature``'s ground (its scene, the dataset at
    the shipped wheel's state read back, the rigid points)."""
    from walkerlab.config import scene_from_dict
    from walkerlab.walker.reference_cases import reference_scene

    _case, d = reference_scene("rolling_polygon", feature, "adams")
    scene = scene_from_dict(d)
    data = Plant.from_scene(scene).data
    x = np.asarray(STATES["rimless_wheel"], float)
    start = wheel_start(data, SimpleNamespace(x=x, period_s=1.0), 2,
                        scene.contact.hub_inertia_kg_m2, scene.terrain)
    model = read_adm(adm_wheel_text(scene, data, start, "wheel"))
    pts = {k: _pad(v) for k, v in functions(data)["points"](x).items()}
    return scene, data, model, pts


def _under(model, p):
    """The ground box under the point ``p`` (3,) [m]: ``p``'s height above its top [m]."""
    for g in model.by_kind["GRAPHICS"].values():
        if "BOX" not in g.flags:
            continue
        o, R = model.marker_pose(g.integer("CORNER"))
        size = np.array([g.number(k) for k in "XYZ"]) * model.length
        local = R.T @ (p - o)
        if 0 <= local[0] <= size[0] and 0 <= local[1] <= size[1] and local[2] > 0:
            return local[2] - size[2]
    raise AssertionError(f"no box under {p}")


def test_a_wheel_on_stairs_stands_its_stance_tip_on_tread_0():
    """Stairs (the generated case): a box per tread, tread 0 (``tread_m`` deep, its middle
    at the stance tip) its top r below height 0, the next one ``riser_m`` lower; the stance
    tip's sphere touches it (its centre r above the top), every CONTACT of a tip on a box."""
    scene, _data, model, pts = _ground_case("stairs")
    t = scene.terrain
    r = scene.walker.spoke_length_m / 1000
    assert _under(model, pts["stance_foot"]) == pytest.approx(r, abs=TOL)
    ahead = np.array([0.5 * t.tread_m + 1e-3, 0.0, -t.riser_m + 1e-3])  # on tread 1
    assert _under(model, ahead) == pytest.approx(r + 1e-3, abs=TOL)
    boxes = [g for g, s in model.by_kind["GRAPHICS"].items() if "BOX" in s.flags]
    assert len(model.by_kind["CONTACT"]) == len(boxes) * scene.walker.spokes


def test_a_wheel_on_its_slope_as_a_profile_has_the_slopes_ground():
    """A profile (the generated case: the slope itself as a profile): a box per segment,
    each tip's sphere centre r plus its rigid height above the slope over the box under
    it, as on the slope."""
    scene, data, model, pts = _ground_case("profile")
    r = scene.walker.spoke_length_m / 1000
    phi = data.slope_rad
    normal = np.array([math.sin(phi), 0.0, math.cos(phi)])
    for name in ("stance_foot", "swing_foot", "trailing_foot", "spoke2_foot"):
        assert _under(model, pts[name]) == pytest.approx(r + normal @ pts[name], abs=TOL)
