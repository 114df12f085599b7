"""Lagrange's equations of a body tree (:class:`walkerlab.walker.tree.BodyTree`): the one
derivation that reads bodies, 3x3 inertias and joint axes, for planar and 3D walkers alike.

Forward kinematics (Featherstone 2008, *Rigid Body Dynamics Algorithms*, ch. 4): each
body's rotation ``R_b`` (3, 3) and frame origin ``o_b`` in the root (slope) frame, from its
parent's and its joint's origin and rotations (:func:`walkerlab.codegen.lagrange.rotation`,
Rodrigues).  Each body's angular velocity is linear in the rates, ``omega_b = W_b dq``, the
sum over the joints from the root of each rotation's axis (in the root frame) times its
angle's rate; its centre of mass ``c_b`` has the Jacobian ``J_b = dc_b/dq``.  Then

    M = sum_b m_b J_b^T J_b + W_b^T R_b I_b R_b^T W_b,
    V = sum_b m_b g (up . c_b),   up = (-sin gamma, cos gamma, 0) in the slope frame,

``C`` from ``M``'s Christoffel symbols (:func:`walkerlab.codegen.lagrange.christoffel`) and
``G = dV/dq`` (Murray, Li & Sastry 1994, ch. 4).  The plastic heel strike at a contact
point ``f(q)`` is the extended-coordinates impact (Hurmuzlu & Marghitu 1994): with the
stance foot free (its position ``p`` three more coordinates, moving every body by ``dp``,
turning none), ``M_e = [[M, A], [A^T, m_tot I]]``, ``A = sum_b m_b J_b^T``, and the rates
that keep the new foot at rest ``[I; -F]``, ``F = df/dq``:

    Mi = M - A F - F^T A^T + m_tot F^T F,    B = M - F^T A^T,    Mi dq+ = B dq-.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from walkerlab.codegen.lagrange import christoffel, rotation
from walkerlab.walker.tree import ROOT, BodyTree

__all__ = ["TreeEquations", "derive_tree", "tree_impact", "tree_kinematics"]


@dataclass(frozen=True)
class TreeEquations:
    """A body tree's flow and energies (sympy, ``n`` coordinates).

    Attributes
    ----------
    q, dq : tuple of Symbol (n,)
    params : dict[str, Symbol]
    M, C : Matrix (n, n); G : Matrix (n, 1)
        ``M qdd + C dq + G = 0``.
    kinetic, potential : Expr
        [J]; the potential from the stance foot's height.
    points : dict[str, Matrix (3, 1)]
        The tree's named points in the slope frame [m].
    A : Matrix (n, 3); total_mass : Expr
        ``sum m_b J_b^T`` and ``sum m_b`` (the extended impact's).
    """

    q: tuple
    dq: tuple
    params: dict
    M: sp.Matrix
    C: sp.Matrix
    G: sp.Matrix
    kinetic: sp.Expr
    potential: sp.Expr
    points: dict
    A: sp.Matrix
    total_mass: sp.Expr


def _expr(x, names: dict):
    """A tree scalar (float or expression string) as a sympy expression of ``names``."""
    return sp.sympify(x, locals=names) if isinstance(x, str) else sp.nsimplify(x)


def tree_kinematics(tree: BodyTree, names: dict, q) -> dict:
    """Each body's ``(R, o, W)``: rotation (3, 3) and frame origin (3, 1) in the slope frame,
    and its angular velocity's Jacobian ``W`` (3, n) (``omega = W dq``)."""
    qv = sp.Matrix(q)
    frames = {ROOT: (sp.eye(3), sp.zeros(3, 1), sp.zeros(3, len(q)))}
    for j in tree.joints:
        R, o, W = frames[j.parent]
        o = o + R * sp.Matrix([_expr(v, names) for v in j.origin])
        for axis, angle in j.rotations:
            a = _expr(angle, names)
            k = R * sp.Matrix(axis)           # the axis in the slope frame
            W = W + k * sp.Matrix([a]).jacobian(qv)
            R = R * rotation(sp.Matrix(axis), a)
        frames[j.child] = (R, o, W)
    return frames


def derive_tree(tree: BodyTree) -> TreeEquations:
    """The flow, energies and points of ``tree`` (module docstring).

    Parameters
    ----------
    tree : BodyTree

    Returns
    -------
    TreeEquations
    """
    q = sp.symbols(" ".join(tree.coordinates), real=True, seq=True)
    dq = sp.symbols(" ".join("d" + c for c in tree.coordinates), real=True, seq=True)
    params = {p: sp.Symbol(p, real=True) for p in tree.params}
    names = {**dict(zip(tree.coordinates, q)), **params}
    frames = tree_kinematics(tree, names, q)
    qv, n = sp.Matrix(q), len(q)
    M, A, total, V = sp.zeros(n, n), sp.zeros(n, 3), 0, 0
    gamma, g = params["gamma"], params["g"]
    up = sp.Matrix([-sp.sin(gamma), sp.cos(gamma), 0])
    for b in tree.bodies:
        R, o, W = frames[b.name]
        m = _expr(b.mass, names)
        c = o + R * sp.Matrix([_expr(v, names) for v in b.com])
        J = c.jacobian(qv)
        M += m * J.T * J
        A += m * J.T
        total += m
        V += m * g * (up.T * c)[0]
        inertia = sp.Matrix([[_expr(v, names) for v in row] for row in b.inertia])
        if inertia != sp.zeros(3, 3):
            M += W.T * (R * inertia * R.T) * W
    M = M.applyfunc(lambda e: sp.trigsimp(sp.expand(e)))
    G = sp.Matrix([sp.expand(sp.diff(V, qi)) for qi in q])
    points = {}
    for p in tree.points:
        R, o, _ = frames[p.body]
        points[p.name] = o + R * sp.Matrix([_expr(v, names) for v in p.offset])
    kinetic = sp.Rational(1, 2) * (sp.Matrix(dq).T * M * sp.Matrix(dq))[0]
    return TreeEquations(q=tuple(q), dq=tuple(dq), params=params, M=M,
                         C=christoffel(M, q, dq), G=G, kinetic=kinetic, potential=V,
                         points=points, A=A, total_mass=total)


def tree_impact(eq: TreeEquations, point: str) -> tuple[sp.Matrix, sp.Matrix]:
    """``(Mi, B)`` (n, n) of the plastic impact at the named contact point, the old stance
    foot leaving the ground: ``Mi dq+ = B dq-`` in the pre-impact labelling (module
    docstring; Hurmuzlu & Marghitu 1994's extended coordinates).

    Raises
    ------
    KeyError
        ``point`` is not a point of the tree.
    """
    F = eq.points[point].jacobian(sp.Matrix(eq.q))
    Mi = eq.M - eq.A * F - F.T * eq.A.T + eq.total_mass * F.T * F
    B = eq.M - F.T * eq.A.T
    return Mi, B
