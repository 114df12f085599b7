"""Shared stage plumbing: artifact paths, input hashes, skip-if-up-to-date, locking.

Run paths come from :mod:`walkerlab.io.runpaths` (the one place that builds
``runs/<scene>/...``; names checked, every output inside the runs folder).
"""

from __future__ import annotations

import hashlib
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import walkerlab
from walkerlab.config import Scene
from walkerlab.io.artifacts import (
    code_hash,
    content_hash,
    root_attrs,
    verified_hash,
    write_artifact,
)
from walkerlab.io.runpaths import artifact_lock, stage_artifact


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


def artifact_path(scene: Scene, runs_root: Path | str, stage: str) -> Path:
    """``runs/<scene name>/<stage>.h5`` (checked by :func:`walkerlab.io.runpaths.stage_artifact`).

    Raises
    ------
    walkerlab.io.runpaths.RunPathError
        Unsafe scene name, a path outside the runs folder, or a run folder owned by another
        scene file of the same name.
    """
    return stage_artifact(scene, runs_root, stage)


def input_hash(stage: str, scene: Scene, sections: tuple[str, ...],
               upstream: tuple[Path, ...] = (), extra: str = "") -> str:
    """Content hash of everything a stage's output depends on.

    ``extra``: stage options that are not scene sections (e.g. a bifurcation grid).
    Includes the upstream artifacts' *recomputed* content hashes
    (:func:`walkerlab.io.artifacts.content_hash`), not the hashes they store: an upstream
    artifact edited by hand changes the key.
    """
    h = hashlib.sha256()
    h.update(stage.encode())
    h.update(extra.encode())
    h.update(scene.section_json(*sections).encode())
    h.update(walkerlab.__version__.encode())
    h.update(code_hash().encode())
    for p in upstream:
        h.update(str(content_hash(p)).encode())
    return h.hexdigest()


def _tell(msg: str) -> None:
    print(msg, file=sys.stderr)


def _leaves(d, prefix: str = "") -> dict[str, object]:
    if isinstance(d, dict):
        out: dict[str, object] = {}
        for k, v in d.items():
            out.update(_leaves(v, f"{prefix}{k}."))
        return out
    return {prefix.rstrip("."): d}


def changed_fields(path: Path, scene: Scene, sections: tuple[str, ...]) -> list[str]:
    """``"simulate.strides 20 -> 5"`` for each scene field (of ``sections``) whose value in the
    artifact's stored scene differs from ``scene``'s; [] when none or unreadable."""
    import json

    try:
        old = json.loads(str(root_attrs(path, "scene_json")["scene_json"]))
    except (KeyError, ValueError):
        return []
    new = json.loads(scene.model_dump_json())
    was = _leaves({k: old.get(k) for k in sections})
    now = _leaves({k: new.get(k) for k in sections})
    return [f"{k} {was.get(k, '-')} -> {now.get(k, '-')}" for k in sorted(set(was) | set(now))
            if was.get(k) != now.get(k)]


def recompute_reason(path: Path, scene: Scene, sections: tuple[str, ...],
                     have: str | None) -> str:
    """One line saying why an existing artifact ``path`` is out of date (``have``: its
    verified input hash, None when its content does not match its stored hash)."""
    if have is None:
        return "it was written by another walkerlab version or changed after it was written"
    diff = changed_fields(path, scene, sections)
    if diff:
        more = f" (+{len(diff) - 3} more fields)" if len(diff) > 3 else ""
        return "scene changed: " + ", ".join(diff[:3]) + more
    old_code = root_attrs(path, "code_hash").get("code_hash")
    if old_code is not None and str(old_code) != code_hash():
        return "walkerlab's code changed"
    return "an upstream artifact or a stage option changed"


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
    path = stage_artifact(scene, runs_root, artifact or stage, claim=True)
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


def _default_section(scene: Scene, section: str):
    """The section's settings with every field at its default, or None when the section has
    a required field (``contact``: a contact law must be chosen)."""
    import typing

    from pydantic import BaseModel, ValidationError

    ann = type(scene).model_fields[section].annotation  # ``FixedPointSettings | None``
    models = [m for m in typing.get_args(ann) or (ann,)
              if isinstance(m, type) and issubclass(m, BaseModel)]
    if len(models) != 1:
        return None
    try:
        return models[0]()
    except ValidationError:
        return None


def require(scene: Scene, section: str, stage: str):
    """Return the scene section a stage needs; a missing section whose fields are all
    optional is its defaults (``fixedpoint:`` left out runs as ``fixedpoint: {}``); a missing
    section with a required field raises a one-line StageError."""
    val = getattr(scene, section)
    if val is None:
        val = _default_section(scene, section)
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
