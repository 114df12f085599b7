"""One Poincaré map for a whole study: how many steps it has, decided before any point is
solved.

A walker's own map is one step when its legs are mirror images and a stride (two steps)
when they differ (:attr:`walkerlab.models.hybrid.base.HybridWalker.steps_per_map`): a 3D
walker at zero hip width is a step map, at any other width a stride map; a spring's rest
angle away from zero, one leg's mass away from the other's, make the same switch.  A study
that solved each point with its own map would put step multipliers beside stride ones (a
stride's are the step's squared) in one column, and draw the instability rising where it
falls.  The study's map is the least common multiple of its points' maps (a stride when
any point needs one), and every point is solved with it
(:meth:`~walkerlab.models.hybrid.base.HybridWalker.with_steps_per_map`).
"""

from __future__ import annotations

import math

from walkerlab.config import SceneError
from walkerlab.models.registry import build_walker
from walkerlab.studies.params import apply_point

__all__ = ["MODEL_SECTIONS", "study_steps_per_map"]

#: the scene sections the rigid walker (and so its map) is built from: an axis outside them
#: (the slope, the solver, the fixed-point settings) does not change how many steps a map has
MODEL_SECTIONS = ("walker.", "terrain.", "ideal.")


def study_steps_per_map(base: dict, paths: list[str], points, origin: str = "<study>", *,
                        plant) -> int:
    """Steps of the one Poincaré map of a study over ``points``: the least common multiple
    of the maps of the rigid walkers at the points (1: a step, 2: a stride).

    Each distinct combination of the values of the axes that build the walker
    (:data:`MODEL_SECTIONS`) is built once, the other axes at their first point's values;
    a point whose scene does not validate or whose walker cannot be built is left out (its
    row says why when it is solved).

    Parameters
    ----------
    base : dict
        The study's scene as a mapping (``Scene.model_dump(mode="json")``).
    paths : list of str
        Dotted scene fields of the axes.
    points : iterable of tuple
        Values of ``paths`` at each point, in their fields' units.
    origin : str
        Scene origin for messages.
    plant : walkerlab.walker.plant.Plant
        The study's plant (its base scene's, handed down): each point's walker is
        :meth:`~walkerlab.walker.plant.Plant.with_` of it.

    Returns
    -------
    int
        1 when every point's walker has a step map (or none can be built), else the least
        common multiple of their maps' steps.
    """
    model = [i for i, p in enumerate(paths) if p.startswith(MODEL_SECTIONS)]
    seen: set = set()
    steps = 1
    first = None
    for values in points:
        values = tuple(values)
        first = values if first is None else first
        key = tuple(values[i] for i in model)
        if key in seen:
            continue
        seen.add(key)
        at = tuple(values[i] if i in model else first[i] for i in range(len(values)))
        try:
            sc = apply_point(base, list(paths), at, origin)
            own = build_walker(plant.with_(sc)).steps_per_map
        except (SceneError, ValueError):
            continue
        steps = math.lcm(steps, own)
    return steps
