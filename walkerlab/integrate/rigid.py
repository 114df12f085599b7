"""Integrate a :class:`~walkerlab.models.hybrid.base.HybridWalker` step by step.

A trajectory is a list of :class:`Segment` (one per step), each with its termination reason
(``heel_strike``, ``fall``, ``t_final``, ``solver_failure``) and the event time and state, as
PyBaMM's solutions record why they stopped.

Each phase runs on a library's integrator, chosen by
:class:`~walkerlab.integrate.solver.Solver` ``backend`` (:mod:`walkerlab.integrate.rigid_phase`);
at each guard crossing the reset and, with the variational equations, the saltation matrix
are applied here.

Nothing here knows the walker's size: states are ``(2n,)`` arrays, guards and resets come
from the walker's phases.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from walkerlab.models.hybrid.base import HybridWalker, Phase

from .ends import RunEnd
from .rigid_phase import integrate_phase, numeric_jacobian, phase_rhs
from .solver import Solver
from .work_limit import start_step

#: A heel strike this soon after the step began [s] is no step: the state sat on the
#: heel-strike surface and never moved (slope 0, all-zero state; a passive step lasts
#: tenths of a second or more).
MIN_STEP_TIME_S = 1e-9
#: Phase switches allowed in one step (a phase graph with a cycle must not loop for ever;
#: a flat-footed step has at most five).
MAX_PHASE_SWITCHES = 64


@dataclass
class Segment:
    """One step of a hybrid trajectory (continuous phases up to the step's end).

    Attributes
    ----------
    index : int
        Step number, from 0.
    stance_leg : str
        Physical leg in stance during this step.
    t_start, t_end : float
        Start and end time [s].
    x_start : ndarray (2n,)
        State at the start (just after the previous impact), role-ordered.
    x_end : ndarray (2n,)
        State at the end, before any reset (the event state).
    x_next : ndarray (2n,) or None
        State after the reset (heel strike only).
    termination : str
        ``heel_strike``, ``fall``, ``t_final``, ``solver_failure`` or ``no_heel_strike``: the
        value of a :class:`~walkerlab.integrate.ends.RunEnd` of
        :data:`~walkerlab.integrate.ends.RIGID_ENDS`.
    event : str
        Name of the guard that fired (or ``""``).
    phase_times : dict[str, float]
        Time at which each phase after the first began (e.g. ``midstance``), by the name of
        the guard that began it.
    phase_log : list of (str, float, float, str)
        Each phase of the step in order: ``(phase name, t_start, t_end, guard that ended
        it)`` (the guard is ``""`` when the step was cut or the solver failed).
    nfev : int
        Right-hand-side evaluations.
    message : str
        Solver message.
    pieces : list of (Phase, OdeSolution)
        Dense output of each phase.
    stance_foot_world : ndarray (2,)
        World position of the stance foot [m].
    """

    index: int
    stance_leg: str
    t_start: float
    t_end: float
    x_start: np.ndarray
    x_end: np.ndarray
    x_next: np.ndarray | None
    termination: str
    event: str
    phase_times: dict
    nfev: int
    message: str
    pieces: list = field(default_factory=list, repr=False)
    stance_foot_world: np.ndarray = field(default_factory=lambda: np.zeros(2))
    monodromy: np.ndarray | None = None
    phase_log: list = field(default_factory=list)

    @property
    def period(self) -> float:
        return self.t_end - self.t_start

    def sample(self, times: np.ndarray) -> np.ndarray:
        """Dense state at ``times`` (within the segment), shape (2n, len(times))."""
        n = self.x_start.size
        times = np.asarray(times, dtype=float)
        out = np.empty((n, times.size))
        done = np.zeros(times.size, dtype=bool)
        for j, (_ph, sol, (ta, tb)) in enumerate(self.pieces):
            last = j == len(self.pieces) - 1
            m = ~done & ((times <= tb) | last)
            if m.any():
                out[:, m] = np.atleast_2d(sol(np.clip(times[m], ta, tb)))[:n]
                done |= m
        return out


class _Held:
    """Dense output of a phase that ended as it began: the state ``x`` at every time."""

    def __init__(self, x: np.ndarray):
        self._x = np.asarray(x, float)

    def __call__(self, t):
        if np.ndim(t) == 0:
            return self._x.copy()
        return np.repeat(self._x[:, None], np.size(t), axis=1)


def _violated_at_entry(phase: Phase, t: float, x: np.ndarray, backend: str = "cyrk"):
    """The first fall guard of ``phase`` marked ``at_entry`` whose function starts on its
    firing side at ``(t, x)``, or None.  On ``cyrk_compiled`` a phase whose compiled flow
    outputs its guards is checked from them (one cfunc call instead of the Python flow and
    ground reactions a flat foot's force guards evaluate)."""
    vals = None
    if backend == "cyrk_compiled" and phase.compiled is not None:
        from ._compiled import guard_values

        vals = guard_values(phase.compiled, t, x)
    for i, g in enumerate(phase.guards):
        if getattr(g, "at_entry", False) and g.outcome == "fall":
            v = float(g.function(t, x)) if vals is None else float(vals[i])
            if g.direction * v > 0:
                return g
    return None


def _grad(guard, x):
    """Gradient (2n,) of a guard function: the model's own, else numerical."""
    gradient = getattr(guard, "gradient", None)
    if gradient is not None:
        return np.asarray(gradient(x), dtype=float)
    return numeric_jacobian(lambda z: np.atleast_1d(guard.function(0.0, z)), x)[0]


def _saltation(f_prev: np.ndarray, f_next: np.ndarray, dg: np.ndarray,
               DR: np.ndarray | None = None) -> np.ndarray:
    """Saltation matrix ``DR + (f+ - DR f-) dg^T / (dg . f-)`` of a guard crossing with a
    reset of Jacobian ``DR`` (identity when None); ``f-``/``f+`` are the flows before/after.
    """
    DR = np.eye(f_prev.size) if DR is None else DR
    return DR + np.outer(f_next - DR @ f_prev, dg) / (dg @ f_prev)


@dataclass
class _StepState:
    """What :func:`integrate_step` carries from one phase of a step to the next."""

    t: float
    x: np.ndarray                     # role-ordered state (2n,)
    Phi: np.ndarray                   # variational state (2n, 2n): d x / d x0 so far
    nfev: int = 0
    pieces: list = field(default_factory=list)
    phase_times: dict = field(default_factory=dict)
    phase_log: list = field(default_factory=list)
    termination: RunEnd = RunEnd.T_FINAL
    event: str = ""
    message: str = ""
    x_next: np.ndarray | None = None


def _next_phase(walker: HybridWalker, k: int, guard, st: _StepState,
                variational: bool) -> int:
    """Phase ``k``'s guard hands the step to the next phase (``k + 1``, or the phase the
    guard names: a flat foot's phase graph) - ``midstance``; a knee strike or a foot slap
    applies its reset - with the saltation matrix of the crossing.  Returns the next
    phase's index."""
    phase = walker.phases[k]
    st.phase_times[guard.name] = st.t
    target = getattr(guard, "next_phase", None)
    k_next = k + 1 if target is None else [p.name for p in walker.phases].index(target)
    x_minus = st.x
    g_reset = getattr(guard, "reset", None)
    if g_reset is not None:  # intra-step impact (e.g. knee strike)
        st.x = np.asarray(g_reset(x_minus), dtype=float)
    if k_next < len(walker.phases) and variational:
        nxt = walker.phases[k_next]
        DR = None if g_reset is None else np.asarray(guard.reset_jacobian(x_minus))
        st.Phi = _saltation(np.asarray(phase.flow(st.t, x_minus)),
                            np.asarray(nxt.flow(st.t, st.x)),
                            _grad(guard, x_minus), DR) @ st.Phi
    return k_next


def _end_step(walker: HybridWalker, phase: Phase, guard, st: _StepState, t0: float,
              variational: bool) -> None:
    """A guard that ends the step: a fall, a heel strike at the step's very start (no step),
    or a heel strike: the reset, and on the variational state the saltation matrix and the
    reset's Jacobian (so ``Phi`` becomes the Poincaré map's Jacobian)."""
    if guard.outcome == "fall":
        st.termination = RunEnd.FALL
        return
    if st.t - t0 <= MIN_STEP_TIME_S:
        st.termination = RunEnd.NO_HEEL_STRIKE
        st.message = (f"no step: the heel-strike guard fired at the step's start "
                      f"(t = {t0:.4g} s); the walker does not move")
        return
    st.termination = RunEnd.HEEL_STRIKE
    # a phase's own heel-strike map (a flat foot's depends on its mode), else the walker's
    reset, reset_jac = ((guard.reset, guard.reset_jacobian)
                        if getattr(guard, "reset", None) is not None
                        else (walker.reset, walker.reset_jacobian))
    st.x_next = np.asarray(reset(st.x), dtype=float)
    if variational:
        f_prev = np.asarray(phase.flow(st.t, st.x))
        S = _saltation(f_prev, np.zeros_like(f_prev), _grad(guard, st.x))
        RJ = reset_jac(st.x) if reset_jac is not None else numeric_jacobian(reset, st.x)
        st.Phi = RJ @ S @ st.Phi


def _enter_step(walker: HybridWalker, st: _StepState, variational: bool) -> int:
    """Apply :attr:`HybridWalker.step_entry` to the step's first state (with its Jacobian
    on the variational state); returns the index of the phase the step begins in."""
    entry = walker.step_entry
    x_new, name = entry(st.x)
    if variational and (name is not None or not np.array_equal(x_new, st.x)):
        st.Phi = numeric_jacobian(lambda z: entry(z)[0], st.x) @ st.Phi  # else the identity
    st.x = np.asarray(x_new, dtype=float)
    return 0 if name is None else [p.name for p in walker.phases].index(name)


def _runs_compiled_on_scipy(phase: Phase) -> bool:
    """Whether a phase run by scipy (a stiff method, e.g. LSODA) calls its compiled flow
    instead of its Python one: an actuated flow of a kind whose Python flow is slow (the
    free-jointed walkers', :attr:`walkerlab.walker.kinds.Kind.joints_free`: the five-link
    biped's and the three-link walker's Python flow evaluates the laws and differentiates
    them by the complex step on every call; the compiled flow is the same function, to
    round-off)."""
    c = phase.compiled
    return (c is not None and getattr(c, "actuators", None) is not None
            and c.structure.kind.joints_free)


def _advance(walker: HybridWalker, phase: Phase, st: _StepState, t_stop: float, n: int,
             solver: Solver, backend: str, variational: bool):
    """Run ``phase`` from ``st`` and record it (its dense output and log line, the state, the
    variational state); returns the guard that ended it, or None when the step ends without
    one (a fall guard violated as the phase begins, a solver failure, ``t_stop``)."""
    if (backend == "cyrk" and solver.backend == "auto" and not variational
            and getattr(phase.compiled, "by_default", False)):
        # a slow Python flow (CompiledFlow.by_default); its variational equations stay in
        # Python: a run asks them a few times (the multipliers), and numba would take
        # longer to compile them (collins2001's: ~15 s) than Python takes to run them
        backend = "cyrk_compiled"
    broken = _violated_at_entry(phase, st.t, st.x, backend)
    if broken is not None:  # e.g. a unilateral contact already pulling as its mode begins
        st.termination, st.event = RunEnd.FALL, broken.name
        st.message = f"{broken.name}: already violated as {phase.name} begins"
        st.pieces.append((phase, _Held(st.x), (st.t, st.t)))
        st.phase_log.append((phase.name, st.t, st.t, broken.name))
        return None
    rhs, jac = phase_rhs(walker, phase, n, variational)
    if backend == "scipy" and _runs_compiled_on_scipy(phase):
        from walkerlab.integrate._compiled import callable_flow

        rhs, jac = callable_flow(phase.compiled, n, variational)
    run = integrate_phase(phase, st.t, st.x, st.Phi, t_stop, n, solver, backend, rhs, jac,
                          variational)
    st.nfev += run.nfev
    st.message = run.message
    st.pieces.append((phase, run.dense, (st.t, run.t_last)))
    st.phase_log.append((phase.name, st.t, run.t_last, "" if run.event is None
                         or run.failed else phase.guards[run.event].name))
    st.t, st.x = run.t_last, run.y_last[:n].copy()
    if run.failed:
        st.termination = RunEnd.SOLVER_FAILURE
        return None
    if run.event is None:
        st.termination = RunEnd.T_FINAL
        return None
    guard = phase.guards[run.event]
    if variational:
        st.Phi = run.y_last[n:].reshape(n, n)
    st.event = guard.name
    return guard


def integrate_step(walker: HybridWalker, x0: np.ndarray, solver: Solver, t0: float = 0.0,
                   max_step_time: float = 5.0, t_final: float | None = None,
                   variational: bool = False, index: int = 0, stance_leg: str = "leg2",
                   stance_foot_world: np.ndarray | None = None) -> Segment:
    """Integrate one step from ``x0`` (just after an impact) until its end.

    Parameters
    ----------
    walker : HybridWalker
    x0 : ndarray, shape (2n,)
        Role-ordered state at the start of the step.
    solver : Solver
    t0 : float
        Start time [s].
    max_step_time : float
        The step is cut (termination ``t_final``) after this long [s].
    t_final : float, optional
        Absolute end time of the run [s].
    variational : bool
        Also integrate the variational equations ``dPhi/dt = A(x) Phi`` (``A`` the analytic
        Jacobian of the flow when the model gives one) and apply saltation matrices at the
        guards; the segment's ``monodromy`` is then the Jacobian of the Poincaré map
        (2n x 2n) at ``x0`` (including the reset), when the step ends in heel strike.

    Returns
    -------
    Segment

    Raises
    ------
    ValueError
        An unusable ``solver.backend`` (see :meth:`Solver.resolved_backend`).
    """
    backend = solver.resolved_backend()
    n = x0.size
    start_step()  # inside a step_work_limit only: this step's evaluations
    if walker.actuators is not None:  # a time-based torque law counts from the step's start
        walker.actuators.begin_step(t0)
    t_stop = t0 + max_step_time
    if t_final is not None:
        t_stop = min(t_stop, t_final)
    st = _StepState(t0, np.asarray(x0, dtype=float), np.eye(n))
    k, switches = 0, 0
    if walker.step_entry is not None:  # e.g. a flat foot's trailing toe kept down
        k = _enter_step(walker, st, variational)
    while k < len(walker.phases) and switches <= MAX_PHASE_SWITCHES:
        phase = walker.phases[k]
        switches += 1
        if st.t >= t_stop:
            break
        guard = _advance(walker, phase, st, t_stop, n, solver, backend, variational)
        if guard is None:
            break
        if guard.outcome == "next_phase":
            k = _next_phase(walker, k, guard, st, variational)
            continue
        _end_step(walker, phase, guard, st, t0, variational)
        break
    return Segment(
        index=index, stance_leg=stance_leg, t_start=t0, t_end=st.t,
        x_start=np.asarray(x0, float), x_end=st.x, x_next=st.x_next,
        termination=st.termination.value, event=st.event, phase_times=st.phase_times,
        phase_log=st.phase_log, nfev=st.nfev, message=st.message, pieces=st.pieces,
        stance_foot_world=np.zeros(2) if stance_foot_world is None else stance_foot_world,
        monodromy=(st.Phi if (variational and st.termination is RunEnd.HEEL_STRIKE)
                   else None),
    )


@dataclass
class HybridTrajectory:
    """A hybrid trajectory: segments (steps) and run statistics."""

    segments: list[Segment]
    wall_time_s: float
    walker: HybridWalker

    @property
    def nfev(self) -> int:
        return sum(s.nfev for s in self.segments)

    @property
    def termination(self) -> str:
        return self.segments[-1].termination if self.segments else RunEnd.T_FINAL.value


def other_leg(walker: HybridWalker, leg: str) -> str:
    a, b = walker.legs[:2]
    return b if leg == a else a


def walker_of_step(walker: HybridWalker, k: int, stance_leg: str) -> HybridWalker:
    """The walker of step ``k`` (0 the first) with ``stance_leg`` in stance: on a ground that
    differs from step to step, step ``k mod p`` of its :attr:`~HybridWalker.cycle`
    (:func:`walkerlab.models.hybrid.ground.on_footholds`); else the stance leg's own
    (:meth:`~HybridWalker.for_stance`: legs that differ)."""
    if walker.cycle is not None:  # a ground that differs from step to step
        return walker.cycle[k % len(walker.cycle)]
    return walker.for_stance(stance_leg)  # legs that differ: each leg's own numbers


def simulate_steps(walker: HybridWalker, x0: np.ndarray, n_steps: int, solver: Solver,
                   max_step_time: float = 5.0, first_stance_leg: str = "leg2") -> HybridTrajectory:
    """Simulate ``n_steps`` steps from ``x0``; stops early on fall or solver failure.

    Parameters
    ----------
    walker : HybridWalker
    x0 : ndarray, shape (2n,)
        Role-ordered state just after heel strike.
    n_steps : int
        Number of steps (a stride is two steps).
    solver : Solver
    max_step_time : float
        A step longer than this ends the run with ``t_final`` [s].
    first_stance_leg : str
        Physical leg in stance during the first step (``leg1`` starts as the swing leg,
        as in paper Eq. 11).

    Returns
    -------
    HybridTrajectory
    """
    t0 = time.perf_counter()
    segs: list[Segment] = []
    x, t, leg = np.asarray(x0, float), 0.0, first_stance_leg
    foot = np.zeros(np.shape(walker.points(x)["stance_foot"]))  # (2,), or (3,) in 3D
    for k in range(n_steps):
        if walker.ground_steps is not None and k >= walker.ground_steps:
            break  # a finite ground (a foothold list that does not repeat): it ends here
        step_walker = walker_of_step(walker, k, leg)
        seg = integrate_step(step_walker, x, solver, t0=t, max_step_time=max_step_time,
                             index=k, stance_leg=leg, stance_foot_world=foot.copy())
        segs.append(seg)
        if seg.termination != RunEnd.HEEL_STRIKE:
            break
        foot = foot + step_walker.points(seg.x_end)["swing_foot"]
        x, t, leg = seg.x_next, seg.t_end, other_leg(walker, leg)
    return HybridTrajectory(segs, time.perf_counter() - t0, walker)
