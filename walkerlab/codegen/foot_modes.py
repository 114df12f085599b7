"""Flat feet on ankle springs: the rigid hybrid view's modes, derived with sympy from the
walker's body tree (:func:`walkerlab.walker.trees.legs_tree` with its soles: the stance heel
the root, each leg on its ankle; :func:`walkerlab.codegen.tree_derive.kinematics` in world
axes, as every other legged walker's equations come from its tree in
:mod:`walkerlab.codegen.legged`) and written as Python source (the same ``make(p)`` module
form as :mod:`walkerlab.codegen.source`, through its printers and solvers).

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
:func:`walkerlab.codegen.double_support.derive_double_support`): the leading foot
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

from walkerlab.codegen import source as codegen
from walkerlab.codegen.compiled_source import cfunc_lines, compiled_head
from walkerlab.codegen.double_support import (
    DOUBLE_SUPPORT_LEADS,
    derive_double_support,
    double_support_lines,
)
from walkerlab.codegen.frames import planar_slope_axes
from walkerlab.codegen.lagrange import christoffel
from walkerlab.codegen.legged import link_springs
from walkerlab.codegen.source import (
    IND,
    PRINTER,
    cse_lines,
    flow_lines,
    numpy_fn,
    reset_lines,
    start_module,
)
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
    (:func:`walkerlab.codegen.double_support.derive_double_support`).

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


def _fast_lines(eq) -> list[str]:
    """:func:`generate_flat`'s flows, resets, guards, ground reactions, double supports."""
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
        fast += double_support_lines(eq, lead)
    return fast


def generate_flat(structure: Structure, key: str) -> str:
    """Source text of a flat-footed walker's generated module (``make(p)`` returns, by name:
    ``flow_<mode>``, ``flow_<mode>_jacobian``, ``flow_<mode>_variational`` for the three
    modes; ``reset_<name>`` and ``reset_<name>_jacobian`` for ``foot_slap``,
    ``heel_strike_heel``, ``heel_strike_toe``; ``guard_<name>``/``grad_<name>``;
    ``ground_heel(x, qdd) -> (N, N_toe)`` and ``ground_toe(x, qdd) -> (N,)`` [N];
    per leading-foot mode ``m`` of the double support (``heel_contact``, ``foot_flat``):
    ``flow_double_support_<m>(t, x, gen=None, level=0.0)``, ``double_support_<m>_forces(t,
    x, gen=None, level=0.0)`` (trailing toe normal and tangential, leading foot normal and
    its toe's share [N]; ``gen`` (3,) [N m] a generalised force in ``q``'s rows, joint
    torques' ``B tau``), ``double_support_<m>_entry(x, level=0.0) -> (x+, (Lam_n, Lam_t))``
    [N s]; and ``double_support_trailing(x, level=0.0) -> (b, db, held energy [J], trailing
    sole angle from the slope [rad])`` (``level`` [m]: the trailing toe's tread above the
    leading heel's line, along the normal: stairs, footholds; held: the trailing spring's
    energy, with feet of mass plus the trailing sole's kinetic energy beyond turning with
    its leg);
    ``section``/``from_section``; ``energies`` and, per pinned point, ``energies_heel`` /
    ``energies_toe`` (dicts ``kinetic``, ``potential`` [J]); ``points``; ``leg_angles``)."""
    eq = derive_flat(structure)
    hoisted = codegen.start_module(eq.params)
    fast = _fast_lines(eq)
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
    call counter) and ``NCONST``, as :func:`walkerlab.codegen.compiled_source.generate_compiled`."""

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
            body += cfunc_lines(name, system, consts, parts[mode], var, extras[mode]) + [""]
    return "\n".join(compiled_head("model code (walkerlab.codegen.foot_modes)", key,
                                   "sin, cos, tan, sqrt, pi", "cfunc, types") + body) + "\n"
