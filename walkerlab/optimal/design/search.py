"""Design optimisation: the numeric scene fields (within bounds) that minimise or maximise a
measure of the scene's own gait, followed from the scene's value (every evaluation starts
the root finder at the last gait found, so the optimiser never jumps to another branch).

Measures (of the period-1 gait ``x*(p)`` of the rigid model): ``step_period`` [s],
``step_length`` [m], ``speed`` [m/s], ``cost_of_transport`` [-] (the energy ledger's,
:mod:`walkerlab.analysis.gait.energy`), ``max_abs_multiplier`` [-] and the robustness
measures of :mod:`walkerlab.optimal.design.measures` (``gait_sensitivity_norm``,
``basin_share``, ``mfpt``).

Gradients of the smooth measures are exact through the fixed point (the implicit function
theorem on the Poincaré map ``P``): ``x* = P(x*, p)`` gives ``dx*/dp = (I - DP)^-1 dP/dp``,
with ``DP`` the map's Jacobian from the variational equations at the fixed point and
``dP/dp``, ``dm/dx``, ``dm/dp`` central differences of single steps; SLSQP
(:func:`scipy.optimize.minimize`) uses them.  ``max_abs_multiplier`` is smooth wherever the
largest multiplier is simple (or one complex pair): its gradient is the eigenvalue
perturbation ``dλ = wᴴ (dDP/dp) v / (wᴴ v)`` (``v``, ``w`` right and left eigenvectors) with
``dDP/dp`` the total derivative of the variational Jacobian along ``(dx*/dp, 1)``, one central
difference of two variational maps per field (:func:`multiplier_gradient`); SLSQP.  Where two
multipliers of different moduli cross it is not differentiable (SLSQP then sees one side).
The basin share and the MFPT are piecewise constant in the design:
Nelder-Mead (derivative-free, within the bounds).  The gait sensitivity norm is smooth but
itself built from differences: its gradient is central differences of the re-solved gait
(step ``1e-4`` of the field's scale), SLSQP.  Hobbelen & Wisse
(2007) and Byl & Tedrake (2009) optimise designs over such gait measures.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from walkerlab.walker.plant import Plant

__all__ = ["MEASURES", "DesignResult", "design_bounds", "design_optimize",
           "measure_gradient", "multiplier_gradient"]

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


class _Gaits:
    """Walkers and their gaits over the design, each solve started at the last gait."""

    def __init__(self, scene, fields, x0, max_step=None, bounds=None):
        from walkerlab.integrate.solver import Solver
        from walkerlab.studies.continuation import scene_value  # light

        self.scene, self.fields = scene, list(fields)
        self.solver = Solver.from_settings(scene.solver)
        # the last gait and its design point: every solve is continued from there
        self.last = np.asarray(x0, float)
        self.p_last = np.array([float(scene_value(scene, f)) for f in self.fields])
        # longest design change solved in one go (field units); longer ones are walked in
        # equal sub-steps, each started at the gait before (natural-parameter continuation)
        self.max_step = None if max_step is None else np.asarray(max_step, float)
        # the design's bounds ((k,), (k,)): no walker is built outside them (a difference
        # stencil at a bound is one-sided there: a stiffness from 0 never goes below it)
        k = len(self.fields)
        lo, hi = (None, None) if bounds is None else bounds
        self.lo = np.full(k, -np.inf) if lo is None else np.asarray(lo, float)
        self.hi = np.full(k, np.inf) if hi is None else np.asarray(hi, float)
        self.count = 0

    def stencil(self, p, j: int, h: float):
        """The two design points of a difference in field ``j`` at ``p``: ``p ± step e_j``
        (``step = h max(1, |p_j|)``) cut at the bounds, and their offsets ``(s+, s-)``
        from ``p_j`` (both ``step`` inside the bounds; one of them 0 at a bound: a
        one-sided difference).  The derivative is ``(f(p+) - f(p-)) / (s+ + s-)``."""
        p = np.asarray(p, float)
        step = h * max(1.0, abs(p[j]))
        pp, pm = p.copy(), p.copy()
        pp[j] = min(self.hi[j], p[j] + step)
        pm[j] = max(self.lo[j], p[j] - step)
        return pp, pm, pp[j] - p[j], p[j] - pm[j]

    def scene_at(self, p):
        from walkerlab.studies.params import apply_point  # light

        return apply_point(self.scene.model_dump(mode="json"), self.fields,
                           tuple(map(float, p)), "optimize --design")

    def walker(self, p):
        from walkerlab.models.registry import build_walker

        sc = self.scene_at(p)  # the design point's walker, described here
        return build_walker(sc, Plant.from_scene(sc))

    def value(self, p, name: str) -> float:
        """A measure that is not one map's (``max_abs_multiplier`` and
        :data:`walkerlab.optimal.design.measures.ROBUSTNESS_MEASURES`) at ``p``."""
        from walkerlab.optimal.design.measures import robustness_measure

        w, fp = self.gait(p)
        if name == "max_abs_multiplier":
            return float(np.max(np.abs(fp.multipliers_variational)))
        return robustness_measure(name, self.scene_at(p), w, fp.x, fp.jacobian_variational)

    def differenced(self, p, name: str, h_rel: float = 1e-4):
        """``(value, gradient (k,))``: central differences of the re-solved measure."""
        p = np.asarray(p, float)
        value = self.value(p, name)
        start = self.last.copy(), self.p_last.copy()
        grad = np.empty(p.size)
        for j in range(p.size):
            pp, pm, sp, sm = self.stencil(p, j, h_rel)
            hi = self.value(pp, name)
            self.last, self.p_last = start[0].copy(), start[1].copy()
            lo = self.value(pm, name)
            self.last, self.p_last = start[0].copy(), start[1].copy()
            grad[j] = (hi - lo) / (sp + sm)
        return value, grad

    def gait(self, p):
        """The walker at ``p`` and its gait, continued from the last one: a change longer
        than ``max_step`` is walked in equal sub-steps, so the root finder never jumps to
        another gait of the same walker (the paper walker has an unstable one, |λ| 2.5,
        a root-finder's jump away at 15 kg)."""
        from walkerlab.analysis.gait.poincare import find_fixed_point  # light

        p = np.asarray(p, float)
        n = 1
        if self.max_step is not None:
            n = max(1, int(np.ceil(np.max(np.abs(p - self.p_last) / self.max_step) - 1e-9)))
        start = self.p_last.copy()
        for k in range(1, n + 1):
            pk = p if k == n else start + (p - start) * (k / n)
            w = self.walker(pk)
            fp = find_fixed_point(w, self.last, self.solver, fd_check=False)
            self.last, self.p_last = np.asarray(fp.x, float), np.asarray(pk, float).copy()
            self.count += 1
        return w, fp


def _measures(walker, x, solver) -> dict[str, float]:
    """The smooth measures of one map from ``x`` (not only at a fixed point)."""
    from walkerlab.analysis.gait.energy import gait_measures  # light
    from walkerlab.analysis.gait.poincare import poincare_map  # light

    steps = walker.steps_per_map
    _, period, _ = poincare_map(walker, np.asarray(x, float), solver)
    g = gait_measures(walker, x, steps, solver)
    return {"step_period": float(period) / steps, "step_length": g["step_length"],
            "speed": g["speed"], "cost_of_transport": g["cost_of_transport"]}


def _gait_at(gaits: _Gaits, p):
    """``(p, walker, x*, DP)`` at the design ``p`` (k,): its walker, its gait's fixed point
    (2n,) and the Poincaré map's variational Jacobian there (2n, 2n), as float arrays."""
    p = np.asarray(p, float)
    w, fp = gaits.gait(p)
    return p, w, np.asarray(fp.x, float), np.asarray(fp.jacobian_variational, float)


def measure_gradient(gaits: _Gaits, p, name: str, h_x: float = 1e-6,
                     h_p: float = 1e-6) -> tuple[float, np.ndarray]:
    """The measure ``name`` of the gait at ``p`` and its gradient (k,) through the fixed
    point (module docstring).

    Raises
    ------
    walkerlab.analysis.gait.poincare.FixedPointNotFound
        No gait at ``p`` near the last one.
    """
    p, w, x, J = _gait_at(gaits, p)
    value = _measures(w, x, gaits.solver)[name]
    n2 = x.size
    dm_dx = np.array([(_measures(w, x + h_x * e, gaits.solver)[name]
                       - _measures(w, x - h_x * e, gaits.solver)[name]) / (2 * h_x)
                      for e in np.eye(n2)])
    grad = np.empty(p.size)
    for j in range(p.size):
        wp, wm, (sp, sm), dx = _gait_shift(gaits, p, j, h_p, x, J)
        dm = (_measures(wp, x, gaits.solver)[name]
              - _measures(wm, x, gaits.solver)[name]) / (sp + sm)
        grad[j] = dm_dx @ dx + dm
    return value, grad


def _gait_shift(gaits: _Gaits, p, j: int, h: float, x, J):
    """The walkers at the difference stencil's two points ``p+``, ``p-``
    (:meth:`_Gaits.stencil`: ``p ± step e_j`` within the bounds), their offsets
    ``(s+, s-)`` and the fixed point's shift ``dx*/dp_j = (I - DP)⁻¹ ∂P/∂p_j`` (2n,) from
    a difference of single maps at the fixed point ``x`` (``J``: its ``DP``; central
    inside the bounds, one-sided at a bound)."""
    from walkerlab.analysis.gait.poincare import poincare_map  # light

    pp, pm, sp, sm = gaits.stencil(p, j, h)
    wp, wm = gaits.walker(pp), gaits.walker(pm)
    dP = (poincare_map(wp, x, gaits.solver)[0] - poincare_map(wm, x, gaits.solver)[0]) \
        / (sp + sm)
    return wp, wm, (sp, sm), np.linalg.solve(np.eye(x.size) - J, dP)


def multiplier_gradient(gaits: _Gaits, p, h: float = 1e-5) -> tuple[float, np.ndarray]:
    """The largest Floquet multiplier's modulus ``|λ|max`` of the gait at ``p`` and its
    gradient (k,) [1/field unit], exact through the fixed point.

    ``x*(p)`` moves by ``dx*/dp_j = (I - DP)⁻¹ ∂P/∂p_j`` (implicit function theorem); the
    variational Jacobian's total derivative ``dDP/dp_j`` is the central difference of
    ``DP(x* ± ε dx*/dp_j, p ± ε e_j)`` (two variational maps, ``ε = h max(1, |p_j|)``), and
    ``d|λ| = Re(conj(λ) wᴴ dDP v / wᴴ v) / |λ|`` (first-order eigenvalue perturbation; e.g.
    Seyranian & Mailybaev 2003, Multiparameter Stability Theory, ch. 2).

    Parameters
    ----------
    gaits : _Gaits
        The design's walkers and gaits (the solve starts at the last gait).
    p : array_like (k,)
        The design fields' values (their units).
    h : float
        Relative step of the directional difference.

    Returns
    -------
    value : float
        ``|λ|max`` [-].
    gradient : ndarray (k,)

    Raises
    ------
    walkerlab.analysis.gait.poincare.FixedPointNotFound
        No gait at ``p`` near the last one.
    """
    from scipy.linalg import eig

    from walkerlab.analysis.gait.poincare import poincare_map  # light

    p, w, x, J = _gait_at(gaits, p)
    ev, W, V = eig(J, left=True, right=True)
    i = int(np.argmax(np.abs(ev)))
    lam, v, wl = ev[i], V[:, i], W[:, i]
    grad = np.empty(p.size)
    for j in range(p.size):
        wp, wm, (sp, sm), dx_dp = _gait_shift(gaits, p, j, h, x, J)
        Jp = poincare_map(wp, x + dx_dp * sp, gaits.solver, jacobian=True)[2]
        Jm = poincare_map(wm, x - dx_dp * sm, gaits.solver, jacobian=True)[2]
        dJ = (np.asarray(Jp, float) - np.asarray(Jm, float)) / (sp + sm)
        dlam = (wl.conj() @ dJ @ v) / (wl.conj() @ v)
        grad[j] = float(np.real(np.conj(lam) * dlam)) / abs(lam)
    return float(abs(lam)), grad


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
                    max_evaluations: int = 60) -> DesignResult:
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
                   bounds=(lo, hi))
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
