"""Shared stage plumbing: the outcome of a stage, skip-if-up-to-date, required sections.

Run paths come from :mod:`walkerlab.io.runpaths` (the one place that builds
``runs/<scene>/...``); whether an artifact is up to date from :mod:`walkerlab.io.freshness`.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.config.sections import default_section
from walkerlab.io.artifacts import code_hash, verified_hash, write_artifact
from walkerlab.io.freshness import input_hash, recompute_reason
from walkerlab.io.runpaths import artifact_lock
from walkerlab.io.runpaths import stage_artifact as artifact_path


class StageError(RuntimeError):
    """A stage cannot run (missing section, failed upstream); the message is one line."""


@dataclass
class StageOutcome:
    """What a stage did: its artifact, whether it was reused, and a printable summary."""

    stage: str
    path: Path
    reused: bool
    wall_time_s: float
    summary: dict = field(default_factory=dict)
    #: why an existing artifact was recomputed, or what was reused in its place (one line)
    note: str = ""
    #: why the run did not reach its goal (a walker that fell: one line), "" when it did;
    #: the CLI exits 1 on it
    failure: str = ""


def _tell(msg: str) -> None:
    print(msg, file=sys.stderr)


def run_cached(stage: str, scene: Scene, runs_root: Path | str, sections: tuple[str, ...],
               upstream: tuple[Path, ...], compute: Callable[[], tuple[Callable, dict]],
               force: bool = False, extra_attrs: dict | None = None,
               extra_key: str = "", also_accept: tuple[str, ...] = (),
               artifact: str | None = None) -> StageOutcome:
    """Run ``compute`` unless the artifact is up to date, then write it atomically.

    ``compute()`` returns ``(writer, summary)``; ``writer(h5file)`` fills the artifact.
    ``extra_key`` enters the input hash; an artifact written with one of the ``also_accept``
    keys (a superset of what is asked for) counts as up to date too.  An existing artifact
    that is recomputed is never replaced silently: one line on stderr says which and why
    (the scene fields that changed, ``--force``, ...), also kept in ``StageOutcome.note``.
    ``artifact``: the file stem when it is not the stage's name (``bifurcation_<field>``;
    from :mod:`walkerlab.io.runpaths`).
    """
    path = artifact_path(scene, runs_root, artifact or stage, claim=True)
    # one writer per artifact: a second identical run waits, then finds the result up to date
    with artifact_lock(path, wait=True, on_wait=_tell):
        key = input_hash(stage, scene, sections, upstream, extra_key)
        note = ""
        if path.is_file() and force:
            note = "--force"  # recomputed whatever it holds: its content is not hashed
        elif path.is_file():
            have = verified_hash(path)
            if have == key or any(have == input_hash(stage, scene, sections, upstream, a)
                                  for a in also_accept):
                return StageOutcome(stage, path, True, 0.0, {})
            # never replace a result silently: say what is recomputed and why (one line)
            note = recompute_reason(path, scene, sections, have)
            _tell(f"{stage}: recomputing {path} ({note})")
        t0 = time.perf_counter()
        writer, summary = compute()
        wall = time.perf_counter() - t0
        write_artifact(path, stage, scene, key, writer, wall,
                       {"code_hash": code_hash(), **(extra_attrs or {})})
    return StageOutcome(stage, path, False, wall, summary, note)


def require(scene: Scene, section: str, stage: str):
    """Return the scene section a stage needs; a missing section whose fields are all
    optional is its defaults (``fixedpoint:`` left out runs as ``fixedpoint: {}``); a missing
    section with a required field raises a one-line StageError."""
    val = getattr(scene, section)
    if val is None:
        val = default_section(scene, section)
    if val is None:
        raise StageError(f"scene '{scene.name}' has no '{section}' section, which stage "
                         f"'{stage}' needs")
    return val


def with_defaults(scene: Scene, section: str, stage: str) -> Scene:
    """``scene`` with ``section`` filled with its defaults when it is missing and every field
    of it is optional (see :func:`require`); the scene's file (``origin``) is kept.

    Raises
    ------
    StageError
        The section is missing and has a required field.
    """
    if getattr(scene, section) is not None:
        return scene
    out = scene.model_copy(update={section: require(scene, section, stage)})
    out._origin = scene.origin
    return out
