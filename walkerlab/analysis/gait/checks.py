"""Checks of a rigid run's trajectory the report states: energy drift between impacts and
the swing foot's clearance above the slope."""

from __future__ import annotations

import numpy as np

from walkerlab.io.trajectory import NamedTrajectory


def energy_drift_in_swing(tr: NamedTrajectory) -> tuple[float, float]:
    """Largest change of the total energy within a continuous phase [J] and relative [-].

    A passive rigid walker conserves energy between impacts (heel strike, knee strike), so
    this measures the integration error.
    """
    tot, step = tr.total, tr.step_index
    phase = tr.phase if tr.phase is not None else np.zeros_like(step)
    key = step.astype(np.int64) * 1000 + phase
    drift = max(float(np.ptp(tot[key == k])) for k in np.unique(key))
    return drift, drift / float(np.max(np.abs(tot)))


def swing_foot_clearance(tr: NamedTrajectory, slope_rad: float, margin: float = 0.1) -> float:
    """Lowest height [m] of the swing foot above the slope inside the steps of ``tr``.

    Heights are normal to the slope through the first stance foot; the first and last
    ``margin`` of each step (lift-off, heel strike, where the height is ~0) are left out.
    A negative value means the foot passes through the ground (scuffing, which the rigid
    model ignores).  Round feet use the ``<leg>_contact`` point when the walker has one.
    """
    lowest = np.inf
    for k in np.unique(tr.step_index):
        m = tr.step_index == k
        t = tr.time[m]
        inner = (t > t[0] + margin * (t[-1] - t[0])) & (t < t[-1] - margin * (t[-1] - t[0]))
        swing = tr.legs[1 - int(tr.stance_leg[m][0])] if len(tr.legs) == 2 else None
        if swing is None or not inner.any():
            continue
        foot = tr.points.get(f"{swing}_contact", tr.points.get(f"{swing}_foot"))
        if foot is None:
            continue
        xy = foot[:, m][:, inner]
        h = xy[1] * np.cos(slope_rad) + xy[0] * np.sin(slope_rad)
        lowest = min(lowest, float(np.min(h)))
    return lowest
