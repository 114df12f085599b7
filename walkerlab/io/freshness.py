"""Is a stage's artifact up to date? Its input hash, and why it is not.

A stage's artifact stores the hash of everything its content depends on
(:func:`input_hash`); :func:`recompute_reason` says in one line why an existing artifact no
longer matches (the scene fields that changed, another walkerlab version, ...).  ``scene``
is a :class:`walkerlab.config.Scene`, taken as it comes (``config`` imports ``io``, never
the other way round; as :func:`walkerlab.io.artifacts.write_artifact` takes it).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import walkerlab
from walkerlab.io.artifacts import code_hash, content_hash, root_attrs
from walkerlab.safefs import NotARegularFile, read_regular


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
    changes the key; issue 26)."""
    arts = {s: str(content_hash(p)) for s, p in artifacts.items()}
    return json.dumps({"artifacts": arts, "code": code_hash()}, sort_keys=True)


def stamp_matches(stamp: Path, key: str) -> bool:
    """Whether the stamp file ``stamp`` holds ``key`` (read bounded and non-blocking: a FIFO
    or a huge file in its place is no match)."""
    try:
        return read_regular(stamp, 1 << 16, "figure stamp").decode() == key
    except (OSError, NotARegularFile, UnicodeDecodeError):
        return False
