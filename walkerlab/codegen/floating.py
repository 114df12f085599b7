"""The floating view of a walker: the same bodies, links and feet as the rigid hybrid model
(:mod:`walkerlab.codegen.symbolic`), with no foot pinned (what the compliant-contact model
integrates).  Derived symbolically (sympy) from the
:class:`~walkerlab.walker.description.Structure`, emitted as numba-compiled code, cached on
disk through :mod:`walkerlab.codegen.cache`.

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
:mod:`walkerlab.codegen.free_joints`); a bisecting torso is eliminated (its angle the mean of
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
``leg1_heel``, ``leg1_toe``, ``leg2_heel``, ``leg2_toe``); ``nf`` below is their number.

Generated numba functions (``x = [q, dq]``, ``p`` the parameter vector in
:func:`param_names` order, outputs written into preallocated arrays):

=====================================  ========================================================
``dyn(x, p, M, h)``                    ``M`` (nq, nq) [kg, kg m, kg m^2], ``h`` (nq,) [N, N m]
``dyn_jac(x, a, p, Dq, Dv)``           ``d(M a + h)/dq``, ``dh/d dq`` (nq, nq), ``a`` fixed
``feet(x, p, P, V, J)``                contact points ``P`` (nf, 2) [m], material velocities
                                       ``V`` (nf, 2) [m/s], Jacobians ``J`` (nf, 2, nq)
``feet_jac(x, F, p, dV, dJtF)``        ``dV = d V_i / dq`` (nf, 2, nq) and
                                       ``dJtF = d(sum_i J_i^T F_i)/dq`` (nq, nq), ``F`` (nf, 2)
``energies(X, p)``                     numpy: kinetic, potential [J] of states (2 nq, k)
``points(X, p)``                       numpy: named points (2, k) [m]
=====================================  ========================================================

Massless bodies (the simplest walker's legs) have no floating model: :func:`check_masses`
raises.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from walkerlab.walker.description import Structure, WalkerData, check_floating_view

__all__ = ["FLAT_FOOT_MESSAGE", "FOOT_PARAMS", "HUB_INERTIA_MESSAGE", "MASSLESS_MESSAGE",
           "WHEEL_COORDINATES", "FloatingEquations",
           "FloatingView", "check_masses", "contact_names", "coordinate_names",
           "derive_floating", "floating_module", "floating_params", "floating_view",
           "generated_state", "param_names"]

MASSLESS_MESSAGE = "a floating (contact) model needs positive leg masses"
LEGS = ("leg1", "leg2")
#: Floating-view parameters of a flat foot (not in the walker description, whose foot is
#: massless): its mass at the ankle [kg] and its inertia about the ankle [kg m^2].
FOOT_PARAMS = ("m_foot", "I_foot")
#: The floating view's coordinates of a spoked wheel (``model: rimless_wheel``): the hub's
#: position [m] and the absolute angle of spoke 0 [rad] (from the downward vertical,
#: positive when its tip is ahead of the hub).
WHEEL_COORDINATES = ("hip_x", "hip_y", "wheel_angle")
HUB_INERTIA_MESSAGE = ("contact.hub_inertia_kg_m2: a rimless wheel with a point-mass hub "
                       "(no walker.hub_inertia_kg_m2) needs a small regularising hub inertia "
                       "in the contact model (its angle has no dynamics once no spoke is "
                       "pinned)")
FLAT_FOOT_MESSAGE = ("contact.flat_foot_mass_kg and contact.flat_foot_inertia_kg_m2: a "
                     "flat-footed walker's contact model needs its feet's mass and inertia "
                     "(the rigid view's feet are massless)")


def coordinate_names(structure: Structure) -> tuple[str, ...]:
    """Names of the floating view's generalised coordinates (module docstring)."""
    if structure.spokes:  # a spoked wheel: the hub's position and spoke0's angle
        return WHEEL_COORDINATES
    if structure.knee:
        ang = tuple(f"{leg}_{ln}_angle" for leg in LEGS for ln in ("thigh", "shank"))
    else:
        ang = tuple(f"{leg}_angle" for leg in LEGS)
    if structure.foot == "flat":  # the feet's absolute angles after the legs'
        ang += tuple(f"{leg}_foot_angle" for leg in LEGS)
    if structure.hinged_torso:  # its own coordinate, last (a five-link biped)
        ang += ("torso_angle",)
    return ("hip_x", "hip_y") + ang


def param_names(structure: Structure) -> tuple[str, ...]:
    """Names of the floating view's parameter vector: ``structure.param_names``, then for
    flat feet the contact model's regularising foot mass ``m_foot`` [kg] and inertia about
    the ankle ``I_foot`` [kg m^2] (:data:`FOOT_PARAMS`; the rigid view's foot is
    massless)."""
    extra = FOOT_PARAMS if structure.foot == "flat" else ()
    return tuple(structure.param_names) + extra


def contact_names(structure: Structure) -> tuple[str, ...]:
    """Names of the contact points, in the order of the generated ``feet`` (one per leg,
    ``leg1``, ``leg2``, for point and arc feet; ``leg1_heel``, ``leg1_toe``,
    ``leg2_heel``, ``leg2_toe`` for flat feet; a spoked wheel's spoke tips ``spoke0``,
    ``spoke1``, ... in the order they touch down rolling downhill)."""
    if structure.spokes:
        return tuple(f"spoke{k}" for k in range(structure.spokes))
    if structure.foot == "flat":
        return tuple(f"{leg}_{end}" for leg in LEGS for end in ("heel", "toe"))
    return LEGS


def floating_params(data: WalkerData, foot_mass_kg: float | None = None,
                    foot_inertia_kg_m2: float | None = None,
                    hub_inertia_kg_m2: float | None = None) -> np.ndarray:
    """The floating view's parameter vector (:func:`param_names` order) of ``data``.

    ``hub_inertia_kg_m2`` [kg m^2]: a spoked wheel's regularising hub inertia
    (``contact.hub_inertia_kg_m2``), used only when the wheel's own ``I_hub`` is 0 (a
    point-mass hub, whose angle has no dynamics once no spoke is pinned); ignored otherwise.

    Raises
    ------
    ValueError
        A flat-footed walker without a foot mass and inertia (:data:`FLAT_FOOT_MESSAGE`); a
        point-mass hub without a regularising inertia (:data:`HUB_INERTIA_MESSAGE`).
    """
    p = [float(v) for v in data.params]
    if data.structure.spokes:
        i_hub = data.structure.param_names.index("I_hub")
        if p[i_hub] <= 0.0:
            if hub_inertia_kg_m2 is None:
                raise ValueError(HUB_INERTIA_MESSAGE)
            p[i_hub] = float(hub_inertia_kg_m2)
        return np.asarray(p, dtype=float)
    if data.structure.foot == "flat":
        if foot_mass_kg is None or foot_inertia_kg_m2 is None:
            raise ValueError(FLAT_FOOT_MESSAGE)
        p += [float(foot_mass_kg), float(foot_inertia_kg_m2)]
    return np.asarray(p, dtype=float)


def check_masses(structure: Structure) -> None:
    """Raise if a body has mass 0 (the massless limit has no floating model).

    Raises
    ------
    ValueError
        One line: :data:`MASSLESS_MESSAGE`.
    """
    light = [b.name for b in structure.bodies if b.massless]
    if light:
        raise ValueError(f"{MASSLESS_MESSAGE} (walker.leg.bodies: {', '.join(light)} has "
                         "mass_kg 0)")


@dataclass(frozen=True)
class FloatingEquations:
    """Symbolic floating view (all sympy; ``nq = len(q)``).

    Attributes
    ----------
    q, dq : tuple of Symbol (nq,)
    params : tuple of Symbol
        :func:`param_names` order.
    M : Matrix (nq, nq); h : Matrix (nq, 1)
    feet : tuple of (Matrix (2, 1), Matrix (2, nq))
        Per contact point (``contacts``): its position (an arc's lowest point) and the
        Jacobian of the material point there.
    kinetic, potential : Expr
    points : dict[str, Matrix (2, 1)]
        Named as the rigid model's: ``hip``, ``<leg>_<body>``, ``<leg>_foot`` (end of the
        leg axis), arc feet ``<leg>_foot_centre`` and ``<leg>_contact`` (lowest point),
        kneed ``<leg>_knee``, flat feet ``<leg>_ankle`` (= ``<leg>_foot``),
        ``<leg>_heel``, ``<leg>_toe``.
    knees : tuple of (int, int)
        Per leg with a knee stop, the indices in ``q`` of its thigh and shank angles (by
        their names); empty for straight legs and for free knees (``knee.lock: free``: no
        stop, as in the rigid view, :mod:`walkerlab.codegen.free_joints`).
    contacts : tuple of str
        Names of the contact points, in the order of ``feet`` (:func:`contact_names`).
    point_legs : tuple of int
        Leg (0 = leg1, 1 = leg2) of each contact point.
    """

    q: tuple
    dq: tuple
    params: tuple
    M: object
    h: object
    feet: tuple
    kinetic: object
    potential: object
    points: dict
    knees: tuple = ()
    contacts: tuple = LEGS
    point_legs: tuple = (0, 1)


@cache
def derive_floating(structure: Structure) -> FloatingEquations:
    """Derive the floating view of ``structure`` (memoised per process).

    Raises
    ------
    ValueError
        Massless bodies (:func:`check_masses`), a foot kind other than point / arc /
        flat, or free knees on feet other than points, legs that differ or with springs
        (:func:`walkerlab.walker.description.check_floating_view`).
    """
    import sympy as sp

    check_floating_view(structure)
    check_masses(structure)
    if structure.spokes:
        return _derive_spoked(structure)
    if structure.foot not in ("point", "arc", "flat"):
        raise ValueError(f"walker.leg.foot.kind: {structure.foot!r} is not supported")
    names = coordinate_names(structure)
    q = sp.symbols(names, real=True)
    dq = sp.symbols([f"d_{n}" for n in names], real=True)
    pnames = param_names(structure)
    par = sp.symbols(pnames, real=True)
    P = dict(zip(pnames, par))
    g, L, gamma = P["g"], P["L"], P["gamma"]
    knee, arc, flat = structure.knee, structure.foot == "arc", structure.foot == "flat"
    lt = P["L_thigh"] if knee else 0
    R = P["R_foot"] if arc else 0
    n_vec = sp.Matrix([sp.sin(gamma), sp.cos(gamma)])
    t_vec = sp.Matrix([sp.cos(gamma), -sp.sin(gamma)])
    nq = len(q)
    hip = sp.Matrix([q[0], q[1]])

    def e(psi):
        return sp.Matrix([sp.sin(psi), -sp.cos(psi)])

    # every point is hip + sum(length * e(angle)): kept as {angle: length} (an angle is a
    # coordinate, or a linear expression of them: an off-axis body's psi + pi/2, the torso's
    # eliminated angle) so that the mass matrix comes out in cos(a - b) form without a
    # trigonometric simplifier
    bodies = []  # (mass, {angle: length}, inertia, link angle or None)
    feet, points = [], {"hip": hip}
    if structure.hip_mass:
        bodies.append((P["M_hip"], {}, 0, None))
    # the parameter vector is the rigid view's first step (leg1 swinging, paper Eq. 11): with
    # legs that differ, leg1's numbers are the swing role's (``sw``), leg2's the stance's
    tags = ("sw_", "st_") if structure.asymmetric else ("", "")
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

    # the upper body on the bisecting hip mechanism: eliminated as in the rigid view (its
    # angle from the upward vertical is the mean of the leg angles; both legs are free here,
    # the mechanism couples them); a hinged torso (five-link biped): its own coordinate
    # ``torso_angle``; a point d up its axis at hip - d e(t)
    hip_links = (q[2], q[4]) if knee else (q[2], q[3])  # leg1's and leg2's links at the hip
    psi_t = (hip_links[0] + hip_links[1]) / 2 if structure.torso else None
    if structure.hinged_torso:
        psi_t = q[names.index("torso_angle")]
    for b in structure.torso:
        lin = {psi_t: -P[f"d_torso_{b.name}"]}
        if b.off_axis:
            lin[psi_t + sp.pi / 2] = P[f"e_torso_{b.name}"]
        inertia = P[f"I_torso_{b.name}"] if b.kind == "rigid_body" else 0
        bodies.append((P[f"m_torso_{b.name}"], lin, inertia, psi_t))
        points[f"torso_{b.name}"] = hip + sum((v * e(a) for a, v in lin.items()),
                                              sp.zeros(2, 1))

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
            w = sp.Matrix([[sp.diff(link, s) for s in q]])
            M += inertia * w.T * w
        y = q[1] - sum((lk * sp.cos(a) for a, lk in lin.items()), sp.Integer(0))
        V += mass * g * y
    for k in range(2, nq):
        M[k, 0], M[k, 1] = M[0, k], M[1, k]
    M = M.applyfunc(sp.factor_terms)
    dqv, qv = sp.Matrix(dq), sp.Matrix(q)
    T = sp.Rational(1, 2) * (dqv.T * M * dqv)[0]
    # torsional spring-dampers (roles of the rigid view's first step: swing = leg1, stance =
    # leg2; a kneed leg's spring acts on its thigh): V_s = k (delta - r)^2 / 2 joins V; the
    # damper's -c J^T J dq joins the bias
    angle = {"swing": hip_links[0], "stance": hip_links[1], "torso": psi_t}
    damping = sp.zeros(nq, nq)
    for i, (first, second) in enumerate(structure.springs):
        delta = angle[second] - angle[first]
        V += P[f"k_s{i}"] * (delta - P[f"r_s{i}"]) ** 2 / 2
        Jd = sp.Matrix([[sp.diff(delta, s) for s in q]])
        damping += P[f"c_s{i}"] * Jd.T * Jd
    if structure.knee_spring:  # a spring-damper at each knee on shank - thigh
        for leg in LEGS:
            knee_angle = q[names.index(f"{leg}_shank_angle")] - q[names.index(f"{leg}_thigh_angle")]
            V += P["k_knee"] * (knee_angle - P["r_knee"]) ** 2 / 2
            Jd = sp.Matrix([[sp.diff(knee_angle, s) for s in q]])
            damping += P["c_knee"] * Jd.T * Jd
    if flat:  # ankle spring-dampers, delta = foot angle - leg angle (toe up > 0)
        for i, leg in enumerate(LEGS):
            delta = q[names.index(f"{leg}_foot_angle")] - hip_links[i]
            V += P[f"k_{tags[i]}ankle"] * (delta - P[f"r_{tags[i]}ankle"]) ** 2 / 2
            Jd = sp.Matrix([[sp.diff(delta, s) for s in q]])
            damping += P[f"c_{tags[i]}ankle"] * Jd.T * Jd
    h = (M * dqv).jacobian(qv) * dqv - sp.Matrix([sp.diff(T, s) for s in q]) \
        + sp.Matrix([sp.diff(V, s) for s in q]) + damping * dqv
    h = h.applyfunc(sp.expand)
    return FloatingEquations(q=tuple(q), dq=tuple(dq), params=tuple(par), M=M, h=h,
                             feet=tuple(feet), kinetic=T, potential=V, points=points,
                             knees=tuple((names.index(f"{leg}_thigh_angle"),
                                          names.index(f"{leg}_shank_angle"))
                                         for leg in LEGS if knee and not structure.free_knees),
                             contacts=contact_names(structure),
                             point_legs=tuple(int(c[3]) - 1 for c in contact_names(structure)))


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
        tip = hub + L * sp.Matrix([sp.sin(psi), -sp.cos(psi)])
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


# ---------------------------------------------------------------------------- code generation
def _printer():
    from sympy.printing.pycode import PythonCodePrinter

    return PythonCodePrinter({"fully_qualified_modules": False, "standard": "python3"})


def _fn(name: str, args: str, eq: FloatingEquations, outputs, pr, jit: bool = True) -> list[str]:
    """A straight-line numba function assigning ``outputs`` [(target, expr)] after a cse."""
    import sympy as sp

    exprs = [e for _, e in outputs]
    repl, red = sp.cse(exprs, symbols=sp.numbered_symbols("_c"), order="none")
    nq = len(eq.q)
    lines = (["@njit(cache=True, error_model='numpy')"] if jit else []) + [f"def {name}({args}):"]
    lines.append(f"    {', '.join(str(s) for s in eq.params)}, = p")
    lines += [f"    {s} = x[{i}]" for i, s in enumerate(eq.q)]
    lines += [f"    {s} = x[{nq + i}]" for i, s in enumerate(eq.dq)]
    lines += [f"    {pr.doprint(a)} = {pr.doprint(b)}" for a, b in repl]
    lines += [f"    {t} = {pr.doprint(r)}" for (t, _), r in zip(outputs, red)]
    return lines + [""]


def _numpy_fn(name: str, eq: FloatingEquations, named: dict) -> list[str]:
    """A vectorised numpy function of states ``X`` (2 nq,) or (2 nq, k) returning a dict."""
    import sympy as sp
    from sympy.printing.numpy import NumPyPrinter

    pr = NumPyPrinter({"fully_qualified_modules": True})
    keys, flat, shapes = list(named), [], []
    for k in keys:
        v = named[k]
        if isinstance(v, sp.MatrixBase):
            shapes.append(v.shape[0])
            flat += list(v)
        else:
            shapes.append(None)
            flat.append(v)
    repl, red = sp.cse(flat, symbols=sp.numbered_symbols("_n"), order="none")
    nq = len(eq.q)
    lines = [f"def {name}(X, p):", f"    {', '.join(str(s) for s in eq.params)}, = p",
             "    X = np.asarray(X, dtype=float)"]
    lines += [f"    {s} = X[{i}]" for i, s in enumerate(eq.q)]
    lines += [f"    {s} = X[{nq + i}]" for i, s in enumerate(eq.dq)]
    lines.append(f"    _z = 0.0 * {eq.q[0]}")
    lines += [f"    {pr.doprint(a)} = {pr.doprint(b)}" for a, b in repl]
    out, pos = [], 0
    for k, shp in zip(keys, shapes):
        if shp is None:
            out.append(f"{k!r}: {pr.doprint(red[pos])} + _z")
            pos += 1
        else:
            vals = [f"{pr.doprint(r)} + _z" for r in red[pos:pos + shp]]
            pos += shp
            out.append(f"{k!r}: np.array(({', '.join(vals)},))")
    return lines + [f"    return {{{', '.join(out)}}}", ""]


def generate_floating(eq: FloatingEquations, key: str) -> str:
    """Source of the numba module of the floating view (module docstring's table)."""
    import sympy as sp

    pr = _printer()
    nq = len(eq.q)
    qv, dqv = sp.Matrix(eq.q), sp.Matrix(eq.dq)
    a = sp.Matrix(sp.symbols(f"a0:{nq}", real=True))
    body = []
    # M and h
    outs = [(f"M[{i}, {j}]", eq.M[i, j]) for i in range(nq) for j in range(nq)]
    outs += [(f"h[{i}]", eq.h[i]) for i in range(nq)]
    body += _fn("dyn", "x, p, M, h", eq, outs, pr)
    # d(M a + h)/dq, dh/d dq
    E = eq.M * a + eq.h
    Dq, Dv = E.jacobian(qv), eq.h.jacobian(dqv)
    outs = [(f"Dq[{i}, {j}]", Dq[i, j]) for i in range(nq) for j in range(nq)]
    outs += [(f"Dv[{i}, {j}]", Dv[i, j]) for i in range(nq) for j in range(nq)]
    lines = _fn("dyn_jac", "x, a, p, Dq, Dv", eq, outs, pr)
    lines.insert(2, f"    {', '.join(str(s) for s in a)}, = a[0], "
                 + ", ".join(f"a[{i}]" for i in range(1, nq)))
    body += lines
    # feet
    outs = []
    for i, (pos, J) in enumerate(eq.feet):
        v = J * dqv
        outs += [(f"P[{i}, {r}]", pos[r]) for r in range(2)]
        outs += [(f"V[{i}, {r}]", v[r]) for r in range(2)]
        outs += [(f"J[{i}, {r}, {k}]", J[r, k]) for r in range(2) for k in range(nq)]
    body += _fn("feet", "x, p, P, V, J", eq, outs, pr)
    nf = len(eq.feet)
    F = sp.Matrix(nf, 2, sp.symbols(f"F0:{2 * nf}", real=True))
    outs = []
    JtF = sp.zeros(nq, 1)
    for i, (_, J) in enumerate(eq.feet):
        dV = (J * dqv).jacobian(qv)
        outs += [(f"dV[{i}, {r}, {k}]", dV[r, k]) for r in range(2) for k in range(nq)]
        JtF += J.T * F[i, :].T
    dJ = JtF.jacobian(qv)
    outs += [(f"dJtF[{i}, {k}]", dJ[i, k]) for i in range(nq) for k in range(nq)]
    lines = _fn("feet_jac", "x, F, p, dV, dJtF", eq, outs, pr)
    lines.insert(2, f"    {', '.join(str(f) for f in F)} = "
                 + ", ".join(f"F[{i}, {r}]" for i in range(nf) for r in range(2)))
    body += lines
    body += _numpy_fn("_energies", eq, {"kinetic": eq.kinetic, "potential": eq.potential})
    body += ["def energies(X, p):", "    d = _energies(X, p)",
             "    return d['kinetic'], d['potential']", ""]
    body += _numpy_fn("points", eq, eq.points)
    head = [f"# walkerlab generated floating model code (walkerlab.codegen.floating); key {key}",
            "# Do not edit: regenerated when the walker description or the generator changes.",
            "from math import sin, cos, tan, sqrt  # noqa: F401",
            "import numpy  # noqa: F401", "import numpy as np", "from numba import njit", "",
            f"NQ = {nq}", f"COORDINATES = {tuple(str(s) for s in eq.q)!r}", ""]
    return "\n".join(head + body) + "\n"


# ---------------------------------------------------------------------------- cache


def _source_hash(paths) -> str:
    h = hashlib.sha256()
    for p in paths:
        h.update(Path(p).read_bytes())
    return h.hexdigest()


def module_key(structure: Structure, tag: str, sources=()) -> str:
    """Cache key: the rigid generator's key of ``structure`` (structure + generator + sympy),
    this file and ``sources`` (files whose text is part of the module), and ``tag``."""
    from walkerlab.codegen import cache

    h = hashlib.sha256(cache.cache_key(structure).encode())
    h.update(tag.encode())
    h.update(_source_hash([__file__, *sources]).encode())
    return h.hexdigest()[:24]


def load_generated(structure: Structure, tag: str, build, sources=()):
    """Import the generated module ``<key>_<tag>.py`` of the cache folder, writing it with
    ``build(key) -> str`` on a miss (or a damaged or untrusted file): one mechanism with the
    rigid compiled flows, :func:`walkerlab.codegen.cache.import_generated`."""
    from walkerlab.codegen import cache

    key, filename, module_name = _generated_names(structure, tag, sources)
    return cache.import_generated(filename, module_name, lambda: build(key))


def _generated_names(structure: Structure, tag: str, sources=()) -> tuple[str, str, str]:
    """The cache key, file name and module name of the generated module ``tag`` of
    ``structure`` (:func:`load_generated`)."""
    key = module_key(structure, tag, sources)
    return key, f"{key}_{tag}.py", f"walkerlab_{tag}_{key}"


def generated_state(structure: Structure, tag: str, sources=()) -> tuple[str, bool | None]:
    """The module name :func:`load_generated` gives the generated module ``tag`` of
    ``structure``, and whether its source is in the user cache already (False: not yet,
    so the first process to load it generates it and numba compiles its kernels; None: no
    user cache folder, nothing shared between processes), without generating or importing
    it."""
    from walkerlab.codegen import cache

    _key, filename, module_name = _generated_names(structure, tag, sources)
    folder = cache.cache_dir()
    return module_name, None if folder is None else (folder / filename).is_file()


def floating_source(structure: Structure, key: str) -> str:
    """Generated source of the floating view of ``structure`` (numba functions, no imports of
    other walkerlab packages)."""
    return generate_floating(derive_floating(structure), key)


def floating_module(structure: Structure):
    """The imported (compiled on first call, cached) floating module of ``structure``.

    Raises
    ------
    ValueError
        Massless bodies (:data:`MASSLESS_MESSAGE`).
    """
    check_masses(structure)
    return load_generated(structure, "floating", lambda key: floating_source(structure, key))


_plain: dict[str, dict] = {}


def floating_plain(structure: Structure) -> dict:
    """The floating module's functions of ``structure`` as the plain Python they are
    generated from (``njit`` the identity): the generated text
    (:func:`walkerlab.codegen.cache.generated_source`, as :func:`load_generated` reads and
    writes it), executed without
    numba, for a check of a few hundred states that should load no compiler (the rigid
    gait's ground reaction, :mod:`walkerlab.models.hybrid.ground_reaction`).  Memoised per
    process.

    Returns
    -------
    dict
        The module's namespace (``NQ``, ``COORDINATES``, ``dyn``, ``feet``, ``feet_jac``, ...).

    Raises
    ------
    ValueError
        Massless bodies (:data:`MASSLESS_MESSAGE`).
    """
    check_masses(structure)
    from walkerlab.codegen import cache

    key, filename, _ = _generated_names(structure, "floating")
    if key in _plain:
        return _plain[key]
    body, _ = cache.generated_source(filename, lambda: floating_source(structure, key))
    body = body.replace("from numba import njit\n", "", 1)

    def njit(*_args, **_kwargs):
        return lambda f: f

    ns = {"njit": njit, "__name__": f"walkerlab_floating_plain_{key}"}
    exec(compile(body, f"<walkerlab floating model {key}>", "exec"), ns)  # codegen's text
    _plain[key] = ns
    return ns


class FloatingView:
    """The floating view of one walker (structure + numbers).

    Parameters
    ----------
    data : WalkerData
    foot_mass_kg, foot_inertia_kg_m2 : float, optional
        A flat foot's mass [kg] (at the ankle) and inertia about the ankle [kg m^2]
        (required for flat feet, ignored otherwise).

    Raises
    ------
    ValueError
        Massless bodies; a flat foot without its mass and inertia.
    """

    def __init__(self, data: WalkerData, foot_mass_kg: float | None = None,
                 foot_inertia_kg_m2: float | None = None):
        check_masses(data.structure)
        self.data = data
        self.structure = data.structure
        self.params = floating_params(data, foot_mass_kg, foot_inertia_kg_m2)
        self._mod = floating_module(data.structure)
        self.nq = int(self._mod.NQ)

    def coordinate_names(self) -> tuple[str, ...]:
        """Generalised coordinates, in order (module docstring)."""
        return coordinate_names(self.structure)

    def _x(self, q, dq=None) -> np.ndarray:
        x = np.zeros(2 * self.nq)
        x[:self.nq] = np.asarray(q, dtype=float)
        if dq is not None:
            x[self.nq:] = np.asarray(dq, dtype=float)
        return x

    def mass_matrix(self, q) -> np.ndarray:
        """M(q) (nq, nq) [kg, kg m, kg m^2]."""
        M, h = np.empty((self.nq, self.nq)), np.empty(self.nq)
        self._mod.dyn(self._x(q), self.params, M, h)
        return M

    def bias(self, q, dq) -> np.ndarray:
        """h(q, dq) = C(q, dq) dq + G(q) (nq,) [N, N m]: ``M qdd + h = sum J^T F``."""
        M, h = np.empty((self.nq, self.nq)), np.empty(self.nq)
        self._mod.dyn(self._x(q, dq), self.params, M, h)
        return h

    def gravity(self, q) -> np.ndarray:
        """G(q) = h(q, 0) (nq,) [N, N m]."""
        return self.bias(q, np.zeros(self.nq))

    def contact_names(self) -> tuple[str, ...]:
        """Names of the contact points (:func:`contact_names`)."""
        return contact_names(self.structure)

    def contact_points(self, q, dq=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per contact point (:meth:`contact_names`): its position (nf, 2) [m], the velocity
        of the material point there (nf, 2) [m/s] and its Jacobian (nf, 2, nq)."""
        nf = len(self.contact_names())
        P, V, J = np.empty((nf, 2)), np.empty((nf, 2)), np.empty((nf, 2, self.nq))
        self._mod.feet(self._x(q, dq), self.params, P, V, J)
        return P, V, J

    def energies(self, X) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic and potential energy [J] of states ``X`` (2 nq,) or (2 nq, k)."""
        return self._mod.energies(X, self.params)

    def points(self, X) -> dict:
        """Named points (hip, each body, feet, arc feet's centres and contact points, knees)
        (2,) or (2, k) [m], named as the rigid model's."""
        return self._mod.points(X, self.params)


def floating_view(data: WalkerData, foot_mass_kg: float | None = None,
                  foot_inertia_kg_m2: float | None = None) -> FloatingView:
    """The floating view of a walker (see :class:`FloatingView`).

    Raises
    ------
    ValueError
        A body with mass 0: :data:`MASSLESS_MESSAGE`; flat feet without their mass and
        inertia: :data:`FLAT_FOOT_MESSAGE`.
    """
    return FloatingView(data, foot_mass_kg, foot_inertia_kg_m2)
