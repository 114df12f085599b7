"""Flat feet on ankle springs: the rigid hybrid view's modes, derived with sympy from a
:class:`~walkerlab.walker.description.Structure` (``foot == "flat"``) and written as Python
source (the same ``make(p)`` module form as :mod:`walkerlab.codegen.source`, through its
printers and solvers).

Coordinates ``q = (swing, stance, stance_ankle)``: the absolute leg angles (from the
vertical, positive foot ahead of the hip) and the stance ankle's angle ``a``: the sole's
angle from the stance leg's perpendicular, positive toe up (the ankle spring's deflection
plus its rest angle).  The sole angle from the horizontal is ``theta_f = stance + a``; on a
slope ``gamma`` the foot lies flat when ``phi = stance + a + gamma = 0``.  Feet are massless
(Wisse et al. 2006, "Ankle springs instead of arc-shaped feet for passive dynamic walkers",
IEEE-RAS Humanoids); the ankle lies on the sole line, ``heel`` behind and ``toe`` ahead of it.
The swing foot carries no load and sits at its spring's rest angle ``r_sw`` (no coordinate).

A *mode* is a pinned contact point plus locked coordinates; each is derived from the same
bodies with Lagrange's equations ``M qdd + C dq + G = 0`` (``C`` in Christoffel form plus
the ankle damper, ``G`` from gravity and the ankle spring ``k (a - r)^2 / 2``):

- ``heel_contact``: the stance heel pinned at the step's reference point ``O`` (the heel's
  touchdown point); the foot turns about it (``phi > 0``, toe up);
- ``foot_flat``: heel pinned and the foot's angle locked (``J = d phi / dq = [0, 1, 1]``,
  ``S`` a basis of its null space): ``[S^T M; J] qdd = [S^T (-C dq - G); 0]``;
- ``heel_off``: the stance toe pinned at ``O + (heel + toe) t`` (``t`` the downhill slope
  direction); the foot turns about it (``phi < 0``, heel up).

The kinematics of a state follow from the sign of ``phi`` (both maps give the same positions at
``phi = 0``), so ``points`` and ``energies`` need no mode (see :data:`HEEL_OFF_PHI_RAD`).

Resets (plastic impulses; the impulse acts only where a contact is made):

- foot slap (``phi`` reaches 0 in heel contact): ``[S^T M; J] dq+ = [S^T M; 0] dq-`` (the toe
  impulse's generalised force lies along ``J^T``: the knee lock's projection);
- heel strike (the swing heel reaches the slope, in any stance mode): the post-impact
  velocities project the pre-impact momenta onto the coordinates with the swing heel pinned
  and the new stance ankle at the swing foot's rest angle, ``Mi dq+ = sum_i J_i+^T m_i v_i-``
  (``Mi = sum_i J_i+^T m_i J_i+`` plus rotational terms), then the leg roles swap; the
  trailing foot is released (massless, it snaps to its rest angle) unless the double
  support keeps its toe down (below).

Double support (after heel strike, roles swapped; :func:`_double_support`): the leading foot
on its heel (or flat), the trailing foot on its toe, pinned (no slip); its ankle angle ``b``
follows from the toe on the slope, the flow is Lagrange's equations on ``(q, b)`` with the
toe's constraint and its force as multipliers (a numeric KKT solve in the generated code);
the entry impact pins the toe (an impulse through the trailing ankle: the massless foot takes
no impulsive moment), the second stage of the two-contact plastic impact.

Ground reaction (for the heel-off and lift-off guards): the total force from Newton,
``F = sum m_i (a_i - g)`` over the bodies (the feet are massless), normal part ``N = F . n``;
in foot flat the toe's share from the moment balance about the heel,
``N_toe (heel + toe) = sum (r_i x m_i (a_i - g)) + I_i alpha_i`` (friction along the slope
has no moment about the heel), and the heel's ``N - N_toe``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import sympy as sp

from walkerlab.codegen import source as codegen
from walkerlab.codegen.source import (
    IND,
    PRINTER,
    cse_lines,
    flow_lines,
    numpy_fn,
    reset_lines,
    start_module,
)
from walkerlab.codegen.symbolic import dot_terms, position_of, velocity_terms
from walkerlab.walker.description import ROLE_TAG, Structure

#: Index of the stance ankle's angle in ``q``.
ANKLE = 2
#: ``points``/``energies`` read a state as heel off (toe pinned) once ``phi`` is below minus
#: this [rad].  Both kinematics give the same positions at ``phi = 0`` but not the same
#: velocities while the foot turns: at the foot slap (``phi = 0`` to round-off, the foot
#: turning at ~20 rad/s) the state is still heel contact; just after heel off (``phi`` ~
#: ``-phi_dd t^2 / 2``) the foot's rate is ``sqrt(2 |phi_dd| |phi|)`` < 2e-5 rad/s at this
#: threshold (``|phi_dd|`` < 100 rad/s^2), so the kinetic energy read there is off by < 1e-4 J
#: for a microsecond.
HEEL_OFF_PHI_RAD = 1e-12


@dataclass(frozen=True)
class _System:
    """What :func:`~walkerlab.codegen.source.flow_lines` and
    :func:`~walkerlab.codegen.source.reset_lines` read (duck-typed Equations)."""

    q: tuple
    dq: tuple
    M: sp.Matrix = None
    C: sp.Matrix = None
    G: sp.Matrix = None
    Mi: sp.Matrix = None
    B: sp.Matrix = None
    relabel_q: sp.Matrix = None
    relabel_rate: sp.Matrix = None


@dataclass(frozen=True)
class FlatEquations:
    """Symbolic results of :func:`derive_flat` (``n = 3``).

    Attributes
    ----------
    q, dq, qdd, params : tuple of Symbol
    flows : dict[str, _System]
        ``heel_contact``, ``foot_flat``, ``heel_off``: ``M, C, G`` (3 x 3, 3 x 3, 3 x 1).
    resets : dict[str, _System]
        ``foot_slap``, ``heel_strike_heel`` (from heel contact or foot flat: heel-pinned
        kinematics), ``heel_strike_toe`` (from heel off): ``Mi, B, relabel_q, relabel_rate``.
    guards : dict[str, Expr]
        Scalar functions of the state.
    ground : dict[str, list of Expr]
        ``heel``: ``[N, N_toe]``, ``toe``: ``[N]`` [N], functions of ``q, dq, qdd``.
    kinematics : dict[str, dict]
        Per pinned point (``heel``, ``toe``): ``points``, ``kinetic``, ``potential``.
    leg_angles : dict[str, Expr]
    """

    q: tuple
    dq: tuple
    qdd: tuple
    params: tuple
    flows: dict
    resets: dict
    guards: dict
    ground: dict
    kinematics: dict
    leg_angles: dict
    push_off: dict | None = None
    double_support: dict | None = None


def _add(lin: dict, angle, length) -> dict:
    out = dict(lin)
    out[angle] = out.get(angle, 0) + length
    return out


@cache
def derive_flat(structure: Structure) -> FlatEquations:
    """Derive the modes, resets, guards, ground reactions and points of a flat-footed biped.

    Returns
    -------
    FlatEquations

    Raises
    ------
    ValueError
        Not a flat-footed straight-legged walker in absolute coordinates, or massless bodies.
    """
    if structure.foot != "flat" or structure.knee or structure.coordinates != "absolute":
        raise ValueError("walker.leg.foot: the flat-foot derivation needs straight legs, "
                         "flat feet and absolute coordinates")
    if any(b.massless for b in structure.bodies):
        raise ValueError("walker.leg.bodies: flat feet need massive bodies (mass_kg > 0)")
    q = sp.symbols("q_swing q_stance q_stance_ankle", real=True)
    dq = sp.symbols("dq_swing dq_stance dq_stance_ankle", real=True)
    qdd = sp.symbols("ddq_swing ddq_stance ddq_stance_ankle", real=True)
    par = sp.symbols(structure.param_names, real=True)
    P = dict(zip(structure.param_names, par))
    g, L, gamma = P["g"], P["L"], P["gamma"]
    ps_sw, ps_st, a = q
    b_new = sp.Symbol("b_new_ankle", real=True)  # the swing ankle, once it is the stance one

    def fp(kind, role):  # a foot's number (per role when the legs differ)
        t = f"{ROLE_TAG[role]}_" if structure.asymmetric else ""
        return P[{"heel": f"heel_{t}m", "toe": f"toe_{t}m", "k": f"k_{t}ankle",
                  "r": f"r_{t}ankle", "c": f"c_{t}ankle"}[kind]]

    def bp(kind, name, role):
        return P[f"{kind}_{ROLE_TAG[role]}_{name}" if structure.asymmetric else f"{kind}_{name}"]

    hs, ts = fp("heel", "stance"), fp("toe", "stance")
    hw, tw, rw = fp("heel", "swing"), fp("toe", "swing"), fp("r", "swing")
    k_a, r_a, c_a = fp("k", "stance"), fp("r", "stance"), fp("c", "stance")
    half = sp.pi / 2
    normal = sp.Matrix([sp.sin(gamma), sp.cos(gamma)])
    tangent = sp.Matrix([sp.cos(gamma), -sp.sin(gamma)])  # along the slope, downhill
    theta_f = ps_st + a
    swap = {"stance": "swing", "swing": "stance"}
    # positions = sum of {angle: length} e(angle) + a constant offset (e(angle + pi/2) is
    # the unit vector at ``angle`` from the x axis)
    anchors = {"heel": ({theta_f + half: hs}, sp.zeros(2, 1)),
               "toe": ({theta_f + half: -ts}, (hs + ts) * tangent)}

    def bodies_from(ankle_lin: dict, pinned: str = "stance"):
        """(mass, lin, inertia, link angle, name) of every body, the hip's lin and the
        other leg's ankle's lin, for the ``pinned`` leg's ankle at ``ankle_lin``; names
        and numbers by the pre-impact roles (``pinned="swing"``: after a heel strike)."""
        other = swap[pinned]
        leg_psi = {"stance": ps_st, "swing": ps_sw}
        hip = _add(ankle_lin, leg_psi[pinned], -L)
        out = []
        if structure.hip_mass:
            out.append((P["M_hip"], hip, 0, leg_psi[pinned], "hip"))
        for b in structure.bodies:
            for role in (pinned, other):
                psi = leg_psi[role]
                lin = _add(hip, psi, bp("d", b.name, role))
                if b.off_axis:
                    lin = _add(lin, psi + half, bp("e", b.name, role))
                inertia = bp("I", b.name, role) if b.kind == "rod" else 0
                out.append((bp("m", b.name, role), lin, inertia, psi, f"{role}_{b.name}"))
        psi_t = (ps_sw + ps_st) / 2
        for b in structure.torso:
            lin = _add(hip, psi_t, -P[f"d_torso_{b.name}"])
            if b.off_axis:
                lin = _add(lin, psi_t + half, P[f"e_torso_{b.name}"])
            inertia = P[f"I_torso_{b.name}"] if b.kind == "rigid_body" else 0
            out.append((P[f"m_torso_{b.name}"], lin, inertia, psi_t, f"torso_{b.name}"))
        return out, hip, _add(hip, leg_psi[other], L)

    qv, dqv, ddv = sp.Matrix(q), sp.Matrix(dq), sp.Matrix(qdd)
    link_angle = {"swing": ps_sw, "stance": ps_st, "torso": (ps_sw + ps_st) / 2}
    flows, kin, ground, guards = {}, {}, {}, {}
    lead_force = {}
    for pin, (ankle_lin, off) in anchors.items():
        bodies, hip, sw_ankle = bodies_from(ankle_lin)
        if pin == "heel":
            trailing_ankle = position_of(sw_ankle)

        def at(lin, _off=off):
            return position_of(lin) + _off
        M = sp.zeros(3, 3)
        V = k_a * (a - r_a) ** 2 / 2
        F = sp.zeros(2, 1)
        mom = sp.Integer(0)
        for mass, lin, inertia, psi, _name in bodies:
            d = velocity_terms(lin, q)
            w = sp.Matrix([[sp.diff(psi, s) for s in q]])
            for i in range(3):
                for j in range(3):
                    M[i, j] += mass * dot_terms(d[i], d[j])
            M += inertia * w.T * w
            pos = at(lin)
            V += mass * g * pos[1]
            vel = pos.jacobian(qv) * dqv
            acc = vel.jacobian(qv) * dqv + vel.jacobian(dqv) * ddv
            f = mass * (acc + sp.Matrix([0, g]))
            F += f
            mom += pos[0] * f[1] - pos[1] * f[0] + inertia * (w * ddv)[0]
        for i, (first, second) in enumerate(structure.springs):  # springs between links
            delta = link_angle[second] - link_angle[first]
            V += P[f"k_s{i}"] * (delta - P[f"r_s{i}"]) ** 2 / 2
        M = M.applyfunc(sp.factor_terms)
        G = sp.Matrix([sp.diff(V, s) for s in q])
        C = sp.zeros(3, 3)
        for i in range(3):
            for j in range(3):
                C[i, j] = sum(sp.Rational(1, 2) * (sp.diff(M[i, j], q[k]) + sp.diff(M[i, k], q[j])
                                                   - sp.diff(M[j, k], q[i])) * dq[k]
                              for k in range(3))
        C[ANKLE, ANKLE] += c_a  # the ankle damper: torque -c da/dt on the ankle coordinate
        for i, (first, second) in enumerate(structure.springs):
            delta = link_angle[second] - link_angle[first]
            Jd = sp.Matrix([[sp.diff(delta, s) for s in q]])
            C += P[f"c_s{i}"] * Jd.T * Jd
        mode = "heel_contact" if pin == "heel" else "heel_off"
        flows[mode] = _System(q, dq, M=M, C=C, G=G)
        N = (F.T * normal)[0]
        lead_force[pin] = (F, mom)
        # moment balance about the pinned heel: the toe's normal force (see module docstring)
        ground[pin] = [N, mom / (hs + ts)] if pin == "heel" else [N]
        heel_sw = at(_add(sw_ankle, ps_sw + rw + half, -hw))
        toe_sw = at(_add(sw_ankle, ps_sw + rw + half, tw))
        points = {"stance_heel": at(_add(ankle_lin, theta_f + half, -hs)),
                  "stance_toe": at(_add(ankle_lin, theta_f + half, ts)),
                  "stance_ankle": at(ankle_lin), "hip": at(hip),
                  "swing_ankle": at(sw_ankle), "swing_heel": heel_sw, "swing_toe": toe_sw}
        # the contract's names: the stance foot is the stance leg's end, the swing foot the
        # next step's reference point (the swing heel)
        points["stance_foot"] = points["stance_ankle"]
        points["swing_foot"] = heel_sw
        for _m, lin, _i, _p, name in bodies:
            if name != "hip":
                points[name] = at(lin)
        T = sp.Rational(1, 2) * (dqv.T * M * dqv)[0]
        kin[pin] = {"points": points, "kinetic": T, "potential": V}
        guards[f"swing_heel_height_{pin}"] = (heel_sw.T * normal)[0]
        guards[f"hip_height_{pin}"] = (at(hip).T * normal)[0]
    guards["swing_foot_ahead"] = ps_sw - ps_st
    guards["foot_angle"] = ps_st + a + gamma
    # foot flat: the heel-contact flow with the foot's angle locked
    Jl = sp.Matrix([[0, 1, 1]])
    S = sp.Matrix([[1, 0], [0, 1], [0, -1]])
    hc = flows["heel_contact"]
    flows["foot_flat"] = _System(q, dq, M=(S.T * hc.M).col_join(Jl),
                                 C=(S.T * hc.C).col_join(sp.zeros(1, 3)),
                                 G=(S.T * hc.G).col_join(sp.zeros(1, 1)))
    resets = {"foot_slap": _System(q, dq, Mi=(S.T * hc.M).col_join(Jl),
                                   B=(S.T * hc.M).col_join(sp.zeros(1, 3)),
                                   relabel_q=qv, relabel_rate=sp.eye(3))}
    # heel strike: post-impact coordinates (swing, stance, b) with the swing heel pinned and
    # the swing foot at angle swing + b (b = its rest angle at impact), in the pre-impact
    # labelling; then the roles swap (new swing = old stance, new stance = old swing)
    post_q = (ps_sw, ps_st, b_new)
    post_bodies, _h, _a = bodies_from({ps_sw + b_new + half: hw}, "swing")
    post = {b[4]: b for b in post_bodies}
    relabel_q = sp.Matrix([ps_st, ps_sw, rw])
    relabel_rate = sp.Matrix([[0, 1, 0], [1, 0, 0], [0, 0, 1]])
    for pin, (ankle_lin, _off) in anchors.items():
        pre_bodies, _h, _a = bodies_from(ankle_lin)
        Mi, Bm = sp.zeros(3, 3), sp.zeros(3, 3)
        for mass, lin, inertia, psi, name in pre_bodies:
            pmass, plin, pinertia, ppsi, _n = post[name]
            dn, dl = velocity_terms(plin, post_q), velocity_terms(lin, q)
            wn = sp.Matrix([[sp.diff(ppsi, s) for s in post_q]])
            wl = sp.Matrix([[sp.diff(psi, s) for s in q]])
            for i in range(3):
                for j in range(3):
                    Mi[i, j] += mass * dot_terms(dn[i], dn[j])
                    Bm[i, j] += mass * dot_terms(dn[i], dl[j])
            Mi += inertia * wn.T * wn
            Bm += inertia * wn.T * wl
        Mi, Bm = (X.subs(b_new, rw).applyfunc(sp.factor_terms) for X in (Mi, Bm))
        resets[f"heel_strike_{pin}"] = _System(q, dq, Mi=Mi, B=Bm, relabel_q=relabel_q,
                                               relabel_rate=relabel_rate)
    push_off = _push_off_systems(q, anchors, bodies_from, kin, flows, resets, post_q, post)
    leg_angles = {"swing_angle": ps_sw, "stance_angle": ps_st, "stance_ankle_angle": a,
                  "swing_ankle_angle": rw + 0 * ps_sw,
                  "swing_rate": dq[0], "stance_rate": dq[1], "stance_ankle_rate": dq[2],
                  "swing_ankle_rate": 0 * dq[0]}
    double = _double_support(q, dq, qdd, flows, trailing_ankle, lead_force["heel"],
                             (fp("toe", "swing"), fp("k", "swing"), fp("r", "swing"),
                              fp("c", "swing")), hs + ts, gamma, normal, tangent, Jl)
    return FlatEquations(q=q, dq=dq, qdd=qdd, params=tuple(par), flows=flows, resets=resets,
                         guards=guards, ground=ground, kinematics=kin, leg_angles=leg_angles,
                         push_off=push_off, double_support=double)


def _translation_rows(lin: dict, qs) -> sp.Matrix:
    """``d position / d q`` (len(qs), 2) of a ``{angle: length}`` leg-vector sum, row ``i``
    the position's rate for ``dq = e_i`` (``e'(a) = (cos a, sin a)``)."""
    rows = [[sum((c * sp.cos(a) for a, c in t), sp.Integer(0)),
             sum((c * sp.sin(a) for a, c in t), sp.Integer(0))]
            for t in velocity_terms(lin, qs)]
    return sp.Matrix(rows)


def _push_off_systems(q, anchors, bodies_from, kin, flows, resets, post_q, post) -> dict:
    """The extended impact system of each pinned point (``heel``, ``toe``): the push-off at
    the stance toe and the heel strike after it.

    Extended coordinates ``qe = (q, x_f, y_f)``: the walker translated by ``(x_f, y_f)``
    with its pinned point.  Per pin: ``De`` (5, 5), the Hessian of the kinetic energy in
    ``dqe`` (``[M, Mt; Mt^T, m I]``, ``Mt = sum m dr/dq``; singular along the massless
    foot's turn about the ankle, which the push-off holds); ``Jt`` (2, 5), the stance toe's
    Jacobian; ``Jh`` (2, 3), the hip's (its speed for a push-off law); ``Mi`` (3, 3) and
    ``Be`` (3, 5), the heel strike's ``Mi dq+ = Be dqe-`` (momenta of the pre-impact
    velocities, the trailing foot free and moving, projected on the post-impact coordinates
    with the swing heel pinned: ``Be = [B | sum J+^T m]``, ``B`` the passive heel strike's,
    so ``Be [dq; 0] = B dq`` to round-off); ``push`` (2,) the vector toe -> hip;
    ``relabel_q`` (3,) and ``relabel_rate`` (3, 3) the role swap."""
    qv = sp.Matrix(q)
    out = {}
    mode = {"heel": "heel_contact", "toe": "heel_off"}
    for pin, (ankle_lin, _off) in anchors.items():
        pre_bodies, _h, _a = bodies_from(ankle_lin)
        Mt, trans, mass = sp.zeros(3, 2), sp.zeros(3, 2), sp.Integer(0)
        for m_, lin, _i, _psi, name in pre_bodies:
            mass += m_
            Mt += m_ * _translation_rows(lin, q)
            trans += m_ * _translation_rows(post[name][1], post_q)
        hs = resets[f"heel_strike_{pin}"]
        b_new = post_q[2]
        trans = trans.subs(b_new, hs.relabel_q[2]).applyfunc(sp.factor_terms)
        De = flows[mode[pin]].M.row_join(Mt).col_join(Mt.T.row_join(mass * sp.eye(2)))
        pts = kin[pin]["points"]
        toe = pts["stance_toe"]
        out[pin] = {"De": De, "Jt": toe.jacobian(qv).row_join(sp.eye(2)),
                    "Jh": pts["hip"].jacobian(qv), "Mi": hs.Mi, "Be": hs.B.row_join(trans),
                    "push": pts["hip"] - toe, "relabel_q": hs.relabel_q,
                    "relabel_rate": hs.relabel_rate}
    return out



#: The leading foot's modes in double support (the trailing foot on its toe): on its heel
#: (turning about it) or flat (its angle locked).
DOUBLE_SUPPORT_LEADS = ("heel_contact", "foot_flat")


def _double_support(q, dq, qdd, flows, ankle, lead_force, trailing, sole, gamma, normal,
                    tangent, Jl) -> dict:
    """Double support after heel strike (roles already swapped): the leading (stance) foot
    on its heel at ``O`` (heel contact) or flat (foot flat), the trailing (swing) foot on its
    toe at a point ``P`` of the slope.  The trailing foot's ankle angle ``b`` (its sole at
    ``swing + b``) is no state: with the toe on the slope, ``sin(swing + b + gamma) = -h/t``
    (``h`` the trailing ankle's height above the slope, ``t`` the toe length), the branch
    with the heel up; its rate from the toe's zero normal velocity.  The flow: Lagrange's
    equations on ``Q = (swing, stance, stance_ankle, b)`` (the foot massless: ``b``'s row
    holds the spring ``k (b - r)`` and damper ``c db`` against the toe's force), the toe
    pinned, ``[M, -J^T; J, 0] [Qdd; lam] = [-C dQ - G; -dJ dQ]`` (``J = dT/dQ`` (2 x 4) of
    the toe ``T``; foot flat adds ``phi = 0``'s row ``[0, 1, 1, 0]``), ``lam`` the ground's
    force on the toe (world axes) [N].  Entry (the plastic impact that pins the toe, Newton's
    restitution 0): in ``q`` the toe's pin is one row ``g = u^T dA/dq`` (``A`` the trailing
    ankle, ``u`` the unit vector from toe to ankle: a massless foot takes no impulsive
    moment, so the toe's impulse ``Lam u`` passes through the ankle) and
    ``[M, -g^T (, -Jl^T); g, 0 (; Jl, 0)] [dq+; Lam] = [M dq-; 0 (; 0)]``."""
    b, db = sp.symbols("b_trail db_trail", real=True)
    t_len, k_b, r_b, c_b = trailing
    sw = q[0]
    h = (ankle.T * normal)[0]
    theta = sw + b
    toe = ankle + t_len * sp.Matrix([sp.cos(theta), sp.sin(theta)])
    Q, dQ = (*q, b), (*dq, db)
    Qv, dQv = sp.Matrix(Q), sp.Matrix(dQ)
    J = toe.jacobian(Qv)
    dJ = (J * dQv).jacobian(Qv) * dQv
    hc = flows["heel_contact"]
    M4 = sp.zeros(4, 4)
    M4[:3, :3] = hc.M
    rhs = sp.zeros(4, 1)
    rhs[:3, 0] = -hc.C * sp.Matrix(dq) - hc.G
    rhs[3, 0] = -c_b * db - k_b * (b - r_b)
    b_of = sp.asin(-h / t_len) - gamma - sw
    hdot = (sp.Matrix([h]).jacobian(sp.Matrix(q)) * sp.Matrix(dq))[0]
    db_of = -hdot / (t_len * sp.cos(theta + gamma)) - dq[0]
    dA = ankle.jacobian(sp.Matrix(q))
    u = -sp.Matrix([sp.cos(theta), sp.sin(theta)])  # toe -> ankle
    g_row = u.T * dA
    F, mom = lead_force
    out = {"b": b, "db": db, "b_of": b_of, "db_of": db_of, "u": u, "toe": toe,
           "trailing_spring": k_b * (b - r_b) ** 2 / 2, "foot_angle": theta + gamma}
    for lead in DOUBLE_SUPPORT_LEADS:
        rows = J if lead == "heel_contact" else J.col_join(sp.Matrix([[0, 1, 1, 0]]))
        gam = -dJ if lead == "heel_contact" else (-dJ).col_join(sp.zeros(1, 1))
        m = rows.rows
        K = sp.zeros(4 + m, 4 + m)
        K[:4, :4] = M4
        K[:4, 4:] = -rows.T
        K[4:, :4] = rows
        imp_rows = g_row if lead == "heel_contact" else g_row.col_join(Jl)
        mi = imp_rows.rows
        Ki = sp.zeros(3 + mi, 3 + mi)
        Ki[:3, :3] = hc.M
        Ki[:3, 3:] = -imp_rows.T
        Ki[3:, :3] = imp_rows
        out[lead] = {"K": K, "rhs": rhs.col_join(gam), "Ki": Ki,
                     "Ki_rhs": (hc.M * sp.Matrix(dq)).col_join(sp.zeros(mi, 1))}
    # the leading foot's ground force: Newton's total (feet massless) less the toe's; in
    # foot flat its toe's share from the moment balance about its heel, less the trailing
    # toe's moment (the lock's multiplier is that moment: its toe force times the sole)
    lam = sp.Matrix(sp.symbols("lam_x lam_y", real=True))
    out["lead_normal"] = ((F - lam).T * normal)[0]
    out["trail_normal"] = (lam.T * normal)[0]
    out["trail_tangential"] = (lam.T * tangent)[0]
    out["lam"] = lam
    out["sole"] = sole
    return out


def _double_support_lines(eq: FlatEquations, lead: str) -> list[str]:
    """Source of ``_double_support_<lead>(x, gen=None) -> (xdot (6,), forces (4,))``
    (forces: the trailing toe's normal and tangential force, the leading foot's normal force
    and its toe's share [N]; ``gen`` (3,) [N m], if given, a generalised force in ``q``'s
    rows added to the right-hand side: joint torques' ``B tau``, the closed chain's
    ``[M -J^T; J 0] [Qdd; lam] = [-C dQ - G + (B tau, 0); -dJ dQ]``),
    ``double_support_<lead>_entry(x) -> (x+, (Lam_n, Lam_t))`` (the toe's impulse [N s])
    and, once, ``double_support_trailing(x) -> (b, db)``."""
    ds = eq.double_support
    sysd = ds[lead]
    n = len(eq.q)
    head = [codegen.unpack(eq)]
    lines, red = cse_lines([ds["b_of"]], PRINTER)
    head += lines + [f"{IND}{ds['b']} = {PRINTER.doprint(red[0])}"]
    lines, red = cse_lines([ds["db_of"]], PRINTER)
    head += lines + [f"{IND}{ds['db']} = {PRINTER.doprint(red[0])}"]
    K, rhs = sysd["K"], sysd["rhs"]
    m = K.rows
    lines, red = cse_lines(list(K) + list(rhs), PRINTER)
    body = list(head) + lines
    body.append(f"{IND}_K = np.array(({', '.join(PRINTER.doprint(e) for e in red[:m * m])},),"
                f" dtype=float).reshape({m}, {m})")
    body.append(f"{IND}_b = np.array(({', '.join(PRINTER.doprint(e) for e in red[m * m:])},),"
                " dtype=float)")
    body.append(f"{IND}if gen is not None:  # joint torques' generalised force in q's rows")
    body.append(f"{IND}    _b[:{n}] += gen")
    body.append(f"{IND}_s = np.linalg.solve(_K, _b).tolist()")
    body += [f"{IND}{s} = _s[{i}]" for i, s in enumerate(eq.qdd)]
    body += [f"{IND}{ds['lam'][0]}, {ds['lam'][1]} = _s[4], _s[5]"]
    toe_share = (f"_s[6] / ({PRINTER.doprint(ds['sole'])})" if lead == "foot_flat" else "0.0")
    lines, red = cse_lines([ds["trail_normal"], ds["trail_tangential"], ds["lead_normal"]],
                           PRINTER)
    body += lines
    rates = ", ".join(str(s) for s in eq.dq)
    accs = ", ".join(str(s) for s in eq.qdd)
    body.append(f"{IND}return (np.array(({rates}, {accs})), "
                f"({', '.join(PRINTER.doprint(e) for e in red)}, {toe_share}))")
    out = [f"    def _double_support_{lead}(x, gen=None):", *body,
           f"    def flow_double_support_{lead}(t, x, gen=None):",
           f"{IND}return _double_support_{lead}(x, gen)[0]",
           f"    def double_support_{lead}_forces(t, x, gen=None):",
           f"{IND}return _double_support_{lead}(x, gen)[1]"]
    Ki, kr = sysd["Ki"], sysd["Ki_rhs"]
    mi = Ki.rows
    lines, red = cse_lines(list(Ki) + list(kr) + list(ds["u"]), PRINTER)
    nk = mi * mi + mi
    u = [PRINTER.doprint(e) for e in red[nk:]]
    names = ", ".join(str(s) for s in eq.q)
    out += [f"    def double_support_{lead}_entry(x):", *head, *lines,
            f"{IND}_K = np.array(({', '.join(PRINTER.doprint(e) for e in red[:mi * mi])},),"
            f" dtype=float).reshape({mi}, {mi})",
            f"{IND}_b = np.array(({', '.join(PRINTER.doprint(e) for e in red[mi * mi:nk])},),"
            " dtype=float)",
            f"{IND}_s = np.linalg.solve(_K, _b)",
            f"{IND}_u = ({u[0]}, {u[1]})",
            f"{IND}_L = float(_s[{n}])",
            f"{IND}_n = (_u[0] * sin(gamma) + _u[1] * cos(gamma)) * _L",
            f"{IND}_t = (_u[0] * cos(gamma) - _u[1] * sin(gamma)) * _L",
            f"{IND}return np.array(({names}, *_s[:{n}])), (_n, _t)"]
    if lead == DOUBLE_SUPPORT_LEADS[0]:
        lines, red = cse_lines([ds["trailing_spring"], ds["foot_angle"]], PRINTER)
        out += ["    def double_support_trailing(x):", *head, *lines,
                f"{IND}return {ds['b']}, {ds['db']}, {PRINTER.doprint(red[0])}, "
                f"{PRINTER.doprint(red[1])}"]
    return out


def _scalar_fn(name: str, eq: FlatEquations, exprs: list, with_acc: bool) -> list[str]:
    """A Python function ``(t, x)`` or ``(x, qdd)`` returning a float or a tuple."""
    lines, red = cse_lines(exprs, PRINTER)
    unpack = codegen.unpack(eq)
    head = [f"    def {name}(x, qdd):" if with_acc else f"    def {name}(t, x):", unpack]
    if with_acc:
        head.append(f"{IND}{', '.join(str(s) for s in eq.qdd)}, = qdd")
    vals = [PRINTER.doprint(e) for e in red]
    ret = vals[0] if len(vals) == 1 and not with_acc else f"({', '.join(vals)},)"
    return head + lines + [f"{IND}return {ret}"]


def _grad_fn(name: str, eq: FlatEquations, expr) -> list[str]:
    x = [*eq.q, *eq.dq]
    lines, red = cse_lines([sp.diff(expr, s) for s in x], PRINTER)
    return [f"    def {name}(x):", codegen.unpack(eq), *lines,
            f"{IND}return np.array(({', '.join(PRINTER.doprint(e) for e in red)},))"]


def generate_flat(structure: Structure, key: str) -> str:
    """Source text of a flat-footed walker's generated module (``make(p)`` returns, by name:
    ``flow_<mode>``, ``flow_<mode>_jacobian``, ``flow_<mode>_variational`` for the three
    modes; ``reset_<name>`` and ``reset_<name>_jacobian`` for ``foot_slap``,
    ``heel_strike_heel``, ``heel_strike_toe``; ``guard_<name>``/``grad_<name>``;
    ``ground_heel(x, qdd) -> (N, N_toe)`` and ``ground_toe(x, qdd) -> (N,)`` [N];
    per leading-foot mode ``m`` of the double support (``heel_contact``, ``foot_flat``):
    ``flow_double_support_<m>(t, x, gen=None)``, ``double_support_<m>_forces(t, x,
    gen=None)`` (trailing toe normal and tangential, leading foot normal and its toe's share
    [N]; ``gen`` (3,) [N m] a generalised force in ``q``'s rows, joint torques' ``B tau``),
    ``double_support_<m>_entry(x) -> (x+, (Lam_n, Lam_t))`` [N s]; and
    ``double_support_trailing(x) -> (b, db, spring energy [J], trailing sole angle from the
    slope [rad])``;
    ``section``/``from_section``; ``energies`` and, per pinned point, ``energies_heel`` /
    ``energies_toe`` (dicts ``kinetic``, ``potential`` [J]); ``points``; ``leg_angles``)."""
    eq = derive_flat(structure)
    hoisted = codegen.start_module(eq.params)
    fast = []
    for mode, system in eq.flows.items():
        fast += flow_lines(system, False, f"flow_{mode}")
        fast += flow_lines(system, True, f"flow_{mode}_jacobian",
                      variational=f"flow_{mode}_variational")
    for name, system in eq.resets.items():
        fast += reset_lines(system, False, f"reset_{name}")
        fast += reset_lines(system, True, f"reset_{name}_jacobian")
    for name, expr in eq.guards.items():
        fast += _scalar_fn(f"guard_{name}", eq, [expr], False)
        fast += _grad_fn(f"grad_{name}", eq, expr)
    for pin, exprs in eq.ground.items():
        fast += _scalar_fn(f"ground_{pin}", eq, exprs, True)
    for lead in DOUBLE_SUPPORT_LEADS:
        fast += _double_support_lines(eq, lead)
    rest = "r_st_ankle" if structure.asymmetric else "r_ankle"
    section = [
        "    def section(x):",
        f"{IND}return np.asarray(x)[[0, 1, 3, 4, 5]]",
        "    def from_section(z):",
        f"{IND}z0, z1, z2, z3, z4, = z",
        f"{IND}return np.array((z0, z1, {rest} + 0.0 * z0, z2, z3, z4))",
    ]
    kin = eq.kinematics
    numpy = [
        *numpy_fn("_points_heel", eq, kin["heel"]["points"]),
        *numpy_fn("_points_toe", eq, kin["toe"]["points"]),
        *numpy_fn("energies_heel", eq, {"kinetic": kin["heel"]["kinetic"],
                                          "potential": kin["heel"]["potential"]}),
        *numpy_fn("energies_toe", eq, {"kinetic": kin["toe"]["kinetic"],
                                         "potential": kin["toe"]["potential"]}),
        "    def _on_toe(x):  # heel off: the foot turned heel up (phi < 0)",
        f"{IND}x = np.asarray(x)",
        f"{IND}return x[1] + x[2] + gamma < {-HEEL_OFF_PHI_RAD!r}",
        "    def points(x):",
        f"{IND}if np.ndim(x) == 1:  # one state: one kinematics",
        f"{IND}    return _points_toe(x) if _on_toe(x) else _points_heel(x)",
        f"{IND}toe, h, o = _on_toe(x), _points_heel(x), _points_toe(x)",
        f"{IND}return {{k: np.where(toe, o[k], h[k]) for k in h}}",
        "    def energies(x):",
        f"{IND}toe, h, o = _on_toe(x), energies_heel(x), energies_toe(x)",
        f"{IND}return (np.where(toe, o['kinetic'], h['kinetic']),",
        f"{IND}        np.where(toe, o['potential'], h['potential']))",
        *numpy_fn("leg_angles", eq, eq.leg_angles),
        # last: the functions above keep their cse symbols' numbering
        *numpy_fn("push_off_heel", eq, eq.push_off["heel"], args="q"),
        *numpy_fn("push_off_toe", eq, eq.push_off["toe"], args="q"),
    ]
    body = [
        "def make(p):",
        f"    {', '.join(structure.param_names)}, = p",
        *hoisted, *fast, *section, *numpy,
        "    return {k: v for k, v in locals().items() if callable(v) and not k.startswith('_')}",
    ]
    head = [
        f"# walkerlab generated model code (walkerlab.codegen.foot_modes); key {key}",
        "# Do not edit: regenerated when the walker description or the generator changes.",
        "from math import sin, cos, tan, sqrt, pi, asin  # noqa: F401",
        "import numpy  # noqa: F401",
        "import numpy as np",
        "",
    ]
    return "\n".join(head + body) + "\n"



#: Ground reactions each compiled flow writes after the state guards (extra outputs) [N]:
#: the pinned contact's normal force ``N``; the toe's share ``N_toe`` in a heel-pinned mode
#: (the moment balance about the heel) or ``N`` in heel off; the heel's ``N - N_toe`` (0 in
#: heel off).  Each mode writes them with its own ``qdd``, as the Python guards read them.
FORCES = ("normal_force", "toe_force", "heel_force")


def _extra_outputs(eq: FlatEquations, mode: str) -> tuple[list[str], list]:
    """Lines and expressions of a mode's extra outputs: every state guard of ``eq.guards``
    (each through its own ``cse``, as its Python function) then :data:`FORCES` (the ground
    reactions of ``ground_<pin>``, through the same ``cse``; ``qdd`` the mode's ``_a0..``)."""
    lines, exprs = [], []
    for expr in eq.guards.values():
        gl, red = cse_lines([expr], PRINTER)
        lines += gl
        exprs.append(red[0])
    pin = "toe" if mode == "heel_off" else "heel"
    lines += [f"{IND}{s} = _a{i}" for i, s in enumerate(eq.qdd)]
    gl, red = cse_lines(eq.ground[pin], PRINTER)
    lines += gl + [f"{IND}_gN = {PRINTER.doprint(red[0])}"]
    normal = sp.Symbol("_gN")
    if pin == "toe":
        return lines, exprs + [normal, normal, sp.Integer(0)]
    lines += [f"{IND}_gT = {PRINTER.doprint(red[1])}", f"{IND}_gH = _gN - _gT"]
    return lines, exprs + [normal, sp.Symbol("_gT"), sp.Symbol("_gH")]


def generate_flat_compiled(structure: Structure, key: str) -> str:
    """Source of a flat-footed walker's compiled module: numba ``cfunc`` right-hand sides
    ``flow_<mode>`` (2n outputs) and ``flow_<mode>_variational`` (``2n + (2n)^2``) for CyRK's
    C++ integrators, the same equations as :func:`generate_flat` (same lines, same key),
    each writing ``GUARDS`` after its outputs (the state guards, then :data:`FORCES`);
    ``constants(p)`` (the data vector: parameters, parameter-only subexpressions, a zeroed
    call counter) and ``NCONST``, as :func:`walkerlab.codegen.source.generate_compiled`."""
    from walkerlab.codegen.source import _cfunc  # (same package: the compass gait's cfuncs)

    eq = derive_flat(structure)
    hoisted = start_module(eq.params)  # filled as the lines below are generated
    parts = {mode: (flow_lines(system, False, parts=True), flow_lines(system, True, parts=True))
             for mode, system in eq.flows.items()}
    extras = {mode: _extra_outputs(eq, mode) for mode in eq.flows}
    consts = list(structure.param_names) + [h.split("=")[0].strip() for h in hoisted]
    body = ["def constants(p):", f"    {', '.join(structure.param_names)}, = p", *hoisted,
            f"    return np.array(({', '.join(consts)}, 0.0), dtype=np.float64)", "",
            f"NCONST = {len(consts)}",
            f"GUARDS = {(*eq.guards, *FORCES)!r}  # extra outputs, in this order", ""]
    for mode, system in eq.flows.items():
        for var in (False, True):
            name = f"flow_{mode}_variational" if var else f"flow_{mode}"
            body += _cfunc(name, system, consts, parts[mode], var, extras[mode]) + [""]
    head = [
        f"# walkerlab compiled model code (walkerlab.codegen.foot_modes); key {key}",
        "# Do not edit: regenerated when the walker description or the generator changes.",
        "from math import sin, cos, tan, sqrt, pi  # noqa: F401",
        "import numpy as np",
        "from numba import cfunc, types",
        "",
        "SIG = types.void(types.CPointer(types.float64), types.float64,",
        "                 types.CPointer(types.float64), types.CPointer(types.float64))",
        "",
    ]
    return "\n".join(head + body) + "\n"
