"""One cell of a basin of attraction (:mod:`walkerlab.studies.basin`): start the walker
there, iterate the Poincaré map and classify where it goes (:func:`classify_cell`); a chunk of
cells is one worker's task (:class:`BasinTask`, :func:`run_basin_chunk`), the walker built
once per scene in a worker.

Outcome of a cell (:data:`OUTCOMES`, stored as int8 codes):

``converged``
    ``max|x_k - x*| < converge_tol`` after ``k`` steps (the period-1 gait); for a
    walker with neutral coordinates (:attr:`HybridWalker.neutral`, the 3D rimless
    wheel's heading: its gaits form a family along it) also within ``converge_tol`` of
    the family's member at ``x_k``'s neutral values (:func:`family_member`: the wheel
    rolling straight at another heading has converged)
``other_attractor``
    ``max|x_k - x_{k-p}| < period_tol`` for some ``1 <= p <= max_period``
    away from ``x*`` (a period-``p`` gait; ``p`` is stored)
``fell_forward``
    a fall guard fired with the hip ahead of the stance foot (x > 0)
``fell_backward``
    ... with the hip behind it
``max_steps``
    none of the above within ``max_steps`` steps
``stalled``
    a step longer than ``max_step_time_s``, or a solver failure
``unreachable``
    (``start: heel_strike``) no pre-impact state on the guard has a heel
    strike that lands on the cell; (``start: fixed_point``) no state on the heel-strike
    surface has the cell's coordinates (a 3D walker's corner cell: the projection of
    :func:`slice_state` raises :class:`~walkerlab.models.hybrid.base.OffSection`)

The grid, its chunks, the partial file and resuming are :mod:`walkerlab.studies.basin`'s
(which re-exports these names).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from walkerlab.config import BasinSettings, scene_from_dict
from walkerlab.integrate.rigid import integrate_step
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.base import OffSection
from walkerlab.studies.basin_slice import (
    BasinError,
    heel_strike_slice,
    slice_state,
)

OUTCOMES = ("converged", "other_attractor", "fell_forward", "fell_backward", "max_steps",
            "stalled", "unreachable")
#: a cell's outcome -> its int8 code in the artifact
CODE = {name: i for i, name in enumerate(OUTCOMES)}


def classify_cell(walker, x0: np.ndarray, x_star: np.ndarray, solver, settings,
                  max_step_time: float = 5.0) -> tuple[int, int, int]:
    """Iterate the Poincaré map from ``x0`` and classify where it goes (Schwab & Wisse
    2001; outcomes in the module docstring).

    ``x0`` and ``x_star`` are post-impact states of shape (2n,) (``walker.state_names()``,
    [rad, rad/s]); ``max_step_time`` [s]: a longer step ends the cell as ``stalled``.

    Returns
    -------
    code : int
        Index into :data:`OUTCOMES`.
    steps : int
        Steps taken until the outcome was decided.
    period : int
        Period of the attractor reached, in Poincare maps (strides when the legs differ;
        1 for the fixed point, 0 if none).
    """
    x = np.asarray(x0, dtype=float)
    hist = [x]
    per_map = walker.steps_per_map  # legs that differ: the section is reached every stride
    for k in range(1, settings.max_steps + 1):
        stance = walker.legs[1] if (k - 1) % per_map == 0 else walker.legs[0]
        step_walker = walker.for_stance(stance)
        seg = integrate_step(step_walker, x, solver, max_step_time=max_step_time)
        if seg.termination == "fall":
            hip = step_walker.points(seg.x_end)["hip"]
            return CODE["fell_forward" if float(hip[0]) > 0 else "fell_backward"], k, 0
        if seg.termination != "heel_strike":
            return CODE["stalled"], k, 0
        x = seg.x_next
        if not np.all(np.isfinite(x)):
            return CODE["stalled"], k, 0
        if k % per_map:  # mid-stride: not on the Poincare section of a stride map
            continue
        if float(np.max(np.abs(x - x_star))) < settings.converge_tol:
            return CODE["converged"], k, 1
        if walker.neutral and float(np.max(np.abs(x - hist[-1]))) < settings.converge_tol:
            # settling (a step shorter than the tolerance): near the gait's family?
            member = family_member(walker, x, solver, max_step_time)
            if member is not None and \
                    float(np.max(np.abs(x - member))) < settings.converge_tol:
                return CODE["converged"], k, 1
        for p in range(1, min(settings.max_period, len(hist)) + 1):
            if float(np.max(np.abs(x - hist[-p]))) < settings.period_tol:
                return CODE["other_attractor"], k, p
        hist.append(x)
    return CODE["max_steps"], settings.max_steps, 0


def family_member(walker, x: np.ndarray, solver, max_step_time: float = 5.0
                  ) -> np.ndarray | None:
    """The period-1 gait at the neutral values of ``x`` (:attr:`HybridWalker.neutral`, the 3D
    wheel's heading: the steady rolling motions form a family along it, Coleman, Chatterjee
    & Ruina 1997), found from ``x`` with them held
    (:func:`walkerlab.analysis.gait.poincare.find_fixed_point`, MINPACK hybrd, xtol 1e-12).

    Parameters
    ----------
    walker : HybridWalker
    x : ndarray, shape (2n,)
        A post-impact state near the family (``walker.state_names()``, [rad, rad/s]).
    solver : Solver
    max_step_time : float
        Longest step [s].

    Returns
    -------
    ndarray, shape (2n,) or None
        The member's post-impact state [rad, rad/s]; None where the root finder finds none.
    """
    # light: only a walker with neutral coordinates needs the root finder
    from walkerlab.analysis.gait.poincare import FixedPointNotFound, find_fixed_point  # light

    try:
        res = find_fixed_point(walker, x, solver, fd_check=False, max_step_time=max_step_time)
    except (FixedPointNotFound, ValueError, ArithmeticError):
        return None
    return np.asarray(res.x, dtype=float)


@dataclass(frozen=True)
class BasinTask:
    """A chunk of cells evaluated by one worker (picklable).

    Attributes
    ----------
    base : dict
        Scene mapping (``Scene.model_dump(mode="json")``).
    x_star : tuple of float
        Fixed point (role-ordered).
    cells : tuple of (int, float, float)
        ``(flat index, x value, y value)``.
    plant : walkerlab.walker.plant.Plant
        The study's plant, built by the stage (it pickles with the task).
    """

    base: dict
    x_star: tuple
    cells: tuple
    #: the fixed point's pre-impact state (``basin.start: heel_strike``), else empty
    x_pre: tuple = ()
    plant: Any = field(kw_only=True)


_WALKERS: dict[str, object] = {}


def walker_and_settings(base: dict, plant):
    """``(walker, basin settings, max step time [s])`` of a scene mapping, built once per
    process (the last scene's kept); the settings' axes are the walker's
    (:func:`default_axes`) when the scene names none.  ``plant``: the study's
    :class:`~walkerlab.walker.plant.Plant`, handed down (the walker of ``base`` is
    :meth:`~walkerlab.walker.plant.Plant.with_` of it)."""
    from walkerlab.models.registry import build_walker

    key = json.dumps(base, sort_keys=True)
    if key not in _WALKERS:
        scene = scene_from_dict(base)
        _WALKERS.clear()
        st = scene.basin or BasinSettings()
        mst = st.max_step_time_s or (scene.fixedpoint.max_step_time_s if scene.fixedpoint
                                     else 5.0)
        walker = build_walker(plant.with_(scene))
        if not {"x_axis", "y_axis"} & st.model_fields_set:  # the default axes: this walker's
            st = st.model_copy(update=dict(zip(("x_axis", "y_axis"),
                                               default_axes(walker, (st.x_axis, st.y_axis)))))
        _WALKERS[key] = (walker, st, mst)
    return _WALKERS[key]


def default_axes(walker, axes: tuple[str, str]) -> tuple[str, str]:
    """The basin's axes when the scene names none: ``axes`` (the stance leg's angle and
    rate) where the Poincaré section keeps both, else the first angle it keeps that is not
    neutral (:attr:`HybridWalker.neutral`) and its rate - a 3D wheel's lean and lean rate
    (its spin angle is fixed by the heel-strike surface, its heading neutral)."""
    names = walker.state_names()
    kept = set(walker.section_names())
    if set(axes) <= kept:
        return axes
    for name in names[:len(names) // 2]:
        rate = name.removesuffix("_angle") + "_rate"
        if name in kept and rate in kept and name not in walker.neutral:
            return name, rate
    return axes


def run_basin_chunk(task: BasinTask) -> list[tuple[int, int, int, int]]:
    """Classify every cell of a chunk: ``[(flat index, code, steps, period), ...]`` (a
    cell with no state on the heel-strike surface: ``unreachable``)."""
    walker, st, max_step_time = walker_and_settings(task.base, task.plant)
    solver = Solver("DOP853", st.rtol, st.atol, backend=st.backend)
    x_star = np.asarray(task.x_star, dtype=float)
    axes = (st.x_axis, st.y_axis)
    hs = heel_strike_slice(walker, np.asarray(task.x_pre), axes) if task.x_pre else None
    out = []
    for idx, vx, vy in task.cells:
        try:
            x0 = (slice_state(walker, x_star, axes, (vx, vy), st.start != "phase_plane")
                  if hs is None else hs.state(walker, (vx, vy)))
        except OffSection:  # no state on the heel-strike surface has these coordinates
            x0 = None
        if x0 is None:
            out.append((int(idx), CODE["unreachable"], 0, 0))
            continue
        out.append((int(idx), *classify_cell(walker, x0, x_star, solver, st, max_step_time)))
    return out


def pre_impact_fixed_point(walker, x_star: np.ndarray, settings, max_step_time: float
                           ) -> np.ndarray:
    """The fixed point's state just before its heel strike, shape (2n,) (one step of the
    basin's integrator from ``x_star``); ``walker.state_names()`` order, [rad, rad/s].
    ``max_step_time`` [s] caps the step.

    Raises
    ------
    BasinError
        The step from ``x_star`` does not end in a heel strike.
    """
    solver = Solver("DOP853", settings.rtol, settings.atol, backend=settings.backend)
    x = np.asarray(x_star, dtype=float)
    for k in range(walker.steps_per_map):  # legs that differ: the stride's closing step
        seg = integrate_step(walker.for_stance(walker.legs[1 - k % 2]), x, solver,
                             max_step_time=max_step_time)
        if seg.termination != "heel_strike":
            break
        x = seg.x_next
    if seg.termination != "heel_strike":
        raise BasinError(f"basin.start: the step from the fixed point ended in "
                         f"{seg.termination!r}, not a heel strike")
    return np.asarray(seg.x_end, dtype=float)
