"""Stage ``bifurcation``: fixed points, Floquet multipliers and steady states over a slope grid
-> ``bifurcation.h5``, or over any numeric scene field -> ``bifurcation_<field>.h5``
(:func:`walkerlab.io.runpaths.bifurcation_stem`; rerun only when the scene's walker, slope,
solver or fixed-point settings, the grid, the options or the code change).  The diagram is
:func:`walkerlab.studies.bifurcation.bifurcation_diagram`; its figure (``<artifact
stem>.png/.svg``) is drawn from the artifact into the report's figures folder.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.config import Scene
from walkerlab.config.options import bifurcation_options
from walkerlab.io.runpaths import bifurcation_stem, figures_dir
from walkerlab.io.schemas.bifurcation import bifurcation_writer, load_bifurcation
from walkerlab.models.hybrid.ground import check_periodic_ground
from walkerlab.plotting.artifact_figures import save_bifurcation_figure
from walkerlab.stages.common import StageOutcome, run_cached, with_defaults
from walkerlab.studies.bifurcation import bifurcation_diagram, diagram_summary, grid_key
from walkerlab.walker.plant import Plant

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint")


def run(scene: Scene, slopes_deg, runs_root: Path | str = "runs", n_transient: int = 100,
        n_keep: int = 30, workers: int = 2, scheduler=None, force: bool = False,
        steady_state: bool = True, param: str = "slope.angle_deg") -> StageOutcome:
    """Compute (or reuse) the bifurcation diagram over ``slopes_deg`` (n,), increasing values
    of ``param`` (a dotted scene field; the slope [deg] by default), and draw it.

    ``n_transient`` steps are simulated per value and ``n_keep`` heel strikes kept, on
    ``workers`` local processes or a Dask ``scheduler``.  ``summary``: ``onset`` (in the
    parameter's unit; ``onset_deg`` for the slope), ``param``, ``unit``, ``figures``.

    Raises
    ------
    StageError
        The scene has no ``fixedpoint`` section.
    walkerlab.studies.params.SweepError
        ``param`` names no field of the scene or a grid value does not validate (one line,
        before anything runs; :func:`walkerlab.studies.bifurcation.grid_key`).
    """
    check_periodic_ground(scene.terrain, "the bifurcation diagram")

    scene = with_defaults(scene, "fixedpoint", "bifurcation")
    n_transient, n_keep, workers = bifurcation_options(n_transient, n_keep, workers)
    slopes = [float(s) for s in np.asarray(slopes_deg, float)]
    stem = bifurcation_stem(param)
    key, unit = grid_key(scene, slopes, n_transient, n_keep, steady_state, param)

    def compute():
        res = bifurcation_diagram(scene, slopes, n_transient, n_keep, workers, scheduler,
                                  steady_state=steady_state, param=param, unit=unit,
                                  plant=Plant.from_scene(scene))  # described once, handed down
        return bifurcation_writer(res), {"onset": res.onset["onset"]}

    out = run_cached("bifurcation", scene, runs_root, SECTIONS, (), compute, force,
                     extra_key=key, artifact=stem)
    data = load_bifurcation(out.path)
    diagram_summary(data, param, out.summary)
    out.summary["figures"] = save_bifurcation_figure(
        data, str(getattr(scene.walker, "model", "walker")), scene.name,
        figures_dir(scene, runs_root), stem)
    return out
