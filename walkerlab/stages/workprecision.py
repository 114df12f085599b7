"""Stage ``workprecision``: error against run time for every solver (work-precision diagram).

For each model and each scipy method and tolerance, the run is repeated ``repeats`` times
(the median wall time is kept) and its error is measured against a tightly converged
reference (DOP853 at ``reference_rtol`` for the ideal model, CyRK's when installed;
odeint/LSODA at ``contact_reference_rtol`` for the contact model, whose atol is 1e-2 * rtol
because its positions are sub-millimetre penetrations).  The ideal model's error is the
max-norm of the difference of the state and time at the last heel strike; the contact
model's error is the max-norm of the leg angles [rad] and rates [rad/s] at the final time.
The artifact stores every point, the Pareto front (no other setting is both faster and more
accurate) and the Pareto-best setting: the fastest one whose error is below
``target_error``.

Speed of the study itself (issue 10), without dropping a method or a tolerance:

- every case (model, method, tolerance) is cached on its own under
  ``runs/<scene>/.cache/workprecision/`` (key: the model's scene sections, the fixed point,
  the case and the sources it runs, :data:`CASE_SOURCES`); a rerun after an unrelated change
  (another target error, a new tolerance, the contact section only, report code) measures
  only what is new;
- the cases run on worker processes ("lanes", :class:`Lanes`), each pinned to its own core
  (``os.sched_setaffinity``) and single-threaded, so a case never shares its core with
  another case; both the wall time and the process CPU time of every run are stored (the
  diagram uses the wall time; on a machine with other load the CPU time is the honest
  figure: ``cpu_time``).  ``walkerlab report`` starts the study right after the fixed point
  with one lane and runs its untimed stages (contact-sim, compare, figures) on the other
  core, whose lane starts once they are done;
- each worker runs every method of a model once, untimed, over one stride before timing
  (compiled code is loaded from the on-disk caches, not timed), and a run longer than
  :data:`SINGLE_RUN_S` is timed once;
- the ideal model is also integrated with CyRK's DOP853/RK45 (group ``CyRK <method>``),
  next to scipy's ``solve_ivp`` methods, which is the integrator benchmark of the project.
"""

from __future__ import annotations

import gc
import hashlib
import json
import os
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import numpy as np

from walkerlab.analysis.hybrid import Solver, simulate_steps
from walkerlab.config import Scene
from walkerlab.io.artifacts import put
from walkerlab.models.registry import build_walker
from walkerlab.stages import fixedpoint as fixedpoint_stage
from walkerlab.stages.common import StageOutcome, artifact_path, require, run_cached

SECTIONS = ("walker", "slope", "ideal", "fixedpoint", "workprecision", "contact", "terrain",
            "contact_sim")


CYRK_PREFIX = "CyRK "


def ideal_runner(scene: Scene, x0: np.ndarray, strides: int):
    """``run(method, rtol, atol) -> (final vector, nfev)`` for the rigid hybrid walker.

    ``method`` is a ``solve_ivp`` method, or ``"CyRK <method>"`` for CyRK's integrator.
    """
    walker = build_walker(scene)

    def run(method, rtol, atol):
        backend = "scipy"
        if method.startswith(CYRK_PREFIX):
            method, backend = method[len(CYRK_PREFIX):], "cyrk"
        tr = simulate_steps(walker, x0, 2 * strides, Solver(method, rtol, atol, None, backend))
        seg = tr.segments[-1]
        if seg.termination != "heel_strike":
            return None, tr.nfev
        return np.concatenate([seg.x_end, [seg.t_end]]), tr.nfev
    return run


def pareto_front(times: np.ndarray, errors: np.ndarray) -> np.ndarray:
    """Indices of the non-dominated points (faster *and* more accurate than no other)."""
    order = np.argsort(times, kind="stable")
    best = np.inf
    keep = []
    for i in order:
        if np.isfinite(errors[i]) and errors[i] < best:
            keep.append(i)
            best = errors[i]
    return np.asarray(keep, dtype=int)


#: a run longer than this [s] is timed once: the timer's resolution and start-up jitter are
#: < 0.1 % of it, and a repeat would cost as much as the whole rest of the study
SINGLE_RUN_S = 1.0


def time_case(runner, method: str, rtol: float, atol: float, repeats: int) -> dict:
    """Run one case up to ``repeats`` times (once if the first run takes longer than
    :data:`SINGLE_RUN_S`): final vector (or None), nfev, wall and CPU times [s]."""
    times, cpu, vec, nfev = [], [], None, 0
    for _ in range(repeats):
        if times and times[0] > SINGLE_RUN_S:
            break
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            vec, nfev = runner(method, rtol, atol)
        except Exception:
            vec = None
        cpu.append(time.process_time() - c0)
        times.append(time.perf_counter() - t0)
    return {"vec": None if vec is None else [float(v) for v in vec], "nfev": int(nfev),
            "times": times, "cpu_times": cpu}


def _rows(cases: dict, methods, rtols, reference) -> dict:
    out = {}
    for m in methods:
        rows = {"rtol": [], "time": [], "cpu_time": [], "error": [], "nfev": [], "repeats": []}
        for rtol in rtols:
            c = cases[(m, rtol)]
            vec = c["vec"]
            rows["rtol"].append(rtol)
            rows["time"].append(float(np.median(c["times"])))
            rows["cpu_time"].append(float(np.median(c["cpu_times"])))
            rows["error"].append(np.inf if vec is None
                                 else float(np.max(np.abs(np.asarray(vec) - reference))))
            rows["nfev"].append(c["nfev"])
            rows["repeats"].append(len(c["times"]))
        out[m] = {k: np.asarray(v) for k, v in rows.items()}
    return out


def study(runner, methods, rtols, atol_factor, repeats, reference) -> dict:
    """Run every (method, rtol) here; returns ``{method: {rtol, time, cpu_time, error, nfev}}``."""
    cases = {(m, r): time_case(runner, m, r, atol_factor * r, repeats)
             for m in methods for r in rtols}
    return _rows(cases, methods, rtols, reference)


# ------------------------------------------------------------------ cached, parallel cases
class Case(NamedTuple):
    """One timed case (picklable: it travels to a worker process)."""

    key: str
    model: str
    scene_json: str
    runs_root: str
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


def _build_runner(model: str, scene_json: str, runs_root: str, x0: tuple, strides: int):
    from walkerlab.config import scene_from_dict

    scene = scene_from_dict(json.loads(scene_json))
    if model == "ideal":
        return ideal_runner(scene, np.asarray(x0), strides)
    from walkerlab.stages.contact_sim import workprecision_runner

    return workprecision_runner(scene, runs_root, np.asarray(x0), strides)


def _runner_for(model: str, scene_json: str, runs_root: str, x0: tuple, strides: int,
                warm: tuple = ()):
    key = (model, scene_json, runs_root, x0, strides)
    if key not in _RUNNERS:
        _RUNNERS.clear()
        if warm:
            w = _build_runner(model, scene_json, runs_root, x0, WARM_STRIDES)
            for case in warm:
                try:
                    w(*case)
                except Exception:  # noqa: BLE001 - the timed runs report failures
                    pass
        _RUNNERS[key] = _build_runner(model, scene_json, runs_root, x0, strides)
        # what is loaded now lives as long as the worker: no collector passes over it
        # inside timed runs (they made a run up to ~1.8x slower, depending on history)
        gc.collect()
        gc.freeze()
    return _RUNNERS[key]


def _run_case(task: Case) -> tuple:
    """Worker: ``task`` -> ``(task.key, result)`` (see :func:`time_case`)."""
    runner = _runner_for(task.model, task.scene_json, task.runs_root, task.x0, task.strides,
                         task.warm)
    return task.key, time_case(runner, task.method, task.rtol, task.atol, task.repeats)


def _pin_worker(core: int) -> None:
    """Worker initializer: stay on ``core`` (the BLAS/OpenMP thread counts are set to 1 in
    the environment the worker was started with, see :func:`_pinned_worker`), then load the
    libraries the runners use (a worker started ahead does this while its caller works)."""
    try:
        os.sched_setaffinity(0, {core})
    except Exception:  # noqa: BLE001 - pinning is best effort (not on every OS)
        pass
    import scipy.integrate  # noqa: F401
    import scipy.optimize  # noqa: F401

    from walkerlab.analysis.hybrid import _have_cyrk

    if _have_cyrk():
        import CyRK  # noqa: F401  (and numba)


def start_worker(core: int):
    """A measuring worker process pinned to ``core``, started now (see :class:`Lanes`)."""
    import multiprocessing as mp

    return _pinned_worker(mp.get_context("spawn"), core)


THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
_ENV_LOCK = threading.Lock()


def _pinned_worker(ctx, core: int):
    """A one-process pool pinned to ``core``, started now with single-threaded BLAS/OpenMP
    (a thread pool is sized when numpy loads, before any initializer runs, so the limit
    must be in the environment the process starts with)."""
    from concurrent.futures import ProcessPoolExecutor

    ex = ProcessPoolExecutor(1, mp_context=ctx, initializer=_pin_worker, initargs=(core,))
    with _ENV_LOCK:
        old = {v: os.environ.get(v) for v in THREAD_VARS}
        os.environ.update({v: "1" for v in THREAD_VARS})
        try:
            ex.submit(int)  # a spawn-context pool starts its process in submit()
        finally:
            for v, val in old.items():
                if val is None:
                    os.environ.pop(v, None)
                else:
                    os.environ[v] = val
    return ex


@dataclass
class Lanes:
    """Where the timed cases run: one single-threaded worker process per core, pinned to it,
    so a timed case never shares its core with another case or with the caller's work.

    Attributes
    ----------
    cores : list of int
        One lane (worker process) per core.
    gates : dict[int, threading.Event]
        A lane whose core is listed starts only once its event is set (``walkerlab report``
        runs its untimed stages on that core meanwhile).
    pending : dict[str, threading.Event]
        Cases of a listed model are taken only once its event is set (the report sets it
        when the model's compiled code is in numba's on-disk cache, so a worker loads it
        instead of compiling it a second time); other models' cases go first.
    cancel : threading.Event
        Set: the lanes take no new case.
    """

    cores: list
    gates: dict = field(default_factory=dict)
    pending: dict = field(default_factory=dict)
    cancel: threading.Event = field(default_factory=threading.Event)
    #: set once the cache was looked up; ``todo_models``: models with cases to measure
    todo_known: threading.Event = field(default_factory=threading.Event)
    todo_models: set = field(default_factory=set)
    #: worker processes started ahead (:func:`start_worker`), by core; a lane takes its own
    workers: dict = field(default_factory=dict)


#: scipy's implicit methods: the slow cases, started first so the lanes finish together
IMPLICIT = ("Radau", "BDF")


def _cost_order(t: Case) -> tuple:
    """Longest first (measured: implicit methods at tight tolerances, then the contact
    model), so the last cases to finish are short ones."""
    base = t.method.removeprefix(CYRK_PREFIX)
    return (base not in IMPLICIT, round(float(np.log10(t.rtol)), 3), t.model != "contact")


def run_cases(tasks: list[Case], cache_dir: Path, workers: int = 2,
              lanes: Lanes | None = None) -> dict:
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

    Returns
    -------
    dict
        ``{case_key: result}`` (see :func:`time_case`), each with ``"cached": bool``.
    """
    cache_dir.mkdir(parents=True, exist_ok=True)
    out, todo = {}, []
    for t in tasks:
        f = cache_dir / f"{t.key}.json"
        if f.is_file():
            try:
                out[t.key] = {**json.loads(f.read_text()), "cached": True}
                continue
            except (OSError, ValueError):
                pass
        todo.append(t)
    if lanes is not None:
        lanes.todo_models.update(t.model for t in todo)
        lanes.todo_known.set()
    lock = threading.Lock()

    def store(key, res, n_lanes):
        res = {**res, "measured_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
               "parallel_workers": n_lanes}
        tmp = cache_dir / f".{key}.tmp"
        tmp.write_text(json.dumps(res))
        os.replace(tmp, cache_dir / f"{key}.json")
        with lock:
            out[key] = {**res, "cached": False}

    if lanes is None:
        cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
        if workers <= 1 or len(todo) <= 1 or len(cores) < workers:
            for t in sorted(todo, key=_cost_order):
                store(*_run_case(t), 1)
            return out
        lanes = Lanes(cores=cores[:workers])
    if not todo:
        return out
    import multiprocessing as mp

    ctx = mp.get_context("spawn")
    todo.sort(key=_cost_order)
    errors: list[BaseException] = []

    def take():
        """Next case whose model is ready; None: nothing left; False: wait."""
        with lock:
            if not todo or lanes.cancel.is_set():
                return None
            for i, t in enumerate(todo):
                ev = lanes.pending.get(t.model)
                if ev is None or ev.is_set():
                    return todo.pop(i)
            return False

    def lane(core):
        gate = lanes.gates.get(core)
        while gate is not None and not gate.wait(0.1):
            if take_nothing_left():
                return
        ex = None  # the worker starts with the lane's first case
        try:
            while (t := take()) is not None:
                if t is False:
                    time.sleep(0.05)
                    continue
                if ex is None:
                    ex = lanes.workers.pop(core, None) or _pinned_worker(ctx, core)
                store(*ex.submit(_run_case, t).result(), len(lanes.cores))
        except BaseException as exc:  # noqa: BLE001 - re-raised in the calling thread
            lanes.cancel.set()
            errors.append(exc)
        finally:
            if ex is not None:
                ex.shutdown(wait=True, cancel_futures=True)

    def take_nothing_left():
        with lock:
            return not todo or lanes.cancel.is_set()

    threads = [threading.Thread(target=lane, args=(c,), name=f"workprecision-core{c}")
               for c in lanes.cores]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    if errors:
        raise errors[0]
    if lanes.cancel.is_set() and todo:
        raise RuntimeError("workprecision: cancelled")
    return out


#: the sources a case's result depends on (a change elsewhere - report text, plots, other
#: stages - keeps the measured cases)
CASE_SOURCES = {
    "ideal": ("analysis", "models", "config.py", "stages/workprecision.py"),
    "contact": ("analysis", "models", "contact", "config.py", "stages/workprecision.py",
                "stages/contact_sim.py"),
}


def _sources_hash(parts: tuple[str, ...]) -> str:
    """SHA-256 over the walkerlab sources under ``parts`` (files or subpackages)."""
    import walkerlab

    root = Path(walkerlab.__file__).parent
    h = hashlib.sha256(walkerlab.__version__.encode())
    for part in parts:
        p = root / part
        for f in sorted(p.rglob("*.py")) if p.is_dir() else [p]:
            h.update(str(f.relative_to(root)).encode())
            h.update(f.read_bytes())
    return h.hexdigest()


def _case_key(model: str, sections_json: str, x0: tuple, strides: int, method: str,
              rtol: float, atol: float, repeats: int) -> str:
    """Key of one case: its inputs (the fixed point by value, so a recomputed but equal fixed
    point keeps the cases) and the sources it runs."""
    h = hashlib.sha256(json.dumps([model, sections_json, [repr(v) for v in x0], strides,
                                   method, rtol, atol, repeats]).encode())
    h.update(_sources_hash(CASE_SOURCES[model]).encode())
    return h.hexdigest()[:32]


def summarize(rows: dict, target: float) -> dict:
    meth = [m for m in rows for _ in rows[m]["rtol"]]
    rt = np.concatenate([rows[m]["rtol"] for m in rows])
    tt = np.concatenate([rows[m]["time"] for m in rows])
    ee = np.concatenate([rows[m]["error"] for m in rows])
    idx = pareto_front(tt, ee)
    ok = np.flatnonzero(ee <= target)
    best = int(ok[np.argmin(tt[ok])]) if ok.size else None
    return {"pareto": [(meth[i], float(rt[i]), float(tt[i]), float(ee[i])) for i in idx],
            "best": None if best is None else (meth[best], float(rt[best]), float(tt[best]),
                                               float(ee[best]))}


IDEAL_SECTIONS = ("walker", "slope", "ideal", "fixedpoint")
CONTACT_SECTIONS = IDEAL_SECTIONS + ("contact", "terrain", "contact_sim")


def _reference_method() -> str:
    """The ideal model's reference integrator: CyRK's DOP853 when installed (the same steps
    as scipy's DOP853, measured: the two reference vectors at rtol 1e-13 differ by 1.0e-13,
    the accuracy both reach, at 0.06 s instead of 0.7 s CPU), else scipy's."""
    from walkerlab.analysis.hybrid import _have_cyrk

    return CYRK_PREFIX + "DOP853" if _have_cyrk() else "DOP853"


def plan(scene: Scene) -> dict:
    """``{model: (methods, rtols, atol_factor, reference (method, rtol, atol), target error,
    scene sections of the model)}`` of the scene's ``workprecision`` section."""
    wp = require(scene, "workprecision", "workprecision")
    out = {}
    if "ideal" in wp.models:
        from walkerlab.analysis.hybrid import CYRK_METHODS, _have_cyrk

        extra = ([CYRK_PREFIX + m for m in wp.methods if m in CYRK_METHODS]
                 if _have_cyrk() else [])
        out["ideal"] = (list(wp.methods) + extra, list(wp.rtols), wp.atol_factor,
                        (_reference_method(), wp.reference_rtol, wp.reference_rtol),
                        wp.target_error, scene.section_json(*IDEAL_SECTIONS))
    if "contact" in wp.models and scene.contact is not None:
        out["contact"] = (list(wp.contact_methods), list(wp.contact_rtols), 1e-2,
                          ("odeint", wp.contact_reference_rtol,
                           wp.contact_reference_rtol * 1e-2), wp.contact_target_error,
                          scene.section_json(*CONTACT_SECTIONS))
    return out


def _warm_cases(model_plan) -> tuple:
    """Each method of a model at its loosest tolerance: the warm-up runs."""
    methods, rtols, af = model_plan[:3]
    r = max(rtols)
    return tuple((m, r, af * r) for m in methods)


def warm_up(scene: Scene, runs_root: Path | str, model: str) -> None:
    """Run ``model``'s warm-up cases in this process (untimed): compiles what they need into
    the on-disk caches (numba kernels and CyRK right-hand sides of the contact model), so
    the timing workers only load it.  Needs the fixed-point artifact."""
    p = plan(scene)
    if model not in p:
        return
    x0, _ = fixedpoint_stage.load_fixed_point(artifact_path(scene, runs_root, "fixedpoint"))
    wp = require(scene, "workprecision", "workprecision")
    _runner_for(model, json.dumps(scene.model_dump(mode="json"), sort_keys=True),
                str(runs_root), tuple(float(v) for v in x0), wp.strides, _warm_cases(p[model]))


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        workers: int = 2, lanes: Lanes | None = None) -> StageOutcome:
    """Run the work-precision study of the scene's ``workprecision`` section.

    Parameters
    ----------
    workers : int
        Processes measuring cases side by side, one pinned core each (1 = in this process).
        ``force`` also re-measures cached cases.
    lanes : Lanes, optional
        Explicit cores/gates for the measuring processes (see :func:`run_cases`).
    """
    from walkerlab.stages.common import artifact_path as _ap

    wp = require(scene, "workprecision", "workprecision")
    fixedpoint_stage.run(scene, runs_root)
    up = (artifact_path(scene, runs_root, "fixedpoint"),)

    def compute():
        x0, _ = fixedpoint_stage.load_fixed_point(up[0])
        x0t = tuple(float(v) for v in x0)
        sj = json.dumps(scene.model_dump(mode="json"), sort_keys=True)
        rr = str(runs_root)
        cache = _ap(scene, runs_root, "workprecision").parent / ".cache" / "workprecision"
        if force and cache.is_dir():
            for f in cache.glob("*.json"):
                f.unlink()
        models = plan(scene)
        tasks, keys = [], {}
        for model, mp_ in models.items():
            methods, rtols, af, ref, _, secs = mp_
            warm = _warm_cases(mp_)
            cases = [(ref[0], ref[1], ref[2], 1)] + [(m, r, af * r, wp.repeats)
                                                     for m in methods for r in rtols]
            for m, r, a, rep in cases:
                k = _case_key(model, secs, x0t, wp.strides, m, r, a, rep)
                keys[(model, m, r, rep)] = k
                tasks.append(Case(k, model, sj, rr, x0t, wp.strides, m, r, a, rep, warm))
        done = run_cases(tasks, cache, workers, lanes)
        results = {}
        for model, (methods, rtols, _, ref, target, _) in models.items():
            refvec = done[keys[(model, ref[0], ref[1], 1)]]["vec"]
            cases = {(m, r): done[keys[(model, m, r, wp.repeats)]] for m in methods
                     for r in rtols}
            rows = _rows(cases, methods, rtols, np.asarray(refvec))
            results[model] = (rows, summarize(rows, target), ref)
        n_cached = sum(1 for v in done.values() if v.get("cached"))

        def writer(f):
            for model, (rows, summ, ref) in results.items():
                g = f.create_group(model)
                g.attrs["reference_method"], g.attrs["reference_rtol"] = ref[:2]
                for m, d in rows.items():
                    put(g, f"{m}/rtol", d["rtol"], "-", "relative tolerance")
                    put(g, f"{m}/time", d["time"], "s", "median wall time")
                    put(g, f"{m}/cpu_time", d["cpu_time"], "s", "median process CPU time")
                    put(g, f"{m}/repeats", d["repeats"], "-", "timed runs (1 when a run "
                        f"takes > {SINGLE_RUN_S:g} s)")
                    put(g, f"{m}/error", d["error"], "rad, rad/s (, s)",
                        "max-norm error vs the reference (inf: run failed)")
                    put(g, f"{m}/nfev", d["nfev"], "-", "RHS evaluations")
                g.attrs["pareto_methods"] = [p[0] for p in summ["pareto"]]
                g.attrs["pareto_rtol"] = [p[1] for p in summ["pareto"]]
                g.attrs["pareto_time"] = [p[2] for p in summ["pareto"]]
                g.attrs["pareto_error"] = [p[3] for p in summ["pareto"]]
                if summ["best"]:
                    g.attrs["best_method"], g.attrs["best_rtol"] = summ["best"][:2]
                    g.attrs["best_time"], g.attrs["best_error"] = summ["best"][2:]
                g.attrs["target_error"] = (wp.target_error if model == "ideal"
                                           else wp.contact_target_error)
            f.attrs["timing"] = ("each case measured in a worker process pinned to its own "
                                 "core, nothing else of walkerlab's on that core; an untimed "
                                 "one-stride warm-up run per worker and method; wall and "
                                 "process CPU time per run")
            f.attrs["cases_reused_from_cache"] = n_cached
            f.attrs["cases_total"] = len(done)
        return writer, {k: v[1] for k, v in results.items()}

    return run_cached("workprecision", scene, runs_root, SECTIONS, up, compute, force)
