"""Work-precision study: error against run time for every solver, measured honestly.

The library behind the ``workprecision`` stage (:mod:`walkerlab.stages.workprecision`, which
plans the cases from the scene, caches them and writes the artifact):

- runners (:func:`ideal_runner`, :func:`contact_runner`): ``run(method, rtol, atol) ->
  (final vector, nfev, CPU time [s])`` for the rigid hybrid walker and the compliant-contact
  walker; the CPU time is this thread's (``time.thread_time``) around the integration call
  alone (model, initial state and limits are built once, outside it), so neither set-up nor
  another process on a shared core is counted;
- timing (:func:`time_case`): a case is run ``repeats`` times (once if a run takes longer
  than :data:`SINGLE_RUN_S`), the integration's CPU time and the wall time of every run;
- where the cases run (:func:`run_cases` on :class:`walkerlab.execution.lanes.Lanes`): one
  single-threaded worker process per core, pinned to it (``os.sched_setaffinity``), so a
  timed case never shares its core with another case; each worker runs every method once,
  untimed, over one stride before timing (compiled code is loaded from the on-disk caches,
  not timed), then freezes its heap for the garbage collector;
- the Pareto front and the fastest setting (:func:`pareto_front`, :func:`summarize`), both
  only where the settings' CPU times differ by more than the spread of their repeats.
"""

from __future__ import annotations

import gc
import json
import os
import threading
import time
from pathlib import Path
from typing import NamedTuple

import numpy as np

from walkerlab.execution.lanes import Lanes, pinned_worker, run_on_lanes

CYRK_PREFIX = "CyRK "


def ideal_runner(scene, x0: np.ndarray, strides: int):
    """``run(method, rtol, atol) -> (final vector, nfev, CPU time [s])`` for the rigid
    hybrid walker.

    ``method`` is a ``solve_ivp`` method, or ``"CyRK <method>"`` for CyRK's integrator; the
    final vector is the state and time at the last of ``2 * strides`` heel strikes
    (shape (2n + 1,)), None if the run did not end in a heel strike; the CPU time is the
    thread's around :func:`walkerlab.integrate.rigid.simulate_steps` alone.
    """
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    walker = build_walker(scene)

    def run(method, rtol, atol):
        backend = "scipy"
        if method.startswith(CYRK_PREFIX):
            method, backend = method[len(CYRK_PREFIX):], "cyrk"
        solver = Solver(method, rtol, atol, None, backend)
        c0 = time.thread_time()
        tr = simulate_steps(walker, x0, 2 * strides, solver)
        cpu = time.thread_time() - c0
        seg = tr.segments[-1]
        if seg.termination != "heel_strike":
            return None, tr.nfev, cpu
        return np.concatenate([seg.x_end, [seg.t_end]]), tr.nfev, cpu
    return run


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


#: a run longer than this [s] is timed once: the timer's resolution and start-up jitter are
#: < 0.1 % of it, and a repeat would cost as much as the whole rest of the study
SINGLE_RUN_S = 1.0


def time_case(runner, method: str, rtol: float, atol: float, repeats: int) -> dict:
    """Run one case up to ``repeats`` times (once if the first run takes longer than
    :data:`SINGLE_RUN_S` of CPU time): final vector (or None), nfev, the CPU times of the
    integration alone (``cpu_times``, the runner's ``time.thread_time`` around its
    integration call) and the wall times of the whole runner call (``times``) [s].  A run
    that raised is timed by the thread's CPU time around the whole call."""
    times, cpu, vec, nfev = [], [], None, 0
    for _ in range(repeats):
        if cpu and cpu[0] > SINGLE_RUN_S:
            break
        t0, c0 = time.perf_counter(), time.thread_time()
        try:
            vec, nfev, c = runner(method, rtol, atol)
        except Exception:
            vec, c = None, time.thread_time() - c0
        cpu.append(float(c))
        times.append(time.perf_counter() - t0)
    return {"vec": None if vec is None else [float(v) for v in vec], "nfev": int(nfev),
            "times": times, "cpu_times": cpu, "clock": "thread_cpu_integration"}


def contact_runner(scene, x0: np.ndarray, step_period: float, strides: int):
    """``run(method, rtol, atol) -> (final vector, nfev, CPU time [s])`` for the
    compliant-contact walker started from the rigid walker's fixed point ``x0`` (step period
    ``step_period`` [s]).

    The final vector is the leg angles [rad] and rates [rad/s] at the final time, read by
    name from the contact walker's state, None unless the run reached its final time.  The
    walker, its initial state and run limits are built once
    (:func:`walkerlab.analysis.contact_sim.scene_start`); the CPU time is the thread's
    around :func:`walkerlab.analysis.contact_sim.simulate_contact` alone.
    """
    from walkerlab.analysis.contact_bench import leg_angle_columns
    from walkerlab.analysis.contact_sim import scene_start, simulate_contact
    from walkerlab.config import SolverSettings
    from walkerlab.integrate.contact import StateIndex
    from walkerlab.models.contact.scene import contact_setup

    setup = contact_setup(scene)
    cs = setup.sim
    walker, z0, limits, _ = scene_start(setup, x0, strides)
    t_final = cs.t_final_s or (2 * strides + 0.5) * step_period
    max_hs = 2 * strides + 1 if cs.stop_after_strides else None
    idx = StateIndex(walker)
    legs = leg_angle_columns(walker)
    rates = [idx.rate_of(idx.names[i]) for i in legs]

    def run(method, rtol, atol):
        sv = SolverSettings.for_contact(method=method, rtol=rtol, atol=atol)
        c0 = time.thread_time()
        res = simulate_contact(walker, z0, t_final, sv, limits, max_heel_strikes=max_hs)
        cpu = time.thread_time() - c0
        if res.termination != "t_final":
            return None, res.nfev, cpu
        return np.concatenate([res.x[-1, legs], res.x[-1, rates]]), res.nfev, cpu
    return run


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


def study(runner, methods, rtols, atol_factor, repeats, reference) -> dict:
    """Run every (method, rtol) here; returns :func:`rows_from_cases`'s rows."""
    cases = {(m, r): time_case(runner, m, r, atol_factor * r, repeats)
             for m in methods for r in rtols}
    return rows_from_cases(cases, methods, rtols, reference)


# ------------------------------------------------------------------ cached, parallel cases
class Case(NamedTuple):
    """One timed case (picklable: it travels to a worker process)."""

    key: str
    model: str
    scene_json: str
    #: the rigid walker's step period [s] (sets the contact model's simulated time)
    step_period: float
    x0: tuple
    strides: int
    method: str
    rtol: float
    atol: float
    repeats: int
    #: ``((method, rtol, atol), ...)`` run once each, untimed, over :data:`WARM_STRIDES`
    #: strides when a worker builds the model's runner: loading compiled code (numba's
    #: on-disk cache, CyRK's compiled right-hand sides, generated model code) and first-call
    #: set-up then stay out of every timed run
    warm: tuple


#: strides of the untimed warm-up runs (one heel strike at least: every code path)
WARM_STRIDES = 1
_RUNNERS: dict = {}


def _build_runner(model: str, scene_json: str, step_period: float, x0: tuple, strides: int):
    from walkerlab.config import scene_from_dict

    scene = scene_from_dict(json.loads(scene_json))
    if model == "ideal":
        return ideal_runner(scene, np.asarray(x0), strides)
    return contact_runner(scene, np.asarray(x0), step_period, strides)


def runner_for(model: str, scene_json: str, step_period: float, x0: tuple, strides: int,
               warm: tuple = ()):
    """The runner of ``model`` (``"ideal"`` or ``"contact"``), built once per process
    after the untimed ``warm`` runs (``((method, rtol, atol), ...)``, over
    :data:`WARM_STRIDES` strides); the heap is then frozen for the garbage collector."""
    key = (model, scene_json, step_period, x0, strides)
    if key not in _RUNNERS:
        _RUNNERS.clear()
        if warm:
            w = _build_runner(model, scene_json, step_period, x0, WARM_STRIDES)
            for case in warm:
                try:
                    w(*case)
                except Exception:  # noqa: BLE001 - the timed runs report failures
                    pass
        _RUNNERS[key] = _build_runner(model, scene_json, step_period, x0, strides)
        # what is loaded now lives as long as the worker: no collector passes over it
        # inside timed runs (they made a run up to ~1.8x slower, depending on history)
        gc.collect()
        gc.freeze()
    return _RUNNERS[key]


def _run_case(task: Case) -> tuple:
    """Worker: ``task`` -> ``(task.key, result)`` (see :func:`time_case`)."""
    runner = runner_for(task.model, task.scene_json, task.step_period, task.x0, task.strides,
                        task.warm)
    return task.key, time_case(runner, task.method, task.rtol, task.atol, task.repeats)


def load_libraries() -> None:
    """Lane worker warm-up (after pinning): load the libraries the runners use."""
    import scipy.integrate  # noqa: F401
    import scipy.optimize  # noqa: F401

    from walkerlab.integrate.solver import available_backends

    if "cyrk" in available_backends():
        from walkerlab.usercache import use_for_numba

        use_for_numba()  # numba's cache in the user cache (before numba loads)
        import CyRK  # noqa: F401  (and numba)


def start_worker(core: int):
    """A measuring worker process pinned to ``core``, started now
    (:func:`walkerlab.execution.lanes.pinned_worker`; see :class:`Lanes`)."""
    return pinned_worker(core, load_libraries)


#: scipy's implicit methods: the slow cases, started first so the lanes finish together
IMPLICIT = ("Radau", "BDF")


def _cost_order(t: Case) -> tuple:
    """Longest first (measured: implicit methods at tight tolerances, then the contact
    model), so the last cases to finish are short ones."""
    base = t.method.removeprefix(CYRK_PREFIX)
    return (base not in IMPLICIT, round(float(np.log10(t.rtol)), 3), t.model != "contact")


def _numbers(v, n: int | None = None) -> bool:
    return (isinstance(v, list) and (n is None or len(v) == n)
            and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v))


def read_cached_case(path: Path) -> dict | None:
    """A cached case result (:func:`time_case`) if the file holds a complete one, else None
    (missing, unreadable, not JSON, or lacking/mistyping a field: the case is measured
    again, issue 19)."""
    from walkerlab.safefs import read_regular

    try:
        res = json.loads(read_regular(path, 1 << 20, "cache entry"))
    except (OSError, ValueError):  # missing, not a bounded regular file, not JSON
        return None
    if not isinstance(res, dict):
        return None
    times, cpu, vec = res.get("times"), res.get("cpu_times"), res.get("vec")
    ok = (res.get("clock") == "thread_cpu_integration"
          and _numbers(times) and len(times) >= 1 and all(x >= 0 for x in times)
          and _numbers(cpu, len(times)) and (vec is None or (_numbers(vec) and len(vec) >= 1))
          and isinstance(res.get("nfev"), int) and not isinstance(res.get("nfev"), bool))
    return res if ok else None


def run_cases(tasks: list[Case], cache_dir: Path, workers: int = 2,
              lanes: Lanes | None = None, on_case=None) -> dict:
    """Results of every case, from the cache or measured (in pinned worker processes).

    Parameters
    ----------
    tasks : list of Case
    cache_dir : Path
        One JSON file per case key.
    workers : int
        Lanes when ``lanes`` is None: one per core of this process's affinity (1, or fewer
        cores than workers: every case in this process, one after the other).
    lanes : Lanes, optional
        Explicit cores, gates and pending models (``walkerlab report``).
    on_case : callable(done, total), optional
        Progress: called with ``(0, cases to measure)`` once the cache was read, then after
        each measured case (from the lanes' threads).

    Returns
    -------
    dict
        ``{case_key: result}`` (see :func:`time_case`), each with ``"cached": bool``.
    """
    cache_dir.mkdir(parents=True, exist_ok=True)
    out, todo = {}, []
    for t in tasks:
        res = read_cached_case(cache_dir / f"{t.key}.json")
        if res is not None:
            out[t.key] = {**res, "cached": True}
        else:  # missing, damaged or incomplete: measured again
            todo.append(t)
    n_todo, n_done = len(todo), [0]
    if on_case is not None:
        on_case(0, n_todo)
    if lanes is not None:
        lanes.todo_models.update(t.model for t in todo)
        lanes.todo_known.set()
    lock = threading.Lock()

    def store(key, res, n_lanes):
        res = {**res, "measured_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
               "parallel_workers": n_lanes}
        from walkerlab.io.artifacts import atomic_write

        text = json.dumps(res).encode()
        atomic_write(cache_dir / f"{key}.json", lambda fh: fh.write(text))
        with lock:
            out[key] = {**res, "cached": False}
            n_done[0] += 1
        if on_case is not None:
            on_case(n_done[0], n_todo)

    if lanes is None:
        cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
        if workers <= 1 or len(todo) <= 1 or len(cores) < workers:
            for t in sorted(todo, key=_cost_order):
                store(*_run_case(t), 1)
            return out
        lanes = Lanes(cores=cores[:workers])
    if not todo:
        return out
    todo.sort(key=_cost_order)
    run_on_lanes(lanes, todo, _run_case, lambda kr: store(*kr, len(lanes.cores)),
                 group=lambda t: t.model, warm=load_libraries, name="workprecision")
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
