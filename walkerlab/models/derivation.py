"""Equations of motion of planar point-mass walkers, derived with sympy (Lagrange, Eq. 2).

The derivation is runnable on its own (``python -m walkerlab.models.derivation``) and is
what the default ("derived") compass-gait model evaluates.  It replaces the printed
Appendix A of the paper, whose Coriolis matrix (A.5) has a wrong sign in ``C[1, 0]``:
the derived ``C[1, 0] = -m L b sin(theta2 - theta1) dtheta1`` (Goswami et al. 1996, Eq. 3),
the printed one has ``+``.  With the printed sign the total energy drifts during swing.

Everything here is generic in the list of point masses, so a kneed walker or a walker with a
torso is derived by the same code from its mass positions.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import sympy as sp


@dataclass(frozen=True)
class PointMassModel:
    """Symbolic description of a planar point-mass walker in stance.

    Attributes
    ----------
    q, dq : tuple of sympy.Symbol, shape (n,)
        Role-ordered generalized coordinates and rates.
    masses : tuple of (sympy.Expr, sympy.Matrix 2x1)
        Mass and position relative to the stance foot (world axes, y up).
    swing_foot : sympy.Matrix 2x1
        Position of the swing foot relative to the stance foot.
    g : sympy.Symbol
        Gravity.
    """

    q: tuple
    dq: tuple
    masses: tuple
    swing_foot: sp.Matrix
    g: sp.Symbol


@dataclass(frozen=True)
class Derived:
    """Symbolic results: ``M qdd + C dq + G = 0`` and the extended impact system (Eq. 6-7)."""

    M: sp.Matrix
    C: sp.Matrix
    G: sp.Matrix
    kinetic: sp.Expr
    potential: sp.Expr
    De: sp.Matrix
    E: sp.Matrix


def compass_gait_symbolic() -> PointMassModel:
    """Compass-gait walker: positions as paper Eq. A.1-A.3 (leg masses at a from the foot)."""
    t1, t2, w1, w2 = sp.symbols("theta1 theta2 dtheta1 dtheta2", real=True)
    m, mh, L, a, g = sp.symbols("m M_H L a g", positive=True)
    b = L - a
    p_stance = sp.Matrix([-a * sp.sin(t2), a * sp.cos(t2)])  # A.1
    p_hip = sp.Matrix([-L * sp.sin(t2), L * sp.cos(t2)])  # A.2
    p_swing = p_hip + sp.Matrix([b * sp.sin(t1), -b * sp.cos(t1)])  # A.3
    foot = p_hip + sp.Matrix([L * sp.sin(t1), -L * sp.cos(t1)])
    return PointMassModel(
        q=(t1, t2), dq=(w1, w2), masses=((m, p_stance), (mh, p_hip), (m, p_swing)),
        swing_foot=foot, g=g,
    )


def derive(model: PointMassModel) -> Derived:
    """Lagrange's equations (paper Eq. 2-3) and the extended impact model (Eq. 5-7).

    Returns
    -------
    Derived
        ``M`` (n x n), Coriolis ``C`` (n x n, Christoffel form, so ``dM/dt - 2C`` is skew),
        ``G`` (n,), energies, extended mass matrix ``De`` ((n+2) x (n+2), coordinates
        ``[q, x_foot, y_foot]``) and ``E`` (2 x (n+2)), the Jacobian of the swing-foot position.
    """
    q, dq = sp.Matrix(model.q), sp.Matrix(model.dq)
    n = len(q)
    T = sp.Integer(0)
    V = sp.Integer(0)
    for mass, p in model.masses:
        v = p.jacobian(q) * dq
        T += sp.Rational(1, 2) * mass * (v.T * v)[0]
        V += mass * model.g * p[1]
    M = sp.simplify(sp.hessian(T, dq))
    G = sp.simplify(sp.Matrix([sp.diff(V, qi) for qi in q]))
    C = sp.zeros(n, n)
    for i in range(n):
        for j in range(n):
            C[i, j] = sp.simplify(sum(
                sp.Rational(1, 2) * (sp.diff(M[i, j], q[k]) + sp.diff(M[i, k], q[j])
                                     - sp.diff(M[j, k], q[i])) * dq[k]
                for k in range(n)
            ))
    # extended coordinates: the stance foot is free at (xf, yf)
    xf, yf, dxf, dyf = sp.symbols("x_f y_f dx_f dy_f", real=True)
    qe = sp.Matrix([*q, xf, yf])
    dqe = sp.Matrix([*dq, dxf, dyf])
    Te = sp.Integer(0)
    for mass, p in model.masses:
        pe = p + sp.Matrix([xf, yf])
        v = pe.jacobian(qe) * dqe
        Te += sp.Rational(1, 2) * mass * (v.T * v)[0]
    De = sp.simplify(sp.hessian(Te, dqe))
    E = sp.simplify((model.swing_foot + sp.Matrix([xf, yf])).jacobian(qe))
    return Derived(M=M, C=C, G=G, kinetic=sp.simplify(T), potential=sp.simplify(V), De=De, E=E)


@cache
def compass_gait_functions():
    """Lambdified numpy functions of the derived compass gait (cached per process).

    Returns
    -------
    dict
        ``M(q, p)``, ``C(q, dq, p)``, ``G(q, p)``, ``De(q, p)``, ``E(q, p)`` and the
        ``symbolic`` results; ``p = (m, M_H, L, a, g)``.  Derivatives for the variational
        equations are taken by complex step on these functions, not derived here.
    """
    model = compass_gait_symbolic()
    d = derive(model)
    q, dq = sp.Matrix(model.q), sp.Matrix(model.dq)
    m, mh, L, a, g = sp.symbols("m M_H L a g", positive=True)
    p = (m, mh, L, a, g)
    args_q = (tuple(q), p)
    args_x = (tuple(q), tuple(dq), p)
    lam = lambda args, expr: sp.lambdify(args, expr, modules="numpy", cse=True)  # noqa: E731
    return {
        "M": lam(args_q, d.M),
        "C": lam(args_x, d.C),
        "G": lam(args_q, d.G),
        "De": lam(args_q, d.De),
        "E": lam(args_q, d.E),
        "symbolic": d,
    }


if __name__ == "__main__":  # pragma: no cover - a readable printout of the derivation
    d = derive(compass_gait_symbolic())
    for name in ("M", "C", "G", "De", "E"):
        print(f"{name} =")
        sp.pprint(getattr(d, name))
