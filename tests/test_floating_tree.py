"""The floating (contact) view of a planar walker from its body tree
(:func:`walkerlab.walker.floating_tree.floating_planar_tree`: the pelvis on two slides, the
legs on their hips, knees, flat feet on their ankles, the upper body bisecting or hinged; a
spoked wheel's hub on the slides), derived as the 3D walkers' trees are
(:func:`walkerlab.codegen.floating_equations.derive_floating`): every field (the mass
matrix, the bias, the energies, every foot's contact point and Jacobian, every named point)
equals the leg-vector sums' (``tests/independent/floating_link_sums.py``, which shares no
kinematics with the tree) at random states and parameters, to round-off; the spoked wheel
equals its closed form (one body: ``diag(M, M, I)``, the spoke tips at ``hub + L e(theta + 2
k alpha)``).  The planar walkers whose expressions come out in the same form (paper,
flat feet, the three-link walker, hip_spring, asymmetric legs) print the same code, bit for
bit (``test_..._same_expression``)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from tests.independent.floating_link_sums import derive_floating as leg_vector_sums
from walkerlab.codegen.floating_equations import derive_floating
from walkerlab.config import load_scene
from walkerlab.walker.plant import Plant


@pytest.mark.parametrize("scene", [
    "paper",                 # point feet, point masses
    "kneed",                 # knees: the shank's parts below the knee
    "flat_feet_foot_mass",   # flat feet on their ankles, heel and toe contacts
    "round_feet",            # arc feet: the lowest point and the material Jacobian
    "torso_bhm",             # the bisecting hip's upper body
    "threelink",             # a hinged torso on straight legs
    pytest.param("rabbit", marks=pytest.mark.slow),           # free knees, hinged torso
    pytest.param("asymmetric_legs", marks=pytest.mark.slow),  # leg1 swing's, leg2 stance's
    pytest.param("hip_spring", marks=pytest.mark.slow),       # a spring-damper at the hip
    pytest.param("paper_rods", marks=pytest.mark.slow),       # rods: an inertia per link
])
def test_the_planar_floating_view_from_its_tree_equals_the_leg_vector_sums(scene):
    structure = Plant.from_scene(load_scene(f"configs/{scene}.yaml")).data.structure
    e, f = leg_vector_sums(structure), derive_floating(structure)
    assert tuple(map(str, f.q + f.dq + f.params)) == tuple(map(str, e.q + e.dq + e.params))
    assert (f.knees, f.contacts, f.point_legs) == (e.knees, e.contacts, e.point_legs)
    assert len(f.feet) == len(e.feet) and set(f.points) == set(e.points)
    fields = lambda eq: [eq.M, eq.h, sp.Matrix([eq.kinetic, eq.potential]),  # noqa: E731
                         *(m for foot in eq.feet for m in foot),
                         *(eq.points[k] for k in sorted(e.points))]
    args = [*e.q, *e.dq, *e.params]
    fe, ff = sp.lambdify(args, fields(e)), sp.lambdify(args, fields(f))
    rng = np.random.default_rng(sum(map(ord, scene)))
    for _ in range(3):   # angles and rates of order 1, lengths and masses of order 1
        x = rng.uniform(0.2, 1.2, len(args))
        for a, b in zip(fe(*x), ff(*x)):
            a, b = np.asarray(a, float), np.asarray(b, float)
            # the same sums of order-1 terms in another order: a few ulps of the largest
            assert np.allclose(b, a, rtol=0, atol=1e-13 * max(1.0, np.max(np.abs(a))))


@pytest.mark.parametrize("scene", ["paper", "flat_feet_foot_mass", "threelink"])
def test_the_planar_floating_view_of_plain_links_is_the_leg_vector_sums_same_expression(scene):
    """Where the tree's sums come out in the leg-vector sums' form (no knee, no arc, no
    upper body on the bisector), the expressions are the same: the generated contact code,
    and every contact run of these walkers, are unchanged to the bit."""
    structure = Plant.from_scene(load_scene(f"configs/{scene}.yaml")).data.structure
    e, f = leg_vector_sums(structure), derive_floating(structure)
    for what in ("M", "h", "kinetic", "potential"):
        assert sp.srepr(getattr(f, what)) == sp.srepr(getattr(e, what)), what
    for (fp, fj), (ep, ej), name in zip(f.feet, e.feet, e.contacts):
        assert sp.srepr(fp) == sp.srepr(ep) and sp.srepr(fj) == sp.srepr(ej), name
    for k in e.points:
        assert sp.srepr(f.points[k]) == sp.srepr(e.points[k]), k


def test_the_planar_spoked_wheel_floating_view_is_its_closed_form():
    """One body (McGeer 1990; Coleman, Chatterjee & Ruina 1997): ``M = diag(M_hub, M_hub,
    I_hub)``, ``h = (0, M_hub g, 0)`` (no velocity terms), spoke ``k``'s tip at ``hub + L
    (sin psi_k, -cos psi_k)``, ``psi_k = theta + 2 k alpha``, on leg2's lane for even k."""
    structure = Plant.from_scene(load_scene("configs/rimless_wheel.yaml")).data.structure
    f = derive_floating(structure)
    assert tuple(map(str, f.q)) == ("hip_x", "hip_y", "wheel_angle")
    P = {str(p): p for p in f.params}
    x, y, th = f.q
    assert sp.simplify(f.M - sp.diag(P["M_hub"], P["M_hub"], P["I_hub"])) == sp.zeros(3, 3)
    assert sp.simplify(f.h - sp.Matrix([0, P["M_hub"] * P["g"], 0])) == sp.zeros(3, 1)
    assert len(f.feet) == structure.spokes == len(f.contacts)
    for k, (pos, J) in enumerate(f.feet):
        psi = th + 2 * k * P["alpha"]
        tip = sp.Matrix([x + P["L"] * sp.sin(psi), y - P["L"] * sp.cos(psi)])
        assert sp.simplify(sp.expand_trig(pos - tip)) == sp.zeros(2, 1), k
        assert sp.simplify(sp.expand_trig(J - tip.jacobian(sp.Matrix(f.q)))) == sp.zeros(2, 3)
        assert f.point_legs[k] == (k + 1) % 2
