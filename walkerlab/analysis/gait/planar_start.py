"""A 3D walker's gait started from its planar twin's: what the root finder starts from when a
3D scene gives no initial guess.

The scale-free seeds (:mod:`walkerlab.analysis.gait.starts`) are a planar walker's: from
them the root finder of a 3D walker, whose lateral mode is unstable (Kuo 1999), finds
nothing.  A 3D walker upright at zero hip width is its planar twin embedded in 3D
(:func:`walkerlab.walker.planar.planar_twin`), so

1. the planar twin's gait is found - in closed form where the model has one (the rimless
   wheel, McGeer 1990: :attr:`HybridWalker.closed_form_gait`), else by the planar search
   (:func:`walkerlab.analysis.gait.search.find_gaits`, the scale-free seeds);
2. its values are kept for the 3D walker's states of the same names (the sagittal ones:
   swing, stance, their rates) and the others (lean, heading, roll) set to zero - a gait
   of the 3D walker at zero width;
3. with a hip width, that gait is carried from width 0 (hip-roll joints need a width: from
   :data:`FIRST_WIDTH` of it) to the scene's width by natural-parameter continuation: at
   each width the fixed point by MINPACK (``scipy.optimize.root`` through
   :func:`~walkerlab.analysis.gait.poincare.find_fixed_point`, the previous width's
   variational Jacobian its start), at the screening tolerance
   (:func:`~walkerlab.analysis.gait.starts.coarse_solver`), predicted by the secant through
   the last two widths; a width that fails halves the step.  The scene's search then
   polishes the last point at the scene's own tolerance.

Each width reached is a line of progress (:func:`walkerlab.progress.task`).  Nothing here
knows a state's row: the states are matched by name.
"""

from __future__ import annotations

import time

import numpy as np

from walkerlab import progress
from walkerlab.analysis.gait.poincare import (
    FixedPointGaveUp,
    FixedPointNotFound,
    find_fixed_point,
)
from walkerlab.analysis.gait.search import COARSE_XTOL, GaitNotFound, find_gaits
from walkerlab.analysis.gait.starts import FallbackStart, coarse_solver
from walkerlab.config import Scene, SceneError
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.base import HybridWalker
from walkerlab.models.registry import build_walker
from walkerlab.walker.planar import CONTACT_ONLY_IN_3D, PlanarTwin, planar_twin

__all__ = ["PlanarStart", "planar_start", "planar_fallback", "embed", "carry_width",
           "FIRST_WIDTH"]

#: a walker that needs a hip width (hip-roll joints) is carried from this fraction of it
FIRST_WIDTH = 0.01
#: the first step of the width continuation, as a fraction of the way [-]
FIRST_STEP = 0.25
#: the smallest step before the continuation gives up [-]
MIN_STEP = 1.0 / 256


class PlanarStart:
    """A start for a 3D walker's root finder from its planar twin.

    Attributes
    ----------
    x : ndarray (2n,)
        The 3D walker's state (``walker.state_names()``, [rad, rad/s]).
    note : str
        How it was found (one line, for the search's notes).
    unique : bool
        The twin's gait is its only one (a closed form: the planar wheel's map of the
        rolling rate has one fixed point), so there is no partner to look for.
    """

    def __init__(self, x: np.ndarray, note: str, unique: bool = False):
        self.x, self.note, self.unique = x, note, unique


def _twin_scene(scene: Scene, walker: dict) -> Scene:
    """The scene with ``walker`` as its walker section, no initial guess (the twin's gait is
    searched for from its own seeds) and no contact field only a 3D walker takes."""
    data = scene.model_dump(mode="json", by_alias=True)
    data["walker"] = walker
    for k in CONTACT_ONLY_IN_3D:  # a 3D walker's contact fields (a planar scene refuses)
        (data.get("contact") or {}).pop(k, None)
    fp = data.get("fixedpoint") or {}
    data["fixedpoint"] = {k: v for k, v in fp.items()
                          if k in ("tolerance", "fd_step", "max_step_time_s")}
    data.pop("published", None)
    return Scene.model_validate(data)


def embed(planar: HybridWalker, x_planar: np.ndarray, walker: HybridWalker
          ) -> np.ndarray | None:
    """The 3D ``walker``'s state with the planar twin's values for the states of the same
    name and zero for the others (lateral: lean, heading, roll angles and rates), or None
    when a planar state has no namesake in 3D.

    Parameters
    ----------
    planar, walker : HybridWalker
    x_planar : ndarray (2m,)
        ``planar.state_names()`` order [rad, rad/s].

    Returns
    -------
    ndarray (2n,) or None
    """
    names = list(walker.state_names())
    x = np.zeros(len(names))
    for name, v in zip(planar.state_names(), x_planar, strict=True):
        if name not in names:
            return None
        x[names.index(name)] = float(v)
    return x


def _planar_gait(twin: Scene, plant) -> tuple[np.ndarray, str, bool] | None:
    """The planar twin's gait and how it was found, or None (``plant``: the twin's)."""
    w = build_walker(plant)
    closed = w.closed_form_gait() if w.closed_form_gait is not None else None
    if closed is not None:
        return np.asarray(closed, float), "its gait in closed form", True
    fp = twin.fixedpoint
    try:
        search = find_gaits(w, Solver.from_settings(twin.solver), None, other_gait=False,
                            xtol=fp.tolerance, fd_step=fp.fd_step,
                            max_step_time=fp.max_step_time_s, fd_check=False)
    except GaitNotFound:
        return None
    return search.result.x, f"its {search.gait.describe()}", False


def carry_width(make, x0: np.ndarray, w0: float, w1: float, solver: Solver,
                max_step_time: float = 5.0, fd_step: float = 1e-7,
                label: str = "width", task: str | None = None
                ) -> tuple[np.ndarray | None, int]:
    """Carry a fixed point from ``make(w0)`` to ``make(w1)`` by natural-parameter
    continuation (module docstring, step 3).

    Parameters
    ----------
    make : callable ``float -> HybridWalker``
    x0 : ndarray (2n,)
        A fixed point (or a close guess) of ``make(w0)`` [rad, rad/s].
    w0, w1 : float
        The parameter's values at both ends [its unit].
    solver : Solver
        The scene's (the continuation runs at its screening tolerance).
    label : str
        The parameter's name in the progress lines.
    task : str, optional
        What the progress lines call the continuation (default ``continuation in <label>
        to <w1>``).

    Returns
    -------
    x : ndarray (2n,) or None
        The fixed point at ``w1`` at the screening tolerance (None: the continuation
        stalled, or the time budget ran out).
    points : int
        Widths solved on the way.
    """
    coarse = coarse_solver(solver)
    kw = {"xtol": COARSE_XTOL, "fd_step": fd_step, "max_step_time": max_step_time,
          "fd_check": False}
    t0 = time.perf_counter()
    with progress.task(task or f"continuation in {label} to {w1:g}") as bar:
        try:
            res = find_fixed_point(make(w0), x0, coarse, **kw)
        except (FixedPointNotFound, FixedPointGaveUp):
            return None, 0
        lam, h, points = 0.0, FIRST_STEP, 1
        hist = [(0.0, res.x)]
        bar.advance(1, info=f"{label} {w0:g} ({time.perf_counter() - t0:.1f} s)")
        while lam < 1.0:
            if h < MIN_STEP:
                return None, points
            nxt = min(1.0, lam + h)
            guess = res.x
            if len(hist) > 1:  # secant predictor through the last two widths
                (la, xa), (lb, xb) = hist[-2], hist[-1]
                guess = xb + (xb - xa) * (nxt - lb) / (lb - la)
            w = w0 + nxt * (w1 - w0)
            try:
                new = find_fixed_point(make(w), guess, coarse,
                                       jacobian_guess=res.jacobian_variational, **kw)
            except FixedPointGaveUp:
                return None, points
            except FixedPointNotFound:
                h /= 2
                continue
            res, lam, points = new, nxt, points + 1
            hist.append((lam, res.x))
            bar.advance(1, info=f"{label} {w:g} ({time.perf_counter() - t0:.1f} s)")
            h = min(2 * h, 1.0 - lam) if lam < 1.0 else h
    return res.x, points


def planar_start(scene: Scene, twin: PlanarTwin, walker: HybridWalker, solver: Solver,
                 *, plant) -> PlanarStart | None:
    """A start for the 3D scene's root finder from its planar twin's gait (module
    docstring), or None (a twin without a gait, or a width continuation that stalled).

    Parameters
    ----------
    scene : Scene
        A 3D walker's scene (``walker.space: 3d``).
    twin : walkerlab.walker.planar.PlanarTwin
        Its walker's planar twin (:func:`walkerlab.walker.planar.planar_twin`).
    walker, solver
        The scene's rigid walker and integrator.
    plant : walkerlab.walker.plant.Plant
        The scene's plant, handed down (the twin's and each width's walker are
        :meth:`~walkerlab.walker.plant.Plant.with_` of it).

    Returns
    -------
    PlanarStart or None
    """
    try:
        twin_scene = _twin_scene(scene, twin.walker)
    except (SceneError, ValueError):
        return None
    twin_plant = plant.with_(twin_scene)  # the twin's walker: another description
    found = _planar_gait(twin_scene, twin_plant)
    if found is None:
        return None
    x_planar, how, unique = found
    planar = build_walker(twin_plant)
    x = embed(planar, x_planar, walker)
    if x is None:
        return None
    note = f"initial guess: the planar twin's gait ({how}), upright"
    if twin.width_field is None:
        return PlanarStart(x, note, unique)
    field, w1 = twin.width_field, twin.width
    w0 = 0.0 if twin.width_zero_allowed else FIRST_WIDTH * w1
    data = scene.model_dump(mode="json", by_alias=True)

    def make(width: float) -> HybridWalker:
        data["walker"][field] = float(width)
        sc = Scene.model_validate(data)
        return build_walker(plant.with_(sc))

    fp = scene.fixedpoint
    max_step = fp.max_step_time_s if fp is not None else 5.0
    fd_step = fp.fd_step if fp is not None else 1e-7
    x1, points = carry_width(make, x, w0, w1, solver, max_step, fd_step, f"walker.{field}")
    if x1 is None or not np.all(np.isfinite(x1)):
        return None
    return PlanarStart(x1, f"{note}, carried from walker.{field} {w0:g} to {w1:g} in "
                           f"{points} continuation points", unique)


def planar_fallback(scene: Scene, walker: HybridWalker, solver: Solver, *, plant
                    ) -> FallbackStart | None:
    """The planar-twin start (:func:`planar_start`) as a fallback of the gait search
    (:class:`~walkerlab.analysis.gait.starts.FallbackStart`: found only when tried), or None
    for a walker without a planar twin (a planar one).

    Parameters
    ----------
    scene, walker, solver, plant
        As :func:`planar_start`'s (a walker of either space).

    Returns
    -------
    FallbackStart or None
    """
    twin = planar_twin(scene.walker)
    if twin is None:
        return None
    label = "the planar twin's gait" + (f" carried in walker.{twin.width_field}"
                                        if twin.width_field is not None else ", upright")
    fb = FallbackStart(label, "planar_twin", None)

    def find():
        start = planar_start(scene, twin, walker, solver, plant=plant)
        if start is None:
            return None
        fb.unique = start.unique
        return start.x, start.note

    fb.find = find
    return fb
