"""The ground's facts both views of a walker read (the rigid hybrid model,
:mod:`walkerlab.models.hybrid.ground`, and the compliant-contact model's terrain,
:mod:`walkerlab.models.contact.terrain`): how far below the stance foot's level each step
lands, from the scene's ``terrain`` section alone; how far above it a walker's hip has
fallen (:data:`FALL_HIP_FRACTION`).

A stair ``riser_m`` down is a landing ``riser_m`` below the stance foot's level (up: above
it); footholds of one height ``h`` a landing at ``-h``; footholds of several heights or of
their own slopes are one landing per step (:func:`foothold_steps`); the slope and a height
profile (walked step by step from the slope's gait) land on the slope's line.

The ground's shape in the rigid run's world frame (x forward, y up, the first stance foot
where the run puts it) is :class:`Ground` (:func:`scene_ground`): straight pieces, each with
the line it lies on, from which the swing foot's clearance is measured
(:meth:`Ground.clearance`) by the fixed point's stair check and the report alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from walkerlab.walker.capability_cells import FOOTHOLD_SLOPES, SEVERAL_FOOTHOLDS

__all__ = ["FALL_HIP_FRACTION", "Ground", "foothold_steps", "landing_drop", "landing_drops",
           "scene_ground", "stair_treads"]

#: A walk has fallen once its hip is below this fraction of the leg length above the ground
#: [-]: the compliant-contact model's fall (``contact_sim.fall_hip_height_m`` by default)
#: and the rigid model's for a walker in 3D, whose sideways capsize stalls the integrator
#: before its hip reaches the ground (a planar rigid walker falls with its hip at the ground).
FALL_HIP_FRACTION = 0.5


def landing_drop(terrain) -> float:
    """Depth [m] of each step's landing below the stance foot's level for a ground whose
    every step is alike (``terrain.kind: stairs``: ``+riser_m`` down, ``-riser_m`` up;
    ``footholds`` of one height ``h``: ``-h``, on the scene's slope); 0.0 for the slope and
    for a profile (walked step by step, :mod:`walkerlab.analysis.gait.profile_walk`, from
    the gait of the scene's slope).

    Raises
    ------
    ValueError
        A ground whose steps differ (footholds of several heights or of their own slopes:
        :func:`foothold_steps` and :func:`walkerlab.models.hybrid.ground.on_footholds`
        walk them in the rigid model): one line naming the field and what to do
        (:data:`walkerlab.walker.capability_cells.SEVERAL_FOOTHOLDS`, the capability table's
        reason).
    """
    if terrain is None or terrain.kind == "slope":
        return 0.0
    if terrain.kind == "stairs":
        return float(terrain.riser_m) * (-1.0 if terrain.direction == "up" else 1.0)
    if terrain.kind == "footholds":
        h = set(terrain.foothold_heights_m or (0.0,))
        if terrain.foothold_slopes_rad is not None:
            raise ValueError(f"terrain.foothold_slopes_rad: {FOOTHOLD_SLOPES}")
        if len(h) == 1:
            return -float(h.pop())
        raise ValueError(f"terrain.foothold_heights_m: {SEVERAL_FOOTHOLDS}")
    # a profile: walked step by step (walkerlab.analysis.gait.profile_walk); its periodic
    # gait, the start of the walk, is the scene's slope's
    return 0.0


def landing_drops(terrain) -> tuple[float, ...]:
    """Depth [m] of each step's landing below the stance foot's level, one per step of the
    ground's period: ``(landing_drop(terrain),)`` for a ground whose every step is alike,
    ``(-h_0, -h_1, ...)`` for footholds of several heights ``terrain.foothold_heights_m``
    (the list repeats, step ``k`` landing ``-h_{k mod p}`` below the stance foot's level
    along the vertical, as the rigid model's heel strike meets it,
    :func:`walkerlab.models.hybrid.ground.on_footholds`).

    Raises
    ------
    ValueError
        Footholds of their own slopes (``terrain.foothold_slopes_rad``; one line naming
        the field, :data:`walkerlab.walker.capability_cells.FOOTHOLD_SLOPES`).
    """
    if terrain is not None and terrain.kind == "footholds" \
            and terrain.foothold_slopes_rad is None \
            and len(set(terrain.foothold_heights_m or (0.0,))) > 1:
        return tuple(-float(h) for h in terrain.foothold_heights_m)
    return (landing_drop(terrain),)


def foothold_steps(terrain, slope_rad: float) -> tuple[tuple[float, float], ...] | None:
    """``((drop_m, slope_rad), ...)``: each step's landing depth [m] below the stance foot's
    level and ground slope [rad] on footholds that differ from step to step (``terrain.kind:
    footholds`` with several heights or with ``foothold_slopes_rad``), one per step in the
    list's order; None for a ground whose every step is alike (:func:`landing_drop`).

    Parameters
    ----------
    terrain : walkerlab.config.TerrainSettings or None
    slope_rad : float
        The scene's slope [rad] (every foothold's without ``foothold_slopes_rad``).
    """
    if terrain is None or terrain.kind != "footholds":
        return None
    h, g = terrain.foothold_heights_m, terrain.foothold_slopes_rad
    if g is None and len(set(h or (0.0,))) == 1:
        return None
    n = len(h) if h else len(g)
    return tuple((-float(h[k]) if h else 0.0, float(g[k]) if g else float(slope_rad))
                 for k in range(n))


def stair_treads(terrain, first_x_m: float, n_treads: int, behind: int = 3
                 ) -> list[tuple[float, float, float]]:
    """``[(x_start, x_end, height), ...]`` [m] of stairs' level treads in the world frame,
    ``tread_m`` deep, each ``riser_m`` below (``direction: down``) or above (``up``) the
    last; tread 0 at height 0 holds the first stance foot at ``x = first_x_m``,
    ``first_foothold_m`` from its back end (default mid-tread).

    Parameters
    ----------
    terrain : walkerlab.config.TerrainSettings
        ``kind: stairs``.
    first_x_m : float
        The first stance foot's x [m].
    n_treads : int
        Treads ahead of tread 0 (the last one runs on for 100 treads' depth).
    behind : int
        Treads behind tread 0 (the first one runs back for 100 treads' depth).
    """
    D = float(terrain.tread_m)
    dh = -landing_drop(terrain)  # each tread's height above the last [m]
    u0 = D / 2 if terrain.first_foothold_m is None else float(terrain.first_foothold_m)
    x0 = float(first_x_m) - u0
    out = []
    for k in range(-int(behind), int(n_treads) + 1):
        a, b = x0 + k * D, x0 + (k + 1) * D
        if k == -int(behind):
            a -= 100.0 * D
        if k == int(n_treads):
            b += 100.0 * D
        out.append((a, b, k * dh))
    return out


@dataclass(frozen=True)
class Ground:
    """A ground of straight pieces in the world frame (x forward, y up) [m]: piece ``i``
    holds ``start[i] <= x < start[i + 1]`` (the first runs back, the last on, without end)
    and lies on the line through ``anchor[i]`` at slope ``slope[i]`` [rad] (downhill
    positive, as the scene's slope).

    Attributes
    ----------
    start : ndarray (m,)
        x where each piece begins [m], increasing (``start[0]`` is not read).
    anchor : ndarray (m, 2)
        A point of each piece's line [m].
    slope : ndarray (m,)
        Each piece's slope [rad].
    name : str
        What the ground is, for a sentence: ``slope``, ``treads``, ``footholds``,
        ``profile``, ``ground``.
    """

    start: np.ndarray
    anchor: np.ndarray
    slope: np.ndarray
    name: str = "ground"

    def piece(self, x) -> np.ndarray:
        """Index of the piece under each ``x`` [m] (ndarray of int, the shape of ``x``)."""
        i = np.searchsorted(self.start, np.asarray(x, float), side="right") - 1
        return np.clip(i, 0, self.start.size - 1)

    def clearance(self, x, y) -> np.ndarray:
        """Height [m] of the points ``(x, y)`` [m] above the piece under them, along that
        piece's normal: ``(y - y_i) cos(g_i) + (x - x_i) sin(g_i)`` for the piece's anchor
        ``(x_i, y_i)`` and slope ``g_i``; negative below the ground (shape of ``x``)."""
        x, y = np.asarray(x, float), np.asarray(y, float)
        i = self.piece(x)
        g, a = self.slope[i], self.anchor[i]
        return (y - a[..., 1]) * np.cos(g) + (x - a[..., 0]) * np.sin(g)


def _pieces(rows, name: str) -> Ground:
    """:class:`Ground` of ``[(x_start, anchor_x, anchor_y, slope), ...]``."""
    r = np.asarray(rows, float).reshape(-1, 4)
    return Ground(r[:, 0].copy(), r[:, 1:3].copy(), r[:, 3].copy(), name)


def scene_ground(terrain, slope_rad: float, footfalls=None, step_slopes=None) -> Ground:
    """The ground of a scene in the rigid run's world frame (the first stance foot at
    ``footfalls[1]``, the world origin without ``footfalls``).

    Parameters
    ----------
    terrain : walkerlab.config.TerrainSettings or None
    slope_rad : float
        The scene's slope [rad].
    footfalls : ndarray (k, 2) or (k, 3), optional
        Where the feet stood [m], in walking order: the first swing foot's start, each
        step's stance foot, the last step's landing (a walker in 3D: its ``z`` across the
        fall line, where the ground is level, not read; the contact points,
        :func:`walkerlab.analysis.gait.checks.footfalls`).  Needed for footholds and a
        drawn per-step ground (their pieces are where the feet stood).
    step_slopes : sequence of float, optional
        Each step's ground slope [rad] on footholds or a drawn per-step ground, step ``k``
        with ``footfalls[k + 1]`` in stance (the list repeats; default the scene's slope).

    Returns
    -------
    Ground
        ``slope`` (and no terrain): the scene's line through the origin.  ``stairs``: the
        treads (:func:`stair_treads`, level, tread 0 at the first stance foot).
        ``profile``: the profile's segments (its own world coordinates, as the rigid walk's,
        :mod:`walkerlab.analysis.gait.profile_walk`), the first and last running on.
        ``footholds`` (or ``step_slopes`` given): one piece per footfall, through it at its
        step's slope, from half-way to the footfall behind to half-way to the one ahead.

    Raises
    ------
    ValueError
        Footholds without ``footfalls``; a profile given only as ``profile_csv`` (one line).
    """
    kind = "slope" if terrain is None else terrain.kind
    if kind == "footholds" or step_slopes is not None:
        if footfalls is None or len(footfalls) < 2:
            raise ValueError("terrain.kind: footholds: the ground is where the feet stood "
                             "(footfalls of a run)")
        f = np.asarray(footfalls, float)
        g = list(step_slopes) if step_slopes else [float(slope_rad)]
        gk = [g[max(k - 1, 0) % len(g)] for k in range(len(f))]  # footfall k: step k - 1's
        edges = np.maximum.accumulate(np.concatenate([[-np.inf], (f[1:, 0] + f[:-1, 0]) / 2]))
        return _pieces([(edges[k], f[k, 0], f[k, 1], gk[k]) for k in range(len(f))],
                       "footholds" if kind == "footholds" else "ground")
    if kind == "stairs":
        x0, y0 = (0.0, 0.0) if footfalls is None else np.asarray(footfalls, float)[1, :2]
        n = 2 if footfalls is None else len(footfalls)
        return _pieces([(a, a, y0 + h, 0.0) for a, _b, h in stair_treads(terrain, x0, n)],
                       "treads")
    if kind == "profile":
        if terrain.profile_m is None:
            raise ValueError("terrain.profile_csv: the rigid walk reads inline profiles "
                             "(terrain.profile_m) only so far")
        P = np.asarray(terrain.profile_m, float)
        rows = [(P[j, 0] if j else -np.inf, P[j, 0], P[j, 1],
                 -math.atan((P[j + 1, 1] - P[j, 1]) / (P[j + 1, 0] - P[j, 0])))
                for j in range(len(P) - 1)]
        return _pieces(rows, "profile")
    return _pieces([(-np.inf, 0.0, 0.0, float(slope_rad))], "slope")
