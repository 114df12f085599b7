"""The Lagrangian core every walker generator shares: the Coriolis matrix of a mass matrix
from its Christoffel symbols, and the bias of a floating view, each written once.

Lagrange's equations of a walker with coordinates ``q`` (n,), kinetic energy
``T = dq^T M(q) dq / 2`` and potential ``V(q)`` are ``M qdd + C(q, dq) dq + G(q) = 0`` with
``G = dV/dq`` and ``C`` from the Christoffel symbols of the first kind of ``M`` (Murray, Li &
Sastry 1994, *A Mathematical Introduction to Robotic Manipulation*, Eq. 4.23; Spong,
Hutchinson & Vidyasagar 2006, Eq. 7.54).  Planar and 3D walkers, their foot modes and free
joints, all read it from here; the walkers with locking knees (planar and 3D) their knee lock
(:func:`knee_lock`).
"""

from __future__ import annotations

from typing import NamedTuple

import sympy as sp

__all__ = ["KneeLock", "bias", "christoffel", "knee_lock"]


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


class KneeLock(NamedTuple):
    """A locking knee's square systems (:func:`knee_lock`), each a pair or triple of sympy
    Matrices with ``n`` rows: ``locked`` ``(Ml, Cl, Gl)`` the flow with the knee locked,
    ``knee_impact`` ``(Mk, Bk)`` the plastic knee strike, ``heel_strike`` ``(Mh, Bh)`` the
    heel strike with the knee locked."""

    locked: tuple
    knee_impact: tuple
    heel_strike: tuple


def spring_dampers(joints, P: dict, q) -> tuple[sp.Expr, sp.Matrix]:
    """Torsional spring-dampers on joint angles: their potential ``sum k (delta - r)^2 / 2``
    [J] and their dampers' matrix ``sum c J^T J`` (n, n) (``J = d delta / dq``; the damper's
    generalised force ``-c J^T J dq``).

    Parameters
    ----------
    joints : iterable of (Expr, str)
        Each spring's angle ``delta`` (an expression of ``q``) [rad] and the tag of its
        parameters ``k_<tag>`` [N m/rad], ``r_<tag>`` [rad], ``c_<tag>`` [N m s/rad].
    P : dict
        The parameters' symbols by name.
    q : sequence of Symbol (n,)
    """
    V, D = sp.Integer(0), sp.zeros(len(q), len(q))
    for delta, tag in joints:
        V += P[f"k_{tag}"] * (delta - P[f"r_{tag}"]) ** 2 / 2
        Jd = sp.Matrix([[sp.diff(delta, k) for k in q]])
        D += P[f"c_{tag}"] * Jd.T * Jd
    return V, D


def knee_lock(M: sp.Matrix, C: sp.Matrix, G: sp.Matrix, Mi: sp.Matrix, B: sp.Matrix,
              thigh: int, shank: int) -> KneeLock:
    """The flow, knee strike and heel strike of a walker whose swing knee locks (McGeer 1990,
    "Passive walking with knees", ICRA; the planar and the 3D kneed walkers alike).

    The locked knee is the constraint ``J_k dq = 0``, ``J_k = d(q_shank - q_thigh)/dq`` (the
    shank's absolute pitch the thigh's); ``S`` (n, n - 1) spans its null space: the shank
    moving with the thigh, every other coordinate alone.  Projecting Lagrange's equations on
    ``S`` removes the lock's constraint force, and ``J_k`` closes each system:

    - locked flow ``[S^T M; J_k] qdd = [S^T (-C dq - G); 0]``, given as
      ``([S^T M; J_k], [S^T C; 0], [S^T G; 0])`` (the printers' ``M qdd + C dq + G = 0``);
    - plastic knee strike ``[S^T M; J_k] dq+ = [S^T M; 0] dq-``: the momenta along ``S``
      (the whole walker's angular momentum about the stance foot, the swing leg's about the
      hip) are conserved, the knee's relative rate stopped;
    - heel strike with the knee locked ``[S^T Mi; J_k] dq+ = [S^T B; 0] dq-`` from the
      unlocked impact ``Mi dq+ = B dq-``.

    Parameters
    ----------
    M, C : sympy Matrix (n, n)
        Mass and Coriolis matrices of the unlocked walker (coordinates ``q``, absolute
        pitches of thigh and shank among them).
    G : sympy Matrix (n, 1)
    Mi, B : sympy Matrix (n, n)
        The heel strike's (knee free) impact matrices.
    thigh, shank : int
        Indices of the swing thigh's and shank's coordinates in ``q``.

    Returns
    -------
    KneeLock
    """
    n = M.rows
    Jk = sp.zeros(1, n)
    Jk[thigh], Jk[shank] = -1, 1
    S = sp.zeros(n, n - 1)
    for k, i in enumerate(i for i in range(n) if i != shank):
        S[i, k] = 1
        if i == thigh:
            S[shank, k] = 1
    z = sp.zeros(1, n)
    locked = (S.T * M).col_join(Jk), (S.T * C).col_join(z), (S.T * G).col_join(sp.zeros(1, 1))
    knee_impact = (S.T * M).col_join(Jk), (S.T * M).col_join(z)
    return KneeLock(locked, knee_impact, ((S.T * Mi).col_join(Jk), (S.T * B).col_join(z)))
