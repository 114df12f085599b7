"""Integrate a :class:`~walkerlab.models.base.HybridWalker` step by step with scipy.

A trajectory is a list of :class:`Segment` (one per step), each with its termination reason
(``heel_strike``, ``fall``, ``t_final``, ``solver_failure``) and the event time and state, as
PyBaMM's solutions record why they stopped.  All integration is done by
``scipy.integrate.solve_ivp``; the guards are its events.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from scipy.integrate import solve_ivp

from walkerlab.models.base import HybridWalker, Phase
from walkerlab.models.compass_gait import complex_step_jacobian

Termination = Literal["heel_strike", "fall", "t_final", "solver_failure"]


@dataclass(frozen=True)
class Solver:
    """Integrator settings (mirrors :class:`walkerlab.config.SolverSettings`)."""

    method: str = "DOP853"
    rtol: float = 1e-10
    atol: float = 1e-10
    max_step_s: float | None = None

    @classmethod
    def from_settings(cls, s) -> Solver:
        return cls(s.method, s.rtol, s.atol, s.max_step_s)

    def kwargs(self) -> dict:
        kw = {"method": self.method, "rtol": self.rtol, "atol": self.atol}
        if self.max_step_s is not None:
            kw["max_step"] = self.max_step_s
        return kw


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
        ``heel_strike``, ``fall``, ``t_final`` or ``solver_failure``.
    event : str
        Name of the guard that fired (or ``""``).
    phase_times : dict[str, float]
        Time at which each phase after the first began (e.g. ``midstance``).
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


def _events_for(phase: Phase, n: int):
    evs = []
    for gd in phase.guards:
        def ev(t, y, _g=gd.function):
            return _g(t, y[:n])
        ev.terminal = True
        ev.direction = gd.direction
        evs.append(ev)
    return evs


def _grad(guard, x):
    if guard.gradient is not None:
        return np.asarray(guard.gradient(x), dtype=float)
    return complex_step_jacobian(lambda z: np.atleast_1d(guard.function(0.0, z)), x)[0]


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
        Also integrate the variational equations and apply saltation matrices; the
        segment's ``monodromy`` is then the Jacobian of the Poincaré map (2n x 2n) at ``x0``
        (including the reset), when the step ends in heel strike.

    Returns
    -------
    Segment
    """
    n = x0.size
    t_stop = t0 + max_step_time
    if t_final is not None:
        t_stop = min(t_stop, t_final)
    x = np.asarray(x0, dtype=float)
    Phi = np.eye(n)
    t = t0
    nfev = 0
    pieces = []
    phase_times = {}
    termination, event, message = "t_final", "", ""
    x_next = None
    for k, phase in enumerate(walker.phases):
        if variational:
            def rhs(tt, y, _f=phase.flow, _jac=phase.jacobian or walker.variational):
                xs = y[:n]
                P = y[n:].reshape(n, n)
                A = _jac(tt, xs)  # the phase's own flow Jacobian (e.g. knee locked)
                return np.concatenate([_f(tt, xs), (A @ P).ravel()])
            y0 = np.concatenate([x, Phi.ravel()])
        else:
            rhs = phase.flow
            y0 = x
        if t >= t_stop:
            break
        sol = solve_ivp(rhs, (t, t_stop), y0, events=_events_for(phase, n),
                        dense_output=True, **solver.kwargs())
        nfev += sol.nfev
        message = sol.message
        pieces.append((phase, sol.sol, (t, float(sol.t[-1]))))
        if sol.status == -1:
            termination, t, x = "solver_failure", float(sol.t[-1]), sol.y[:n, -1]
            break
        fired = [(te[0], i) for i, te in enumerate(sol.t_events) if len(te)]
        if not fired:
            t, x = float(sol.t[-1]), sol.y[:n, -1]
            termination = "t_final"
            break
        te, i = min(fired)
        guard = phase.guards[i]
        y_ev = sol.y_events[i][0]
        t, x = float(te), y_ev[:n].copy()
        if variational:
            Phi = y_ev[n:].reshape(n, n)
        event = guard.name
        if guard.outcome == "next_phase":
            phase_times[guard.name] = t
            x_minus = x
            if guard.reset is not None:  # intra-step impact (e.g. knee strike)
                x = np.asarray(guard.reset(x_minus), dtype=float)
            if k + 1 < len(walker.phases) and variational:
                nxt = walker.phases[k + 1]
                f_prev, f_next = phase.flow(t, x_minus), nxt.flow(t, x)
                dg = _grad(guard, x_minus)
                DR = np.eye(n) if guard.reset is None else guard.reset_jacobian(x_minus)
                # saltation matrix: DR + (f+ - DR f-) dg^T / (dg . f-)
                Phi = (DR + np.outer(f_next - DR @ f_prev, dg) / (dg @ f_prev)) @ Phi
            continue
        if guard.outcome == "fall":
            termination = "fall"
            break
        termination = "heel_strike"
        x_next = walker.reset(x)
        if variational:
            f_prev = phase.flow(t, x)
            dg = _grad(guard, x)
            S = np.eye(n) - np.outer(f_prev, dg) / (dg @ f_prev)
            Phi = walker.reset_jacobian(x) @ S @ Phi
        break
    return Segment(
        index=index, stance_leg=stance_leg, t_start=t0, t_end=t, x_start=np.asarray(x0, float),
        x_end=x, x_next=x_next, termination=termination, event=event, phase_times=phase_times,
        nfev=nfev, message=message, pieces=pieces,
        stance_foot_world=np.zeros(2) if stance_foot_world is None else stance_foot_world,
        monodromy=Phi if (variational and termination == "heel_strike") else None,
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
        return self.segments[-1].termination if self.segments else "t_final"


def other_leg(walker: HybridWalker, leg: str) -> str:
    a, b = walker.legs[:2]
    return b if leg == a else a


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
    foot = np.zeros(2)
    for k in range(n_steps):
        seg = integrate_step(walker, x, solver, t0=t, max_step_time=max_step_time, index=k,
                             stance_leg=leg, stance_foot_world=foot.copy())
        segs.append(seg)
        if seg.termination != "heel_strike":
            break
        foot = foot + walker.points(seg.x_end)["swing_foot"]
        x, t, leg = seg.x_next, seg.t_end, other_leg(walker, leg)
    return HybridTrajectory(segs, time.perf_counter() - t0, walker)
