"""The cases of a work-precision study planned from a scene: models, methods, tolerances,
references, target errors, warm-up cases, and the key under which a measured case is kept
(its inputs and the sources it runs).  :func:`run_study` measures them
(:mod:`walkerlab.bench.workprecision`) for the ``workprecision`` stage.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import walkerlab
from walkerlab import progress
from walkerlab.bench.workprecision import CYRK_PREFIX, Case, run_cases
from walkerlab.bench.workprecision_results import rows_from_cases, summarize
from walkerlab.config import Scene
from walkerlab.integrate.solver import CYRK_METHODS, available_backends

#: the sources a case's result depends on (a change elsewhere - report text, plots, other
#: stages - keeps the measured cases)
CASE_SOURCES = {
    "ideal": ("analysis", "models", "integrate", "config", "walker", "codegen"),
    "contact": ("analysis", "models", "integrate", "config", "walker", "codegen"),
}


def sources_hash(parts: tuple[str, ...]) -> str:
    """SHA-256 over the walkerlab sources under ``parts`` (files or subpackages)."""
    root = Path(walkerlab.__file__).parent
    h = hashlib.sha256(walkerlab.__version__.encode())
    for part in parts:
        p = root / part
        for f in sorted(p.rglob("*.py")) if p.is_dir() else [p]:
            h.update(str(f.relative_to(root)).encode())
            h.update(f.read_bytes())
    return h.hexdigest()


def case_key(model: str, sections_json: str, x0: tuple, strides: int, method: str,
              rtol: float, atol: float, repeats: int) -> str:
    """Key of one case: its inputs (the fixed point by value, so a recomputed but equal fixed
    point keeps the cases) and the sources it runs."""
    h = hashlib.sha256(json.dumps([model, sections_json, [repr(v) for v in x0], strides,
                                   method, rtol, atol, repeats]).encode())
    h.update(sources_hash(CASE_SOURCES[model]).encode())
    return h.hexdigest()[:32]


IDEAL_SECTIONS = ("walker", "slope", "ideal", "fixedpoint")
CONTACT_SECTIONS = IDEAL_SECTIONS + ("contact", "terrain", "contact_sim")


def reference_method() -> str:
    """The ideal model's reference integrator: CyRK's DOP853 when installed (the same steps
    as scipy's DOP853, measured: the two reference vectors at rtol 1e-13 differ by 1.0e-13,
    the accuracy both reach, at 0.06 s instead of 0.7 s CPU), else scipy's."""
    return CYRK_PREFIX + "DOP853" if "cyrk" in available_backends() else "DOP853"


def plan(scene: Scene) -> dict:
    """``{model: (methods, rtols, atol_factor, reference (method, rtol, atol), target error,
    scene sections of the model)}`` of the scene's ``workprecision`` section.

    Raises
    ------
    ValueError
        The scene has no ``workprecision`` section.
    """
    wp = scene.workprecision
    if wp is None:
        raise ValueError(f"scene '{scene.name}' has no 'workprecision' section")
    out = {}
    if "ideal" in wp.models:
        extra = ([CYRK_PREFIX + m for m in wp.methods if m in CYRK_METHODS]
                 if "cyrk" in available_backends() else [])
        out["ideal"] = (list(wp.methods) + extra, list(wp.rtols), wp.atol_factor,
                        (reference_method(), wp.reference_rtol, wp.reference_rtol),
                        wp.target_error, scene.section_json(*IDEAL_SECTIONS))
    if "contact" in wp.models and scene.contact is not None:
        out["contact"] = (list(wp.contact_methods), list(wp.contact_rtols), 1e-2,
                          ("odeint", wp.contact_reference_rtol,
                           wp.contact_reference_rtol * 1e-2), wp.contact_target_error,
                          scene.section_json(*CONTACT_SECTIONS))
    return out


def warm_cases(model_plan) -> tuple:
    """Each method of a model at its loosest tolerance: the warm-up runs."""
    methods, rtols, af = model_plan[:3]
    r = max(rtols)
    return tuple((m, r, af * r) for m in methods)


def run_study(scene: Scene, wp, x0, step_period_s: float, cache: Path, workers: int = 2,
              lanes=None) -> tuple[dict, int, int]:
    """Measure every case of the scene's plan (:func:`plan`) from the gait ``x0`` (its step
    period [s]), keeping each measured case in ``cache`` (a case found there is not timed
    again), and turn them into work-precision rows.

    Parameters
    ----------
    wp : walkerlab.config.WorkPrecisionSettings
        The scene's ``workprecision`` section (strides, repeats).
    workers : int
        Processes measuring cases side by side, one pinned core each (1 = in this process).
    lanes : walkerlab.execution.lanes.Lanes, optional
        Explicit cores/gates for the measuring processes
        (:func:`walkerlab.bench.workprecision.run_cases`).

    Returns
    -------
    (dict, int, int)
        ``{model: (rows, summary, reference)}``, the cases found in the cache, all cases.
    """
    import numpy as np

    x0t = tuple(float(v) for v in x0)
    sj = json.dumps(scene.model_dump(mode="json"), sort_keys=True)
    period = float(step_period_s)
    models = plan(scene)
    tasks, keys = [], {}
    for model, mp_ in models.items():
        methods, rtols, af, ref, _, secs = mp_
        warm = warm_cases(mp_)
        cases = [(ref[0], ref[1], ref[2], 1)] + [(m, r, af * r, wp.repeats)
                                                 for m in methods for r in rtols]
        for m, r, a, rep in cases:
            k = case_key(model, secs, x0t, wp.strides, m, r, a, rep)
            keys[(model, m, r, rep)] = k
            tasks.append(Case(k, model, sj, period, x0t, wp.strides, m, r, a, rep, warm))
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
    return results, sum(1 for v in done.values() if v.get("cached")), len(done)
