"""walkerlab's axes in the exports' (MJCF, URDF) for walkers in three dimensions, in one place.

walkerlab's world (:mod:`walkerlab.codegen.frames`): ``x`` horizontal downhill, ``y`` up,
``z = x × y`` (to the walker's right).  The exports': ``x`` downhill, ``z`` up, so ``y`` is
walkerlab's ``-z``: a vector ``v`` reads ``TO_MUJOCO @ v`` (a rotation, right-handed both).
walkerlab's pitch axis ``z`` (a positive angle moves a foot ahead, leans an upper body
back) is the exports' ``0 -1 0``; the slope's fall line
``(cos gamma, -sin gamma, 0)`` is ``(cos gamma, 0, -sin gamma)`` (:func:`slope_axes`, with the
slope's normal).  A body's frame at the
export's reference pose (:mod:`walkerlab.export.tree_bodies`) is the world's.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["TO_MUJOCO", "slope_axes"]

#: walkerlab's world axes (x downhill, y up, z to the right) in MuJoCo's (x downhill, z up):
#: ``X = x``, ``Y = -z``, ``Z = y`` (a rotation: right-handed both)
TO_MUJOCO = ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0))


def slope_axes(slope_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """The slope's fall line and normal in the exports' axes (the ground a plane turned by
    ``slope_rad`` about ``y``, falling towards +x).

    Parameters
    ----------
    slope_rad : float
        The slope's angle [rad].

    Returns
    -------
    fall, normal : ndarray (3,)
        ``(cos phi, 0, -sin phi)`` and ``(sin phi, 0, cos phi)``.
    """
    return (np.array([math.cos(slope_rad), 0.0, -math.sin(slope_rad)]),
            np.array([math.sin(slope_rad), 0.0, math.cos(slope_rad)]))
