"""A planar walker's export bodies read from its body tree
(:func:`walkerlab.export.planar_bodies.planar_bodies`: :func:`walkerlab.walker.trees.
legs_tree` through :func:`walkerlab.export.tree_bodies.export_bodies`) against the walker's
links (:func:`walkerlab.walker.multibody.multibody`: each leg segment's bodies summed by the
parallel-axis theorem along the leg, no tree, no sympy), which the exports wrote before the
tree did: the same bodies in the same order, on the same joints (names, axes, the locking
knee's stop), at the same places, with the same masses, centres of mass and inertias, and
each foot where the links put it.  Tolerance 1e-15 of the leg length, mass and largest
moment: the tree's expressions are evaluated from the same numbers (round-off only; the
shipped scenes' files compare equal)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.export.planar_bodies import _link_bodies, planar_bodies
from walkerlab.walker.description import walker_data
from walkerlab.walker.multibody import multibody

ROOT = Path(__file__).resolve().parents[1]


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
    links = _link_bodies(mb, 0.0, None)
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
