"""Stage ``workprecision``: error against run time for every solver (work-precision diagram).

For each model and each scipy method and tolerance, the run is repeated ``repeats`` times
(the median wall time is kept) and its error is measured against a tightly converged
reference (DOP853 at ``reference_rtol`` for the ideal model; odeint/LSODA at
``contact_reference_rtol`` for the contact model, whose atol is 1e-2 * rtol because its
positions are sub-millimetre penetrations).  The ideal model's error is the max-norm of the
difference of the state and time at the last heel strike; the contact model's error is the
max-norm of the leg angles [rad] and rates [rad/s] at the final time.  The artifact stores
every point, the Pareto front (no other setting is both faster and more accurate) and the
Pareto-best setting: the fastest one whose error is below ``target_error``.

Speed of the study itself (issue 10), without dropping a method or a tolerance:

- every case (model, method, tolerance) is cached on its own under
  ``runs/<scene>/.cache/workprecision/`` (key: the model's scene sections, the fixed point,
  the case and the sources it runs, :data:`CASE_SOURCES`); a rerun after an unrelated change
  (another target error, a new tolerance, the contact section only, report code) measures
  only what is new;
- the cases run on two worker processes, each pinned to its own core
  (``os.sched_setaffinity``) and single-threaded, so a case never shares its core with
  another case; both the wall time and the process CPU time of every run are stored (the
  diagram uses the wall time; on a machine with other load the CPU time is the honest
  figure: ``cpu_time``);
- the ideal model is also integrated with CyRK's DOP853/RK45 (group ``CyRK <method>``),
  next to scipy's ``solve_ivp`` methods, which is the integrator benchmark of the project.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

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
_RUNNERS: dict = {}


def _runner_for(model: str, scene_json: str, runs_root: str, x0: tuple, strides: int):
    key = (model, scene_json, runs_root, x0, strides)
    if key not in _RUNNERS:
        from walkerlab.config import scene_from_dict

        _RUNNERS.clear()
        scene = scene_from_dict(json.loads(scene_json))
        if model == "ideal":
            _RUNNERS[key] = ideal_runner(scene, np.asarray(x0), strides)
        else:
            from walkerlab.stages.contact_sim import workprecision_runner

            _RUNNERS[key] = workprecision_runner(scene, runs_root, np.asarray(x0), strides)
    return _RUNNERS[key]


def _run_case(task: tuple) -> tuple:
    """Worker: ``task = (case_key, model, scene_json, runs_root, x0, strides, method, rtol,
    atol, repeats)`` -> ``(case_key, result)``."""
    key, model, scene_json, runs_root, x0, strides, method, rtol, atol, repeats = task
    runner = _runner_for(model, scene_json, runs_root, x0, strides)
    return key, time_case(runner, method, rtol, atol, repeats)


def _pin_worker(queue) -> None:
    """Pool initializer: take one core of the two offered and stay on it, single-threaded."""
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = "1"
    try:
        os.sched_setaffinity(0, {queue.get(timeout=5)})
    except Exception:  # noqa: BLE001 - pinning is best effort (not on every OS)
        pass


def run_cases(tasks: list[tuple], cache_dir: Path, workers: int = 2) -> dict:
    """Results of every case, from the cache or measured (in ``workers`` pinned processes).

    Returns
    -------
    dict
        ``{case_key: result}`` (see :func:`time_case`), each with ``"cached": bool``.
    """
    cache_dir.mkdir(parents=True, exist_ok=True)
    out, todo = {}, []
    for t in tasks:
        f = cache_dir / f"{t[0]}.json"
        if f.is_file():
            try:
                out[t[0]] = {**json.loads(f.read_text()), "cached": True}
                continue
            except (OSError, ValueError):
                pass
        todo.append(t)

    def store(key, res):
        res = {**res, "measured_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
               "parallel_workers": workers}
        tmp = cache_dir / f".{key}.tmp"
        tmp.write_text(json.dumps(res))
        os.replace(tmp, cache_dir / f"{key}.json")
        out[key] = {**res, "cached": False}

    cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    if workers <= 1 or len(todo) <= 1 or len(cores) < workers:
        for t in todo:
            store(*_run_case(t))
        return out
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed

    ctx = mp.get_context("spawn")
    # longest first: implicit methods at tight tolerances, the contact model
    todo.sort(key=lambda t: (t[1] != "contact", np.log10(t[7])))
    with ctx.Manager() as mgr:
        q = mgr.Queue()
        for c in cores[:workers]:
            q.put(c)
        with ProcessPoolExecutor(workers, mp_context=ctx, initializer=_pin_worker,
                                 initargs=(q,)) as ex:
            for fut in as_completed([ex.submit(_run_case, t) for t in todo]):
                store(*fut.result())
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


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        workers: int = 2) -> StageOutcome:
    """Run the work-precision study of the scene's ``workprecision`` section.

    Parameters
    ----------
    workers : int
        Processes measuring cases side by side, one pinned core each (1 = in this process).
        ``force`` also re-measures cached cases.
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
        plan = {}  # model -> (methods, rtols, atol_factor, reference case, target)
        if "ideal" in wp.models:
            from walkerlab.analysis.hybrid import CYRK_METHODS, _have_cyrk

            extra = ([CYRK_PREFIX + m for m in wp.methods if m in CYRK_METHODS]
                     if _have_cyrk() else [])
            plan["ideal"] = (list(wp.methods) + extra, list(wp.rtols), wp.atol_factor,
                             ("DOP853", wp.reference_rtol, wp.reference_rtol), wp.target_error,
                             scene.section_json(*IDEAL_SECTIONS))
        if "contact" in wp.models and scene.contact is not None:
            plan["contact"] = (list(wp.contact_methods), list(wp.contact_rtols), 1e-2,
                               ("odeint", wp.contact_reference_rtol,
                                wp.contact_reference_rtol * 1e-2), wp.contact_target_error,
                               scene.section_json(*CONTACT_SECTIONS))
        tasks, keys = [], {}
        for model, (methods, rtols, af, ref, _, secs) in plan.items():
            cases = [(ref[0], ref[1], ref[2], 1)] + [(m, r, af * r, wp.repeats)
                                                     for m in methods for r in rtols]
            for m, r, a, rep in cases:
                k = _case_key(model, secs, x0t, wp.strides, m, r, a, rep)
                keys[(model, m, r, rep)] = k
                tasks.append((k, model, sj, rr, x0t, wp.strides, m, r, a, rep))
        done = run_cases(tasks, cache, workers)
        results = {}
        for model, (methods, rtols, _, ref, target, _) in plan.items():
            refvec = done[keys[(model, ref[0], ref[1], 1)]]["vec"]
            cases = {(m, r): done[keys[(model, m, r, wp.repeats)]] for m in methods
                     for r in rtols}
            rows = _rows(cases, methods, rtols, np.asarray(refvec))
            results[model] = (rows, summarize(rows, target))
        n_cached = sum(1 for v in done.values() if v.get("cached"))

        def writer(f):
            for model, (rows, summ) in results.items():
                g = f.create_group(model)
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
            f.attrs["timing"] = (f"cases measured by {workers} process(es), each pinned to its "
                                 "own core; wall and process CPU time per run")
            f.attrs["cases_reused_from_cache"] = n_cached
            f.attrs["cases_total"] = len(done)
        return writer, {k: v[1] for k, v in results.items()}

    return run_cached("workprecision", scene, runs_root, SECTIONS, up, compute, force)
