"""walkerlab's axes in the exports' (MJCF, URDF) for walkers in three dimensions, in one place.

walkerlab's world (:mod:`walkerlab.codegen.frames`): ``x`` horizontal downhill, ``y`` up,
``z = x × y`` (to the walker's right).  The exports': ``x`` downhill, ``z`` up, so ``y`` is
walkerlab's ``-z``: a vector ``v`` reads ``TO_MUJOCO @ v`` (a rotation, right-handed both).
walkerlab's pitch axis ``z`` (a positive angle moves a foot ahead, leans an upper body
back) is the exports' ``0 -1 0``; the slope's fall line
``(cos gamma, -sin gamma, 0)`` is ``(cos gamma, 0, -sin gamma)``.  A body's frame at the
export's reference pose (:mod:`walkerlab.export.tree_bodies`) is the world's.
"""

from __future__ import annotations

__all__ = ["TO_MUJOCO"]

#: walkerlab's world axes (x downhill, y up, z to the right) in MuJoCo's (x downhill, z up):
#: ``X = x``, ``Y = -z``, ``Z = y`` (a rotation: right-handed both)
TO_MUJOCO = ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0))
