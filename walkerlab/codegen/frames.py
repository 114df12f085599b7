"""Rotations and the slope's frame, written once for every symbolic derivation: in three
dimensions (:mod:`walkerlab.codegen.derive_3d`, :mod:`walkerlab.codegen.tree_derive`) and in
the plane (the planar walkers' generators take the slope's normal and fall line from
:func:`planar_slope_axes`).

Frames
------
World axes as the planar walkers': ``x`` horizontal downhill, ``y`` up, ``z = x × y``.  The
slope's frame has the fall line ``s = (cos gamma, -sin gamma, 0)``, the slope's unit normal
``n = (sin gamma, cos gamma, 0)`` and ``z`` as its axes; a vector with components ``r`` in
it has the world components ``slope_to_world(gamma) @ r`` and the height
``slope_up(gamma) . r`` above the horizontal through the slope frame's origin.  A planar
walker's world is the ``x, y`` plane: its slope's normal and fall line are ``n`` and ``s``
without their ``z`` components.
"""

from __future__ import annotations

import sympy as sp

__all__ = ["leg_unit", "planar_slope_axes", "rotation", "skew", "slope_to_world", "slope_up"]


def skew(v) -> sp.Matrix:
    """The cross-product matrix (3, 3) of a 3-vector: ``skew(a) @ b == a × b``."""
    k = sp.Matrix(v)
    return sp.Matrix([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])


def rotation(axis: sp.Matrix, angle) -> sp.Matrix:
    """Rotation matrix (3, 3) by ``angle`` [rad] about the unit vector ``axis`` (3,):
    Rodrigues' formula ``I + sin(angle) K + (1 - cos(angle)) K^2``, ``K = skew(axis)``
    (Murray, Li & Sastry 1994, Eq. 2.14)."""
    K = skew(axis)
    return sp.eye(3) + sp.sin(angle) * K + (1 - sp.cos(angle)) * K * K


def slope_up(gamma) -> sp.Matrix:
    """The upward vertical (3, 1) in the slope's frame (module docstring): the height of a
    point ``r`` above the horizontal is ``-sin(gamma) r_s + cos(gamma) r_n``."""
    return sp.Matrix([-sp.sin(gamma), sp.cos(gamma), 0])


def slope_to_world(gamma) -> sp.Matrix:
    """The rotation (3, 3) from the slope's frame to world axes: its columns are ``s``,
    ``n`` and ``z`` in world axes."""
    return sp.Matrix([[sp.cos(gamma), sp.sin(gamma), 0],
                      [-sp.sin(gamma), sp.cos(gamma), 0], [0, 0, 1]])


def planar_slope_axes(gamma) -> tuple[sp.Matrix, sp.Matrix]:
    """The slope's unit normal ``n = (sin gamma, cos gamma)`` and its fall line (the
    tangent along the slope, downhill) ``s = (cos gamma, -sin gamma)``, each (2, 1), in a
    planar walker's world axes (``x`` horizontal downhill, ``y`` up; module docstring)."""
    return (sp.Matrix([sp.sin(gamma), sp.cos(gamma)]),
            sp.Matrix([sp.cos(gamma), -sp.sin(gamma)]))


def leg_unit(psi) -> sp.Matrix:
    """The unit vector (2, 1) from the hip towards the foot of a planar leg at ``psi`` [rad]
    from the vertical (foot ahead positive), in world axes: ``(sin psi, -cos psi)``."""
    return sp.Matrix([sp.sin(psi), -sp.cos(psi)])
