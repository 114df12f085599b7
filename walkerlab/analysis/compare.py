"""Compare two named trajectories (paper Fig. 8, Table 3)."""

from __future__ import annotations

import numpy as np

from walkerlab.io.trajectory import NamedTrajectory


def aligned_errors(ref: NamedTrajectory, other: NamedTrajectory):
    """Errors ``other - ref`` of angles [rad] and rates [rad/s], on ``ref``'s time grid.

    ``other`` is linearly interpolated onto the reference sample times within the common time
    span (both runs start at t = 0 from the same state). Samples exactly at an impact appear
    twice in the ideal trajectory (pre/post), so the reference grid is made strictly
    increasing by dropping the duplicate post-impact time.

    Returns
    -------
    time : ndarray (k,)
    angle_err, rate_err : dict[leg, ndarray (k,)]
    """
    t_end = min(ref.time[-1], other.time[-1])
    keep = (ref.time <= t_end) & np.concatenate([[True], np.diff(ref.time) > 0])
    t = ref.time[keep]
    _, first = np.unique(other.time, return_index=True)
    ang = {leg: np.interp(t, other.time[first], other.angle[leg][first]) - ref.angle[leg][keep]
           for leg in ref.legs}
    rat = {leg: np.interp(t, other.time[first], other.rate[leg][first]) - ref.rate[leg][keep]
           for leg in ref.legs}
    return t, ang, rat


def limit_cycle_distance(ref: NamedTrajectory, other: NamedTrajectory, leg: str,
                         rate_scale: float = 1.0) -> float:
    """Mean distance [rad-equivalent] from the ``ref`` limit cycle of ``leg`` to the nearest
    point of ``other``'s phase curve, in the (angle, rate * rate_scale) plane."""
    a = np.vstack([ref.angle[leg], ref.rate[leg] * rate_scale]).T
    b = np.vstack([other.angle[leg], other.rate[leg] * rate_scale]).T
    if a.size == 0 or b.size == 0:
        return float("nan")
    step = max(1, b.shape[0] // 4000)
    b = b[::step]
    d = np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(-1)).min(axis=1)
    return float(np.mean(d))
