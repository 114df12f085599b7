"""The floating view's coordinates, parameters, contact points and symbolic equations,
derived (sympy) from the :class:`~walkerlab.walker.description.Structure`; the generated
code, its cache and the numeric view are in :mod:`walkerlab.codegen.floating`.


Conventions (shared with the rigid view and the contact model)
--------------------------------------------------------------
World axes x downhill, y up, gravity ``(0, -g)``; ground line ``y = -x tan(phi)`` with outward
normal ``n = (sin phi, cos phi)`` and down-slope tangent ``t = (cos phi, -sin phi)``.
Generalised coordinates ``q = [hip_x, hip_y, angles of leg1's links, angles of leg2's links]``
[m, m, rad...]: a straight leg has one link (``leg{i}_angle``), a kneed leg a thigh then a
shank (``leg{i}_thigh_angle``, ``leg{i}_shank_angle``); each angle is absolute, from the
vertical, positive when the foot is ahead of the hip.  A torso hinged at the hip (the
five-link biped of Westervelt, Grizzle & Koditschek 2003: free knees, ``torso.coupling:
hinged``) adds its own coordinate ``torso_angle`` last (from the upward vertical, positive
leaning back, as the rigid view's); its free knees have no stop (as in the rigid view,
:mod:`walkerlab.codegen.legged`); a bisecting torso is eliminated (its angle the mean of
the legs').  A point at distance ``d`` along a link
at angle ``psi`` from the link's proximal joint is at ``joint + d (sin psi, -cos psi)``.

Equations
---------
``M(q) qdd + h(q, dq) = sum_i J_i(q)^T F_i + Q_stop`` with ``T = sum 1/2 m |v|^2 + 1/2 I w^2``,
``V = sum m g y``, ``M`` the Hessian of ``T`` in ``dq`` and the bias
``h = d(M dq)/dq dq - dT/dq + dV/dq`` (= ``C(q, dq) dq + G(q)``).  For every foot the contact
point is

- point foot: the foot point;
- arc foot (radius ``R``, centre on the shank axis at ``L - R`` from the hip): the arc's
  lowest point ``centre - R n`` (where the penetration is measured).  The force acts on the
  *material* point of the arc there, whose velocity is ``v_centre + w x (-R n) = v_centre +
  R w t`` (``w`` the shank's rate), so its Jacobian is ``J_centre + R t e_shank^T`` and rolling
  emerges from friction.
- flat foot (Wisse et al. 2006, "Ankle springs instead of arc-shaped feet"): a foot link
  per leg on a revolute ankle at the leg's end, with its own absolute angle
  ``leg{i}_foot_angle`` (coordinates after the legs'; equal to the leg's angle when the
  ankle is at rest with rest angle 0, sole direction ``u = (cos psi_f, sin psi_f)``, so a
  foot flat on the slope has ``psi_f = -phi``), and two contact points, the heel at
  ``ankle - heel u`` and the toe at ``ankle + toe u`` (material points of the foot).  The
  ankle's spring-damper acts on ``delta = psi_f - psi_leg`` (toe up > 0): ``V_a = k (delta -
  r)^2 / 2`` and the damper's ``-c J_d^T J_d dq``.  The walker description's foot is massless;
  this view regularises it with a mass ``m_foot`` at the ankle and an inertia ``I_foot``
  about the ankle (:data:`FOOT_PARAMS`, set by the contact section,
  ``contact.flat_foot_mass_kg``, ``contact.flat_foot_inertia_kg_m2``), appended to the
  parameter vector (:func:`param_names`).

The contact points are named by :func:`contact_names` (``leg1``, ``leg2``; flat feet
their heels and toes; a spoked wheel its spoke tips).  Walkers in 3D (straight legs, the
spoked wheel) derive from their body trees: :mod:`walkerlab.codegen.floating_3d`.

Massless bodies (the simplest walker's legs) have no floating model: :func:`check_masses`
raises.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from walkerlab.codegen.floating_3d import derive_legs_3d, derive_wheel_3d
from walkerlab.codegen.floating_names import (  # noqa: F401 (re-exported)
    FOOT_PARAMS,
    FREE_3D,
    FREE_WHEEL_3D,
    LEGS,
    MASSLESS_MESSAGE,
    ROLES_3D,
    WHEEL_3D_COORDINATES,
    WHEEL_COORDINATES,
    FloatingEquations,
    check_masses,
    contact_names,
    coordinate_names,
    param_names,
)
from walkerlab.walker.description import Structure
from walkerlab.walker.multibody import check_floating_view


@cache
def derive_floating(structure: Structure) -> FloatingEquations:
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
    if structure.in_3d:  # from the body trees (walkerlab.codegen.floating_3d)
        return derive_wheel_3d(structure) if structure.spokes else derive_legs_3d(structure)
    if structure.spokes:
        return _derive_spoked(structure)
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


def _derive_spoked(structure: Structure) -> FloatingEquations:
    """The floating view of a spoked wheel (``model: rimless_wheel``; McGeer 1990, Coleman,
    Chatterjee & Ruina 1997): one rigid body, the hub (mass ``M_hub`` at its centre, inertia
    ``I_hub`` about it) with ``n`` massless spokes of length ``L``; ``q = [hip_x, hip_y,
    wheel_angle]`` (:data:`WHEEL_COORDINATES`).  Spoke ``k``'s tip, the contact point
    ``spoke<k>``, is at ``hub + L e(theta + 2 pi k / n)``: spoke 1 is the next ahead of
    spoke 0 (the rigid view's swing spoke when spoke 0 is in stance), so rolling downhill
    the spokes touch down in the order 0, 1, 2, ...  ``T = M |v|^2 / 2 + I w^2 / 2``,
    ``V = M g y``; the mass matrix is ``diag(M, M, I)``.  The contact points alternate
    between the legs' lanes (spoke ``k`` on leg2's for even ``k``, leg1's for odd: spoke 0
    is the first stance, the pinned point of a pinned start)."""
    import sympy as sp

    from walkerlab.codegen.frames import leg_unit as e  # light

    names = coordinate_names(structure)
    q = sp.symbols(names, real=True)
    dq = sp.symbols([f"d_{n}" for n in names], real=True)
    par = sp.symbols(param_names(structure), real=True)
    P = dict(zip(param_names(structure), par))
    g, L, m, inertia, alpha = P["g"], P["L"], P["M_hub"], P["I_hub"], P["alpha"]
    hub = sp.Matrix([q[0], q[1]])
    feet, points = [], {"hip": hub}
    for k in range(structure.spokes):
        psi = q[2] + 2 * k * alpha
        tip = hub + L * e(psi)
        feet.append((tip, tip.jacobian(sp.Matrix(q))))
        points[f"spoke{k}_foot"] = tip
    M = sp.diag(m, m, inertia)
    dqv = sp.Matrix(dq)
    T = sp.Rational(1, 2) * (dqv.T * M * dqv)[0]
    V = m * g * q[1]
    h = sp.Matrix([0, m * g, 0])
    contacts = contact_names(structure)
    return FloatingEquations(q=tuple(q), dq=tuple(dq), params=tuple(par), M=M, h=h,
                             feet=tuple(feet), kinetic=T, potential=V, points=points,
                             knees=(), contacts=contacts,
                             point_legs=tuple((k + 1) % 2 for k in range(len(contacts))))
