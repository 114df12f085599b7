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
from walkerlab.walker.floating_tree import floating_planar_tree
from walkerlab.walker.multibody import check_floating_view


@cache
def derive_floating(structure: Structure) -> FloatingEquations:
    """Derive the floating view of ``structure`` (memoised per process): a planar legged
    walker's from its floating tree (:func:`walkerlab.walker.floating_tree.
    floating_planar_tree`; every body and foot where the tree's kinematics puts it, read as
    a sum of link vectors, :func:`_link_sums`), the mass matrix and potential of its bodies
    (:func:`_mass_and_potential`), its feet (:func:`_feet`), the spring-dampers
    (:func:`_springs`), then the bias ``h`` (module docstring); a 3D walker's and a spoked
    wheel's from theirs.

    Raises
    ------
    ValueError
        Massless bodies (:func:`check_masses`), a foot kind other than point / arc /
        flat, or free knees on feet other than points, legs that differ or with springs
        (:func:`walkerlab.walker.multibody.check_floating_view`).
    """
    import sympy as sp

    from walkerlab.codegen.lagrange import bias  # light: sympy on first derivation only
    from walkerlab.codegen.tree_derive import kinematics  # light

    check_floating_view(structure)
    check_masses(structure)
    if structure.in_3d:  # from the body trees (walkerlab.codegen.floating_3d)
        return derive_wheel_3d(structure) if structure.spokes else derive_legs_3d(structure)
    if structure.spokes:
        return _derive_spoked(structure)
    if structure.foot not in ("point", "arc", "flat"):
        raise ValueError(f"walker.leg.foot.kind: {structure.foot!r} is not supported")
    tree, coords = floating_planar_tree(structure, param_names(structure))
    kin = kinematics(tree, coords)   # the root is the world: world axes
    q = sp.symbols(coords.names, real=True)
    dq = sp.symbols([f"d_{n}" for n in coords.names], real=True)
    rename = {**dict(zip(kin.q, q)), **dict(zip(kin.dq, dq))}
    P = dict(zip(tree.params, kin.params))
    hip = sp.Matrix(q[:2])
    bodies = [(kin.masses[b], _link_sums(kin.coms[b].xreplace(rename), hip),
               kin.inertias[b][2, 2], kin.omegas[b][2].xreplace(rename))
              for b in kin.coms if kin.masses[b] != 0]
    M, V = _mass_and_potential(q, dq, P["g"], bodies)
    dqv = sp.Matrix(dq)
    T = sp.Rational(1, 2) * (dqv.T * M * dqv)[0]
    names = list(coords.names)
    hips = [q[names.index(f"{leg}_thigh_angle" if structure.knee else f"{leg}_angle")]
            for leg in LEGS]
    psi_t = None
    if structure.torso:
        psi_t = (q[names.index("torso_angle")] if structure.hinged_torso
                 else (hips[0] + hips[1]) / 2)
    Vs, damping = _springs(structure, q, P, hips, psi_t)
    V = V + Vs
    h = (bias(M, V, q, dq) + damping * dqv).applyfunc(sp.expand)
    feet, points = _feet(structure, kin, rename, q, P)
    return FloatingEquations(q=tuple(q), dq=tuple(dq), params=tuple(kin.params), M=M, h=h,
                             feet=tuple(feet), kinetic=T, potential=V, points=points,
                             knees=tuple((names.index(f"{leg}_thigh_angle"),
                                          names.index(f"{leg}_shank_angle"))
                                         for leg in LEGS
                                         if structure.knee and not structure.free_knees),
                             contacts=contact_names(structure),
                             point_legs=tuple(int(c[3]) - 1 for c in contact_names(structure)))


def _link_sums(point, hip) -> dict:
    """A planar point of the floating tree (3, 1; world axes) as ``hip + sum(length *
    e(angle))`` (``e(a) = (sin a, -cos a)``, :func:`walkerlab.codegen.frames.leg_unit`):
    ``{angle: length}``, each angle a link's absolute angle (a linear expression of the
    coordinates: the bisecting torso's mean; ``+ pi/2`` for a length ahead of the link's
    axis), so that velocities and the mass matrix come out in ``cos(a - b)`` form without a
    trigonometric simplifier.

    Raises
    ------
    ValueError
        The point is not such a sum (its height does not match its run).
    """
    import sympy as sp


    lin: dict = {}
    for term in sp.Add.make_args(sp.expand(point[0] - hip[0])):
        if term == 0:   # the hip itself
            continue
        (trig,) = [f for f in sp.Mul.make_args(term) if isinstance(f, sp.sin | sp.cos)]
        angle = trig.args[0]
        key = angle if isinstance(trig, sp.sin) else angle + sp.pi / 2
        lin[key] = lin.get(key, 0) + term / trig
    if sp.expand(_at(lin, hip)[1] - point[1]) != 0:
        raise ValueError("floating tree: a point is not a sum of link vectors from the hip")
    return lin


def _at(lin: dict, hip):
    """``hip + sum(length * e(angle))`` of a ``{angle: length}`` sum (:func:`_link_sums`)."""
    import sympy as sp

    from walkerlab.codegen.frames import leg_unit  # light

    return hip + sum((v * leg_unit(a) for a, v in lin.items()), sp.zeros(2, 1))


def _mass_and_potential(q, dq, g, bodies: list):
    """The mass matrix ``M`` (nq, nq) (``factor_terms`` applied) and the gravitational
    potential ``V`` of ``bodies`` ``(mass, {angle: length}, inertia about z, spin)`` (the
    spin ``omega_z``, linear in ``dq``): ``T = sum m |v|^2 / 2 + I omega_z^2 / 2``, each
    velocity ``(dhip_x, dhip_y) + sum length a' (cos a, sin a)``."""
    import sympy as sp

    nq = len(q)
    M = sp.zeros(nq, nq)
    V = sp.Integer(0)
    for mass, lin, inertia, spin in bodies:
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
        if inertia != 0:
            w = sp.Matrix([[sp.diff(spin, v) for v in dq]])
            M += inertia * w.T * w
        y = q[1] - sum((lk * sp.cos(a) for a, lk in lin.items()), sp.Integer(0))
        V += mass * g * y
    for k in range(2, nq):
        M[k, 0], M[k, 1] = M[0, k], M[1, k]
    return M.applyfunc(sp.factor_terms), V


def _feet(structure: Structure, kin, rename: dict, q, P: dict) -> tuple[list, dict]:
    """The contact points ``(position (2, 1), Jacobian (2, nq))`` of the feet and the named
    points, in world axes, of a planar floating tree's kinematics (module docstring: an
    arc's lowest point with its material point's Jacobian, a flat foot's heel and toe)."""
    import sympy as sp

    from walkerlab.codegen.frames import leg_unit, planar_slope_axes  # light

    qv = sp.Matrix(q)
    hip = sp.Matrix(q[:2])

    def at(v):
        return _at(_link_sums(v.xreplace(rename), hip), hip)

    n_vec, t_vec = planar_slope_axes(P["gamma"])
    R = P["R_foot"] if structure.foot == "arc" else 0
    names = [str(c) for c in q]
    feet, points = [], {"hip": hip}
    for leg in LEGS:
        lower = q[names.index(f"{leg}_shank_angle" if structure.knee else f"{leg}_angle")]
        upper = f"{leg}_thigh" if structure.knee else leg
        for b in structure.bodies:
            link = f"{leg}_shank" if structure.knee and b.link == "shank" else upper
            points[f"{leg}_{b.name}"] = at(kin.coms[f"{link}_{b.name}"])
        end = at(kin.contacts[f"{leg}_foot"])   # a round foot's centre, a flat foot's ankle
        if structure.foot == "arc":
            sel = sp.Matrix([[1 if k == lower else 0 for k in q]])
            feet.append((end - R * n_vec, end.jacobian(qv) + R * t_vec * sel))
            # named as the rigid model's points: the arc's lowest point (contact) and the
            # end of the leg axis (foot)
            points[f"{leg}_foot_centre"] = end
            points[f"{leg}_contact"] = end - R * n_vec
            points[f"{leg}_foot"] = end + R * leg_unit(lower)
        elif structure.foot == "flat":
            for tip in ("heel", "toe"):
                pos = at(kin.contacts[f"{leg}_{tip}"])
                feet.append((pos, pos.jacobian(qv)))
                points[f"{leg}_{tip}"] = pos
            points[f"{leg}_foot"] = points[f"{leg}_ankle"] = end
        else:
            feet.append((end, end.jacobian(qv)))
            points[f"{leg}_foot"] = end
        if structure.knee:
            points[f"{leg}_knee"] = at(kin.contacts[f"{leg}_knee"])
    for b in structure.torso:
        points[f"torso_{b.name}"] = at(kin.coms[f"torso_{b.name}"])
    return feet, points


def _springs(structure: Structure, q, P: dict, hips: list, psi_t):
    """The torsional spring-dampers' potential ``sum k (delta - r)^2 / 2`` [J] (added to
    gravity's) and damping matrix (the damper's ``-c J^T J dq`` joins the bias).

    Roles of the rigid view's first step (swing = leg1, stance = leg2; a kneed leg's spring
    acts on its thigh, ``hips``); a knee spring on ``shank - thigh``; flat feet's ankle
    springs on ``delta = foot angle - leg angle`` (toe up > 0)."""
    from walkerlab.codegen.lagrange import spring_dampers  # light: sympy on first use

    names = [str(c) for c in q]
    tags = ("sw_", "st_") if structure.asymmetric else ("", "")
    angle = {"swing": hips[0], "stance": hips[1], "torso": psi_t}
    joints = [(angle[second] - angle[first], f"s{i}")
              for i, (first, second) in enumerate(structure.springs)]
    if structure.knee_spring:  # a spring-damper at each knee on shank - thigh
        joints += [(q[names.index(f"{leg}_shank_angle")] - q[names.index(f"{leg}_thigh_angle")],
                    "knee") for leg in LEGS]
    if structure.foot == "flat":  # ankle spring-dampers, delta = foot - leg angle (toe up > 0)
        joints += [(q[names.index(f"{leg}_foot_angle")] - hips[i], f"{tags[i]}ankle")
                   for i, leg in enumerate(LEGS)]
    return spring_dampers(joints, P, q)


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
