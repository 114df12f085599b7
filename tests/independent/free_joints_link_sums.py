"""Symbolic derivation of a planar biped whose joints are all free: two thighs and two shanks
on free (never locking) knees and, optionally, a torso hinged at the hip with its own
coordinate - the five-link biped of Westervelt, Grizzle & Koditschek (2003), "Hybrid zero
dynamics of planar biped walkers", IEEE TAC 48(1):42-56 (their RABBIT), and without the
torso a four-link biped - or two straight legs under a hinged torso: the three-link walker
of Grizzle, Abba & Plestan (2001), "Asymptotically stable walking for biped robots:
analysis via systems with impulse effects", IEEE TAC 46(1):51-64, and of Westervelt,
Grizzle, Chevallereau, Choi & Morris (2007), *Feedback Control of Dynamic Bipedal Robot
Locomotion*, CRC Press.

Coordinates (:data:`walkerlab.walker.description.FREE_KNEE_ROLES`, then ``torso``; straight
legs :data:`walkerlab.walker.description.HINGED_ROLES`): every link's absolute angle, the
legs' from the downward vertical (positive when the link's lower end is ahead of its upper
end, as the straight legs' angles, paper Eq. 1), the torso's from the upward vertical
(positive leaning back, as the bisecting torso's).  All are counter-clockwise rotations, so
a joint's relative angle is a difference of two coordinates.  With ``e(a) = (sin a, -cos
a)`` (world axes: x downhill, y up) and the stance foot at the origin::

    stance knee = -l_s e(q_ss);  hip = stance knee - l_t e(q_st)
    swing knee  = hip + l_t e(q_wt);  swing foot = swing knee + l_s e(q_ws)
    torso point at d = hip - d e(q_t)

(``l_t`` the thigh, ``l_s = L - l_t`` the shank); straight legs (``q = (q_st, q_sw,
q_t)``): ``hip = -L e(q_st)``, ``swing foot = hip + L e(q_sw)``.  Then, as in
:mod:`walkerlab.codegen.legged` (whose helpers for sums of link vectors this module
uses):

- flow: Lagrange's equations ``M qdd + C dq + G = 0``, ``C`` from Christoffel symbols;
- heel strike: plastic impact of the swing foot, the old stance foot leaving the ground
  without impulse; with the post-impact velocities parametrised with the swing foot at rest
  the impulse drops out, ``Mi dq+ = B dq-`` (Westervelt et al. 2003, Sec. III-B; the same
  impact as the extended-coordinate one, ``impact_matrices``: stance foot free at
  ``(x_f, y_f)``, ``De`` and the swing foot's Jacobian ``E``); then the legs' roles swap
  (the torso keeps its angle);
- guards: ``heel_strike`` = ``swing_clearance`` = the swing foot's height above the slope
  (straight legs: ``heel_strike = q_st + q_sw + 2 gamma``, the legs symmetric about the
  slope's normal, as :mod:`walkerlab.codegen.legged`'s; their swing foot passes through
  the ground at mid-stance, which the ideal model ignores), ``swing_foot_ahead`` = its
  distance ahead of the stance foot along the slope, ``hip_height``;
- arc feet (straight legs only): the stance arc rolls (:func:`_rolling`), the impact is
  about the swing arc's material contact point;
- Poincare section: the post-impact states, where the new swing foot (behind) is on the
  ground; the swing shank's angle is solved from that (``-acos(..) - gamma``; a straight
  swing leg's ``-q_st - 2 gamma``, the legs symmetric about the slope's normal);
- leg angles: every link's, and the virtual legs' (``stance``/``swing``: the angle of the line
  from the hip to the stance / swing foot, the straight legs' angles when the knees are
  straight; ``stance`` is the phase variable of the joint-torque laws; written with
  ``atan``, they hold while the hip is above the feet).
"""

from __future__ import annotations

import sympy as sp

from tests.independent.link_sums import add_mass_terms, extended_impact, position_of
from walkerlab.codegen.equations import Equations
from walkerlab.codegen.frames import planar_slope_axes
from walkerlab.codegen.lagrange import christoffel
from walkerlab.walker.description import Structure

__all__ = ["derive_five_link", "generate_five_link"]

#: index of the swing shank's angle in ``q`` (solved from the heel-strike surface)
SECTION_DROP = 3
#: ... and of the straight swing leg's (:data:`walkerlab.walker.description.HINGED_ROLES`)
STRAIGHT_SECTION_DROP = 1


def _plus(lin: dict, psi, length) -> dict:
    """Copy of the link-vector sum ``lin`` with ``length`` more along the angle ``psi``."""
    out = dict(lin)
    out[psi] = out.get(psi, 0) + length
    return out


def _check(structure: Structure) -> None:
    straight = structure.hinged_torso and not structure.knee
    if not straight and (not structure.free_knees or not structure.knee):
        raise ValueError("walker.leg.knee.lock: the five-link generator needs free knees "
                         "(or straight legs under a hinged torso)")
    arc_ok = straight and structure.foot == "arc"
    if ((structure.foot != "point" and not arc_ok) or structure.asymmetric or structure.springs
            or structure.knee_spring or any(b.off_axis or b.massless for b in structure.bodies)
            or any(b.off_axis for b in structure.torso)
            or (structure.torso and not structure.hinged_torso)):
        raise ValueError("walker.leg.knee.lock: free knees need identical legs with point "
                         "feet, massive bodies on the link axes, no springs and a hinged "
                         "torso (if any) today")


def _bodies(structure: Structure, P: dict, psi: dict, lin: dict) -> tuple[list, dict]:
    """The bodies ``(mass, {angle: length}, inertia, link angle)`` and the named points'
    link-vector sums (see the module docstring for the chain)."""
    lt, L = (P["L_thigh"] if structure.knee else 0), P["L"]
    points = dict(lin)
    bodies = []
    if structure.hip_mass:
        bodies.append((P["M_hip"], lin["hip"], 0, psi.get("stance_thigh", psi.get("stance"))))
    for b in structure.bodies:
        d = P[f"d_{b.name}"]
        inertia = P[f"I_{b.name}"] if b.kind == "rod" else 0
        for role in ("stance", "swing"):
            if b.link == "leg":  # a straight leg: d from the hip along it
                a = psi[role]
                where = _plus(lin["hip"], a, d)
            elif b.link == "thigh":
                a = psi[f"{role}_thigh"]
                where = _plus(lin["hip"], a, d)
            elif role == "stance":  # d from the hip along the straightened leg
                a = psi["stance_shank"]
                where = {a: d - L}
            else:
                a = psi["swing_shank"]
                where = _plus(lin["swing_knee"], a, d - lt)
            points[f"{role}_{b.name}"] = where
            bodies.append((P[f"m_{b.name}"], where, inertia, a))
    for b in structure.torso:
        a = psi["torso"]
        where = _plus(lin["hip"], a, -P[f"d_torso_{b.name}"])
        points[f"torso_{b.name}"] = where
        inertia = P[f"I_torso_{b.name}"] if b.kind == "rigid_body" else 0
        bodies.append((P[f"m_torso_{b.name}"], where, inertia, a))
    return bodies, points


def _matrices(q, bodies: list, foot_lin: dict, g):
    """Mass matrix ``M``, impact matrices ``Mi`` (velocities with the swing foot at rest)
    and ``B`` (momentum of the pre-impact velocities on those directions), potential ``V``."""
    n = len(q)
    M, Mi, B = sp.zeros(n, n), sp.zeros(n, n), sp.zeros(n, n)
    V = sp.Integer(0)
    for mass, lin, inertia, a in bodies:
        w = sp.Matrix([[sp.diff(a, k) for k in q]])
        add_mass_terms(M, Mi, B, mass, lin, foot_lin, q, n)
        M += inertia * w.T * w
        Mi += inertia * w.T * w
        B += inertia * w.T * w
        V += mass * g * position_of(lin)[1]
    return [X.applyfunc(sp.factor_terms) for X in (M, Mi, B)] + [V]


def _rolling(q, dq, bodies: list, point_lin: dict, P: dict, psi: dict, normal, tangent):
    """Straight legs on arc feet (radius ``R``, centre on the leg's axis at ``L - R`` from
    the hip; McGeer 1990): every position gains the stance arc's rolling offset ``-R (q_st +
    gamma) t + R n`` (its contact point rolls along the slope from the step's reference
    point), so ``M`` and the impact matrices come from plain Jacobians; the impact is about
    the swing arc's material contact point, moving at ``v_centre + R w t`` (``w`` the swing
    leg's rate), as :mod:`walkerlab.codegen.legged`'s arc feet.

    Returns
    -------
    M, Mi, B : Matrix (n, n)
    V : Expr
    points : dict
        The named points (``stance_foot`` the step's reference point, ``stance_contact``,
        ``stance_foot_centre``, ``swing_contact``, ``swing_foot_centre``, ``swing_foot``
        the next step's reference point).
    De, E : Matrix
        The extended impact (:func:`~walkerlab.codegen.link_sums.extended_impact`'s,
        with the offset and the arc's spin).
    """
    R, gamma, g = P["R_foot"], P["gamma"], P["g"]
    st, ws = psi["stance"], psi["swing"]
    offset = -R * (st + gamma) * tangent + R * normal
    qv = sp.Matrix(q)
    n = len(q)
    spin = sp.Matrix([[sp.diff(ws, k) for k in q]])
    centre = position_of(point_lin["swing_foot"]) + offset
    Jf = centre.jacobian(qv) + R * tangent * spin  # the swing arc's material contact point
    M, Mi, B = sp.zeros(n, n), sp.zeros(n, n), sp.zeros(n, n)
    V = sp.Integer(0)
    for mass, lin, inertia, a in bodies:
        pos = position_of(lin) + offset
        J = pos.jacobian(qv)
        w = sp.Matrix([[sp.diff(a, k) for k in q]])
        Jn = J - Jf
        M += mass * J.T * J + inertia * w.T * w
        Mi += mass * Jn.T * Jn + inertia * w.T * w
        B += mass * Jn.T * J + inertia * w.T * w
        V += mass * g * pos[1]
    points = {k: position_of(v) + offset for k, v in point_lin.items()}
    contact = centre - R * normal
    points.update(stance_foot=sp.zeros(2, 1), stance_foot_centre=offset,
                  stance_contact=offset - R * normal, swing_foot_centre=centre,
                  swing_contact=contact, swing_foot=contact + R * (ws + gamma) * tangent)
    De, E = extended_impact(q, dq, [(m, position_of(lin) + offset, i, a)
                                    for m, lin, i, a in bodies],
                            centre, arc=(R, tangent, ws))
    return [X.applyfunc(sp.factor_terms) for X in (M, Mi, B)] + [V, points, De, E]


def _guards(structure: Structure, points: dict, psi: dict, gamma, normal, tangent) -> dict:
    """The five-link biped's guards (:func:`derive_five_link`): ``heel_strike``,
    ``swing_foot_ahead``, ``hip_height``, ``swing_clearance`` of its ``points`` (arc feet:
    their contact points) on the slope ``gamma`` (its ``normal`` and ``tangent``)."""
    arc = structure.foot == "arc"
    hip, foot = points["hip"], points["swing_foot"]
    clearance = ((points["swing_contact"] if arc else foot).T * normal)[0]
    # the heel strike: the swing foot reaching the slope (its height); straight legs, whose
    # swing foot passes through the ground at mid-stance (ignored, as the compass gait's,
    # Goswami et al. 1996), reach it when the legs are symmetric about the slope's normal
    strike = clearance if structure.knee else psi["stance"] + psi["swing"] + 2 * gamma
    ahead = ((points["swing_contact"] - points["stance_contact"]) if arc else foot).T * tangent
    return {"heel_strike": strike, "swing_foot_ahead": ahead[0],
            "hip_height": (hip.T * normal)[0], "swing_clearance": clearance}


def _leg_angles(hip, foot, psi: dict) -> dict:
    """The generated ``leg_angles`` (:func:`derive_five_link`): the stance leg's (stance
    foot to ``hip``) and the swing leg's (``hip`` to swing ``foot``) angle from the frame's
    y axis [rad], and every coordinate by its role (``psi``)."""
    # atan, not atan2: complex-safe (the complex-step Jacobians of torque laws that read the
    # phase variable), and exact while the hip is above both feet
    return {"stance": sp.atan(-hip[0] / hip[1]),
            "swing": sp.atan((foot[0] - hip[0]) / (hip[1] - foot[1])),
            **psi}


def derive_five_link(structure: Structure) -> Equations:
    """Flow, impact, guards, section, energies, points and leg angles of a free-jointed biped
    (see the module docstring).

    Parameters
    ----------
    structure : Structure
        With ``free_knees`` (and optionally ``hinged_torso``), or straight legs with
        ``hinged_torso``.

    Returns
    -------
    Equations
        ``n = 4`` (no torso) or ``5``; straight legs ``3``; no locked flow, no knee strike.

    Raises
    ------
    ValueError
        A structure this generator does not handle (one line).
    """
    _check(structure)
    roles = structure.roles
    q = sp.symbols([f"q_{r}" for r in roles], real=True)
    dq = sp.symbols([f"dq_{r}" for r in roles], real=True)
    par = sp.symbols(structure.param_names, real=True)
    P = dict(zip(structure.param_names, par))
    psi = dict(zip(roles, q))
    g, gamma = P["g"], P["gamma"]
    if structure.knee:
        lt = P["L_thigh"]
        ls = P["L"] - lt
        ss, st, wt, ws = (psi[r] for r in roles[:4])
        lin = {"stance_foot": {}, "stance_knee": {ss: -ls}, "hip": {ss: -ls, st: -lt}}
        lin["swing_knee"] = _plus(lin["hip"], wt, lt)
        lin["swing_foot"] = _plus(lin["swing_knee"], ws, ls)
    else:  # straight legs under a hinged torso (arc feet: the hip at L - R from the centre)
        st, ws = psi["stance"], psi["swing"]
        reach = P["L"] - (P["R_foot"] if structure.foot == "arc" else 0)
        lin = {"stance_foot": {}, "hip": {st: -reach}}
        lin["swing_foot"] = _plus(lin["hip"], ws, reach)
    bodies, point_lin = _bodies(structure, P, psi, lin)
    normal, tangent = planar_slope_axes(gamma)
    arc = structure.foot == "arc"
    if arc:
        M, Mi, B, V, points, De, E = _rolling(q, dq, bodies, point_lin, P, psi, normal,
                                              tangent)
    else:
        M, Mi, B, V = _matrices(q, bodies, lin["swing_foot"], g)
        points = {k: position_of(v) for k, v in point_lin.items()}
    qv, dqv = sp.Matrix(q), sp.Matrix(dq)
    C = christoffel(M, q, dq)
    G = sp.Matrix([sp.diff(V, k) for k in q])
    hip, foot = points["hip"], points["swing_foot"]
    guards = _guards(structure, points, psi, gamma, normal, tangent)
    if structure.knee:
        relabel_q = sp.Matrix([ws, wt, st, ss, *q[4:]])  # legs swap, the torso keeps its
        reach = (ls * sp.cos(ss + gamma) + lt * sp.cos(st + gamma)  # angle
                 - lt * sp.cos(wt + gamma)) / ls
        drop, drop_solution = SECTION_DROP, -sp.acos(reach) - gamma
    else:
        relabel_q = sp.Matrix([ws, st, q[2]])  # the legs swap, the torso keeps its angle
        drop, drop_solution = STRAIGHT_SECTION_DROP, -st - 2 * gamma
    leg_angles = _leg_angles(hip, foot, psi)
    if not arc:
        De, E = extended_impact(q, dq, [(m, position_of(lin), i, a)
                                        for m, lin, i, a in bodies], foot)
    return Equations(
        q=tuple(q), dq=tuple(dq), params=tuple(par), M=M, C=C, G=G, Mi=Mi, B=B,
        relabel_q=relabel_q, relabel_rate=relabel_q.jacobian(qv),
        kinetic=sp.Rational(1, 2) * (dqv.T * M * dqv)[0], potential=V, guards=guards,
        points=points, leg_angles=leg_angles, section_drop=drop,
        drop_solution=drop_solution, De=De, E=E, limit=False, section_tied={})


def generate_five_link(structure: Structure, key: str) -> str:
    """Source of the generated module of a free-jointed biped: :func:`walkerlab.codegen.
    source.generate` of :func:`derive_five_link` (the same function table as every biped's),
    with ``acos`` imported for the section."""
    from walkerlab.codegen import source

    body = source.generate(derive_five_link(structure), structure.param_names, key)
    return body.replace("import numpy as np\n", "import numpy as np\nfrom math import acos  "
                        "# noqa: F401  (the section's swing shank)\n", 1)
