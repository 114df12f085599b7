"""Stage ``bifurcation``: fixed points, Floquet multipliers and steady states over a slope grid
-> ``bifurcation.h5`` (cached like every stage: rerun only when the scene's walker, slope,
solver or fixed-point settings, the grid, the options or the code change).

The figure is drawn from the artifact into the report's figures folder, so the report of the
scene shows it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from walkerlab.config import CommandOptions, Scene, validate_option
from walkerlab.stages.common import StageOutcome, require, run_cached
from walkerlab.stages.plot import figures_dir

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint")


def run(scene: Scene, slopes_deg, runs_root: Path | str = "runs", n_transient: int = 100,
        n_keep: int = 30, workers: int = 2, scheduler=None, force: bool = False,
        steady_state: bool = True) -> StageOutcome:
    """Compute (or reuse) the bifurcation diagram and draw ``bifurcation.png/.svg``.

    Parameters
    ----------
    slopes_deg : array_like (n,)
        Slope grid [deg], increasing.
    n_transient, n_keep : int
        Steps simulated per slope, heel strikes kept.
    workers, scheduler
        Local processes or a Dask scheduler address.

    Returns
    -------
    StageOutcome
        ``summary["onset_deg"]`` when computed; ``path`` is the artifact.

    Raises
    ------
    StageError
        The scene has no ``fixedpoint`` section.
    """
    from walkerlab.plotting.sweep_figures import bifurcation_figure, save
    from walkerlab.sweep.bifurcation import (
        bifurcation_diagram,
        bifurcation_writer,
        load_bifurcation,
    )

    require(scene, "fixedpoint", "bifurcation")
    n_transient = validate_option(CommandOptions, "bifurcation_transient", n_transient,
                                  "--transient")
    n_keep = validate_option(CommandOptions, "bifurcation_keep", n_keep, "--keep")
    workers = validate_option(CommandOptions, "workers", workers, "--workers")
    slopes = [float(s) for s in np.asarray(slopes_deg, float)]
    key = json.dumps({"slopes_deg": slopes, "n_transient": n_transient, "n_keep": n_keep,
                      "steady_state": steady_state})

    def compute():
        res = bifurcation_diagram(scene, slopes, n_transient, n_keep, workers, scheduler,
                                  steady_state=steady_state)
        return bifurcation_writer(res), {"onset_deg": res.onset["onset_deg"]}

    out = run_cached("bifurcation", scene, runs_root, SECTIONS, (), compute, force,
                     extra_key=key)
    data = load_bifurcation(out.path)
    out.summary.setdefault("onset_deg", float(data["onset/onset_slope"]))
    model = str(getattr(scene.walker, "model", "walker")).replace("_", " ")
    figs = save(bifurcation_figure(data, f"{model}, scene {scene.name}"),
                figures_dir(scene, runs_root), "bifurcation")
    out.summary["figures"] = figs
    return out
