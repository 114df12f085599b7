"""The gait over a design and the gradients of its measures, for the design optimisation
(:mod:`walkerlab.optimal.design.search`).

:class:`_Gaits` holds the walkers and their gaits over the design, each solve continued
from the last gait found (so a solve never jumps to another branch), and the difference
stencils cut at the design's bounds.

Gradients of the smooth measures are exact through the fixed point (the implicit function
theorem on the Poincaré map ``P``): ``x* = P(x*, p)`` gives ``dx*/dp = (I - DP)^-1 dP/dp``,
with ``DP`` the map's Jacobian from the variational equations at the fixed point and
``dP/dp``, ``dm/dx``, ``dm/dp`` central differences of single steps
(:func:`measure_gradient`).  ``max_abs_multiplier`` is smooth wherever the largest
multiplier is simple (or one complex pair): its gradient is the eigenvalue perturbation
``dλ = wᴴ (dDP/dp) v / (wᴴ v)`` (``v``, ``w`` right and left eigenvectors) with
``dDP/dp`` the total derivative of the variational Jacobian along ``(dx*/dp, 1)``, one
central difference of two variational maps per field (:func:`multiplier_gradient`).  Where
two multipliers of different moduli cross it is not differentiable.  The gait sensitivity
norm's gradient is central differences of the re-solved gait (:meth:`_Gaits.differenced`,
step ``1e-4`` of the field's scale).
"""

from __future__ import annotations

import numpy as np

__all__ = ["measure_gradient", "multiplier_gradient"]


class _Gaits:
    """Walkers and their gaits over the design, each solve started at the last gait;
    ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant`, handed down by the stage
    (each design point's walker is :meth:`~walkerlab.walker.plant.Plant.with_` of it)."""

    def __init__(self, scene, fields, x0, max_step=None, bounds=None, *, plant):
        from walkerlab.integrate.solver import Solver
        from walkerlab.studies.continuation import scene_value  # light

        self.scene, self.fields, self.plant = scene, list(fields), plant
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

        sc = self.scene_at(p)  # the design point's walker: a neighbour of the scene's
        return build_walker(self.plant.with_(sc))

    def value(self, p, name: str) -> float:
        """A measure that is not one map's (``max_abs_multiplier`` and
        :data:`walkerlab.optimal.design.measures.ROBUSTNESS_MEASURES`) at ``p``."""
        from walkerlab.optimal.design.measures import robustness_measure

        w, fp = self.gait(p)
        if name == "max_abs_multiplier":
            return float(np.max(np.abs(fp.multipliers_variational)))
        return robustness_measure(name, self.scene_at(p), w, fp.x, fp.jacobian_variational,
                                  plant=self.plant)

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
