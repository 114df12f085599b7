"""A planar walker's export bodies read from its body tree
(:func:`walkerlab.export.planar_bodies.planar_bodies`: :func:`walkerlab.walker.trees.
legs_tree` through :func:`walkerlab.export.tree_bodies.export_bodies`) against the walker's
links (:func:`walkerlab.walker.multibody.multibody`: each leg segment's bodies summed by the
parallel-axis theorem along the leg, no tree, no sympy), which the exports wrote before the
tree did: the same bodies in the same order, on the same joints (names, axes, the locking
knee's stop), at the same places, with the same masses, centres of mass and inertias, and
each foot where the links put it.  Tolerance 1e-15 of the leg length, mass and largest
moment: the tree's expressions are evaluated from the same numbers (round-off only; the
shipped scenes' files compare equal).

Flat feet (the tree's soles, :func:`walkerlab.walker.trees.legs_tree`) against the scene's
numbers: each sole on its ankle hinge at its leg's end, with the foot's mass (the walker's,
or for massless feet the contact model's regularising one), and the tree's heel, toe and
ankle points where the sole's geometry puts them."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from walkerlab.codegen.tree_derive import kinematics
from walkerlab.config import load_scene
from walkerlab.export.parts import export_part
from walkerlab.export.planar_bodies import planar_bodies
from walkerlab.export.scene_feet import flat_foot_bodies
from walkerlab.export.tree_bodies import ExportBody, ExportJoint
from walkerlab.walker.description import walker_data
from walkerlab.walker.multibody import multibody
from walkerlab.walker.trees import legs_tree

ROOT = Path(__file__).resolve().parents[1]


#: the planar hinges' axis (world -y: a positive angle moves the foot ahead)
PITCH = (0.0, -1.0, 0.0)


def _link_bodies(mb):
    """The links of ``mb`` as the exports wrote them before the tree: each link on its
    hinge about ``0 -1 0`` (a knee with a stop in ``[-pi, 0]``), its moment about the pitch
    axis (and about x), its foot a massless body on a fixed joint."""
    stops = export_part(mb).knee_stops

    def body(ln):
        kids = [body(k) for k in mb.links if k.parent == ln.name]
        if ln.foot_m is not None:
            leg = ln.name.split("_")[0]
            kids.append(ExportBody(f"{leg}_foot", "foot", np.array([0.0, 0.0, -ln.foot_m]),
                                   (ExportJoint(f"{leg}_foot", "fixed"),), 0.0, np.zeros(3),
                                   np.zeros((3, 3))))
        limit = (-math.pi, 0.0) if stops and ln.joint.endswith("_knee") else None
        return ExportBody(ln.name, ln.name, np.array([0.0, 0.0, -ln.joint_from_parent_m]),
                          (ExportJoint(ln.joint, "hinge", PITCH, limit=limit),),
                          ln.mass_kg, np.array([ln.com_off_axis_m, 0.0, -ln.com_m]),
                          np.diag([ln.inertia_kg_m2, ln.inertia_kg_m2, 0.0]), tuple(kids))
    slides = (ExportJoint("hip_x", "slide", (1.0, 0.0, 0.0)),
              ExportJoint("hip_z", "slide", (0.0, 0.0, 1.0)))
    return ExportBody("hip", "pelvis", np.zeros(3), slides, mb.hip_mass_kg, np.zeros(3),
                      np.zeros((3, 3)), tuple(body(ln) for ln in mb.links
                                              if ln.parent == "hip"))


def _pairs(a, b):
    """The two body trees' bodies side by side, parents first (their shapes the same)."""
    assert [c.name for c in a.children] == [c.name for c in b.children], a.name
    yield a, b
    for x, y in zip(a.children, b.children):
        yield from _pairs(x, y)


@pytest.mark.parametrize("scene", [
    "paper", "paper_rods", "asymmetric_legs", "kneed", "round_feet", "torso_bhm",
    "hip_spring", "threelink", "rabbit",
])
def test_a_planar_walkers_tree_bodies_are_its_links(scene):
    sc = load_scene(ROOT / "configs" / f"{scene}.yaml")
    data = walker_data(sc.walker, sc.slope.phi_rad)
    mb = multibody(data)
    tree, couplings = planar_bodies(data)
    links = _link_bodies(mb)
    L, scale = mb.leg_length_m, max(b.mass_kg for b in links.walk())
    moment = max(float(np.abs(b.inertia_kg_m2).max()) for b in links.walk()) or 1.0
    for x, y in _pairs(tree, links):
        assert [(j.name, j.kind, j.limit) for j in x.joints] == [
            (j.name, j.kind, j.limit) for j in y.joints], x.name
        for jx, jy in zip(x.joints, y.joints):
            np.testing.assert_allclose(jx.axis, jy.axis, rtol=0, atol=1e-15)
        np.testing.assert_allclose(x.pos_m, y.pos_m, rtol=0, atol=1e-15 * L)
        assert abs(x.mass_kg - y.mass_kg) <= 1e-15 * scale, x.name
        np.testing.assert_allclose(x.com_m, y.com_m, rtol=0, atol=1e-15 * L)
        np.testing.assert_allclose(x.inertia_kg_m2, y.inertia_kg_m2, rtol=0,
                                   atol=1e-15 * moment)
    # the bisecting hip: the torso's hinge at the legs' mean; no other coupling
    assert [c.terms for c in couplings] == (
        [(("torso_hip", 2), ("leg1_hip", -1), ("leg2_hip", -1))] if mb.couplings else [])


def _scene_data(scene):
    sc = load_scene(ROOT / "configs" / f"{scene}.yaml")
    return sc, walker_data(sc.walker, sc.slope.phi_rad)


@pytest.mark.parametrize("scene", ["flat_feet", "flat_feet_foot_mass"])
def test_flat_feet_export_bodies_are_soles_on_ankles_with_the_scenes_foot_mass(scene):
    """Each leg (``hip`` on ``hip_x``, ``hip_z``): its hinge ``leg<i>_hip``, its mass
    ``m_mass`` at ``d_mass`` below the hip, the site ``leg<i>_foot`` and the sole
    ``leg<i>_sole`` on the hinge ``leg<i>_ankle`` about the pitch axis at the leg's end
    ``L``, its angle the swing foot's ``swing_ankle`` (leg2: ``stance_ankle``), the foot's
    mass at the ankle: the walker's ``walker.leg.foot.mass_kg`` and inertia about the ankle
    (about the pitch axis and along the sole; none about the leg), massless feet mass 0 in
    the tree and the contact model's regularising mass and inertia with the scene's feet;
    no coupling."""
    sc, data = _scene_data(scene)
    w, foot = sc.walker, sc.walker.leg.foot
    L, body = w.leg.length_m, w.leg.bodies[0]
    own = (foot.mass_kg or 0.0, foot.inertia_about_ankle_kg_m2 or 0.0)
    scene_feet = flat_foot_bodies(sc, data)
    for feet, (mass, moment) in ((None, own), (scene_feet, scene_feet[0][5:])):
        hip, couplings = planar_bodies(data, 0.0, feet)
        assert couplings == ()
        assert [(j.name, j.kind) for j in hip.joints] == [("hip_x", "slide"),
                                                          ("hip_z", "slide")]
        assert hip.mass_kg == w.hip_mass_kg
        for leg, ankle_angle in zip(hip.children, ("swing_ankle", "stance_ankle")):
            name = leg.name
            assert [(j.name, j.kind, j.axis) for j in leg.joints] == [
                (f"{name}_hip", "hinge", PITCH)]
            assert leg.mass_kg == body.mass_kg
            np.testing.assert_array_equal(leg.com_m, [0.0, 0.0, -body.from_hip_m])
            kids = {c.name: c for c in leg.children}
            assert sorted(kids) == [f"{name}_foot", f"{name}_sole"]
            site, sole = kids[f"{name}_foot"], kids[f"{name}_sole"]
            np.testing.assert_array_equal(site.pos_m, [0.0, 0.0, -L])
            assert [j.kind for j in site.joints] == ["fixed"] and site.mass_kg == 0
            np.testing.assert_array_equal(sole.pos_m, [0.0, 0.0, -L])
            (j,) = sole.joints
            assert (j.name, j.kind, j.axis, j.limit) == (f"{name}_ankle", "hinge", PITCH,
                                                         None)
            assert str(j.angle) == f"q_{ankle_angle}"
            assert sole.mass_kg == mass and not sole.com_m.any() and not sole.children
            np.testing.assert_array_equal(sole.inertia_kg_m2, np.diag([moment, moment, 0.0]))


def test_a_flat_footed_trees_heel_toe_and_ankles_are_the_soles_geometry():
    """The tree's points at a pose (the stance foot flat on the slope: ``stance_ankle =
    -(stance + gamma)``) against the sole's geometry in the slope's frame, from the stance
    heel (the root): the stance toe ``heel + toe`` down the slope, the stance ankle
    ``heel`` down it, the hip ``L`` up the stance leg (its angle ``stance + gamma`` from the
    slope's normal), the swing ankle ``L`` down the swing leg, the swing heel ``heel``
    behind and the toe ``toe`` ahead of it along the swing sole (its angle ``swing +
    swing_ankle + gamma`` from the slope); exact (sympy, then 1e-15 m of round-off)."""
    sc, data = _scene_data("flat_feet_foot_mass")
    tree, coords = legs_tree(data.structure)
    assert tree.root.stance_contact == "stance_heel"
    kin = kinematics(tree, coords)
    P = dict(zip(data.structure.param_names, data.params))
    g, L, heel, toe = P["gamma"], P["L"], P["heel_m"], P["toe_m"]
    swing, stance, swing_ankle = 0.3, -0.2, 0.15
    at = dict(zip(kin.q, (swing, stance, -(stance + g), swing_ankle)))
    at.update(zip(kin.params, data.params))

    def point(name):
        return np.array(sp.Matrix(kin.contacts[name]).subs(at).evalf(), float).ravel()

    def turn(angle, v):
        c, s = math.cos(angle), math.sin(angle)
        return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1], 0.0])

    ankle = np.array([heel, 0.0, 0.0])
    hip = ankle + turn(stance + g, (0.0, L))
    swing_ankle_at = hip + turn(swing + g, (0.0, -L))
    sole = swing + swing_ankle + g
    expected = {"stance_heel": np.zeros(3), "stance_toe": np.array([heel + toe, 0.0, 0.0]),
                "swing_ankle": swing_ankle_at,
                "swing_heel": swing_ankle_at + turn(sole, (-heel, 0.0)),
                "swing_toe": swing_ankle_at + turn(sole, (toe, 0.0))}
    for name, want in expected.items():
        np.testing.assert_allclose(point(name), want, rtol=0, atol=1e-15 * L, err_msg=name)
    np.testing.assert_allclose(np.array(sp.Matrix(kin.origins["pelvis"]).subs(at).evalf(),
                                        float).ravel(), hip, rtol=0, atol=1e-15 * L)
    assert sp.simplify(kin.masses["swing_sole"] - kin.params[list(
        map(str, kin.params)).index("m_foot")]) == 0
