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

The cases (model, method, tolerance) are measured by :mod:`walkerlab.analysis.workprecision`
(worker processes pinned to their own cores, untimed warm-up, wall and CPU time).  This stage
plans them from the scene, keeps each measured case under
``runs/<scene>/.cache/workprecision/`` (key: the model's scene sections, the fixed point by
value, the case and the sources it runs, :data:`CASE_SOURCES`), so a rerun after an unrelated
change (another target error, a new tolerance, the contact section only, report code)
measures only what is new, and writes the artifact.  The ideal model is also integrated with
CyRK's DOP853/RK45 (group ``CyRK <method>``), next to scipy's ``solve_ivp`` methods.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from walkerlab.analysis.workprecision import (
    CYRK_PREFIX,
    SINGLE_RUN_S,
    Case,
    rows_from_cases,
    run_cases,
    runner_for,
    summarize,
)
from walkerlab.config import Scene
from walkerlab.execution.lanes import Lanes
from walkerlab.io.runpaths import run_cache_dir
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.io.schemas.workprecision import WorkPrecisionRun, write_workprecision
from walkerlab.stages.common import StageOutcome, artifact_path, require, run_cached

SECTIONS = ("walker", "slope", "ideal", "fixedpoint", "workprecision", "contact", "terrain",
            "contact_sim")


#: the sources a case's result depends on (a change elsewhere - report text, plots, other
#: stages - keeps the measured cases)
CASE_SOURCES = {
    "ideal": ("analysis", "models", "integrate", "config"),
    "contact": ("analysis", "models", "contact", "integrate", "config"),
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


IDEAL_SECTIONS = ("walker", "slope", "ideal", "fixedpoint")
CONTACT_SECTIONS = IDEAL_SECTIONS + ("contact", "terrain", "contact_sim")


def _reference_method() -> str:
    """The ideal model's reference integrator: CyRK's DOP853 when installed (the same steps
    as scipy's DOP853, measured: the two reference vectors at rtol 1e-13 differ by 1.0e-13,
    the accuracy both reach, at 0.06 s instead of 0.7 s CPU), else scipy's."""
    from walkerlab.integrate.solver import available_backends

    return CYRK_PREFIX + "DOP853" if "cyrk" in available_backends() else "DOP853"


def plan(scene: Scene) -> dict:
    """``{model: (methods, rtols, atol_factor, reference (method, rtol, atol), target error,
    scene sections of the model)}`` of the scene's ``workprecision`` section."""
    wp = require(scene, "workprecision", "workprecision")
    out = {}
    if "ideal" in wp.models:
        from walkerlab.integrate.solver import CYRK_METHODS, available_backends

        extra = ([CYRK_PREFIX + m for m in wp.methods if m in CYRK_METHODS]
                 if "cyrk" in available_backends() else [])
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
    fp = load_fixedpoint(artifact_path(scene, runs_root, "fixedpoint"))
    wp = require(scene, "workprecision", "workprecision")
    runner_for(model, json.dumps(scene.model_dump(mode="json"), sort_keys=True),
               float(fp.step_period_s), tuple(float(v) for v in fp.x), wp.strides,
               _warm_cases(p[model]))


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        workers: int = 2, lanes: Lanes | None = None) -> StageOutcome:
    """Run the work-precision study of the scene's ``workprecision`` section.

    Parameters
    ----------
    workers : int
        Processes measuring cases side by side, one pinned core each (1 = in this process).
        ``force`` also re-measures cached cases.
    lanes : Lanes, optional
        Explicit cores/gates for the measuring processes (see
        :func:`walkerlab.analysis.workprecision.run_cases`).
    """

    wp = require(scene, "workprecision", "workprecision")
    up = (artifact_path(scene, runs_root, "fixedpoint"),)

    def compute():
        fp = load_fixedpoint(up[0])
        x0t = tuple(float(v) for v in fp.x)
        sj = json.dumps(scene.model_dump(mode="json"), sort_keys=True)
        period = float(fp.step_period_s)
        cache = run_cache_dir(scene, runs_root, "workprecision")
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
                tasks.append(Case(k, model, sj, period, x0t, wp.strides, m, r, a, rep, warm))
        from walkerlab import progress

        with progress.task(f"work-precision: timing {len(tasks)} cases (uncached)") as bar:
            done = run_cases(tasks, cache, workers, lanes,
                             on_case=lambda k, n: bar.update(k, total=n))
        results = {}
        for model, (methods, rtols, _, ref, target, _) in models.items():
            refvec = done[keys[(model, ref[0], ref[1], 1)]]["vec"]
            cases = {(m, r): done[keys[(model, m, r, wp.repeats)]] for m in methods
                     for r in rtols}
            rows = rows_from_cases(cases, methods, rtols, np.asarray(refvec))
            results[model] = (rows, summarize(rows, target), ref)
        n_cached = sum(1 for v in done.values() if v.get("cached"))

        run = WorkPrecisionRun(results, n_cached, len(done), wp.target_error,
                               wp.contact_target_error, SINGLE_RUN_S)
        return (lambda f: write_workprecision(f, run)), {k: v[1] for k, v in results.items()}

    return run_cached("workprecision", scene, runs_root, SECTIONS, up, compute, force)
