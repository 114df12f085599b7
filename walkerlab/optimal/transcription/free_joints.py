"""The least-effort step of a five-link biped by direct collocation (CasADi ``Opti`` +
IPOPT), Kelly's set-up: M. Kelly (2017), "An introduction to trajectory optimization: how to
do your own direct collocation", SIAM Review 59(4):849-904, Sec. 7 and his OptimTraj demo
``demo/fiveLinkBiped`` (step length 0.5 m, step period 0.7 s, minimise ``int |u|^2 dt``,
torques at the hips and knees, no ankle torque).

Transcription (separated Hermite-Simpson, as :mod:`walkerlab.optimal.transcription.step`): states
``x_k`` (10,) and torques ``u_k`` (4,:
:data:`walkerlab.optimal.transcription.free_joint_functions.JOINTS`) at
``2N + 1`` points on ``[0, T]``; the flow, the feet and the reset are the walker's own
symbolic model (:func:`walkerlab.optimal.transcription.free_joint_functions.five_link_functions`).
Constraints:

- periodic through the heel strike: ``x_0 = reset(x_2N)`` (Kelly's ``cst_heelStrike``);
- the step ends on the ground, ``step length`` ahead (``cst_stepLength``), the swing foot
  moving down there and up at the start (``cst_footVel``);
- the swing foot above the ground at every interior point (``clearance >= 0``);
- no knee hyper-extension: ``shank - thigh <= 0`` on both legs (``pathConstraint``);
- ``|u| <= max_torque_n_m``; the target step length / period / speed given.

The initial guess is Kelly's kind: straight legs swapping at constant rates between the
heel-strike postures of the target step, with a swing-knee bend (so the guess clears the
ground), zero torques.

Replay: the rigid five-link model (:func:`walkerlab.models.hybrid.rigid.make_rigid_walker`,
its generated code, guards and reset) with the torques as a function of the time since the
heel strike (:func:`torques_of_time`), one step from ``x_0`` (scipy's DOP853 at 1e-12).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from walkerlab.optimal.transcription.ipopt import iteration_history, solve
from walkerlab.optimal.transcription.step import target_constraints

__all__ = ["FiveLinkResult", "collocate_five_link", "kelly_guess", "replay_five_link",
           "torques_of_time"]


@dataclass
class FiveLinkResult:
    """An optimised step of a five-link biped.

    Attributes
    ----------
    t : ndarray (2N + 1,)
        Collocation times [s].
    x : ndarray (2N + 1, 10)
        States there (the walker's ``state_names()`` order).
    u : ndarray (2N + 1, 4)
        Joint torques [N m] (:data:`walkerlab.optimal.transcription.free_joint_functions.JOINTS`
        order).
    step_period_s, step_length_m : float
    objective : float
        ``int |u|^2 dt`` [N^2 m^2 s] (Simpson's rule on the points).
    status : str
        IPOPT's return status.
    iterations : int
    wall_time_s, cpu_time_s : float
        The solve's (IPOPT and the function evaluations; not the set-up).
    history : dict of str -> ndarray
        IPOPT's iteration history (:func:`walkerlab.optimal.transcription.ipopt.iteration_history`).
    """

    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    step_period_s: float
    step_length_m: float
    objective: float
    status: str
    iterations: int
    wall_time_s: float
    cpu_time_s: float
    history: dict = field(default_factory=dict)


def kelly_guess(leg_length_m: float, step_length_m: float, period_s: float, points: int):
    """A guess step (module docstring): ``(t (m,), x (m, 10))``; ``reset`` maps its end onto
    its start (straight legs at ``+-a``, ``sin a = step / (2 L)``, the torso upright)."""
    a = float(np.arcsin(min(step_length_m / (2.0 * leg_length_m), 0.9)))
    t = np.linspace(0.0, period_s, points)
    s, w = t / period_s, np.pi / period_s
    lin, dlin = a * (1.0 - 2.0 * s), np.full_like(s, -2.0 * a / period_s)
    bump, dbump = np.sin(np.pi * s), w * np.cos(np.pi * s)
    q = np.stack([lin, lin, -lin + 0.2 * bump, -lin - 0.5 * bump, 0.0 * s], axis=1)
    dq = np.stack([dlin, dlin, -dlin + 0.2 * dbump, -dlin - 0.5 * dbump, 0.0 * s], axis=1)
    return t, np.hstack([q, dq])


def _guess_numbers(data, spec):
    """The guess's step length [m] and period [s]: the targets, else a 0.5 m step at 0.7 s."""
    T = spec.target_step_period_s
    D = spec.target_step_length_m
    v = spec.target_speed_m_per_s
    if D is None:
        D = v * T if (v is not None and T is not None) else 0.625 * data.leg_length_m
    if T is None:
        T = D / v if v is not None else 0.7
    return D, T


def _constrain(opti, fns: dict, spec, X, U, T, p) -> None:
    """The step's constraints (module docstring) on the decision variables ``X`` (2n, K),
    ``U`` (4, K) and ``T``."""
    import casadi as ca

    K = X.shape[1]
    h = T / ((K - 1) // 2)
    F = fns["flow"].map(K)(X, U, ca.repmat(p, 1, K))
    feet = fns["feet"].map(K)(X, ca.repmat(p, 1, K))  # clearance, ahead, rate, knees
    i, m, j = np.arange(0, K - 1, 2), np.arange(1, K, 2), np.arange(2, K, 2)
    opti.subject_to(X[:, m] == 0.5 * (X[:, i] + X[:, j]) + h / 8 * (F[:, i] - F[:, j]))
    opti.subject_to(X[:, j] == X[:, i] + h / 6 * (F[:, i] + 4 * F[:, m] + F[:, j]))
    opti.subject_to(X[:, 0] == fns["reset"](X[:, -1], p))
    opti.subject_to(feet[0, -1] == 0)                    # heel strike at the end
    opti.subject_to(feet[2, -1] <= 0)                    # ... moving down
    opti.subject_to(feet[2, 0] >= 0)                     # the trailing foot lifts off
    opti.subject_to(feet[0, 1:-1] >= 0)                  # above the ground in between
    opti.subject_to(ca.vec(feet[3:5, :]) <= 0)           # no knee hyper-extension
    opti.subject_to(feet[1, -1] >= 1e-3)                 # the swing foot ahead
    opti.subject_to(opti.bounded(-np.pi / 2, X[:fns["n"], :], np.pi / 2))
    opti.subject_to(opti.bounded(0.1, T, 5.0))
    if spec.max_torque_n_m is not None:
        opti.subject_to(opti.bounded(-spec.max_torque_n_m, U, spec.max_torque_n_m))
    target_constraints(opti, spec, T, feet[1, -1])


def collocate_five_link(data, spec, fns: dict | None = None) -> FiveLinkResult:
    """Optimise one step of a five-link biped (module docstring).

    Parameters
    ----------
    data : WalkerData
        ``structure.free_knees`` set (with or without a torso).
    spec : walkerlab.optimal.transcription.step.CollocationSpec
        ``intervals``, ``max_torque_n_m`` and the targets (its push-off fields must be off).
    fns : dict, optional
        :func:`walkerlab.optimal.transcription.free_joint_functions.five_link_functions` (looked up
        when not given).

    Returns
    -------
    FiveLinkResult

    Raises
    ------
    ValueError
        A push-off asked for (one line).
    """
    import casadi as ca

    from walkerlab.optimal.transcription.free_joint_functions import five_link_functions

    if spec.push_off_free or spec.push_off_n_s:
        raise ValueError("optimize.push_off: a five-link biped has no push-off (its hips and "
                         "knees are driven)")
    fns = fns or five_link_functions(data.structure)
    n2, N = 2 * fns["n"], int(spec.intervals)
    K = 2 * N + 1
    p = ca.DM(np.asarray(data.params, float))
    opti = ca.Opti()
    X, U = opti.variable(n2, K), opti.variable(4, K)
    T = opti.variable()
    h = T / N
    _constrain(opti, fns, spec, X, U, T, p)
    weights = np.concatenate([[1.0], np.tile([4.0, 2.0], N)[:K - 2], [1.0]])
    effort = h / 6 * ca.sum2(ca.DM(weights).T * ca.sum1(U ** 2))
    opti.minimize(effort)
    D, Tg = _guess_numbers(data, spec)
    _, xg = kelly_guess(data.leg_length_m, D, Tg, K)
    opti.set_initial(T, Tg)
    opti.set_initial(X, xg.T)
    opti.set_initial(U, 0.0)
    opti.solver("ipopt", {"print_time": False, "expand": True},
                {"print_level": 0, "tol": 1e-10, "constr_viol_tol": 1e-11, "max_iter": 1000,
                 "sb": "yes"})
    status, get, wall, cpu = solve(opti)
    Tv = float(get(T))
    Xv = np.asarray(get(X)).reshape(n2, K).T
    Uv = np.asarray(get(U)).reshape(4, K).T
    return FiveLinkResult(
        t=np.linspace(0.0, Tv, K), x=Xv, u=Uv, step_period_s=Tv,
        step_length_m=float(np.asarray(fns["feet"](Xv[-1], p))[1, 0]),
        objective=float(get(effort)), status=status,
        iterations=int(opti.stats().get("iter_count", -1)), wall_time_s=wall, cpu_time_s=cpu,
        history=iteration_history(opti.stats()))


def torques_of_time(t: np.ndarray, u: np.ndarray):
    """The optimised torques as a function of the time since the heel strike [s] -> (k,)
    [N m]: in each Hermite-Simpson interval the quadratic through its three points (the
    transcription's own control); before ``t_0`` held, after ``t_2N`` the last quadratic
    extrapolated (a replayed step may end slightly later than the collocated one).

    Parameters
    ----------
    t : ndarray (2N + 1,)
        Collocation times [s].
    u : ndarray (2N + 1, k)
        Torques there [N m].
    """
    t, u = np.asarray(t, float), np.asarray(u, float).reshape(len(t), -1)
    nint = (len(t) - 1) // 2

    def tau(s: float) -> np.ndarray:
        s = max(float(s), t[0])
        i = 2 * min(int((s - t[0]) / (t[2] - t[0])), nint - 1)
        ti, tm, tj = t[i], t[i + 1], t[i + 2]
        return (u[i] * (s - tm) * (s - tj) / ((ti - tm) * (ti - tj))
                + u[i + 1] * (s - ti) * (s - tj) / ((tm - ti) * (tm - tj))
                + u[i + 2] * (s - ti) * (s - tm) / ((tj - ti) * (tj - tm)))
    return tau


def replay_five_link(data, res: FiveLinkResult, x0: np.ndarray | None = None, solver=None):
    """One step of the rigid five-link model (its generated code, its own phases, guards and
    reset: not the CasADi expressions the optimisation used) from ``res.x[0]`` with the
    torques :func:`torques_of_time` of ``res`` (open loop), or from ``x0`` (the closed
    start of :func:`walkerlab.optimal.replay.shooting.close_step`).

    Parameters
    ----------
    data : WalkerData
    res : FiveLinkResult
    x0 : ndarray (2n,), optional
        The start (default ``res.x[0]``); the return error is measured against it.
    solver : walkerlab.integrate.solver.Solver, optional
        Default DOP853 at rtol = atol = 1e-12.

    Returns
    -------
    error : float
        Max-norm return error ``|x_0' - x_0|`` [rad, rad/s] (inf when the step does not end
        in a heel strike).
    walker : HybridWalker
        The replayed walker (open-loop torques of the time since each heel strike).
    segment : walkerlab.integrate.rigid segment
        The replayed step.
    """
    from walkerlab.config.actuation import Actuation, JointTorque, TorqueLaw
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.hybrid.actuated import actuate
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.transcription.free_joint_functions import JOINTS

    spec = Actuation(torques=[JointTorque(joint=j, law=TorqueLaw(), max_torque_n_m=1e6)
                              for j in JOINTS])
    walker = actuate(make_rigid_walker(data, "biped", "derived"), data, spec)
    acts = walker.actuators
    tau = torques_of_time(res.t, res.u)
    acts.torques = lambda t, x: tau(float(np.real(t)) - acts.t_origin)
    solver = solver or Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    start = np.asarray(res.x[0] if x0 is None else x0, float)
    seg = integrate_step(walker, start, solver, max_step_time=3.0 * res.step_period_s)
    if seg.termination != "heel_strike":
        return float("inf"), walker, seg
    return float(np.max(np.abs(seg.x_next - start))), walker, seg
