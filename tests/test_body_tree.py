"""The body tree (walkerlab.walker.tree) and its one Lagrangian derivation
(walkerlab.codegen.tree_derive): the 3D straight-legged walker written as a tree has the
equations of today's hand derivation (derive_3d.derive_compass: mass matrix, Coriolis and
gravity terms, the heel strike's impact matrices, the named points), and a tree whose axes
are all the slope's z is the planar compass gait (codegen.symbolic).  Compared numerically at
random states and parameters: both sides are sympy expressions of the same symbols, so
agreement to round-off (1e-12 relative) means the same equations."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from walkerlab.codegen.tree_derive import derive_tree, tree_impact
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.walker.plant import Plant
from walkerlab.walker.tree import ROOT, Body, BodyTree, Joint, Point, compass_3d_tree

ROOT_DIR = Path(__file__).resolve().parents[1]
CONFIGS = ROOT_DIR / "configs"
#: agreement of two derivations of the same equations: round-off of O(10) operations
TOL = 1e-12


def _rel(a, b):
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(a)), 1e-300))


def _compare(ref, eq, Mi, B, params, rng, extra_G=None):
    """Largest relative difference of M, C, G, Mi, B, the swing foot and the hip at 5
    random states (coordinates matched by name; the reference's points in world axes)."""
    names = [str(s) for s in ref.q]
    perm = [[str(s) for s in eq.q].index(n) for n in names]
    inv = np.argsort(perm)
    G = ref.G if extra_G is None else ref.G + extra_G(ref)
    rsy = list(ref.q) + list(ref.dq) + list(ref.params)
    tsy = list(eq.q) + list(eq.dq) + list(eq.params.values())
    pairs = [(ref.M, eq.M), (ref.C, eq.C), (ref.Mi, Mi), (ref.B, B), (G, eq.G)]
    g = params["gamma"]
    to_world = sp.Matrix([[sp.cos(g), sp.sin(g), 0], [-sp.sin(g), sp.cos(g), 0], [0, 0, 1]])
    pairs += [(ref.points[p], to_world * eq.points[p]) for p in ("swing_foot", "hip")]
    fr = sp.lambdify(rsy, [a for a, _ in pairs], "numpy")
    ft = sp.lambdify(tsy, [b for _, b in pairs], "numpy")
    worst = 0.0
    for _ in range(5):
        qv, dqv = rng.normal(0, 0.4, len(names)), rng.normal(0, 1.0, len(names))
        rva = list(qv) + list(dqv) + [params[str(s)] for s in ref.params]
        tva = list(qv[inv]) + list(dqv[inv]) + [params[n] for n in eq.params]
        for k, (a, b) in enumerate(zip(fr(*rva), ft(*tva))):
            a, b = np.array(a, float), np.array(b, float)
            if k < 4:  # matrices in the coordinates: the tree's reordered
                b = b[np.ix_(perm, perm)]
            elif k == 4:
                a, b = a.ravel(), b.ravel()[perm]
            worst = max(worst, _rel(a.ravel(), b.ravel()))
    return worst


def _params(ref, rng):
    p = {str(s): v for s, v in zip(ref.params, rng.uniform(0.2, 1.2, len(ref.params)))}
    p.update(g=9.81, L=1.0, gamma=0.03)
    if "a_leg" in p:
        p["a_leg"] = 0.4
    return p


def _structure(scene):
    return Plant.from_scene(scene).structure


@pytest.mark.slow  # two symbolic derivations and their Coriolis terms (~15 s unloaded)
@pytest.mark.parametrize("leg_rod", [False, True])
def test_the_3d_compass_from_its_body_tree_has_the_hand_derivations_equations(leg_rod):
    """hip_width.yaml's walker (point masses; and each leg a slender rod about its mass
    point, I_leg): M, C, G, the impact's Mi and B, the swing foot and the hip."""
    from walkerlab.codegen.derive_3d import derive_compass

    d = load_scene(CONFIGS / "hip_width.yaml").model_dump(mode="json", exclude_none=True)
    if leg_rod:
        d["walker"]["leg_inertia_kg_m2"] = 0.02
    ref = derive_compass(_structure(scene_from_dict(d)))
    eq = derive_tree(compass_3d_tree(leg_rod=leg_rod))
    Mi, B = tree_impact(eq, "swing_foot")
    rng = np.random.default_rng(3)
    assert _compare(ref, eq, Mi, B, _params(ref, rng), rng) < TOL


@pytest.mark.slow  # the hip-roll walker's hand derivation and its tree's (~1 min each)
def test_the_hip_roll_walker_from_its_body_tree_has_the_hand_derivations_equations():
    """hip_width_stabilised.yaml's walker (hip-roll joints, the pelvis' inertia about the
    fall line): the same equations, its G without the lateral foot-placement law's forces
    (a controller, not the tree's: derive_compass subtracts them)."""
    from walkerlab.codegen.derive_3d import _hip_roll_forces, derive_compass

    ref = derive_compass(_structure(load_scene(CONFIGS / "hip_width_stabilised.yaml")))
    eq = derive_tree(compass_3d_tree(hip_roll=True))
    Mi, B = tree_impact(eq, "swing_foot")
    rng = np.random.default_rng(5)

    def law(r):
        return _hip_roll_forces(r.q, r.dq, {str(s): s for s in r.params})
    assert _compare(ref, eq, Mi, B, _params(ref, rng), rng, law) < TOL


def _planar_compass_tree() -> BodyTree:
    """The paper's compass gait (Table 1: hip mass, a point mass on each leg at d_mass from
    the hip) as a tree whose every axis is z."""
    z = (0.0, 0.0, 1.0)
    bodies = (Body("stance_leg", "m_mass", (0.0, "L - d_mass", 0.0)), Body("hip", "M_hip"),
              Body("swing_leg", "m_mass", (0.0, "-d_mass", 0.0)))
    joints = (Joint("ankle", ROOT, "stance_leg", rotations=((z, "q_stance + gamma"),)),
              Joint("stance_hip", "stance_leg", "hip", (0.0, "L", 0.0),
                    ((z, "-(q_stance + gamma)"),)),
              Joint("swing_hip", "hip", "swing_leg", rotations=((z, "q_swing + gamma"),)))
    points = (Point("hip", "hip"), Point("swing_foot", "swing_leg", (0.0, "-L", 0.0)))
    return BodyTree(("q_swing", "q_stance"), ("g", "L", "gamma", "M_hip", "m_mass", "d_mass"),
                    bodies, joints, points)


def test_a_tree_whose_axes_are_all_z_is_the_planar_compass_gait():
    """The planar generator's (codegen.symbolic) compass gait of configs/paper.yaml: the
    same M, C, G, impact and points (its points in the plane, z = 0)."""
    from walkerlab.codegen.cache import derive_equations

    ref = derive_equations(_structure(load_scene(CONFIGS / "paper.yaml")))
    eq = derive_tree(_planar_compass_tree())
    Mi, B = tree_impact(eq, "swing_foot")

    class Planar:  # the reference's points with z = 0
        q, dq, params, M, C, G, Mi, B = (ref.q, ref.dq, ref.params, ref.M, ref.C, ref.G,
                                          ref.Mi, ref.B)
        points = {k: sp.Matrix([*ref.points[k], 0]) for k in ("swing_foot", "hip")}
    rng = np.random.default_rng(7)
    params = {"g": 9.81, "L": 1.0, "gamma": 0.0174, "M_hip": 10.0, "m_mass": 5.0,
              "d_mass": 0.5}
    assert _compare(Planar, eq, Mi, B, params, rng) < TOL


@pytest.mark.parametrize("tree, says", [
    (lambda: BodyTree(("q",), ("g", "gamma"), (Body("a", 1.0),),
                      (Joint("j", "b", "a"),)), "joint j: parent 'b' is not placed"),
    (lambda: BodyTree(("q",), ("g", "gamma"), (Body("a", 1.0),), ()), "body a: no joint"),
    (lambda: BodyTree(("q",), ("g", "gamma"),
                      (Body("a", 1.0, inertia=((1, 2, 0), (0, 1, 0), (0, 0, 1))),),
                      (Joint("j", ROOT, "a"),)), "body a: inertia must be a symmetric 3x3"),
])
def test_a_malformed_tree_is_refused_naming_the_part(tree, says):
    with pytest.raises(ValueError, match=says):
        tree()
