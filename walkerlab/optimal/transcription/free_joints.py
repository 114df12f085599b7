"""The least-effort step of a five-link biped by direct collocation (CasADi ``Opti`` +
IPOPT), Kelly's set-up: M. Kelly (2017), "An introduction to trajectory optimization: how to
do your own direct collocation", SIAM Review 59(4):849-904, Sec. 7 and his OptimTraj demo
``demo/fiveLinkBiped`` (step length 0.5 m, step period 0.7 s, minimise ``int |u|^2 dt``,
torques at the hips and knees, no ankle torque).

Transcription (separated Hermite-Simpson: the multi-phase transcription of
:mod:`walkerlab.optimal.transcription.mode_sequence` over the step as one phase): states
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

from dataclasses import dataclass

import numpy as np

from walkerlab.optimal.transcription.ipopt import CollocatedStep

__all__ = ["FiveLinkResult", "collocate_five_link", "kelly_guess", "replay_five_link",
           "step_sequence", "torques_of_time"]


@dataclass(kw_only=True)
class FiveLinkResult(CollocatedStep):
    """An optimised step of a five-link biped: the fields of
    :class:`~walkerlab.optimal.transcription.ipopt.CollocatedStep` (``x`` (m, 10); ``u``
    (m, 4), the joint torques in
    :data:`walkerlab.optimal.transcription.free_joint_functions.JOINTS` order; ``objective``
    ``int |u|^2 dt`` [N^2 m^2 s], Simpson's rule on the points) and this.

    Attributes
    ----------
    cpu_time_s : float
        The solve's CPU time [s] (IPOPT and the function evaluations; not the set-up; as
        ``wall_time_s``).
    """

    cpu_time_s: float


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


def _constrain(opti, fns: dict, X, T, p) -> None:
    """The five-link step's own constraints (module docstring) beside the multi-phase
    transcription's (defects, heel strike at the end moving down, the swing foot above the
    ground inside and ahead at the end, the reset, the torque limit, the targets): the
    trailing foot lifts off at the start, no knee hyper-extension, the joint angles within
    +-pi/2, the period within [0.1, 5] s."""
    import casadi as ca

    K = X.shape[1]
    feet = fns["feet"].map(K)(X, ca.repmat(p, 1, K))  # clearance, ahead, rate, knees
    opti.subject_to(feet[2, 0] >= 0)                     # the trailing foot lifts off
    opti.subject_to(ca.vec(feet[3:5, :]) <= 0)           # no knee hyper-extension
    opti.subject_to(opti.bounded(-np.pi / 2, X[:fns["n"], :], np.pi / 2))
    opti.subject_to(opti.bounded(0.1, T, 5.0))


def step_sequence(fns: dict, p) -> dict:
    """The five-link step as a sequence of one phase for
    :func:`walkerlab.optimal.transcription.mode_sequence.collocate_phases`: its flow with
    the four joint torques (:data:`walkerlab.optimal.transcription.free_joint_functions.
    JOINTS`), the swing foot's height as the heel-strike guard (crossed downward; kept
    >= 0 inside), its rate, the reset, the step length, and the step's own constraints
    (:func:`_constrain`) and IPOPT options; ``p`` the parameter vector."""
    import casadi as ca

    from walkerlab.optimal.transcription.free_joint_functions import JOINTS
    from walkerlab.optimal.transcription.phases import ModePhase

    x, u = ca.SX.sym("x", 2 * fns["n"]), ca.SX.sym("u", len(JOINTS))
    feet = fns["feet"](x, p)
    phase = ModePhase("step", "heel_strike", -1,
                      ca.Function("flow", [x, u], [fns["flow"](x, u, p)]),
                      ca.Function("guard", [x, u], [feet[0]]),
                      ca.Function("guard_rate", [x, u], [feet[2]]),
                      ca.Function("reset", [x], [fns["reset"](x, p)]),
                      clearance=ca.Function("clearance", [x], [feet[0]]),
                      step=ca.Function("step", [x], [feet[1]]))
    return {"phases": [phase], "n": fns["n"], "torques": len(JOINTS),
            "ahead": ca.Function("ahead", [x], [feet[1]]),
            "constrain": lambda opti, Xs, Us, Ts: _constrain(opti, fns, Xs[0], Ts[0], p),
            "solver": ({"expand": True},
                       {"print_level": 0, "tol": 1e-10, "constr_viol_tol": 1e-11,
                        "max_iter": 1000, "sb": "yes"})}


def collocate_five_link(data, spec, fns: dict | None = None) -> FiveLinkResult:
    """Optimise one step of a five-link biped (module docstring): the multi-phase
    transcription (:func:`walkerlab.optimal.transcription.mode_sequence.collocate_phases`)
    over the step as one phase with its four joint torques (:func:`step_sequence`), from
    Kelly's guess (:func:`kelly_guess`) on a uniform mesh.

    Parameters
    ----------
    data : WalkerData
        Of the kind ``free_joints`` (with or without a torso).
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
        A push-off asked for (the capability table's line: ``optimize.push_off: ...``).
    """
    from dataclasses import replace

    import casadi as ca

    from walkerlab.optimal.transcription.free_joint_functions import five_link_functions
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases

    if spec.push_off_free or spec.push_off_n_s:  # the capability table's line
        data.structure.kind.require("push_off", "optimize", "optimize.push_off")
    fns = fns or five_link_functions(data.structure)
    K = 2 * int(spec.intervals) + 1
    p = ca.DM(np.asarray(data.params, float))
    D, Tg = _guess_numbers(data, spec)
    tg, xg = kelly_guess(data.leg_length_m, D, Tg, K)
    # the heel strike moving down (rate <= 0), not at a touchdown rate
    res = collocate_phases(step_sequence(fns, p), replace(spec, touchdown_rate_rad_per_s=0.0),
                           [("step", tg, xg)])
    return FiveLinkResult(
        t=res.t, x=res.x, u=res.u, step_period_s=res.step_period_s,
        step_length_m=res.step_length_m, objective=res.objective, status=res.status,
        iterations=res.iterations, wall_time_s=res.wall_time_s, cpu_time_s=res.cpu_time_s,
        history=res.history)


def torques_of_time(t: np.ndarray, u: np.ndarray):
    """The optimised torques as a function of the time since the heel strike [s] -> (k,)
    [N m]: in each Hermite-Simpson interval the quadratic through its three points (the
    transcription's own control); before ``t_0`` held, after ``t_2N`` the last quadratic
    extrapolated (a replayed step may end slightly later than the collocated one).
    ``t`` (2N + 1,) [s] and ``u`` (2N + 1, k) [N m] are the collocation times and the
    torques there (as :func:`walkerlab.optimal.replay.phase.control_of_time`'s).
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
    from walkerlab.config.actuation import Actuation, JointTorque, TorqueLaw  # light
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.hybrid.actuated import actuate  # light
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
