"""Stage ``mfpt``: mean first-passage time on per-step random slopes -> ``mfpt.h5`` (+ figure).

Reads (after the pipeline has run ``fixedpoint``, :mod:`walkerlab.stages.pipeline`) the
scene's ``mfpt`` section (defaults when absent), ``terrain.per_step`` (distribution
and seed) and the gait from ``fixedpoint.h5``; the walks and mesh cells run on local
processes or Dask (:mod:`walkerlab.sweep.mfpt`).  Skipped when the scene sections, the sigma
list, the method, the upstream gait and the code are unchanged.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from walkerlab.config import CommandOptions, MfptSettings, Scene, validate_option
from walkerlab.io.runpaths import artifact_lock, stage_artifact
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.stages.common import (
    StageError,
    StageOutcome,
    _tell,
    artifact_path,
    input_hash,
    require,
)

SECTIONS = ("walker", "slope", "ideal", "terrain", "mfpt")


def figure_path(scene: Scene, runs_root: Path | str) -> Path:
    """``runs/<scene>/report/figures/mfpt.png``."""
    from walkerlab.io.runpaths import figures_dir

    return figures_dir(scene, runs_root) / "mfpt.png"


def draw(scene: Scene, runs_root: Path | str = "runs") -> list[Path]:
    """Draw log MFPT against sigma (PNG + SVG) from ``mfpt.h5``."""
    from walkerlab.io.schemas.mfpt import load
    from walkerlab.plotting.figures import save
    from walkerlab.plotting.mfpt_figures import mfpt_figure

    d = load(artifact_path(scene, runs_root, "mfpt"))
    fig = mfpt_figure(d, f"Mean first-passage time - scene '{scene.name}'")
    return save(fig, figure_path(scene, runs_root).parent, "mfpt")


def check(scene: Scene, sigma_rad: list[float] | None = None, method: str | None = None,
          workers: int = 2, **_options) -> tuple[MfptSettings, int]:
    """The settings (``mfpt`` section with the command-line overrides) and worker count,
    checked before anything runs.

    Raises
    ------
    StageError
        No ``fixedpoint`` section, or an option out of bounds (one line).
    """
    require(scene, "fixedpoint", "mfpt")
    st = scene.mfpt or MfptSettings()
    if sigma_rad is not None:
        sigma_rad = validate_option(MfptSettings, "sigma_rad", list(sigma_rad), "--sigma-rad",
                                    "mfpt.sigma_rad")
    if method is not None:
        method = validate_option(MfptSettings, "method", method, "--method", "mfpt.method")
    workers = validate_option(CommandOptions, "workers", workers, "--workers")
    st = st.model_copy(update={k: v for k, v in (("sigma_rad", sigma_rad), ("method", method))
                               if v is not None})
    return st, workers


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        sigma_rad: list[float] | None = None, method: str | None = None, workers: int = 2,
        scheduler=None) -> StageOutcome:
    """Compute (or reuse) the MFPT of the scene's rigid walker at each sigma.

    Parameters
    ----------
    sigma_rad : list of float, optional
        Per-step slope standard deviations [rad]; overrides ``mfpt.sigma_rad``.
    method : {"mesh", "montecarlo", "both"}, optional
        Overrides ``mfpt.method``.
    workers : int
        Local worker processes (1 = in this process).
    scheduler : str, optional
        Dask scheduler address.

    Raises
    ------
    StageError
        No ``fixedpoint`` section, bad settings, or a walker the per-step terrain cannot
        carry (one line).
    """
    st, workers = check(scene, sigma_rad, method, workers)
    up = artifact_path(scene, runs_root, "fixedpoint")
    path = stage_artifact(scene, runs_root, "mfpt", claim=True)
    with artifact_lock(path, wait=True, on_wait=_tell):
        return _run_locked(scene, runs_root, force, st, workers, scheduler, up, path)


def _run_locked(scene, runs_root, force, st, workers, scheduler, up, path) -> StageOutcome:
    from walkerlab.io.artifacts import verified_hash, write_artifact
    from walkerlab.io.schemas import mfpt as schema

    key = input_hash("mfpt", scene, SECTIONS, (up,),
                     extra=f"sigma={st.sigma_rad};method={st.method}")
    if not force and path.is_file() and verified_hash(path) == key:
        if not figure_path(scene, runs_root).is_file():
            draw(scene, runs_root)
        return StageOutcome("mfpt", path, True, 0.0, {})
    note = ""
    if not force and path.is_file():
        from walkerlab.stages.common import recompute_reason

        note = recompute_reason(path, scene, SECTIONS, verified_hash(path))
        _tell(f"mfpt: recomputing {path} ({note})")
    x_star = load_fixedpoint(up).x
    t0 = time.perf_counter()
    try:
        data = compute(scene, x_star, st, workers, scheduler)
    except ValueError as exc:
        raise StageError(str(exc)) from None
    wall = time.perf_counter() - t0
    write_artifact(path, "mfpt", scene, key, lambda f: schema.write(f, data), wall,
                   {"workers": workers if scheduler is None else 0,
                    "scheduler": str(scheduler or "")})
    draw(scene, runs_root)
    summary = {"sigma_rad": list(map(float, data.sigma_rad)),
               "mfpt_steps_montecarlo": list(map(float, data["mfpt_steps_montecarlo"])),
               "mfpt_steps_mesh": list(map(float, data["mfpt_steps_mesh"]))}
    return StageOutcome("mfpt", path, False, wall, summary, note)


def compute(scene: Scene, x_star: np.ndarray, st: MfptSettings, workers: int = 1,
            scheduler=None):
    """Monte Carlo and/or mesh MFPT at every ``st.sigma_rad`` -> ``MfptData``.

    Raises
    ------
    ValueError
        The walker cannot walk on per-step slopes, or the mesh is asked for a uniform
        slope distribution (its quadrature is Gauss-Hermite).
    """
    from walkerlab.analysis.python_step import needs_python_path
    from walkerlab.io.schemas.mfpt import VARIABLES, MfptData
    from walkerlab.models.registry import build_walker
    from walkerlab.sweep import mfpt as work

    per = scene.terrain.per_step if scene.terrain is not None else None
    dist = per.slope_distribution if per is not None else "normal"
    seed = per.seed if per is not None else st.seed
    if st.method in ("mesh", "both") and dist != "normal":
        raise ValueError("mfpt.method: the mesh integrates a normal slope distribution "
                         "(Gauss-Hermite); use --method montecarlo for "
                         "terrain.per_step.slope_distribution: uniform")
    walker = build_walker(scene)
    if st.method in ("mesh", "both") and needs_python_path(walker):
        raise ValueError("mfpt.method: the mesh needs the compiled batched step map (its "
                         "~10^6 step images); this walker has no compiled flows (flat feet): "
                         "use --method montecarlo")
    work.step_map_for(scene.model_dump(mode="json"))  # validates the walker in this process
    sig = np.asarray(st.sigma_rad, float)
    vals = {k: np.full(sig.size, np.nan) for k in VARIABLES}
    hist = []
    for i, sd in enumerate(sig):
        if st.method in ("montecarlo", "both"):
            t = time.perf_counter()
            mc = work.monte_carlo(scene, x_star, sd, st.walks, st.max_steps, seed, dist,
                                  workers, scheduler)
            m, se = mc.mfpt
            vals["mfpt_steps_montecarlo"][i] = m
            vals["mfpt_steps_montecarlo_stderr"][i] = se
            vals["montecarlo_walks"][i] = mc.steps.size
            vals["montecarlo_falls"][i] = int(mc.fell.sum())
            vals["montecarlo_heel_strikes"][i] = int(mc.steps.sum())
            vals["montecarlo_wall_time_s"][i] = time.perf_counter() - t
        if st.method in ("mesh", "both"):
            t = time.perf_counter()
            last, all_meshes = work.mesh(scene, x_star, sd, st, workers, scheduler)
            vals["mfpt_steps_mesh"][i] = last.mfpt_steps
            vals["mfpt_steps_mesh_quasi_stationary"][i] = last.mfpt_quasi_stationary_steps
            vals["mesh_cells"][i] = last.cells
            vals["mesh_change"][i] = last.change
            vals["mesh_converged"][i] = float(last.converged)
            vals["mesh_escaped"][i] = last.escaped
            vals["mesh_wall_time_s"][i] = time.perf_counter() - t
            hist += [{"sigma_rad": float(sd), "h": r.h, "cells": r.cells,
                      "mfpt_steps": r.mfpt_steps,
                      "change": r.change if math.isfinite(r.change) else math.nan}
                     for r in all_meshes]
    return MfptData(sig, vals, st.method, walker.state_names(), hist)
