"""Round feet and leg inertia in a 3D walker's Adams dataset (:mod:`walkerlab.export.adams_3d`,
configs/round_feet_3d.yaml's walker), read back by walkerlab's reader
(:mod:`walkerlab.export.adams_reader`) and set against the rigid model at a state.

References the writer does not compute: the masses and the rod inertia are the scene's
numbers; the discs' centres and the contact points are the rigid model's generated
``points`` (``stance_foot_centre``, ``stance_contact``, ...; in the exports' axes, z up:
``X = x, Y = -z, Z = y``, written out here); the kinetic energy is the rigid model's
``0.5 dq^T M(q) dq``.  The state is not a gait (the file's statements are functions of the
state; a lean and rates all nonzero so that no term vanishes): no gait search.  Tolerance
1e-9 (m, relative): the file writes 17 significant digits in mm and degrees.
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from walkerlab.codegen.cache import functions
from walkerlab.config import load_scene
from walkerlab.export.adams_3d import adams3d_start, adm3d_text
from walkerlab.export.adams_reader import read_adm
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
TOL = 1e-9
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
FLOOR = 1e-12  # kg m^2: the export's moment of a rod about its own axis


@pytest.fixture(scope="module")
def round_feet():
    scene = load_scene(ROOT / "configs" / "round_feet_3d.yaml")
    plant = Plant.from_scene(scene)
    data = plant.data
    x = np.array([0.02, -0.19947, 0.17947, -0.05, -0.185, -0.239])
    start = adams3d_start(plant, SimpleNamespace(x=x, period_s=2.0, step_lengths_m=(0.4,)), 2)
    text = adm3d_text(scene, data, start, "walker")
    return scene, data, x, read_adm(text), text


def test_round_feet_datasets_masses_and_rod_inertia_are_the_scenes(round_feet):
    """Each leg part carries 0.5 kg and the rod's 0.02 kg m^2 about every axis across the
    leg (the rigid leg's direction from its hip to its disc centre), the export's floor
    along it; the hip 1 kg; the total the walker's."""
    scene, data, x, model, _text = round_feet
    pts = {k: C @ np.ravel(v) for k, v in functions(data)["points"](x).items()}
    w = scene.walker
    assert model.part_mass(2) == pytest.approx(w.hip_mass_kg, rel=1e-15)
    for pid, leg in ((3, "swing"), (4, "stance")):
        assert model.part_mass(pid) == pytest.approx(w.leg_mass_kg, rel=1e-15)
        e = pts[f"{leg}_foot_centre"] - pts[f"{leg}_hip"]
        e = e / np.linalg.norm(e)
        want = w.leg_inertia_kg_m2 * (np.eye(3) - np.outer(e, e)) + FLOOR * np.outer(e, e)
        np.testing.assert_allclose(model.part_inertia(pid), want, atol=TOL * w.leg_inertia_kg_m2)
    total = sum(model.part_mass(p) for p in model.by_kind["PART"] if p != 1)
    assert total == pytest.approx(data.total_mass_kg, rel=1e-15)


def test_round_feet_datasets_kinetic_energy_is_the_rigid_models(round_feet):
    """0.5 sum(m v^2 + w^T I w) over the parts (rod inertia included) equals the rigid
    model's 0.5 dq^T M(q) dq at the state (relative 1e-9)."""
    _scene, data, x, model, _text = round_feet
    n = x.size // 2
    M = np.asarray(functions(data)["matrices"](x)[0], float).reshape(n, n)
    want = 0.5 * x[n:] @ M @ x[n:]
    got = 0.0
    for pid in (p for p in model.by_kind["PART"] if p != 1):
        v, w = model.part_velocity(pid)
        got += 0.5 * model.part_mass(pid) * v @ v + 0.5 * w @ model.part_inertia(pid) @ w
    assert got == pytest.approx(want, rel=TOL)


def test_round_feet_are_discs_about_the_pitch_axes_on_the_rigid_centres(round_feet):
    """Each foot is a GRAPHICS/CYLINDER of the scene's radius about its leg's pitch axis
    (Rot(s, lean) z: the legs roll with the lean), its middle at the rigid disc centre; the
    stance disc touches its patch where the rigid disc touches the slope (the contact
    point's depth 0, the centre R cos(lean) above the patch top), the pin's ground marker at its
    centre; every CONTACT's IGEOM is a disc."""
    scene, data, x, model, _text = round_feet
    pts = {k: C @ np.ravel(v) for k, v in functions(data)["points"](x).items()}
    R = scene.walker.foot_radius_m
    phi = data.slope_rad
    fall = np.array([math.cos(phi), -math.sin(phi), 0.0])
    K = np.array([[0, -fall[2], fall[1]], [fall[2], 0, -fall[0]], [-fall[1], fall[0], 0]])
    rot = np.eye(3) + math.sin(x[0]) * K + (1 - math.cos(x[0])) * K @ K
    axis = C @ rot @ np.array([0.0, 0.0, 1.0])
    for gid, leg in ((303, "swing"), (403, "stance")):
        g = model.get("GRAPHICS", gid)
        assert "CYLINDER" in g.flags
        assert g.number("RADIUS") * model.length == pytest.approx(R, rel=1e-15)
        base, Rb = model.marker_pose(g.integer("CM"))
        assert abs(abs(Rb[:, 2] @ axis) - 1) < TOL
        middle = base + Rb[:, 2] * g.number("LENGTH") * model.length / 2
        np.testing.assert_allclose(middle, pts[f"{leg}_foot_centre"], atol=TOL)
        np.testing.assert_allclose(model.marker_pose(gid)[0], middle, atol=TOL)
    assert {c.integer("IGEOM") for c in model.by_kind["CONTACT"].values()} == {303, 403}
    np.testing.assert_allclose(model.marker_pose(102)[0], pts["stance_foot_centre"], atol=TOL)
    centre, contact = pts["stance_foot_centre"], pts["stance_contact"]
    depths = []
    for c in model.by_kind["CONTACT"].values():
        if c.integer("IGEOM") != 403:
            continue
        box = model.get("GRAPHICS", c.integer("JGEOM"))
        o, Rp = model.marker_pose(box.integer("CORNER"))
        size = np.array([box.number(k) for k in "XYZ"]) * model.length
        local = Rp.T @ (contact - o)
        if 0 <= local[0] <= size[0] and 0 <= local[1] <= size[1]:
            depths.append((local[2] - size[2], (Rp.T @ (centre - o))[2] - size[2]))
    assert len(depths) == 1   # the disc, rolled by the lean about the fall line, has its
    # lowest point R cos(lean) below its centre along the slope's normal
    assert depths[0] == pytest.approx((0.0, R * math.cos(x[0])), abs=TOL)
