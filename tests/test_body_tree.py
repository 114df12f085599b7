"""The body tree (walkerlab/walker/tree.py) and its one Lagrangian derivation
(walkerlab/codegen/tree_derive.py) against hand derivations that share no code with it: the
3D compass with hip width, with and without hip-roll joints, with rod legs and round feet
(``tests/independent/hand_3d_compass.py``: point masses summed, written out as walkerlab
derived it before the tree), the 3D spoked wheel (``tests/independent/hand_3d_wheel.py``) and
the planar compass gait (``tests/independent/planar_link_sums.py``), numerically at random
states and parameters.

Tolerance: 1e-12 relative to the largest entry of the compared matrix - the two derivations
are the same mechanics in different expression trees, so they differ by round-off only
(measured: 0 to 3e-16); a modelling difference (a mass misplaced, an inertia about the wrong
axis, a joint turned the wrong way) shows at order 1e-2 or more
(:func:`test_a_misplaced_pelvis_mass_is_seen_by_the_comparison`).
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import sympy as sp

from tests.compass_3d_tree import compass_3d_tree
from tests.independent.hand_3d_compass import derive_compass
from tests.independent.hand_3d_wheel import derive_spoked as hand_spoked
from tests.independent.planar_link_sums import derive
from walkerlab.codegen.derive_3d import derive_spoked
from walkerlab.codegen.legged import derive_legged
from walkerlab.codegen.tree_derive import derive_tree, heel_strike, kinematics
from walkerlab.walker.description import BodySpec, Structure
from walkerlab.walker.tree import Body, BodyTree, ContactPoint, CoordinateMap, Joint, Root
from walkerlab.walker.trees import spoked_wheel_3d_tree

RTOL = 1e-12


def _same(e):
    return e


def _params(names, rng, *, mirror=False) -> dict:
    """Random physical parameters by name (the hip-roll law's gains 0: its generalised
    forces, which are no part of the tree, then vanish from ``derive_compass``'s ``G``)."""
    L = rng.uniform(0.7, 1.3)
    value = {"g": rng.uniform(9.0, 10.5), "L": L, "gamma": rng.uniform(-0.1, 0.2),
             "M_hip": rng.uniform(0.5, 20.0), "m_leg": rng.uniform(0.5, 8.0),
             "a_leg": rng.uniform(0.2, 0.8) * L, "w_hip": rng.uniform(0.05, 0.4)
             * (-1 if mirror else 1), "I_leg": rng.uniform(0.01, 0.5),
             "I_pelvis": rng.uniform(0.01, 0.5), "m_mass": rng.uniform(0.5, 8.0),
             "d_mass": rng.uniform(0.2, 0.8) * L, "I_mass": rng.uniform(0.01, 0.5),
             "M_hub": rng.uniform(0.5, 20.0), "I_hub": rng.uniform(0.01, 2.0),
             "I_diam": rng.uniform(0.01, 2.0), "alpha": rng.uniform(0.2, 0.8),
             "R_foot": rng.uniform(0.05, 0.3) * L}
    return {n: value.get(n, 0.0) for n in names}


def _close(name, reference, candidate, args, points):
    """``reference`` and ``candidate`` (sympy matrices) equal to :data:`RTOL` relative at
    every point of ``points`` (arrays in ``args``' order)."""
    fa, fb = sp.lambdify(args, reference), sp.lambdify(args, candidate)
    for x in points:
        a, b = np.array(fa(*x), float), np.array(fb(*x), float)
        scale = np.max(np.abs(a))
        assert scale > 0, name
        assert np.max(np.abs(a - b)) <= RTOL * scale, (name, x, a, b)


def _states(e, rng, count=4):
    """``count`` random ``(q, dq, params)`` points, one with the mirror step's hip width."""
    names = [str(p) for p in e.params]
    out = []
    for k in range(count):
        q = rng.uniform(-0.6, 0.6, len(e.q))
        dq = rng.uniform(-2.0, 2.0, len(e.dq))
        par = _params(names, rng, mirror=k == count - 1)
        out.append(np.concatenate([q, dq, [par[n] for n in names]]))
    return out


def _compare(e, te, Mi, B, rng):
    """The flow's matrices, the bias ``C dq``, gravity, the potential and the impact map
    (``Mi``, ``B`` and the post-impact rates ``Mi^-1 B dq``) of two derivations."""
    assert tuple(map(str, te.q)) == tuple(map(str, e.q))
    assert tuple(map(str, te.params)) == tuple(map(str, e.params))
    args = e.q + e.dq + e.params
    pts = _states(e, rng)
    dqv = sp.Matrix(e.dq)
    for name, ref, cand in (("M", e.M, te.M), ("C", e.C, te.C), ("C dq", e.C * dqv, te.C * dqv),
                            ("G", e.G, te.G), ("V", sp.Matrix([e.potential]),
                                               sp.Matrix([te.potential])),
                            ("Mi", e.Mi, Mi), ("B", e.B, B)):
        _close(name, ref, cand, args, pts)
    post_ref, post = sp.lambdify(args, [e.Mi, e.B * dqv]), sp.lambdify(args, [Mi, B * dqv])
    for x in pts:
        (m1, r1), (m2, r2) = post_ref(*x), post(*x)
        a = np.linalg.solve(np.array(m1, float), np.array(r1, float))
        b = np.linalg.solve(np.array(m2, float), np.array(r2, float))
        assert np.max(np.abs(a - b)) <= 1e-11 * np.max(np.abs(a)), (x, a, b)


def _structure_3d(*, hip_roll=False, rod=False, arc=False) -> Structure:
    return Structure("absolute", (BodySpec("mass", "rod" if rod else "point_mass"),),
                     hip_mass=True, foot="arc" if arc else "point", in_3d=True,
                     hip_width=True, hip_roll=hip_roll)


@pytest.mark.parametrize("rod", [False, pytest.param(True, marks=pytest.mark.slow)],
                         ids=["point_legs", "rod_legs"])
def test_the_3d_compass_tree_reproduces_derive_compass(rod):
    """The 3D compass with hip width (Kuo 1999) as a tree: its mass matrix, Coriolis matrix
    and bias, gravity, potential and heel-strike impact equal ``derive_compass``'s at random
    states and parameters, the mirror step's negative hip width among them."""
    e = derive_compass(_structure_3d(rod=rod))
    tree, coords = compass_3d_tree(leg_inertia=rod)
    te = derive_tree(tree, coords, simplify=_same)
    Mi, B = heel_strike(te, "swing_foot", simplify=_same)
    _compare(e, te, Mi, B, np.random.default_rng(81 + rod))
    # the named points (world axes) and the swing foot's height above the slope
    args = e.q + e.dq + e.params
    pts = _states(e, np.random.default_rng(7))
    for ours, theirs in (("swing_foot", "swing_foot"), ("pelvis_com", "hip"),
                         ("stance_leg_mass_com", "stance_mass"),
                         ("swing_leg_mass_com", "swing_mass"),
                         ("pelvis_origin", "stance_hip"), ("swing_leg_origin", "swing_hip")):
        _close(ours, e.points[theirs], te.points[ours], args, pts)
    _close("clearance", sp.Matrix([e.guards["swing_clearance"]]),
           sp.Matrix([te.kinematics.contacts["swing_foot"][1]]), args, pts)


@pytest.mark.slow
def test_the_hip_roll_walker_tree_reproduces_derive_compass():
    """With hip-roll joints (five coordinates, the pelvis' roll inertia), derived with the
    same simplification as ``derive_compass`` (the form production would print): equal at
    random states (the law's gains 0: its forces are no part of the tree)."""
    e = derive_compass(_structure_3d(hip_roll=True))
    tree, coords = compass_3d_tree(hip_roll=True)
    te = derive_tree(tree, coords)
    Mi, B = heel_strike(te, "swing_foot")
    _compare(e, te, Mi, B, np.random.default_rng(810))


@pytest.mark.slow
@pytest.mark.parametrize("width, rod", [(False, True), (True, False)],
                         ids=["round_feet_rod_legs", "round_feet_hip_width"])
def test_production_3d_equations_from_the_tree_equal_the_hand_derivation(width, rod):
    """The equations production generates for the 3D straight-legged walker
    (``legged.derive_legged``, derived from its tree) equal the hand derivation's
    with round feet (McGeer 1990's discs rolling in each leg's rolled sagittal plane: the
    tree's slide along the fall line, the impact about the disc's material point), at random
    states: flow, impact, potential, the heel-strike surface, the section's solved swing
    angle and the named points (70 s each: the arc's simplification)."""
    st = Structure("absolute", (BodySpec("mass", "rod" if rod else "point_mass"),),
                   foot="arc", in_3d=True, hip_width=width)
    e, ours = derive_compass(st), derive_legged(st)
    rng = np.random.default_rng(83)
    args = e.q + e.dq + e.params
    pts = _states(e, rng)
    for name, ref, cand in (("M", e.M, ours.M), ("C", e.C, ours.C), ("G", e.G, ours.G),
                            ("V", sp.Matrix([e.potential]), sp.Matrix([ours.potential])),
                            ("Mi", e.Mi, ours.Mi), ("B", e.B, ours.B),
                            ("heel", sp.Matrix([e.guards["heel_strike"]]),
                             sp.Matrix([ours.guards["heel_strike"]])),
                            ("drop", sp.Matrix([e.drop_solution]),
                             sp.Matrix([ours.drop_solution])),
                            *((k, e.points[k], ours.points[k]) for k in e.points)):
        if name == "drop":   # acos: keep the states where it is defined
            fa = sp.lambdify(args, ref)
            with np.errstate(invalid="ignore"):
                here = [x for x in pts
                        if np.isfinite(np.asarray(fa(*x), dtype=float).ravel()).all()]
            assert here, "no state where the section's swing angle is defined"
            _close(name, ref, cand, args, here)
            continue
        if name == "stance_foot":
            continue
        _close(name, ref, cand, args, pts)


@pytest.mark.slow
@pytest.mark.parametrize("spokes", [6, 9])
def test_production_spoked_wheel_from_the_tree_equals_the_hand_derivation(spokes):
    """The equations production generates for the 3D spoked wheel (Coleman, Chatterjee &
    Ruina 1997; ``derive_3d.derive_spoked``, now one body on a spherical joint in its tree)
    equal the hand derivation's (``tests/independent/hand_3d_wheel.py``: the kinetic energy
    by König, the impact as the angular momentum about the new foot) at random states: flow,
    impact and its post-impact rates, potential, the heel-strike surface, the section's
    solved spin and every named point (35 s: the hand derivation's simplification)."""
    st = Structure("absolute", (), hip_mass=True, spokes=spokes, in_3d=True)
    e, ours = hand_spoked(st), derive_spoked(st)
    _compare(e, ours, ours.Mi, ours.B, np.random.default_rng(97 + spokes))
    args = e.q + e.dq + e.params
    pts = _states(e, np.random.default_rng(spokes))
    assert set(ours.points) == set(e.points)
    assert ours.relabel_q == e.relabel_q and ours.relabel_rate == e.relabel_rate
    for name, ref, cand in (("heel", sp.Matrix([e.guards["heel_strike"]]),
                             sp.Matrix([ours.guards["heel_strike"]])),
                            ("drop", sp.Matrix([e.drop_solution]),
                             sp.Matrix([ours.drop_solution])),
                            *((k, e.points[k], ours.points[k]) for k in e.points
                              if k != "stance_foot")):
        _close(name, ref, cand, args, pts)


def test_the_3d_tree_upright_and_narrow_is_the_planar_compass_gait():
    """The 3D compass tree with no lean and zero hip width: its pitch block of the mass
    matrix is the planar compass gait's (leg mass ``a`` from the foot = ``L - d`` from the
    hip)."""
    tree, coords = compass_3d_tree()
    te = derive_tree(tree, coords, simplify=_same)
    planar = derive(Structure("absolute", (BodySpec("mass", "point_mass"),), hip_mass=True))
    P3, P2 = dict(zip(map(str, te.params), te.params)), dict(zip(map(str, planar.params),
                                                                 planar.params))
    sub = {te.q[0]: 0, P3["w_hip"]: 0, P3["m_leg"]: P2["m_mass"],
           P3["a_leg"]: P2["L"] - P2["d_mass"], te.q[1]: planar.q[0], te.q[2]: planar.q[1],
           **{P3[k]: P2[k] for k in ("g", "L", "gamma", "M_hip")}}
    pitch = te.M[1:, 1:].subs(sub)
    assert sp.simplify(pitch - planar.M) == sp.zeros(2, 2)
    assert te.M[0, 1].subs(sub) == 0   # no coupling of lean and pitch when upright


@pytest.mark.parametrize("make", [lambda: compass_3d_tree(hip_roll=True),
                                  spoked_wheel_3d_tree], ids=["hip_roll_walker", "wheel"])
def test_each_body_turns_at_its_body_frame_angular_velocity(make):
    """Each body's angular velocity in its own frame is the body velocity ``R^T R'``
    (Murray, Li & Sastry 1994, Eq. 2.49): independent of the tree's unrolled recursion,
    and seen by every inertia, not only by the symmetric ones of today's walkers."""
    kin = kinematics(*make())
    qv, dqv = sp.Matrix(kin.q), sp.Matrix(kin.dq)
    rng = np.random.default_rng(49)
    args = kin.q + kin.dq + kin.params
    for name, R in kin.rotations.items():
        Rdot = sum((R.diff(qi) * dqi for qi, dqi in zip(qv, dqv)), sp.zeros(3, 3))
        fR, fRd = sp.lambdify(args, R), sp.lambdify(args, Rdot)
        fw = sp.lambdify(args, kin.omegas[name])
        for _ in range(3):
            x = rng.uniform(-1.0, 1.0, len(args))
            body = np.array(fR(*x), float).T @ np.array(fRd(*x), float)
            assert np.allclose(body, -body.T, atol=1e-13)
            w = np.array([body[2, 1], body[0, 2], body[1, 0]])
            assert np.allclose(np.ravel(np.array(fw(*x), float)), w, rtol=0, atol=1e-13), name


def test_a_misplaced_pelvis_mass_is_seen_by_the_comparison():
    """The comparison can fail: the pelvis' mass at the swing hip instead of midway differs
    from ``derive_compass`` far beyond the tolerance."""
    e = derive_compass(_structure_3d())
    tree, coords = compass_3d_tree()
    pelvis = tree.body("pelvis")
    moved = Body(pelvis.name, pelvis.mass_kg, pelvis.inertia_kg_m2, (0, 0, "w_hip"),
                 pelvis.joint)
    wrong = BodyTree(tree.params, tree.root,
                     tuple(moved if b.name == "pelvis" else b for b in tree.bodies),
                     tree.contacts)
    te = derive_tree(wrong, coords, simplify=_same)
    args = e.q + e.dq + e.params
    x = _states(e, np.random.default_rng(3), 1)[0]
    a = np.array(sp.lambdify(args, e.M)(*x), float)
    b = np.array(sp.lambdify(args, te.M)(*x), float)
    assert np.max(np.abs(a - b)) > 1e-3 * np.max(np.abs(a))


def _leg(**change):
    fields = dict(name="leg", mass_kg="m", inertia_kg_m2=((0, 0, 0), (0, 0, 0), (0, 0, 0)),
                  com_m=(0, "a", 0),
                  joint=Joint("ankle", "revolute", "slope", (0, 0, 0), ((0, 0, 1),), ("q",)))
    fields.update(change)
    return Body(**fields)


def _tree(*bodies, params=("m", "a", "g", "gamma"), contacts=None):
    return BodyTree(params, Root(), bodies,
                    contacts if contacts is not None
                    else (ContactPoint("stance_foot", "leg", (0, 0, 0)),))


@pytest.mark.parametrize("change, field", [
    (dict(joint=Joint("ankle", "revolute", "torso", (0, 0, 0), ((0, 0, 1),), ("q",))),
     "tree.bodies[0].joint.parent"),
    (dict(joint=Joint("ankle", "universal", "slope", (0, 0, 0), ((0, 0, 1),), ("q",))),
     "tree.bodies[0].joint.axes"),
    (dict(joint=Joint("ankle", "revolute", "slope", (0, 0, 0), ((0, 0, 2),), ("q",))),
     "tree.bodies[0].joint.axes[0]"),
    (dict(joint=Joint("ankle", "hinge", "slope", (0, 0, 0), ((0, 0, 1),), ("q",))),
     "tree.bodies[0].joint.kind"),
    (dict(joint=Joint("ankle", "revolute", "slope", (0, 0, 0), ((0, 0, 1),), ("m",))),
     "tree.bodies[0].joint.coordinates"),
    (dict(inertia_kg_m2=((1, 0.1, 0), (0, 1, 0), (0, 0, 1))), "tree.bodies[0].inertia_kg_m2"),
    (dict(mass_kg=-1.0), "tree.bodies[0].mass_kg"),
    (dict(com_m=(0, "b", 0)), "tree.bodies[0].com_m[1]"),
    (dict(com_m=(0, 1)), "tree.bodies[0].com_m"),
    (dict(joint=Joint("ankle", "revolute", "slope", (0, 0, 0), ((0, 0, 1),), ("q",),
                      ((0, -1.0),))), "tree.bodies[0].joint.stops[0]"),
    (dict(joint=Joint("ankle", "revolute", "slope", (0, 0, 0), ((0, 0, 1),), ("q",),
                      (None, None))), "tree.bodies[0].joint.stops"),
    (dict(joint=Joint("ankle", "revolute", "slope", (0, 0, 0), ((0, 0, 1),), ("q",),
                      ((0, "b"),))), "tree.bodies[0].joint.stops[0]"),
])
def test_a_bad_tree_is_refused_naming_the_field(change, field):
    """A malformed body or joint is refused in one line that names the field."""
    with pytest.raises(ValueError, match="^" + re.escape(field) + ":"):
        _tree(_leg(**change))


def test_a_tree_without_its_stance_contact_or_with_a_stray_contact_is_refused():
    with pytest.raises(ValueError, match=r"^tree.root.stance_contact:"):
        _tree(_leg(), contacts=())
    with pytest.raises(ValueError, match=r"^tree.contacts\[0\].body:"):
        _tree(_leg(), contacts=(ContactPoint("stance_foot", "arm", (0, 0, 0)),))


def test_a_coordinate_map_missing_a_joint_is_refused_naming_the_field():
    tree = _tree(_leg())
    with pytest.raises(ValueError, match=r"^coordinates.joint_angles: no expression for q"):
        derive_tree(tree, CoordinateMap(("theta",), ()))
    with pytest.raises(ValueError, match=r"^coordinates.joint_angles\[q\]:"):
        derive_tree(tree, CoordinateMap(("theta",), (("q", "theta + phi"),)))
