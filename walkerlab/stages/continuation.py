"""Stage ``continuation``: the scene's gait continued over a scene field, special points,
period-doubling switches, optional two-parameter curves -> ``continuation_<field>.h5``
(``continuation_<field>+<field2>.h5`` with the curves over a second field, so a
two-parameter run keeps the one-parameter run's artifact;
:mod:`walkerlab.io.schemas.continuation`) and its figure(s) in the report's figures folder.
The computation is :func:`walkerlab.studies.continuation.run_continuation`."""

from __future__ import annotations

import json
from pathlib import Path

from walkerlab.analysis.continuation.gait_map import MapFailed
from walkerlab.config import Scene
from walkerlab.io.runpaths import bifurcation_artifacts, continuation_stem, figures_dir
from walkerlab.io.schemas.bifurcation import load_bifurcation
from walkerlab.io.schemas.continuation import continuation_writer, load_continuation
from walkerlab.models.hybrid.ground import check_periodic_ground
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached
from walkerlab.studies.continuation import check_continuation, run_continuation
from walkerlab.walker.plant import Plant

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint")


def run(scene: Scene, path: str, start: float, stop: float, switch: int = 0,
        path2: str | None = None, range2: tuple | None = None, runs_root: Path | str = "runs",
        force: bool = False) -> StageOutcome:
    """Compute (or reuse) ``continuation_<path>.h5`` (``continuation_<path>+<path2>.h5``
    with ``path2``) and draw its figures under the same name.

    Raises
    ------
    StageError
        No ``fixedpoint`` section, no gait at the scene's own value, or a bad ``switch``.
    walkerlab.config.SceneError
        A range or field the continuation cannot follow
        (:func:`walkerlab.studies.continuation.check_continuation`; one line).
    walkerlab.studies.params.SweepError
        A field that does not exist (one line).
    """
    check_periodic_ground(scene.terrain, "continuation")

    from walkerlab.plotting.continuation_figures import (  # light
        continuation_figure,
        cost_of_transport_figure,
        two_parameter_figure,
    )
    from walkerlab.plotting.figures import save  # light

    require(scene, "fixedpoint", "continuation")
    if switch not in (0, 1, 2):
        raise StageError(f"--switch: {switch} is not 0, 1 or 2 (period doublings to follow)")
    start, stop, range2 = check_continuation(scene, path, start, stop, path2, range2)
    stem = continuation_stem(path, path2)
    key = json.dumps({"param": path, "range": [start, stop], "switch": switch,
                      "param2": path2, "range2": list(range2) if range2 else None})

    def compute():
        try:
            res, curves = run_continuation(scene, path, start, stop, switch, path2, range2,
                                           plant=Plant.from_scene(scene))  # handed down
        except MapFailed as exc:
            raise StageError(f"continuation of {path}: {exc}") from None
        summary = {"special_points": [(s.kind, s.p, s.period, s.cause) for s in res.specials]}
        return continuation_writer(res, curves), summary

    out = run_cached("continuation", scene, runs_root, SECTIONS, (), compute, force,
                     extra_key=key, artifact=stem)
    data = load_continuation(out.path)
    brute = None
    bif = ("bifurcation" if path == "slope.angle_deg" else f"bifurcation_{path}")
    cand = {**bifurcation_artifacts(scene, runs_root),
            "bifurcation": out.path.parent / "bifurcation.h5"}.get(bif)
    if cand is not None and cand.is_file():
        brute = load_bifurcation(cand)
    model = str(getattr(scene.walker, "model", "walker")).replace("_", " ")
    figdir = figures_dir(scene, runs_root)
    figs = save(continuation_figure(data, f"{model}, scene {scene.name}", brute), figdir, stem)
    if data.curves:
        figs += save(two_parameter_figure(data, f"{model}, scene {scene.name}"), figdir,
                     stem + "_two_parameter")
    cot = cost_of_transport_figure(data, f"{model}, scene {scene.name}: cost of transport")
    if cot is not None:
        figs += save(cot, figdir, stem + "_cost_of_transport")
    out.summary.update(figures=figs, data=data)
    return out
