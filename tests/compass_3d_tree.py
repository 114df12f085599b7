"""The 3D straight-legged walker of the ``model: compass_gait`` shorthand as a body tree
(:func:`compass_3d_tree`), a fixture of the tree tests: :func:`walkerlab.walker.trees.
biped_tree` on the shorthand's parameter names."""

from __future__ import annotations

from walkerlab.walker.tree import BodyTree, CoordinateMap
from walkerlab.walker.trees import Part, biped_tree

#: the parameters the 3D compass's tree reads, before the hip-roll law's gains (the order
#: of :data:`walkerlab.walker.description.COMPASS_3D_PARAMS` and its tails)
_BASE = ("g", "L", "gamma", "M_hip", "m_leg", "a_leg")
_HIP_ROLL_LAW = ("I_pelvis", "kp_pelvis", "kd_pelvis", "kp_swing", "kd_swing", "g_lean",
                 "g_lean_rate")


def compass_3d_tree(*, hip_roll: bool = False, leg_inertia: bool = False
                    ) -> tuple[BodyTree, CoordinateMap]:
    """The 3D straight-legged walker with hip width ``w_hip`` as a tree
    (:func:`biped_tree`: a point mass ``m_leg`` on each leg ``a_leg`` from its
    foot), and the coordinates ``lean, swing, stance`` (and, with ``hip_roll``,
    ``pelvis_roll, swing_roll``) as its joint angles' map.

    Parameters
    ----------
    hip_roll : bool
        The legs hang from the pelvis on roll joints (the pelvis' inertia ``I_pelvis`` about
        the fall line; the law's gains are parameters the tree does not read).
    leg_inertia : bool
        Each leg a slender rod with ``I_leg`` [kg m^2] about its mass point normal to it.

    Returns
    -------
    BodyTree, CoordinateMap
        Parameters ``g, L, gamma, M_hip, m_leg, a_leg, w_hip[, I_leg][, I_pelvis, kp_pelvis,
        ...]`` (:data:`walkerlab.walker.description.COMPASS_3D_PARAMS` and its tails).
    """
    params = _BASE + ("w_hip",) + (("I_leg",) if leg_inertia else ()) + (
        _HIP_ROLL_LAW if hip_roll else ())
    leg = Part("mass", "m_leg", "L - a_leg", "I_leg" if leg_inertia else None)
    return biped_tree(params, (leg,), hip_width="w_hip", hip_roll=hip_roll)
