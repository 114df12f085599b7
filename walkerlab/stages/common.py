"""Shared stage plumbing: the outcome of a stage, its cache, the sections it needs.

The cache is :func:`walkerlab.io.freshness.write_if_stale`; run paths come from
:mod:`walkerlab.io.runpaths` (:func:`~walkerlab.io.runpaths.stage_artifact`); a section
left out as its defaults from :mod:`walkerlab.config.sections`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.config.sections import section_or_default, with_default_section
from walkerlab.io.freshness import write_if_stale


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


def run_cached(stage: str, scene: Scene, runs_root: Path | str, sections: tuple[str, ...],
               upstream: tuple[Path, ...], compute: Callable[[], tuple[Callable, dict]],
               force: bool = False, extra_attrs: dict | None = None,
               extra_key: str = "", also_accept: tuple[str, ...] = (),
               artifact: str | None = None) -> StageOutcome:
    """Run ``compute`` unless the artifact is up to date, then write it atomically
    (:func:`walkerlab.io.freshness.write_if_stale`, where every argument is described).
    ``compute()`` returns ``(writer, summary)``; ``writer(h5file)`` fills the artifact."""
    done = write_if_stale(stage, scene, runs_root, sections, upstream, compute, force,
                          extra_attrs, extra_key, also_accept, artifact)
    return StageOutcome(stage, done.path, done.reused, done.wall_time_s, done.summary,
                        done.note)


def require(scene: Scene, section: str, stage: str):
    """Return the scene section a stage needs; a missing section whose fields are all
    optional is its defaults (``fixedpoint:`` left out runs as ``fixedpoint: {}``); a missing
    section with a required field raises a one-line StageError."""
    val = section_or_default(scene, section)
    if val is None:
        raise StageError(f"scene '{scene.name}' has no '{section}' section, which stage "
                         f"'{stage}' needs")
    return val


def with_defaults(scene: Scene, section: str, stage: str) -> Scene:
    """``scene`` with ``section`` filled with its defaults when it is missing and every field
    of it is optional (see :func:`require`); the scene's file (``origin``) is kept.  Raises
    StageError: the section is missing and has a required field."""
    require(scene, section, stage)
    return with_default_section(scene, section)
