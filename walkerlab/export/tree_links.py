"""A planar walker's leg links read from its body tree: the links the Adams dataset
(:mod:`walkerlab.export.adams`), the OpenSim model (:mod:`walkerlab.export.opensim`) and the
MJCF's and URDF's header and extras (:mod:`walkerlab.export.multibody`) write are the
tree's export bodies (:func:`walkerlab.export.planar_bodies.planar_bodies`, the bodies the
URDF and the MJCF write), not numbers of their own.

:func:`tree_multibody` is the walker's :class:`~walkerlab.walker.multibody.Multibody` (its
refusals, springs, couplings, leg length, feet, gravity and slope: the description's) with
its links and its hip mass those of the tree: each :class:`~walkerlab.walker.multibody.Link`
an export body on a hinge (a leg ``leg<i>``, a thigh ``leg<i>_thigh``, a shank
``leg<i>_shank``, the torso), in the exports' axes (``x`` ahead, ``z`` up, the pitch axis
``y``, :mod:`walkerlab.export.tree_bodies`) at the reference pose (legs hanging straight
down, the torso straight up):

- ``joint_from_parent_m``: the body's origin down its parent's axis [m] (``-z``);
- ``com_m``, ``com_off_axis_m``: its centre of mass down its axis and ahead of it [m];
- ``inertia_kg_m2``: its moment about the pitch axis at its centre of mass [kg m^2] (the
  tree's, no floor);
- ``foot_m``: the foot point (a round foot's centre, a flat foot's ankle) down its axis [m],
  on the link that carries it; ``length_m`` that plus the foot's radius (a thigh: its
  knee; the torso: the farthest of its bodies above the hip, at least a tenth of the leg,
  a drawing length).
"""

from __future__ import annotations

from dataclasses import replace

import sympy as sp

from walkerlab.export.planar_bodies import planar_bodies
from walkerlab.walker.multibody import Link, Multibody, multibody

__all__ = ["tree_links", "tree_multibody"]


def tree_multibody(data) -> Multibody:
    """The planar walker of ``data`` (:func:`walkerlab.walker.description.walker_data`) as
    :func:`walkerlab.walker.multibody.multibody` has it, with the links and hip mass of its
    body tree (:func:`tree_links`).

    Returns
    -------
    Multibody

    Raises
    ------
    ValueError
        What :func:`walkerlab.walker.multibody.multibody` refuses (a link without mass, a
        spoked wheel, a walker without a floating view), one line.
    """
    mb = multibody(data)
    hip_mass, links = tree_links(data, mb)
    return replace(mb, hip_mass_kg=hip_mass, links=links)


def tree_links(data, mb: Multibody) -> tuple[float, tuple[Link, ...]]:
    """The hip's mass [kg] and the leg links of the walker's body tree (module docstring),
    ``leg1``'s, then ``leg2``'s (the stance role's numbers), then the torso's.

    Parameters
    ----------
    data : WalkerData
        A planar legged walker.
    mb : Multibody
        Its multibody (:func:`walkerlab.walker.multibody.multibody`): its foot radius and
        leg length (a drawing length's floor).

    Returns
    -------
    float, tuple of Link
    """
    root, _ = planar_bodies(data, 0.0)
    links: list[Link] = []

    def visit(b, parent: str) -> None:
        hinges = [j for j in b.joints if j.kind == "hinge"]
        if not hinges or b.tree_body in mb.tree.soles:  # a foot point, a sole: the feet's
            return
        points = [c for c in b.children if c.mass_kg == 0 and not c.children
                  and all(j.kind == "fixed" for j in c.joints)]
        links_below = [c for c in b.children if c not in points]
        foot = next((0.0 - c.pos_m[2] for c in points), None)
        up = b.tree_body == "torso"
        if foot is not None:
            length = foot + mb.foot_radius_m
        elif up:
            length = _torso_height(data, mb)
        else:
            length = next(0.0 - c.pos_m[2] for c in links_below)
        links.append(Link(b.name, parent, hinges[0].name, 0.0 - b.pos_m[2], length,
                          b.mass_kg, 0.0 - b.com_m[2], float(b.inertia_kg_m2[1, 1]), foot,
                          b.com_m[0] + 0.0, up))
        for c in links_below:
            visit(c, b.name)

    for c in root.children:
        visit(c, "hip")
    return root.mass_kg, tuple(links)


def _torso_height(data, mb: Multibody) -> float:
    """The torso's drawing length [m]: its farthest body above the hip (the tree's welded
    parts ``torso_<part>``), at least a tenth of the leg."""
    from walkerlab.walker.trees import legs_tree  # the parts' distances, by name

    s = data.structure
    tree, _ = legs_tree(s)
    values = dict(zip(s.param_names, data.params))
    ups = [float(sp.sympify(b.com_m[1]).subs(values)) for b in tree.bodies
           if b.joint.parent == "torso" and b.joint.kind == "fixed"]
    return max(max(ups), mb.leg_length_m / 10)
