"""The ground's facts both views of a walker read (the rigid hybrid model,
:mod:`walkerlab.models.hybrid.ground`, and the compliant-contact model's terrain,
:mod:`walkerlab.models.contact.terrain`): how far below the stance foot's level each step
lands, from the scene's ``terrain`` section alone.

A stair ``riser_m`` down is a landing ``riser_m`` below the stance foot's level (up: above
it); footholds of one height ``h`` a landing at ``-h``; footholds of several heights or of
their own slopes are one landing per step (:func:`foothold_steps`); the slope and a height
profile (walked step by step from the slope's gait) land on the slope's line.
"""

from __future__ import annotations

__all__ = ["foothold_steps", "landing_drop"]


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
        walk them): one line.
    """
    if terrain is None or terrain.kind == "slope":
        return 0.0
    if terrain.kind == "stairs":
        return float(terrain.riser_m) * (-1.0 if terrain.direction == "up" else 1.0)
    if terrain.kind == "footholds":
        h = set(terrain.foothold_heights_m or (0.0,))
        if terrain.foothold_slopes_rad is not None:
            raise ValueError("terrain.foothold_slopes_rad: footholds of their own slopes "
                             "differ from step to step: not one landing for every step (the "
                             "rigid model walks them, one walker per step)")
        if len(h) == 1:
            return -float(h.pop())
        raise ValueError("terrain.foothold_heights_m: footholds of different heights "
                         "differ from step to step: not one landing for every step (the "
                         "rigid model walks them, one walker per step)")
    # a profile: walked step by step (walkerlab.analysis.gait.profile_walk); its periodic
    # gait, the start of the walk, is the scene's slope's
    return 0.0


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
