"""Design optimisation: the numeric scene fields (within bounds) that minimise or maximise a
measure of the scene's own gait, followed from the scene's value (every evaluation starts
the root finder at the last gait found, so the optimiser never jumps to another branch).

Measures (of the period-1 gait ``x*(p)`` of the rigid model): ``step_period`` [s],
``step_length`` [m], ``speed`` [m/s], ``cost_of_transport`` [-] (the energy ledger's,
:mod:`walkerlab.analysis.gait.energy`), ``max_abs_multiplier`` [-] and the robustness
measures of :mod:`walkerlab.optimal.design.measures` (``gait_sensitivity_norm``,
``basin_share``, ``mfpt``).

The optimisers: SLSQP (:func:`scipy.optimize.minimize`) on the smooth measures, with
their gradients through the fixed point, the largest multiplier's by eigenvalue
perturbation and the gait sensitivity norm's by differences of the re-solved gait
(:mod:`walkerlab.optimal.design.gradients`; where two multipliers of different moduli
cross, SLSQP sees one side).  The basin share and the MFPT are piecewise constant in
the design: Nelder-Mead (derivative-free, within the bounds).  Hobbelen & Wisse (2007)
and Byl & Tedrake (2009) optimise designs over such gait measures.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from walkerlab.optimal.design.gradients import _Gaits, measure_gradient, multiplier_gradient

__all__ = ["MEASURES", "DesignResult", "design_bounds", "design_optimize"]

#: Measures of a gait a design can optimise, with their units.
MEASURES = {"step_period": "s", "step_length": "m", "speed": "m/s", "cost_of_transport": "-",
            "max_abs_multiplier": "-", "gait_sensitivity_norm": "-", "basin_share": "-",
            "mfpt": "steps"}
#: gradients through the fixed point (implicit function theorem)
SMOOTH = ("step_period", "step_length", "speed", "cost_of_transport")
#: smooth, gradients by central differences of the re-solved gait
DIFFERENCED = ("gait_sensitivity_norm",)
#: longest design change solved in one go, as a share of each field's bound span
MAX_STEP_SHARE = 0.05
#: smooth where the largest multiplier is simple: eigenvalue perturbation through the gait
SPECTRAL = ("max_abs_multiplier",)


@dataclass
class DesignResult:
    """An optimised design.

    Attributes
    ----------
    fields : list of str
        The scene fields varied (dotted paths).
    values : ndarray (k,)
        Their optimal values (the fields' units).
    objective : str
        The measure (:data:`MEASURES`).
    value : float
        The measure there (its unit).
    gradient : ndarray (k,)
        d measure / d field there (NaN for ``basin_share`` and ``mfpt``, piecewise
        constant).
    success : bool
    message : str
        Why the optimiser stopped.
    evaluations : int
        Fixed points solved.
    history : list of (ndarray, float)
        Each evaluation's field values and measure.
    unit : str
        The measure's unit (:data:`MEASURES`).
    """

    fields: list
    values: np.ndarray
    objective: str
    value: float
    gradient: np.ndarray
    success: bool
    message: str
    evaluations: int
    history: list = field(default_factory=list)
    unit: str = "-"


def design_bounds(scene, items: list[str]) -> dict:
    """The design's bounds from ``--design FIELD=LO:HI`` strings, checked against the scene
    before anything runs: every field once, a numeric field the scene sets (not a whole
    number), ``LO < HI`` both finite, and the scene valid with the field at each bound.

    Parameters
    ----------
    scene : Scene
    items : list of str
        ``FIELD=LO:HI`` (the field's unit).

    Returns
    -------
    dict
        ``{field: (lo, hi)}`` in the order given.

    Raises
    ------
    ValueError
        One line naming ``--design`` and the item.
    """
    import math

    from walkerlab.config.errors import SceneError  # light
    from walkerlab.studies.continuation import scene_value  # light
    from walkerlab.studies.params import ParamAxis, apply_point, takes_whole_numbers  # light

    bounds: dict = {}
    base = scene.model_dump(mode="json")
    for item in items:
        field, _, rng = item.partition("=")
        field = field.strip()
        lo, _, hi = rng.partition(":")
        try:
            lo_v, hi_v = float(lo), float(hi)
        except ValueError:
            raise ValueError(f"--design {item!r}: write FIELD=LO:HI with numbers") from None
        if not (lo_v < hi_v) or not all(math.isfinite(v) for v in (lo_v, hi_v)):
            raise ValueError(f"--design {item!r}: LO < HI, both finite")
        if field in bounds:
            raise ValueError(f"--design {field}: given twice ({field}={bounds[field][0]:g}:"
                             f"{bounds[field][1]:g} and {item}); give each field once")
        try:  # an unknown field, one the scene leaves unset, or a bound out of its range
            scene_value(scene, field)
            if takes_whole_numbers(scene, ParamAxis(field, (), field)):
                raise ValueError(f"{field}: the field takes whole numbers; a design "
                                 "optimisation varies a real number")
            for v in (lo_v, hi_v):
                apply_point(base, [field], (v,), f"--design {item}")
        except (SceneError, ValueError) as exc:
            msg = str(exc).replace(f"--param {field!r}", f"--design {field}", 1)
            raise ValueError(msg if msg.startswith("--design")
                             else f"--design {item}: {msg}") from None
        bounds[field] = (lo_v, hi_v)
    return bounds


def design_optimize(scene, bounds: dict, objective: str, x_gait, maximize: bool = False,
                    max_evaluations: int = 60, *, plant) -> DesignResult:
    """Optimise the scene's fields within ``bounds`` for the gait measure ``objective``.

    Parameters
    ----------
    scene : Scene
        Its gait (``x_gait``) at the fields' present values starts everything.
    bounds : dict
        ``{field: (lo, hi)}`` in the fields' units; the start is the scene's value (clipped).
    objective : str
        A key of :data:`MEASURES`.
    x_gait : ndarray (2n,)
        The scene's gait just after heel strike (``fixedpoint.h5``).
    maximize : bool
    max_evaluations : int
        Cap on the optimiser's iterations.
    plant : walkerlab.walker.plant.Plant
        The scene's plant, built by the stage (each design point's walker is
        :meth:`~walkerlab.walker.plant.Plant.with_` of it).

    Returns
    -------
    DesignResult

    Raises
    ------
    ValueError
        An unknown objective (one line).
    """
    from walkerlab.studies.continuation import scene_value  # light

    if objective not in MEASURES:
        raise ValueError(f"optimize --objective: one of {', '.join(MEASURES)}, not "
                         f"{objective!r}")
    fields = list(bounds)
    lo = np.array([bounds[f][0] for f in fields], float)
    hi = np.array([bounds[f][1] for f in fields], float)
    p0 = np.clip([float(scene_value(scene, f)) for f in fields], lo, hi)
    gaits = _Gaits(scene, fields, x_gait, max_step=MAX_STEP_SHARE * (hi - lo),
                   bounds=(lo, hi), plant=plant)
    sign = -1.0 if maximize else 1.0
    history: list = []
    box = (p0, lo, hi, sign)
    if objective in SMOOTH:
        res, value, grad = _gradient_search(
            gaits, lambda g, p: measure_gradient(g, p, objective), box, 1e-12,
            max_evaluations, history)
    elif objective in DIFFERENCED + SPECTRAL:
        slope = multiplier_gradient if objective in SPECTRAL else \
            (lambda g, p: g.differenced(p, objective))
        res, value, grad = _gradient_search(gaits, slope, box, 1e-10, max_evaluations,
                                            history)
    else:
        res, value, grad = _simplex_search(gaits, objective, box, max_evaluations, history)
    return DesignResult(fields, np.asarray(res.x, float), objective, float(value),
                        np.asarray(grad, float), bool(res.success), str(res.message),
                        gaits.count, history, MEASURES[objective])


def _gradient_search(gaits, slope, box, ftol: float, max_evaluations: int, history: list):
    """SLSQP (Kraft 1988) on ``sign * value`` with its gradient ``slope(gaits, p) -> (value,
    gradient)`` inside the bounds; ``box`` is ``(p0, lo, hi, sign)``.  Every evaluation is
    appended to ``history``; returns ``(res, value, gradient)`` at the clipped optimum."""
    from scipy.optimize import minimize

    p0, lo, hi, sign = box

    def fun(p):
        p = np.clip(p, lo, hi)  # the optimiser's rounding never leaves the bounds
        v, g = slope(gaits, p)
        history.append((np.array(p, float), v))
        return sign * v, sign * g

    res = minimize(fun, p0, jac=True, method="SLSQP", bounds=list(zip(lo, hi)),
                   options={"maxiter": max_evaluations, "ftol": ftol})
    res.x = np.clip(res.x, lo, hi)
    value, grad = slope(gaits, res.x)
    return res, value, grad


def _simplex_search(gaits, objective: str, box, max_evaluations: int, history: list):
    """Nelder-Mead (Nelder & Mead 1965) on ``sign * value`` of a measure with no gradient,
    inside the bounds; ``box`` is ``(p0, lo, hi, sign)``.  Every evaluation is appended to
    ``history``; returns ``(res, value, NaN gradient)`` at the clipped optimum."""
    from scipy.optimize import minimize

    p0, lo, hi, sign = box

    def fun(p):
        p = np.clip(p, lo, hi)
        v = gaits.value(p, objective)
        history.append((np.array(p, float), v))
        return sign * v

    res = minimize(fun, p0, method="Nelder-Mead", bounds=list(zip(lo, hi)),
                   options={"maxfev": max_evaluations, "xatol": 1e-6, "fatol": 1e-9})
    res.x = np.clip(res.x, lo, hi)
    return res, gaits.value(res.x, objective), np.full(len(p0), np.nan)
