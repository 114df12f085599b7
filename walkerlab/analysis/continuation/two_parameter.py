"""Two-parameter continuation of a fold or a period doubling of a gait.

The augmented system ``[F(z, p1, p2); psi(z, p1, p2)] = 0`` (``F`` the ``k``-step map's
fixed-point residual on the heel-strike section, ``psi`` the fold or period-doubling test
function of :mod:`walkerlab.analysis.continuation.gait_map`) is solved for ``(z, p1)`` at each
``p2`` by ``scipy.optimize.root`` (``hybr``; the rows of ``F`` analytic from the
variational equations, the row of ``psi`` by central differences), with a secant predictor
in ``p2``: the stability boundary in the plane of two scene fields (Goswami, Thuilot &
Espiau 1998: period doubling over slope and hip-to-leg mass ratio).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.analysis.continuation.gait_map import (
    RESIDUAL_TOL,
    BranchSystem,
    MapFailed,
    WalkerFamily,
)
from walkerlab.analysis.continuation.points import (
    CRITICAL_MULTIPLIER,
    BranchPoint,
    SpecialPoint,
    branch_point,
    critical_pair,
    tests_at,
)

__all__ = ["TwoParameterCurve", "special_point_at", "two_parameter"]


@dataclass
class TwoParameterCurve:
    """A curve of fold or period-doubling points in the plane of two fields.

    Attributes
    ----------
    kind : str            ``fold`` or ``period_doubling``
    period : int          the branch's period ``k``
    path, path2 : str     the two fields; unit, unit2 their units
    p : ndarray (N,)      first parameter at the special point
    p2 : ndarray (N,)     second parameter
    x : ndarray (N, 2n)   states there
    multiplier : ndarray (N,) complex   the critical multiplier (+1 or -1)
    """

    kind: str
    period: int
    path: str
    path2: str
    unit: str
    unit2: str
    p: np.ndarray
    p2: np.ndarray
    x: np.ndarray
    multiplier: np.ndarray


def special_point_at(family: WalkerFamily, kind: str, k: int, p_guess: float,
                     z_guess: np.ndarray, p_scale: float) -> tuple[float, BranchPoint]:
    """Solve the augmented system ``[F(z, p); psi(z, p)] = 0`` for ``(z, p)``
    (``scipy.optimize.root``, ``hybr``; ``F``'s rows analytic, ``psi``'s by central
    differences).

    Raises
    ------
    MapFailed
        No convergence.
    """
    from scipy.optimize import root

    sys = BranchSystem(family, k, p_scale)

    def psi(u):
        info = sys.full(u[:-1], u[-1] * p_scale)
        return tests_at(info)[kind], info

    def G(u):
        try:
            F = sys.residual(u[:-1], u[-1] * p_scale)
            return np.append(F, psi(u)[0])
        except MapFailed:
            return np.full(u.size, 1e3)

    def jac(u):
        try:
            val, info = psi(u)
            Fp = sys.dp(u[:-1], u[-1] * p_scale) * p_scale
            grad = np.empty(u.size)
            for i in range(u.size):
                h = 1e-6 * (1 + abs(u[i]))
                e = np.zeros(u.size)
                e[i] = h
                grad[i] = (psi(u + e)[0] - psi(u - e)[0]) / (2 * h)
        except MapFailed:
            return np.eye(u.size)
        return np.vstack([np.column_stack([info["Fz"], Fp]), grad])

    u0 = np.append(z_guess, p_guess / p_scale)
    sol = root(G, u0, jac=jac, method="hybr", options={"xtol": 1e-12, "maxfev": 40})
    u = sol.x
    try:
        info = sys.full(u[:-1], u[-1] * p_scale)
    except MapFailed as exc:
        raise MapFailed("no special point", str(exc)) from None
    if float(np.max(np.abs(info["F"]))) > RESIDUAL_TOL or not sol.success:
        raise MapFailed("no special point", " ".join(str(sol.message).split()))
    q = branch_point(sys, u, info, None)
    mu = critical_pair(q, kind)[1]
    if abs(mu - CRITICAL_MULTIPLIER[kind]) > 1e-5:
        raise MapFailed("no special point", f"critical multiplier {mu:.6g}")
    return float(u[-1] * p_scale), q


def two_parameter(family: WalkerFamily, sp: SpecialPoint, path2: str, p2_start: float,
                  p2_values: np.ndarray, p_scale: float, unit: str = "-",
                  unit2: str = "-") -> TwoParameterCurve:
    """Continue the fold or period doubling ``sp`` (located at ``path2 = p2_start``) over
    ``p2_values`` (both ways from ``p2_start``, secant predictor in ``p2``); stops where the
    augmented system fails.

    Returns
    -------
    TwoParameterCurve
        Points sorted by ``p2``.
    """
    rows = [(p2_start, sp.p, sp.x, sp.point.z, complex(CRITICAL_MULTIPLIER[sp.kind]))]
    vals = np.asarray(p2_values, float)
    for side in (vals[vals > p2_start], vals[vals < p2_start][::-1]):
        hist = [(p2_start, sp.p, sp.point.z)]
        for p2 in side:
            fam = family.at(**{path2: float(p2)})
            if len(hist) >= 2:
                (a2, ap, az), (b2, bp, bz) = hist[-2], hist[-1]
                lam = (p2 - b2) / (b2 - a2)
                pg, zg = bp + lam * (bp - ap), bz + lam * (bz - az)
            else:
                pg, zg = hist[-1][1], hist[-1][2]
            try:
                p, q = special_point_at(fam, sp.kind, sp.period, pg, zg, p_scale)
            except MapFailed:
                break
            mu = critical_pair(q, sp.kind)[1]
            rows.append((float(p2), p, q.x, q.z, mu))
            hist.append((float(p2), p, q.z))
    rows.sort(key=lambda r: r[0])
    return TwoParameterCurve(sp.kind, sp.period, family.path, path2, unit, unit2,
                             np.array([r[1] for r in rows]), np.array([r[0] for r in rows]),
                             np.array([r[2] for r in rows]), np.array([r[4] for r in rows]))


