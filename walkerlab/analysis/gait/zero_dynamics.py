"""The hybrid zero dynamics of a walker under virtual constraints and its restricted
Poincare map, by quadrature along the constraint surface (Westervelt, Grizzle & Koditschek
2003, IEEE TAC 48(1):42-56, Sec. V, Theorems 2-4; Westervelt et al. 2007, *Feedback
Control of Dynamic Bipedal Robot Locomotion*, Sec. 5.4-5.5).

With ``y = 0`` the configuration is ``q(theta)`` (the outputs at ``hd(s(theta))``) and the
velocity ``q'(theta) theta'``.  With ``b`` spanning the annihilator of the actuators'
columns (``b^T B = 0``: for absolute link angles a rotation of the whole walker about its
stance foot, ``b = (1, ..., 1)``), ``sigma = b^T M(q) dq`` (the angular momentum about the
stance foot) is driven by gravity alone, ``sigma' = -b^T G(q)`` (the kinetic energy does not
change under the rotation ``b``: checked, ``W = q'^T (d M / d b) q'`` = 0).  On the surface
``sigma = I(theta) theta'``, ``I = b^T M q'``, so ``zeta = sigma^2 / 2`` obeys::

    d zeta / d theta = -I(theta) b^T G(q(theta)),   zeta(theta) = zeta+ - V(theta),
    V(theta) = int_{theta+}^{theta} I b^T G d theta

The heel strike maps ``sigma-`` to ``sigma+ = delta sigma-``, ``delta = b^T M(q+) Delta_dq
q'(theta-) / I(theta-)``, so the restricted Poincare map (pre-impact ``zeta-``) is
``rho(zeta) = delta^2 zeta - V(theta-)``; its fixed point ``zeta* = -V(theta-) / (1 -
delta^2)`` exists (a step that reaches ``theta-``) when ``delta^2 < 1`` and
``delta^2 / (1 - delta^2) V(theta-) + V_max < 0``, ``V_max`` the largest ``V`` over the
step, and is exponentially stable with multiplier ``delta^2``.  The step period is
``T = int_{theta+}^{theta-} d theta / theta' = int I / sigma d theta``.

The integrals are Chebyshev interpolants on the step's phase interval (Trefethen 2013,
*Approximation Theory and Approximation Practice*: the integrands are analytic, so 64
points reach round-off) and a Gauss-Legendre rule for the period.
"""

from __future__ import annotations

import time
import weakref
from dataclasses import dataclass, field

import numpy as np

from walkerlab.integrate.rigid import integrate_step
from walkerlab.models.hybrid.virtual_constraints import annihilator, bezier

__all__ = ["ZeroDynamics", "compare_full_order", "gaits_on_zero_dynamics", "impact_multiplier",
           "no_orbit_reason", "zero_dynamics"]

#: Chebyshev points of the integrands along the step
NODES = 64
#: :func:`no_orbit_reason` of each controller (weakly held: gone with its walker)
_NO_ORBIT: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass
class ZeroDynamics:
    """The hybrid zero dynamics of one controller (module docstring for the symbols).

    Attributes
    ----------
    delta2 : float
        ``delta^2``, the restricted map's multiplier [-].
    v_minus, v_max : float
        ``V(theta-)`` and ``max V`` over the step [(kg m^2/s)^2, as ``zeta``].
    zeta_star : float
        The fixed point ``zeta*`` (pre-impact) [(kg m^2/s)^2]; NaN without one.
    exists : bool
        ``delta^2 < 1`` and ``delta^2 / (1 - delta^2) V(theta-) + V_max < 0``.
    existence_margin : float
        ``delta^2 / (1 - delta^2) V(theta-) + V_max`` (< 0: a fixed point exists).
    theta_plus, theta_minus : float
        The phase variable at the step's start and end [rad or m].
    phase_rate_minus, phase_rate_plus : float
        ``theta'`` at the fixed point just before / after the heel strike [rad/s or m/s].
    step_period_s : float
        The step's duration at the fixed point, by quadrature [s].
    x_plus : ndarray (2n,)
        The fixed point's post-impact state on the surface [rad, rad/s].
    max_torque_n_m : float
        Largest ``|u|`` of the feedforward torque along the periodic orbit [N m].
    saturates : bool
        ``max_torque_n_m`` exceeds the controller's saturation (the computed torque is then
        not applied: the zero dynamics is not the closed loop's).
    kinetic_invariance : float
        ``max |W| / max |I|`` over the step (0: the rotation ``b`` leaves the kinetic
        energy unchanged, the quadrature's premise).
    timing_delta2_s, timing_total_s : float
        Wall time of ``delta^2`` alone and of everything here [s].
    min_clearance_m : float
        The swing foot's lowest height inside the step on the surface [m] (< 0: it strikes
        the ground before ``theta-``, and the full-order gait is not the zero dynamics').
    phase_unit : str
        The phase variable's unit (rad, or m for the hip's position).
    design : walkerlab.models.hybrid.virtual_constraints.Design
    output_names, joints : tuple of str
        The outputs and the actuated joints.
    full_order : dict
        The full-order fixed point's counterparts (:func:`compare_full_order`; empty until
        then).
    """

    delta2: float
    v_minus: float
    v_max: float
    zeta_star: float
    exists: bool
    existence_margin: float
    theta_plus: float
    theta_minus: float
    phase_rate_minus: float
    phase_rate_plus: float
    step_period_s: float
    x_plus: np.ndarray = field(repr=False)
    max_torque_n_m: float = np.nan
    saturates: bool = False
    kinetic_invariance: float = 0.0
    timing_delta2_s: float = np.nan
    timing_total_s: float = np.nan
    min_clearance_m: float = np.nan
    phase_unit: str = "rad"
    design: object = field(default=None, repr=False)
    output_names: tuple = ()
    joints: tuple = ()
    full_order: dict = field(default_factory=dict)

    @property
    def stable(self) -> bool:
        """``delta^2`` inside the unit interval (the restricted map contracts)."""
        return bool(0.0 <= self.delta2 < 1.0)


def impact_multiplier(ctrl, b=None) -> float:
    """``delta^2`` of ``ctrl`` (a
    :class:`walkerlab.models.hybrid.virtual_constraints.VirtualConstraintController`): the
    heel strike's ratio of ``sigma`` on the surface, squared."""
    d = ctrl.design
    n = ctrl.n
    b = annihilator(ctrl.B) if b is None else b
    dth = d.theta_minus - d.theta_plus
    qd = ctrl.tangent(d.q_minus, bezier(d.alpha, 1.0)[1], dth)
    M_m = ctrl.fns["matrices"](np.concatenate([d.q_minus, qd]))[0]
    xp = np.real(ctrl.fns["reset"](np.concatenate([d.q_minus, qd])))
    M_p = ctrl.fns["matrices"](xp)[0]
    sig_m = b @ np.real(M_m) @ qd
    sig_p = b @ np.real(M_p) @ xp[n:]
    return float((sig_p / sig_m) ** 2)


def zero_dynamics(ctrl) -> ZeroDynamics:
    """The zero dynamics, its restricted Poincare map and the fixed point's step (module
    docstring).

    Parameters
    ----------
    ctrl : walkerlab.models.hybrid.virtual_constraints.VirtualConstraintController

    Returns
    -------
    ZeroDynamics
    """
    from numpy.polynomial import Chebyshev

    t0 = time.perf_counter()
    b = annihilator(ctrl.B)
    delta2 = impact_multiplier(ctrl, b)
    t_delta = time.perf_counter() - t0
    d = ctrl.design
    n = ctrl.n
    th_p, th_m = d.theta_plus, d.theta_minus
    dth = th_m - th_p
    k = np.arange(NODES)
    s = np.sort((1 - np.cos(np.pi * (k + 0.5) / NODES)) / 2)  # Chebyshev points in (0, 1)
    qs, ts = ctrl.path(s)
    I_, bG, W = _node_terms(ctrl, b, qs, ts)
    theta = th_p + s * dth
    dom = sorted((th_p, th_m))
    integrand = Chebyshev.fit(theta, I_ * bG, NODES - 1, domain=dom)
    V = integrand.integ(lbnd=th_p)
    inertia = Chebyshev.fit(theta, I_, NODES - 1, domain=dom)
    v_minus = float(V(th_m))
    v_max = _v_max(V, integrand, th_p, th_m)
    margin = (delta2 / (1 - delta2) * v_minus + v_max) if delta2 < 1 else np.inf
    exists = bool(delta2 < 1 and margin < 0)
    zeta = -v_minus / (1 - delta2) if delta2 < 1 else np.nan
    rate_m = rate_p = period = np.nan
    x_plus = np.full(2 * n, np.nan)
    umax = np.nan
    if exists:
        rate_m, rate_p, period, x_plus, umax = _orbit(ctrl, V, inertia, delta2 * zeta, zeta,
                                                      (qs, ts, theta))
    return ZeroDynamics(
        delta2=delta2, v_minus=v_minus, v_max=v_max, zeta_star=float(zeta), exists=exists,
        existence_margin=float(margin), theta_plus=th_p, theta_minus=th_m,
        phase_rate_minus=rate_m, phase_rate_plus=rate_p, step_period_s=period, x_plus=x_plus,
        max_torque_n_m=umax, saturates=bool(ctrl.limit is not None and umax > ctrl.limit),
        kinetic_invariance=float(np.max(np.abs(W)) / np.max(np.abs(I_))),
        timing_delta2_s=t_delta, timing_total_s=time.perf_counter() - t0,
        min_clearance_m=min(ctrl.pieces.foot(q)[0] for q in qs),
        phase_unit="m" if ctrl.spec.phase.point is not None else "rad", design=d,
        output_names=tuple(ctrl.output_names), joints=tuple(ctrl.joints))


def _node_terms(ctrl, b: np.ndarray, qs, ts) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """At the nodes' configurations ``qs`` and tangents ``ts`` of the path: ``b^T M q'``
    (the zero dynamics' inertia), ``b^T G`` and ``q'^T (dM/dq b) q'`` (kinetic invariance's
    residual, by a complex step), each (NODES,)."""
    n = ctrl.n
    I_ = np.empty(NODES)
    bG = np.empty(NODES)
    W = np.empty(NODES)
    h = 1e-30
    for j, (q, qp) in enumerate(zip(qs, ts)):
        x = np.concatenate([q, qp])
        M, _C, G = ctrl.fns["matrices"](x)
        I_[j] = b @ np.real(M) @ qp
        bG[j] = b @ np.real(np.ravel(G))
        xc = x.astype(complex)
        xc[:n] += 1j * h * b
        dM = np.imag(ctrl.fns["matrices"](xc)[0]) / h
        W[j] = qp @ dM @ qp
    return I_, bG, W


def _v_max(V, integrand, th_p: float, th_m: float) -> float:
    """The zero dynamics' potential's maximum over the step (at least 0), on a grid refined
    by brentq where it is inside (``V' = I b^T G = 0``)."""
    grid = np.linspace(th_p, th_m, 2001)
    vals = V(grid)
    j = int(np.argmax(vals))
    v_max = float(vals[j])
    if 0 < j < len(grid) - 1:  # refine the interior maximum: V' = I b^T G = 0
        from scipy.optimize import brentq

        a, c = sorted((grid[j - 1], grid[j + 1]))
        if integrand(a) * integrand(c) < 0:
            r = brentq(integrand, a, c, xtol=1e-15)
            v_max = max(v_max, float(V(r)))
    return max(v_max, 0.0)


def _orbit(ctrl, V, inertia, zeta_p: float, zeta: float, nodes: tuple) -> tuple:
    """The fixed point's step on the zero dynamics (``zeta_p = delta^2 zeta``, ``zeta`` the
    energies after and before the heel strike): the phase rates before and after the heel
    strike, the step period [s] (Gauss-Legendre quadrature), the state after the heel
    strike (2n,) and the largest torque [N m] at the path's ``nodes`` ``(qs, ts, theta)``."""
    qs, ts, theta = nodes
    d = ctrl.design
    th_p, dth = d.theta_plus, d.theta_minus - d.theta_plus
    sign = np.sign(dth)
    rate_m = float(sign * np.sqrt(2 * zeta) / abs(inertia(d.theta_minus)))
    rate_p = float(sign * np.sqrt(2 * zeta_p) / abs(inertia(th_p)))
    xg, wg = np.polynomial.legendre.leggauss(NODES)
    tg = th_p + (xg + 1) / 2 * dth
    period = float(abs(dth) / 2 * np.sum(wg * np.abs(inertia(tg))
                                         / np.sqrt(2 * (zeta_p - V(tg)))))
    qp0 = ctrl.tangent(d.q_plus, bezier(d.alpha, 0.0)[1], dth)
    x_plus = np.concatenate([d.q_plus, qp0 * rate_p])
    us = []
    for q, qp, th in zip(qs, ts, theta):
        rate = sign * np.sqrt(2 * max(zeta_p - V(th), 0.0)) / abs(inertia(th))
        _y, _dy, A, Lf2, _mb = ctrl.terms(np.concatenate([q, qp * rate]))
        us.append(np.linalg.solve(np.real(A), -np.real(Lf2)))
    return rate_m, rate_p, period, x_plus, float(np.max(np.abs(us)))


def compare_full_order(zd: ZeroDynamics, ctrl, walker, result, solver) -> dict:
    """The full-order fixed point's counterparts of the restricted map's numbers, stored in
    ``zd.full_order`` and returned: ``phase_rate_minus``, ``phase_rate_plus`` (its phase
    rates at the heel strike [rad/s or m/s]), ``step_period_s``, ``delta2_multiplier`` (the
    variational Floquet multiplier nearest ``delta^2``), ``other_multiplier`` (the largest
    ``|multiplier|`` of the others: the feedback's), ``output_plus``, ``output_rate_plus``
    (``max |y|``, ``max |y'|`` just after the heel strike [rad, rad/s]).

    Parameters
    ----------
    zd : ZeroDynamics
    ctrl : walkerlab.models.hybrid.virtual_constraints.VirtualConstraintController
    walker : HybridWalker
    result : walkerlab.analysis.gait.poincare.FixedPointResult
    solver : walkerlab.integrate.solver.Solver
    """
    n = ctrl.n  # the map's first step (walkerlab.analysis.gait.poincare.poincare_map's)
    x_minus = np.asarray(integrate_step(walker.for_step(0), result.x, solver,
                                        stance_leg=walker.legs[1]).x_end, float)

    def rate(x):
        _h0, _J, _dd, _th, gth, _ = ctrl.pieces(np.asarray(x, float))
        return float(gth @ np.asarray(x, float)[n:])
    mult = np.asarray(result.multipliers_variational)
    j = int(np.argmin(np.abs(mult - zd.delta2)))
    others = np.delete(mult, j)
    y, dy = ctrl.outputs(result.x)
    zd.full_order = {
        "phase_rate_minus": rate(x_minus), "phase_rate_plus": rate(result.x),
        "step_period_s": float(result.period_s), "delta2_multiplier": complex(mult[j]),
        "other_multiplier": float(np.max(np.abs(others))) if others.size else 0.0,
        "output_plus": float(np.max(np.abs(y))), "output_rate_plus": float(np.max(np.abs(dy)))}
    return zd.full_order


def gaits_on_zero_dynamics(walker) -> bool:
    """Whether ``walker`` (a :class:`~walkerlab.models.hybrid.base.HybridWalker`) is under
    virtual constraints whose gaits are orbits of their hybrid zero dynamics: outputs made
    invariant by the heel strike (``invariant: true``) and driven to zero by unsaturated
    computed torque (no ``max_torque_n_m``; Westervelt, Grizzle & Koditschek 2003, IEEE
    TAC 48(1):42-56, Sec. V, Theorems 3-4).  Its gait search then starts on that orbit
    only (:func:`walkerlab.analysis.gait.search.find_gaits`)."""
    ctrl = getattr(getattr(walker, "actuators", None), "controller", None)
    return ctrl is not None and bool(ctrl.spec.invariant) and ctrl.limit is None


def no_orbit_reason(walker) -> str:
    """Why a walker under invariant virtual constraints has no gait, or ``""``.

    Under outputs made invariant by the heel strike (``invariant: true``) and driven to
    zero by unsaturated computed torque, a period-1 gait of the closed loop is a periodic
    orbit of its hybrid zero dynamics (Westervelt, Grizzle & Koditschek 2003, IEEE TAC
    48(1):42-56, Sec. V, Theorems 3-4).  That orbit's pre-impact ``zeta* = -V(theta-) /
    (1 - delta^2)`` must carry the step over the top of the potential, ``delta^2 zeta* >
    V_max`` (:func:`zero_dynamics`; for ``delta^2 < 1`` the existence margin ``delta^2 /
    (1 - delta^2) V(theta-) + V_max < 0``).  When it cannot, the message (one clause naming
    the key) says so, and neither the root finder
    (``walkerlab.analysis.gait.poincare.find_fixed_point``) nor the scale-free seeds (a
    passive walker's) are started: they would spend the search's budget on starts the
    controller drives to huge rates.  ``walker``: a
    :class:`~walkerlab.models.hybrid.base.HybridWalker`; ``""`` for any other walker, a
    saturating controller (``max_torque_n_m``: the outputs may leave the surface) and
    non-invariant outputs (:func:`gaits_on_zero_dynamics`).
    """
    if not gaits_on_zero_dynamics(walker):
        return ""
    ctrl = walker.actuators.controller
    if ctrl in _NO_ORBIT:  # one controller, one answer: asked by every root-finder start
        return _NO_ORBIT[ctrl]
    _NO_ORBIT[ctrl] = _no_orbit(zero_dynamics(ctrl))
    return _NO_ORBIT[ctrl]


def _no_orbit(zd: ZeroDynamics) -> str:
    """:func:`no_orbit_reason` of the zero dynamics ``zd``."""
    d2 = zd.delta2
    if not np.isfinite(d2) or d2 == 1.0:
        return ""
    if d2 * (-zd.v_minus / (1.0 - d2)) > zd.v_max:  # an orbit (unstable when delta^2 > 1)
        return ""
    why = (f"existence margin {zd.existence_margin:.4g} > 0: the step stalls before its "
           "heel strike" if d2 < 1 else f"V(theta-) {zd.v_minus:.4g}")
    return ("walker.actuation.virtual_constraints: its zero dynamics has no periodic orbit "
            f"(delta^2 {d2:.4g}, {why}), and with invariant: true every gait lies on it; "
            "change the outputs' Bezier coefficients")
