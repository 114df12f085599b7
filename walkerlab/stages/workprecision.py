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

The cases (model, method, tolerance) are planned by
:mod:`walkerlab.bench.workprecision_plan` and measured by
:mod:`walkerlab.bench.workprecision` (worker processes pinned to their own cores, untimed
warm-up, wall and CPU time).  This stage keeps each measured case under
``runs/<scene>/.cache/workprecision/`` (key: the model's scene sections, the fixed point by
value, the case and the sources it runs,
:data:`walkerlab.bench.workprecision_plan.CASE_SOURCES`), so a rerun after an unrelated
change (another target error, a new tolerance, the contact section only, report code)
measures only what is new, and writes the artifact.  The ideal model is also integrated with
CyRK's DOP853/RK45 (group ``CyRK <method>``), next to scipy's ``solve_ivp`` methods.
"""

from __future__ import annotations

import json
from pathlib import Path

from walkerlab.bench.workprecision import SINGLE_RUN_S, runner_for
from walkerlab.bench.workprecision_plan import plan, run_study, warm_cases
from walkerlab.config import Scene
from walkerlab.execution.lanes import Lanes
from walkerlab.io.runpaths import run_cache_dir, stage_artifact
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.io.schemas.workprecision import WorkPrecisionRun, write_workprecision
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached
from walkerlab.walker.description import walker_data
from walkerlab.walker.kinds import KindRefused

SECTIONS = ("walker", "slope", "ideal", "fixedpoint", "workprecision", "contact", "terrain",
            "contact_sim")


def check(scene: Scene, **_options) -> None:
    """Refuse before anything runs (the fixed point upstream included).

    Raises
    ------
    StageError
        No ``workprecision`` section, or its contact model asked of a walker without a
        contact view (a 3D walker: the capability table's contact cell), one line.
    """
    require(scene, "workprecision", "workprecision")
    try:
        models = plan(scene)
    except ValueError as exc:  # no workprecision section (one line)
        raise StageError(str(exc)) from None
    if "contact" in models:

        kind = walker_data(scene.walker, scene.slope.phi_rad).structure.kind
        try:
            kind.require("walk", "contact", f"workprecision.models: contact: {kind.field}")
        except KindRefused as exc:
            raise StageError(str(exc)) from None


def warm_up(scene: Scene, runs_root: Path | str, model: str) -> None:
    """Run ``model``'s warm-up cases in this process (untimed): compiles what they need into
    the on-disk caches (numba kernels and CyRK right-hand sides of the contact model), so
    the timing workers only load it.  Needs the fixed-point artifact."""
    wp = require(scene, "workprecision", "workprecision")
    p = plan(scene)
    if model not in p:
        return
    fp = load_fixedpoint(stage_artifact(scene, runs_root, "fixedpoint"))
    runner_for(model, json.dumps(scene.model_dump(mode="json"), sort_keys=True),
               float(fp.step_period_s), tuple(float(v) for v in fp.x), wp.strides,
               warm_cases(p[model]))


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        workers: int = 2, lanes: Lanes | None = None) -> StageOutcome:
    """Run the work-precision study of the scene's ``workprecision`` section with
    ``workers`` measuring processes or explicit ``lanes``
    (:func:`walkerlab.bench.workprecision_plan.run_study`); ``force`` also re-measures
    cached cases."""
    wp = require(scene, "workprecision", "workprecision")
    up = (stage_artifact(scene, runs_root, "fixedpoint"),)

    def compute():
        fp = load_fixedpoint(up[0])
        cache = run_cache_dir(scene, runs_root, "workprecision")
        if force and cache.is_dir():
            for f in cache.glob("*.json"):
                f.unlink()
        results, n_cached, n = run_study(scene, wp, fp.x, fp.step_period_s, cache, workers,
                                          lanes)
        run = WorkPrecisionRun(results, n_cached, n, wp.target_error, wp.contact_target_error,
                               SINGLE_RUN_S)
        return (lambda f: write_workprecision(f, run)), {k: v[1] for k, v in results.items()}

    return run_cached("workprecision", scene, runs_root, SECTIONS, up, compute, force)
