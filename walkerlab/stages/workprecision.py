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
"""

from __future__ import annotations

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


def ideal_runner(scene: Scene, x0: np.ndarray, strides: int):
    """``run(method, rtol, atol) -> (final vector, nfev)`` for the rigid hybrid walker."""
    walker = build_walker(scene)

    def run(method, rtol, atol):
        tr = simulate_steps(walker, x0, 2 * strides, Solver(method, rtol, atol))
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


def study(runner, methods, rtols, atol_factor, repeats, reference) -> dict:
    """Run every (method, rtol); returns ``{method: {rtol, time, error, nfev}}``."""
    out = {}
    for m in methods:
        rows = {"rtol": [], "time": [], "error": [], "nfev": []}
        for rtol in rtols:
            times, vec, nfev = [], None, 0
            for _ in range(repeats):
                t0 = time.perf_counter()
                try:
                    vec, nfev = runner(m, rtol, atol_factor * rtol)
                except Exception:
                    vec = None
                times.append(time.perf_counter() - t0)
            err = np.inf if vec is None else float(np.max(np.abs(vec - reference)))
            rows["rtol"].append(rtol)
            rows["time"].append(float(np.median(times)))
            rows["error"].append(err)
            rows["nfev"].append(nfev)
        out[m] = {k: np.asarray(v) for k, v in rows.items()}
    return out


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


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False) -> StageOutcome:
    """Run the work-precision study of the scene's ``workprecision`` section."""
    wp = require(scene, "workprecision", "workprecision")
    fixedpoint_stage.run(scene, runs_root)
    up = (artifact_path(scene, runs_root, "fixedpoint"),)

    def compute():
        x0, _ = fixedpoint_stage.load_fixed_point(up[0])
        results = {}
        if "ideal" in wp.models:
            runner = ideal_runner(scene, x0, wp.strides)
            ref, _ = runner("DOP853", wp.reference_rtol, wp.reference_rtol)
            rows = study(runner, wp.methods, wp.rtols, wp.atol_factor, wp.repeats, ref)
            results["ideal"] = (rows, summarize(rows, wp.target_error))
        if "contact" in wp.models and scene.contact is not None:
            from walkerlab.stages.contact_sim import workprecision_runner

            runner = workprecision_runner(scene, runs_root, x0, wp.strides)
            ref, _ = runner("odeint", wp.contact_reference_rtol,
                            wp.contact_reference_rtol * 1e-2)
            rows = study(runner, wp.contact_methods, wp.contact_rtols, 1e-2, wp.repeats, ref)
            results["contact"] = (rows, summarize(rows, wp.contact_target_error))

        def writer(f):
            for model, (rows, summ) in results.items():
                g = f.create_group(model)
                for m, d in rows.items():
                    put(g, f"{m}/rtol", d["rtol"], "-", "relative tolerance")
                    put(g, f"{m}/time", d["time"], "s", "median wall time")
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
        return writer, {k: v[1] for k, v in results.items()}

    return run_cached("workprecision", scene, runs_root, SECTIONS, up, compute, force)
