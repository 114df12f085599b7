"""A gait found before as the start of a new scene's gait search: the stored gait of the
walker nearest this one (same structure, fewest and smallest differing numbers), carried to
this walker along the straight line between the two scenes' numeric fields
(:func:`walkerlab.studies.continuation.homotopy_family`) by natural-parameter continuation
at the screening tolerance (:func:`walkerlab.analysis.gait.planar_start.carry_width`).

It is only a *start*: the root finder then polishes it at the scene's own tolerance, so the
gait found is the scene's, whichever stored gait started it.  The stage reads the stored
gaits (:mod:`walkerlab.stages.fixedpoint`); nothing here reads a file.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from walkerlab.analysis.continuation.gait_map import MapFailed
from walkerlab.analysis.gait.planar_start import carry_width
from walkerlab.analysis.gait.starts import FallbackStart
from walkerlab.config import Scene
from walkerlab.integrate.solver import Solver
from walkerlab.studies.continuation import homotopy_family, numeric_fields

__all__ = ["StoredGait", "nearest_stored", "stored_gait_start"]


class StoredGait:
    """A gait stored by an earlier run.

    Attributes
    ----------
    scene : Scene
        The scene it was found for.
    load : callable ``() -> ndarray (2n,)``
        Its fixed point [rad, rad/s] in ``walker.state_names()`` order (read only when
        chosen).
    where : str
        Where it is stored (for the notes).
    what : str
        What it is, for the notes (default ``the gait stored in <where>``).
    """

    def __init__(self, scene: Scene, load: Callable[[], np.ndarray], where: str,
                 what: str | None = None):
        self.scene, self.load, self.where = scene, load, where
        self.what = what or f"the gait stored in {where}"


def _distance(fields: dict) -> tuple[int, float]:
    """How far apart two walkers are: the number of differing fields, then the sum of their
    relative differences."""
    rel = sum(abs(a - b) / max(abs(a), abs(b), 1e-12) for a, b in fields.values())
    return len(fields), rel


def nearest_stored(scene: Scene, stored: Sequence[StoredGait]
                   ) -> tuple[StoredGait, dict] | None:
    """The stored gait of the walker nearest ``scene``'s: the same structure (only numbers
    differ, :func:`~walkerlab.studies.continuation.numeric_fields`: the same states), fewest
    differing fields, then smallest sum of relative differences; None without one.

    Returns
    -------
    (StoredGait, fields) or None
        ``fields``: dotted path -> (stored value, this scene's value).
    """
    best, best_key = None, (math.inf, math.inf)
    new = scene.model_dump(mode="json")
    for s in stored:
        try:
            fields = numeric_fields(s.scene.model_dump(mode="json"), new)
        except ValueError:  # another structure: no straight line joins them
            continue
        key = _distance(fields)
        if key < best_key:
            best, best_key = (s, fields), key
    return best


def stored_gait_start(scene: Scene, stored: Sequence[StoredGait],
                      solver: Solver | None = None, *, plant) -> FallbackStart | None:
    """The nearest stored gait carried to ``scene``'s walker (module docstring) as a start
    of its gait search (:class:`~walkerlab.analysis.gait.starts.FallbackStart`, carried only
    when tried), or None when no stored gait is of the same structure.

    Parameters
    ----------
    scene : Scene
    stored : sequence of StoredGait
    solver : Solver, optional
        The scene's (default ``Solver.from_settings(scene.solver)``).
    plant : walkerlab.walker.plant.Plant
        The scene's plant, handed down by the stage (the walkers on the way from a stored
        gait are :meth:`~walkerlab.walker.plant.Plant.with_` of it).

    Returns
    -------
    FallbackStart or None
    """
    found = nearest_stored(scene, stored)
    if found is None:
        return None
    known, fields = found
    solver = Solver.from_settings(scene.solver) if solver is None else solver
    fp = scene.fixedpoint
    max_step = fp.max_step_time_s if fp is not None else 5.0
    fd_step = fp.fd_step if fp is not None else 1e-7
    over = ", ".join(fields)
    label = known.what + (f", carried in {over}" if fields else "")

    def find():
        try:
            x0 = np.asarray(known.load(), float)
        except (OSError, ValueError, KeyError):
            return None
        if not fields:  # the same walker: its gait is this one's
            return x0, f"initial guess: {known.what} (same walker)"
        make, _ = homotopy_family(known.scene, scene, plant=plant)
        try:
            x, points = carry_width(lambda lam: make({"lambda": lam}), x0, 0.0, 1.0, solver,
                                    max_step, fd_step, "lambda",
                                    f"homotopy from {known.where} over {over}")
        except MapFailed:
            return None
        if x is None or not np.all(np.isfinite(x)):
            return None
        return x, (f"initial guess: {known.what}, carried over {over} "
                   f"({points} continuation points at the screening tolerance)")

    return FallbackStart(label, "stored_gait", find)
