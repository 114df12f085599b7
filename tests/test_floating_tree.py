"""The planar floating (contact) view from its body tree
(:func:`walkerlab.walker.floating_tree.floating_planar_tree`: the pelvis on two slides, the
legs on their hips, knees, flat feet on their ankles, the upper body bisecting or hinged):
every field of :func:`walkerlab.codegen.floating_equations.derive_floating` (the mass matrix,
the bias, the energies, every foot's contact point and Jacobian, every named point) is the
same sympy expression as the leg-vector sums' that derived it before
(``tests/independent/floating_link_sums.py``, which shares no kinematics with the tree), so
the generated contact kernels, and every contact run, are unchanged to the bit."""

from __future__ import annotations

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
def test_the_planar_floating_view_from_its_tree_is_the_leg_vector_sums_expression(scene):
    structure = Plant.from_scene(load_scene(f"configs/{scene}.yaml")).data.structure
    e, f = leg_vector_sums(structure), derive_floating(structure)
    assert tuple(map(str, f.q + f.dq + f.params)) == tuple(map(str, e.q + e.dq + e.params))
    assert (f.knees, f.contacts, f.point_legs) == (e.knees, e.contacts, e.point_legs)
    for what in ("M", "h", "kinetic", "potential"):
        assert sp.srepr(getattr(f, what)) == sp.srepr(getattr(e, what)), what
    assert len(f.feet) == len(e.feet)
    for (fp, fj), (ep, ej), name in zip(f.feet, e.feet, e.contacts):
        assert sp.srepr(fp) == sp.srepr(ep) and sp.srepr(fj) == sp.srepr(ej), name
    assert set(f.points) == set(e.points)
    for k in e.points:
        assert sp.srepr(f.points[k]) == sp.srepr(e.points[k]), k
