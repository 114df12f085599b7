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
- the rows of the study, its Pareto front and the fastest setting:
  :mod:`walkerlab.bench.workprecision_results`.
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

from walkerlab.analysis.contact.sim import scene_start, simulate_contact
from walkerlab.bench.contact import leg_angle_columns
from walkerlab.config import SolverSettings, scene_from_dict
from walkerlab.execution.lanes import Lanes, pinned_worker, run_on_lanes
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver, available_backends
from walkerlab.models.contact.scene import contact_setup
from walkerlab.safefs import read_regular
from walkerlab.usercache import use_for_numba
from walkerlab.walker.layout import StateIndex
from walkerlab.walker.plant import Plant

CYRK_PREFIX = "CyRK "


def ideal_runner(scene, x0: np.ndarray, strides: int):
    """``run(method, rtol, atol) -> (final vector, nfev, CPU time [s])`` for the rigid
    hybrid walker.

    ``method`` is a ``solve_ivp`` method, or ``"CyRK <method>"`` for CyRK's integrator; the
    final vector is the state and time at the last of ``2 * strides`` heel strikes
    (shape (2n + 1,)), None if the run did not end in a heel strike; the CPU time is the
    thread's around :func:`walkerlab.integrate.rigid.simulate_steps` alone.
    """
    from walkerlab.models.registry import build_walker

    walker = build_walker(Plant.from_scene(scene))

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
    (:func:`walkerlab.analysis.contact.sim.scene_start`); the CPU time is the thread's
    around :func:`walkerlab.analysis.contact.sim.simulate_contact` alone.
    """
    setup = contact_setup(scene, plant=Plant.from_scene(scene))
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


# ------------------------------------------------------------------ cached, parallel cases
class Case(NamedTuple):
    """One timed case (picklable: it travels to a worker process).

    ``x0`` is the start state as a tuple of 2n floats (the rigid walker's ``state_names()``,
    [rad, rad/s]); ``rtol`` [-] and ``atol`` [rad, rad/s] the integrator's tolerances.
    """

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

    if "cyrk" in available_backends():
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
    again)."""
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
        from walkerlab.io.artifacts import atomic_write  # light

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
