"""``workprecision.h5``: error against run time of every solver setting (writer and loader).

Layout: one group per model (``ideal``, ``contact``), one subgroup per method with, on one
row per relative tolerance: ``rtol``, ``time`` (median CPU time of the integration alone
over the repeats [s]), ``time_min``, ``time_max`` (fastest and slowest repeat [s]),
``wall_time`` (median wall time of the whole run [s]), ``repeats``, ``error`` (max-norm
error against the reference run), ``nfev``; the model group's attributes hold the
reference setting, the Pareto front (``pareto_methods/rtol/time/error``), the fastest
setting reaching the target error (``best_*``), the settings the timing noise cannot
separate from it (``tied_*``) and ``target_error``.  Root attributes: ``timing``,
``cases_reused_from_cache``, ``cases_total``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader, put

STAGE = "workprecision"


@dataclass
class WorkPrecisionRun:
    """What the work-precision stage measured (the writer's input).

    Attributes
    ----------
    results : dict[str, (rows, summary, reference)]
        Per model: ``rows`` ``{method: {column: ndarray (n_rtol,)}}``
        (:func:`walkerlab.bench.workprecision_results.rows_from_cases`), ``summary``
        (:func:`walkerlab.bench.workprecision_results.summarize`), the reference setting.
    cases_reused, cases_total : int
    target_error, contact_target_error : float
    single_run_s : float
        A case slower than this [s] is timed once
        (:data:`walkerlab.bench.workprecision.SINGLE_RUN_S`).
    """

    results: dict
    cases_reused: int
    cases_total: int
    target_error: float
    contact_target_error: float
    single_run_s: float


def write_workprecision(f, run: WorkPrecisionRun) -> None:
    """Fill an open (in-memory) artifact with ``run`` (layout in the module docstring)."""
    for model, (rows, summ, ref) in run.results.items():
        g = f.create_group(model)
        g.attrs["reference_method"], g.attrs["reference_rtol"] = ref[:2]
        for m, d in rows.items():
            put(g, f"{m}/rtol", d["rtol"], "-", "relative tolerance")
            cpu = "thread CPU time of the integration call alone"
            put(g, f"{m}/time", d["time"], "s", f"median {cpu}", clock="thread_cpu")
            put(g, f"{m}/time_min", d["time_min"], "s", f"fastest of the repeats ({cpu})",
                clock="thread_cpu")
            put(g, f"{m}/time_max", d["time_max"], "s", f"slowest of the repeats ({cpu})",
                clock="thread_cpu")
            put(g, f"{m}/wall_time", d["wall_time"], "s", "median wall time of the whole "
                "run (set-up included; shared cores make it noisy)", clock="wall")
            put(g, f"{m}/repeats", d["repeats"], "-", "timed runs (1 when a run "
                f"takes > {run.single_run_s:g} s)")
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
            g.attrs["best_time_min"], g.attrs["best_time_max"] = \
                summ["best_spread"][2], summ["best_spread"][4]
            g.attrs["best_repeats"] = summ["best_spread"][5]
            # whether the fastest setting is faster than the timing noise
            g.attrs["best_separated"] = summ["separated"]
            g.attrs["tied_methods"] = [c[0] for c in summ["tied"]] or [""]
            g.attrs["tied_rtol"] = [c[1] for c in summ["tied"]] or [np.nan]
            g.attrs["tied_time_min"] = [c[2] for c in summ["tied"]] or [np.nan]
            g.attrs["tied_time_max"] = [c[4] for c in summ["tied"]] or [np.nan]
        g.attrs["target_error"] = (run.target_error if model == "ideal"
                                   else run.contact_target_error)
    f.attrs["timing"] = ("each case measured in a worker process pinned to its own "
                         "core, nothing else of walkerlab's on that core; an untimed "
                         "one-stride warm-up run per worker and method; per run the "
                         "thread CPU time (time.thread_time) of the integration call "
                         "alone (ranks the settings) and the wall time of the run")
    f.attrs["cases_reused_from_cache"] = run.cases_reused
    f.attrs["cases_total"] = run.cases_total


@dataclass
class WorkPrecisionModel:
    """One model's study as loaded.

    Attributes
    ----------
    rows : dict[str, dict[str, ndarray (n_rtol,)]]
        Per method: ``time``, ``time_min``, ``time_max`` (CPU time of the integration
        [s]), ``wall_time`` [s], ``error``, ``rtol``, ``nfev``, ``repeats`` (those stored).
    choice : dict
        The model group's attributes (reference, ``best_*``, ``tied_*``, ``pareto_*``,
        ``target_error``).
    """

    rows: dict
    choice: dict


@dataclass
class WorkPrecisionArtifact:
    """A loaded ``workprecision.h5``: ``models`` by name ("ideal", "contact"), in file order."""

    path: Path
    models: dict


@artifact_loader(STAGE)
def load_workprecision(f, path: Path) -> WorkPrecisionArtifact:
    """Load ``workprecision.h5``."""
    models = {}
    for model in f:
        g = f[model]
        rows = {m: {k: g[m][k][()] for k in ("time", "time_min", "time_max", "error",
                                             "rtol", "nfev", "repeats", "wall_time")
                    if k in g[m]}
                for m in g if isinstance(g[m], type(g))}
        models[model] = WorkPrecisionModel(rows, {k: g.attrs[k] for k in g.attrs})
    return WorkPrecisionArtifact(Path(path), models)


def pareto(choice: dict) -> list[dict]:
    """The Pareto front of one model (``choice``: its attributes) as rows ``method``,
    ``rtol``, ``time`` [s], ``error``."""
    return [dict(zip(("method", "rtol", "time", "error"), r))
            for r in zip([str(s) for s in choice.get("pareto_methods", [])],
                         np.asarray(choice.get("pareto_rtol", [])),
                         np.asarray(choice.get("pareto_time", [])),
                         np.asarray(choice.get("pareto_error", [])))]
