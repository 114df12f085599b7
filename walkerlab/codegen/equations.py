"""The symbolic equations of a walker's rigid hybrid view (flow, impact, guards, energies,
points, the extended impact system) as the printers of :mod:`walkerlab.codegen.source` read
them; derived by :func:`walkerlab.codegen.legged.derive_legged` (and, for a spoked wheel,
:func:`walkerlab.codegen.derive_3d.derive_spoked`, planar or 3D).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp


@dataclass(frozen=True)
class Flow:
    """A walker's flow in its coordinates (all sympy; ``n = len(q)``).

    Attributes
    ----------
    q, dq : tuple of Symbol, shape (n,)
    params : tuple of Symbol
        In ``structure.param_names`` order.
    M, C : Matrix (n, n); G : Matrix (n, 1)
        Flow ``M qdd + C dq + G = 0`` (after the massless limit, if any).
    """

    q: tuple
    dq: tuple
    params: tuple
    M: sp.Matrix
    C: sp.Matrix
    G: sp.Matrix


@dataclass(frozen=True)
class Equations(Flow):
    """Symbolic results of :func:`walkerlab.codegen.legged.derive_legged` (all sympy): the
    :class:`Flow` and

    Attributes
    ----------
    Mi, B : Matrix (n, n)
        Impact ``Mi dq+ = B dq-`` in the pre-impact labelling.
    relabel_q : Matrix (n, 1)
        Coordinates after the role swap, as functions of the pre-impact ``q``.
    relabel_rate : Matrix (n, n)
        ``dq_new = relabel_rate @ dq+``.
    kinetic, potential : Expr
        Energies [J] (massless bodies carry none); potential from the stance foot's height.
    guards : dict[str, Expr]
        ``heel_strike``, ``swing_foot_ahead``, ``hip_height``.
    points : dict[str, Matrix (2, 1) or (3, 1)]
        Named points relative to the stance foot (world axes, x downhill, y up; in 3D also
        z, :mod:`walkerlab.codegen.derive_3d`).
    leg_angles : dict[str, Expr]
        ``stance`` and ``swing`` absolute leg angles from the vertical.
    section_drop : int
        Index in ``q`` solved from the heel-strike guard; ``drop_solution`` is its expression.
    De, E : Matrix
        Extended impact matrices (coordinates ``[q, x_f, y_f]``, paper Eq. 6-7, A.7-A.24):
        the stance foot free, ``E`` the swing foot's material contact point's Jacobian
        (every foot kind: the push-off's transition reads them).
    section_tied : dict[int, int]
        State indices equal to another one on the section (kneed: the swing shank angle and
        rate equal the thigh's just after heel strike).
    locked : tuple (M, C, G) or None
        Flow with the swing knee locked, as the square system described above.
    knee_impact : tuple (Mk, Bk) or None
        Plastic knee strike ``Mk dq+ = Bk dq-``.
    """

    Mi: sp.Matrix
    B: sp.Matrix
    relabel_q: sp.Matrix
    relabel_rate: sp.Matrix
    kinetic: sp.Expr
    potential: sp.Expr
    guards: dict
    points: dict
    leg_angles: dict
    section_drop: int
    drop_solution: sp.Expr
    De: sp.Matrix
    E: sp.Matrix
    limit: bool
    section_tied: dict | None = None
    locked: tuple | None = None
    knee_impact: tuple | None = None
