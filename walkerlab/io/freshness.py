"""Is a stage's artifact up to date? Its input hash, and why it is not.

A stage's artifact stores the hash of everything its content depends on
(:func:`input_hash`); :func:`recompute_reason` says in one line why an existing artifact no
longer matches (the scene fields that changed, another walkerlab version, ...);
:func:`write_if_stale` is the cache every stage runs through (one writer per artifact, reuse
when up to date, atomic write otherwise).  ``scene``
is a :class:`walkerlab.config.Scene`, taken as it comes (``config`` imports ``io``, never
the other way round; as :func:`walkerlab.io.artifacts.write_artifact` takes it).
"""

from __future__ import annotations

import hashlib
import json
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import walkerlab
from walkerlab.io.artifacts import (
    code_hash,
    content_hash,
    root_attrs,
    verified_hash,
    write_artifact,
)
from walkerlab.io.runpaths import artifact_lock, claimed, stage_artifact
from walkerlab.safefs import NotARegularFile, read_regular, refuse_link

#: Root attribute of an artifact whose result depends on the machine it ran on (a run that a
#: user's wall-clock limit cut short: ``time_limit``), its value one line saying what was
#: cut: such an artifact is written and read like any other but never reused as up to date,
#: so the next run recomputes it (a run bounded by work ends the same everywhere and is kept).
NOT_FINAL_ATTR = "not_final"


def not_final(path: Path) -> str:
    """What cut the artifact ``path`` short (its :data:`NOT_FINAL_ATTR`), "" for a result
    that may be reused (or an absent or unreadable file)."""
    return str(root_attrs(path, NOT_FINAL_ATTR).get(NOT_FINAL_ATTR, ""))


def input_hash(stage: str, scene, sections: tuple[str, ...],
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


def _leaves(d, prefix: str = "") -> dict[str, object]:
    if isinstance(d, dict):
        out: dict[str, object] = {}
        for k, v in d.items():
            out.update(_leaves(v, f"{prefix}{k}."))
        return out
    return {prefix.rstrip("."): d}


def changed_fields(path: Path, scene, sections: tuple[str, ...]) -> list[str]:
    """``"simulate.strides 20 -> 5"`` for each scene field (of ``sections``) whose value in the
    artifact's stored scene differs from ``scene``'s; [] when none or unreadable."""
    try:
        old = json.loads(str(root_attrs(path, "scene_json")["scene_json"]))
    except (KeyError, ValueError):
        return []
    new = json.loads(scene.model_dump_json())
    was = _leaves({k: old.get(k) for k in sections})
    now = _leaves({k: new.get(k) for k in sections})
    return [f"{k} {was.get(k, '-')} -> {now.get(k, '-')}" for k in sorted(set(was) | set(now))
            if was.get(k) != now.get(k)]


def recompute_reason(path: Path, scene, sections: tuple[str, ...],
                     have: str | None) -> str:
    """One line saying why an existing artifact ``path`` is out of date (``have``: its
    verified input hash, None when its content does not match its stored hash)."""
    if have is None:
        if content_hash(path) is None:  # opens (or not) but HDF5 cannot read all of it
            return "it is damaged: HDF5 cannot read all of it"
        return "it was written by another walkerlab version or changed after it was written"
    diff = changed_fields(path, scene, sections)
    if diff:
        more = f" (+{len(diff) - 3} more fields)" if len(diff) > 3 else ""
        return "scene changed: " + ", ".join(diff[:3]) + more
    old_code = root_attrs(path, "code_hash").get("code_hash")
    if old_code is not None and str(old_code) != code_hash():
        return "walkerlab's code changed"
    return "an upstream artifact or a stage option changed"


def drawing_key(artifacts: dict[str, Path]) -> str:
    """Key of figures drawn from ``artifacts`` (``{stage: path}`` of those that exist): their
    *recomputed* content hashes and walkerlab's code (a hand edit, or a recompute after one,
    changes the key)."""
    arts = {s: str(content_hash(p)) for s, p in artifacts.items()}
    return json.dumps({"artifacts": arts, "code": code_hash()}, sort_keys=True)


def stamp_matches(stamp: Path, key: str) -> bool:
    """Whether the stamp file ``stamp`` holds ``key`` (read bounded and non-blocking: a FIFO
    or a huge file in its place is no match)."""
    try:
        return read_regular(stamp, 1 << 16, "figure stamp").decode() == key
    except (OSError, NotARegularFile, UnicodeDecodeError):
        return False


def _tell(msg: str) -> None:
    print(msg, file=sys.stderr)


@dataclass
class CachedArtifact:
    """An artifact :func:`write_if_stale` reused or wrote."""

    path: Path
    reused: bool
    wall_time_s: float
    #: what ``compute`` returned beside its writer ({} when reused)
    summary: dict = field(default_factory=dict)
    #: why an existing artifact was recomputed (one line), "" otherwise
    note: str = ""


def write_if_stale(stage: str, scene, runs_root: Path | str, sections: tuple[str, ...],
                   upstream: tuple[Path, ...], compute: Callable[[], tuple[Callable, dict]],
                   force: bool = False, extra_attrs: dict | None = None, extra_key: str = "",
                   also_accept: tuple[str, ...] = (), artifact: str | None = None,
                   tell: Callable[[str], None] = _tell) -> CachedArtifact:
    """Run ``compute`` unless the stage's artifact is up to date, then write it atomically.

    Parameters
    ----------
    stage : str
        The stage (its name enters the input hash and the artifact's ``stage`` attribute).
    scene : walkerlab.config.Scene
    runs_root : path
        The runs folder (:mod:`walkerlab.io.runpaths`).
    sections : tuple of str
        The scene sections the artifact depends on (:func:`input_hash`).
    upstream : tuple of Path
        Artifacts read by ``compute`` (their recomputed content hashes enter the key).
    compute : callable
        ``compute() -> (writer, summary)``; ``writer(h5file)`` fills the artifact.
    force : bool
        Recompute whatever the existing artifact holds (its content is not hashed).
    extra_attrs : dict, optional
        Root attributes written beside ``code_hash``.
    extra_key : str
        Stage options that enter the input hash (a grid, a sigma list).
    also_accept : tuple of str
        Other ``extra_key`` values whose artifact counts as up to date too (a superset of
        what is asked for).
    artifact : str, optional
        The file stem when it is not the stage's name (``bifurcation_<field>``).
    tell : callable
        Where the waiting and recompute lines go (stderr).

    Returns
    -------
    CachedArtifact
        Reused (``wall_time_s`` 0, empty summary) or written (an artifact whose writer set
        :data:`NOT_FINAL_ATTR`, a run a wall-clock limit cut short, is never reused); an
        existing artifact that is recomputed is never replaced silently: one line through
        ``tell`` says which and why (the scene fields that changed, ``--force``, ...), also
        kept in ``note``.

    Raises
    ------
    walkerlab.io.runpaths.RunPathError, walkerlab.io.artifacts.ArtifactError
        A bad run path, a symbolic link in place of the artifact (both before anything
        is computed), an artifact that cannot be written (one line); and whatever
        ``compute`` raises (nothing is written then).
    """
    def up_to_date(have) -> bool:
        return have == key or any(have == input_hash(stage, scene, sections, upstream, a)
                                  for a in also_accept)

    key = input_hash(stage, scene, sections, upstream, extra_key)
    if not force and claimed(scene, runs_root):  # an up-to-date artifact is reused without
        # writing anything (the lock, the folder's claim): a read-only runs folder serves it;
        # artifacts are replaced atomically, so reading one without the lock sees a whole file
        path = refuse_link(stage_artifact(scene, runs_root, artifact or stage))
        if path.is_file() and up_to_date(verified_hash(path)) and not not_final(path):
            return CachedArtifact(path, True, 0.0, {})
    # a link in place of the artifact is refused now, not after the computation
    path = refuse_link(stage_artifact(scene, runs_root, artifact or stage, claim=True))
    # one writer per artifact: a second identical run waits, then finds the result up to date
    with artifact_lock(path, wait=True, on_wait=tell):
        key = input_hash(stage, scene, sections, upstream, extra_key)
        note = ""
        if path.is_file() and force:
            note = "--force"  # recomputed whatever it holds: its content is not hashed
        elif path.is_file():
            have = verified_hash(path)
            cut = not_final(path)
            if up_to_date(have) and not cut:
                return CachedArtifact(path, True, 0.0, {})
            # never replace a result silently: say what is recomputed and why (one line)
            note = (f"its run was cut short by a wall-clock limit ({cut}), which is never "
                    "kept as a result" if cut and up_to_date(have)
                    else recompute_reason(path, scene, sections, have))
            tell(f"{stage}: recomputing {path} ({note})")
        t0 = time.perf_counter()
        writer, summary = compute()
        wall = time.perf_counter() - t0
        write_artifact(path, stage, scene, key, writer, wall,
                       {"code_hash": code_hash(), **(extra_attrs or {})})
    return CachedArtifact(path, False, wall, summary, note)
