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
their heels and toes; a spoked wheel its spoke tips).

Walkers in 3D (straight legs, locking knees, the spoked wheel) have the same equations with
points of three components in world axes (``x`` downhill, ``y`` up, ``z`` lateral) and, per
contact point, the Jacobian of its body's spin about the slope's normal (``spins``, where
the contact's torsional friction acts); the generated contact module
(:mod:`walkerlab.models.contact.generated`) reads the dimension from the points.

One derivation for every walker (:func:`_flow`): its floating tree (planar:
:func:`walkerlab.walker.floating_tree.floating_planar_tree`, the pelvis or a wheel's hub on
the world's slides; 3D: the rigid tree set free at its stance contact by
:func:`walkerlab.walker.tree.free_root`), its kinematics
(:func:`walkerlab.codegen.tree_derive.kinematics`), the mass matrix and potential of
:func:`walkerlab.codegen.tree_derive.mass_and_potential` (a planar tree's mass matrix in the
closed form of sums of ``cos(q_i - q_j)``, :func:`walkerlab.codegen.tree_derive.
product_to_sum`; a 3D tree's unsimplified: common subexpressions are the generated code's)
and the bias ``h`` of :func:`walkerlab.codegen.lagrange.bias`; then the walker's contact
points and named points (:func:`_planar_feet`, :func:`_legs_3d`, :func:`_wheel_tips`).

Massless bodies (the simplest walker's legs) have no floating model: :func:`check_masses`
raises.
"""

from __future__ import annotations

import dataclasses
from functools import cache

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
from walkerlab.walker.tree import free_root
from walkerlab.walker.trees import legs_tree, spoked_wheel_3d_tree

#: the radius of the solid rod, as a fraction of the leg length, whose axial moment of
#: inertia each leg of a 3D walker of zero hip width carries in the contact view
#: (:func:`legs_axial_inertia`): ``m (0.01 L)^2 / 2`` for a leg of mass ``m``
AXIAL_RADIUS_L = 0.01


@cache
def derive_floating(structure: Structure, held_heading: bool = False) -> FloatingEquations:
    """Derive the floating view of ``structure`` (memoised per process; module docstring):
    its floating tree's flow (:func:`_flow`) with the walker's contact points, planar
    (:func:`_planar_legs`, :func:`_wheel_tips`) or in 3D (:func:`_legs_3d`, the wheel's
    :func:`_wheel_tips`); ``held_heading``: a legged walker in 3D on three slides, its
    heading held (``contact.hold_heading``, :func:`_legs_3d`).

    Raises
    ------
    ValueError
        Massless bodies (:func:`check_masses`), a foot kind other than point / arc /
        flat, or free knees on feet other than points, legs that differ or with springs
        (:func:`walkerlab.walker.multibody.check_floating_view`).
    """
    check_floating_view(structure)
    check_masses(structure)
    if structure.spokes:
        return _wheel_tips(structure)
    if structure.in_3d:
        return _legs_3d(structure, held_heading)
    if held_heading:
        raise ValueError("contact.hold_heading: a planar walker has no heading (its feet "
                         "turn in its plane only)")
    if structure.foot not in ("point", "arc", "flat"):
        raise ValueError(f"walker.leg.foot.kind: {structure.foot!r} is not supported")
    return _planar_legs(structure)


def _flow(structure: Structure, tree, coords, held_heading: bool = False):
    """The flow of a floating tree ``tree`` (its map ``coords``) in the floating view's
    coordinates (:func:`coordinate_names`): ``(kin, q, dq, rename, M, V, h)``, ``kin`` the
    tree's kinematics (:func:`walkerlab.codegen.tree_derive.kinematics`), ``rename`` its
    symbols to ``q``, ``dq``; a planar tree's mass matrix by
    :func:`walkerlab.codegen.tree_derive.product_to_sum`, its bias with the spring-dampers
    (:func:`_springs`) and expanded."""
    import sympy as sp

    from walkerlab.codegen.lagrange import bias  # light: sympy on first derivation only
    from walkerlab.codegen.tree_derive import (  # light
        kinematics,
        mass_and_potential,
        product_to_sum,
    )

    kin = kinematics(tree, coords)
    names = coordinate_names(structure, held_heading)
    q = sp.symbols(names, real=True)
    dq = sp.symbols([f"d_{n}" for n in names], real=True)
    rename = {**dict(zip(kin.q, q)), **dict(zip(kin.dq, dq))}
    M, _, _, V = mass_and_potential(kin)
    M, V = M.xreplace(rename), V.xreplace(rename)
    if structure.in_3d:
        return kin, q, dq, rename, M, V, bias(M, V, q, dq)
    M = M.applyfunc(product_to_sum)
    damping = sp.zeros(len(q), len(q))
    if not structure.spokes:   # the legs' spring-dampers
        Vs, damping = _springs(structure, q, dict(zip(tree.params, kin.params)))
        V = V + Vs
    return kin, q, dq, rename, M, V, (bias(M, V, q, dq) + damping * sp.Matrix(dq)).applyfunc(
        sp.expand)


def _equations(kin, q, dq, M, V, h, feet, points, **more) -> FloatingEquations:
    """The :class:`FloatingEquations` of a flow and its contact points (``more``: knees,
    contacts, point legs, stance forces, spins)."""
    import sympy as sp

    dqv = sp.Matrix(dq)
    return FloatingEquations(q=tuple(q), dq=tuple(dq), params=tuple(kin.params), M=M, h=h,
                             feet=tuple(feet), kinetic=sp.Rational(1, 2) * (dqv.T * M * dqv)[0],
                             potential=V, points=points, **more)


def _planar_legs(structure: Structure) -> FloatingEquations:
    """A planar legged walker's floating view: its floating tree
    (:func:`walkerlab.walker.floating_tree.floating_planar_tree`; every body and foot where
    the tree's kinematics puts it), the flow (:func:`_flow`) and the feet
    (:func:`_planar_feet`)."""
    tree, coords = floating_planar_tree(structure, param_names(structure))
    kin, q, dq, rename, M, V, h = _flow(structure, tree, coords)
    feet, points = _planar_feet(structure, kin, rename, q)
    names = list(coordinate_names(structure))
    knees = tuple((names.index(f"{leg}_thigh_angle"), names.index(f"{leg}_shank_angle"))
                  for leg in LEGS if structure.knee and not structure.free_knees)
    contacts = contact_names(structure)
    return _equations(kin, q, dq, M, V, h, feet, points, knees=knees, contacts=contacts,
                      point_legs=tuple(int(c[3]) - 1 for c in contacts))


def _planar_feet(structure: Structure, kin, rename: dict, q) -> tuple[list, dict]:
    """The contact points ``(position (2, 1), Jacobian (2, nq))`` of the feet and the named
    points, in world axes, of a planar floating tree's kinematics (module docstring: an
    arc's lowest point with its material point's Jacobian, a flat foot's heel and toe)."""
    import sympy as sp

    from walkerlab.codegen.frames import leg_unit, planar_slope_axes  # light

    qv = sp.Matrix(q)
    P = {str(p): p for p in kin.params}

    def at(v):   # the root is the world: world axes, the plane's two rows
        return v.xreplace(rename)[:2, :]

    n_vec, t_vec = planar_slope_axes(P["gamma"])
    R = P["R_foot"] if structure.foot == "arc" else 0
    names = [str(c) for c in q]
    feet, points = [], {"hip": sp.Matrix(q[:2])}
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


def _springs(structure: Structure, q, P: dict):
    """The torsional spring-dampers' potential ``sum k (delta - r)^2 / 2`` [J] (added to
    gravity's) and damping matrix (the damper's ``-c J^T J dq`` joins the bias).

    Roles of the rigid view's first step (swing = leg1, stance = leg2; a kneed leg's spring
    acts on its thigh, ``hips``); a knee spring on ``shank - thigh``; flat feet's ankle
    springs on ``delta = foot angle - leg angle`` (toe up > 0)."""
    from walkerlab.codegen.lagrange import spring_dampers  # light: sympy on first use

    names = [str(c) for c in q]
    hips = [q[names.index(f"{leg}_thigh_angle" if structure.knee else f"{leg}_angle")]
            for leg in LEGS]
    psi_t = None
    if structure.torso:
        psi_t = (q[names.index("torso_angle")] if structure.hinged_torso
                 else (hips[0] + hips[1]) / 2)
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


def _legs_3d(structure: Structure, held_heading: bool = False) -> FloatingEquations:
    """The floating view of a 3D legged walker from its body tree
    (:func:`walkerlab.walker.trees.legs_tree` with ``floating``, Kuo 1999), set free at
    leg2's foot (:func:`walkerlab.walker.tree.free_root`: slides along the world's ``x, y,
    z`` and a heading, :data:`FREE_3D`, then the tree's joints in its own coordinates
    renamed by :data:`ROLES_3D`; ``held_heading``: the slides only, the heading held as
    the rigid model's stance foot holds it, so the whole walker does not yaw and the stance
    foot turns about the ground's normal with its leg's lean and pitch, the rigid universal
    ankle's ``-beta' sin(phi)``).  The feet ``leg1`` (the rigid
    model's swing foot) and ``leg2`` (its stance foot, the root's contact); round feet's the
    discs' lowest points with their material points' Jacobians (:func:`_disc_contact`).
    The hip-roll law's torques act between bodies (no force on the free coordinates): the
    view leaves them out of the flow (they are ``stance_forces``).

    Locking knees (McGeer 1990): both legs carry their knee (the floating tree's stance
    knee), each link's pitch a coordinate (``leg<i>_thigh_angle``, ``leg<i>_shank_angle``
    in the leg's rolled sagittal plane, the knee's angle their difference), ``knees`` their
    indices (the contact model's knee stop and latch act there, as on the planar kneed
    walker's), the points ``leg<i>_knee``.
    """
    import sympy as sp

    from walkerlab.codegen.frames import slope_to_world  # light: sympy on first use
    from walkerlab.codegen.legged import stance_forces  # light: sympy on first use

    free = FREE_3D[:3] if held_heading else FREE_3D
    tree, coords = free_root(*legs_tree(structure, floating=True), free)
    kin, q, dq, rename, M, V, h = _flow(structure, tree, coords, held_heading)
    qv = sp.Matrix(q)
    to_world = slope_to_world(kin.gamma)
    # each leg's links by role: the foot's (the shank with a knee) and the thigh's
    knee = structure.knee
    feet_links = ("swing_shank", "stance_shank") if knee else ("swing_leg", "stance_leg")
    feet, points = [], {}
    if structure.rolling_feet:  # each foot's lowest point, its material point's Jacobian
        P = dict(zip(tree.params, kin.params))
        radius, lateral = P["R_foot"], P.get("R_lat", 0)
        for leg, link, centre in (("leg1", feet_links[0], kin.contacts["swing_foot_centre"]),
                                  ("leg2", feet_links[1], kin.origins[feet_links[1]])):
            low, J = _disc_contact(kin, link, centre, radius, lateral)
            pos = to_world * low.xreplace(rename)
            feet.append((pos, (to_world * J).xreplace(rename)))
            points[f"{leg}_contact"] = pos
            points[f"{leg}_foot_centre"] = to_world * centre.xreplace(rename)
    else:
        for leg, contact in (("leg1", "swing_foot"), ("leg2", "stance_foot")):
            pos = to_world * kin.contacts[contact].xreplace(rename)
            feet.append((pos, pos.jacobian(qv)))
            points[f"{leg}_foot"] = pos
    # each foot's spin about the slope's normal: its link's angular velocity there
    spins = tuple(_spin(kin, link, rename) for link in feet_links)
    points["hip"] = to_world * kin.coms["pelvis"].xreplace(rename)
    # each leg's own hip, w/2 from the pelvis' (the push-off's line: the rigid model's
    # stance_hip and swing_hip, walkerlab.codegen.derive_3d)
    points["leg1_hip"] = to_world * kin.origins["swing_leg"].xreplace(rename)
    points["leg2_hip"] = to_world * kin.origins["pelvis"].xreplace(rename)
    for b in structure.bodies:
        for leg, role in (("leg1", "swing"), ("leg2", "stance")):
            link = f"{role}_shank" if knee and b.link == "shank" else f"{role}_leg"
            points[f"{leg}_{b.name}"] = to_world * kin.coms[f"{link}_{b.name}"].xreplace(rename)
    for b in structure.torso:
        points[f"torso_{b.name}"] = to_world * kin.coms[f"torso_{b.name}"].xreplace(rename)
    knees = ()
    if knee:  # the knees at the shank's (swing) and the thigh's (stance) frame origin
        points["leg1_knee"] = to_world * kin.origins["swing_shank"].xreplace(rename)
        points["leg2_knee"] = to_world * kin.origins["stance_leg"].xreplace(rename)
        names = [str(c) for c in q]
        knees = tuple((names.index(f"{leg}_thigh_angle"), names.index(f"{leg}_shank_angle"))
                      for leg in LEGS)
    return _equations(kin, q, dq, M, V, h, feet, points, knees=knees, contacts=LEGS,
                      point_legs=(0, 1), spins=spins,
                      stance_forces=stance_forces(structure, q, dq, kin.params, ROLES_3D))


def _spin(kin, body: str, rename):
    """The Jacobian (1, nq) of ``body``'s angular velocity about the slope's normal (the
    slope frame's ``y``): ``omega = R_b omega_b``."""
    import sympy as sp

    return ((kin.rotations[body] * kin.omegas[body]).jacobian(sp.Matrix(kin.dq))[1, :]
            .xreplace(rename))


def _wheel_tips(structure: Structure) -> FloatingEquations:
    """The floating view of a spoked wheel (``model: rimless_wheel``; McGeer 1990; Coleman,
    Chatterjee & Ruina 1997): one body, the hub (mass ``M_hub`` at its centre; inertia
    ``I_hub`` about the axle, in 3D ``I_diam`` about any diameter) with ``n`` massless
    spokes of length ``L``.  Planar: its floating tree's (the hub on the world's slides,
    :func:`walkerlab.walker.floating_tree.floating_planar_tree`), ``q = [hip_x, hip_y,
    wheel_angle]`` (:data:`WHEEL_COORDINATES`); in 3D its rigid tree
    (:func:`walkerlab.walker.trees.spoked_wheel_3d_tree`: a spherical joint at spoke 0's tip,
    heading, lean, spin) set free there by three slides along the world's axes
    (:func:`walkerlab.walker.tree.free_root` with :data:`FREE_WHEEL_3D`: no heading of its
    own), ``q = [spoke0_foot_x, spoke0_foot_y, spoke0_foot_z, heading, lean, wheel_angle]``
    (:data:`WHEEL_3D_COORDINATES`), each tip with the wheel's spin about the slope's normal
    (``spins``).  Upright the sagittal rows are the planar wheel's.

    Spoke ``k``'s tip, the contact point ``spoke<k>`` (a material point of the wheel, its
    Jacobian the position's), is ``k`` spokes ahead of spoke 0, so rolling downhill the
    spokes touch down in the order 0, 1, 2, ...; the points ``hip`` (the hub) and
    ``spoke<k>_foot``.  The contact points alternate between the legs' lanes (spoke ``k`` on
    leg2's for even ``k``, leg1's for odd: spoke 0 is the first stance, the pinned point of
    a pinned start).

    Raises
    ------
    ValueError
        The tree's parameters are not the walker's, in order.
    """
    import sympy as sp

    from walkerlab.codegen.frames import slope_to_world  # light: sympy on first use

    if structure.in_3d:
        tree, coords = free_root(*spoked_wheel_3d_tree(structure.spokes), FREE_WHEEL_3D)
        tips, hub = wheel_tip_names(structure.spokes), "wheel"
    else:
        tree, coords = floating_planar_tree(structure, param_names(structure))
        tips, hub = tuple(f"spoke{k}_foot" for k in range(structure.spokes)), "pelvis"
    kin, q, dq, rename, M, V, h = _flow(structure, tree, coords)
    if tuple(str(p) for p in kin.params) != tuple(structure.param_names):
        raise ValueError("floating_equations: the wheel tree's parameters are not the "
                         "walker's, in order")  # floating_params' vector is the walker's
    d = 3 if structure.in_3d else 2
    to_world = slope_to_world(kin.gamma)[:d, :]
    qv = sp.Matrix(q)
    feet, points = [], {"hip": to_world * kin.coms[hub].xreplace(rename)}
    for k, tip in enumerate(tips):
        pos = to_world * kin.contacts[tip].xreplace(rename)
        feet.append((pos, pos.jacobian(qv)))
        points[f"spoke{k}_foot"] = pos
    contacts = contact_names(structure)
    spins = (_spin(kin, "wheel", rename),) * len(contacts) if structure.in_3d else ()
    return _equations(kin, q, dq, M, V, h, feet, points, contacts=contacts, spins=spins,
                      point_legs=tuple((k + 1) % 2 for k in range(len(contacts))))


def wheel_tip_names(spokes: int) -> tuple[str, ...]:
    """The contact points of :func:`walkerlab.walker.trees.spoked_wheel_3d_tree` that are
    spoke ``0, 1, ..., spokes - 1``'s tips (spoke ``k`` is ``k`` spokes ahead of spoke 0, the
    tree's stance spoke): ``stance_foot``, ``next_foot``, ``spoke2_foot``, ...,
    ``trailing_foot``."""
    inner = tuple(f"spoke{k}_foot" for k in range(2, spokes - 1))
    return ("stance_foot", "next_foot") + inner + ("trailing_foot",)


def legs_axial_inertia(structure: Structure, eq: FloatingEquations) -> FloatingEquations:
    """The floating view ``eq`` of a 3D legged walker of zero hip width with each leg's
    axial moment of inertia added, as the contact view integrates it: every leg link a solid
    rod of radius :data:`AXIAL_RADIUS_L` ``L`` about its own axis (its frame's ``y``),
    ``I_a = m r^2 / 2`` with ``m`` the mass welded to the link; any other walker's ``eq``
    as it is.

    Why: the rigid view's legs are slender (no inertia about their axes) and its stance foot
    does not twist, so it has no heading; the contact view's floating base turns about the
    slope's normal.  With zero hip width every mass lies on the legs' axes, and when the legs
    pass each other (equal pitches) they lie on one line: the walker has no inertia about it,
    the mass matrix is singular (its smallest eigenvalue goes as the square of the pitches'
    difference: 1e-6 at 4 mrad for configs/round_feet_3d.yaml) and the twist's friction
    drives a mode that no step size resolves: the integrator stalls at a leg crossing
    (measured on configs/paper_3d.yaml and configs/round_feet_3d.yaml).  The added inertia
    acts only through a leg's spin about its axis, which a walk upright in its sagittal
    plane (no heading, no roll: the rigid gait's) never excites, so that walk and its
    comparison with the rigid gait do not depend on it; it adds ``I_a sin^2(theta)``
    (under 1e-5 of the walker's) to the roll inertia about the stance foot.

    Parameters
    ----------
    structure : Structure
        The walker (:func:`derive_floating`'s).
    eq : FloatingEquations
        Its floating view (:func:`derive_floating`).

    Returns
    -------
    FloatingEquations
        ``M + sum_i I_a J_i^T J_i`` with ``J_i`` (1, nq) the Jacobian of leg link ``i``'s
        spin about its axis, the bias of that kinetic energy added to ``h``
        (:func:`walkerlab.codegen.lagrange.bias`) and to ``kinetic``.
    """
    import sympy as sp

    from walkerlab.codegen.lagrange import bias  # light: sympy on first use
    from walkerlab.codegen.tree_derive import kinematics  # light: sympy on first use

    if not structure.in_3d or structure.spokes:
        return eq
    rigid, coords = legs_tree(structure, floating=True)
    swing_hip = next(b.joint for b in rigid.bodies if b.name == "swing_leg")
    if any(c != 0 for c in swing_hip.origin_m):  # the hips apart (a hip width): no line
        return eq
    tree, fcoords = free_root(rigid, coords, FREE_3D)
    kin = kinematics(tree, fcoords)
    rename = {**dict(zip(kin.q, eq.q)), **dict(zip(kin.dq, eq.dq))}
    par = {str(p): p for p in kin.params}
    links = ("swing_leg", "stance_leg") + (("swing_shank", "stance_shank")
                                            if structure.knee else ())
    dM = sp.zeros(len(eq.q), len(eq.q))
    for link in links:
        mass = sum((sp.sympify(b.mass_kg, locals=par) for b in tree.bodies
                    if b.joint.parent == link and b.joint.kind == "fixed"), sp.Integer(0))
        if mass == 0:
            continue
        J = kin.omegas[link][1, :].jacobian(sp.Matrix(kin.dq)).xreplace(rename)
        axial = mass * (sp.Float(AXIAL_RADIUS_L) * par["L"]) ** 2 / 2
        dM += axial * (J.T * J)
    dqv = sp.Matrix(eq.dq)
    return dataclasses.replace(eq, M=eq.M + dM, h=eq.h + bias(dM, 0, eq.q, eq.dq),
                               kinetic=eq.kinetic + sp.Rational(1, 2) * (dqv.T * dM * dqv)[0])


def _disc_contact(kin, body: str, centre, radius, lateral=0):
    """A round foot's contact on the slope: the lowest point of the disc of ``radius``
    about ``centre`` (3, 1) in the plane normal to ``body``'s ``z`` axis (its leg's
    sagittal plane; McGeer 1990), ``centre - R u / |u|`` with ``u = n - (n . a) a`` the
    slope's normal ``n`` without its part along the disc's axis ``a``, and the Jacobian
    (3, nq) of the disc's material point there, ``v = v_centre + omega x (low - centre)``
    (``omega`` the body's angular velocity: a disc that rolls without slip has that point
    at rest).  A foot curved both ways (``lateral`` the tube's radius ``R_l``, the torus'
    major radius ``R - R_l``; Coleman & Ruina 1998, :mod:`walkerlab.codegen.rolling_feet`):
    the tube's centre circle's lowest point, ``R_l`` lower, ``centre - (R - R_l) u / |u| -
    R_l n``.  Slope frame, the tree's own coordinates (``kin``:
    :class:`walkerlab.codegen.tree_derive.TreeKinematics`)."""
    import sympy as sp

    R_b = kin.rotations[body]
    a = R_b * sp.Matrix([0, 0, 1])
    n = sp.Matrix([0, 1, 0])
    u = n - a[1] * a
    low = centre - (radius - lateral) * u / sp.sqrt(1 - a[1] ** 2) - lateral * n
    r = low - centre
    skew = sp.Matrix([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    omega = R_b * kin.omegas[body].jacobian(sp.Matrix(kin.dq))
    return low, centre.jacobian(sp.Matrix(kin.q)) - skew * omega
