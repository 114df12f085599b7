"""Stage ``simulate``: N strides of the rigid hybrid walker -> ``simulate.h5``.

The run is :func:`walkerlab.analysis.gait.rigid_run.simulate_run`; the layout
:mod:`walkerlab.io.schemas.simulate`.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.analysis.gait.rigid_run import simulate_run
from walkerlab.config import Scene, SceneError
from walkerlab.config.options import with_strides, with_terrain_seed
from walkerlab.io.freshness import input_hash
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.io.schemas.simulate import longer_run_note, run_end, write_simulate
from walkerlab.stages.common import StageError, StageOutcome, run_cached
from walkerlab.walker.plant import Plant

SECTIONS = ("walker", "slope", "ideal", "solver", "simulate")


def sections(scene: Scene) -> tuple[str, ...]:
    """The sections the run depends on: :data:`SECTIONS`, and ``terrain`` (its per-step
    distributions) for a run on a drawn ground (``simulate.terrain_seed``)."""
    sim = scene.simulate
    if sim is not None and sim.terrain_seed is not None:
        return (*SECTIONS, "terrain")
    return SECTIONS


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        strides: int | None = None, terrain_seed: int | None = None) -> StageOutcome:
    """Simulate ``simulate.strides`` strides (2 steps each) and write ``simulate.h5``.

    The initial state is the fixed point from ``fixedpoint.h5`` (which must exist:
    :mod:`walkerlab.stages.pipeline` runs it first) or the scene's explicit state.  Without
    ``strides`` (the scene's number), an existing run of the same walker with *more* strides
    (``simulate --strides 20``) is reused, and said so in ``StageOutcome.note``
    (:func:`walkerlab.io.schemas.simulate.longer_run_note`), rather than replaced, and
    judged on the scene's own strides (a longer run that falls after them walks the
    scene's: ``failure`` stays empty).
    ``terrain_seed`` (``--terrain-seed``): walk the per-step ground of ``terrain.per_step``
    drawn from that seed (:func:`walkerlab.analysis.gait.rigid_run.rough_ground_steps`).

    Raises
    ------
    StageError
        ``strides`` out of bounds, upstream failure; a run that falls is *not* an error: it
        is recorded (``StageOutcome.failure`` says so).
    """
    try:
        scene = with_terrain_seed(with_strides(scene, strides), terrain_seed)
    except SceneError as exc:
        raise StageError(str(exc)) from None
    secs = sections(scene)
    upstream: tuple[Path, ...] = ()
    if scene.simulate.initial_state == "fixed_point":
        upstream = (stage_artifact(scene, runs_root, "fixedpoint"),)
    path, note = stage_artifact(scene, runs_root, "simulate"), ""
    if strides is None and not force:
        note = longer_run_note(path, scene.simulate.strides, lambda n: input_hash(
            "simulate", with_strides(scene, n), secs, upstream))
    out = (StageOutcome("simulate", path, True, 0.0, {}, note) if note else
           run_cached("simulate", scene, runs_root, secs, upstream,
                      lambda: _compute(scene, upstream), force))
    term = run_end(out.path, scene.simulate.strides if note else None)
    if term != "heel_strike":
        out.failure = f"the walker did not complete the run: {term}"
    return out


def _compute(scene: Scene, upstream: tuple[Path, ...]):
    fp = load_fixedpoint(upstream[0]) if scene.simulate.initial_state == "fixed_point" else None
    try:
        run = simulate_run(scene, fp, Plant.from_scene(scene))  # described once, handed down
    except ValueError as exc:
        raise StageError(str(exc)) from None
    return (lambda f: write_simulate(f, run)), run.summary
