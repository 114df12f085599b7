"""A periodic hybrid gait by direct collocation (CasADi ``Opti`` + IPOPT): one step of a
walker with a hip torque (and a push-off), the heel-strike reset as the periodic boundary
condition, the step period free.

Transcription (Kelly 2017, "An introduction to trajectory optimization: how to do your own
direct collocation", SIAM Review 59(4):849-904, Sec. 4, separated Hermite-Simpson): states
``x_k`` and the hip torque ``u_k`` at ``2N + 1`` points on ``[0, T]`` (``N`` intervals of
``h = T / N``, their mid-points at odd ``k``); per interval ``i -> m -> j``::

    x_m = (x_i + x_j) / 2 + h (f_i - f_j) / 8,      x_j = x_i + h (f_i + 4 f_m + f_j) / 6

with ``f = [dq, M(q)^-1 (B u - C(q, dq) dq - G(q))]`` from the walker's generated symbolic
equations (:func:`walkerlab.codegen.symbolic.derive`, paper Eq. 3 with ``B u``; ``B`` the
hip angle's gradient, so ``+u`` acts on the swing leg and ``-u`` on the stance leg as in
:mod:`walkerlab.models.actuation`).  The end is a heel strike (the generated guard = 0, the
swing foot ahead); the step's start is the end mapped by push-off + heel strike + role swap
(the extended-coordinate impact of :mod:`walkerlab.models.hybrid.actuated`, symbolic here):
``x_0 = reset(x_2N)``.  Objective: the effort ``int u^2 dt`` (Simpson's rule on the same
points), with the push-off's weighted square ``w P^2`` added when it is free.  Constraints:
optional target speed, step length or step period, a torque limit.

A result is called a gait only after its **replay**: the rigid model integrated (scipy's
DOP853 at 1e-12) from ``x_0`` with the optimised torque as a function of time (piecewise
quadratic through the points, Hermite-Simpson's control), until its heel strike, then the
same reset; the return error ``|x_0' - x_0|`` is stored.

Straight legs with point feet (the walkers whose push-off the rigid view carries in
extended coordinates); one hip torque.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

__all__ = ["CollocationResult", "CollocationSpec", "collocate_step", "replay", "step_functions",
           "torque_of_time"]


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


@dataclass
class CollocationResult:
    """An optimised step.

    Attributes
    ----------
    t : ndarray (2N + 1,)
        Collocation times [s].
    x : ndarray (2N + 1, 2n)
        States there (the rigid walker's ``state_names()`` order).
    u : ndarray (2N + 1,)
        Hip torque [N m].
    step_period_s, step_length_m, push_off_n_s : float
    objective : float
        ``int u^2 dt`` [N^2 m^2 s] (+ the push-off's weighted work when it is free).
    status : str
        IPOPT's return status.
    iterations : int
    wall_time_s : float
    replay_error : float
        Max-norm return error of the replay (module docstring).
    """

    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    step_period_s: float
    step_length_m: float
    push_off_n_s: float
    objective: float
    status: str
    iterations: int
    wall_time_s: float
    replay_error: float = np.nan


def _to_casadi(exprs, syms, values: dict):
    """A CasADi function of ``syms`` (sympy) computing the sympy matrix ``exprs`` with the
    parameters ``values`` substituted (SX in, SX matrix out)."""
    import casadi as ca
    import sympy as sp

    mat = sp.Matrix(exprs).subs(values)
    f = sp.lambdify(syms, mat, modules=[{"sin": ca.sin, "cos": ca.cos, "sqrt": ca.sqrt,
                                         "Abs": ca.fabs, "ImmutableDenseMatrix": list,
                                         "MutableDenseMatrix": list}, "math"])
    args = [ca.SX.sym(str(s)) for s in syms]
    rows = f(*args)
    out = ca.vertcat(*[ca.horzcat(*[ca.SX(v) if not isinstance(v, ca.SX) else v for v in r])
                       for r in rows])
    return ca.Function("f", [ca.vertcat(*args)], [out])


def step_functions(data, eq):
    """CasADi functions of one step of ``data`` (a WalkerData with straight legs and point
    feet) from its symbolic equations ``eq``: ``flow(x, u)`` (2n,), ``guard(x)`` (the heel
    strike, 0 at it), ``ahead(x)`` (> 0: the swing foot ahead), ``step(x)`` (the feet's
    distance [m]) and ``reset(x, P)`` (push-off ``P`` [N s] + heel strike + role swap).

    Raises
    ------
    ValueError
        Knees, arc or flat feet, massless legs (one line).
    """
    import casadi as ca
    import sympy as sp

    st = data.structure
    if st.knee or st.foot != "point" or any(b.massless for b in st.bodies) or st.torso:
        raise ValueError("optimize: straight legs with point feet and massive legs only "
                         "today (knees, arc and flat feet, a torso, massless legs: not yet)")
    n = len(eq.q)
    vals = dict(zip(eq.params, data.params))
    q, dq = list(eq.q), list(eq.dq)
    xs = q + dq
    M = _to_casadi(eq.M, xs, vals)
    C = _to_casadi(eq.C, xs, vals)
    G = _to_casadi(eq.G, xs, vals)
    delta = eq.leg_angles["swing"] - eq.leg_angles["stance"]
    B = _to_casadi(sp.Matrix([delta]).jacobian(q).T, xs, vals)
    x = ca.SX.sym("x", 2 * n)
    u = ca.SX.sym("u")
    qdd = ca.solve(M(x), B(x) * u - C(x) @ x[n:] - G(x))
    flow = ca.Function("flow", [x, u], [ca.vertcat(x[n:], qdd)])
    guard = ca.Function("guard", [x], [_to_casadi([eq.guards["heel_strike"]], xs, vals)(x)])
    ahead = ca.Function("ahead", [x], [_to_casadi([eq.guards["swing_foot_ahead"]], xs,
                                                  vals)(x)])
    foot = _to_casadi(eq.points["swing_foot"], xs, vals)(x)
    step = ca.Function("step", [x], [ca.sqrt(foot[0] ** 2 + foot[1] ** 2)])
    # push-off + heel strike in extended coordinates [q, x_f, y_f]
    qe = list(eq.q) + [sp.Symbol("x_f"), sp.Symbol("y_f")]
    De = _to_casadi(eq.De.subs({qe[n]: 0, qe[n + 1]: 0}), xs, vals)(x)
    E = _to_casadi(eq.E.subs({qe[n]: 0, qe[n + 1]: 0}), xs, vals)(x)
    hip = _to_casadi(eq.points["hip"], xs, vals)(x)
    e = hip / ca.sqrt(hip[0] ** 2 + hip[1] ** 2)
    P = ca.SX.sym("P")
    dqe = ca.vertcat(x[n:], 0, 0)
    Ef = ca.horzcat(ca.SX.zeros(2, n), ca.SX.eye(2))
    dqe_po = dqe + ca.solve(De, Ef.T @ (P * e))
    K = ca.vertcat(ca.horzcat(De, -E.T), ca.horzcat(E, ca.SX.zeros(2, 2)))
    sol = ca.solve(K, ca.vertcat(De @ dqe_po, 0, 0))
    qn = _to_casadi(eq.relabel_q, xs, vals)(x)
    R = np.array(eq.relabel_rate.subs(vals), float)
    reset = ca.Function("reset", [x, P], [ca.vertcat(qn, ca.DM(R) @ sol[:n])])
    return {"flow": flow, "guard": guard, "ahead": ahead, "step": step, "reset": reset,
            "n": n}


def collocate_step(data, eq, spec: CollocationSpec, guess_t: np.ndarray,
                   guess_x: np.ndarray, guess_u: np.ndarray | None = None,
                   fns: dict | None = None) -> CollocationResult:
    """Optimise one step (module docstring).

    Parameters
    ----------
    data : WalkerData
    eq : Equations
        ``walkerlab.codegen.symbolic.derive(data.structure)``.
    spec : CollocationSpec
    guess_t : ndarray (m,)
        Times [s] of a guess step (e.g. a simulated gait from heel strike to heel strike).
    guess_x : ndarray (m, 2n)
        Its states.
    guess_u : ndarray (m,), optional
        Its hip torque [N m] (default 0).
    fns : dict, optional
        :func:`step_functions` of the walker (built when not given).

    Returns
    -------
    CollocationResult

    Raises
    ------
    ValueError
        A walker this transcription does not handle (one line).
    """
    import casadi as ca

    fns = fns or step_functions(data, eq)
    n2, N = 2 * fns["n"], int(spec.intervals)
    K = 2 * N + 1
    opti = ca.Opti()
    X = opti.variable(n2, K)
    U = opti.variable(1, K)
    T = opti.variable()
    P = opti.variable() if spec.push_off_free else spec.push_off_n_s
    h = T / N
    f = [fns["flow"](X[:, k], U[k]) for k in range(K)]
    for i in range(0, K - 1, 2):
        m, j = i + 1, i + 2
        opti.subject_to(X[:, m] == 0.5 * (X[:, i] + X[:, j]) + h / 8 * (f[i] - f[j]))
        opti.subject_to(X[:, j] == X[:, i] + h / 6 * (f[i] + 4 * f[m] + f[j]))
    opti.subject_to(fns["guard"](X[:, -1]) == 0)
    opti.subject_to(fns["ahead"](X[:, -1]) >= 1e-3)
    opti.subject_to(X[:, 0] == fns["reset"](X[:, -1], P))
    opti.subject_to(opti.bounded(0.05 * guess_t[-1], T, 5.0 * guess_t[-1]))
    if spec.max_torque_n_m is not None:
        opti.subject_to(opti.bounded(-spec.max_torque_n_m, U, spec.max_torque_n_m))
    length = fns["step"](X[:, -1])
    if spec.target_step_period_s is not None:
        opti.subject_to(T == spec.target_step_period_s)
    if spec.target_step_length_m is not None:
        opti.subject_to(length == spec.target_step_length_m)
    if spec.target_speed_m_per_s is not None:
        opti.subject_to(length == spec.target_speed_m_per_s * T)
    w = np.tile([4.0, 2.0], N)[:K - 2]
    weights = np.concatenate([[1.0], w, [1.0]])  # Simpson on the 2N + 1 points
    effort = h / 6 * ca.sum2(ca.DM(weights).T * U ** 2)
    obj = effort
    if spec.push_off_free:
        opti.subject_to(opti.bounded(0.0, P, spec.push_off_max_n_s))
        obj = obj + spec.push_off_weight * P ** 2
    opti.minimize(obj)
    tk = np.linspace(0.0, 1.0, K) * guess_t[-1]
    opti.set_initial(T, float(guess_t[-1]))
    opti.set_initial(X, np.stack([np.interp(tk, guess_t, guess_x[:, c])
                                  for c in range(n2)]))
    opti.set_initial(U, np.interp(tk, guess_t, np.zeros_like(guess_t)
                                  if guess_u is None else guess_u)[None])
    if spec.push_off_free:
        opti.set_initial(P, spec.push_off_n_s)
    opti.solver("ipopt", {"print_time": False},
                {"print_level": 0, "tol": 1e-12, "acceptable_tol": 1e-10, "max_iter": 500,
                 "sb": "yes"})
    t0 = time.perf_counter()
    try:
        sol = opti.solve()
        status, get = "Solve_Succeeded", sol.value
    except RuntimeError:
        status, get = str(opti.stats().get("return_status", "failed")), opti.debug.value
    wall = time.perf_counter() - t0
    Tv = float(get(T))
    Xv, Uv = np.asarray(get(X)).reshape(n2, K).T, np.asarray(get(U)).ravel()
    return CollocationResult(
        t=np.linspace(0.0, Tv, K), x=Xv, u=Uv, step_period_s=Tv,
        step_length_m=float(fns["step"](Xv[-1])),
        push_off_n_s=float(get(P)) if spec.push_off_free else float(spec.push_off_n_s),
        objective=float(get(obj)), status=status,
        iterations=int(opti.stats().get("iter_count", -1)), wall_time_s=wall)


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


def replay(data, res: CollocationResult, solver=None) -> tuple[float, object]:
    """The optimised step replayed on the rigid model (its generated code and its own
    phases, guards and reset; not the CasADi expressions the optimisation used): the walker
    of ``data`` with a hip actuator whose torque is :func:`torque_of_time` (from each step's
    heel strike) and the optimised push-off, one step from ``x_0``
    (:func:`walkerlab.integrate.rigid.integrate_step`, DOP853 at rtol = atol = 1e-12 unless
    ``solver`` is given).

    Returns
    -------
    error : float
        Max-norm return error ``|x_0' - x_0|`` (inf when the step does not end in a heel
        strike).
    walker : HybridWalker
        The replayed walker (its Floquet multipliers: :func:`walkerlab.analysis.gait.
        poincare.find_fixed_point` from ``x_0``).
    """
    from walkerlab.config.actuation import Actuation, JointTorque, PushOff, TorqueLaw
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.hybrid.actuated import actuate
    from walkerlab.models.hybrid.rigid import make_rigid_walker

    # a saturated law is never a generated spring (models.hybrid.actuated.spring_equivalent):
    # its torque is the Actuators' own, which is replaced by the optimised one below
    spec = Actuation(push_off=PushOff(impulse_n_s=max(res.push_off_n_s, 0.0)),
                     torques=[JointTorque(joint="hip", law=TorqueLaw(), max_torque_n_m=1e6)])
    walker = actuate(make_rigid_walker(data, "biped", "derived"), data, spec)
    acts = walker.actuators
    tau = torque_of_time(res)
    acts.torques = lambda t, x: np.array([tau(float(np.real(t)) - acts.t_origin)])
    solver = solver or Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    seg = integrate_step(walker, np.asarray(res.x[0], float), solver,
                         max_step_time=3.0 * res.step_period_s)
    if seg.termination != "heel_strike":
        return float("inf"), walker
    return float(np.max(np.abs(seg.x_next - res.x[0]))), walker
