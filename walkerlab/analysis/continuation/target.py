"""Gait targets: the value of one walker parameter (an actuation parameter, typically the
push-off impulse) that gives a period-1 gait with a target speed, step length or step period,
solved together with the fixed point (as Kuo's DynLoco ``findgait(target=speed, varying=P)``).

Unknowns ``u = (z, p)``: the section coordinates ``z`` (2n - 1) of the post-impact state and
the parameter ``p``; equations ``section(P(from_section(z); p)) - z = 0`` and
``measure(z, p) - target = 0`` (one step map gives both), solved by ``scipy.optimize.root``
(MINPACK hybr) from the gait at the parameter's own value.

A walker with neutral coordinates (:attr:`HybridWalker.neutral`, the 3D rimless wheel's
heading: its gaits form a family along it) has them held at the start's values, as
:func:`walkerlab.analysis.gait.poincare.find_fixed_point` and the continuation's
:class:`~walkerlab.analysis.continuation.gait_map.BranchSystem` hold them: their equations
are left out and the root finder solves the others for the other coordinates and ``p``, so
the answer is the member of the scene's own family (the upright wheel rolling at the
start's heading), not one the measure prefers along the family (freed, the heading changes
the distance travelled downhill and the root finder drifts along the family: a wheel
rolling off the fall line, or uphill).  The held equations are checked in the final
residual (on the family they hold by themselves).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.analysis.continuation.gait_map import MapFailed, WalkerFamily
from walkerlab.analysis.gait.metrics import step_length
from walkerlab.analysis.gait.poincare import StepFailed

__all__ = ["MEASURES", "TargetNotReached", "TargetResult", "solve_target"]

#: the measures a target can name: scene-style name -> (measure, unit)
MEASURES = {"speed_m_per_s": ("speed", "m/s"), "step_length_m": ("step_length", "m"),
            "step_period_s": ("step_period", "s")}


class TargetNotReached(RuntimeError):
    """No gait of the family meets the target from the start (one line: why)."""


@dataclass(frozen=True)
class TargetResult:
    """The parameter value and gait that meet a target.

    Attributes
    ----------
    p : float
        The varied parameter's value [its field's unit].
    x : ndarray, shape (2n,)
        The gait's post-impact state [rad, rad/s].
    measures : dict[str, float]
        ``speed`` [m/s], ``step_length`` [m], ``step_period`` [s] of the gait.
    residual : float
        max ``|F|`` at the solution (state part [rad, rad/s] and target part [its unit]).
    maps : int
        Step maps integrated.
    """

    p: float
    x: np.ndarray
    measures: dict
    residual: float
    maps: int


def _measures(walker, x, solver, max_step_time):
    """``(P(x), {speed [m/s], step_length [m], step_period [s]})`` of one map from ``x``."""
    from walkerlab.analysis.gait.poincare import poincare_map

    steps: list = []
    x1, period, _ = poincare_map(walker, x, solver, max_step_time, steps=steps)
    lengths = [step_length(walker, s) for s in steps]
    return x1, {"speed": sum(lengths) / period, "step_length": float(np.mean(lengths)),
                "step_period": period / len(steps)}


def solve_target(family: WalkerFamily, p0: float, x0, measure: str, value: float, *,
                 xtol: float = 1e-11) -> TargetResult:
    """The parameter value near ``p0`` whose period-1 gait has ``measure`` = ``value``.

    Parameters
    ----------
    family : WalkerFamily
        The walker as a function of the varied field (:func:`walkerlab.studies.continuation.
        scene_family`).
    p0 : float
        Start value of the varied field [its unit].
    x0 : array_like, shape (2n,)
        A gait's post-impact state at (or near) ``p0``.
    measure : {"speed", "step_length", "step_period"}
    value : float
        The target [m/s, m or s].
    xtol : float
        Relative tolerance of the root finder.

    Returns
    -------
    TargetResult

    Raises
    ------
    TargetNotReached
        The root finder did not converge, or the gait fell on the way (one line).
    ValueError
        An unknown measure.
    """
    from scipy.optimize import root

    if measure not in {m for m, _ in MEASURES.values()}:
        raise ValueError(f"target: {measure!r} is not one of speed, step_length, step_period")
    try:
        w0 = family.walker(p0)
    except MapFailed as exc:  # the start itself off the field's domain
        raise TargetNotReached(f"no gait at the start ({exc})") from None
    z0 = np.asarray(w0.section(np.asarray(x0, float)), float)
    scale_p = max(abs(p0), 1e-3)
    maps = 0
    held = w0.neutral_in_section()  # the neutral coordinates: held at the start's values
    free = [i for i in range(z0.size) if i not in held]
    rows = free + [z0.size]  # the equations solved: the free ones' and the target's

    def full(u):
        """``u`` of the root finder (the free coordinates, ``p / scale_p``) -> all of them."""
        if not held:
            return u
        z = np.append(z0, 0.0)
        z[rows] = u
        return z

    def F(u):
        nonlocal maps
        z, p = u[:-1], u[-1] * scale_p
        try:
            w = family.walker(float(p))
            x = w.from_section(z)
            x1, m = _measures(w, x, family.solver, family.max_step_time)
        except (MapFailed, StepFailed, ValueError):  # a fall, a value off the domain: away
            return np.full(u.size, 1e3 * (1.0 + np.linalg.norm(u)))
        maps += 1
        return np.concatenate([w.section(x1) - z, [(m[measure] - value) / abs(value)]])

    u0 = np.concatenate([z0, [p0 / scale_p]])
    if held:
        sol = root(lambda v: F(full(v))[rows], u0[rows], method="hybr",
                   options={"xtol": xtol})
        sol.x = full(sol.x)
    else:
        sol = root(F, u0, method="hybr", options={"xtol": xtol})
    res = float(np.max(np.abs(F(sol.x))))  # every equation, the held ones' too
    if not sol.success or res > 1e-8:
        raise TargetNotReached(f"no gait with {measure} = {value:g} near the start "
                               f"(residual {res:.2g}; {' '.join(str(sol.message).split())})")
    return _result_at(family, float(sol.x[-1] * scale_p), sol.x[:-1], res, maps)


def _result_at(family: WalkerFamily, p: float, z, residual: float, maps: int
               ) -> TargetResult:
    """The :class:`TargetResult` of the root at the field's value ``p`` and section
    coordinates ``z`` (:func:`solve_target`): its gait's measures from one more map."""
    w = family.walker(p)
    x = w.from_section(z)
    try:
        _, m = _measures(w, x, family.solver, family.max_step_time)
    except (MapFailed, StepFailed) as exc:  # pragma: no cover - its last map walked
        raise TargetNotReached(str(exc)) from None
    return TargetResult(p, np.asarray(x, float), m, residual, maps)
