"""Rough ground for the compliant-contact walker, as geometry: footfall heights and the
checkerboard lanes that carry them.

The contact model walks on the checkerboard lanes of :mod:`walkerlab.models.contact.model`: footfall
``k`` of the gait lands on a patch centred at ``s = k l`` (``l`` the gait's step length;
leg2's lane holds the even footfalls, leg1's the odd ones; footfall 0 is the stance foot the
walk starts on).  Rough ground gives each patch a height ``h_k`` along the slope's outward
normal (:attr:`walkerlab.models.contact.model.ContactWalker.heights1`), so

* a single step-down of ``h`` at the first heel strike is ``h_k = -h`` for every ``k >= 1``
  (a step-up: ``+h``), as the rigid model's swing-foot clearance guard meets the ground
  ``h`` below the slope line through the stance foot
  (:meth:`walkerlab.integrate.batch_step.BatchStepMap.step`, ``drop_m``);
* per-step slopes ``gamma_k`` (Byl & Tedrake 2009) are the heights at which the line
  through footfall ``k`` at slope ``gamma_k`` meets the next footfall,
  ``h_{k+1} = h_k - l tan(gamma_k - gamma)`` (``gamma`` the scene's slope): the swing foot
  lands where it would on the rigid model's per-step slope.  Between footfalls the patches
  stay parallel to the scene's slope and gravity keeps its direction (the rigid model's
  per-step slope also turns gravity within the step); the two terrains agree to first
  order in ``gamma_k - gamma`` at the footfalls only.

The scene's ground (``terrain.kind``, :func:`terrain_ground`) enters the same way: on the
paper's checkerboard lanes (``lanes: checkerboard``) stairs and footholds are patches at the
rigid gait's footholds, footfall ``k`` at the height of its tread, ``-k`` times the landing
drop per step (:func:`walkerlab.models.ground.landing_drop`; the heights the rigid
model's heel strikes meet).  Footholds of several heights ``h_0, ..., h_{p-1}`` (the list
repeats) are patches at the rigid period-``p`` gait's own footfalls, step by step
(:func:`footfall_positions` of each step's advance along the slope, which the caller
measures on the rigid gait: :mod:`walkerlab.analysis.contact.footfalls`), footfall ``k``
at ``(h_0 + ... + h_{k-1}) cos(phi)`` along the slope's normal (:func:`footfall_heights`);
on continuous ground (``lanes: continuous``) the stairs are a
polyline of level treads and vertical risers (:func:`stairs_line`) that both feet meet
everywhere, so a toe swinging into a riser is caught by it
(:attr:`walkerlab.models.contact.model.ContactWalker.ground_line`).

A height profile (``terrain.kind: profile``) is the polyline itself on continuous ground
(:func:`profile_line`); on the checkerboard lanes (the ground of straight legs, whose swing
foot passes below the ground at mid-stance) each patch is the profile under it
(:func:`profile_patch_heights`): flat, parallel to the slope, at the profile's height at
the patch's centre, which the profile must keep across the patch (to
:data:`PROFILE_PATCH_TOL_M`; refused in one line otherwise), so a profile that is the
scene's slope gives the slope's patches (heights 0 to rounding) and its walk.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from walkerlab.models.ground import landing_drops, stair_treads

from .lanes import footprint_offsets

__all__ = ["PROFILE_PATCH_TOL_M", "check_ground", "footfall_heights", "footfall_lanes",
           "footfall_positions", "ground_drops", "profile_line", "profile_patch_heights",
           "slope_heights", "stairs_line", "step_heights", "terrain_ground"]

#: how far [m] a profile may depart from a checkerboard patch's plane across the patch
#: (:func:`profile_patch_heights`): 1 um, under 2 % of the contact's static penetration
#: (the shipped law, 1e5 N/mm^2.2, takes ~0.07 mm under a 30 kg walker), so the patch is the
#: profile to well within what the feet sink into it
PROFILE_PATCH_TOL_M = 1e-6


def slope_heights(slopes_rad: np.ndarray, mean_rad: float, step_length_m: float
                  ) -> np.ndarray:
    """Footfall heights [m] (n + 1,) of per-step slopes ``slopes_rad`` (n,) about
    ``mean_rad``: ``h_0 = 0``, ``h_{k+1} = h_k - l tan(gamma_k - mean)``."""
    d = -step_length_m * np.tan(np.asarray(slopes_rad, float) - float(mean_rad))
    return np.concatenate([[0.0], np.cumsum(d)])


def step_heights(n_footfalls: int, height_m: float) -> np.ndarray:
    """Footfall heights [m] (n_footfalls,) of one step of ``height_m`` (< 0 a step-down)
    at the first heel strike: 0 for footfall 0, ``height_m`` from footfall 1 on."""
    h = np.full(int(n_footfalls), float(height_m))
    h[0] = 0.0
    return h


def footfall_lanes(walker, heights_m: np.ndarray):
    """``walker`` with patch ``k`` of the footfall order at height ``heights_m[k]`` [m]
    (footfalls past the given heights keep the last one).

    Parameters
    ----------
    walker : ContactWalker
        With checkerboard lanes (:func:`walkerlab.models.contact.model.checkerboard_lanes`):
        leg2's patches are footfalls 0, 2, 4, ..., leg1's 1, 3, ....
    heights_m : ndarray (k,)

    Continuous ground (``terrain.kind: continuous``, the kneed walker's) becomes contiguous
    patches: each lane's patches widen to twice the step length, so every lane is ground
    everywhere (from its first footfall's patch on) and a height changes half-way between
    that lane's footfalls.

    Raises
    ------
    ValueError
        Lanes without patches.
    """
    if walker.lane1.size == 0 or walker.lane2.size == 0:
        raise ValueError("terrain: rough ground for the contact model needs the lanes of "
                         "footfalls (ContactWalker.from_settings)")
    h = np.asarray(heights_m, float)
    n = 2 * max(walker.lane1.size, walker.lane2.size)
    h = np.concatenate([h, np.full(max(0, n - h.size), h[-1] if h.size else 0.0)])
    ground = {}
    if walker.continuous:
        ground = {"continuous": False,
                  "patch_half_width": float(walker.lane1[0] - walker.lane2[0])}
    return replace(walker, heights2=h[0:2 * walker.lane2.size:2],
                   heights1=h[1:2 * walker.lane1.size:2], **ground)


def footholds_line(footfalls_m, heights_m, phi: float, run_m: float = 100.0) -> np.ndarray:
    """Vertices (m, 2) [m] of footholds on continuous ground as a polyline in the world frame
    (x downhill, y up): a tread through each footfall ``k`` (at ``footfalls_m[k]`` along the
    slope and ``heights_m[k]`` along its outward normal), along the slope's line, joined to
    the next by a vertical riser half-way (in x) between the two footfalls; the first and
    last treads run on ``run_m`` beyond their footfalls.  The footholds say where the feet
    land (:func:`walkerlab.models.ground.landing_drops`), not what lies between them: a
    tread to the half-way riser is the ground a walker's stance foot or a wheel's stance
    spoke rolls on until the next footfall takes over.

    Parameters
    ----------
    footfalls_m : ndarray (n,)
        The footfalls along the slope [m], in walking order (increasing).
    heights_m : ndarray (n,)
        Their heights along the slope's outward normal [m]
        (:func:`footfall_heights`).
    phi : float
        The slope [rad] (the treads' angle, downhill).
    run_m : float
        How far the first and last treads run on [m].
    """
    s, h = np.asarray(footfalls_m, float), np.asarray(heights_m, float)
    c, sn = math.cos(phi), math.sin(phi)
    x, y = s * c + h * sn, -s * sn + h * c     # the footfalls in the world frame

    def on(k: int, xx: float) -> tuple[float, float]:   # tread k's point above xx
        return xx, float(y[k] - (xx - x[k]) * math.tan(phi))

    pts = [on(0, float(x[0] - run_m * c))]
    for k in range(s.size - 1):
        mid = 0.5 * float(x[k] + x[k + 1])
        pts += [on(k, mid), on(k + 1, mid)]
    pts.append(on(s.size - 1, float(x[-1] + run_m * c)))
    return np.asarray(pts, dtype=float)


def stairs_line(terrain, first_x_m: float, n_treads: int, behind: int = 3) -> np.ndarray:
    """Vertices (m, 2) [m] of stairs as a polyline in the world frame: the level treads of
    :func:`walkerlab.models.ground.stair_treads` (the rigid view's, the same ground) joined
    by vertical risers; tread 0 at height 0 holds the first stance foot at
    ``x = first_x_m``, ``first_foothold_m`` from its back end (default mid-tread).

    The parameters are :func:`~walkerlab.models.ground.stair_treads`'.
    """
    pts = []
    for a, b, h in stair_treads(terrain, first_x_m, n_treads, behind):
        pts += [(a, h), (b, h)]
    return np.asarray(pts, dtype=float)


def check_ground(terrain) -> float:
    """The landing drop per step [m] of a ground the contact model builds (0.0 for the
    slope; :func:`walkerlab.models.ground.landing_drop`; footholds of several heights: their
    mean, the drop per step on average; each step's is :func:`ground_drops`').

    Raises
    ------
    ValueError
        One line naming the field and what to do: a profile from a CSV, footholds of
        their own slopes (the rigid model walks them), footholds on continuous ground (no
        ground between the footholds).
    """
    drops = ground_drops(terrain)
    return drops[0] if len(drops) == 1 else float(np.mean(drops))


def ground_drops(terrain) -> tuple[float, ...]:
    """The landing drop [m] of each step of the ground's period, for a ground the contact
    model builds: ``(0.0,)`` for the slope and a profile, ``(drop,)`` for stairs and
    footholds of one height, one per height for footholds of several heights
    (:func:`walkerlab.models.ground.landing_drops`).

    Raises
    ------
    ValueError
        As :func:`check_ground` (one line).
    """
    if terrain is None or terrain.kind == "slope":
        return (0.0,)
    if terrain.kind == "profile":
        if terrain.profile_m is None:
            raise ValueError("terrain.profile_csv: the contact model reads inline profiles "
                             "(terrain.profile_m) only so far, as the rigid walk does")
        return (0.0,)
    return landing_drops(terrain)


def footfall_positions(step_lengths_m, n_footfalls: int) -> np.ndarray:
    """Along-slope positions [m] (n_footfalls,) of the footfalls of a gait whose steps
    advance ``step_lengths_m`` (p,) in turn: footfall 0 at 0, footfall ``k`` at
    ``sum_{j<k} l_j`` (``l_j = step_lengths_m[j mod p]``).  Steps given as vectors
    ``(p, d)`` [m] (a 3D walker's advance, its lateral offset and its drop): the footfalls
    as points ``(n_footfalls, d)``, footfall 0 at the origin."""
    ell = np.asarray(step_lengths_m, float)
    ell = ell.ravel() if ell.ndim < 2 else ell
    steps = ell[np.arange(max(int(n_footfalls) - 1, 0)) % len(ell)]
    return np.concatenate([np.zeros((1, *ell.shape[1:])), np.cumsum(steps, axis=0)])


def footfall_heights(drops_m, n_footfalls: int, phi: float) -> np.ndarray:
    """Heights [m] (n_footfalls,) along the slope's outward normal of the footfalls of a
    ground whose steps land ``drops_m`` (p,) below the stance foot's level in turn (a drop
    along the vertical, the rigid model's, :func:`walkerlab.models.ground.landing_drops`):
    footfall 0 at 0, footfall ``k`` at ``-(sum_{j<k} d_j) cos(phi)``."""
    d = np.asarray(drops_m, float).ravel()
    steps = d[np.arange(max(int(n_footfalls) - 1, 0)) % d.size]
    return -np.concatenate([[0.0], np.cumsum(steps)]) * math.cos(float(phi))


def profile_line(terrain, first_x_m: float, first_y_m: float) -> np.ndarray:
    """Vertices (m, 2) [m] of a height profile (``terrain.profile_m``) as the contact model's
    polyline ground in the world frame: the profile's first point at the first stance foot
    (as the rigid walk places it, :mod:`walkerlab.analysis.gait.profile_walk`), its first and
    last segments run on along their own lines for 100 m.

    Parameters
    ----------
    terrain : walkerlab.config.TerrainSettings
        ``kind: profile`` with ``profile_m``.
    first_x_m, first_y_m : float
        The first stance foot's contact point in the world frame [m].
    """
    pts = np.asarray(terrain.profile_m, dtype=float)
    pts = pts - pts[0] + np.array([first_x_m, first_y_m])
    head = pts[0] - 100.0 * (pts[1] - pts[0]) / np.hypot(*(pts[1] - pts[0]))
    tail = pts[-1] + 100.0 * (pts[-1] - pts[-2]) / np.hypot(*(pts[-1] - pts[-2]))
    return np.vstack([head, pts, tail])


def profile_patch_heights(terrain, centres_m, half_width_m: float, phi: float,
                          first_m: float = 0.0) -> np.ndarray:
    """Heights [m] along the slope's outward normal (> 0 raised) of flat checkerboard patches
    centred at ``centres_m`` (along-slope s [m]) on a height profile: the profile's height
    above the slope line at each centre, its first point at ``s = first_m`` on that line
    (the first stance foot; beyond its ends its first and last segments run on, as
    :func:`profile_line`'s).

    Parameters
    ----------
    terrain : walkerlab.config.TerrainSettings
        ``kind: profile`` with ``profile_m`` (world x forward, y up [m]).
    centres_m : ndarray (k,)
        Patch centres [m] along the slope.
    half_width_m : float
        Half the patch width [m].
    phi : float
        The scene's slope [rad].
    first_m : float
        Along-slope place of the profile's first point [m].

    Returns
    -------
    ndarray (k,)

    Raises
    ------
    ValueError
        One line naming ``terrain.lanes``: a profile that departs from a patch's plane by
        more than :data:`PROFILE_PATCH_TOL_M` across it (the measured depth and where), or
        one that turns back along the slope (a wall steeper than the slope's normal).
    """
    P = np.asarray(terrain.profile_m, dtype=float)
    P = P - P[0]
    cp, sp = math.cos(phi), math.sin(phi)
    s = first_m + P[:, 0] * cp - P[:, 1] * sp  # along the slope
    n = P[:, 0] * sp + P[:, 1] * cp  # above the slope line through the first point
    if np.any(np.diff(s) <= 0.0):
        i = int(np.flatnonzero(np.diff(s) <= 0.0)[0])
        raise ValueError(f"terrain.lanes: checkerboard on a profile lays flat patches along "
                         f"the slope; the profile turns back along it after x = "
                         f"{terrain.profile_m[i][0]:g} m (a face steeper than the slope's "
                         "normal): give lanes: continuous (the profile as a polyline)")

    def height(q):
        q = np.asarray(q, float)
        out = np.interp(q, s, n)
        lo, hi = q < s[0], q > s[-1]
        out = np.where(lo, n[0] + (q - s[0]) * (n[1] - n[0]) / (s[1] - s[0]), out)
        return np.where(hi, n[-1] + (q - s[-1]) * (n[-1] - n[-2]) / (s[-1] - s[-2]), out)

    c = np.asarray(centres_m, float)
    h = height(c)
    for ck, hk in zip(c, h):
        a, b = ck - half_width_m, ck + half_width_m
        q = np.concatenate([[a, b], s[(s > a) & (s < b)]])
        dev = float(np.max(np.abs(height(q) - hk)))
        if dev > PROFILE_PATCH_TOL_M:
            raise ValueError(
                f"terrain.lanes: checkerboard on a profile lays flat patches at its height; "
                f"the profile departs from the patch at s = {ck:.4g} m along the slope by "
                f"{1e3 * dev:.3g} mm (more than {1e3 * PROFILE_PATCH_TOL_M:g} mm): give "
                "lanes: continuous, or a profile straight across each footfall's patch")
    return h


def terrain_ground(walker, terrain, n_steps: int):
    """``walker`` (its lanes laid out at the footfalls,
    :meth:`walkerlab.models.contact.model.ContactWalker.on_terrain`) on the scene's ground.

    Parameters
    ----------
    walker : ContactWalker
    terrain : walkerlab.config.TerrainSettings
    n_steps : int
        Steps the run may take.

    Returns
    -------
    ContactWalker
        ``kind: slope``: ``walker`` itself (bit for bit today's ground).  Stairs and
        footholds of one height on the checkerboard lanes: the patches at the footholds'
        heights (footfall ``k`` at ``-k drop cos(phi)`` along the slope's normal,
        :func:`footfall_lanes`); footholds of several heights: footfall ``k`` at
        :func:`footfall_heights` (the lanes laid at the rigid gait's footfalls, step by
        step).  Stairs on continuous ground: the treads and risers as a polyline
        (:func:`stairs_line`); footholds on continuous ground: a tread through each
        footfall, risers half-way (:func:`footholds_line`); a profile: its polyline
        (:func:`profile_line`), or on the checkerboard lanes flat patches at its height
        (:func:`profile_patch_heights`).

    Raises
    ------
    ValueError
        A ground the contact model does not build (one line, naming the field): a profile
        that is not flat across a checkerboard patch (:func:`profile_patch_heights`),
        footholds of their own slopes (:func:`ground_drops`).
    """
    if terrain is None or terrain.kind == "slope":
        return walker
    drops = ground_drops(terrain)
    if terrain.kind == "profile" and terrain.lanes == "checkerboard":  # flat patches on it,
        # the profile's first point at the first stance foot's footfall (leg2's patch 0)
        first = float(walker.lane2[0]) - footprint_offsets(walker.data)[1]
        hw, phi = float(walker.patch_half_width), float(walker.phi)
        return replace(walker,
                       heights1=profile_patch_heights(terrain, walker.lane1, hw, phi, first),
                       heights2=profile_patch_heights(terrain, walker.lane2, hw, phi, first))
    if terrain.lanes == "checkerboard":
        n = 2 * max(walker.lane1.size, walker.lane2.size)
        if len(drops) > 1:
            return footfall_lanes(walker, footfall_heights(drops, n, float(walker.phi)))
        heights = -np.arange(n) * drops[0] * math.cos(float(walker.phi))
        return footfall_lanes(walker, heights)
    first = float(walker.lane2[0]) if walker.lane2.size else 0.0
    if terrain.kind == "profile":  # the first footfall along the slope, in the world frame
        phi = float(walker.phi)
        return replace(walker, ground_line=profile_line(
            terrain, first * math.cos(phi), -first * math.sin(phi)))
    if terrain.kind == "footholds":  # treads through the footfalls, risers half-way
        phi, p = float(walker.phi), len(drops)
        n = 2 * min(walker.lane1.size, walker.lane2.size)
        falls = np.empty(n)
        falls[0::2], falls[1::2] = walker.lane2[:n // 2], walker.lane1[:n // 2]
        heights = footfall_heights(drops, n, phi)
        # the footfall before the first (the trailing foot's, a wheel's trailing spoke's):
        # the period's last step before it, periodic footholds; else level with the first
        back = drops[-1] if terrain.periodic is not False else 0.0
        falls = np.r_[falls[0] - (falls[p] - falls[p - 1]), falls]
        heights = np.r_[heights[0] + back * math.cos(phi), heights]
        return replace(walker, ground_line=footholds_line(falls, heights, phi))
    return replace(walker, ground_line=stairs_line(terrain, first, int(n_steps) + 2))
