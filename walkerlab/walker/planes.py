"""Which of a walker's coordinates turn out of the sagittal plane (a walker in 3D: its
lean and rolls about the fall line, a spoked wheel's heading about the slope's normal), by
name: the roles of :mod:`walkerlab.walker.description` (``COMPASS_3D_ROLES``,
``HIP_ROLL_ROLES``, ``SPOKED_3D_ROLES``) and the legs' names the views give them.  The
figures draw those on axes of their own without knowing the walker's state size."""

from __future__ import annotations

__all__ = ["OUT_OF_PLANE_WORDS", "out_of_plane"]

#: Last word of a coordinate out of the sagittal plane (3D: lean, rolls, a wheel's heading;
#: a role's name or a leg's, ``leg1_roll_angle``); every other one is a pitch in that plane.
OUT_OF_PLANE_WORDS = ("lean", "roll", "heading")


def out_of_plane(name: str) -> bool:
    """Whether the coordinate ``name`` (``lean_angle``, ``leg1_roll_rate``) turns out of the
    sagittal plane (:data:`OUT_OF_PLANE_WORDS`): the figures draw it on axes of its own.

    Parameters
    ----------
    name : str

    Returns
    -------
    bool
    """
    stem = name.removesuffix("_angle").removesuffix("_rate")
    return stem.rsplit("_", 1)[-1] in OUT_OF_PLANE_WORDS
