"""Tiny sympy Lagrange helper for the independent reference walkers (not walkerlab code).

Kept deliberately separate from ``walkerlab.models``: these prototypes are an independent
check of the generic framework, so they share no code with it.
"""

from __future__ import annotations

import numpy as np
import sympy as sp


def lagrange(q, dq, bodies, g, mass_matrix_only=False):
    """Mass matrix, velocity terms and gravity of ``T - V`` for planar bodies.

    Parameters
    ----------
    q, dq : list of sympy.Symbol, shape (n,)
    bodies : list of (mass, inertia_about_com, position (2x1 Matrix), angle expr)
        ``angle`` is the body's absolute angle (only used with a non-zero inertia).
    g : sympy expression
        Gravity [m/s^2], acting along -y.

    Returns
    -------
    M : Matrix (n, n); h : Matrix (n,) with ``M qdd + h = 0``; T, V : Expr
    """
    qv, dqv = sp.Matrix(q), sp.Matrix(dq)
    n = len(q)
    M = sp.zeros(n, n)
    V = sp.Integer(0)
    for m, inertia, p, ang in bodies:
        J = p.jacobian(qv)
        M += m * J.T * J
        if inertia != 0:
            a = sp.Matrix([ang]).jacobian(qv)
            M += inertia * a.T * a
        V += m * g * p[1]
    T = sp.Rational(1, 2) * (dqv.T * M * dqv)[0]
    if mass_matrix_only:
        return M, None, T, V
    # d/dt dT/ddq - dT/dq + dV/dq = M qdd + h
    dM = [M.diff(qk) for qk in q]
    h = sp.Matrix([sum((dM[k][i, j] - sp.Rational(1, 2) * dM[i][j, k]) * dq[j] * dq[k]
                       for j in range(n) for k in range(n)) + sp.diff(V, q[i])
                   for i in range(n)])
    return M, h, T, V


def lam(args, expr):
    f = sp.lambdify(args, expr, modules="numpy", cse=True)
    return lambda *a: np.asarray(f(*a))
