"""The Lagrangian core every walker generator shares: the Coriolis matrix of a mass matrix
from its Christoffel symbols, and the bias of a floating view, each written once.

Lagrange's equations of a walker with coordinates ``q`` (n,), kinetic energy
``T = dq^T M(q) dq / 2`` and potential ``V(q)`` are ``M qdd + C(q, dq) dq + G(q) = 0`` with
``G = dV/dq`` and ``C`` from the Christoffel symbols of the first kind of ``M`` (Murray, Li &
Sastry 1994, *A Mathematical Introduction to Robotic Manipulation*, Eq. 4.23; Spong,
Hutchinson & Vidyasagar 2006, Eq. 7.54).  Planar and 3D walkers, their foot modes and free
joints, all read it from here.
"""

from __future__ import annotations

import sympy as sp

__all__ = ["bias", "christoffel"]


def christoffel(M: sp.Matrix, q, dq) -> sp.Matrix:
    """Coriolis matrix of the mass matrix ``M(q)``.

    ``C_ij = sum_k c_ijk dq_k``, ``c_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2``
    (Murray, Li & Sastry 1994, Eq. 4.23), summed over ``k`` in coordinate order (the order
    fixes the expression tree, and so the generated code's round-off).

    Parameters
    ----------
    M : sympy Matrix (n, n)
        Symmetric mass matrix [kg m^2, kg m, kg by coordinate], a function of ``q``.
    q, dq : sequence of Symbol (n,)
        Coordinates [rad or m] and their rates [rad/s or m/s].

    Returns
    -------
    sympy Matrix (n, n)
        ``C`` with ``M qdd + C dq + G = 0`` (``dM/dt - 2 C`` skew-symmetric).
    """
    n = len(q)
    C = sp.zeros(n, n)
    for i in range(n):
        for j in range(n):
            C[i, j] = sum(sp.Rational(1, 2) * (sp.diff(M[i, j], q[k]) + sp.diff(M[i, k], q[j])
                                               - sp.diff(M[j, k], q[i])) * dq[k]
                          for k in range(n))
    return C


def bias(M: sp.Matrix, V, q, dq) -> sp.Matrix:
    """The bias ``h = d(M dq)/dq dq - dT/dq + dV/dq`` (``= C(q, dq) dq + G(q)``) of the mass
    matrix ``M(q)`` and potential ``V(q)``, without the Christoffel symbols: what a floating
    view integrates (``M qdd + h = J^T F``), where ``C`` itself is never needed.

    Parameters
    ----------
    M : sympy Matrix (n, n)
        Symmetric mass matrix, a function of ``q``.
    V : Expr
        Potential energy [J].
    q, dq : sequence of Symbol (n,)

    Returns
    -------
    sympy Matrix (n, 1)
        [N, N m by coordinate].
    """
    qv, dqv = sp.Matrix(q), sp.Matrix(dq)
    T = sp.Rational(1, 2) * (dqv.T * M * dqv)[0]
    return ((M * dqv).jacobian(qv) * dqv - sp.Matrix([sp.diff(T, v) for v in q])
            + sp.Matrix([sp.diff(V, v) for v in q]))
