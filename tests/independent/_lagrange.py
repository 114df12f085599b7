"""Tiny sympy Lagrange helper for the independent reference walkers (not walkerlab code).

Kept deliberately separate from ``walkerlab.models``: these prototypes are an independent
check of the generic framework, so they share no code with it.
"""

from __future__ import annotations

import numpy as np
import sympy as sp


def lagrange(q, dq, bodies, g):
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
    T = sp.Integer(0)
    V = sp.Integer(0)
    for m, inertia, p, ang in bodies:
        v = p.jacobian(qv) * dqv
        T += sp.Rational(1, 2) * m * (v.T * v)[0]
        if inertia != 0:
            w = (sp.Matrix([ang]).jacobian(qv) * dqv)[0]
            T += sp.Rational(1, 2) * inertia * w**2
        V += m * g * p[1]
    M = sp.hessian(T, dqv)
    # d/dt dL/ddq - dL/dq = M qdd + (dM/dt) dq - dT/dq + dV/dq
    Mdot_dq = sp.Matrix([sum(sp.diff(M[i, j], q[k]) * dq[k] * dq[j]
                             for j in range(len(q)) for k in range(len(q)))
                         for i in range(len(q))])
    h = Mdot_dq - sp.Matrix([sp.diff(T, qi) for qi in q]) + sp.Matrix([sp.diff(V, qi) for qi in q])
    return M, h, T, V


def lam(args, expr):
    f = sp.lambdify(args, expr, modules="numpy", cse=True)
    return lambda *a: np.asarray(f(*a))
