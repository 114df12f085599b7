"""The independent reference of the planar floating (contact) view: the leg-vector sums that
derived it before the body tree did (:func:`walkerlab.codegen.floating_equations.
derive_floating`): every point ``hip + sum(length * e(angle))`` of absolute link angles,
the mass matrix in ``cos(a - b)`` form, sharing no kinematics with the tree.  Conventions:
the module docstring of :mod:`walkerlab.codegen.floating_equations`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from walkerlab.codegen.floating_names import (
    LEGS,
    FloatingEquations,
    check_masses,
    contact_names,
    coordinate_names,
    param_names,
)
from walkerlab.walker.description import Structure
from walkerlab.walker.multibody import check_floating_view


@cache
def derive_floating(structure: Structure) -> FloatingEquations:  # planar legs only
    """Derive the floating view of ``structure`` (memoised per process): the legs' bodies
    and feet (:func:`_legs`), the torso's (:func:`_torso`), the mass matrix and potential
    of the bodies (:func:`_mass_and_potential`), the spring-dampers (:func:`_springs`),
    then the bias ``h`` (module docstring).

    Raises
    ------
    ValueError
        Massless bodies (:func:`check_masses`), a foot kind other than point / arc /
        flat, or free knees on feet other than points, legs that differ or with springs
        (:func:`walkerlab.walker.multibody.check_floating_view`).
    """
    import sympy as sp

    from walkerlab.codegen.lagrange import bias  # light: sympy on first derivation only

    check_floating_view(structure)
    check_masses(structure)
    if structure.foot not in ("point", "arc", "flat"):
        raise ValueError(f"walker.leg.foot.kind: {structure.foot!r} is not supported")
    s = _symbols(structure)
    q, dq, names = s.q, s.dq, s.names
    bodies, feet, points = _legs(s)
    psi_t = _torso(s, bodies, points)
    M, V = _mass_and_potential(s, bodies)
    dqv = sp.Matrix(dq)
    T = sp.Rational(1, 2) * (dqv.T * M * dqv)[0]
    V, damping = _springs(s, V, psi_t)
    h = (bias(M, V, q, dq) + damping * dqv).applyfunc(sp.expand)
    return FloatingEquations(q=tuple(q), dq=tuple(dq), params=tuple(s.par), M=M, h=h,
                             feet=tuple(feet), kinetic=T, potential=V, points=points,
                             knees=tuple((names.index(f"{leg}_thigh_angle"),
                                          names.index(f"{leg}_shank_angle"))
                                         for leg in LEGS
                                         if s.knee and not structure.free_knees),
                             contacts=contact_names(structure),
                             point_legs=tuple(int(c[3]) - 1 for c in contact_names(structure)))


@dataclass(frozen=True)
class _Symbols:
    """What every section of :func:`derive_floating` reads: the coordinates, rates and
    parameters (by name ``P``), the foot's kind, the thigh length ``lt`` and arc radius
    ``R`` (0 when absent), the tags of leg1's and leg2's numbers and the hip's links."""

    structure: Structure
    names: tuple
    q: tuple
    dq: tuple
    par: tuple
    P: dict
    knee: bool
    arc: bool
    flat: bool
    lt: object
    R: object
    tags: tuple
    hip_links: tuple


def _symbols(structure: Structure) -> _Symbols:
    """The symbols of :func:`derive_floating` (:class:`_Symbols`)."""
    import sympy as sp

    names = coordinate_names(structure)
    q = sp.symbols(names, real=True)
    dq = sp.symbols([f"d_{n}" for n in names], real=True)
    pnames = param_names(structure)
    par = sp.symbols(pnames, real=True)
    P = dict(zip(pnames, par))
    knee, arc, flat = structure.knee, structure.foot == "arc", structure.foot == "flat"
    # the parameter vector is the rigid view's first step (leg1 swinging, paper Eq. 11): with
    # legs that differ, leg1's numbers are the swing role's (``sw``), leg2's the stance's
    tags = ("sw_", "st_") if structure.asymmetric else ("", "")
    hip_links = (q[2], q[4]) if knee else (q[2], q[3])  # leg1's and leg2's links at the hip
    return _Symbols(structure, names, q, dq, par, P, knee, arc, flat,
                    P["L_thigh"] if knee else 0, P["R_foot"] if arc else 0, tags, hip_links)


def _legs(s: _Symbols) -> tuple[list, list, dict]:
    """The legs' bodies ``(mass, {angle: length}, inertia, link angle or None)`` (the hip's
    point mass first), their contact points ``(position, Jacobian)`` and named points.

    Every point is ``hip + sum(length * e(angle))``, kept as ``{angle: length}`` (an angle
    is a coordinate, or a linear expression of them: an off-axis body's ``psi + pi/2``, the
    torso's eliminated angle) so that the mass matrix comes out in ``cos(a - b)`` form
    without a trigonometric simplifier."""
    import sympy as sp

    from walkerlab.codegen.frames import leg_unit as e  # light
    from walkerlab.codegen.frames import planar_slope_axes  # light

    structure, q, P, tags = s.structure, s.q, s.P, s.tags
    L, gamma, lt, R, knee = P["L"], P["gamma"], s.lt, s.R, s.knee
    n_vec, t_vec = planar_slope_axes(gamma)
    nq = len(q)
    hip = sp.Matrix([q[0], q[1]])
    bodies = []
    feet, points = [], {"hip": hip}
    if structure.hip_mass:
        bodies.append((P["M_hip"], {}, 0, None))
    arc, flat, names = s.arc, s.flat, s.names
    for i, leg in enumerate(LEGS):
        ks = (2 + 2 * i, 3 + 2 * i) if knee else (2 + i,)
        upper, lower = ks[0], ks[-1]
        for b in structure.bodies:
            d = P[f"d_{tags[i]}{b.name}"]
            lin = ({q[upper]: lt, q[lower]: d - lt} if b.link == "shank" else {q[upper]: d})
            link = q[lower] if b.link == "shank" else q[upper]
            if b.off_axis:  # ahead of the link's axis
                lin[link + sp.pi / 2] = P[f"e_{tags[i]}{b.name}"]
            inertia = P[f"I_{tags[i]}{b.name}"] if b.kind == "rod" else 0
            bodies.append((P[f"m_{tags[i]}{b.name}"], lin, inertia, link))
            points[f"{leg}_{b.name}"] = hip + sum((v * e(a) for a, v in lin.items()),
                                                 sp.zeros(2, 1))
        foot_lin = {upper: lt, lower: L - lt - R} if knee else {upper: L - R}
        centre = hip + sum((v * e(q[k]) for k, v in foot_lin.items()), sp.zeros(2, 1))
        Jc = centre.jacobian(sp.Matrix(q))
        if arc:
            sel = sp.Matrix([[1 if k == lower else 0 for k in range(nq)]])
            feet.append((centre - R * n_vec, Jc + R * t_vec * sel))
            # named as the rigid model's points: the arc's lowest point (contact) and the
            # end of the leg axis (foot)
            points[f"{leg}_foot_centre"] = centre
            points[f"{leg}_contact"] = centre - R * n_vec
            points[f"{leg}_foot"] = centre + R * e(q[lower])
        elif flat:
            # the foot link on a revolute ankle at the leg's end (the ankle on the sole
            # line): sole direction u = (cos psi_f, sin psi_f) = e(psi_f + pi/2), psi_f the
            # foot's absolute angle (= the leg's at the spring's rest with r = 0); heel and
            # toe are material points of the foot; the foot's mass sits at the ankle
            psi_f = q[names.index(f"{leg}_foot_angle")]
            u = e(psi_f + sp.pi / 2)
            for end, d in (("heel", -P[f"heel_{tags[i]}m"]), ("toe", P[f"toe_{tags[i]}m"])):
                pos = centre + d * u
                feet.append((pos, pos.jacobian(sp.Matrix(q))))
                points[f"{leg}_{end}"] = pos
            points[f"{leg}_foot"] = centre
            points[f"{leg}_ankle"] = centre
            bodies.append((P["m_foot"], {q[upper]: L}, P["I_foot"], psi_f))
        else:
            feet.append((centre, Jc))
            points[f"{leg}_foot"] = centre
        if knee:
            points[f"{leg}_knee"] = hip + lt * e(q[upper])
    return bodies, feet, points


def _torso(s: _Symbols, bodies: list, points: dict):
    """Append the torso's bodies and points; return the torso's angle (None without one).

    The upper body on the bisecting hip mechanism is eliminated as in the rigid view (its
    angle from the upward vertical is the mean of the leg angles; both legs are free here,
    the mechanism couples them); a hinged torso (five-link biped) has its own coordinate
    ``torso_angle``; a point ``d`` up its axis is at ``hip - d e(t)``."""
    import sympy as sp

    from walkerlab.codegen.frames import leg_unit as e  # light

    structure, q, P, hip_links = s.structure, s.q, s.P, s.hip_links
    hip = points["hip"]
    psi_t = (hip_links[0] + hip_links[1]) / 2 if structure.torso else None
    if structure.hinged_torso:
        psi_t = q[s.names.index("torso_angle")]
    for b in structure.torso:
        lin = {psi_t: -P[f"d_torso_{b.name}"]}
        if b.off_axis:
            lin[psi_t + sp.pi / 2] = P[f"e_torso_{b.name}"]
        inertia = P[f"I_torso_{b.name}"] if b.kind == "rigid_body" else 0
        bodies.append((P[f"m_torso_{b.name}"], lin, inertia, psi_t))
        points[f"torso_{b.name}"] = hip + sum((v * e(a) for a, v in lin.items()),
                                              sp.zeros(2, 1))
    return psi_t


def _mass_and_potential(s: _Symbols, bodies: list):
    """The mass matrix ``M`` (nq, nq) (``factor_terms`` applied) and the gravitational
    potential ``V`` of ``bodies`` (:func:`_legs`)."""
    import sympy as sp

    q, g = s.q, s.P["g"]
    nq = len(q)
    M = sp.zeros(nq, nq)
    V = sp.Integer(0)
    for mass, lin, inertia, link in bodies:
        M[0, 0] += mass
        M[1, 1] += mass
        # d position / d q_k = sum over angles a of length * da/dq_k * (cos a, sin a)
        terms = [[(a, lk * sp.diff(a, q[k])) for a, lk in lin.items() if sp.diff(a, q[k]) != 0]
                 for k in range(nq)]
        for k in range(2, nq):
            for a, ca in terms[k]:
                M[0, k] += mass * ca * sp.cos(a)
                M[1, k] += mass * ca * sp.sin(a)
            for j in range(2, nq):
                for a, ca in terms[k]:
                    for b_, cb in terms[j]:
                        M[k, j] += mass * ca * cb * sp.cos(a - b_)
        if link is not None and inertia != 0:
            w = sp.Matrix([[sp.diff(link, v) for v in q]])
            M += inertia * w.T * w
        y = q[1] - sum((lk * sp.cos(a) for a, lk in lin.items()), sp.Integer(0))
        V += mass * g * y
    for k in range(2, nq):
        M[k, 0], M[k, 1] = M[0, k], M[1, k]
    M = M.applyfunc(sp.factor_terms)
    return M, V


def _springs(s: _Symbols, V, psi_t):
    """Add the torsional spring-dampers to ``V``; return it and the damping matrix (the
    damper's ``-c J^T J dq`` joins the bias).

    Roles of the rigid view's first step (swing = leg1, stance = leg2; a kneed leg's spring
    acts on its thigh): ``V_s = k (delta - r)^2 / 2``; a knee spring on ``shank - thigh``;
    flat feet's ankle springs on ``delta = foot angle - leg angle`` (toe up > 0)."""
    import sympy as sp

    structure, q, P, names, tags = s.structure, s.q, s.P, s.names, s.tags
    hip_links, flat = s.hip_links, s.flat
    nq = len(q)
    angle = {"swing": hip_links[0], "stance": hip_links[1], "torso": psi_t}
    damping = sp.zeros(nq, nq)
    for i, (first, second) in enumerate(structure.springs):
        delta = angle[second] - angle[first]
        V += P[f"k_s{i}"] * (delta - P[f"r_s{i}"]) ** 2 / 2
        Jd = sp.Matrix([[sp.diff(delta, v) for v in q]])
        damping += P[f"c_s{i}"] * Jd.T * Jd
    if structure.knee_spring:  # a spring-damper at each knee on shank - thigh
        for leg in LEGS:
            knee_angle = q[names.index(f"{leg}_shank_angle")] - q[names.index(f"{leg}_thigh_angle")]
            V += P["k_knee"] * (knee_angle - P["r_knee"]) ** 2 / 2
            Jd = sp.Matrix([[sp.diff(knee_angle, v) for v in q]])
            damping += P["c_knee"] * Jd.T * Jd
    if flat:  # ankle spring-dampers, delta = foot angle - leg angle (toe up > 0)
        for i, leg in enumerate(LEGS):
            delta = q[names.index(f"{leg}_foot_angle")] - hip_links[i]
            V += P[f"k_{tags[i]}ankle"] * (delta - P[f"r_{tags[i]}ankle"]) ** 2 / 2
            Jd = sp.Matrix([[sp.diff(delta, v) for v in q]])
            damping += P[f"c_{tags[i]}ankle"] * Jd.T * Jd
    return V, damping
