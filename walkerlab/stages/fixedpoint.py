"""Stage ``fixedpoint``: period-1 gait of the rigid hybrid walker -> ``fixedpoint.h5``.

The search is :func:`walkerlab.analysis.gait.scene.fixed_point_run`; the layout
:mod:`walkerlab.io.schemas.fixedpoint`.
"""

from __future__ import annotations

import json
from pathlib import Path

from walkerlab.config import Scene, SceneError
from walkerlab.io.schemas.fixedpoint import write_fixedpoint
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint", "published")


def _known(scene: Scene, known) -> Scene | None:
    """The scene whose gait starts this one's search by homotopy (``--from`` or
    ``fixedpoint.from``), None without one; a bad one: StageError (one line)."""
    if known is None and getattr(scene.fixedpoint, "from_", None) is None:
        return None
    from walkerlab.studies.continuation import known_scene  # only for a homotopy start

    try:
        return known_scene(scene, known)
    except SceneError as exc:
        raise StageError(f"fixedpoint.from: {exc}") from None


def _from_key(src: Scene | None) -> str:
    return "" if src is None else "from:" + json.dumps(src.model_dump(mode="json"),
                                                       sort_keys=True)


def fresh_artifact(scene: Scene, runs_root: Path | str = "runs") -> Path | None:
    """``runs/<scene>/fixedpoint.h5`` when it is up to date for ``scene`` (what
    :func:`run` would reuse, with or without the other equation variants), else None
    (missing, stale, edited, or the scene's ``fixedpoint.from`` cannot be read).

    Read-only: nothing is computed or written, no lock is taken.
    """
    from walkerlab.io.artifacts import verified_hash
    from walkerlab.io.freshness import input_hash
    from walkerlab.io.runpaths import RunPathError, stage_artifact

    try:
        path = stage_artifact(scene, runs_root, "fixedpoint")
        from_key = _from_key(_known(scene, None))
    except (StageError, RunPathError, ValueError):
        return None
    if not path.is_file():
        return None
    have = verified_hash(path)
    if have is None:
        return None
    if any(have == input_hash("fixedpoint", scene, SECTIONS, (), extra + from_key)
           for extra in ("variants", "")):
        return path
    return None


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        compare_variants: bool = True, known: Scene | Path | str | None = None
        ) -> StageOutcome:
    """Find the fixed point of the scene's equation variant.

    With ``compare_variants`` (the default) the other equation variants (printed Appendix A,
    ...) of a compass gait compared with published numbers are solved too (~0.1 s), for the
    report's comparison with Eq. (11): ``walkerlab fixedpoint`` then writes the very artifact
    the report needs.  ``compare_variants=False`` reuses such an artifact (a superset).
    ``known`` (or the scene's ``fixedpoint.from``): a scene whose gait is carried to this
    walker by homotopy and used as the initial guess (``walkerlab fixedpoint --from``).

    Raises
    ------
    StageError
        No ``fixedpoint`` section, or no fixed point for the scene's own variant.
    """
    require(scene, "fixedpoint", "fixedpoint")
    src = _known(scene, known)
    from_key = _from_key(src)

    def compute():
        # the rigid analysis only when the gait is computed: a run that reuses fixedpoint.h5
        # (every downstream stage's upstream check) imports none of it
        from walkerlab.analysis.gait.scene import fixed_point_run
        from walkerlab.analysis.gait.search import GaitNotFound

        guess = note = None
        try:
            if src is not None:  # the known gait carried here
                from walkerlab.studies.continuation import homotopy_start

                guess, note = homotopy_start(scene, src)
            run, summary = fixed_point_run(scene, compare_variants, guess, note)
        except GaitNotFound as exc:
            raise StageError(f"fixedpoint: {exc}") from None
        except ValueError as exc:  # a malformed initial guess or gait choice (one line)
            raise StageError(str(exc)) from None
        return (lambda f: write_fixedpoint(f, run)), summary

    return run_cached("fixedpoint", scene, runs_root, SECTIONS, (), compute, force,
                      extra_key=("variants" if compare_variants else "") + from_key,
                      also_accept=() if compare_variants else ("variants" + from_key,))
