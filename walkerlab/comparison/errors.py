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


def phase_aligned_errors(ref: NamedTrajectory, other: NamedTrajectory, n_per_step: int = 100):
    """Errors ``other - ref`` with each step on normalised step time (the phase, not the
    clock: two gaits of different step periods are compared at the same fraction of the
    same step).

    Step ``k`` of a trajectory runs from its first sample with ``step_index == k`` to the first
    sample of step ``k + 1`` (its heel strike); steps that both trajectories complete are
    compared.  On each, both are interpolated linearly at ``n_per_step`` equally spaced
    fractions ``s`` in [0, 1) of the step's duration.

    Returns
    -------
    step_phase : ndarray (m,)
        ``k + s`` [-] (step number plus the fraction of the step), m = n_steps * n_per_step.
    errors : dict[name, ndarray (m,)]
        Per coordinate both have, in the coordinate's unit (``ref.units``).
    """
    def bounds(tr):
        steps = np.unique(tr.step_index)
        starts = {int(k): float(tr.time[np.argmax(tr.step_index == k)]) for k in steps}
        return {k: (starts[k], starts[k + 1]) for k in starts if k + 1 in starts}

    br, bo = bounds(ref), bounds(other)
    common = sorted(set(br) & set(bo))
    s = np.arange(n_per_step) / n_per_step
    phase = np.concatenate([k + s for k in common]) if common else np.zeros(0)
    names = [n for n in ref.coordinates if n in other.coordinates]
    err = {n: [] for n in names}
    for k in common:
        tr_ = br[k][0] + s * (br[k][1] - br[k][0])
        to_ = bo[k][0] + s * (bo[k][1] - bo[k][0])
        for n in names:
            err[n].append(_interp(other, n, to_) - _interp(ref, n, tr_))
    return phase, {n: np.concatenate(v) if v else np.zeros(0) for n, v in err.items()}


def _interp(tr: NamedTrajectory, name: str, t):
    """``tr``'s coordinate at times ``t`` (at a repeated impact time: the later, post-impact
    sample)."""
    rev_t = tr.time[::-1]
    _, last = np.unique(rev_t, return_index=True)
    idx = len(tr.time) - 1 - last
    return np.interp(t, tr.time[idx], tr.coordinates[name][idx])
