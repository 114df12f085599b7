"""Every walker's body tree (:mod:`walkerlab.walker.tree`), for the questions the exports ask
of its form: :func:`walker_tree` (the legs' :func:`walkerlab.walker.trees.legs_tree`, the
spoked wheels' :func:`spoked_wheel_tree` and
:func:`walkerlab.walker.trees.spoked_wheel_3d_tree`).

The exports write a walker as its tree has it: a tree of one body rolling on its contact
points (:attr:`~walkerlab.walker.tree.BodyTree.one_body`: a spoked wheel), planar or not
(:attr:`~walkerlab.walker.tree.BodyTree.in_plane`), with soles
(:attr:`~walkerlab.walker.tree.BodyTree.soles`: flat feet), a knee (a joint ``swing_knee``)
and its stop (:attr:`~walkerlab.walker.tree.BodyTree.stopped_joints`): they ask the tree what
is there, not the walker's kind.
"""

from __future__ import annotations

from dataclasses import replace

from walkerlab.walker.tree import BodyTree, ContactPoint, CoordinateMap, Joint, Root, diagonal
from walkerlab.walker.trees import legs_tree, spoked_wheel_3d_tree

__all__ = ["spoked_wheel_tree", "walker_tree"]

Z = (0, 0, 1)


def spoke_foot(k: int) -> tuple:
    """The foot of the spoke ``k`` spokes ahead of the stance spoke in the wheel's frame
    (3,) [m]: the hub ``(0, L, 0)`` plus ``Rot(z, 2 k alpha) (0, -L, 0)``."""
    return (f"L * sin({2 * k} * alpha)", f"L - L * cos({2 * k} * alpha)", 0)


def spoked_wheel_tree(spokes: int | None = None) -> tuple[BodyTree, CoordinateMap]:
    """The planar spoked wheel (McGeer 1990; Coleman, Chatterjee & Ruina 1997) as a tree:
    one body on a pitch joint at the stance spoke's foot, its angle from the slope's normal
    ``stance + gamma`` (``stance`` the stance spoke's angle from the vertical); the hub
    ``M_hub`` at ``(0, L, 0)`` in the wheel's frame with ``I_hub`` about the axle ``z``; the
    spokes' feet as :func:`walkerlab.walker.trees.spoked_wheel_3d_tree` has them.

    Parameters
    ----------
    spokes : int, optional
        The number of spokes (each spoke's foot a contact point); None: the stance and next
        feet only.

    Returns
    -------
    BodyTree, CoordinateMap
        Parameters ``g, L, gamma, M_hub, I_hub, alpha``; the coordinate ``stance``.
    """
    params = ("g", "L", "gamma", "M_hub", "I_hub", "alpha")
    wheel = replace(spoked_wheel_3d_tree()[0].body("wheel"),
                    inertia_kg_m2=diagonal(0, 0, "I_hub"),
                    joint=Joint("stance_spoke", "revolute", "slope", (0, 0, 0), (Z,),
                                ("wheel_spin",)))
    names = {1: "next_foot"} if spokes is None else {
        1: "next_foot", -1: "trailing_foot", **{k: f"spoke{k}_foot" for k in range(2, spokes - 1)}}
    tree = BodyTree(params, Root(), (wheel,),
                    (ContactPoint("stance_foot", "wheel", (0, 0, 0)),
                     *(ContactPoint(name, "wheel", spoke_foot(k)) for k, name in names.items())))
    return tree, CoordinateMap(("stance",), (("wheel_spin", "stance + gamma"),))


def walker_tree(structure) -> tuple[BodyTree, CoordinateMap]:
    """The body tree of any walker's structure
    (:class:`walkerlab.walker.description.Structure`): a spoked wheel's
    (:func:`spoked_wheel_tree`, in 3D :func:`walkerlab.walker.trees.spoked_wheel_3d_tree`),
    else its legs' (:func:`walkerlab.walker.trees.legs_tree`), a massless body (the mass -> 0
    limit, Garcia et al. 1998, which :func:`~walkerlab.walker.trees.legs_tree` refuses) left
    out: the tree's form, for the exports' questions about it (module docstring), not its
    numbers.

    Returns
    -------
    BodyTree, CoordinateMap
    """
    if structure.spokes:
        return (spoked_wheel_3d_tree(structure.spokes) if structure.in_3d
                else spoked_wheel_tree(structure.spokes))
    if any(b.massless for b in structure.bodies):
        structure = replace(structure, bodies=tuple(b for b in structure.bodies
                                                    if not b.massless))
    return legs_tree(structure)
