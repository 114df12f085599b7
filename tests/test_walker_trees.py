"""The exports ask the walker's body tree what is there (issue 97, item 4): every walker has a
tree (:func:`walkerlab.walker.walker_trees.walker_tree`), whose form (one body or legs, in the
plane or not, soles, knees and their stops) is what the kind's words said, and the leg
links the Adams dataset, the OpenSim model and the MJCF's header write are the tree's
(:func:`walkerlab.export.tree_links.tree_multibody`)."""

from __future__ import annotations

from pathlib import Path

import pytest

from walkerlab.config import load_scene
from walkerlab.walker.plant import Plant
from walkerlab.walker.tree import BodyTree
from walkerlab.walker.walker_trees import spoked_wheel_tree, walker_tree

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def _tree(name: str) -> BodyTree:
    return walker_tree(Plant.from_scene(load_scene(CONFIGS / f"{name}.yaml")).structure)[0]


@pytest.mark.parametrize("name, one_body, in_plane, soles, knee, stops", [
    ("paper", False, True, (), False, 0),
    ("kneed", False, True, (), True, 1),
    ("rabbit", False, True, (), True, 0),
    ("flat_feet", False, True, ("stance_sole", "swing_sole"), False, 0),
    ("simplest", False, True, (), False, 0),          # massless legs: the form alone
    ("rimless_wheel", True, True, (), False, 0),
    ("rimless_wheel_3d", True, False, (), False, 0),
    ("hip_width", False, False, (), False, 0),
    ("kneed_3d", False, False, (), True, 1),
])
def test_every_shipped_walkers_tree_says_its_form(name, one_body, in_plane, soles, knee,
                                                   stops):
    tree = _tree(name)
    assert tree.one_body == one_body
    assert tree.in_plane == in_plane
    assert tree.soles == soles
    assert tree.has_joint("swing_knee") == knee
    assert len(tree.stopped_joints) == stops


def test_the_planar_spoked_wheel_tree_is_one_body_on_a_pitch_joint_with_every_spokes_foot():
    tree, coords = spoked_wheel_tree(8)
    coords.check(tree)
    assert tree.one_body and tree.in_plane
    assert [j.kind for j in tree.joints] == ["revolute"]
    # the stance foot, the next and the trailing spoke's, spokes 2..6 ahead
    assert len(tree.contacts) == 8
    assert coords.names == ("stance",)


def test_a_tree_with_an_expression_axis_is_not_in_the_plane():
    from walkerlab.walker.tree import free_root

    tree, coords = spoked_wheel_tree()
    floating, _ = free_root(tree, coords, ("x", "y", "z", "heading"))
    assert not floating.in_plane  # the slides along world x and y: axes of the slope angle


@pytest.mark.parametrize("name", ["paper", "kneed", "torso_bhm", "flat_feet", "rabbit",
                                  "threelink", "asymmetric_legs", "round_feet", "paper_rods",
                                  "goswami1996"])
def test_the_exports_leg_links_are_the_body_trees_as_the_multibody_had_them(name):
    from walkerlab.export.tree_links import tree_multibody
    from walkerlab.walker.multibody import multibody

    data = Plant.from_scene(load_scene(CONFIGS / f"{name}.yaml")).data
    mb, tree_mb = multibody(data), tree_multibody(data)
    assert tree_mb.links == mb.links
    assert tree_mb.hip_mass_kg == mb.hip_mass_kg
