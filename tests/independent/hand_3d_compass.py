"""The 3D straight-legged walker (Kuo 1999, "Stabilization of lateral motion in passive
dynamic walking", IJRR 18(9)) derived by hand from its point masses, as walkerlab derived it
before the body tree (kept as an independent reference for the tree's derivation,
``walkerlab.codegen.derive_3d.derive_compass``; not walkerlab code: its own rotations, its
own Christoffel symbols; only the hip-roll law, a controller's torques, is the generator's).

Frames: world ``x`` downhill, ``y`` up; the slope's frame has the fall line ``s``, the
normal ``n`` and ``z``.  Coordinates ``lean`` (the pelvis' roll about the fall line), then
the legs' pitches ``swing``, ``stance`` from the vertical; with hip-roll joints
``pelvis_roll`` and ``swing_roll``.  Positions are sums of point masses' (and the rods'
rotational energy ``I (|omega|^2 - (omega . u)^2) / 2``); round feet roll as discs in their
legs' rolled sagittal planes.  The impact is Hurmuzlu & Marghitu (1994)'s in extended
coordinates, written out.
"""

from __future__ import annotations

from types import SimpleNamespace

import sympy as sp

# the hip-roll law is the walker's controller, not the mechanics this checks: the scene's own
from walkerlab.codegen.legged import hip_roll_forces as _hip_roll_forces


def rotation(axis, angle):
    """Rodrigues' rotation (3, 3) about the unit ``axis``."""
    k = sp.Matrix(axis)
    K = sp.Matrix([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return sp.eye(3) + sp.sin(angle) * K + (1 - sp.cos(angle)) * K * K


def slope_up(gamma):
    return sp.Matrix([-sp.sin(gamma), sp.cos(gamma), 0])


def slope_to_world(gamma):
    return sp.Matrix([[sp.cos(gamma), sp.sin(gamma), 0],
                      [-sp.sin(gamma), sp.cos(gamma), 0], [0, 0, 1]])


def _dot(a, b):
    return (a.T * b)[0]


def christoffel(M, q, dq):
    """``C`` with ``C dq`` the Coriolis and centrifugal terms (Christoffel symbols of the
    first kind)."""
    n = len(q)
    C = sp.zeros(n, n)
    for k in range(n):
        for j in range(n):
            C[k, j] = sp.Rational(1, 2) * sum(
                (sp.diff(M[k, j], q[i]) + sp.diff(M[k, i], q[j]) - sp.diff(M[i, j], q[k]))
                * dq[i] for i in range(n))
    return C


def _point_mass_matrix(masses, q, p_foot=False):
    """Mass matrix (n, n) of point masses ``[(m, r(q) (3, 1))]`` and, with ``p_foot``, the
    coupling ``A = sum m J^T`` (n, 3) and the total mass of the extended system whose stance
    foot is free (``[q, foot position]``)."""
    n = len(q)
    qv = sp.Matrix(q)
    M = sp.zeros(n, n)
    A = sp.zeros(n, 3)
    total = 0
    for m, r in masses:
        J = sp.Matrix(r).jacobian(qv)
        M += m * J.T * J
        A += m * J.T
        total += m
    return M, A, total


def _leg_rotation_mass(q, phi, th_st, phi_w, th_sw, gamma, inertia) -> sp.Matrix:
    """Mass matrix (n, n) of the legs' inertia normal to their axes: a leg (frame
    ``Rot(s, lean) Rot(z, theta + gamma)`` in the slope's frame, axis ``u``) turning at
    ``omega = s lean' + Rot(s, lean) z theta'`` has ``T = I (|omega|^2 - (omega . u)^2) / 2``
    (a slender rod's inertia ``I`` about its mass point [kg m^2], none about its axis)."""
    ez, es = sp.Matrix([0, 0, 1]), sp.Matrix([1, 0, 0])
    qv = sp.Matrix(q)
    out = sp.zeros(len(q), len(q))
    for lean, theta in ((phi, th_st), (phi_w, th_sw)):
        roll = rotation(es, lean)
        u = roll * rotation(ez, theta + gamma) * sp.Matrix([0, 1, 0])
        W = es * sp.Matrix([lean]).jacobian(qv) + roll * ez * sp.Matrix([theta]).jacobian(qv)
        out += inertia * (W.T * W - W.T * u * u.T * W)
    return out


def derive_compass(structure) -> SimpleNamespace:
    """The hand derivation of the 3D straight-legged walker (module docstring)."""
    if not structure.in_3d or structure.spokes:
        raise ValueError("derive_3d.derive_compass: the structure is not a 3D straight-legged "
                         "walker")
    phi, th_sw, th_st = sp.symbols("q_lean q_swing q_stance", real=True)
    dphi, dth_sw, dth_st = sp.symbols("dq_lean dq_swing dq_stance", real=True)
    q, dq = (phi, th_sw, th_st), (dphi, dth_sw, dth_st)
    phi_p = phi_w = phi                                # the legs rigid to the pelvis in roll
    if structure.hip_roll:
        phi_p, phi_w = sp.symbols("q_pelvis_roll q_swing_roll", real=True)
        dphi_p, dphi_w = sp.symbols("dq_pelvis_roll dq_swing_roll", real=True)
        q, dq = q + (phi_p, phi_w), dq + (dphi_p, dphi_w)
    par = sp.symbols(structure.param_names, real=True)
    P = dict(zip(structure.param_names, par))
    g, L, gamma, M_hip, m, a = (P[k] for k in ("g", "L", "gamma", "M_hip", "m_leg", "a_leg"))
    w = P.get("w_hip", 0)
    # vectors in the slope's frame (fall line s, normal n, z): there the roll is about the
    # first axis and a leg's pitch about the third, from the normal by theta + gamma
    ez = sp.Matrix([0, 0, 1])

    def roll_of(angle):
        return rotation(sp.Matrix([1, 0, 0]), angle)
    axis = roll_of(phi_p) * ez                         # the hip axis

    def leg(theta, length, lean=phi):  # from the hip to a point at ``length`` down the leg
        return roll_of(lean) * (rotation(ez, theta + gamma) * sp.Matrix([0, -length, 0]))

    arc = structure.foot == "arc"
    R = P["R_foot"] if arc else 0
    e_s, e_n = sp.Matrix([1, 0, 0]), sp.Matrix([0, 1, 0])
    # the stance disc's centre from the step's reference point: its contact point rolled
    # -R (theta_st + gamma) down the fall line, the centre R along the rolled normal above it
    offset = (-R * (th_st + gamma) * e_s + R * roll_of(phi) * e_n) if arc else sp.zeros(3, 1)
    hip_st = offset - leg(th_st, L - R)
    hip_sw = hip_st + w * axis
    pelvis = hip_st + w / 2 * axis
    m_st = hip_st + leg(th_st, L - a)                  # a from the foot's lowest point
    m_sw = hip_sw + leg(th_sw, L - a, phi_w)
    centre_sw = hip_sw + leg(th_sw, L - R, phi_w)      # the point foot, or the disc's centre
    swing_contact = centre_sw - R * roll_of(phi_w) * e_n
    # the next step's reference point (where its contact is with its leg normal to the slope)
    swing_foot = swing_contact + R * (th_sw + gamma) * e_s
    masses = [(M_hip, pelvis), (m, m_st), (m, m_sw)]
    M, A, total = _point_mass_matrix(masses, q)
    if structure.hip_roll:  # the pelvis' own inertia about the fall line (it rolls by phi_p)
        M[3, 3] += P["I_pelvis"]
    if structure.bodies[0].kind == "rod":  # each leg's inertia normal to its axis
        M += _leg_rotation_mass(q, phi, th_st, phi_w, th_sw, gamma, P["I_leg"])
    M = M.applyfunc(lambda e: sp.trigsimp(sp.expand(e)))
    C = christoffel(M, q, dq)
    # height above the horizontal of a point r (slope frame): -sin(gamma) r_s + cos(gamma) r_n
    up = slope_up(gamma)
    potential = sum(mi * g * _dot(r, up) for mi, r in masses)
    G = sp.Matrix([sp.expand(sp.diff(potential, qi)) for qi in q])
    if structure.hip_roll:
        G = G - _hip_roll_forces(q, dq, P)
    kinetic = sp.Rational(1, 2) * (sp.Matrix(dq).T * M * sp.Matrix(dq))[0]
    # impact about the new foot (extended coordinates, the old stance foot free)
    # the rates that keep the swing foot's material contact point at rest: a point foot's,
    # or the disc's lowest point's velocity plus R theta_sw' s (the material point's, v_c +
    # omega x (-R n_w) = d(contact)/dt + R theta_sw' s: the lean pivots the disc about it)
    F = swing_contact.jacobian(sp.Matrix(q))
    if arc:
        F += R * e_s * sp.Matrix([[sp.diff(th_sw, k) for k in q]])
    Mi = (M - A * F - F.T * A.T + total * F.T * F).applyfunc(
        lambda e: sp.trigsimp(sp.expand(e)))
    B = (M - F.T * A.T).applyfunc(lambda e: sp.trigsimp(sp.expand(e)))
    to_world = slope_to_world(gamma)                   # columns s, n, z
    height = swing_contact[1]
    relabel_q = sp.Matrix([phi, th_st, th_sw])        # lean kept, the legs' roles swap
    if structure.hip_roll:  # the swing leg's roll is the new lean, the old stance leg's
        relabel_q = sp.Matrix([phi_w, th_st, th_sw, phi_p, phi])   # the new swing roll
    relabel_rate = relabel_q.jacobian(sp.Matrix(q))
    sigma = th_sw + th_st + 2 * gamma
    if structure.hip_width:
        heel = height
        # just after heel strike the swing foot (the old stance foot) is on the slope behind
        drop_solution = -gamma - sp.acos(sp.cos(th_st + gamma) - w * sp.tan(phi) / (L - R))
        if structure.hip_roll:
            drop_solution = -gamma - sp.acos((L * sp.cos(phi) * sp.cos(th_st + gamma)
                                              - w * sp.sin(phi_p)) / (L * sp.cos(phi_w)))
    else:
        heel = sigma
        drop_solution = -th_st - 2 * gamma
    points = {k: to_world * v for k, v in (
        ("hip", pelvis), ("stance_hip", hip_st), ("swing_hip", hip_sw),
        ("stance_foot", sp.zeros(3, 1)), ("swing_foot", swing_foot), ("stance_mass", m_st),
        ("swing_mass", m_sw))}
    if arc:
        points.update({k: to_world * v for k, v in (
            ("stance_contact", offset - R * roll_of(phi) * e_n), ("stance_foot_centre", offset),
            ("swing_contact", swing_contact), ("swing_foot_centre", centre_sw))})
    len(q)
    return SimpleNamespace(
        q=q, dq=dq, params=tuple(par), M=M, C=C, G=G, Mi=Mi, B=B,
        relabel_q=relabel_q, relabel_rate=relabel_rate, kinetic=kinetic, potential=potential,
        guards={"heel_strike": heel, "swing_foot_ahead": th_sw - th_st,
                "hip_height": pelvis[1], "swing_clearance": height},
        points=points, leg_angles={"stance": th_st, "swing": th_sw, "lean": phi,
                                   # each leg's roll by leg (the lean is the stance leg's)
                                   **({"pelvis_roll": phi_p, "stance_roll": phi,
                                       "swing_roll": phi_w} if structure.hip_roll else {})},
        section_drop=1, drop_solution=drop_solution,
    )
