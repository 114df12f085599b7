"""Compare two named trajectories (paper Fig. 8, Table 3), coordinate by coordinate."""

from __future__ import annotations

import numpy as np

from walkerlab.io.trajectory import NamedTrajectory


def aligned_errors(ref: NamedTrajectory, other: NamedTrajectory):
    """Errors ``other - ref`` of every coordinate both trajectories have, on ``ref``'s grid.

    ``other`` is linearly interpolated onto the reference sample times within the common time
    span (both runs start at t = 0 from the same state). Samples exactly at an impact appear
    twice in the ideal trajectory (pre/post), so the reference grid is made strictly
    increasing by dropping the duplicate post-impact time.

    Returns
    -------
    time : ndarray (k,)
        Reference sample times [s].
    errors : dict[name, ndarray (k,)]
        Per coordinate, in the coordinate's unit (``ref.units``), in ``ref``'s order.
    """
    t_end = min(ref.time[-1], other.time[-1])
    keep = (ref.time <= t_end) & np.concatenate([[True], np.diff(ref.time) > 0])
    t = ref.time[keep]
    _, first = np.unique(other.time, return_index=True)
    err = {n: np.interp(t, other.time[first], other.coordinates[n][first]) - v[keep]
           for n, v in ref.coordinates.items() if n in other.coordinates}
    return t, err


def limit_cycle_distance(ref: NamedTrajectory, other: NamedTrajectory, angle: str, rate: str,
                         rate_scale: float = 1.0) -> float:
    """Mean distance from the ``ref`` limit cycle in the (``angle``, ``rate`` * rate_scale)
    plane to the nearest point of ``other``'s phase curve [rad-equivalent]."""
    a = np.vstack([ref.coordinates[angle], ref.coordinates[rate] * rate_scale]).T
    b = np.vstack([other.coordinates[angle], other.coordinates[rate] * rate_scale]).T
    if a.size == 0 or b.size == 0:
        return float("nan")
    step = max(1, b.shape[0] // 4000)
    b = b[::step]
    from scipy.spatial import cKDTree  # nearest neighbours in O(n log n), not an (n, m) table

    d, _ = cKDTree(b).query(a)
    return float(np.mean(d))
