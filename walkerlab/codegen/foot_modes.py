"""Flat feet on ankle springs: the rigid hybrid view's modes, derived with sympy from the
walker's body tree (:func:`walkerlab.walker.trees.legs_tree` with its soles: the stance heel
the root, each leg on its ankle; :func:`walkerlab.codegen.tree_derive.kinematics` in world
axes, as every other legged walker's equations come from its tree in
:mod:`walkerlab.codegen.legged`), printed as every walker's: Python source
(:func:`walkerlab.codegen.source.generate_flat`, the same ``make(p)`` module form) and its
compiled twin (:func:`walkerlab.codegen.compiled_source.generate_flat_compiled`).

Coordinates ``q = (swing, stance, stance_ankle)``: the absolute leg angles (from the
vertical, positive foot ahead of the hip) and the stance ankle's angle ``a``: the sole's
angle from the stance leg's perpendicular, positive toe up (the ankle spring's deflection
plus its rest angle).  The sole angle from the horizontal is ``theta_f = stance + a``; on a
slope ``gamma`` the foot lies flat when ``phi = stance + a + gamma = 0``.  Feet are massless
(Wisse et al. 2006, "Ankle springs instead of arc-shaped feet for passive dynamic walkers",
IEEE-RAS Humanoids) or, with ``structure.foot_mass``, each a body of mass ``m_foot`` at its
ankle and inertia ``I_foot`` about it; the ankle lies on the sole line, ``heel`` behind and
``toe`` ahead of it.  The swing foot carries no load and sits at its spring's rest angle
``r_sw`` (no coordinate; with mass it turns with its leg, the limit of its stiff, overdamped
ankle: its spring-damper's time constant ``c / k`` is 25 ms on configs/flat_feet.yaml, its
inertial torque ``I_foot`` times the leg's angular acceleration ~5e-3 N m).

A *mode* is a pinned contact point plus locked coordinates; each is derived from the tree's
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
  (``Mi = sum_i J_i+^T m_i J_i+`` plus rotational terms; feet with mass among the bodies,
  the trailing sole's angular momentum projected on its leg's turn), then the leg roles
  swap; the trailing foot is released (it snaps to its rest angle) unless the double
  support keeps its toe down (below).

Double support (after heel strike, roles swapped;
:func:`derive_double_support`): the leading foot
on its heel (or flat), the trailing foot on its toe, pinned (no slip); its ankle angle ``b``
follows from the toe on the slope, the flow is Lagrange's equations on ``(q, b)`` with the
toe's constraint and its force as multipliers (a numeric KKT solve in the generated code);
the entry impact pins the toe (an impulse through the trailing ankle: the massless foot takes
no impulsive moment), the second stage of the two-contact plastic impact.

Ground reaction (for the heel-off and lift-off guards): the total force from Newton,
``F = sum m_i (a_i - g)`` over the bodies (feet with mass among them), normal part ``N = F . n``;
in foot flat the toe's share from the moment balance about the heel,
``N_toe (heel + toe) = sum (r_i x m_i (a_i - g)) + I_i alpha_i`` (friction along the slope
has no moment about the heel), and the heel's ``N - N_toe``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import sympy as sp

from walkerlab.codegen.frames import planar_slope_axes
from walkerlab.codegen.lagrange import christoffel
from walkerlab.codegen.legged import link_springs
from walkerlab.codegen.tree_derive import kinematics, product_to_sum
from walkerlab.walker.description import ROLE_TAG, Structure
from walkerlab.walker.tree import CoordinateMap
from walkerlab.walker.trees import legs_tree

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
    """What :func:`~walkerlab.codegen.printers.flow_lines` and
    :func:`~walkerlab.codegen.printers.reset_lines` read (duck-typed Equations)."""

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
    heel_off_phi_rad: float = HEEL_OFF_PHI_RAD


def _foot_name(structure: Structure, kind: str, role: str) -> str:
    """A foot's parameter name by kind (``heel``, ``toe``, ``k``, ``r``, ``c``) and role (per
    role when the legs differ)."""
    t = f"{ROLE_TAG[role]}_" if structure.asymmetric else ""
    return {"heel": f"heel_{t}m", "toe": f"toe_{t}m", "k": f"k_{t}ankle", "r": f"r_{t}ankle",
            "c": f"c_{t}ankle"}[kind]


def _held(coords: CoordinateMap, rest: str) -> CoordinateMap:
    """The rigid view's coordinates of a flat-footed tree: the swing foot held at its
    spring's rest angle ``rest`` (a parameter's name) from its leg, no coordinate of its own
    (module docstring)."""
    return CoordinateMap(tuple(n for n in coords.names if n != "swing_ankle"),
                         tuple((c, rest if c == "swing_ankle_pitch" else e)
                               for c, e in coords.joint_angles))


def _other_role(name: str) -> str:
    """A body's name with the legs' roles swapped (``stance_sole`` -> ``swing_sole``)."""
    return name.replace("stance", "\0").replace("swing", "stance").replace("\0", "swing")


@cache
def derive_flat(structure: Structure) -> FlatEquations:
    """Derive the modes, resets, guards, ground reactions and points of a flat-footed biped
    from its body tree (:func:`walkerlab.walker.trees.legs_tree`, the stance heel its root;
    Lagrange's equations by :func:`walkerlab.codegen.tree_derive.derive_tree`): the pinned
    modes (:func:`_pinned_modes`), foot flat and the resets (:func:`_locked_and_resets`),
    the push-off systems (:func:`_push_off_systems`) and the double support
    (:func:`walkerlab.codegen.foot_modes.derive_double_support`).

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
    tree, coords = legs_tree(structure)
    rest = {role: _foot_name(structure, "r", role) for role in ("swing", "stance")}
    kin = kinematics(tree, _held(coords, rest["swing"]), world=True)
    q, dq = kin.q, kin.dq
    qdd = sp.symbols("ddq_swing ddq_stance ddq_stance_ankle", real=True)
    P = dict(zip(tree.params, kin.params))
    def fp(kind: str, role: str):
        return P[_foot_name(structure, kind, role)]
    gamma = P["gamma"]
    ps_sw, ps_st, a = q
    hs, ts = fp("heel", "stance"), fp("toe", "stance")
    normal, tangent = planar_slope_axes(gamma)
    flows, kin_pins, ground, guards, lead_force, trailing_ankle, pre = _pinned_modes(
        structure, kin, P, fp, qdd)
    guards["swing_foot_ahead"] = ps_sw - ps_st
    guards["foot_angle"] = ps_st + a + gamma
    Jl = sp.Matrix([[0, 1, 1]])
    post = kin   # the tree after the heel strike: the same, unless the legs differ
    if structure.asymmetric:
        swapped, swapped_coords = legs_tree(structure, swap_roles=True)
        post = kinematics(swapped, _held(swapped_coords, rest["stance"]), world=True)
    resets, trans = _locked_and_resets(kin, post, pre, flows, Jl, fp("r", "swing"))
    push_off = _push_off_systems(q, kin_pins, pre, flows, resets, trans)
    leg_angles = {"swing_angle": ps_sw, "stance_angle": ps_st, "stance_ankle_angle": a,
                  "swing_ankle_angle": fp("r", "swing") + 0 * ps_sw,
                  "swing_rate": dq[0], "stance_rate": dq[1], "stance_ankle_rate": dq[2],
                  "swing_ankle_rate": 0 * dq[0]}
    double = derive_double_support(q, dq, qdd, flows, trailing_ankle, lead_force["heel"],
                                   (fp("toe", "swing"), fp("k", "swing"), fp("r", "swing"),
                                    fp("c", "swing")), hs + ts, gamma, normal, tangent, Jl,
                                   P["I_foot"] if structure.foot_mass else 0)
    return FlatEquations(q=q, dq=dq, qdd=qdd, params=kin.params, flows=flows, resets=resets,
                         guards=guards, ground=ground, kinematics=kin_pins,
                         leg_angles=leg_angles, push_off=push_off, double_support=double)


def _world(kin, structure: Structure | None = None) -> dict:
    """Every massive body's centre of mass and (given ``structure``) every named point of a
    tree's kinematics in world axes (``kinematics(..., world=True)``: sums of lengths times
    sines and cosines of the links' absolute angles) (2, 1), the root (the stance heel) at
    the origin, and each massive body's mass, inertia about ``z`` and angular rate's row
    ``d omega / d dq`` (1, n)."""
    dqv = sp.Matrix(kin.dq)

    def world(v):
        return v[:2, :].applyfunc(sp.expand)

    bodies = {name: (kin.masses[name], kin.inertias[name][2, 2], world(r),
                     kin.omegas[name][2:, :].jacobian(dqv))
              for name, r in kin.coms.items()
              if kin.masses[name] != 0 or kin.inertias[name] != sp.zeros(3, 3)}
    if structure is None:
        return {"bodies": bodies}
    named = {"stance_heel": kin.contacts["stance_heel"], "stance_toe": kin.contacts["stance_toe"],
             "stance_ankle": kin.origins["stance_leg"], "hip": kin.origins["pelvis"],
             "swing_ankle": kin.contacts["swing_ankle"],
             "swing_heel": kin.contacts["swing_heel"], "swing_toe": kin.contacts["swing_toe"]}
    # the contract's names: the stance foot is the stance leg's end, the swing foot the
    # next step's reference point (the swing heel)
    named["stance_foot"], named["swing_foot"] = named["stance_ankle"], named["swing_heel"]
    for b in structure.bodies:
        for role in ("stance", "swing"):
            named[f"{role}_{b.name}"] = kin.coms[f"{role}_leg_{b.name}"]
    for b in structure.torso:
        named[f"torso_{b.name}"] = kin.coms[f"torso_{b.name}"]
    return {"bodies": bodies, "points": {k: world(v) for k, v in named.items()}}


def _pinned_modes(structure: Structure, kin, P: dict, fp, qdd):
    """Per pinned point (``heel``, ``toe``): the flow ``heel_contact`` / ``heel_off``, the
    kinematics (points, energies), the ground reaction (Newton's total and, heel pinned, the
    toe's share from the moment balance about the heel: module docstring) and the guards on
    the swing heel's and the hip's heights.

    Lagrange's equations of the tree's bodies (``T = sum [m |r_c'|^2 + I omega^2] / 2``,
    ``V`` gravity plus the ankle's and the links' springs; Murray, Li & Sastry 1994,
    Sec. 4.3), with every point in world axes.  The tree's root is the stance heel; with the
    toe pinned at ``O + (heel + toe) s`` every point moves by ``(heel + toe) s - toe(q)``.

    Returns
    -------
    flows, kinematics, ground, guards : dict
    lead_force : dict
        Per pin, Newton's total force (world axes) and moment about the origin ``(F, mom)``.
    trailing_ankle : Matrix (2, 1)
        The swing ankle's position, heel pinned (world axes).
    pre : dict
        Per pin, each massive body's ``(mass, inertia, J_c, J_w)`` (world axes).
    """
    q, dq = kin.q, kin.dq
    qv, dqv, ddv = sp.Matrix(q), sp.Matrix(dq), sp.Matrix(qdd)
    gamma, g = P["gamma"], P["g"]
    normal, tangent = planar_slope_axes(gamma)
    hs, ts = fp("heel", "stance"), fp("toe", "stance")
    a = q[ANKLE]
    k_a, r_a, c_a = fp("k", "stance"), fp("r", "stance"), fp("c", "stance")
    sw, st = q[0], q[1]
    Vs, D = link_springs(structure, q, P, (sw, sw, st, 0))
    spring = k_a * (a - r_a) ** 2 / 2 + Vs
    world = _world(kin, structure)
    toe = world["points"]["stance_toe"]
    flows, kin_pins, ground, guards, lead_force, pre = {}, {}, {}, {}, {}, {}
    for pin in ("heel", "toe"):
        shift = sp.zeros(2, 1) if pin == "heel" else (hs + ts) * tangent - toe
        M, V = sp.zeros(3, 3), spring
        bodies, F, mom = [], sp.zeros(2, 1), sp.Integer(0)
        for m, inertia, r, Jw in world["bodies"].values():
            pos = (r + shift).applyfunc(sp.expand)
            Jc = pos.jacobian(qv)
            M += m * Jc.T * Jc + inertia * Jw.T * Jw
            V += m * g * pos[1]
            bodies.append((m, inertia, Jc, Jw))
            vel = Jc * dqv
            acc = vel.jacobian(qv) * dqv + Jc * ddv
            f = m * (acc + sp.Matrix([0, g]))
            F += f
            mom += pos[0] * f[1] - pos[1] * f[0] + inertia * (Jw * ddv)[0]
        M = M.applyfunc(product_to_sum)
        V = product_to_sum(V)
        C = christoffel(M, q, dq) + D
        C[ANKLE, ANKLE] += c_a  # the ankle damper: torque -c da/dt on the ankle coordinate
        G = sp.Matrix([sp.expand(sp.diff(V, k)) for k in q])
        flows["heel_contact" if pin == "heel" else "heel_off"] = _System(q, dq, M=M, C=C, G=G)
        pre[pin] = bodies
        lead_force[pin] = (F, mom)
        # moment balance about the pinned heel: the toe's normal force (see module docstring)
        N = (F.T * normal)[0]
        ground[pin] = [N, mom / (hs + ts)] if pin == "heel" else [N]
        points = {k: (v + shift).applyfunc(sp.expand) for k, v in world["points"].items()}
        if pin == "heel":
            trailing_ankle = points["swing_ankle"]
        kin_pins[pin] = {"points": points, "kinetic": sp.Rational(1, 2) * (dqv.T * M * dqv)[0],
                         "potential": V}
        guards[f"swing_heel_height_{pin}"] = sp.expand((points["swing_heel"].T * normal)[0])
        guards[f"hip_height_{pin}"] = sp.expand((points["hip"].T * normal)[0])
    return flows, kin_pins, ground, guards, lead_force, trailing_ankle, pre


def _locked_and_resets(kin, post, pre: dict, flows: dict, Jl, rest):
    """Add the ``foot_flat`` flow (the heel-contact flow with the foot's angle locked,
    ``Jl = d phi / dq``) to ``flows``; return the resets (``foot_slap``, ``heel_strike_heel``,
    ``heel_strike_toe``) and the heel strike's translation rows (for the push-off).

    Heel strike: the post-impact bodies are the tree with the legs' roles swapped
    (``post``, :func:`walkerlab.walker.trees.legs_tree`'s ``swap_roles``; its root the
    swing heel, the new stance ankle ``b`` its coordinate, at the swing foot's rest angle
    ``rest`` at impact), in the pre-impact labelling ``(swing, stance, b)``: ``Mi = sum
    J+^T m J+``, ``B = sum J+^T m J-`` over the bodies (plus their rotations), then the roles
    swap (new swing = old stance, new stance = old swing)."""
    q, dq = kin.q, kin.dq
    ps_sw, ps_st, _a = q
    b_new = sp.Symbol("b_new_ankle", real=True)  # the swing ankle, once it is the stance one
    qv = sp.Matrix(q)
    S = sp.Matrix([[1, 0], [0, 1], [0, -1]])
    hc = flows["heel_contact"]
    flows["foot_flat"] = _System(q, dq, M=(S.T * hc.M).col_join(Jl),
                                 C=(S.T * hc.C).col_join(sp.zeros(1, 3)),
                                 G=(S.T * hc.G).col_join(sp.zeros(1, 1)))
    resets = {"foot_slap": _System(q, dq, Mi=(S.T * hc.M).col_join(Jl),
                                   B=(S.T * hc.M).col_join(sp.zeros(1, 3)),
                                   relabel_q=qv, relabel_rate=sp.eye(3))}
    # the post-impact tree's coordinates (swing, stance, stance_ankle) in the pre-impact
    # labelling: its swing leg the old stance one, its stance leg the old swing one
    post_q = sp.Matrix([ps_sw, ps_st, b_new])
    to_pre = dict(zip(post.q, (ps_st, ps_sw, b_new)))
    order = [1, 0, 2]   # the post tree's rates in (swing, stance, b) order
    after, trans = {}, sp.zeros(3, 2)
    for name, (m, inertia, r, Jw) in _world(post)["bodies"].items():
        Jn = r.xreplace(to_pre).jacobian(post_q)
        after[_other_role(name)] = (m, inertia, Jn, Jw[:, order])
        trans += m * Jn.T
    rw = rest
    relabel_q = sp.Matrix([ps_st, ps_sw, rw])
    relabel_rate = sp.Matrix([[0, 1, 0], [1, 0, 0], [0, 0, 1]])
    Mi = sum((m * Jn.T * Jn + inertia * Jwn.T * Jwn for m, inertia, Jn, Jwn in after.values()),
             sp.zeros(3, 3))
    Mi = Mi.subs(b_new, rw).applyfunc(product_to_sum)   # the same after either pin
    names = [n for n in kin.coms
             if kin.masses[n] != 0 or kin.inertias[n] != sp.zeros(3, 3)]
    for pin in ("heel", "toe"):
        Bm = sp.zeros(3, 3)
        for name, (m, inertia, Jc, Jw) in zip(names, pre[pin]):
            _m, _i, Jn, Jwn = after[name]
            Bm += m * Jn.T * Jc + inertia * Jwn.T * Jw
        resets[f"heel_strike_{pin}"] = _System(
            q, dq, Mi=Mi, B=Bm.subs(b_new, rw).applyfunc(product_to_sum), relabel_q=relabel_q,
            relabel_rate=relabel_rate)
    return resets, trans.subs(b_new, rw).applyfunc(product_to_sum)


def _push_off_systems(q, kin_pins, pre, flows, resets, trans) -> dict:
    """The extended impact system of each pinned point (``heel``, ``toe``): the push-off at
    the stance toe and the heel strike after it (Wisse et al. 2006).

    Extended coordinates ``qe = (q, x_f, y_f)``: the walker translated by ``(x_f, y_f)``
    with its pinned point.  Per pin: ``De`` (5, 5), the Hessian of the kinetic energy in
    ``dqe`` (``[M, Mt; Mt^T, m I]``, ``Mt = sum m dr/dq`` in world axes; singular along the
    massless foot's turn about the ankle, which the push-off holds); ``Jt`` (2, 5), the
    stance toe's Jacobian; ``Jh`` (2, 3), the hip's (its speed for a push-off law); ``Mi``
    (3, 3) and ``Be`` (3, 5), the heel strike's ``Mi dq+ = Be dqe-`` (momenta of the
    pre-impact velocities, the trailing foot free and moving, projected on the post-impact
    coordinates with the swing heel pinned: ``Be = [B | sum J+^T m]``, ``B`` the passive
    heel strike's, so ``Be [dq; 0] = B dq`` to round-off); ``push`` (2,) the vector toe ->
    hip; ``relabel_q`` (3,) and ``relabel_rate`` (3, 3) the role swap."""
    qv = sp.Matrix(q)
    out = {}
    for pin, mode in (("heel", "heel_contact"), ("toe", "heel_off")):
        Mt = sum((m * Jc.T for m, _i, Jc, _w in pre[pin]), sp.zeros(3, 2))
        mass = sum((m for m, *_ in pre[pin]), sp.Integer(0))
        hs = resets[f"heel_strike_{pin}"]
        De = flows[mode].M.row_join(Mt).col_join(Mt.T.row_join(mass * sp.eye(2)))
        pts = kin_pins[pin]["points"]
        toe = pts["stance_toe"]
        out[pin] = {"De": De, "Jt": toe.jacobian(qv).row_join(sp.eye(2)),
                    "Jh": pts["hip"].jacobian(qv), "Mi": hs.Mi, "Be": hs.B.row_join(trans),
                    "push": pts["hip"] - toe, "relabel_q": hs.relabel_q,
                    "relabel_rate": hs.relabel_rate}
    return out


#: The leading foot's modes in double support (the trailing foot on its toe): on its heel
#: (turning about it) or flat (its angle locked).
DOUBLE_SUPPORT_LEADS = ("heel_contact", "foot_flat")


def _lead_system(lead: str, M4, rhs, J, dJ, M, g_row, Jl, dq, foot_inertia) -> dict:
    """One leading-foot mode's double support (:func:`derive_double_support`): the flow's
    system ``K [Qdd; lam] = rhs`` (``M4``, the toe's ``J``, ``dJ dQ``; foot flat adds the
    lock's row) and the entry's ``Ki [dq+; Lam] = Ki_rhs`` (on ``q`` with the pin's row
    ``g_row``, ``M`` the heel contact's mass matrix; with ``foot_inertia`` the impact on
    ``Q``, ``entry_on_Q``)."""
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
    Ki[:3, :3] = M
    Ki[:3, 3:] = -imp_rows.T
    Ki[3:, :3] = imp_rows
    out = {"K": K, "rhs": rhs.col_join(gam), "Ki": Ki,
           "Ki_rhs": (M * sp.Matrix(dq)).col_join(sp.zeros(mi, 1))}
    if foot_inertia != 0:  # the toe pinned on Q (see derive_double_support)
        out["Ki"] = K
        out["Ki_rhs"] = (M4 * sp.Matrix([*dq, 0])).col_join(sp.zeros(m, 1))
        out["entry_on_Q"] = True
    return out


def derive_double_support(q, dq, qdd, flows, ankle, lead_force, trailing, sole, gamma, normal,
                    tangent, Jl, foot_inertia=0) -> dict:
    """Double support after heel strike (roles already swapped): the leading (stance) foot
    on its heel at ``O`` (heel contact) or flat (foot flat), the trailing (swing) foot on its
    toe at a point ``P`` of the slope.  The trailing foot's ankle angle ``b`` (its sole at
    ``swing + b``) is no state: with the toe on the slope, ``sin(swing + b + gamma) = -h/t``
    (``h`` the trailing ankle's height above the slope, ``t`` the toe length), the branch
    with the heel up (a toe on a line ``level`` [m] above the leading heel's, the tread it
    stood on when the heel struck a landing lower down: ``sin(swing + b + gamma) = (level -
    h)/t``); its rate from the toe's zero normal velocity.  The flow: Lagrange's
    equations on ``Q = (swing, stance, stance_ankle, b)`` (the foot massless: ``b``'s row
    holds the spring ``k (b - r)`` and damper ``c db`` against the toe's force), the toe
    pinned, ``[M, -J^T; J, 0] [Qdd; lam] = [-C dQ - G; -dJ dQ]`` (``J = dT/dQ`` (2 x 4) of
    the toe ``T``; foot flat adds ``phi = 0``'s row ``[0, 1, 1, 0]``), ``lam`` the ground's
    force on the toe (world axes) [N].  Entry (the plastic impact that pins the toe, Newton's
    restitution 0): in ``q`` the toe's pin is one row ``g = u^T dA/dq`` (``A`` the trailing
    ankle, ``u`` the unit vector from toe to ankle: a massless foot takes no impulsive
    moment, so the toe's impulse ``Lam u`` passes through the ankle) and
    ``[M, -g^T (, -Jl^T); g, 0 (; Jl, 0)] [dq+; Lam] = [M dq-; 0 (; 0)]``.

    Feet with mass (``foot_inertia`` ``I`` [kg m^2] about the ankle, the mass at the ankle
    already a body of ``flows``, whose swing foot turns with its leg): the trailing sole
    turns at ``d(swing + b)/dt``, so ``M`` gains ``I`` in the ``(swing, b)`` block beyond
    the locked foot's ``I`` in ``(swing, swing)``; the entry is then the impact on ``Q``
    with the toe pinned in both directions, ``[M4, -J^T (, -Jl4^T); J, 0 (; Jl4, 0)]
    [dQ+; Lam] = [M4 (dq-, 0); 0 (; 0)]`` (the foot turning with its leg before it,
    ``db- = 0``; ``Lam`` (2,) the toe's impulse in world axes [N s]), whose limit ``I -> 0``
    is the massless entry above."""
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
    M4[0, 3] = M4[3, 0] = M4[3, 3] = foot_inertia
    rhs = sp.zeros(4, 1)
    rhs[:3, 0] = -hc.C * sp.Matrix(dq) - hc.G
    rhs[3, 0] = -c_b * db - k_b * (b - r_b)
    b_of = sp.asin(-h / t_len) - gamma - sw
    # the trailing toe on a line ``level`` [m] above the leading heel's (along the normal):
    # the tread it stood on when the heel struck a lower landing (stairs, footholds)
    level = sp.Symbol("level", real=True)
    b_of_level = sp.asin((level - h) / t_len) - gamma - sw
    hdot = (sp.Matrix([h]).jacobian(sp.Matrix(q)) * sp.Matrix(dq))[0]
    db_of = -hdot / (t_len * sp.cos(theta + gamma)) - dq[0]
    dA = ankle.jacobian(sp.Matrix(q))
    u = -sp.Matrix([sp.cos(theta), sp.sin(theta)])  # toe -> ankle
    g_row = u.T * dA
    F, mom = lead_force
    held = k_b * (b - r_b) ** 2 / 2
    if foot_inertia != 0:  # the sole's kinetic energy beyond turning with its leg (held in M)
        held += foot_inertia * ((dq[0] + db) ** 2 - dq[0] ** 2) / 2
    out = {"b": b, "db": db, "b_of": b_of, "b_of_level": b_of_level, "db_of": db_of, "u": u,
           "toe": toe, "trailing_spring": held, "foot_angle": theta + gamma,
           "leads": DOUBLE_SUPPORT_LEADS}
    for lead in DOUBLE_SUPPORT_LEADS:
        out[lead] = _lead_system(lead, M4, rhs, J, dJ, hc.M, g_row, Jl, dq, foot_inertia)
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
