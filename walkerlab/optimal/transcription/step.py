"""A periodic hybrid gait by direct collocation (CasADi ``Opti`` + IPOPT): one step of a
walker with a hip torque (and a push-off), the heel-strike reset as the periodic boundary
condition, the step period free.

Transcription (Kelly 2017, "An introduction to trajectory optimization: how to do your own
direct collocation", SIAM Review 59(4):849-904, Sec. 4, separated Hermite-Simpson): states
``x_k`` and the hip torque ``u_k`` at ``2N + 1`` points on ``[0, T]`` (``N`` intervals of
``h = T / N``, their mid-points at odd ``k``); per interval ``i -> m -> j``::

    x_m = (x_i + x_j) / 2 + h (f_i - f_j) / 8,      x_j = x_i + h (f_i + 4 f_m + f_j) / 6

with ``f = [dq, M(q)^-1 (B u - C(q, dq) dq - G(q))]`` from the walker's generated symbolic
equations (:func:`walkerlab.codegen.legged.derive_legged`, paper Eq. 3 with ``B u``; ``B`` the
hip angle's gradient, so ``+u`` acts on the swing leg and ``-u`` on the stance leg as in
:mod:`walkerlab.models.actuation`).  The end is a heel strike (the generated guard = 0, the
swing foot ahead); the step's start is the end mapped by push-off + heel strike + role swap
(the extended-coordinate impact of :mod:`walkerlab.models.hybrid.actuated`, symbolic here):
``x_0 = reset(x_2N)``; the swing foot comes down onto the ground at the end (the guard's
rate below ``-touchdown_rate``, the rigid model's event direction).  Objectives
(:data:`OBJECTIVES`, or a weighted sum of them): the effort ``int u^2 dt`` (Simpson's rule
on the same points; with a free push-off its weighted square ``w P^2`` added), the
push-off's work, the cost of transport (the hip's positive work ``int max(p, 0) dt``,
exact through slack variables ``s >= 0, s >= p`` at every point as Srinivasan & Ruina
2006 and Kelly 2017 do, plus the push-off's work, per weight and step length; alone, a
tiny effort weight added) and the peak torque (epigraph form: ``-s <= u_k <= s``,
minimise ``s``).  Constraints:
optional target speed, step length or step period, a torque limit, no scuffing (the swing
foot above a bound at every point but the ends), the stance foot's ground reaction
``m (a_com + g)`` with a non-negative normal force inside the friction cone, the hip's
joint limits.

Collocated as the sequence of one phase by the multi-phase transcription
(:func:`walkerlab.optimal.transcription.mode_sequence.collocate_step`); this module gives
that phase its functions (:func:`step_functions`), the spec and the replay.

A result is called a gait only after its **replay**: the rigid model integrated (scipy's
DOP853 at 1e-12) from ``x_0`` with the optimised torque as a function of time (piecewise
quadratic through the points, Hermite-Simpson's control), until its heel strike, then the
same reset; the return error ``|x_0' - x_0|`` is stored.

Straight legs with point or arc feet, a torso on the bisecting hip (the push-off at the
trailing foot's material contact point through the generated extended impact, as the rigid
view's :mod:`walkerlab.models.hybrid.push_off`), or massless legs with a hip mass (Kuo's
2002 walker: the torque per foot mass on the swing leg's row, the point hip's transition);
one hip torque.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from walkerlab.codegen.casadi_functions import casadi_function
from walkerlab.optimal.transcription.ipopt import CollocatedStep

__all__ = ["OBJECTIVES", "CollocationResult", "CollocationSpec",
           "check_objective", "ipopt_options", "number", "positive_power", "replay",
           "replay_actuation", "step_functions", "target_constraints", "torque_of_time"]


@dataclass(frozen=True)
class CollocationSpec:
    """What to optimise.

    Attributes
    ----------
    intervals : int
        Hermite-Simpson intervals ``N``.
    push_off_n_s : float
        Push-off impulse [N s] (fixed) ...
    push_off_free : bool
        ... or a decision variable in ``[0, push_off_max_n_s]``, its work added to the
        objective (weight ``push_off_weight`` [1/s]: J -> N^2 m^2 s).
    max_torque_n_m : float or None
        ``|u| <= max`` [N m].
    target_speed_m_per_s, target_step_length_m, target_step_period_s : float or None
        Equality targets (speed = step length / step period).
    objective : str
        A key of :data:`OBJECTIVES`, or ``weighted``: ``sum w_i J_i`` over ``weights``.
    weights : tuple of (str, float)
        The weighted sum's terms (names of :data:`OBJECTIVES`) and weights.
    cost_of_transport_effort_weight : float
        With ``objective = "cost_of_transport"``: ``w`` [1 / (N^2 m^2 s)] of the effort
        added to it (``J = CoT + w int u^2 dt``).  The cost of transport alone leaves the
        torque free wherever it does negative or no work (a torque per foot mass on massless
        legs does none), a degenerate optimum; the tiny effort picks the least torque
        among the least-CoT gaits.  Where the least cost of transport needs positive
        work and nothing bounds the torque, ``w`` is part of the problem: the compass
        walker on level ground with a hip torque only (0.5 m/s, 40-80 intervals) has CoT
        0.091, 0.053, 0.030 at ``w`` = 1e-2, 1e-3, 1e-4, its torques growing towards
        impulses (at 1e-6 they chatter between the points, the replay no longer closes);
        give a torque limit or a larger ``w`` there.
    min_clearance_m : float or None
        The swing foot at least this high above the slope [m] at every point but the first
        and the last (no scuffing).
    friction_coefficient : float or None
        The stance foot's ground reaction: normal force >= 0 and ``|F_t| <= mu F_n``.
    hip_angle_range_rad : tuple (lo, hi) or None
        The hip joint's limits on ``swing - stance`` angle [rad].
    touchdown_rate_rad_per_s : float
        The heel-strike guard falls at least this fast at the end [rad/s]: the swing foot
        comes down onto the ground, not grazing it (a grazing touchdown moves the replay's
        event time by the state error / the rate).
    warm_start : bool
        The guess is an optimum (another ``optimize.h5``): IPOPT's barrier starts at 1e-6
        (:func:`ipopt_options`).
    """

    intervals: int = 40
    push_off_n_s: float = 0.0
    push_off_free: bool = False
    push_off_max_n_s: float = 100.0
    push_off_weight: float = 1.0
    max_torque_n_m: float | None = None
    target_speed_m_per_s: float | None = None
    target_step_length_m: float | None = None
    target_step_period_s: float | None = None
    objective: str = "effort"
    weights: tuple = ()
    cost_of_transport_effort_weight: float = 1e-4
    min_clearance_m: float | None = None
    friction_coefficient: float | None = None
    hip_angle_range_rad: tuple | None = None
    touchdown_rate_rad_per_s: float = 0.05
    warm_start: bool = False

#: Objectives of one step, with their units (``u`` per foot mass on massless legs).
OBJECTIVES = {"effort": "N^2 m^2 s", "push_off_work": "J", "cost_of_transport": "-",
              "peak_torque": "N m"}


@dataclass(kw_only=True)
class CollocationResult(CollocatedStep):
    """An optimised step (``N`` intervals: ``m = 2N + 1`` points; ``u`` (m,) the hip
    torque): the fields of :class:`~walkerlab.optimal.transcription.ipopt.CollocatedStep`
    and these.

    Attributes
    ----------
    push_off_n_s : float
        The push-off impulse [N s].
    objective : float
        The spec's objective at the optimum (its unit: :data:`OBJECTIVES`; ``effort``
        with a free push-off adds ``push_off_weight P^2``, ``cost_of_transport``
        ``cost_of_transport_effort_weight`` times the effort).
    terms : dict
        Every objective of :data:`OBJECTIVES` evaluated there (the cost of transport's
        positive work exact, ``max(p, 0)`` at the points; ``peak_torque`` ``max |u|``).
    replay_error : float
        Max-norm return error of the replay (module docstring).
    violations : str
        When IPOPT did not converge: the constraint groups with the largest violation
        (:func:`walkerlab.optimal.transcription.ipopt.largest_violations`).
    """

    push_off_n_s: float
    replay_error: float = np.nan
    terms: dict = field(default_factory=dict)
    violations: str = ""


def step_functions(data, eq):
    """CasADi functions of one step of ``data`` (a WalkerData with straight legs and point
    feet, the legs massive or all massless with a hip mass) from its symbolic equations
    ``eq``: ``flow(x, u)`` (2n,), ``guard(x)`` (the heel strike, 0 at it),
    ``guard_rate(x, u)`` (its time derivative), ``ahead(x)`` (> 0: the swing foot ahead),
    ``step(x)`` (the feet's distance [m]), ``reset(x, P)`` (push-off ``P`` [N s] + heel
    strike + role swap), ``push_off_work(x, P)`` [J], ``clearance(x)`` (the swing foot's
    height above the slope [m]), ``hip_angle(x)`` (swing minus stance [rad]),
    ``power(x, u)`` (the hip torque's power [W]) and ``grf(x, u)`` (the stance foot's
    ground reaction along the slope's normal and tangent, forward positive [N]).

    On massless legs (the limit ``m_foot -> 0``, :mod:`walkerlab.codegen.legged`) ``u``
    is the torque per foot mass acting on the swing leg's row only and doing no work, and
    the transition is the point hip's (Kuo 2002, as :mod:`walkerlab.models.hybrid.actuated`).

    Raises
    ------
    ValueError
        Knees or flat feet (a step of phases), partly massless legs, legs that differ
        (one line).
    """
    import casadi as ca
    import sympy as sp

    st = data.structure
    massless = [b.massless for b in st.bodies]
    limit = bool(massless) and all(massless)
    if not (st.kind.collocation is not None and st.kind.collocation.one_step):
        raise ValueError("optimize: knees and flat feet take a step of phases "
                         "(walkerlab.optimal.transcription.phases.mode_functions)")
    if any(massless) and not limit:
        raise ValueError("optimize: legs with some massless bodies have no finite equations "
                         "of motion (a massless body carries no inertia its torque could "
                         "act on): make every leg body massive, or all massless with a hip "
                         "mass")
    if limit and not st.hip_mass:
        raise ValueError("optimize: massless legs without a hip mass have no mass at all "
                         "(walker.hip_mass_kg must be > 0)")
    if getattr(data, "mirror", None) is not None:
        raise ValueError("optimize: legs that differ take a stride of two different steps "
                         "(walkerlab.optimal.transcription.stride); one step would be periodic "
                         "only for mirror-image legs")
    n = len(eq.q)
    vals = dict(zip(eq.params, data.params))
    xs = list(eq.q) + list(eq.dq)

    def fn(name, exprs, *extra):
        return ca.Function(name, [x, *extra], [casadi_function(exprs, xs, vals)(x)])

    x, u, P = ca.SX.sym("x", 2 * n), ca.SX.sym("u"), ca.SX.sym("P")
    M, C, G = (casadi_function(m, xs, vals)(x) for m in (eq.M, eq.C, eq.G))
    delta = eq.leg_angles["swing"] - eq.leg_angles["stance"]
    if limit:  # the rows of the absolute leg angles / m_foot, the swing row first
        B = ca.DM([1.0] + [0.0] * (n - 1))
    else:
        B = casadi_function(sp.Matrix([delta]).jacobian(eq.q).T, xs, vals)(x)
    qdd = ca.solve(M, B * u - C @ x[n:] - G)
    foot = casadi_function(eq.points["swing_foot"], xs, vals)(x)
    hip_angle = casadi_function([delta], xs, vals)(x)
    rate = ca.jacobian(hip_angle, x[:n]) @ x[n:]
    if limit:
        reset, work = _reset_point_hip(eq, xs, vals, x, P, data.total_mass_kg)
    else:  # the extended impact (an upper body rides on the hip; an arc's rolling contact)
        reset, work = _reset_extended(eq, xs, vals, x, P, data.total_mass_kg)
    return {"flow": ca.Function("flow", [x, u], [ca.vertcat(x[n:], qdd)]),
            "guard": fn("guard", [eq.guards["heel_strike"]]),
            "guard_rate": ca.Function("guard_rate", [x, u], [ca.jacobian(
                casadi_function([eq.guards["heel_strike"]], xs, vals)(x), x) @ ca.vertcat(
                    x[n:], qdd)]),
            "ahead": fn("ahead", [eq.guards["swing_foot_ahead"]]),
            "step": ca.Function("step", [x], [ca.sqrt(foot[0] ** 2 + foot[1] ** 2)]),
            "reset": ca.Function("reset", [x, P], [reset]),
            "push_off_work": ca.Function("push_off_work", [x, P], [work]),
            "clearance": fn("clearance", [eq.guards["swing_clearance"]]),
            "hip_angle": ca.Function("hip_angle", [x], [hip_angle]),
            "power": ca.Function("power", [x, u], [0 * u if limit else u * rate]),
            "grf": ca.Function("grf", [x, u], [_ground_reaction(data, eq, xs, vals, x,
                                                               qdd)]),
            "n": n, "limit": limit, "total_mass_kg": float(data.total_mass_kg),
            "gravity": float(data.gravity_m_per_s2)}


def _relabel(eq, xs, vals, x, dq_plus):
    """The post-impact state with the roles swapped (CasADi)."""
    import casadi as ca

    qn = casadi_function(eq.relabel_q, xs, vals)(x)
    R = np.array(eq.relabel_rate.subs(vals), float)
    return ca.vertcat(qn, ca.DM(R) @ dq_plus)


def _reset_extended(eq, xs, vals, x, P, _mass, lock=None):
    """Push-off + heel strike in extended coordinates ``[q, p]``, ``p`` the stance foot's
    ``k`` translations (``E``'s rows: 2 for a planar walker, ``(x_f, y_f)``; 3 for a walker
    in 3D, :func:`walkerlab.codegen.legged.extended_impact`) as the rigid view's
    :class:`walkerlab.models.hybrid.push_off.PushOffTransition`: the impulse at the
    trailing foot's material contact point - a point foot, an arc's rolling contact
    ``stance_contact`` - to the trailing leg's hip (a 3D walker's ``stance_hip``, else the
    ``hip``); the generated ``De, E``, an arc's ``E`` at the leading arc's material contact
    point), and the push-off's work [J].

    ``lock`` (a sympy expression of ``eq.q``, None: nothing held): a constraint held through
    both impulses with gradient ``a = d(lock)/dq`` (a kneed walker's locked swing knee, the
    knee's extension: McGeer 1990; :meth:`PushOffTransition.hold_lock`)::

        [De  -a^T] [dqe_po]   [De dqe- + E_f^T P e]
        [a     0 ] [ lam  ] = [        0          ]

    then the heel strike with ``[E; a]`` in place of ``E``."""
    import casadi as ca
    import sympy as sp

    n, k = len(eq.q), eq.E.shape[0]
    fs = {sp.Symbol("x_f"): 0, sp.Symbol("y_f"): 0}
    De = casadi_function(eq.De.subs(fs), xs, vals)(x)
    E = casadi_function(eq.E.subs(fs), xs, vals)(x)
    hip = casadi_function(eq.points["stance_hip" if "stance_hip" in eq.points else "hip"],
                          xs, vals)(x)
    if "stance_contact" in eq.points:  # an arc foot: from its rolling contact point
        hip = hip - casadi_function(eq.points["stance_contact"], xs, vals)(x)
    r2 = hip[0] ** 2
    for i in range(1, k):
        r2 = r2 + hip[i] ** 2
    e = hip / ca.sqrt(r2)
    dqe = ca.vertcat(x[n:], *[0] * k)
    Ef = ca.horzcat(ca.SX.zeros(k, n), ca.SX.eye(k))
    if lock is None:
        dqe_po = dqe + ca.solve(De, Ef.T @ (P * e))
        K = ca.vertcat(ca.horzcat(De, -E.T), ca.horzcat(E, ca.SX.zeros(k, k)))
        sol = ca.solve(K, ca.vertcat(De @ dqe_po, *[0] * k))
    else:  # the lock held through both impulses (as the rigid model's transition)
        a = ca.horzcat(casadi_function(sp.Matrix([lock]).jacobian(eq.q), xs, vals)(x),
                       ca.SX.zeros(1, k))
        A = ca.vertcat(ca.horzcat(De, -a.T), ca.horzcat(a, ca.SX.zeros(1, 1)))
        dqe_po = ca.solve(A, ca.vertcat(De @ dqe + Ef.T @ (P * e), 0))[:n + k]
        Cl = ca.vertcat(E, a)
        K = ca.vertcat(ca.horzcat(De, -Cl.T), ca.horzcat(Cl, ca.SX.zeros(k + 1, k + 1)))
        sol = ca.solve(K, ca.vertcat(De @ dqe_po, *[0] * (k + 1)))
    work = 0.5 * (dqe_po.T @ De @ dqe_po - dqe.T @ De @ dqe)
    return _relabel(eq, xs, vals, x, sol[:n]), work


def _reset_point_hip(eq, xs, vals, x, P, mass):
    """Push-off + heel strike of a walker whose mass is all at the hip (Kuo 2002, Eq. 2):
    ``v_po = v + (P / M) e_trail``, the heel strike removes the velocity along the leading
    leg, the trailing foot keeps none across its leg; and the push-off's work [J]."""
    import casadi as ca

    n = len(eq.q)
    q, dq = x[:n], x[n:]
    hip = casadi_function(eq.points["hip"], xs, vals)(x)
    lead = casadi_function(eq.points["swing_foot"], xs, vals)(x)
    v = ca.jacobian(hip, q) @ dq
    et = hip / ca.norm_2(hip)
    el = (hip - lead) / ca.norm_2(hip - lead)
    v_po = v + (P / mass) * et
    v_plus = v_po - ca.dot(v_po, el) * el
    v_foot = ca.dot(v_plus, et) * et
    qn = casadi_function(eq.relabel_q, xs, vals)(x)
    qs = ca.SX.sym("qs", n)  # the new coordinates: Jacobian of (hip, swing foot) there
    where = ca.Function("where", [x], [ca.vertcat(hip, lead)])
    Jn = ca.Function("Jn", [qs], [ca.jacobian(where(ca.vertcat(qs, ca.SX.zeros(n))),
                                              qs)])(qn)
    b = ca.vertcat(v_plus, v_foot)
    dq_plus = ca.solve(Jn.T @ Jn, Jn.T @ b)
    work = 0.5 * mass * (ca.dot(v_po, v_po) - ca.dot(v, v))
    return ca.vertcat(qn, dq_plus), work


def _ground_reaction(data, eq, xs, vals, x, qdd):
    """The stance foot's ground reaction ``m_total (a_com + g y)`` [N] along the slope's
    normal and tangent (forward positive), from the bodies' named points and masses.

    A walker in 3D (points (3,), the third row lateral: :mod:`walkerlab.codegen.derive_3d`)
    has its linear momentum in the rows of the stance foot's translations of its extended
    mass matrix, ``p = De[n:, :n] dq`` (world axes, the foot at rest:
    :func:`walkerlab.codegen.legged.extended_impact`), so the force is ``dp/dt + m_total
    g y`` (Newton), every body's inertia and the pelvis' included; its (3,): normal, along
    the fall line, lateral."""
    import casadi as ca

    from walkerlab.walker.description import ROLE_TAG

    st = data.structure
    n = len(eq.q)
    if eq.points["hip"].shape[0] == 3:  # in 3D: the momentum rows of the extended system
        import sympy as sp

        if not any(eq.De[n:, :n]):
            raise ValueError("optimize.friction_coefficient: a 3D walker's ground reaction "
                             "is read from its extended impact system, which round feet "
                             "lack (walker.foot_radius_m)")
        mom = casadi_function(eq.De[n:, :n] * sp.Matrix(eq.dq), xs, vals)(x)
        F = ca.jacobian(mom, x) @ ca.vertcat(x[n:], qdd) + ca.vertcat(
            0, data.total_mass_kg * data.gravity_m_per_s2, 0)
        gam = data.slope_rad
        return ca.vertcat(ca.sin(gam) * F[0] + ca.cos(gam) * F[1],
                          ca.cos(gam) * F[0] - ca.sin(gam) * F[1], F[2])
    names = list(st.param_names)
    pts = [(float(data.params[names.index("M_hip")]), "hip")] if st.hip_mass else []
    for b in st.bodies:
        for role in ("stance", "swing"):
            if b.massless:
                continue
            tag = f"{ROLE_TAG[role]}_" if st.asymmetric else ""
            pts.append((float(data.params[names.index(f"m_{tag}{b.name}")]),
                        f"{role}_{b.name}"))
    mtot = sum(m for m, _ in pts)
    com = sum(m * casadi_function(eq.points[p], xs, vals)(x) for m, p in pts) / mtot
    vel = ca.jacobian(com, x[:n]) @ x[n:]
    acc = ca.jacobian(vel, x) @ ca.vertcat(x[n:], qdd)
    F = mtot * (acc + ca.vertcat(0, data.gravity_m_per_s2))
    gam = data.slope_rad
    return ca.vertcat(ca.sin(gam) * F[0] + ca.cos(gam) * F[1],
                      ca.cos(gam) * F[0] - ca.sin(gam) * F[1])


def number(v) -> float:
    """A scalar value of the optimum (a structurally zero term comes back sparse)."""
    return float(np.asarray(v.toarray() if hasattr(v, "toarray") else v).ravel()[0])


def ipopt_options(spec) -> dict:
    """IPOPT's options: tight tolerances; with the cost of transport's slack variables no
    bound relaxation (IPOPT relaxes every inequality by ``bound_relax_factor`` = 1e-8
    relative by default, which lets each ``s_k`` go ~1e-8 below 0 and biases the positive
    work by as much; at 0 the slack is exact) and a small initial barrier (``mu_init``
    1e-9 for IPOPT's 0.1).

    The barrier on ``s_k - p_k >= 0`` rewards negative power at every point, so early
    iterations (the barrier large) push the torque to brake wherever it can, and the
    objective - zero on every gait whose torque only brakes, a continuum, bar the effort
    weight - does not pull it back.  Measured on the kneed walker (60 intervals, effort
    weight 1e-6): at 0.9 m/s the default barrier ends (Solve_Succeeded, 223 iterations) at
    100 N m peak torques whose power changes sign between the points and a replay that does
    not close; from a guess 5 % off its passive gait at 68 N m and a replay error 1.7e-2.
    With 1e-9: 0.0096 N m (the least-effort gait's 0.0097; 113 iterations, replay 1.2e-7)
    and 0.0063 N m (82 iterations, replay 1.6e-7); on its passive slope (effort weight
    1e-2) the default barrier ends on the walker's other, unstable passive gait (period
    0.4921 s, |multiplier| 2.28), 1e-9 on the stable one (period within 1e-4).  The
    compass walker of configs/compass_optimal.yaml at 0.6 m/s (40 intervals, effort weight
    1e-6): 180 N m and a replay error 1.7e-3 with the default barrier, 149 N m and 1.6e-4
    with 1e-9; with the effort weight 1e-4 (the default since) a braking torque of 17 N m,
    a gait (replay 2.7e-7).  The cost of transport's torques are sharper than the
    effort's: the kneed walker at 0.9 m/s with the friction cone binding (mu 0.2312) has
    3.5 N m peaks, the replay closing to 6.2e-6 on 60 intervals (not a gait) and 6.8e-7 on
    120, the cost of transport rising 2.69e-4 -> 3.23e-4 with the mesh (the positive work
    is counted at the points).

    From a guess that is an optimum (``warm_start``, another ``optimize.h5``) the barrier
    starts at 1e-6: IPOPT's 0.1 first pushes the guess off its active constraints and back
    (the kneed walker at 0.9 m/s from its own ``optimize.h5``: 32 iterations, against 29
    from its passive gait; from 1e-6: 7, the same optimum to 2e-16 of the objective)."""
    opts = {"print_level": 0, "tol": 1e-12, "acceptable_tol": 1e-10, "max_iter": 500,
            "sb": "yes"}
    asked = dict(spec.weights) if spec.objective == "weighted" else {spec.objective: 1.0}
    if spec.warm_start:
        opts["mu_init"] = 1e-6
    if "cost_of_transport" in asked:
        opts["bound_relax_factor"] = 0.0
        opts["mu_init"] = 1e-9
    return opts


def peak_torque(opti, U, asked: dict):
    """The largest |torque| over the collocation points ``U``: in epigraph form (a variable
    ``s`` with ``-s <= U <= s``) when it is among the ``asked`` objectives, else the plain
    (non-smooth) maximum, for the record."""
    import casadi as ca

    if "peak_torque" not in asked:
        return ca.mmax(ca.fabs(U))
    peak = opti.variable()
    opti.subject_to(opti.bounded(-peak, U, peak))
    opti.set_initial(peak, 1.0)
    return peak


def target_constraints(opti, spec, T, length) -> None:
    """The gait targets of ``spec`` (step period [s], step length [m], speed [m/s]) as
    equality constraints on the step's period ``T`` and length ``length`` (CasADi
    expressions) of ``opti``; a target left ``None`` adds nothing."""
    if spec.target_step_period_s is not None:
        opti.subject_to(T == spec.target_step_period_s)
    if spec.target_step_length_m is not None:
        opti.subject_to(length == spec.target_step_length_m)
    if spec.target_speed_m_per_s is not None:
        opti.subject_to(length == spec.target_speed_m_per_s * T)


def positive_power(opti, power):
    """The positive part of the actuator power at the points, exactly, by slack variables
    (Srinivasan & Ruina 2006, Nature 439:72-75; Kelly 2017, SIAM Review 59(4), on
    non-smooth objectives): ``s_k >= 0`` and ``s_k >= p_k`` at every point, ``s`` in the
    objective with positive quadrature weights, so at the optimum ``s_k = max(p_k, 0)``.
    The problem stays smooth (the kink moves into linear inequalities, which the interior
    point method handles); no smoothing width.

    Returns
    -------
    casadi.MX (1, K)
        The slack variables [W].
    """
    s = opti.variable(1, power.shape[1])
    opti.subject_to(s >= 0)
    opti.subject_to(s >= power)
    opti.set_initial(s, 1e-3)
    return s


def check_objective(spec) -> None:
    """Refuse an objective that is not one of :data:`OBJECTIVES` or their weighted sum.

    Raises
    ------
    ValueError
        An unknown objective or weighted term, or a weighted sum of none (one line).
    """
    if spec.objective == "weighted":
        bad = [k for k, _ in spec.weights if k not in OBJECTIVES]
        if bad or not spec.weights:
            raise ValueError(f"optimize.weights: terms among {', '.join(OBJECTIVES)}")
    elif spec.objective not in OBJECTIVES:
        raise ValueError(f"optimize.objective: one of {', '.join(OBJECTIVES)} or weighted")


def torque_of_time(res: CollocationResult):
    """The optimised hip torque as a function of time [s] -> [N m]: in each interval the
    quadratic through its three points (Hermite-Simpson's control), held outside."""
    t, u = res.t, res.u

    def tau(s: float) -> float:
        s = min(max(float(s), t[0]), t[-1])
        i = min(int((s - t[0]) / (t[2] - t[0])), (len(t) - 3) // 2) * 2
        ti, tm, tj = t[i], t[i + 1], t[i + 2]
        return float(u[i] * (s - tm) * (s - tj) / ((ti - tm) * (ti - tj))
                     + u[i + 1] * (s - ti) * (s - tj) / ((tm - ti) * (tm - tj))
                     + u[i + 2] * (s - ti) * (s - tm) / ((tj - ti) * (tj - tm)))
    return tau


def replay_actuation(data, push_off_n_s: float) -> tuple[object, object]:
    """What a replay of an optimised step acts with: a hip torque law to be replaced by the
    optimised torque of time and the optimised push-off, and the passive rigid walker.

    Parameters
    ----------
    data : WalkerData
        The walker's parameters (massless legs: the torque scales with the foot mass).
    push_off_n_s : float
        The optimised push-off impulse [N s] (a negative one is taken as 0).

    Returns
    -------
    spec : walkerlab.config.actuation.Actuation
        The actuation (``max_torque_n_m`` 1e6: a saturated law is never a generated spring,
        :func:`walkerlab.models.hybrid.actuated.spring_equivalent`, so its torque is the
        Actuators' own, which the replay replaces by the optimised one).
    passive : HybridWalker
        The passive rigid walker of ``data`` (the derived model).
    """
    from walkerlab.config.actuation import Actuation, JointTorque, PushOff, TorqueLaw  # light
    from walkerlab.models.hybrid.rigid import make_rigid_walker  # light

    st = data.structure
    massless = bool(st.bodies) and all(b.massless for b in st.bodies)
    spec = Actuation(push_off=PushOff(impulse_n_s=max(push_off_n_s, 0.0)),
                     torques=[JointTorque(joint="hip", law=TorqueLaw(), max_torque_n_m=1e6,
                                          scaled_by="foot_mass" if massless else "none")])
    return spec, make_rigid_walker(data, "biped", "derived")


def replay(data, res: CollocationResult, solver=None,
           drop_m: float = 0.0) -> tuple[float, object]:
    """The optimised step replayed on the rigid model (its generated code and its own
    phases, guards and reset; not the CasADi expressions the optimisation used): the walker
    of ``data`` with a hip actuator whose torque is :func:`torque_of_time` (from each step's
    heel strike) and the optimised push-off, one step from ``x_0``
    (:func:`walkerlab.integrate.rigid.integrate_step`, DOP853 at rtol = atol = 1e-12 unless
    ``solver`` is given), its heel strike at a landing ``drop_m`` [m] below the stance
    foot's level (stairs, footholds of one height:
    :func:`walkerlab.models.hybrid.ground.on_landing`; 0: the slope's).

    Returns
    -------
    error : float
        Max-norm return error ``|x_0' - x_0|`` (inf when the step does not end in a heel
        strike).
    walker : HybridWalker
        The replayed walker (its Floquet multipliers: :func:`walkerlab.analysis.gait.
        poincare.find_fixed_point` from ``x_0``).
    """
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.hybrid.actuated import actuate  # light

    spec, passive = replay_actuation(data, res.push_off_n_s)
    if drop_m != 0.0:
        from walkerlab.models.hybrid.ground import on_landing

        passive = on_landing(passive, data, drop_m)
    walker = actuate(passive, data, spec)
    acts = walker.actuators
    tau = torque_of_time(res)
    acts.torques = lambda t, x: np.array([tau(float(np.real(t)) - acts.t_origin)])
    zero = np.zeros((1, 2 * acts.n))
    acts.torque_jacobian = lambda t, x: zero  # a torque of time alone: d tau/dx = 0
    solver = solver or Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    seg = integrate_step(walker, np.asarray(res.x[0], float), solver,
                         max_step_time=3.0 * res.step_period_s)
    if seg.termination != "heel_strike":
        return float("inf"), walker
    return float(np.max(np.abs(seg.x_next - res.x[0]))), walker
