"""The rolling of a 3D walker's feet curved in both directions (``walker.leg.foot.kind:
toroidal``; Coleman & Ruina 1998, "An uncontrolled walking toy that cannot stand still",
PRL 80(16); Collins, Wisse & Ruina 2001, "A three-dimensional passive-dynamic walking robot
with two legs and knees", IJRR 20(7)): the Chaplygin reduction of the tree's Lagrangian
(:func:`reduce_rolling`) and the heel strike onto such a foot (:func:`rolling_impact`).

The foot is a torus patch on each leg (:mod:`walkerlab.walker.foot_trees`): its sagittal
section an arc of radius ``R`` about the leg frame's origin ``c`` (the torus' axis, the
leg's rolled hip axis ``a = Rot(s, phi) z``), its lateral section an arc of radius ``R_l``
(the tube; major radius ``rho = R - R_l``).  With the leg rolled by ``phi`` about the fall
line ``s`` and pitched by ``beta`` about ``a`` (the stance foot neither slips nor twists:
no yaw), its lowest point is ``p = c - rho Rot(s, phi) n - R_l n``, and the velocity of
the foot's material point there is

    v_m = p' + (rho + R_l cos(phi)) beta' s - R_l phi' z

(the angular velocity ``phi' s + beta' a`` crossed with ``p - c``).  Rolling, ``v_m = 0``:
the contact moves ``R_l phi`` across the fall line (holonomic: the tree's joint) and along
it at ``travel' = -(rho + R_l cos(phi)) beta'``, which no function of the configuration
integrates (the rolling radius about the axis changes with the lean; a rolling torus, as a
motorcycle tyre, is not holonomic).  ``R_l = 0`` is the disc foot
(:func:`walkerlab.codegen.legged.derive_legged`'s arc: ``travel = -R beta``).

The tree carries ``travel`` as its last coordinate; the Lagrangian ``L(q, q')`` does not
depend on it but through the slope's potential, whose force along ``s`` is constant.  With
``q_f = (q, travel)`` and ``q_f' = S(q) q'`` (``S = [I; r(q)]``, ``r = d travel / dq'``), the
d'Alembert-Lagrange equations projected on the admissible motions (Chaplygin; Neimark &
Fufaev 1972, "Dynamics of Nonholonomic Systems", Ch. III)::

    S^T M_f S q'' + (S^T M_f S' + S^T C_f(q, S q') S) q' + S^T G_f = 0,

closed in ``(q, q')``: the reduced flow ``M, C, G``.  Its energy ``T + V`` is conserved with
``V`` at the true travel; the printed potential takes the travel of the foot rolling on its
equator, ``-R beta`` (what the contact's travel would be at zero lean), which differs from
the true one by ``R_l int (1 - cos phi) beta' dt``; the points (and the step length) are
measured from that reference alike.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import sympy as sp

from walkerlab.codegen.frames import rotation

__all__ = ["Rolling", "contact_point", "material_jacobian", "reduce_rolling",
           "rolling_impact"]

E_S, E_N, E_Z = sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0]), sp.Matrix([0, 0, 1])


@dataclass(frozen=True)
class Rolling:
    """The reduced flow of a walker on toroidal feet (module docstring); ``n`` the walker's
    coordinates (the tree's but ``travel``).

    Attributes
    ----------
    q, dq : tuple of Symbol (n,)
    M, C : Matrix (n, n); G : Matrix (n, 1)
        The reduced flow ``M q'' + C q' + G = 0`` [SI].
    kinetic, potential : Expr
        [J]; the potential at the reference travel ``-R beta`` (module docstring).
    kinematics : walkerlab.codegen.tree_derive.TreeKinematics
        The tree's, ``travel`` replaced by its reference.
    S : Matrix (n + 1, n)
        The admissible rates ``q_f' = S q'``.
    travel_rate : Expr
        ``travel'`` [m/s] (the stance contact's speed along the fall line).
    """

    q: tuple
    dq: tuple
    M: sp.Matrix
    C: sp.Matrix
    G: sp.Matrix
    kinetic: sp.Expr
    potential: sp.Expr
    kinematics: object
    S: sp.Matrix
    travel_rate: sp.Expr


def contact_point(centre: sp.Matrix, phi, R, R_l) -> sp.Matrix:
    """The lowest point (3, 1) of a toroidal foot whose torus' centre is ``centre`` (3, 1),
    its leg rolled by ``phi`` about the fall line [m] (module docstring)."""
    return centre - (R - R_l) * rotation(E_S, phi) * E_N - R_l * E_N


def material_jacobian(contact: sp.Matrix, q, phi, beta, R, R_l) -> sp.Matrix:
    """The velocity Jacobian (3, n) of a toroidal foot's material point at its lowest point
    ``contact`` (3, 1), in the coordinates ``q``: ``v_m = p' + (R - R_l + R_l cos phi) beta'
    s - R_l phi' z`` (module docstring; ``phi``, ``beta`` the leg's roll and pitch from the
    slope's normal as expressions of ``q``)."""
    qv = sp.Matrix(q)
    dbeta = sp.Matrix([[sp.diff(beta, k) for k in q]])
    dphi = sp.Matrix([[sp.diff(phi, k) for k in q]])
    return (contact.jacobian(qv) + (R - R_l + R_l * sp.cos(phi)) * E_S * dbeta
            - R_l * E_Z * dphi)


def reduce_rolling(te, P: dict, phi, beta, simplify=sp.expand) -> Rolling:
    """The Chaplygin-reduced flow of a tree on a toroidal stance foot (module docstring).

    Parameters
    ----------
    te : walkerlab.codegen.tree_derive.TreeEquations
        The tree's Lagrange equations, its last coordinate the stance contact's ``travel``.
    P : dict
        Parameter name -> symbol (``R_foot``, ``R_lat``).
    phi, beta : Expr
        The stance leg's roll (the lean) and its pitch from the slope's normal
        (``stance + gamma``), in the walker's coordinates.
    simplify : callable
        Applied to the reduced ``M``, ``C``, ``G``.

    Returns
    -------
    Rolling
    """
    R, R_l = P["R_foot"], P["R_lat"]
    *q, travel = te.q
    *dq, dtravel = te.dq
    n = len(q)
    rate = sp.Matrix([[-(R - R_l + R_l * sp.cos(phi)) * sp.diff(beta, k) for k in q]])
    S = sp.eye(n).col_join(rate)
    dqv = sp.Matrix(dq)
    travel_rate = (rate * dqv)[0]
    S_dot = sp.zeros(n + 1, n)
    S_dot[n, :] = sum((rate.diff(k) * d for k, d in zip(q, dq)), sp.zeros(1, n))
    C_f = te.C.subs(dtravel, travel_rate)
    M = (S.T * te.M * S).applyfunc(simplify)
    C = (S.T * te.M * S_dot + S.T * C_f * S).applyfunc(simplify)
    G = (S.T * te.G).applyfunc(simplify)
    ref = {travel: -R * beta}
    kin = te.kinematics
    sub = {k: v.subs(ref) for k, v in kin.contacts.items()}
    kin = replace(kin, q=tuple(q), dq=tuple(dq),
                  origins={k: v.subs(ref) for k, v in kin.origins.items()},
                  coms={k: v.subs(ref) for k, v in kin.coms.items()}, contacts=sub)
    kinetic = sp.Rational(1, 2) * (dqv.T * M * dqv)[0]
    return Rolling(tuple(q), tuple(dq), M, C, G, kinetic, te.potential.subs(ref), kin, S,
                   travel_rate)


def rolling_impact(te, rolling: Rolling, F: sp.Matrix, simplify=sp.expand
                   ) -> tuple[sp.Matrix, sp.Matrix]:
    """The plastic heel strike onto a toroidal foot (Hurmuzlu & Marghitu 1994, in extended
    coordinates ``(q_f, p)``, ``p`` the root's translation): the pre-impact motion rolls on
    the old stance foot (``q_f' = S q'-``, ``p' = 0``); after it the new foot's material
    point is at rest (``q_f' = (q'+, 0)``, ``p' = -F q'+``: ``J``); projected on ``J``,
    ``J^T De J q'+ = J^T De (S q'-, 0)``::

        Mi = M_f[:n, :n] - A_n F - F^T A_n^T + m F^T F,
        B  = (M_f S)[:n, :] - F^T A_f^T S,

    ``A_f`` (n + 1, 3) the tree's extended coupling, ``A_n`` its first ``n`` rows.

    Parameters
    ----------
    te : walkerlab.codegen.tree_derive.TreeEquations
    rolling : Rolling
    F : Matrix (3, n)
        The new stance foot's material point's velocity Jacobian (:func:`material_jacobian`
        of the tree's own contact point, the travel held).
    simplify : callable

    Returns
    -------
    Mi, B : Matrix (n, n)
        ``Mi q'+ = B q'-``.
    """
    n = len(rolling.q)
    M_f, A_f = te.M, te.A   # neither depends on the travel (a translation)
    A_n = A_f[:n, :]
    Mi = M_f[:n, :n] - A_n * F - F.T * A_n.T + te.total_mass * F.T * F
    B = (M_f * rolling.S)[:n, :] - F.T * (A_f.T * rolling.S)
    return Mi.applyfunc(simplify), B.applyfunc(simplify)
