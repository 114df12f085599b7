"""The planar walkers as body trees, the special case of the 3D biped's
(:func:`walkerlab.walker.trees.legs_tree`: every joint a pitch about ``z``): Lagrange's
equations derived from the tree (:func:`walkerlab.codegen.tree_derive.derive_tree`) equal
the planar derivation by sums of leg vectors (``tests/independent/planar_link_sums.py``,
which shares no kinematics with the tree) for the shipped planar walkers' structures:
the mass matrix, the Coriolis and centrifugal terms, gravity, the potential, and the rates
after the heel strike (Goswami, Thuilot & Espiau 1996; McGeer 1990 for the knee and the round
feet; Wisse, Hobbelen & Schwab 2007 for the bisecting hip), numerically at random states and
parameters; the walkers whose joints are all free (the five-link biped, Westervelt, Grizzle &
Koditschek 2003, free knees on both legs; the three-link walker, Grizzle, Abba & Plestan
2001; each with a hinged torso) equal :func:`walkerlab.codegen.free_joints.
derive_five_link`'s; flat feet (Wisse et al. 2006) with foot mass, in heel contact and foot
flat, equal the leg-vector sums' modes (``tests/independent/flat_feet_link_sums.py``, from
the pinned heel) with the ankle spring and damper added.  The 3D trees the same builder makes
are the production derivation's (``tests/test_body_tree.py``)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import sympy as sp

from tests.independent.flat_feet_link_sums import derive_flat
from tests.independent.free_joints_link_sums import derive_five_link
from tests.independent.planar_link_sums import derive
from tests.test_body_tree import _close  # the same comparison (1e-12 relative)
from walkerlab.codegen.tree_derive import (
    derive_tree,
    kinematics,
    mass_and_potential,
    plastic_impact,
    simplifier,
)
from walkerlab.config import load_scene
from walkerlab.walker.description import BodySpec, Structure
from walkerlab.walker.plant import Plant
from walkerlab.walker.tree import CoordinateMap
from walkerlab.walker.trees import legs_tree


def _params(names: list[str], rng) -> dict:
    """Random physical parameters by name: a knee between the hip and the foot, each thigh
    body above it and each shank body below it, springs off (the tree carries bodies and
    joints, not the springs' potential)."""
    L = rng.uniform(0.7, 1.3)
    thigh = rng.uniform(0.35, 0.6) * L
    out = {}
    for n in names:
        if n in ("L", "L_thigh"):
            v = L if n == "L" else thigh
        elif n == "g":
            v = rng.uniform(9.0, 10.5)
        elif n == "gamma":
            v = rng.uniform(-0.1, 0.2)
        elif n.startswith(("m_", "M_")):
            v = rng.uniform(0.5, 8.0)
        elif n.startswith("I_"):
            v = rng.uniform(0.01, 0.5)
        elif n.startswith("e_"):
            v = rng.uniform(-0.1, 0.1)
        elif n.startswith("d_torso"):
            v = rng.uniform(0.1, 0.6)
        elif n.startswith("d_"):
            v = rng.uniform(thigh + 0.01, L) if "shank" in n else rng.uniform(0.05, thigh)
        elif n == "R_foot":
            v = rng.uniform(0.05, 0.3) * L
        elif n.startswith(("k_", "c_", "r_")):
            v = 0.0
        else:
            raise KeyError(n)
        out[n] = v
    return out


def _swing_contact_jacobian(te, structure: Structure) -> sp.Matrix:
    """The velocity Jacobian of the swing foot's material contact point: a point foot's, or
    a round foot's lowest point plus ``R`` times its leg's pitch rate along the slope (the
    disc's material point ``v_centre + omega x (-R n)``)."""
    kin, q = te.kinematics, sp.Matrix(te.q)
    if structure.foot != "arc":
        return kin.contacts["swing_foot"].jacobian(q)
    P = dict(zip(map(str, te.params), te.params))
    swing = te.q[list(structure.roles).index("swing")]
    lowest = kin.contacts["swing_foot_centre"] - P["R_foot"] * sp.Matrix([0, 1, 0])
    return lowest.jacobian(q) + P["R_foot"] * sp.Matrix([1, 0, 0]) * sp.Matrix(
        [[sp.diff(swing, k) for k in te.q]])


def _scene_structure(name: str) -> Structure:
    return Plant.from_scene(load_scene(f"configs/{name}.yaml")).data.structure


def _agree(structure: Structure, seed: int) -> None:
    free = structure.free_knees or structure.hinged_torso   # every joint free
    e = derive_five_link(structure) if free else derive(structure)
    tree, coords = legs_tree(structure)
    te = derive_tree(tree, coords)
    assert tuple(map(str, te.q)) == tuple(map(str, e.q))
    assert tuple(map(str, te.params)) == tuple(map(str, e.params))
    dq = sp.Matrix(e.dq)
    pairs = [("M", e.M, te.M), ("C dq", e.C * dq, te.C * dq), ("G", e.G, te.G),
             ("V", sp.Matrix([e.potential]), sp.Matrix([te.potential]))]
    if free or not structure.knee:   # the kneed heel strike holds the knee: the locked system
        Mi, B = plastic_impact(te.M, te.A, te.total_mass,
                               _swing_contact_jacobian(te, structure),
                               simplifier(te.kinematics))
        pairs.append(("rates after the heel strike", e.Mi.LUsolve(e.B * dq),
                      Mi.LUsolve(B * dq)))
    args = list(e.q) + list(e.dq) + list(e.params)
    names = [str(p) for p in e.params]
    rng = np.random.default_rng(seed)
    points = []
    for _ in range(4):
        par = _params(names, rng)
        points.append(np.concatenate([rng.uniform(-0.6, 0.6, len(e.q)),
                                      rng.uniform(-2.0, 2.0, len(e.dq)),
                                      [par[n] for n in names]]))
    for what, reference, tree_value in pairs:
        _close(what, reference, tree_value, args, points)


@pytest.mark.parametrize("scene", [
    "paper",                 # the compass gait, point masses
    "asymmetric_legs",       # legs that differ (per-role parameters)
    "kneed",                 # a knee on the swing leg, thigh and shank masses
    "round_feet",            # rolling arc feet, rod legs
    pytest.param("paper_rods", marks=pytest.mark.slow),
    pytest.param("hip_spring", marks=pytest.mark.slow),
    pytest.param("torso_bhm", marks=pytest.mark.slow),   # an upper body on a bisecting hip
    pytest.param("threelink", marks=pytest.mark.slow),   # a hinged torso on straight legs
    pytest.param("rabbit", marks=pytest.mark.slow),      # free knees on both legs, hinged torso
])
def test_a_shipped_planar_walker_derived_from_its_tree_equals_the_planar_derivation(scene):
    _agree(_scene_structure(scene), seed=sum(map(ord, scene)))


def test_a_planar_trees_mass_matrix_is_in_relative_angles_and_a_3d_tree_is_product_to_sum():
    """The planar trees' entries come out in the planar closed form (``product_to_sum``:
    ``cos(q_i - q_j)``, no product of two turns' sines or cosines left); the 3D trees' are
    simplified the same way (:func:`walkerlab.codegen.tree_derive.simplifier`), and their
    mass matrix equals the unsimplified one at a random state."""
    te = derive_tree(*legs_tree(_scene_structure("paper")))
    stance, swing = te.q
    assert simplifier(te.kinematics).__name__ == "product_to_sum"
    products = [f for f in sp.preorder_traversal(te.M) if isinstance(f, sp.Mul)
                and sum(isinstance(a, sp.cos | sp.sin) for a in f.args) > 1]
    assert not products, products
    assert te.M[0, 1].has(sp.cos(stance - swing)) or te.M[0, 1].has(sp.cos(swing - stance))
    kin3d = kinematics(*legs_tree(_scene_structure("hip_width")))
    assert simplifier(kin3d).__name__ == "product_to_sum"
    M3 = derive_tree(*legs_tree(_scene_structure("hip_width"))).M
    raw, _, _, _ = mass_and_potential(kin3d)
    rng = np.random.default_rng(7)
    at = {s: v for s, v in zip([*kin3d.q, *kin3d.params], rng.uniform(0.2, 1.2, 99))}
    num = np.array(M3.subs(at).evalf(), float)
    assert np.allclose(num, np.array(raw.subs(at).evalf(), float), rtol=1e-13, atol=0)
    assert not any(isinstance(f, sp.Mul) and sum(isinstance(a, sp.cos | sp.sin)
                                                 for a in f.args) > 1
                   for f in sp.preorder_traversal(M3))


def test_garcias_coordinates_and_a_body_off_the_leg_axis_derive_alike():
    """Garcia et al.'s (1998) slope-relative coordinates (``stance`` from the slope's normal,
    ``hip`` between the legs) with a massive foot, and a body ahead of its leg's axis."""
    _agree(Structure("slope_relative", (BodySpec("foot_mass", "point_mass"),), hip_mass=True),
           seed=3)
    _agree(Structure("absolute", (BodySpec("mass", "point_mass", off_axis=True),),
                     hip_mass=True), seed=4)


@pytest.mark.parametrize("structure, field", [
    (Structure("slope_relative", (BodySpec("foot", "point_mass", massless=True),),
               hip_mass=True), "walker.leg.bodies"),
])
def test_a_walker_the_tree_does_not_carry_yet_is_refused_naming_the_field(structure, field):
    with pytest.raises(ValueError, match=rf"^{field}"):
        legs_tree(structure)


def _flat_coordinates(coords: CoordinateMap, foot_flat: bool, rest: str) -> CoordinateMap:
    """The flat-footed tree's map with the swing ankle at its spring's rest angle ``rest``
    (:mod:`walkerlab.codegen.foot_modes`: no coordinate) and, ``foot_flat``, the stance sole
    locked flat on the slope (``stance_ankle = -(stance + gamma)``; coordinates ``swing,
    stance``)."""
    held = {"swing_ankle_pitch": rest}
    if foot_flat:
        held.update(stance_sole_pitch="0", stance_ankle_pitch="stance + gamma")
    names = ("swing", "stance") if foot_flat else ("swing", "stance", "stance_ankle")
    return CoordinateMap(names, tuple((c, held.get(c, e)) for c, e in coords.joint_angles))


@pytest.mark.parametrize("asymmetric", [False, True])
def test_a_flat_footed_trees_heel_contact_and_foot_flat_equal_the_foot_modes(asymmetric):
    """configs/flat_feet_foot_mass.yaml's structure (a foot of mass ``m_foot`` and inertia
    ``I_foot`` at each ankle; ``asymmetric``: its legs' and feet's numbers per role): the
    tree's Lagrange equations with the swing foot at its rest
    angle equal the leg-vector sums' ``heel_contact`` flow
    (``M``; ``C dq`` and ``G`` less the ankle's damper ``c dq_a`` and spring ``k (a - r)``,
    which the tree leaves to the exports), and with the sole locked flat its ``foot_flat``
    flow's (``S^T M S``, ``S^T (C S dq + G)`` at ``a = -(stance + gamma)``, ``S`` the lock's
    null space; the ankle's spring and damper added to the tree's), at random states and
    parameters (1e-12 relative)."""
    structure = replace(_scene_structure("flat_feet_foot_mass"), asymmetric=asymmetric)
    assert structure.foot_mass
    e = derive_flat(structure)
    hc = e.flows["heel_contact"]
    tree, coords = legs_tree(structure)
    P = dict(zip(map(str, e.params), e.params))
    sw, st = ("sw_", "st_") if asymmetric else ("", "")
    k, r, c = P[f"k_{st}ankle"], P[f"r_{st}ankle"], P[f"c_{st}ankle"]
    a, da = e.q[2], e.dq[2]
    dq = sp.Matrix(e.dq)
    th = derive_tree(tree, _flat_coordinates(coords, False, f"r_{sw}ankle"))
    assert tuple(map(str, th.q)) == tuple(map(str, e.q))
    ankle = sp.Matrix([0, 0, 1])
    pairs = [("heel contact M", hc.M, th.M),
             ("heel contact C dq", hc.C * dq, th.C * dq + c * da * ankle),
             ("heel contact G", hc.G, th.G + k * (a - r) * ankle)]
    tf = derive_tree(tree, _flat_coordinates(coords, True, f"r_{sw}ankle"))
    S = sp.Matrix([[1, 0], [0, 1], [0, -1]])
    flat = {a: -(e.q[1] + P["gamma"]), da: -e.dq[1]}
    dq2 = sp.Matrix(tf.dq).subs({t: f for t, f in zip(tf.dq, e.dq)})
    to_e = {t: f for t, f in zip(tf.q + tf.dq, e.q[:2] + e.dq[:2])}
    ankle_torque = (k * (a - r) * ankle + c * da * ankle).subs(flat)   # spring, damper
    pairs += [("foot flat M", S.T * hc.M.subs(flat) * S, tf.M.subs(to_e)),
              ("foot flat C dq + G", S.T * (hc.C * S * dq2 + hc.G).subs(flat),
               (tf.C * sp.Matrix(tf.dq) + tf.G).subs(to_e) + S.T * ankle_torque)]
    names = [str(p) for p in e.params]
    rng = np.random.default_rng(81)
    points = []
    for _ in range(4):
        par = _params([n for n in names if not n.startswith(("heel_", "toe_"))], rng)
        for t in (sw, st):
            par.update({f"heel_{t}m": rng.uniform(0.02, 0.1), f"toe_{t}m": rng.uniform(0.05, 0.2),
                        f"k_{t}ankle": rng.uniform(50, 200), f"r_{t}ankle": rng.uniform(-0.2, 0.2),
                        f"c_{t}ankle": rng.uniform(0.5, 5)})
        points.append(np.concatenate([rng.uniform(-0.6, 0.6, 3), rng.uniform(-2.0, 2.0, 3),
                                      [par[n] for n in names]]))
    args = list(e.q) + list(e.dq) + list(e.params)
    for what, reference, tree_value in pairs:
        _close(what, reference, tree_value, args, points)


def _scene_numbers(name: str) -> tuple[Structure, dict]:
    plant = Plant.from_scene(load_scene(f"configs/{name}.yaml"))
    return plant.data.structure, dict(zip(plant.data.structure.param_names, plant.data.params))


def _printed_pairs(e, f, dq) -> list:
    """What the printers read of two derivations' equations, as pairs of sympy matrices
    that must agree: the accelerations ``M^-1 (-C dq - G)`` (the rows of the massless limit
    and of the knee lock are a convention: the solutions are the physics), the rates after
    the heel strike, the role swap, the section, the energies, the guards, the named
    points and leg angles, and the push-off's extended system ``De``, ``E``."""
    def one(v):
        return sp.Matrix([v])
    pairs = [("accelerations", e.M.LUsolve(-(e.C * dq + e.G)), f.M.LUsolve(-(f.C * dq + f.G))),
             ("rates after the heel strike", e.Mi.LUsolve(e.B * dq), f.Mi.LUsolve(f.B * dq)),
             ("coordinates after the swap", e.relabel_q, f.relabel_q),
             ("rates' swap", e.relabel_rate, f.relabel_rate),
             ("the section's coordinate", one(e.drop_solution), one(f.drop_solution)),
             ("kinetic energy", one(e.kinetic), one(f.kinetic)),
             ("potential energy", one(e.potential), one(f.potential)),
             ("De", e.De, f.De), ("E", e.E, f.E)]
    assert set(e.guards) == set(f.guards) and set(e.points) == set(f.points)
    assert set(e.leg_angles) == set(f.leg_angles)
    pairs += [(f"guard {k}", one(e.guards[k]), one(f.guards[k])) for k in e.guards]
    pairs += [(f"point {k}", e.points[k], f.points[k]) for k in e.points]
    pairs += [(f"leg angle {k}", one(e.leg_angles[k]), one(f.leg_angles[k]))
              for k in e.leg_angles]
    if e.locked is not None:
        pairs += [("locked accelerations",
                   e.locked[0].LUsolve(-(e.locked[1] * dq + e.locked[2])),
                   f.locked[0].LUsolve(-(f.locked[1] * dq + f.locked[2]))),
                  ("rates after the knee strike", e.knee_impact[0].LUsolve(e.knee_impact[1] * dq),
                   f.knee_impact[0].LUsolve(f.knee_impact[1] * dq))]
    return pairs


@pytest.mark.parametrize("scene", [
    "paper",                 # the compass gait with the printed A.5's sign (appendix_a)
    "kneed",                 # a locking knee: the locked flow and the knee strike
    "simplest",              # Garcia et al.'s coordinates and massless legs (the limit)
    "hip_spring",            # a torsional spring-damper between the legs
    pytest.param("round_feet", marks=pytest.mark.slow),   # arc feet, rod legs
    pytest.param("torso_bhm", marks=pytest.mark.slow),    # an upper body, bisecting hip
    pytest.param("asymmetric_legs", marks=pytest.mark.slow),
    pytest.param("paper_rods", marks=pytest.mark.slow),
    "threelink",             # straight legs under a hinged torso (free joints)
    pytest.param("rabbit", marks=pytest.mark.slow),       # free knees, hinged torso
])
def test_a_planar_walkers_printed_equations_from_its_tree_equal_the_leg_vector_sums(scene):
    """Every field the printers read of :func:`walkerlab.codegen.legged.derive_legged` (the
    tree's equations with the heel strike, the role swap, the section, the springs, the
    massless limit, the knee lock and the push-off's extended system added) equals the
    leg-vector sums' derivation (``tests/independent/planar_link_sums.py``; a
    free-jointed one's, ``tests/independent/free_joints_link_sums.py``) at random
    states and the scene's parameters (1e-12 relative: both are exact, so they differ by
    round-off on terms of order 1-10)."""
    from walkerlab.codegen.legged import derive_legged

    structure, numbers = _scene_numbers(scene)
    free = structure.free_knees or structure.hinged_torso
    e = derive_five_link(structure) if free else derive(structure)
    f = derive_legged(structure)
    assert tuple(map(str, f.q)) == tuple(map(str, e.q))
    assert tuple(map(str, f.params)) == tuple(map(str, e.params))
    assert (f.limit, f.section_drop, bool(f.section_tied)) == (
        e.limit, e.section_drop, bool(e.section_tied))
    args = list(e.q) + list(e.dq) + list(e.params)
    rng = np.random.default_rng(sum(map(ord, scene)))
    points = [np.concatenate([rng.uniform(-0.5, 0.5, len(e.q)), rng.uniform(-2, 2, len(e.dq)),
                              [numbers[str(p)] for p in e.params]]) for _ in range(3)]
    for what, reference, tree_value in _printed_pairs(e, f, sp.Matrix(e.dq)):
        fa, fb = sp.lambdify(args, reference), sp.lambdify(args, tree_value)
        for x in points:   # a point at the stance foot is 0: there, to 1e-12 absolute
            with np.errstate(invalid="ignore"):   # a section's acos off its domain: nan
                a, b = np.array(fa(*x), float), np.array(fb(*x), float)
            scale = max(np.nanmax(np.abs(a)), 1.0) if np.isfinite(a).any() else 1.0
            np.testing.assert_allclose(b, a, rtol=0, atol=1e-12 * scale, equal_nan=True,
                                       err_msg=what)


def test_the_planar_spoked_wheel_from_its_tree_equals_the_spoke_vector_sums():
    """The rimless wheel (configs/rimless_wheel.yaml; McGeer 1990) derived from its tree
    (:func:`walkerlab.codegen.derive_3d.derive_spoked`) equals the spoke-vector sums
    (``tests/independent/planar_wheel.py``): flow, impact ``B = m L^2 cos 2 alpha + I``,
    energies, guards and every spoke's foot, at a state and the scene's numbers (1e-12)."""
    from tests.independent.planar_wheel import derive as spoke_sums
    from walkerlab.codegen.derive_3d import derive_spoked

    structure, numbers = _scene_numbers("rimless_wheel")
    e, f = spoke_sums(structure), derive_spoked(structure)
    assert set(e.points) == set(f.points) and set(e.guards) == set(f.guards)
    args = list(e.q) + list(e.dq) + list(e.params)
    x = [0.1, -0.7] + [numbers[str(p)] for p in e.params]
    dq = sp.Matrix(e.dq)
    pairs = [(e.M.LUsolve(-(e.C * dq + e.G)), f.M.LUsolve(-(f.C * dq + f.G))),
             (e.Mi.LUsolve(e.B * dq), f.Mi.LUsolve(f.B * dq)),
             (sp.Matrix([e.kinetic, e.potential]), sp.Matrix([f.kinetic, f.potential])),
             (e.relabel_q, f.relabel_q),
             (sp.Matrix([e.drop_solution]), sp.Matrix([f.drop_solution]))]
    pairs += [(sp.Matrix([e.guards[k]]), sp.Matrix([f.guards[k]])) for k in e.guards]
    pairs += [(e.points[k], f.points[k]) for k in e.points]
    for a, b in pairs:
        va, vb = (np.array(sp.lambdify(args, m)(*x), float) for m in (a, b))
        assert np.max(np.abs(va - vb)) <= 1e-12 * max(np.max(np.abs(va)), 1.0)
