"""Stage ``simulate``: N strides of the rigid hybrid walker -> ``simulate.h5``.

The run is :func:`walkerlab.analysis.rigid_run.simulate_run`; the layout
:mod:`walkerlab.io.schemas.simulate`.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.analysis.rigid_run import simulate_run
from walkerlab.config import Scene, SimulateSettings
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.io.schemas.simulate import run_end, strides_of, write_simulate
from walkerlab.stages.common import StageError, StageOutcome, artifact_path, run_cached

SECTIONS = ("walker", "slope", "ideal", "solver", "simulate")


def with_strides(scene: Scene, strides: int | None) -> Scene:
    """Scene with ``simulate.strides`` overridden (section created with defaults if absent)."""
    sim = scene.simulate or SimulateSettings()
    if strides is not None:
        from pydantic import ValidationError

        try:
            sim = SimulateSettings.model_validate({**sim.model_dump(), "strides": strides})
        except ValidationError as err:
            raise StageError(f"--strides {strides}: {err.errors()[0]['msg'].lower()} "
                             "(simulate.strides)") from None
    return scene.model_copy(update={"simulate": sim})


def _longer_run(scene: Scene, runs_root, upstream: tuple[Path, ...]) -> StageOutcome | None:
    """The existing ``simulate.h5`` when it holds *more* strides of the same run (an earlier
    ``simulate --strides N``) than the scene asks for: it contains the scene's strides, and
    the result the user asked for is kept rather than replaced (``StageOutcome.note`` says
    so; the CLI and the report print it)."""
    from walkerlab.io.artifacts import verified_hash
    from walkerlab.io.freshness import input_hash

    path = artifact_path(scene, runs_root, "simulate")
    n = strides_of(path)
    if n is None or n <= scene.simulate.strides:
        return None
    have = verified_hash(path)
    if have is None or have != input_hash("simulate", with_strides(scene, n), SECTIONS, upstream):
        return None
    note = (f"kept {n} strides of an earlier 'simulate --strides {n}'; the scene asks for "
            f"{scene.simulate.strides}, the first {scene.simulate.strides} are the same run")
    return StageOutcome("simulate", path, True, 0.0, {}, note)


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        strides: int | None = None) -> StageOutcome:
    """Simulate ``simulate.strides`` strides (2 steps each) and write ``simulate.h5``.

    The initial state is the fixed point from ``fixedpoint.h5`` (which must exist:
    :mod:`walkerlab.stages.pipeline` runs it first) or the scene's explicit state.  Without
    ``strides`` (the scene's number), an existing run of the same walker with *more* strides
    (``simulate --strides 20``) is reused, and said so, rather than replaced.

    Raises
    ------
    StageError
        Upstream failure; a run that falls is *not* an error: it is recorded
        (``StageOutcome.failure`` says so).
    """
    scene = with_strides(scene, strides)
    sim = scene.simulate
    upstream: tuple[Path, ...] = ()
    if sim.initial_state == "fixed_point":
        upstream = (artifact_path(scene, runs_root, "fixedpoint"),)
    out = None
    if strides is None and not force:
        out = _longer_run(scene, runs_root, upstream)
    if out is None:
        out = run_cached("simulate", scene, runs_root, SECTIONS, upstream,
                         lambda: _compute(scene, upstream), force)
    term = run_end(out.path)
    if term != "heel_strike":
        out.failure = f"the walker did not complete the run: {term}"
    return out


def _compute(scene: Scene, upstream: tuple[Path, ...]):
    fp = load_fixedpoint(upstream[0]) if scene.simulate.initial_state == "fixed_point" else None
    try:
        run = simulate_run(scene, fp)
    except ValueError as exc:
        raise StageError(str(exc)) from None
    return (lambda f: write_simulate(f, run)), run.summary
