"""The one multi-phase transcription of ``walkerlab optimize``: a step (or a stride) as a
sequence of the walker's phases (:mod:`walkerlab.optimal.transcription.phases`; a kneed
walker's unlocked and locked swing, flat feet's modes, a stride's steps of the walker and
its mirror: :mod:`walkerlab.optimal.transcription.stride`) optimised by Hermite-Simpson
collocation per phase (CasADi ``Opti`` + IPOPT), its starting guess from the rigid model's
own step and its replay on the rigid model.  One step of straight legs is the sequence of
one phase (:func:`collocate_step`: its flow, heel-strike guard and reset, push-off
included, from :func:`walkerlab.optimal.transcription.step.step_functions`, on a uniform
mesh; the transcription of :mod:`walkerlab.optimal.transcription.step`'s docstring); a
five-link biped's step is one phase with its four joint torques
(:func:`walkerlab.optimal.transcription.free_joints.step_sequence`: its own constraints and
IPOPT options beside).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from walkerlab.config.actuation import Actuation, JointTorque, PushOff, TorqueLaw
from walkerlab.models.hybrid.actuated import actuate
from walkerlab.optimal.transcription.ipopt import (
    CollocatedStep,
    iteration_history,
    largest_violations,
    solve,
)
from walkerlab.optimal.transcription.phase_nlp import _chain_phases, _objective, _pushes

__all__ = ["PhasedResult", "collocate_footholds", "collocate_phases", "collocate_step",
           "footholds_guess", "optimized_guess",
           "phase_torque_of_time", "phased_guess", "replay_phases", "step_phase"]

#: objectives the phased transcription takes
#: (:data:`walkerlab.optimal.transcription.step.OBJECTIVES`)
PHASED_OBJECTIVES = ("effort", "cost_of_transport", "peak_torque")

@dataclass(kw_only=True)
class PhasedResult(CollocatedStep):
    """An optimised step of a walker with phases: the fields of
    :class:`~walkerlab.optimal.transcription.ipopt.CollocatedStep` (``t`` every phase's
    ``2 N_p + 1`` points in turn, a phase's first time repeating the previous phase's last:
    the state jumps there; ``u`` (m,) the hip torque) and these.

    Attributes
    ----------
    phase_names : tuple of str
    phase_start : ndarray (P,) of int
        Index in ``t`` of each phase's first point.
    phase_duration_s : ndarray (P,)
    build_time_s, cpu_time_s : float
        Building the programme; IPOPT's CPU (user + sys) time.
    terms : dict
        ``effort`` [N^2 m^2 s], ``cost_of_transport`` [-] (the hip's positive work per
        weight and step length; exact, ``max(p, 0)`` at the points) and ``peak_torque``
        [N m] at the optimum.
    violations : str
        When IPOPT did not converge: the constraint groups with the largest violation at
        its last iterate (:func:`walkerlab.optimal.transcription.ipopt.largest_violations`;
        ``""``: none, or it converged).
    """

    phase_names: tuple
    phase_start: np.ndarray
    phase_duration_s: np.ndarray
    build_time_s: float
    cpu_time_s: float
    terms: dict = field(default_factory=dict)
    push_off_n_s: float = 0.0
    violations: str = ""


def phased_guess(walker, x0, period_s: float, solver, intervals: int):
    """One step of the rigid ``walker`` from the post-impact state ``x0`` (2n,), each
    phase sampled on its own mesh of ``N_p`` intervals (their mid-points halfway), the
    ``intervals`` shared among the phases and placed within each by
    :func:`mesh_density` (at least 3 a phase): Hermite-Simpson's error per interval,
    ``~ h^5 |x^(5)|``, is then about the same in every interval (de Boor's equidistribution;
    Betts 2010, Ch. 4.7), so a fast transient (a flat foot's ankle after heel strike) gets
    short intervals and a slow phase long ones.

    Returns
    -------
    guess : list of (name, t (2 N_p + 1,) [s from the phase's start], x (2 N_p + 1, 2n))
    phase_log : list
        The step's :attr:`walkerlab.integrate.rigid.Segment.phase_log` (its phase
        sequence: :func:`walkerlab.optimal.transcription.phases.phase_order`).

    Raises
    ------
    ValueError
        As :func:`walkerlab.optimal.guess.starting_segment`: the step does not end in a heel
        strike (one line).
    """
    from walkerlab.optimal.guess import starting_segment

    x0 = np.asarray(x0, float)
    seg = starting_segment(walker, x0, period_s, solver)
    dens = [mesh_density(ph, sol, a, b, x0.size) for ph, sol, (a, b) in seg.pieces]
    total = sum(c[-1] for _t, c in dens)
    out = []
    for (ph, sol, (a, b)), (tf, cum) in zip(seg.pieces, dens):
        # half by the density, half by the duration (the density alone starves a slow phase
        # whose errors the resets carry on: the kneed walker's locked swing)
        cum = 0.5 * cum / total + 0.5 * (tf - tf[0]) / (seg.t_end - seg.t_start)
        N = max(3, int(round(intervals * cum[-1])))
        ends = np.interp(np.linspace(0.0, cum[-1], N + 1), cum, tf)
        t = np.empty(2 * N + 1)
        t[0::2], t[1::2] = ends, 0.5 * (ends[:-1] + ends[1:])
        t[0], t[-1] = a, b
        out.append((ph.name, t - a, np.asarray(sol(t), float)[:x0.size].T))
    return out, seg.phase_log


def optimized_guess(d, names: list, intervals: int):
    """Another optimisation's step (an ``optimize.h5`` of a walker with phases, read by
    :func:`walkerlab.io.schemas.optimize.load`) as the starting guess: each phase's states
    and torque on its own mesh, its ``N_p`` rescaled so that they sum to about
    ``intervals`` (at least 3 a phase; the artifact's mesh density kept, its interval ends
    interpolated, the points linearly; unchanged when the counts agree).

    Parameters
    ----------
    d : walkerlab.io.schemas.optimize.OptimizeData
    names : list of str
        The phases the scene's gait goes through (the guess's must be the same).
    intervals : int

    Returns
    -------
    guess : list of (name, t (2 N_p + 1,) [s from the phase's start], x (2 N_p + 1, 2n))
    torque : list of ndarray (2 N_p + 1,) [N m]

    Raises
    ------
    ValueError
        The artifact has no phases (a one-step optimisation) or other ones (one line
        naming ``optimize.initial_guess``).
    """
    if not d.phase_names or d.phase_start is None:
        raise ValueError("optimize.initial_guess: the optimize.h5 has no phases (a one-step "
                         "optimisation): give one of this walker (its phases "
                         f"{', '.join(names)})")
    if list(d.phase_names) != list(names):
        raise ValueError(f"optimize.initial_guess: its phases {list(d.phase_names)} are not "
                         f"the scene gait's {list(names)}")
    X = np.stack(list(d.states.values()), axis=1)
    bounds = list(np.asarray(d.phase_start, int)) + [d.time.size]
    counts = [(b - a - 1) // 2 for a, b in zip(bounds[:-1], bounds[1:])]
    guess, torque = [], []
    for name, a, b, n_old in zip(names, bounds[:-1], bounds[1:], counts):
        t, u = np.asarray(d.time[a:b], float), np.asarray(d.torque[a:b], float)
        n_new = max(3, int(round(intervals * n_old / sum(counts))))
        tn = t
        if n_new != n_old:
            ends = np.interp(np.linspace(0.0, n_old, n_new + 1), np.arange(n_old + 1), t[0::2])
            tn = np.empty(2 * n_new + 1)
            tn[0::2], tn[1::2] = ends, 0.5 * (ends[:-1] + ends[1:])
        xn = np.stack([np.interp(tn, t, X[a:b, c]) for c in range(X.shape[1])], axis=1)
        guess.append((name, tn - tn[0], xn))
        torque.append(np.interp(tn, t, u))
    return guess, torque


def mesh_density(phase, sol, a: float, b: float, n2: int, samples: int = 401):
    """The cumulative mesh density of a phase on ``[a, b]`` [s]: ``int rho dt`` with
    ``rho = max_i |x_i^(5)|^(1/5)`` (the fifth derivative from the phase's flow ``f``
    along the dense output ``sol``, differentiated four times by finite differences on
    ``samples`` points; within 1/40 of the ends, where the differences are one-sided, the
    nearest value inside), floored at a tenth of its mean (no interval starves).

    Returns
    -------
    t : ndarray (samples,) [s]
    cum : ndarray (samples,)
        ``int_a^t rho``, increasing, ``cum[0] = 0``.
    """
    from scipy.integrate import cumulative_trapezoid

    t = np.linspace(a, b, samples)
    x = np.asarray(sol(t), float)[:n2]
    d = np.stack([np.asarray(phase.flow(tk, x[:, k]), float) for k, tk in enumerate(t)], 1)
    for _ in range(4):
        d = np.gradient(d, t, axis=1) if b > a else d
    rho = np.max(np.abs(d), axis=0) ** 0.2
    edge = max(1, samples // 40)  # one-sided differences at the ends: their nearest inside
    rho[:edge], rho[-edge:] = rho[edge], rho[-edge - 1]
    rho = np.maximum(rho, 0.1 * max(rho.mean(), 1e-300)) + 1e-300
    return t, cumulative_trapezoid(rho, t, initial=0.0)


#: why a sequence of phases whose heel strike has no push-off map is not optimised with a
#: push-off (one line; every kind with phases has one: the capability table,
#: :data:`walkerlab.walker.kinds.CAPABILITIES`, refuses the others before)
PHASED_PUSH_OFF = ("optimize.push_off: this step's heel strike has no push-off map in the "
                   "collocation (give optimize.push_off: fixed and no "
                   "walker.actuation.push_off)")


def _check(spec, phases) -> None:
    """Refuse what the phased transcription does not take (one line)."""
    asked = dict(spec.weights) if spec.objective == "weighted" else {spec.objective: 1.0}
    strikes = [p for p in phases if p.guard_name == "heel_strike"]
    pushes = _pushes(spec) and bool(strikes) and all(p.push_off is not None for p in strikes)
    known = PHASED_OBJECTIVES + (("push_off_work",) if pushes else ())
    bad = [k for k in asked if k not in known]
    if bad:
        raise ValueError(f"optimize.objective: a walker with phases takes "
                         f"{' or '.join(known)} (or their weighted sum) today")
    if _pushes(spec) and not pushes:
        raise ValueError(PHASED_PUSH_OFF)


def collocate_phases(fns: dict, spec, guess: list, guess_u: list | None = None
                     ) -> PhasedResult:
    """Optimise one step phase by phase (:mod:`walkerlab.optimal.transcription.phases`), or a
    stride of
    steps (legs that differ, :mod:`walkerlab.optimal.transcription.stride`: a ``heel_strike`` phase
    inside the sequence ends a step; every heel strike has the swing foot ahead, each step
    its own clearance ends, and the targets are the mean step's).

    Parameters
    ----------
    fns : dict
        :func:`walkerlab.optimal.transcription.phases.mode_functions` of the walker (or a
        sequence of the same keys: :func:`step_phase`'s, :func:`walkerlab.optimal.
        transcription.free_joints.step_sequence`); optional keys: ``torques`` (torques at
        every point, default 1: ``u`` (k,) then, its effort ``int |u|^2 dt``), ``power``
        (absent: no cost of transport), ``constrain(opti, Xs, Us, Ts)`` (a walker's own
        constraints on the decision variables) and ``solver`` (``(plugin options, IPOPT
        options)``, default :func:`walkerlab.optimal.transcription.step.ipopt_options`).
    spec : walkerlab.optimal.transcription.step.CollocationSpec
        Its ``intervals`` are shared among the phases by ``guess``'s meshes.
    guess : list of (name, t, x)
        :func:`phased_guess`: each phase's starting mesh (its length fixes ``N_p``).
    guess_u : list of ndarray (2 N_p + 1,), optional
        Each phase's starting hip torque [N m] (default 0; another optimisation's).

    Returns
    -------
    PhasedResult

    Raises
    ------
    ValueError
        An objective or constraint this transcription does not take, or a guess whose
        phases are not the walker's (one line).
    """
    import casadi as ca

    from walkerlab.optimal.transcription.step import ipopt_options

    phases = fns["phases"]
    _check(spec, phases)
    if [g[0] for g in guess] != [p.name for p in phases]:
        raise ValueError("optimize: the starting step's phases "
                         f"{[g[0] for g in guess]} are not the walker's")
    t_build = time.perf_counter()
    n2 = 2 * fns["n"]
    opti = ca.Opti()
    Xs = [opti.variable(n2, g[1].size) for g in guess]
    nu = int(fns.get("torques", 1))  # torques at every point (a five-link biped: 4)
    Us = [opti.variable(nu, g[1].size) for g in guess]
    Ts = [opti.variable() for _ in guess]
    effort, po_work, strikes = 0, 0, 0
    push = opti.variable() if spec.push_off_free else spec.push_off_n_s
    if spec.push_off_free:
        opti.subject_to(opti.bounded(0.0, push, spec.push_off_max_n_s))
        opti.set_initial(push, spec.push_off_n_s)
    taus = [np.asarray(g[1], float) / float(g[1][-1]) for g in guess]
    effort, po_work, strikes = _chain_phases(opti, fns, spec, guess, guess_u, (Xs, Us, Ts),
                                             taus, push, (effort, po_work, strikes))
    obj, terms = _objective(opti, spec, fns, (Xs, Us, Ts), taus, (effort, po_work, strikes),
                            push)
    opti.minimize(obj)
    if "constrain" in fns:  # a walker's own constraints on the whole sequence
        fns["constrain"](opti, Xs, Us, Ts)
    plugin, options = fns.get("solver", ({}, None))  # a walker's own IPOPT options
    opti.solver("ipopt", {"print_time": False, **plugin},
                ipopt_options(spec) if options is None else options)
    build = time.perf_counter() - t_build
    return _solve(opti, Xs, Us, Ts, taus, obj, terms, fns, [p.name for p in phases], build,
                  push if _pushes(spec) else 0.0)


def _solve(opti, Xs, Us, Ts, taus, obj, terms, fns, names, build, push=0.0) -> PhasedResult:
    """Run IPOPT and read the phases back as one step (``push``: the push-off impulse, a
    number or the decision variable)."""
    from walkerlab.optimal.transcription.step import number

    status, get, wall, cpu = solve(opti)
    n2 = Xs[0].shape[0]
    ts, xs, us, starts, durs, offset = [], [], [], [], [], 0.0
    for X, U, T, tau in zip(Xs, Us, Ts, taus):
        Tv, K = float(get(T)), X.shape[1]
        starts.append(sum(len(a) for a in ts))
        ts.append(offset + Tv * tau)
        xs.append(np.asarray(get(X)).reshape(n2, K).T)
        u = np.asarray(get(U)).reshape(U.shape[0], K).T
        us.append(u.ravel() if U.shape[0] == 1 else u)
        durs.append(Tv)
        offset += Tv
    X_all = np.concatenate(xs)  # (m, 2n): every phase's points in turn
    return PhasedResult(
        t=np.concatenate(ts), x=X_all, u=np.concatenate(us), phase_names=tuple(names),
        phase_start=np.array(starts), phase_duration_s=np.array(durs), step_period_s=offset,
        step_length_m=float(fns["phases"][-1].step(X_all[-1])), objective=float(get(obj)),
        status=status,
        iterations=int(opti.stats().get("iter_count", -1)), build_time_s=build,
        wall_time_s=wall, cpu_time_s=cpu, terms={k: number(get(v)) for k, v in terms.items()},
        history=iteration_history(opti.stats()),
        push_off_n_s=float(push) if isinstance(push, (int, float)) else float(get(push)),
        violations="" if status == "Solve_Succeeded" else largest_violations(opti))


def phase_torque_of_time(res: PhasedResult):
    """The optimised hip torque as a function of the time since the heel strike [s] ->
    [N m]: in the phase holding it, the quadratic through its interval's three points
    (Hermite-Simpson's control), held outside the step."""
    ends = np.cumsum(res.phase_duration_s)
    bounds = list(res.phase_start) + [res.t.size]

    def tau(s: float) -> float:
        s = min(max(float(s), 0.0), float(ends[-1]))
        p = min(int(np.searchsorted(ends, s)), len(ends) - 1)
        t, u = res.t[bounds[p]:bounds[p + 1]], res.u[bounds[p]:bounds[p + 1]]
        i = min(int(np.searchsorted(t[0::2], s, side="right")) - 1, (len(t) - 3) // 2) * 2
        i = max(i, 0)
        ti, tm, tj = t[i], t[i + 1], t[i + 2]
        return float(u[i] * (s - tm) * (s - tj) / ((ti - tm) * (ti - tj))
                     + u[i + 1] * (s - ti) * (s - tj) / ((tm - ti) * (tm - tj))
                     + u[i + 2] * (s - ti) * (s - tm) / ((tj - ti) * (tj - tm)))
    return tau


def replay_phases(data, res: PhasedResult, solver=None):
    """The optimised step replayed on the rigid model (its generated code, its own phases,
    guards and resets; not the CasADi expressions): the walker with a hip actuator whose
    torque is :func:`phase_torque_of_time` from each step's heel strike, and the optimum's
    push-off impulse ``res.push_off_n_s`` [N s] before each heel strike when it is positive
    (the rigid model's :mod:`walkerlab.models.hybrid.push_off`), one step from ``x_0``
    (DOP853 at rtol = atol = 1e-12 unless ``solver`` is given).

    Returns
    -------
    error : float
        Max-norm return error ``|x_0' - x_0|`` (inf when the step does not end in a heel
        strike or crosses other phases than the optimised ones).
    walker : HybridWalker
        The replayed walker.
    """
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.hybrid.rigid import make_rigid_walker

    spec = Actuation(torques=[JointTorque(joint="hip", law=TorqueLaw(), max_torque_n_m=1e6)])
    if res.push_off_n_s > 0.0:  # the optimum's push-off before each heel strike
        spec = Actuation(push_off=PushOff(impulse_n_s=float(res.push_off_n_s)),
                         torques=spec.torques)
    walker = actuate(make_rigid_walker(data, "biped", "derived", double_support=False), data,
                     spec)  # the transcription has no double support yet
    acts = walker.actuators
    if hasattr(acts.torques, "begin_step"):  # a flat foot's push-off holds the torques'
        acts = acts.torques  # actuators (walkerlab.models.hybrid.toe_push_off.FlatPushOff)
    tau = phase_torque_of_time(res)
    acts.torques = lambda t, x: np.array([tau(float(np.real(t)) - acts.t_origin)])
    solver = solver or Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    seg = integrate_step(walker, np.asarray(res.x[0], float), solver,
                         max_step_time=3.0 * res.step_period_s)
    crossed = tuple(ph.name for ph, _s, _ab in seg.pieces)
    if seg.termination != "heel_strike" or crossed != tuple(res.phase_names):
        return float("inf"), walker
    return float(np.max(np.abs(seg.x_next - res.x[0]))), walker


def step_phase(fns: dict):
    """One step of straight legs as a phase
    (:class:`walkerlab.optimal.transcription.phases.ModePhase`) from its one-step functions
    ``fns`` (:func:`walkerlab.optimal.transcription.step.step_functions`): the flow, the
    heel strike's guard (crossed downward) and rate, the reset without and with a push-off
    (and its work), the clearance, the step length and the ground reaction; no guard sign
    kept inside (``inside=False``: the swing foot of straight legs may dip through the
    ground mid-swing, the clearance bound is ``optimize.min_clearance_m``)."""
    import casadi as ca

    from walkerlab.optimal.transcription.phases import ModePhase

    x, u, P = ca.MX.sym("x", 2 * fns["n"]), ca.MX.sym("u"), ca.MX.sym("P")
    return ModePhase("step", "heel_strike", -1, fns["flow"],
                     ca.Function("guard", [x, u], [fns["guard"](x)]), fns["guard_rate"],
                     ca.Function("reset", [x], [fns["reset"](x, 0.0)]),
                     clearance=fns["clearance"], step=fns["step"], grf=fns["grf"],
                     push_off=ca.Function("push_off", [x, P], [fns["reset"](x, P),
                                                               fns["push_off_work"](x, P)]),
                     inside=False)


def collocate_step(data, eq, spec, guess_t: np.ndarray, guess_x: np.ndarray,
                   guess_u: np.ndarray | None = None, fns: dict | None = None,
                   ground=None):
    """Optimise one step of straight legs (the transcription of
    :mod:`walkerlab.optimal.transcription.step`'s docstring) as the sequence of one phase
    (:func:`step_phase`) on a uniform mesh of ``spec.intervals`` intervals.

    Parameters
    ----------
    data : WalkerData
    eq : Equations or None
        ``walkerlab.codegen.legged.derive_legged(data.structure)`` (unused when ``fns`` is
        given, e.g. by :func:`walkerlab.optimal.transcription.step_cache.
        cached_step_functions`).
    spec : walkerlab.optimal.transcription.step.CollocationSpec
    guess_t : ndarray (m,)
        Times [s] of a guess step (e.g. a simulated gait from heel strike to heel strike).
    guess_x : ndarray (m, 2n)
        Its states.
    guess_u : ndarray (m,), optional
        Its hip torque [N m] (default 0).
    fns : dict, optional
        :func:`~walkerlab.optimal.transcription.step.step_functions` of the walker (built
        when not given).
    ground : walkerlab.optimal.transcription.landing.StepGround, optional
        The landing of stairs or footholds of one height (one drop:
        :func:`walkerlab.optimal.transcription.landing.landing_phase`, its advance held to
        ``ground.advance_m`` when given; the result's ``step_length_m`` the advance along
        the slope); None: the slope's heel strike.

    Returns
    -------
    walkerlab.optimal.transcription.step.CollocationResult

    Raises
    ------
    ValueError
        A walker this transcription does not handle, an unknown objective (one line).
    """
    from walkerlab.optimal.transcription.step import (
        CollocationResult,
        check_objective,
        step_functions,
    )

    fns = fns or step_functions(data, eq)
    check_objective(spec)
    K = 2 * int(spec.intervals) + 1
    tk = np.linspace(0.0, 1.0, K) * guess_t[-1]
    x = np.stack([np.interp(tk, guess_t, guess_x[:, c]) for c in range(guess_x.shape[1])],
                 axis=1)
    u = np.interp(tk, guess_t, np.zeros_like(guess_t) if guess_u is None else guess_u)
    phase = step_phase(fns)
    extra = {}
    if ground is not None:
        from walkerlab.optimal.transcription.landing import landing_phase

        phase = landing_phase(phase, fns, ground.drops_m[0], ground.slope_rad)
        if ground.advance_m is not None and spec.target_step_length_m is None:
            # stairs: one tread a step (a target step length is the tread, held by it)
            def constrain(opti, Xs, _Us, _Ts, advance=float(ground.advance_m)):
                opti.subject_to(phase.step(Xs[-1][:, -1]) == advance)
            extra["constrain"] = constrain
    res = collocate_phases({**fns, "phases": [phase], **extra}, spec, [("step", tk, x)],
                           [u])
    return CollocationResult(
        t=res.t, x=res.x, u=res.u, step_period_s=res.step_period_s,
        step_length_m=res.step_length_m, push_off_n_s=res.push_off_n_s,
        objective=res.objective, status=res.status, iterations=res.iterations,
        wall_time_s=res.wall_time_s, terms={"push_off_work": 0.0, **res.terms},
        history=res.history, violations=res.violations)


def collocate_footholds(fns: dict, spec, ground, guess: list, guess_u: list | None = None
                        ) -> PhasedResult:
    """Optimise one period of straight legs on footholds that differ from step to step
    (:mod:`walkerlab.optimal.transcription.landing`): ``p = len(ground.drops_m)`` steps,
    step ``k`` a phase ``step_<k>`` of ``spec.intervals`` intervals landing
    ``ground.drops_m[k]`` [m] below its stance foot's level, each joined to the next by the
    heel strike (push-off included) and the last to the first (the period-``p`` map's
    periodicity); the targets are the mean step's (:func:`collocate_phases`).

    Parameters
    ----------
    fns : dict
        :func:`walkerlab.optimal.transcription.step.step_functions` of the walker.
    spec : walkerlab.optimal.transcription.step.CollocationSpec
    ground : walkerlab.optimal.transcription.landing.StepGround
    guess : list of (name, t (2N + 1,), x (2N + 1, 2n))
        Each step's starting mesh (``step_<k>``, :func:`footholds_guess`).
    guess_u : list of ndarray (2N + 1,), optional
        Each step's starting hip torque [N m] (default 0).

    Returns
    -------
    PhasedResult
        Its phases the ``p`` steps; ``step_period_s`` the period's (all steps'),
        ``step_length_m`` the last step's advance.

    Raises
    ------
    ValueError
        An objective the transcription does not take (one line).
    """
    from walkerlab.optimal.transcription.landing import landing_phase
    from walkerlab.optimal.transcription.step import check_objective

    check_objective(spec)
    base = step_phase(fns)
    phases = [landing_phase(base, fns, d, ground.slope_rad, f"step_{k}")
              for k, d in enumerate(ground.drops_m)]
    return collocate_phases({**fns, "phases": phases}, spec, guess, guess_u)


def footholds_guess(walker, x0, period_s: float, solver, intervals: int):
    """The starting period of :func:`collocate_footholds`: the rigid walker on the
    footholds (``walker.cycle``: :func:`walkerlab.models.hybrid.ground.on_footholds`)
    stepped ``len(walker.cycle)`` times from the post-impact state ``x0`` (2n,), each step
    sampled on a uniform mesh of ``intervals`` intervals (its mid-points halfway).

    Returns
    -------
    list of (``step_<k>``, t (2N + 1,) [s from the step's heel strike], x (2N + 1, 2n))

    Raises
    ------
    ValueError
        A step does not end in a heel strike (one line).
    """
    from walkerlab.integrate.rigid import simulate_steps

    x0 = np.asarray(x0, float)
    p = len(walker.cycle)
    run = simulate_steps(walker, x0, p, solver, max_step_time=3.0 * period_s)
    if len(run.segments) < p or any(s.termination != "heel_strike" for s in run.segments):
        raise ValueError("optimize: the starting gait does not step over the footholds "
                         f"({run.segments[-1].termination})")
    out = []
    for k, seg in enumerate(run.segments):
        t = np.linspace(seg.t_start, seg.t_end, 2 * int(intervals) + 1)
        x = np.empty((t.size, x0.size))
        for j, (_ph, sol, (a, b)) in enumerate(seg.pieces):
            last = j == len(seg.pieces) - 1
            sel = (t >= a) & ((t <= b) if last else (t < b))
            if sel.any():
                x[sel] = np.asarray(sol(t[sel]), float)[:x0.size].T
        out.append((f"step_{k}", t - t[0], x))
    return out
