"""The exported MuJoCo scene's ground (:mod:`walkerlab.export.scene`): the checkerboard's
patches centred on the rigid gait's footfalls, one lane per leg, laid out for
:data:`EXPORT_STEPS` footfalls (:func:`checkerboard`, :func:`footfalls_per_step`), the
patches of a ground profile (:func:`profile_patches`), stairs' and footholds' heights and
treads (:func:`ground_pieces`) and the file's comments on them (:func:`ground_notes`).
Lengths in [m] along the slope.
"""

from __future__ import annotations

import math

import numpy as np

from walkerlab.analysis.contact.footfalls import rigid_step_lengths
from walkerlab.config import Scene
from walkerlab.config.contact import TerrainSettings
from walkerlab.models.contact.scene import ideal_step_length
from walkerlab.models.contact.terrain import (
    check_ground,
    footfall_heights,
    footfall_positions,
    ground_drops,
    profile_patch_heights,
    stairs_line,
)

#: Footfalls laid out per lane in an exported checkerboard (the MuJoCo test walks >= 10 steps).
EXPORT_STEPS = 40


def checkerboard(walker, ideal, terrain: TerrainSettings) -> tuple:
    """The checkerboard's footfalls ``(leg1's, leg2's)`` along the ground [m], before the
    feet's :meth:`footprints`: the keyframe's feet are one step apart, leg2's step (the last
    of the gait's map; stairs, footholds: the footholds' spacing, along the slope)."""
    ell2 = ideal_step_length(walker, ideal.x, along_slope=not terrain.is_slope)
    ells = tuple(getattr(ideal, "step_lengths_m", ()) or ())
    # legs that differ: leg1's step differs from leg2's by the rigid steps' difference
    # (exact for point feet), else footfalls drift off the patches stride by stride
    k = np.arange(EXPORT_STEPS // 2 + 1)
    if len(ells) == 2:
        ell1 = ell2 + (ells[0] - ells[1])
        return (tuple(ell1 + (k - 1) * (ell1 + ell2)), tuple((ell1 + ell2) * k))
    return (tuple(ell2 * (2 * k - 1)), tuple(2 * ell2 * k))


def footfalls_per_step(scene: Scene, walker, x_ideal, terrain: TerrainSettings,
                       plant) -> tuple[tuple, tuple]:
    """The checkerboard of footholds of several heights: ``(lanes, lane_heights)``, each
    ``(leg1's, leg2's)`` [m], the patches at the rigid period-n gait's footfalls step by step
    (:func:`walkerlab.analysis.contact.footfalls.rigid_step_lengths`) and their heights along
    the slope normal (:func:`walkerlab.models.contact.terrain.footfall_heights`).  The
    keyframe's stance foot (leg2) is footfall 0 at the origin, its trailing foot (leg1)
    footfall -1, the last step of the rigid map (``l_{m-1}`` behind, ``d_{m-1} cos(phi)``
    above); leg2's lane holds footfalls 0, 2, ..., leg1's -1, 1, 3, ....  ``plant``: the
    scene's :class:`~walkerlab.walker.plant.Plant` (the stage's)."""
    ells = rigid_step_lengths(scene, walker, x_ideal, plant=plant)
    drops = ground_drops(terrain)
    n = EXPORT_STEPS + 1  # footfalls 0 .. EXPORT_STEPS
    s = footfall_positions(ells, n)
    h = footfall_heights(drops, n, float(walker.phi))
    s_back = -ells[-1]
    h_back = drops[(len(ells) - 1) % len(drops)] * math.cos(float(walker.phi))
    lanes = (tuple(float(v) for v in (s_back, *s[1::2])), tuple(float(v) for v in s[0::2]))
    heights = (tuple(float(v) for v in (h_back, *h[1::2])), tuple(float(v) for v in h[0::2]))
    return lanes, heights


def profile_patches(terrain: TerrainSettings, lanes: tuple, ahead_m: float,
                     phi: float) -> tuple:
    """The heights ``(leg1's, leg2's)`` [m] along the slope normal of the checkerboard
    patches ``lanes`` (along-slope centres [m], leg2's contact point at the origin, the
    profile's first point there) on a height profile: the contact model's flat patches
    (:func:`walkerlab.models.contact.terrain.profile_patch_heights`), each box from its
    footfall ``- w/2`` to ``+ w/2 + ahead_m``.

    Raises
    ------
    ValueError
        A profile not flat across a patch (one line naming ``terrain.lanes``).
    """
    hw = 0.5 * (terrain.patch_width_m + ahead_m)
    return tuple(tuple(float(h) for h in profile_patch_heights(
        terrain, np.asarray(lane, float) + 0.5 * ahead_m, hw, phi)) for lane in lanes)


def ground_notes(terrain: TerrainSettings, treads, profile, lane_heights) -> tuple:
    """The MJCF's comments on a ground that is not the plain slope (stairs, a profile,
    footholds)."""
    terrain_notes = ()
    if treads is not None:
        terrain_notes += (f"Stairs (terrain: riser {terrain.riser_m:g} m "
                          f"{terrain.direction or 'down'}, tread {terrain.tread_m:g} m): a box "
                          "per tread (geoms tread<i>), its top the tread, its faces the "
                          "risers.",)
    elif profile is not None:
        terrain_notes += ("Profile (terrain.kind: profile, lanes: continuous): a height field "
                          "hfield 'profile' sampled every 5 mm from its polyline, the first "
                          "stance foot on its first point (both feet touch it).",)
    elif lane_heights is not None and terrain.kind == "profile":
        terrain_notes += ("Profile (terrain.kind: profile, lanes: checkerboard): the "
                          "checkerboard patches, flat, each at the profile's height under it "
                          "(walkerlab.models.contact.terrain.profile_patch_heights), the "
                          "first stance foot on its first point.",)
    elif lane_heights is not None and terrain.kind == "footholds" \
            and len(set(terrain.foothold_heights_m or (0.0,))) > 1:
        terrain_notes += ("Footholds of several heights (terrain.foothold_heights_m, in "
                          "turn): the checkerboard patches at the rigid period-n gait's "
                          "footfalls step by step (walkerlab.analysis.contact.footfalls), "
                          "each the step's height below the last along the vertical.",)
    elif lane_heights is not None:
        terrain_notes += ("Footholds (terrain.kind: " + terrain.kind + "): the checkerboard "
                          "patches at the rigid gait's footholds, each at its tread's height "
                          "(a riser below or above the last).",)
    return terrain_notes


def ground_pieces(terrain: TerrainSettings, walker, x_ideal) -> tuple:
    """The MJCF's ground on stairs or footholds (:class:`MjcfScene` ``lane_heights``,
    ``treads``): the checkerboard patches' heights along the slope normal (footfall ``j``
    at ``-j drop cos(phi)``, leg2's lane holding footfalls 0, 2, ..., leg1's -1, 1, 3, ...:
    the keyframe's trailing foot stands on the tread behind), or continuous stairs' treads
    (:func:`walkerlab.models.contact.terrain.stairs_line`, the stance foot at the origin).

    Raises
    ------
    ValueError
        A ground the contact model does not build (one line,
        :func:`walkerlab.models.contact.terrain.check_ground`).
    """
    drop = check_ground(terrain) * math.cos(float(walker.phi))
    if terrain.lanes == "checkerboard":
        k = np.arange(EXPORT_STEPS // 2 + 1)
        return (tuple(-(2 * k - 1) * drop), tuple(-(2 * k) * drop)), None
    line = stairs_line(terrain, 0.0, EXPORT_STEPS + 2)
    return None, tuple((float(line[i, 0]), float(line[i + 1, 0]), float(line[i, 1]))
                       for i in range(0, len(line), 2))
