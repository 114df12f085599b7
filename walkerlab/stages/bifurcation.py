"""Stage ``bifurcation``: fixed points, Floquet multipliers and steady states over a slope grid
-> ``bifurcation.h5``, or over any numeric scene field -> ``bifurcation_<field>.h5``
(:func:`walkerlab.io.runpaths.bifurcation_stem`; cached like every stage: rerun only when the
scene's walker, slope, solver or fixed-point settings, the grid, the options or the code
change).

The figure (``<artifact stem>.png/.svg``) is drawn from the artifact into the report's
figures folder, so the report of the scene shows it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from walkerlab.config import CommandOptions, Scene, validate_option
from walkerlab.io.runpaths import figures_dir
from walkerlab.stages.common import StageOutcome, run_cached, with_defaults

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint")


def run(scene: Scene, slopes_deg, runs_root: Path | str = "runs", n_transient: int = 100,
        n_keep: int = 30, workers: int = 2, scheduler=None, force: bool = False,
        steady_state: bool = True, param: str = "slope.angle_deg") -> StageOutcome:
    """Compute (or reuse) the bifurcation diagram and draw ``<artifact stem>.png/.svg``.

    Parameters
    ----------
    slopes_deg : array_like (n,)
        Grid of ``param``, increasing (the slope [deg] by default).
    n_transient, n_keep : int
        Steps simulated per slope, heel strikes kept.
    workers, scheduler
        Local processes or a Dask scheduler address.
    param : str
        Dotted scene field of the grid (lists by item name or index,
        ``walker.leg.bodies.thigh_mass.mass_kg``); default the slope [deg].

    Returns
    -------
    StageOutcome
        ``summary``: ``onset`` (in the parameter's unit; also ``onset_deg`` for the slope),
        ``param``, ``unit``, ``figures``; ``path`` is the artifact.

    Raises
    ------
    StageError
        The scene has no ``fixedpoint`` section.
    walkerlab.sweep.params.SweepError
        ``param`` names no field of the scene or a grid value does not validate (one line,
        before anything runs).
    """
    from walkerlab.io.runpaths import bifurcation_stem
    from walkerlab.io.schemas.bifurcation import SLOPE_PATH, bifurcation_writer, load_bifurcation
    from walkerlab.plotting.sweep_figures import bifurcation_figure, save
    from walkerlab.sweep.bifurcation import bifurcation_diagram, onset_value
    from walkerlab.sweep.params import ParamAxis, axis_unit, check_axes

    scene = with_defaults(scene, "fixedpoint", "bifurcation")
    n_transient = validate_option(CommandOptions, "bifurcation_transient", n_transient,
                                  "--transient")
    n_keep = validate_option(CommandOptions, "bifurcation_keep", n_keep, "--keep")
    workers = validate_option(CommandOptions, "workers", workers, "--workers")
    slopes = [float(s) for s in np.asarray(slopes_deg, float)]
    stem = bifurcation_stem(param)
    if param == SLOPE_PATH:  # the slope's cache key, as before
        key = json.dumps({"slopes_deg": slopes, "n_transient": n_transient, "n_keep": n_keep,
                          "steady_state": steady_state})
    else:
        check_axes(scene, [ParamAxis(param, tuple(slopes), f"{param}=<grid>")])
        key = json.dumps({"param": param, "values": slopes, "n_transient": n_transient,
                          "n_keep": n_keep, "steady_state": steady_state})
    unit = axis_unit(scene, ParamAxis(param, tuple(slopes), param))

    def compute():
        res = bifurcation_diagram(scene, slopes, n_transient, n_keep, workers, scheduler,
                                  steady_state=steady_state, param=param, unit=unit)
        return bifurcation_writer(res), {"onset": res.onset["onset"]}

    out = run_cached("bifurcation", scene, runs_root, SECTIONS, (), compute, force,
                     extra_key=key, artifact=stem)
    data = load_bifurcation(out.path)
    out.summary.setdefault("onset", onset_value(data))
    out.summary.update(param=param, unit=data["parameter_unit"])
    if param == SLOPE_PATH:
        out.summary["onset_deg"] = out.summary["onset"]
    model = str(getattr(scene.walker, "model", "walker")).replace("_", " ")
    figs = save(bifurcation_figure(data, f"{model}, scene {scene.name}"),
                figures_dir(scene, runs_root), stem)
    out.summary["figures"] = figs
    return out
