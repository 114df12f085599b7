"""The floating views of walkers in three dimensions, derived (sympy) from their body trees
(:mod:`walkerlab.walker.trees`) set free on the ground by
:func:`walkerlab.walker.tree.free_root`: the straight-legged walker (Kuo 1999;
:func:`derive_legs_3d`) and the spoked wheel (Coleman, Chatterjee & Ruina 1997;
:func:`derive_wheel_3d`).  Their
:class:`~walkerlab.codegen.floating_equations.FloatingEquations` are a planar walker's with
points of three components in world axes (``x`` downhill, ``y`` up, ``z`` lateral) and, per
contact point, the Jacobian of its body's spin about the slope's normal (``spins``, where
the contact's torsional friction acts); the generated contact module
(:mod:`walkerlab.models.contact.generated`) reads the dimension from the points.

Both share one derivation (:func:`_free_flow`): the tree with its free joints ahead of its
own, its kinematics (:func:`walkerlab.codegen.tree_derive.kinematics`), the mass matrix and
potential of :func:`walkerlab.codegen.tree_derive.mass_and_potential` and the bias
``h = d(M dq)/dq dq - dT/dq + dV/dq`` of :func:`walkerlab.codegen.lagrange.bias`,
unsimplified (common subexpressions are the generated code's).
"""

from __future__ import annotations

from walkerlab.codegen.floating_names import (
    FREE_3D,
    FREE_WHEEL_3D,
    LEGS,
    ROLES_3D,
    FloatingEquations,
    contact_names,
    coordinate_names,
)
from walkerlab.walker.description import Structure
from walkerlab.walker.tree import free_root
from walkerlab.walker.trees import legs_tree, spoked_wheel_3d_tree

__all__ = ["AXIAL_RADIUS_L", "derive_legs_3d", "derive_wheel_3d", "legs_axial_inertia",
           "wheel_tip_names"]

#: the radius of the solid rod, as a fraction of the leg length, whose axial moment of
#: inertia each leg of a 3D walker of zero hip width carries in the contact view
#: (:func:`legs_axial_inertia`): ``m (0.01 L)^2 / 2`` for a leg of mass ``m``
AXIAL_RADIUS_L = 0.01


def _free_flow(structure: Structure, rigid, coords, free: tuple):
    """The floating tree of ``rigid`` (its map ``coords``) with the free joints ``free``
    (:func:`walkerlab.walker.tree.free_root`), its kinematics and the flow in the floating
    view's coordinates (:func:`walkerlab.codegen.floating_equations.coordinate_names`):
    ``(tree, kin, q, dq, rename, M, V, h)``, ``rename`` the kinematics' symbols to ``q``,
    ``dq``."""
    import sympy as sp

    from walkerlab.codegen.lagrange import bias  # light: sympy on first use
    from walkerlab.codegen.tree_derive import kinematics, mass_and_potential  # light

    tree, fcoords = free_root(rigid, coords, free)
    kin = kinematics(tree, fcoords)
    names = coordinate_names(structure)
    q = sp.symbols(names, real=True)
    dq = sp.symbols([f"d_{n}" for n in names], real=True)
    rename = {**dict(zip(kin.q, q)), **dict(zip(kin.dq, dq))}
    M, _, _, V = mass_and_potential(kin)
    M, V = M.xreplace(rename), V.xreplace(rename)
    return tree, kin, q, dq, rename, M, V, bias(M, V, q, dq)


def _spin(kin, body: str, rename):
    """The Jacobian (1, nq) of ``body``'s angular velocity about the slope's normal (the
    slope frame's ``y``): ``omega = R_b omega_b``."""
    import sympy as sp

    return ((kin.rotations[body] * kin.omegas[body]).jacobian(sp.Matrix(kin.dq))[1, :]
            .xreplace(rename))


def derive_legs_3d(structure: Structure) -> FloatingEquations:
    """The floating view of a 3D legged walker from its body tree
    (:func:`walkerlab.walker.trees.legs_tree` with ``floating``, Kuo 1999), set free at
    leg2's foot (:func:`walkerlab.walker.tree.free_root`: slides along the world's ``x, y,
    z`` and a heading, :data:`~walkerlab.codegen.floating_equations.FREE_3D`, then the
    tree's joints in its own coordinates renamed by
    :data:`~walkerlab.codegen.floating_equations.ROLES_3D`).  The feet ``leg1`` (the rigid
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

    from walkerlab.codegen.derive_3d import stance_forces  # light: sympy on first use
    from walkerlab.codegen.frames import slope_to_world  # light: sympy on first use

    rigid, coords = legs_tree(structure, floating=True)
    tree, kin, q, dq, rename, M, V, h = _free_flow(structure, rigid, coords, FREE_3D)
    qv, dqv = sp.Matrix(q), sp.Matrix(dq)
    to_world = slope_to_world(kin.gamma)
    # each leg's links by role: the foot's (the shank with a knee) and the thigh's
    knee = structure.knee
    feet_links = ("swing_shank", "stance_shank") if knee else ("swing_leg", "stance_leg")
    feet, points = [], {}
    if structure.foot == "arc":  # each disc's lowest point, its material point's Jacobian
        radius = dict(zip(tree.params, kin.params))["R_foot"]
        for leg, link, centre in (("leg1", feet_links[0], kin.contacts["swing_foot_centre"]),
                                  ("leg2", feet_links[1], kin.origins[feet_links[1]])):
            low, J = _disc_contact(kin, link, centre, radius)
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
    return FloatingEquations(q=tuple(q), dq=tuple(dq),
                             params=tuple(kin.params), M=M, h=h, feet=tuple(feet),
                             kinetic=sp.Rational(1, 2) * (dqv.T * M * dqv)[0], potential=V,
                             points=points, knees=knees, contacts=LEGS, point_legs=(0, 1),
                             stance_forces=stance_forces(structure, q, dq, kin.params,
                                                         ROLES_3D),
                             spins=spins)


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
        The walker (:func:`derive_legs_3d`'s).
    eq : FloatingEquations
        Its floating view (:func:`derive_legs_3d`).

    Returns
    -------
    FloatingEquations
        ``M + sum_i I_a J_i^T J_i`` with ``J_i`` (1, nq) the Jacobian of leg link ``i``'s
        spin about its axis, the bias of that kinetic energy added to ``h``
        (:func:`walkerlab.codegen.lagrange.bias`) and to ``kinetic``.
    """
    import dataclasses

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


def wheel_tip_names(spokes: int) -> tuple[str, ...]:
    """The contact points of :func:`walkerlab.walker.trees.spoked_wheel_3d_tree` that are
    spoke ``0, 1, ..., spokes - 1``'s tips (spoke ``k`` is ``k`` spokes ahead of spoke 0, the
    tree's stance spoke): ``stance_foot``, ``next_foot``, ``spoke2_foot``, ...,
    ``trailing_foot``."""
    inner = tuple(f"spoke{k}_foot" for k in range(2, spokes - 1))
    return ("stance_foot", "next_foot") + inner + ("trailing_foot",)


def derive_wheel_3d(structure: Structure) -> FloatingEquations:
    """The floating view of a spoked wheel in 3D from its body tree
    (:func:`walkerlab.walker.trees.spoked_wheel_3d_tree`; Coleman, Chatterjee & Ruina 1997):
    one body, the hub (mass ``M_hub`` at its centre, inertia ``diag(I_diam, I_diam, I_hub)``
    in the wheel's frame, ``z`` its axle) with ``n`` massless spokes of length ``L``, on a
    spherical joint at spoke 0's tip (heading, lean, spin); set free there by three slides
    along the world's axes (:func:`walkerlab.walker.tree.free_root` with
    :data:`~walkerlab.codegen.floating_equations.FREE_WHEEL_3D`: no heading of its own, the
    tree's joint turns about the slope's normal already).  ``q = [spoke0_foot_x,
    spoke0_foot_y, spoke0_foot_z, heading, lean, wheel_angle]``
    (:data:`~walkerlab.codegen.floating_equations.WHEEL_3D_COORDINATES`), the wheel's angle
    spoke 0's from the downward vertical in its plane (the rigid tree's ``stance``).

    Every spoke tip is a contact point, ``spoke<k>`` (:func:`contact_names`: spoke ``k``
    ``k`` spokes ahead of spoke 0, so rolling downhill they touch down in the order 0, 1,
    2, ..., as the planar wheel's, :func:`walkerlab.codegen.floating_equations.
    _derive_spoked`), each a material point of the wheel (its Jacobian the position's),
    each with the wheel's spin about the slope's normal (``spins``); the points ``hip`` (the
    hub) and ``spoke<k>_foot``.  Upright (heading and lean 0) the sagittal rows are the
    planar wheel's.  The contact points alternate between the legs' lanes as the planar
    wheel's (spoke ``k`` on leg2's for even ``k``).
    """
    import sympy as sp

    from walkerlab.codegen.frames import slope_to_world  # light: sympy on first use

    rigid, coords = spoked_wheel_3d_tree(structure.spokes)
    _, kin, q, dq, rename, M, V, h = _free_flow(structure, rigid, coords, FREE_WHEEL_3D)
    if tuple(str(p) for p in kin.params) != tuple(structure.param_names):
        raise ValueError("floating_3d.derive_wheel_3d: the wheel tree's parameters are not "
                         "the walker's, in order")  # floating_params' vector is the walker's
    qv, dqv = sp.Matrix(q), sp.Matrix(dq)
    to_world = slope_to_world(kin.gamma)
    feet, points = [], {"hip": to_world * kin.coms["wheel"].xreplace(rename)}
    for k, tip in enumerate(wheel_tip_names(structure.spokes)):
        pos = to_world * kin.contacts[tip].xreplace(rename)
        feet.append((pos, pos.jacobian(qv)))
        points[f"spoke{k}_foot"] = pos
    contacts = contact_names(structure)
    return FloatingEquations(q=tuple(q), dq=tuple(dq), params=tuple(kin.params), M=M, h=h,
                             feet=tuple(feet),
                             kinetic=sp.Rational(1, 2) * (dqv.T * M * dqv)[0], potential=V,
                             points=points, contacts=contacts,
                             point_legs=tuple((k + 1) % 2 for k in range(len(contacts))),
                             spins=(_spin(kin, "wheel", rename),) * len(contacts))


def _disc_contact(kin, body: str, centre, radius):
    """A round foot's contact on the slope: the lowest point of the disc of ``radius``
    about ``centre`` (3, 1) in the plane normal to ``body``'s ``z`` axis (its leg's
    sagittal plane; McGeer 1990), ``centre - R u / |u|`` with ``u = n - (n . a) a`` the
    slope's normal ``n`` without its part along the disc's axis ``a``, and the Jacobian
    (3, nq) of the disc's material point there, ``v = v_centre + omega x (low - centre)``
    (``omega`` the body's angular velocity: a disc that rolls without slip has that point
    at rest).  Slope frame, the tree's own coordinates (``kin``:
    :class:`walkerlab.codegen.tree_derive.TreeKinematics`)."""
    import sympy as sp

    R_b = kin.rotations[body]
    a = R_b * sp.Matrix([0, 0, 1])
    u = sp.Matrix([0, 1, 0]) - a[1] * a
    low = centre - radius * u / sp.sqrt(1 - a[1] ** 2)
    r = low - centre
    skew = sp.Matrix([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    omega = R_b * kin.omegas[body].jacobian(sp.Matrix(kin.dq))
    return low, centre.jacobian(sp.Matrix(kin.q)) - skew * omega
