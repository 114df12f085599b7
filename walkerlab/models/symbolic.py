"""Generic symbolic derivation of a planar biped from its :class:`Structure` (sympy).

Nothing here is specific to one walker: positions of all bodies follow from the leg angles,
then

- flow: Lagrange's equations ``M(q) qdd + C(q, dq) dq + G(q) = 0`` (paper Eq. 2-4), with
  ``T = sum 1/2 m |v|^2 + 1/2 I w^2`` and ``V = sum m g y``; ``C`` in Christoffel form;
- heel strike: plastic impact at the swing foot (paper Eq. 5-8).  With the generalised
  velocities after impact parametrised with the new stance foot at rest, the impulse drops
  out and ``Mi(q) dq+ = B(q) dq-`` (``Mi`` is the inertia about the new stance foot, ``B``
  the momentum of the pre-impact velocities projected on the same directions: conservation of
  angular momentum about the new contact point, of the swing part about the hip, ...).  The
  leg roles are then swapped;
- guards: ``sigma = psi_sw + psi_st + 2 gamma`` (heel strike: the swing foot reaches the
  slope with the legs symmetric about its normal), ``psi_sw - psi_st`` (swing foot ahead),
  hip height above the slope (fall);
- energies, named points, absolute leg angles.

Massless limit (Garcia et al. 1998).  A body with mass 0 gets the symbolic mass ``beta``;
``M, C, G`` (and ``Mi, B``) are linear in ``beta``.  A row of the equations that vanishes at
``beta = 0`` (the equation of a coordinate that moves only massless bodies) is replaced by its
coefficient of ``beta`` (the row divided by the mass), every other row by its value at
``beta = 0``.  The result is the exact limit ``beta -> 0`` of the equations (Garcia et al.'s
Eq. 2-4), not a small-mass approximation.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from walkerlab.models.description import Structure

#: coordinate of ``q`` eliminated on the heel-strike surface (the rest parametrise the section)
SECTION_DROP = {"absolute": 0, "slope_relative": 1}


@dataclass(frozen=True)
class Equations:
    """Symbolic results of :func:`derive` (all sympy; ``n = len(q)``).

    Attributes
    ----------
    q, dq : tuple of Symbol, shape (n,)
    params : tuple of Symbol
        In ``structure.param_names`` order.
    M, C : Matrix (n, n); G : Matrix (n, 1)
        Flow ``M qdd + C dq + G = 0`` (after the massless limit, if any).
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
    points : dict[str, Matrix (2, 1)]
        Named points relative to the stance foot (world axes, x downhill, y up).
    leg_angles : dict[str, Expr]
        ``stance`` and ``swing`` absolute leg angles from the vertical.
    section_drop : int
        Index in ``q`` solved from the heel-strike guard; ``drop_solution`` is its expression.
    De, E : Matrix
        Extended impact matrices (coordinates ``[q, x_f, y_f]``, paper Eq. 6-7, A.7-A.24) for
        the printed-equation variants.
    """

    q: tuple
    dq: tuple
    params: tuple
    M: sp.Matrix
    C: sp.Matrix
    G: sp.Matrix
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


def _e(psi):
    """Unit vector from the hip towards the foot of a leg at angle ``psi`` from the vertical."""
    return sp.Matrix([sp.sin(psi), -sp.cos(psi)])


def _leg_angles(structure: Structure, q, gamma):
    """Absolute (stance, swing) leg angles from the vertical, positive foot ahead of the hip."""
    if structure.coordinates == "absolute":
        swing, stance = q
        return stance, swing
    theta, phi = q  # Garcia et al. (1998): theta from the slope normal, phi between the legs
    return theta - gamma, theta - phi - gamma


def _trig(e):
    """Cheap trigonometric tidy-up: products of sines/cosines of two angles to cos(a - b)."""
    return sp.trigsimp(sp.expand(e), method="fu") if e.has(sp.sin, sp.cos) else e


def _row_limit(rows: sp.Matrix, beta) -> tuple[sp.Matrix, bool]:
    """Exact limit ``beta -> 0`` of a system linear in ``beta`` (see module docstring)."""
    out = sp.zeros(*rows.shape)
    scaled = False
    for i in range(rows.rows):
        row = rows[i, :]
        at0 = row.subs(beta, 0)
        if all(sp.expand(v) == 0 for v in at0):
            out[i, :] = row.diff(beta).subs(beta, 0)
            scaled = True
        else:
            out[i, :] = at0
    return out, scaled


def derive(structure: Structure) -> Equations:
    """Derive flow, impact, guards, energies and points of ``structure``.

    Returns
    -------
    Equations

    Raises
    ------
    ValueError
        A foot kind this derivation does not handle.
    """
    if structure.foot != "point":
        raise ValueError(f"walker.leg.foot.kind: {structure.foot!r} is not supported")
    n = len(structure.roles)
    q = sp.symbols([f"q_{r}" for r in structure.roles], real=True)
    dq = sp.symbols([f"dq_{r}" for r in structure.roles], real=True)
    par = sp.symbols(structure.param_names, real=True)
    P = dict(zip(structure.param_names, par))
    beta = sp.Symbol("beta", positive=True)
    g, L, gamma = P["g"], P["L"], P["gamma"]
    psi_st, psi_sw = _leg_angles(structure, q, gamma)
    qv, dqv = sp.Matrix(q), sp.Matrix(dq)

    # derive in absolute leg angles psi = (psi_sw, psi_st): each massless body then moves with
    # one coordinate only, so the row limit below is exact; map to q at the end (psi = A q + c)
    ps_sw, ps_st = sp.symbols("psi_swing psi_stance", real=True)
    dps = sp.Matrix(sp.symbols("dpsi_swing dpsi_stance", real=True))
    psv = sp.Matrix([ps_sw, ps_st])
    hip = -L * _e(ps_st)  # stance foot at the origin (A.2)
    points = {"stance_foot": sp.zeros(2, 1), "hip": hip, "swing_foot": hip + L * _e(ps_sw)}
    bodies = []  # (mass, position, inertia, link angle)
    if structure.hip_mass:
        bodies.append((P["M_hip"], hip, 0, ps_st))
    for b in structure.bodies:
        mass = beta if b.massless else P[f"m_{b.name}"]
        inertia = P[f"I_{b.name}"] if b.kind == "rod" else 0
        for role, psi in (("stance", ps_st), ("swing", ps_sw)):
            pos = hip + P[f"d_{b.name}"] * _e(psi)
            if f"{role}_{b.name}" in points:
                raise ValueError(f"walker.leg.bodies: body name {b.name!r} is reserved")
            points[f"{role}_{b.name}"] = pos
            bodies.append((mass, pos, inertia, psi))

    foot = points["swing_foot"]
    Jf = foot.jacobian(psv)
    T = sp.Integer(0)
    V = sp.Integer(0)
    Mi = sp.zeros(2, 2)
    Bm = sp.zeros(2, 2)
    Mp = sp.zeros(2, 2)
    for mass, pos, inertia, psi in bodies:
        J = pos.jacobian(psv)
        a = sp.Matrix([[sp.diff(psi, s) for s in psv]])
        Mp += mass * J.T * J + inertia * a.T * a
        V += mass * g * pos[1]
        Jn = J - Jf  # velocity Jacobian with the swing foot at rest (new pivot)
        Mi += mass * Jn.T * Jn + inertia * a.T * a
        Bm += mass * Jn.T * J + inertia * a.T * a
    Mp = Mp.applyfunc(_trig)
    Mi = Mi.applyfunc(_trig)
    Bm = Bm.applyfunc(_trig)
    T = sp.Rational(1, 2) * (dps.T * Mp * dps)[0]
    G = sp.Matrix([sp.diff(V, s) for s in psv])
    C = sp.zeros(2, 2)
    for i in range(2):
        for j in range(2):
            C[i, j] = sum(sp.Rational(1, 2) * (sp.diff(Mp[i, j], psv[k]) + sp.diff(Mp[i, k], psv[j])
                                               - sp.diff(Mp[j, k], psv[i])) * dps[k]
                          for k in range(2))
    lim = any(b.massless for b in structure.bodies)
    M = Mp
    if lim:
        flow, _ = _row_limit(Mp.row_join(C).row_join(G), beta)
        M, C, G = flow[:, :2], flow[:, 2:4], flow[:, 4]
        imp, _ = _row_limit(Mi.row_join(Bm), beta)
        Mi, Bm = imp[:, :2], imp[:, 2:]
        T, V = T.subs(beta, 0), V.subs(beta, 0)
    # to the scene's coordinates: psi = A q + c, dpsi = A dq
    psi_q = sp.Matrix([psi_sw, psi_st])
    A = psi_q.jacobian(qv)
    sub = {ps_sw: psi_sw, ps_st: psi_st, dps[0]: (A * dqv)[0], dps[1]: (A * dqv)[1]}
    W = sp.eye(2) if lim else A.T  # keep psi rows in the limit; else Lagrange's rows in q
    M, C, G = (W * M * A).subs(sub), (W * C * A).subs(sub), (W * G).subs(sub)
    Mi, Bm = (W * Mi * A).subs(sub), (W * Bm * A).subs(sub)
    T, V = T.subs(sub), V.subs(sub)
    points = {k: v.subs(sub) for k, v in points.items()}
    hip, foot = points["hip"], points["swing_foot"]
    bodies = [(m_, pos.subs(sub), i_, psi.subs(sub)) for m_, pos, i_, psi in bodies]

    # role swap: new stance leg = old swing leg (absolute angles), solved for the new q
    qn = sp.symbols([f"qn_{r}" for r in structure.roles], real=True)
    nst, nsw = _leg_angles(structure, qn, gamma)
    sol = sp.solve([nst - psi_sw, nsw - psi_st], qn, dict=True)[0]
    relabel_q = sp.Matrix([sp.expand(sol[s]) for s in qn])
    relabel_rate = relabel_q.jacobian(qv)

    sigma = sp.expand(psi_sw + psi_st + 2 * gamma)
    drop = SECTION_DROP[structure.coordinates]
    drop_solution = sp.solve(sigma, q[drop])[0]
    normal = sp.Matrix([sp.sin(gamma), sp.cos(gamma)])
    guards = {"heel_strike": sigma, "swing_foot_ahead": sp.expand(psi_sw - psi_st),
              "hip_height": (hip.T * normal)[0]}

    # extended coordinates (stance foot free at (x_f, y_f)) for the printed-equation variants
    xf, yf, dxf, dyf = sp.symbols("x_f y_f dx_f dy_f", real=True)
    qe, dqe = sp.Matrix([*q, xf, yf]), sp.Matrix([*dq, dxf, dyf])
    Te = sp.Integer(0)
    for mass, pos, inertia, psi in bodies:
        ve = (pos + sp.Matrix([xf, yf])).jacobian(qe) * dqe
        a = sp.Matrix([[sp.diff(psi, qi) for qi in qe]])
        Te += sp.Rational(1, 2) * mass * (ve.T * ve)[0] + sp.Rational(1, 2) * inertia * (a * dqe)[0] ** 2
    Te = Te.subs(beta, 0) if lim else Te
    De = sp.hessian(Te, dqe)
    E = (foot + sp.Matrix([xf, yf])).jacobian(qe)
    return Equations(
        q=tuple(q), dq=tuple(dq), params=tuple(par), M=M, C=C, G=G, Mi=Mi, B=Bm,
        relabel_q=relabel_q, relabel_rate=relabel_rate, kinetic=T, potential=V, guards=guards,
        points=points, leg_angles={"stance": psi_st, "swing": psi_sw}, section_drop=drop,
        drop_solution=drop_solution, De=De, E=E, limit=lim,
    )
