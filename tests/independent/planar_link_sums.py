"""An independent reference for the planar bipeds' equations: their derivation by sums of
leg vectors (``e(psi) = (sin psi, -cos psi)``, no body tree, no frames), which printed the
planar walkers before :mod:`walkerlab.codegen.legged` derived them from the tree; the tests
compare the two (``tests/test_planar_trees.py``).

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

from tests.independent.link_sums import (
    add_length,
    add_mass_terms,
    extended_impact,
    position_of,
)
from walkerlab.codegen.equations import Equations
from walkerlab.codegen.frames import planar_slope_axes
from walkerlab.codegen.lagrange import christoffel, knee_lock
from walkerlab.walker.description import ROLE_TAG, Structure

#: coordinate of ``q`` eliminated on the heel-strike surface (the rest parametrise the section)
SECTION_DROP = {"absolute": 0, "slope_relative": 1}


def _leg_angles(structure: Structure, q, gamma):
    """Absolute (stance, swing) leg angles from the vertical, positive foot ahead of the hip."""
    if structure.coordinates == "absolute":
        swing, stance = q
        return stance, swing
    theta, phi = q  # Garcia et al. (1998): theta from the slope normal, phi between the legs
    return theta - gamma, theta - phi - gamma


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


@dataclass(frozen=True)
class _Symbols:
    """Symbols and link angles of a derivation (set up by :func:`_symbols`).

    ``q, dq, par`` are the scene's coordinates, rates and parameters (``P`` by name);
    ``psi_sw, psi_st`` the absolute swing (thigh) and stance leg angles as functions of ``q``
    and ``psi_q`` every link angle so; ``psv, dps`` the absolute link angles the derivation
    works in (``ps_sw, ps_shank, ps_st``; ``ps_shank`` is ``ps_sw`` without a knee) and their
    rates, ``psi_t`` the torso's angle; ``normal, tangent`` the slope's unit vectors, ``lt``
    the thigh length and ``R`` the foot radius (0 when there is none).
    """

    structure: Structure
    knee: bool
    arc: bool
    n: int
    q: list
    dq: list
    par: list
    P: dict
    beta: sp.Symbol
    qv: sp.Matrix
    dqv: sp.Matrix
    psi_sw: sp.Expr
    psi_st: sp.Expr
    psi_q: list
    ps_sw: sp.Symbol
    ps_shank: sp.Symbol
    ps_st: sp.Symbol
    psi_t: sp.Expr
    psv: sp.Matrix
    dps: sp.Matrix
    normal: sp.Matrix
    tangent: sp.Matrix
    lt: sp.Expr
    R: sp.Expr


@dataclass(frozen=True)
class _Geometry:
    """Leg-vector sums ``{link angle: length}`` of the hip, the swing knee and the swing foot
    (or arc centre), the stance arc's rolling ``offset`` added to every position, the named
    points, the swing foot's contact point and its arc's centre (None for point feet)."""

    hip_lin: dict
    knee_lin: dict
    foot_lin: dict
    offset: sp.Matrix
    points: dict
    swing_contact: sp.Matrix
    centre_sw: sp.Matrix | None

    def at(self, lin: dict) -> sp.Matrix:
        """Position of a leg-vector sum, relative to the stance foot."""
        return position_of(lin) + self.offset


@dataclass(frozen=True)
class _Dynamics:
    """Flow ``M, C, G``, impact ``Mi, Bm``, energies ``T, V``, whether the massless limit was
    taken (``lim``) and the knee-locked flow and knee strike (``locked``, ``knee_impact``, or
    None) - in link angles, then (:func:`_to_scene`) in the scene's coordinates."""

    M: sp.Matrix
    C: sp.Matrix
    G: sp.Matrix
    Mi: sp.Matrix
    Bm: sp.Matrix
    T: sp.Expr
    V: sp.Expr
    lim: bool
    locked: tuple | None
    knee_impact: tuple | None


def _symbols(structure: Structure) -> _Symbols:
    """Check the structure is one this derivation handles and set up its symbols: the scene's
    coordinates, rates and parameters, the absolute leg angles they give, and the absolute link
    angles the derivation works in.  Each massless body then moves with one link angle only,
    so the row limit is exact; :func:`_to_scene` maps to ``q`` at the end."""
    if structure.foot not in ("point", "arc"):
        raise ValueError(f"walker.leg.foot.kind: {structure.foot!r} is not supported")
    knee, arc = structure.knee, structure.foot == "arc"
    if (knee or arc) and structure.coordinates != "absolute":
        raise ValueError("walker.coordinates: a knee or arc feet need 'absolute'")
    q = sp.symbols([f"q_{r}" for r in structure.roles], real=True)
    dq = sp.symbols([f"dq_{r}" for r in structure.roles], real=True)
    par = sp.symbols(structure.param_names, real=True)
    P = dict(zip(structure.param_names, par))
    gamma = P["gamma"]
    if knee:  # absolute angles (KNEED_ROLES): swing thigh, swing shank, stance
        psi_q = list(q)
        psi_sw, psi_st = q[0], q[2]
    else:
        psi_st, psi_sw = _leg_angles(structure, q, gamma)
        psi_q = [psi_sw, psi_st]
    if knee:
        ps_sw, ps_shank, ps_st = sp.symbols("psi_swing psi_swing_shank psi_stance", real=True)
        dps = sp.Matrix(sp.symbols("dpsi_swing dpsi_swing_shank dpsi_stance", real=True))
        psv = sp.Matrix([ps_sw, ps_shank, ps_st])
    else:
        ps_sw, ps_st = sp.symbols("psi_swing psi_stance", real=True)
        dps = sp.Matrix(sp.symbols("dpsi_swing dpsi_stance", real=True))
        psv = sp.Matrix([ps_sw, ps_st])
        ps_shank = ps_sw
    normal, tangent = planar_slope_axes(gamma)
    return _Symbols(
        structure=structure, knee=knee, arc=arc, n=len(structure.roles), q=q, dq=dq, par=par,
        P=P, beta=sp.Symbol("beta", positive=True), qv=sp.Matrix(q), dqv=sp.Matrix(dq),
        psi_sw=psi_sw, psi_st=psi_st, psi_q=psi_q, ps_sw=ps_sw, ps_shank=ps_shank, ps_st=ps_st,
        psi_t=(ps_sw + ps_st) / 2, psv=psv, dps=dps,
        normal=normal, tangent=tangent,
        lt=P["L_thigh"] if knee else 0, R=P["R_foot"] if arc else 0,
    )


def _geometry(s: _Symbols) -> _Geometry:
    """Positions of the hip, the knees and the feet (and, with arc feet, the contact points
    and arc centres) relative to the stance foot.  Every position is a sum of leg vectors
    ``{link angle: length along it}`` times ``e(angle)`` plus, with arc feet, the rolling
    offset of the stance arc (contact + R n), whose centre stays on the leg at ``L - R`` from
    the hip; the stance foot is at the origin (paper A.2)."""
    L, R, gamma, ps_st = s.P["L"], s.R, s.P["gamma"], s.ps_st
    hip_lin = {ps_st: -(L - R)} if s.arc else {ps_st: -L}
    offset = (-R * (ps_st + gamma) * s.tangent + R * s.normal) if s.arc else sp.zeros(2, 1)

    def at(lin):
        return position_of(lin) + offset

    knee_lin = add_length(hip_lin, s.ps_sw, s.lt) if s.knee else hip_lin
    # point foot, or the swing arc's centre
    foot_lin = add_length(knee_lin, s.ps_shank, L - s.lt - R)
    centre_sw = None
    if s.arc:
        centre_sw = at(foot_lin)
        swing_contact = centre_sw - R * s.normal
        swing_foot = swing_contact + R * (s.ps_shank + gamma) * s.tangent  # next reference
    else:
        swing_foot = swing_contact = at(foot_lin)
    points = {"stance_foot": sp.zeros(2, 1), "hip": at(hip_lin), "swing_foot": swing_foot}
    if s.knee:
        points["swing_knee"] = at(knee_lin)
        points["stance_knee"] = at(add_length(hip_lin, ps_st, s.lt))
    if s.arc:
        points["stance_contact"] = offset - R * s.normal
        points["stance_foot_centre"] = offset
        points["swing_contact"] = swing_contact
        points["swing_foot_centre"] = centre_sw
    return _Geometry(hip_lin, knee_lin, foot_lin, offset, points, swing_contact, centre_sw)


def _bodies(s: _Symbols, geo: _Geometry) -> tuple[list, dict]:
    """The bodies ``(mass, {angle: length}, inertia, link angle)`` - hip mass, each leg body
    for the stance and the swing role (mass ``beta`` when massless), torso bodies - and the
    named points with each body's position added.  The upper body sits on the bisecting hip
    mechanism: its angle from the upward vertical, positive leaning back, is the mean of the
    leg angles; a point ``d`` up its axis lies at ``hip - d e(psi_t)``, one ``e`` ahead of the
    axis at ``+ e e(psi_t + pi/2)``."""
    structure, P, hip_lin = s.structure, s.P, geo.hip_lin
    points = dict(geo.points)
    bodies = []
    if structure.hip_mass:
        bodies.append((P["M_hip"], hip_lin, 0, s.ps_st))

    def bp(kind, name, role):  # a leg body's parameter (per role when the legs differ)
        return P[f"{kind}_{ROLE_TAG[role]}_{name}" if structure.asymmetric else f"{kind}_{name}"]

    for b in structure.bodies:
        for role in ("stance", "swing"):
            mass = s.beta if b.massless else bp("m", b.name, role)
            inertia = bp("I", b.name, role) if b.kind == "rod" else 0
            d = bp("d", b.name, role)
            if role == "stance":
                lin, psi = add_length(hip_lin, s.ps_st, d), s.ps_st
            elif b.link == "shank":
                lin, psi = add_length(geo.knee_lin, s.ps_shank, d - s.lt), s.ps_shank
            else:
                lin, psi = add_length(hip_lin, s.ps_sw, d), s.ps_sw
            if b.off_axis:  # ahead of the link's axis: e(psi + pi/2) = (cos psi, sin psi)
                lin = add_length(lin, psi + sp.pi / 2, bp("e", b.name, role))
            if f"{role}_{b.name}" in points:
                raise ValueError(f"walker.leg.bodies: body name {b.name!r} is reserved")
            points[f"{role}_{b.name}"] = geo.at(lin)
            bodies.append((mass, lin, inertia, psi))
    psi_t = s.psi_t
    for b in structure.torso:
        lin = add_length(hip_lin, psi_t, -P[f"d_torso_{b.name}"])
        if b.off_axis:
            lin = add_length(lin, psi_t + sp.pi / 2, P[f"e_torso_{b.name}"])
        points[f"torso_{b.name}"] = geo.at(lin)
        inertia = P[f"I_torso_{b.name}"] if b.kind == "rigid_body" else 0
        bodies.append((P[f"m_torso_{b.name}"], lin, inertia, psi_t))
    return bodies, points


def _inertia(s: _Symbols, geo: _Geometry, bodies: list):
    """Mass matrix ``Mp``, impact matrices ``Mi`` (velocities with the swing foot's contact
    point at rest) and ``Bm`` (momentum of the pre-impact velocities on the same directions),
    all in link angles, and the gravitational potential ``V``.  With point feet the matrices
    are built from ``e'(a) . e'(b) = cos(a - b)`` and come out simplified without a
    trigonometric simplifier; with arc feet (the rolling offset moves with ``psi_st``) from
    plain Jacobians, the swing arc's material contact point moving at ``v_centre + w x (-R n)``.

    Returns
    -------
    Mp, Mi, Bm : Matrix (n, n)
    V : Expr
    """
    n, psv = s.n, s.psv
    V = sp.Integer(0)
    Mi = sp.zeros(n, n)
    Bm = sp.zeros(n, n)
    Mp = sp.zeros(n, n)
    if s.arc:  # material point of the swing arc at the contact: v_centre + w x (-R n)
        Jf = geo.centre_sw.jacobian(psv) + s.R * s.tangent * sp.Matrix(
            [[sp.diff(s.ps_shank, k) for k in psv]])
    for mass, lin, inertia, psi in bodies:
        a = sp.Matrix([[sp.diff(psi, k) for k in psv]])
        if s.arc:
            J = geo.at(lin).jacobian(psv)
            Jn = J - Jf  # velocity Jacobian with the swing arc's contact point at rest
            Mp += mass * J.T * J
            Mi += mass * Jn.T * Jn
            Bm += mass * Jn.T * J
        else:
            # d(position)/d(psi_k) = sum over the angles a of lin[a] da/dpsi_k e'(a)
            # (a = psi_k for a body on a leg's axis); Mi, Bm with the swing foot at rest
            add_mass_terms(Mp, Mi, Bm, mass, lin, geo.foot_lin, psv, n)
        Mp += inertia * a.T * a
        Mi += inertia * a.T * a
        Bm += inertia * a.T * a
        V += mass * s.P["g"] * geo.at(lin)[1]
    Mp, Mi, Bm = (X.applyfunc(sp.factor_terms) for X in (Mp, Mi, Bm))
    return Mp, Mi, Bm, V


def _springs(s: _Symbols, V):
    """Torsional spring-dampers: each spring's ``V_s = k (delta - r)^2 / 2`` joins the
    potential ``V`` (so ``G`` and the energy include it) and its damper's generalised force
    ``-c J^T J dpsi`` the damping matrix ``D`` (added to ``C``).  The swing knee's spring acts
    on ``shank - thigh``; the stance knee is straight and locked, so its spring holds a
    constant energy and no torque the lock does not take, and is left out.

    Returns
    -------
    V : Expr
    D : Matrix (n, n)
    """
    psv, P = s.psv, s.P
    link_angle = {"swing": s.ps_sw, "stance": s.ps_st, "torso": s.psi_t}
    D = sp.zeros(s.n, s.n)
    for i, (first, second) in enumerate(s.structure.springs):
        delta = link_angle[second] - link_angle[first]
        k_, r_, c_ = P[f"k_s{i}"], P[f"r_s{i}"], P[f"c_s{i}"]
        V += k_ * (delta - r_) ** 2 / 2
        Jd = sp.Matrix([[sp.diff(delta, k) for k in psv]])
        D += c_ * Jd.T * Jd
    if s.structure.knee_spring:
        knee_angle = s.ps_shank - s.ps_sw
        V += P["k_knee"] * (knee_angle - P["r_knee"]) ** 2 / 2
        Jd = sp.Matrix([[sp.diff(knee_angle, k) for k in psv]])
        D += P["c_knee"] * Jd.T * Jd
    return V, D


def _lagrange(s: _Symbols, Mp, Mi, Bm, V, D) -> _Dynamics:
    """Lagrange's equations in link angles: ``G = dV/dpsi``, ``C`` from the Christoffel
    symbols of the first kind of ``Mp`` plus the dampers ``D`` (the printed A.5's sign flip of
    ``C[1, 0]`` for the ``appendix_a`` variant), the kinetic energy; then the exact massless
    limit of flow and impact (see the module docstring) and, with a knee, the knee lock
    ``J_k dpsi = 0`` (``S`` spans its null space: thigh and shank together): locked flow,
    knee strike and heel strike with the knee locked as square systems."""
    n, psv, dps, beta = s.n, s.psv, s.dps, s.beta
    T = sp.Rational(1, 2) * (dps.T * Mp * dps)[0]
    G = sp.Matrix([sp.diff(V, k) for k in psv])
    C = christoffel(Mp, psv, dps)  # Christoffel symbols of the first kind
    C += D
    structure = s.structure
    if structure.variant == "appendix_a":  # the paper's printed A.5: C[1, 0] sign flipped
        if (structure.coordinates != "absolute" or len(structure.bodies) != 1 or s.knee
                or s.arc):
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
    if s.knee:  # the swing thigh and shank are link angles 0 and 1
        locked, knee_impact, (Mi, Bm) = knee_lock(M, C, G, Mi, Bm, thigh=0, shank=1)
    return _Dynamics(M, C, G, Mi, Bm, T, V, lim, locked, knee_impact)


def _to_scene(s: _Symbols, dyn: _Dynamics, geo: _Geometry, points: dict, bodies: list):
    """Map everything from link angles to the scene's coordinates, ``psi = A q + c`` and
    ``dpsi = A dq``: the equations' rows stay link-angle rows in the massless limit (each
    moves one body), else they become Lagrange's rows in ``q`` (``A^T``).  A kneed walker's
    coordinates are absolute (``A = I``): its locked systems only need the substitution.

    Returns
    -------
    dyn : _Dynamics
        In ``q``.
    points : dict[str, Matrix (2, 1)]
    swing_contact : Matrix (2, 1)
    bodies : list of (mass, position, inertia, link angle)
        Positions and link angles in ``q``.
    sub : dict
        The substitution of link angles and rates.
    """
    n = s.n
    psi_q = sp.Matrix(s.psi_q)
    A = psi_q.jacobian(s.qv)
    sub = {k: e for k, e in zip(s.psv, psi_q)}
    sub.update({s.dps[i]: (A * s.dqv)[i] for i in range(n)})
    W = sp.eye(n) if dyn.lim else A.T  # keep psi rows in the limit; else Lagrange's rows in q
    locked, knee_impact = dyn.locked, dyn.knee_impact
    if s.knee:
        locked = tuple(m_.subs(sub) for m_ in locked)
        knee_impact = tuple(m_.subs(sub) for m_ in knee_impact)
    out = _Dynamics(
        M=(W * dyn.M * A).subs(sub), C=(W * dyn.C * A).subs(sub), G=(W * dyn.G).subs(sub),
        Mi=(W * dyn.Mi * A).subs(sub), Bm=(W * dyn.Bm * A).subs(sub), T=dyn.T.subs(sub),
        V=dyn.V.subs(sub), lim=dyn.lim, locked=locked, knee_impact=knee_impact,
    )
    points = {k: v.subs(sub) for k, v in points.items()}
    bodies = [(m_, geo.at(lin).subs(sub), i_, psi.subs(sub)) for m_, lin, i_, psi in bodies]
    return out, points, geo.swing_contact.subs(sub), bodies, sub


def _swap_and_guards(s: _Symbols, points: dict, swing_contact, sub: dict) -> dict:
    """Role swap at heel strike (the new stance leg is the old swing leg, absolute angles,
    solved for the new ``q``; a kneed walker's swing knee is locked at heel strike and the new
    swing knee starts straight), the guards, the heel-strike section (the coordinate solved
    from its guard; kneed: the shank's angle and rate tied to the thigh's) and the named
    absolute leg angles.  Returns the matching :class:`Equations` fields by name."""
    structure, q, n, gamma = s.structure, s.q, s.n, s.P["gamma"]
    psi_sw, psi_st = s.psi_sw, s.psi_st
    qn = sp.symbols([f"qn_{r}" for r in structure.roles], real=True)
    if s.knee:
        eqs = [qn[2] - psi_sw, qn[0] - psi_st, qn[1] - psi_st]
    else:
        nst, nsw = _leg_angles(structure, qn, gamma)
        eqs = [nst - psi_sw, nsw - psi_st]
    sol = sp.solve(eqs, qn, dict=True)[0]
    relabel_q = sp.Matrix([sp.expand(sol[k]) for k in qn])
    relabel_rate = relabel_q.jacobian(s.qv)

    sigma = sp.expand(psi_sw + psi_st + 2 * gamma)
    drop = SECTION_DROP[structure.coordinates]
    drop_solution = sp.solve(sigma, q[drop])[0]
    guards = {"heel_strike": sigma, "swing_foot_ahead": sp.expand(psi_sw - psi_st),
              "hip_height": (points["hip"].T * s.normal)[0],
              "swing_clearance": (swing_contact.T * s.normal)[0]}
    leg_angles = {"stance": psi_st, "swing": psi_sw}
    tied = {}
    if s.knee:
        guards["knee_extension"] = q[1] - q[0]  # zero when straight, > 0 hyperextended
        leg_angles = {"stance_thigh": psi_st, "stance_shank": psi_st, "swing_thigh": q[0],
                      "swing_shank": q[1]}
        tied = {1: 0, n + 1: n}
    if structure.torso:  # on a kneed walker the bisector of the thighs
        leg_angles["torso"] = s.psi_t.subs(sub)
    return {"relabel_q": relabel_q, "relabel_rate": relabel_rate, "guards": guards,
            "leg_angles": leg_angles, "section_drop": drop, "drop_solution": drop_solution,
            "section_tied": tied}


@cache
def derive(structure: Structure) -> Equations:
    """Derive flow, impact, guards, energies and points of ``structure`` (memoised per process).

    Parameters
    ----------
    structure : Structure
        The walker's form (no numbers).

    Returns
    -------
    Equations

    Raises
    ------
    ValueError
        A foot kind this derivation does not handle, or a knee / arc feet with coordinates
        other than ``absolute``.
    """
    s = _symbols(structure)
    geo = _geometry(s)
    bodies, points = _bodies(s, geo)
    Mp, Mi, Bm, V = _inertia(s, geo, bodies)
    V, D = _springs(s, V)
    dyn, points, swing_contact, bodies, sub = _to_scene(
        s, _lagrange(s, Mp, Mi, Bm, V, D), geo, points, bodies)
    swap = _swap_and_guards(s, points, swing_contact, sub)
    # the extended impact system (a push-off at the stance foot's contact point): the swing
    # foot's material contact point, an arc's from its centre and its spin.  The stance
    # arc's material contact point moves at (dx_f, dy_f) there: the rolling offset's rate
    # -R dpsi t cancels the arc's spin about its centre R dpsi t, so an impulse there (a
    # push-off) has the generalised force [0, ..., 0, F] for a point foot and an arc alike
    massless = s.beta if dyn.lim else None
    De, E = (extended_impact(s.q, s.dq, bodies, points["swing_foot_centre"],
                             massless=massless, arc=(s.R, s.tangent, s.ps_shank.subs(sub)))
             if s.arc else
             extended_impact(s.q, s.dq, bodies, points["swing_foot"], massless=massless))
    extra = ({"locked": dyn.locked, "knee_impact": dyn.knee_impact} if s.arc or s.knee
             else {"section_tied": None})
    return Equations(
        q=tuple(s.q), dq=tuple(s.dq), params=tuple(s.par), M=dyn.M, C=dyn.C, G=dyn.G,
        Mi=dyn.Mi, B=dyn.Bm, kinetic=dyn.T, potential=dyn.V, points=points, De=De, E=E,
        limit=dyn.lim, **{**swap, **extra},
    )
