"""A sweep's plan and identity: which points each chain evaluates, in which order
(:func:`plan_chunks`), a base scene's value at a dotted parameter path (:func:`base_value`)
and the hash that names the sweep's inputs (:func:`sweep_input_hash`: scene, stage, axes,
options, walkerlab's version and code).

Chunks are *runs along the first axis* (for every combination of the other axes; split at
the base scene's own value of the first parameter when it lies inside the axis), dealt
out for balance: all chains run at once (each has one piece in flight), so the workers
stay busy while there are at least as many unfinished chains as workers; a run longer
than ``total / workers`` is dealt out *interleaved* into ``k`` chains (points ``0, k,
2k, ...``, ``1, k+1, ...``).

The chains are run by :mod:`walkerlab.studies.runner` (which re-exports these names).
"""

from __future__ import annotations

import hashlib
import json
import math
from typing import Any

import numpy as np

import walkerlab
from walkerlab.config import Scene
from walkerlab.io.artifacts import code_hash
from walkerlab.studies.params import ParamAxis, grid_points, list_item


def _dotted_get(d: dict, path: str):
    """Value at a dotted path of a scene mapping (list items by name or index); None if
    absent."""
    from walkerlab.config import SceneError

    node: Any = d
    for k in path.split("."):
        if isinstance(node, list):
            try:
                node = list_item(node, k, path)
            except SceneError:
                return None
            continue
        if not isinstance(node, dict) or k not in node:
            return None
        node = node[k]
    return node


def base_value(base: dict, path: str):
    """The value of a dotted field in a scene dump ``base`` (the slope in either unit:
    ``slope.angle_deg`` of a scene given in radians, and the other way round); None if
    absent."""
    v = _dotted_get(base, path)
    if v is None and path == "slope.angle_deg" and _dotted_get(base, "slope.angle_rad") is not None:
        v = math.degrees(_dotted_get(base, "slope.angle_rad"))
    if v is None and path == "slope.angle_rad" and _dotted_get(base, "slope.angle_deg") is not None:
        v = math.radians(_dotted_get(base, "slope.angle_deg"))
    return v


def plan_chunks(axes: list[ParamAxis], base: dict, done: set[int] | frozenset = frozenset(),
                chunk_size: int | None = None, workers: int = 1) -> list[list[tuple[int, tuple]]]:
    """Split the grid into ordered chunks of ``(index, values)``.

    Parameters
    ----------
    axes : list of ParamAxis
    base : dict
        Base scene mapping (its value of the first parameter anchors the runs).
    done : set of int
        Indices already computed (resume); they are left out.
    chunk_size : int, optional
        Longest chunk (consecutive points); default: whole runs, a run of ``m`` points
        longer than ``t = ceil(total / workers)`` dealt out interleaved into
        ``ceil(m / t)`` chains.
    workers : int

    Returns
    -------
    list of list of (int, tuple)
        Chunks in submission order (longest first, for load balance).
    """
    shape = tuple(len(a) for a in axes)
    pts = grid_points(axes)
    a0 = axes[0]
    anchor = None
    bv = base_value(base, a0.path)
    if a0.numeric and isinstance(bv, (int, float)) and not isinstance(bv, bool) and len(a0) > 1:
        vals = np.asarray(a0.values, float)
        anchor = int(np.argmin(np.abs(vals - float(bv))))
    runs: list[list[int]] = []
    for rest in np.ndindex(*shape[1:]) if len(shape) > 1 else [()]:
        line = [int(np.ravel_multi_index((i0, *rest), shape)) for i0 in range(shape[0])]
        if anchor is None or anchor == 0:
            cand = [line]
        else:
            cand = [line[anchor:], line[:anchor][::-1]]
        for r in cand:
            r = [i for i in r if i not in done]
            if r:
                runs.append(r)
    if chunk_size is not None:
        runs = [r[k:k + chunk_size] for r in runs for k in range(0, len(r), max(1, chunk_size))]
    elif workers > 1 and runs:
        target = math.ceil(sum(len(r) for r in runs) / workers)
        runs = [r[j::k] for r in runs for k in [math.ceil(len(r) / target)] for j in range(k)]
    runs.sort(key=len, reverse=True)
    return [[(i, pts[i]) for i in r] for r in runs]


def sweep_input_hash(scene: Scene, stage: str, axes: list[ParamAxis], options: dict) -> str:
    """Content hash of a sweep (scene, stage, axes, options, walkerlab version and code)."""
    h = hashlib.sha256()
    h.update(json.dumps([scene.model_dump(mode="json"), stage,
                         [[a.path, list(a.values)] for a in axes], options],
                        sort_keys=True, default=str).encode())
    h.update(walkerlab.__version__.encode())
    h.update(code_hash().encode())
    return h.hexdigest()
