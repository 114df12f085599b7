"""The results of a work-precision study (:mod:`walkerlab.bench.workprecision`): the rows
of the measured cases (median CPU time, its spread over the repeats, the error against the
reference), the Pareto front and the fastest setting reaching the target error, both only
where the settings' CPU times differ by more than the spread of their repeats.
"""

from __future__ import annotations

import numpy as np

__all__ = ["pareto_front", "rows_from_cases", "summarize"]


def pareto_front(times: np.ndarray, errors: np.ndarray, time_min: np.ndarray | None = None,
                 time_max: np.ndarray | None = None) -> np.ndarray:
    """Indices of the non-dominated points, ordered by time.

    Without a spread: a point stays unless another is at most as slow and at least as
    accurate (one of the two strictly).  With the spread of the repeats (``time_min``,
    ``time_max``, shape like ``times`` [s]), times are compared only beyond it: point ``j``
    dominates ``i`` when it is at least as accurate and either clearly faster
    (``time_max[j] < time_min[i]``) or indistinguishable in time (the ranges overlap) and
    strictly more accurate.  So the front never holds two settings whose time ranges
    overlap (the less accurate of them is dominated), and a point is not dropped for a
    difference in time that lies inside the timing noise.
    """
    t = np.asarray(times, float)
    e = np.asarray(errors, float)
    lo = t if time_min is None else np.asarray(time_min, float)
    hi = t if time_max is None else np.asarray(time_max, float)
    keep = []
    for i in np.argsort(t, kind="stable"):
        if not np.isfinite(e[i]):
            continue
        if time_min is None and time_max is None:
            dominated = any(np.isfinite(e[j]) and e[j] <= e[i] and t[j] <= t[i]
                            and (e[j] < e[i] or t[j] < t[i]) for j in range(t.size) if j != i)
        else:
            dominated = any(
                np.isfinite(e[j]) and e[j] <= e[i]
                and (hi[j] < lo[i] or (e[j] < e[i] and lo[j] <= hi[i] and lo[i] <= hi[j]))
                for j in range(t.size) if j != i)
        if not dominated:
            keep.append(int(i))
    return np.asarray(keep, dtype=int)


def rows_from_cases(cases: dict, methods, rtols, reference) -> dict:
    """``{method: {rtol, time, time_min, time_max, wall_time, error, nfev, repeats}}``
    (arrays over ``rtols``; ``time`` is the median CPU time of the integration over the
    repeats, ``time_min``/``time_max`` their spread, ``wall_time`` the median wall time)
    from ``{(method, rtol): time_case result}``; the error is the max-norm distance of the
    final vector from ``reference`` (inf where the run failed)."""
    out = {}
    for m in methods:
        rows = {"rtol": [], "time": [], "time_min": [], "time_max": [], "wall_time": [],
                "error": [], "nfev": [], "repeats": []}
        for rtol in rtols:
            c = cases[(m, rtol)]
            vec = c["vec"]
            rows["rtol"].append(rtol)
            rows["time"].append(float(np.median(c["cpu_times"])))
            rows["time_min"].append(float(np.min(c["cpu_times"])))
            rows["time_max"].append(float(np.max(c["cpu_times"])))
            rows["wall_time"].append(float(np.median(c["times"])))
            rows["error"].append(np.inf if vec is None
                                 else float(np.max(np.abs(np.asarray(vec) - reference))))
            rows["nfev"].append(c["nfev"])
            rows["repeats"].append(len(c["times"]))
        out[m] = {k: np.asarray(v) for k, v in rows.items()}
    return out


def summarize(rows: dict, target: float) -> dict:
    """Pareto front, and the fastest setting reaching ``target`` when the timings can tell.

    Parameters
    ----------
    rows : dict
        :func:`rows_from_cases` output (``time`` the median, ``time_min``/``time_max`` the
        spread of the repeats; rows without a spread count as one run).
    target : float
        Error a setting must reach [rad, rad/s].

    Returns
    -------
    dict
        ``pareto``: ``[(method, rtol, median time, error)]``; ``best``: the setting with the
        smallest median time among those reaching ``target`` (None if none does);
        ``separated``: whether that choice exceeds the timing noise: its slowest run is
        faster than the fastest run of every other setting reaching the target, each
        measured at least twice (or it is the only one reaching it); ``tied``: the settings
        the timings cannot separate from ``best`` (``best`` first), each
        ``(method, rtol, min, median, max time, repeats)``.
    """
    meth = [m for m in rows for _ in rows[m]["rtol"]]
    cat = {k: np.concatenate([np.asarray(rows[m].get(k, rows[m]["time"]), float)
                              for m in rows]) for k in ("rtol", "time", "time_min",
                                                        "time_max", "error")}
    reps = np.concatenate([np.asarray(rows[m].get("repeats", np.ones(len(rows[m]["rtol"]))))
                           for m in rows])
    rt, tt, ee = cat["rtol"], cat["time"], cat["error"]
    lo, hi = cat["time_min"], cat["time_max"]
    idx = pareto_front(tt, ee, lo, hi)
    ok = np.flatnonzero(ee <= target)
    best = int(ok[np.argmin(tt[ok])]) if ok.size else None
    tied, separated = [], False
    if best is not None:
        others = [int(j) for j in ok[np.argsort(tt[ok], kind="stable")] if j != best]
        overlap = [j for j in others if lo[j] <= hi[best]]
        measured = reps[best] >= 2 and (not others or reps[others[0]] >= 2)
        separated = not overlap and measured
        if not separated:
            tied = [best, *(overlap or others[:1])]

    def case(i):
        return (meth[i], float(rt[i]), float(lo[i]), float(tt[i]), float(hi[i]), int(reps[i]))
    return {"pareto": [(meth[i], float(rt[i]), float(tt[i]), float(ee[i])) for i in idx],
            "best": None if best is None else (meth[best], float(rt[best]), float(tt[best]),
                                               float(ee[best])),
            "separated": bool(separated),
            "best_spread": None if best is None else case(best),
            "tied": [case(i) for i in tied]}
