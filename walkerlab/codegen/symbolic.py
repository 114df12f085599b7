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

Knees and round feet (same derivation, more links / another contact point):

- knee (``structure.knee``): the swing leg is a thigh (``psi_swt``) and a shank (``psi_sws``);
  the stance leg stays straight.  The locked knee is the constraint ``J_k dpsi = 0`` with
  ``J_k = d(psi_sws - psi_swt)/dpsi`` on the same coordinates.  With ``S`` a basis of its null
  space, a locked phase, a plastic knee strike and a heel strike with the knee locked are the
  square systems ``[S^T M; J_k] qdd = [S^T (-C dq - G); 0]``, ``[S^T M; J_k] dq+ =
  [S^T M; 0] dq-`` (angular momentum of the whole walker about the stance foot and of the
  swing leg about the hip conserved, McGeer 1990 "Passive walking with knees") and
  ``[S^T Mi; J_k] dq+ = [S^T B; 0] dq-``;
- arc feet (``structure.foot == "arc"``, radius ``R``, centre on the leg axis at ``L - R``
  from the hip): the stance arc rolls without slip, its contact point is ``-R (psi_st +
  gamma)`` along the slope from the step's reference point (where the contact is when the
  stance leg is normal to the slope).  The heel-strike impact is about the swing arc's
  *material* contact point (velocity ``v_centre + w x (-R n)``).  ``swing_foot`` is the next
  step's reference point, ``swing_contact`` the arc's lowest point; R = 0 is the point foot.

Massless limit (Garcia et al. 1998).  A body with mass 0 gets the symbolic mass ``beta``;
``M, C, G`` (and ``Mi, B``) are linear in ``beta``.  A row of the equations that vanishes at
``beta = 0`` (the equation of a coordinate that moves only massless bodies) is replaced by its
coefficient of ``beta`` (the row divided by the mass), every other row by its value at
``beta = 0``.  The result is the exact limit ``beta -> 0`` of the equations (Garcia et al.'s
Eq. 2-4), not a small-mass approximation.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import sympy as sp

from walkerlab.walker.description import ROLE_TAG, Structure

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
        the printed-equation variants (zeros for kneed or arc-footed walkers).
    section_tied : dict[int, int]
        State indices equal to another one on the section (kneed: the swing shank angle and
        rate equal the thigh's just after heel strike).
    locked : tuple (M, C, G) or None
        Flow with the swing knee locked, as the square system described above.
    knee_impact : tuple (Mk, Bk) or None
        Plastic knee strike ``Mk dq+ = Bk dq-``.
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
    section_tied: dict | None = None
    locked: tuple | None = None
    knee_impact: tuple | None = None


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


def position_of(lin: dict) -> sp.Matrix:
    """Position ``sum(length * e(angle))`` of a ``{angle: length}`` leg-vector sum."""
    out = sp.zeros(2, 1)
    for psi, length in lin.items():
        out += length * _e(psi)
    return out


def velocity_terms(lin: dict, psv) -> list[list[tuple]]:
    """For each ``psi_k``: the ``(angle, coefficient)`` terms of ``d position / d psi_k =
    sum coefficient * e'(angle)`` of a ``{angle: length}`` leg-vector sum."""
    out = []
    for s in psv:
        terms = []
        for a, length in lin.items():
            da = sp.diff(a, s)
            if length != 0 and da != 0:
                terms.append((a, length * da))
        out.append(terms)
    return out


def dot_terms(u: list, v: list):
    """``(sum cu e'(a)) . (sum cv e'(b)) = sum cu cv cos(a - b)``."""
    return sum((cu * cv * sp.cos(a - b) for a, cu in u for b, cv in v), sp.Integer(0))


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


@cache
def derive(structure: Structure) -> Equations:
    """Derive flow, impact, guards, energies and points of ``structure`` (memoised per process).

    Returns
    -------
    Equations

    Raises
    ------
    ValueError
        A foot kind this derivation does not handle, or a knee / arc feet with coordinates
        other than ``absolute``.
    """
    if structure.foot not in ("point", "arc"):
        raise ValueError(f"walker.leg.foot.kind: {structure.foot!r} is not supported")
    knee, arc = structure.knee, structure.foot == "arc"
    if (knee or arc) and structure.coordinates != "absolute":
        raise ValueError("walker.coordinates: a knee or arc feet need 'absolute'")
    n = len(structure.roles)
    q = sp.symbols([f"q_{r}" for r in structure.roles], real=True)
    dq = sp.symbols([f"dq_{r}" for r in structure.roles], real=True)
    par = sp.symbols(structure.param_names, real=True)
    P = dict(zip(structure.param_names, par))
    beta = sp.Symbol("beta", positive=True)
    g, L, gamma = P["g"], P["L"], P["gamma"]
    qv, dqv = sp.Matrix(q), sp.Matrix(dq)
    if knee:  # absolute angles (KNEED_ROLES): swing thigh, swing shank, stance
        psi_q = list(q)
        psi_sw, psi_st = q[0], q[2]
    else:
        psi_st, psi_sw = _leg_angles(structure, q, gamma)
        psi_q = [psi_sw, psi_st]

    # derive in absolute link angles psi (swing link(s), stance): each massless body then moves
    # with one coordinate only, so the row limit below is exact; map to q at the end
    if knee:
        ps_sw, ps_shank, ps_st = sp.symbols("psi_swing psi_swing_shank psi_stance", real=True)
        dps = sp.Matrix(sp.symbols("dpsi_swing dpsi_swing_shank dpsi_stance", real=True))
        psv = sp.Matrix([ps_sw, ps_shank, ps_st])
    else:
        ps_sw, ps_st = sp.symbols("psi_swing psi_stance", real=True)
        dps = sp.Matrix(sp.symbols("dpsi_swing dpsi_stance", real=True))
        psv = sp.Matrix([ps_sw, ps_st])
        ps_shank = ps_sw
    normal = sp.Matrix([sp.sin(gamma), sp.cos(gamma)])
    tangent = sp.Matrix([sp.cos(gamma), -sp.sin(gamma)])  # along the slope, downhill
    lt = P["L_thigh"] if knee else 0
    R = P["R_foot"] if arc else 0
    # every position is a sum of leg vectors {link angle: length along it} times e(angle),
    # plus, with arc feet, the rolling offset of the stance arc (contact + R n) - (L - R) stays
    # on the leg: the stance arc's centre is at L - R from the hip
    hip_lin = {ps_st: -(L - R)} if arc else {ps_st: -L}  # stance foot at the origin (A.2)
    offset = (-R * (ps_st + gamma) * tangent + R * normal) if arc else sp.zeros(2, 1)

    def at(lin):
        return position_of(lin) + offset

    def add(lin, psi, length):
        out = dict(lin)
        out[psi] = out.get(psi, 0) + length
        return out

    knee_lin = add(hip_lin, ps_sw, lt) if knee else hip_lin
    foot_lin = add(knee_lin, ps_shank, L - lt - R)   # point foot, or the swing arc's centre
    if arc:
        centre_sw = at(foot_lin)
        swing_contact = centre_sw - R * normal
        swing_foot = swing_contact + R * (ps_shank + gamma) * tangent  # next reference point
    else:
        swing_foot = swing_contact = at(foot_lin)
    points = {"stance_foot": sp.zeros(2, 1), "hip": at(hip_lin), "swing_foot": swing_foot}
    if knee:
        points["swing_knee"] = at(knee_lin)
        points["stance_knee"] = at(add(hip_lin, ps_st, lt))
    if arc:
        points["stance_contact"] = offset - R * normal
        points["stance_foot_centre"] = offset
        points["swing_contact"] = swing_contact
        points["swing_foot_centre"] = centre_sw
    bodies = []  # (mass, {angle: length}, inertia, link angle)
    if structure.hip_mass:
        bodies.append((P["M_hip"], hip_lin, 0, ps_st))

    def bp(kind, name, role):  # a leg body's parameter (per role when the legs differ)
        return P[f"{kind}_{ROLE_TAG[role]}_{name}" if structure.asymmetric else f"{kind}_{name}"]

    for b in structure.bodies:
        for role in ("stance", "swing"):
            mass = beta if b.massless else bp("m", b.name, role)
            inertia = bp("I", b.name, role) if b.kind == "rod" else 0
            d = bp("d", b.name, role)
            if role == "stance":
                lin, psi = add(hip_lin, ps_st, d), ps_st
            elif b.link == "shank":
                lin, psi = add(knee_lin, ps_shank, d - lt), ps_shank
            else:
                lin, psi = add(hip_lin, ps_sw, d), ps_sw
            if b.off_axis:  # ahead of the link's axis: e(psi + pi/2) = (cos psi, sin psi)
                lin = add(lin, psi + sp.pi / 2, bp("e", b.name, role))
            if f"{role}_{b.name}" in points:
                raise ValueError(f"walker.leg.bodies: body name {b.name!r} is reserved")
            points[f"{role}_{b.name}"] = at(lin)
            bodies.append((mass, lin, inertia, psi))
    # upper body on the bisecting hip mechanism (the coupling eliminated): its angle from the
    # upward vertical, positive leaning back, is the mean of the leg angles; a point d up its
    # axis lies at hip - d e(psi_t), one e ahead of the axis at + e e(psi_t + pi/2)
    psi_t = (ps_sw + ps_st) / 2
    for b in structure.torso:
        lin = add(hip_lin, psi_t, -P[f"d_torso_{b.name}"])
        if b.off_axis:
            lin = add(lin, psi_t + sp.pi / 2, P[f"e_torso_{b.name}"])
        points[f"torso_{b.name}"] = at(lin)
        inertia = P[f"I_torso_{b.name}"] if b.kind == "rigid_body" else 0
        bodies.append((P[f"m_torso_{b.name}"], lin, inertia, psi_t))

    V = sp.Integer(0)
    Mi = sp.zeros(n, n)
    Bm = sp.zeros(n, n)
    Mp = sp.zeros(n, n)
    if arc:  # material point of the swing arc at the contact: v_centre + w x (-R n)
        Jf = centre_sw.jacobian(psv) + R * tangent * sp.Matrix([[sp.diff(ps_shank, s)
                                                                for s in psv]])
    for mass, lin, inertia, psi in bodies:
        a = sp.Matrix([[sp.diff(psi, k) for k in psv]])
        if arc:  # the rolling offset moves with psi_st: plain Jacobians
            J = at(lin).jacobian(psv)
            Jn = J - Jf  # velocity Jacobian with the swing arc's contact point at rest
            Mp += mass * J.T * J
            Mi += mass * Jn.T * Jn
            Bm += mass * Jn.T * J
        else:
            # d(position)/d(psi_k) = sum over the angles a of lin[a] da/dpsi_k e'(a), and
            # e'(a) . e'(b) = cos(a - b): the inertia matrices come out simplified without a
            # trigonometric simplifier (a = psi_k for a body on a leg's axis)
            new = {k: lin.get(k, 0) - foot_lin.get(k, 0)
                   for k in {**lin, **foot_lin}}  # swing foot at rest
            dl, dn = velocity_terms(lin, psv), velocity_terms(new, psv)
            for i in range(n):
                for j in range(n):
                    Mp[i, j] += mass * dot_terms(dl[i], dl[j])
                    Mi[i, j] += mass * dot_terms(dn[i], dn[j])
                    Bm[i, j] += mass * dot_terms(dn[i], dl[j])
        Mp += inertia * a.T * a
        Mi += inertia * a.T * a
        Bm += inertia * a.T * a
        V += mass * g * at(lin)[1]
    Mp, Mi, Bm = (X.applyfunc(sp.factor_terms) for X in (Mp, Mi, Bm))
    T = sp.Rational(1, 2) * (dps.T * Mp * dps)[0]
    # torsional spring-dampers: V_s = k (delta - r)^2 / 2 joins the potential (so G and the
    # energy include it); the damper's generalised force -c J^T J dpsi joins C dq
    link_angle = {"swing": ps_sw, "stance": ps_st, "torso": psi_t}
    D = sp.zeros(n, n)
    for i, (first, second) in enumerate(structure.springs):
        delta = link_angle[second] - link_angle[first]
        k_, r_, c_ = P[f"k_s{i}"], P[f"r_s{i}"], P[f"c_s{i}"]
        V += k_ * (delta - r_) ** 2 / 2
        Jd = sp.Matrix([[sp.diff(delta, s) for s in psv]])
        D += c_ * Jd.T * Jd
    if structure.knee_spring:  # the swing knee's (the stance knee is straight, locked: its
        # spring holds a constant energy and no torque the lock does not take, left out)
        knee_angle = ps_shank - ps_sw
        V += P["k_knee"] * (knee_angle - P["r_knee"]) ** 2 / 2
        Jd = sp.Matrix([[sp.diff(knee_angle, s) for s in psv]])
        D += P["c_knee"] * Jd.T * Jd
    G = sp.Matrix([sp.diff(V, s) for s in psv])
    C = sp.zeros(n, n)
    for i in range(n):
        for j in range(n):
            C[i, j] = sum(sp.Rational(1, 2) * (sp.diff(Mp[i, j], psv[k]) + sp.diff(Mp[i, k], psv[j])
                                               - sp.diff(Mp[j, k], psv[i])) * dps[k]
                          for k in range(n))  # Christoffel symbols of the first kind
    C += D
    if structure.variant == "appendix_a":  # the paper's printed A.5: C[1, 0] sign flipped
        if structure.coordinates != "absolute" or len(structure.bodies) != 1 or knee or arc:
            raise ValueError("ideal.variant: appendix_a exists only for the compass gait")
        C[1, 0] = -C[1, 0]
    lim = any(b.massless for b in structure.bodies)
    M = Mp
    if lim:
        flow, _ = _row_limit(Mp.row_join(C).row_join(G), beta)
        M, C, G = flow[:, :n], flow[:, n:2 * n], flow[:, 2 * n]
        imp, _ = _row_limit(Mi.row_join(Bm), beta)
        Mi, Bm = imp[:, :n], imp[:, n:]
        T, V = T.subs(beta, 0), V.subs(beta, 0)
    locked = knee_impact = None
    if knee:  # knee lock J_k dpsi = 0; S spans its null space (thigh and shank together)
        Jk = sp.Matrix([[-1, 1, 0]])
        S = sp.Matrix([[1, 0], [1, 0], [0, 1]])
        z = sp.zeros(1, n)
        locked = (S.T * M).col_join(Jk), (S.T * C).col_join(z), (S.T * G).col_join(sp.zeros(1, 1))
        knee_impact = (S.T * M).col_join(Jk), (S.T * M).col_join(z)
        Mi, Bm = (S.T * Mi).col_join(Jk), (S.T * Bm).col_join(z)
    # to the scene's coordinates: psi = A q + c, dpsi = A dq
    psi_q = sp.Matrix(psi_q)
    A = psi_q.jacobian(qv)
    sub = {s: e for s, e in zip(psv, psi_q)}
    sub.update({dps[i]: (A * dqv)[i] for i in range(n)})
    W = sp.eye(n) if lim else A.T  # keep psi rows in the limit; else Lagrange's rows in q
    M, C, G = (W * M * A).subs(sub), (W * C * A).subs(sub), (W * G).subs(sub)
    Mi, Bm = (W * Mi * A).subs(sub), (W * Bm * A).subs(sub)
    if knee:  # absolute coordinates: A = I, the systems are already in q
        locked = tuple(m_.subs(sub) for m_ in locked)
        knee_impact = tuple(m_.subs(sub) for m_ in knee_impact)
    T, V = T.subs(sub), V.subs(sub)
    points = {k: v.subs(sub) for k, v in points.items()}
    hip, foot = points["hip"], points["swing_foot"]
    swing_contact = swing_contact.subs(sub)
    bodies = [(m_, at(lin).subs(sub), i_, psi.subs(sub)) for m_, lin, i_, psi in bodies]

    # role swap: new stance leg = old swing leg (absolute angles), solved for the new q
    qn = sp.symbols([f"qn_{r}" for r in structure.roles], real=True)
    if knee:  # the swing knee is locked at heel strike; the new swing knee starts straight
        eqs = [qn[2] - psi_sw, qn[0] - psi_st, qn[1] - psi_st]
    else:
        nst, nsw = _leg_angles(structure, qn, gamma)
        eqs = [nst - psi_sw, nsw - psi_st]
    sol = sp.solve(eqs, qn, dict=True)[0]
    relabel_q = sp.Matrix([sp.expand(sol[s]) for s in qn])
    relabel_rate = relabel_q.jacobian(qv)

    sigma = sp.expand(psi_sw + psi_st + 2 * gamma)
    drop = SECTION_DROP[structure.coordinates]
    drop_solution = sp.solve(sigma, q[drop])[0]
    guards = {"heel_strike": sigma, "swing_foot_ahead": sp.expand(psi_sw - psi_st),
              "hip_height": (hip.T * normal)[0],
              "swing_clearance": (swing_contact.T * normal)[0]}
    leg_angles = {"stance": psi_st, "swing": psi_sw}
    tied = {}
    if knee:
        guards["knee_extension"] = q[1] - q[0]  # zero when straight, > 0 hyperextended
        leg_angles = {"stance_thigh": psi_st, "stance_shank": psi_st, "swing_thigh": q[0],
                      "swing_shank": q[1]}
        tied = {1: 0, n + 1: n}
    if structure.torso:  # on a kneed walker the bisector of the thighs
        leg_angles["torso"] = psi_t.subs(sub)

    if knee or arc:  # the printed-equation variants exist for the point-foot compass gait only
        return Equations(
            q=tuple(q), dq=tuple(dq), params=tuple(par), M=M, C=C, G=G, Mi=Mi, B=Bm,
            relabel_q=relabel_q, relabel_rate=relabel_rate, kinetic=T, potential=V,
            guards=guards, points=points, leg_angles=leg_angles, section_drop=drop,
            drop_solution=drop_solution, De=sp.zeros(n + 2, n + 2), E=sp.zeros(2, n + 2),
            limit=lim, section_tied=tied, locked=locked, knee_impact=knee_impact,
        )
    # extended coordinates (stance foot free at (x_f, y_f)) for the printed-equation variants
    xf, yf, dxf, dyf = sp.symbols("x_f y_f dx_f dy_f", real=True)
    qe, dqe = sp.Matrix([*q, xf, yf]), sp.Matrix([*dq, dxf, dyf])
    Te = sp.Integer(0)
    for mass, pos, inertia, psi in bodies:
        ve = (pos + sp.Matrix([xf, yf])).jacobian(qe) * dqe
        a = sp.Matrix([[sp.diff(psi, qi) for qi in qe]])
        Te += (sp.Rational(1, 2) * mass * (ve.T * ve)[0]
               + sp.Rational(1, 2) * inertia * (a * dqe)[0] ** 2)
    Te = Te.subs(beta, 0) if lim else Te
    De = sp.hessian(Te, dqe)
    E = (foot + sp.Matrix([xf, yf])).jacobian(qe)
    return Equations(
        q=tuple(q), dq=tuple(dq), params=tuple(par), M=M, C=C, G=G, Mi=Mi, B=Bm,
        relabel_q=relabel_q, relabel_rate=relabel_rate, kinetic=T, potential=V, guards=guards,
        points=points, leg_angles=leg_angles, section_drop=drop,
        drop_solution=drop_solution, De=De, E=E, limit=lim,
    )
