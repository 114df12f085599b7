"""The actuation hook of the contact integrator loop: a powered compliant-contact walker
(one with ``actuators``) in :func:`walkerlab.integrate.contact.integrate_contact`'s one loop.

A powered walker's right-hand side depends on two discrete states the passive one does not
have: which leg is in stance (the hip torques act +tau on the swing leg) and whether a
push-off pulse is running (:mod:`walkerlab.models.contact.actuation`).  So the loop's chunks
go in segments (:class:`ActuationHook`, no loop of its own), on
:func:`scipy.integrate.solve_ivp` with event location:

1. from the step's start until the push-off pulse starts: ``pulse_s`` before the swing
   foot's predicted touchdown on a patch at least ``ContactActuators.min_step_m`` ahead of
   the stance foot (its penetration extrapolated at its rate,
   :func:`walkerlab.integrate.powered_events.pulse_lead`, crosses 0), or a fall;
2. the pulse, a force ``P / pulse_s`` for ``pulse_s`` seconds along the stance (soon
   trailing) leg at its foot, ``P`` from the hip speed at its start.  The rigid model's
   push-off comes immediately before the heel strike, with the trailing foot free for it
   (Kuo 2002); a pulse started at the touchdown instead works inside the compliant
   collision, against the ground (3.5x the rigid work per step at 5 ms on
   configs/powered_compass.yaml).  The touchdown, when it comes within the pulse, swaps the
   roles and the pulse runs on to its end;
3. to the touchdown (a heel strike: the roles swap) if the pulse ended before it; a touchdown
   without a pulse before it (none predicted in time) gets the pulse from the touchdown, and
   with ``pulse_s = 0`` the impulse at once at the touchdown (``dq += M^-1 J^T P e``, before
   any collision force: the rigid model's order);
4. repeat until the end time, the ``stop`` predicate (strides cap) or an event.

As ``pulse_s -> 0`` the run converges to the impulse's, first order in ``pulse_s``: the pulse
takes over the stance foot's weight support while it lasts, so its work falls short of the
impulse's by ~13 mJ per ms on configs/powered_compass.yaml (0.2280 J for the impulse at the
first touchdown, 0.2267 J at 0.1 ms, 0.2148 J at 1 ms, 0.1618 J at 5 ms; the rigid model's
0.2346 J on its own gait, whose touchdown state the contact walker's differs from).

A free-jointed (five-link) biped's joint torques (:mod:`walkerlab.models.contact.joint_torques`)
run the same way: the stance leg switched at the heel strike sets which leg's hip and knee
carry the ``stance_*`` laws and which the ``swing_*`` ones; the time-based laws count from it.

A flat-footed walker's ankle push-off is a third discrete state: off from the run's start
and from each touchdown, on from the stance heel's lift-off with its toe loaded (an event:
the heel's penetration crossing 0 downwards) until the next touchdown.

The state carries four work integrals beside the walker's (``actuators.work_names`` [J]:
the hip torques' positive and negative work, the push-off's, the contact forces'; flat feet:
the ankle push-off's positive and negative work, the dampers', the contact forces'), so the energy
ledger of a run closes to the integrator's tolerance: ``E(t) - E(0) = sum of the works``
with ``E`` the walker's kinetic + gravitational energy (the contact springs' energy is in
the contact term).  Samples are on the run's grid (``sample_rate_hz`` from ``t0``); trips and
flights are found on them as in the passive run (:func:`walkerlab.integrate.contact.first_event`).

Methods: with ``cyrk_bdf`` (:data:`walkerlab.integrate._cyrk.CYRK_METHODS`) the run is
compiled segments (:class:`walkerlab.integrate.compiled_segments.CompiledSegments`): the
walker's actuators are data of its compiled right-hand side
(:mod:`walkerlab.models.contact.powered_source`: torque laws with their phase and time
tables, the pulse, the ankle push-off, the stance leg and the step's start), the events are
found on each segment's samples and located on CyRK's dense output, and after a heel strike
the run goes on from a sample :data:`RESUME_BACK_S` before it with the strike in its data;
no Python runs inside a step.  A replay whose laws are Python callables, and the
:func:`~scipy.integrate.solve_ivp` methods (``LSODA``, ``Radau``, ``BDF``, ...), run
``solve_ivp`` segments with the same events (``numbalsoda`` and ``odeint`` have no event
location and run as ``LSODA`` here); the analytic Jacobian of the passive walker is passed
to ``solve_ivp`` (the actuation's derivatives left out: Newton directions only).
"""

from __future__ import annotations

import time

import numpy as np

from walkerlab.models.contact.actuation import powered_rhs

from .compiled_segments import Stalled, grid_inside
from .contact_events import work_limit_message
from .ends import RunEnd
from .powered_events import (
    fall_event,
    heel_off_event,
    pulse_event,
    pulse_lead_s,
    touchdown_event,
)

__all__ = ["IVP_METHODS", "STALL_CALLS", "ActuationHook", "impulse_jump", "powered_atol"]


#: solve_ivp methods a powered run uses as given (others run as LSODA).
IVP_METHODS = ("LSODA", "Radau", "BDF", "RK45", "DOP853", "RK23")


#: RHS calls without the time advancing by more than 1e-9 s after which a segment ends (a
#: force jump the solver cannot step over, e.g. a foot entering a patch from its side).
STALL_CALLS = 20_000

#: A compiled segment ends this many times the last step's duration after the step began
#: (:meth:`ActuationHook.segment_end`).
STEP_MARGIN = 1.1
#: ... and at least this long [s].
MIN_SEGMENT_S = 0.05
#: The segment after a push-off pulse that ended before its touchdown is this long [s].
AFTER_PULSE_S = 0.005
#: A compiled run goes on after a heel strike from a sample this long [s] before it, the
#: strike in its data (:class:`walkerlab.integrate.compiled_segments.CompiledSegments`):
#: the segment that found the touchdown crossed it with a ghost swing foot (no collision
#: integrated), and the run integrates the collision once, from just before it, with the
#: solver's step already small.  Measured on the paper walker with a hip law (warm, 5 heel
#: strikes, RHS evaluations): 16 360 from the touchdown itself, 16 170 from 2 ms before,
#: 16 005 from 5 ms, 17 217 from 50 ms (the passive run: 13 124).
RESUME_BACK_S = 0.002


class _Deadline(Exception):
    pass


class _Stall(Exception):
    pass


def _segment(walker, y0, t0, t1, grid, stance, push, solver, limits, deadline, events,
             t_origin=0.0, ankle=False):
    """One segment on solve_ivp; returns the solution (``t_eval`` the grid inside);
    ``t_origin`` [s] is when the present step began (time-based torque laws); ``ankle``:
    the ankle push-off is on."""
    import time

    from scipy.integrate import solve_ivp  # here: a run without actuators needs none of it

    n, nw = 2 * walker.nq, len(walker.actuators.work_names)
    method = solver.method if solver.method in IVP_METHODS else "LSODA"

    mark = [t0, 0]
    fast = getattr(walker.actuators, "compiled_rhs", lambda w: None)(walker)

    def f(t, y):
        if time.perf_counter() > deadline:
            raise _Deadline
        if t > mark[0] + 1e-9:
            mark[0], mark[1] = t, 0
        mark[1] += 1
        if mark[1] > STALL_CALLS:
            raise _Stall(y)
        if fast is not None:  # the compiled right-hand side (point feet, straight legs)
            return fast(y, stance, push, t - t_origin)
        dx, p = powered_rhs(walker, y[:n], stance, push, t - t_origin, ankle)
        return np.concatenate([dx, p])

    def jac(t, y):
        J = np.zeros((n + nw, n + nw))
        J[:n, :n] = walker.jac(t, y[:n])
        return J

    kw = {} if method in ("RK45", "DOP853", "RK23") else {"jac": jac}
    inside = grid_inside(grid, t0, t1)
    return solve_ivp(f, (t0, t1), y0, method=method, rtol=solver.rtol,
                     atol=powered_atol(walker, solver.atol),
                     max_step=solver.max_step_s or np.inf, t_eval=np.append(inside, t1),
                     events=events, dense_output=False, **kw)


def compiled_segments(walker, solver, grid, held_force: bool = False):
    """The compiled segments of a powered run
    (:class:`walkerlab.integrate.compiled_segments.CompiledSegments`), or None when the run
    is on ``solve_ivp``: ``solver.method`` not a compiled one
    (:data:`walkerlab.integrate._cyrk.CYRK_METHODS`) or torque laws that are not data (a
    replay's Python callables: :func:`walkerlab.models.contact.powered_data.powered_data`);
    ``held_force``: the run carries a force held from outside (a Gymnasium action)."""
    from walkerlab.models.contact.powered_data import powered_data

    from ._cyrk import CYRK_METHODS

    if solver.method not in CYRK_METHODS:
        return None
    data = powered_data(walker, held_force)
    if data is None:
        return None
    from .compiled_segments import CompiledSegments

    return CompiledSegments(walker, data, solver,
                            powered_atol(walker, solver.atol, len(data.work_names)), grid)


def powered_atol(walker, atol: float, n_works: int | None = None):
    """The absolute tolerance of a powered run's state and work integrals: the scalar
    ``atol``, or, for hip torques on flat feet, ``atol`` times the walker's per-state
    :meth:`~walkerlab.models.contact.model.ContactWalker.atol_scale` (a flat foot's rotation
    rates looser, as in a passive run: :func:`walkerlab.integrate.contact.run_atol`) and
    ``atol`` on each work integral, shape (2 nq + n_works,) (``n_works`` default
    ``len(work_names)``).  An ankle push-off run
    keeps the scalar (configs/flat_feet_push_off.yaml's numbers were measured with it).

    Held to the angles' atol, LSODA chatters in foot flat on the regularising foot inertia's
    fast rates: 127 486 RHS calls over the first 0.5 s of configs/flat_feet_optimal.yaml's
    replay against 2 074 with the per-state atol."""
    acts = walker.actuators
    if getattr(acts, "foot", None) is None or acts.ankle is not None:
        return atol
    from .contact_events import run_atol

    nw = len(acts.work_names) if n_works is None else n_works
    return np.concatenate([run_atol(walker, atol, "LSODA"), np.full(nw, float(atol))])


def impulse_jump(walker, x, trailing, P):
    """The state after a push-off impulse ``P`` [N s] at leg ``trailing``'s foot along that
    leg towards the hip, applied at once: ``M dq+ = M dq- + J_foot^T P e``.

    Parameters
    ----------
    walker : ContactWalker
    x : ndarray, shape (2 nq,)
    trailing : int
        0: leg1, 1: leg2.
    P : float
        [N s].

    Returns
    -------
    x_plus : ndarray, shape (2 nq,)
    work : float
        Its work, the kinetic energy it adds [J].
    """
    n = walker.nq
    e, J, _ = walker.actuators.push_direction(walker, x, trailing)
    M = walker.mass_matrix(x)
    dq = x[n:] + np.linalg.solve(M, J.T @ (P * e))
    work = 0.5 * dq @ M @ dq - 0.5 * x[n:] @ M @ x[n:]
    return np.concatenate([x[:n], dq]), float(work)


class ActuationHook:
    """The actuation hook of the contact integrator loop
    (:func:`walkerlab.integrate.contact.integrate_contact`) for a powered walker: its
    discrete state (the stance leg, switched at touchdown; the push-off pulse; the ankle
    push-off), the powered right-hand side with the work integrals, the events that switch
    the discrete state and their transitions.  The loop asks :meth:`advance` for each chunk
    (one or more segments on solve_ivp with event location), its stop predicate after each
    heel strike, and :meth:`finish` for the samples.

    Parameters
    ----------
    walker : ContactWalker
        With ``actuators``.
    solver : Solver
    limits : ContactLimits
    deadline : float
        ``time.perf_counter()`` value past which the run stops (``time_limit``).
    grid : ndarray
        The run's sample times [s].
    """

    def __init__(self, walker, solver, limits, deadline, grid, held_force: bool = False,
                 launch_height_m: float | None = None):
        self.walker, self.solver, self.limits = walker, solver, limits
        self.held_force = held_force
        self.deadline, self.grid = deadline, grid
        self.stance = 1  # leg2 carries the first stance (the contact model's convention)
        self.t_origin = float(grid[0])  # when the present step began [s]
        self.step_s = None  # the last step's duration [s] (none before the first strike)
        self.t_strike = None  # the last heel strike's time [s] (none before the first)
        # a compiled run's next segment from before the last heel strike: (t, y, stance,
        # step start, ankle on) before it (None: from the present state)
        self.resume, self.segment = None, None
        self.pulse_end = None  # when the last push-off pulse ended before its touchdown [s]
        self.segments = None  # compiled segments, set by start() where they apply
        self.touch = touchdown_event(walker, lambda: self.stance)
        self.fall = fall_event(walker, limits, launch_height_m)
        self.heel_off = (None if walker.actuators.ankle is None  # flat feet only
                         else heel_off_event(walker, lambda: self.stance))
        self.ankle_on = False  # the ankle push-off (flat feet), off until the heel lifts
        self.ts, self.Ys, self.nfev, self.njev = [], [], 0, 0
        self.term, self.msg, self.event = RunEnd.T_FINAL, "Integration successful.", None

    def _run(self, y, t, tb, push, events):
        """One segment (compiled where :attr:`segments` is set, else on ``solve_ivp``);
        returns the solution, or None when the run ends here (the work bound,
        ``limits.max_rhs_evaluations``, is asked before each segment)."""
        most = getattr(self.limits, "max_rhs_evaluations", None)
        if most is not None and self.nfev >= most:

            self.term, self.msg = RunEnd.WORK_LIMIT, work_limit_message(self.limits)
            return None
        try:
            if self.segments is not None:
                if time.perf_counter() > self.deadline:
                    raise _Deadline
                if self.resume is not None and push is None:  # from before the strike
                    tr, yr, stance, origin, ankle = self.resume
                    sol = self.segments.run(yr, tr, tb, events, stance, origin, None, ankle,
                                            switch_s=t)
                else:
                    sol = self.segments.run(y, t, tb, events, self.stance, self.t_origin,
                                            push, self.ankle_on)
                self.resume = None
                self.segment = (t, y, sol)
            else:
                sol = _segment(self.walker, y, t, tb, self.grid, self.stance, push,
                               self.solver, self.limits, self.deadline, events,
                               self.t_origin, self.ankle_on)
        except Stalled as stall:
            from .contact_events import trip_or_failure

            t_s, y_s, why = stall.args
            self.term, self.msg, self.event = trip_or_failure(
                self.walker, t_s, np.asarray(y_s)[:2 * self.walker.nq],
                f"the compiled solver stopped at t = {t_s:.6g} s ({why})", -1, 0.01)
            return None
        except _Deadline:
            self.term, self.msg = RunEnd.TIME_LIMIT, "wall-time limit reached"
            return None
        except ValueError as err:  # solve_ivp's event bracketing (a force jump between
            # its function's evaluations): the run ends, the reason said
            self.term = RunEnd.SOLVER_FAILURE
            self.msg = f"solve_ivp could not locate an event at t = {t:.6g} s ({err})"
            return None
        except _Stall as stall:
            from .contact_events import trip_or_failure

            n2 = 2 * self.walker.nq  # the walker's state, without the work integrals
            state = np.asarray(stall.args[0])[:n2]
            self.term, self.msg, self.event = trip_or_failure(
                self.walker, t, state,
                f"the solver stalled after t = {t:.6g} s (a force jump it cannot step over)",
                -1, 0.01)
            return None
        self.nfev, self.njev = self.nfev + sol.nfev, self.njev + sol.njev
        if sol.status < 0:
            self.term, self.msg = RunEnd.SOLVER_FAILURE, str(sol.message)
            return None
        return sol

    def _keep(self, sol, t_end, y_end=None):
        """Store the samples before ``t_end`` (and ``(t_end, y_end)`` itself if given)."""
        ts = np.asarray(sol.t, float)  # solve_ivp answers a list if no sample came
        Y = sol.y.T if ts.size else np.empty((0, self.Ys[0].shape[1]))
        if y_end is None and t_end == np.inf:  # all of them (the answer's own arrays)
            self.ts.append(ts)
            self.Ys.append(Y)
            return
        keep = ts < t_end - 1e-12
        self.ts.append(ts[keep] if y_end is None else np.append(ts[keep], t_end))
        self.Ys.append(Y[keep] if y_end is None else np.vstack([Y[keep], y_end[None]]))

    def _pulse(self, y, t, tp, trailing, force, touch: bool):
        """The push-off pulse ``force`` [N] along leg ``trailing`` from ``t`` to ``tp`` [s];
        ``touch``: the leading foot's touchdown may end it early (then the heel strike is
        the caller's).  Returns ``(t, y, touched)``, or None when the run ends here (a fall
        stored)."""
        events = [self.fall, self.touch] if touch else [self.fall]
        sol = self._run(y, t, tp, (trailing, force), events)
        if sol is None:
            return None
        if sol.t_events[0].size:
            self._fell(sol)
            return None
        if touch and sol.t_events[1].size:
            t, y = float(sol.t_events[1][0]), sol.y_events[1][0].copy()
            self._keep(sol, t)
            return t, y, True
        self._keep(sol, tp)
        return float(sol.t[-1]), sol.y[:, -1].copy(), False

    def _fell(self, sol):
        self._keep(sol, sol.t_events[0][0], sol.y_events[0][0])
        self.term, self.msg = RunEnd.FALL, "fall: hip below the fall height"
        k = sum(len(a) for a in self.ts) - 1
        self.event = (RunEnd.FALL.value, k, float(sol.t_events[0][0]), "", np.nan)

    def start(self, x0, t, segments=None):
        """Start a run at ``(t, x0)`` (leg2 in stance, the work integrals 0); ``segments``:
        the compiled segments of an earlier run of this hook's walker, solver, grid and held
        force, used again (None: built for this run where they apply)."""
        acts = self.walker.actuators
        self.segments = (compiled_segments(self.walker, self.solver, self.grid,
                                           self.held_force) if segments is None else segments)
        self.work_names = (tuple(acts.work_names) if self.segments is None
                           else self.segments.pdata.work_names)
        nw = len(self.work_names)
        self.t, self.y = float(t), np.concatenate([np.asarray(x0, float), np.zeros(nw)])
        self.ts, self.Ys = [np.array([self.t])], [self.y[None]]
        # the pulse ends at the predicted touchdown (module docstring); ``pushed``: this
        # step's pulse has run (or is running)
        self.pulsed = pulse_lead_s(acts) > 0.0
        self.lead = (pulse_event(self.walker, lambda: self.stance, acts.pulse_s)
                     if self.pulsed else None)
        self.pushed = False

    def run_until(self, t_end: float) -> list[float]:
        """Advance to ``t_end`` [s] or the run's end (:attr:`term`); returns the heel-strike
        times inside [s] (a Gymnasium control period: the environment's one run)."""
        strikes = []
        while self.t < t_end - 1e-12:
            step = self.advance(min(self.segment_end(self.t, self.limits.chunk_s), t_end),
                                t_end)
            if step == "end":
                break
            if step == "strike":
                strikes.append(self.t_origin)
        return strikes

    def forget(self) -> None:
        """Drop the samples kept so far but the present state (a long episode's memory)."""
        self.ts, self.Ys = [np.array([self.t])], [self.y[None]]

    def advance(self, tb: float, t1: float) -> str:
        """Integrate from the present ``(self.t, self.y)`` to ``tb`` [s] or the next discrete
        event (the push-off pulse's start, heel strike, heel off), the event's transition
        applied (the pulse its own segments; ``t1`` the run's end).  Returns ``"end"`` (the
        run ends here: a fall, the deadline, a stall or a solver failure, ``self.term``
        says which), ``"strike"`` (a heel strike was handled: the caller may ask its stop
        predicate) or ``"go"``."""
        acts = self.walker.actuators
        n = 2 * self.walker.nq
        t, y = self.t, self.y
        watch = acts.ankle is not None and not self.ankle_on
        arm = self.pulsed and not self.pushed
        sol = self._run(y, t, tb, None,
                        [self.fall, self.touch] + ([self.heel_off] if watch else [])
                        + ([self.lead] if arm else []))
        if sol is None:
            return "end"
        if sol.t_events[0].size:  # a fall
            self._fell(sol)
            return "end"
        ilead = 3 if watch else 2  # the pulse event's index (after heel off's)
        if watch and sol.t_events[2].size and not (arm and sol.t_events[3].size):
            # heel off: the ankle push-off starts
            self.t, self.y = float(sol.t_events[2][0]), sol.y_events[2][0].copy()
            self._keep(sol, self.t)
            self.ankle_on = True
            return "go"
        if arm and sol.t_events[ilead].size and not sol.t_events[1].size:
            # the pulse starts pulse_s before the predicted touchdown, at the stance
            # (trailing) foot, its impulse from the hip speed here (the pre-impact one)
            t, y = float(sol.t_events[ilead][0]), sol.y_events[ilead][0].copy()
            self._keep(sol, t)
            self.t, self.y = t, y
            self.pushed = True
            P = acts.impulse(self.walker, y[:n])
            if not P > 0.0:
                return "go"
            tp, trailing = min(t + acts.pulse_s, t1), self.stance
            got = self._pulse(y, t, tp, trailing, P / acts.pulse_s, True)
            if got is None:
                return "end"
            t, y, touched = got
            self.t, self.y = t, y
            if not touched:  # the touchdown after the pulse: the next segments
                self.pulse_end = t  # (it comes about now: a short segment first)
                return "go"
            self._strike(t)  # the pulse straddles the touchdown: its rest after it
            if t < tp - 1e-12:
                got = self._pulse(y, t, tp, trailing, P / acts.pulse_s, False)
                if got is None:
                    return "end"
                self.t, self.y = got[:2]
            self.pushed = False
            return "strike"
        if not sol.t_events[1].size:  # the chunk's end
            self._keep(sol, np.inf)
            self.t, self.y = float(sol.t[-1]), sol.y[:, -1].copy()
            return "go"
        t, y = float(sol.t_events[1][0]), sol.y_events[1][0].copy()
        self._keep(sol, t)
        self.t, self.y = t, y
        trailing = self.stance
        before = (trailing, self.t_origin, self.ankle_on)
        self._strike(t)
        P = acts.impulse(self.walker, y[:n]) if not self.pushed else 0.0
        self.pushed = False
        if self.segments is not None and not P > 0.0:  # the next segment: from before it
            self.resume = (*self._back(t), *before)
        if P > 0.0 and acts.pulse_s == 0.0:
            y[:n], w = impulse_jump(self.walker, y[:n], trailing, P)
            y[n + 2] += w
        elif P > 0.0:  # no pulse before the touchdown (it came too fast): from it
            tp = min(t + acts.pulse_s, t1)
            got = self._pulse(y, t, tp, trailing, P / acts.pulse_s, False)
            if got is None:
                return "end"
            self.t, self.y = got[:2]
        return "strike"

    def samples(self) -> tuple[np.ndarray, np.ndarray]:
        """The run's samples so far: times (n,) [s] and the walker's states (n, 2 nq)."""
        return np.concatenate(self.ts), np.vstack(self.Ys)[:, :2 * self.walker.nq]

    def stopped(self):
        """The caller's stop predicate held after a heel strike: the present state is the
        run's last sample, its end ``heel_strike``."""
        self._keep_last(self.t, self.y)
        self.term, self.msg = RunEnd.HEEL_STRIKE, "the heel strikes asked for were made"

    def finish(self):
        """The run's result: ``(t (n,), X (n, 2 nq), nfev, njev, termination, message,
        event, work (n, len(work_names)))``, a trip or flight seen on the samples (as the
        passive run's :func:`~walkerlab.integrate.contact_events.first_event`) ending it
        there."""
        from .contact_events import first_event

        walker, limits = self.walker, self.limits
        n = 2 * walker.nq
        Y = np.vstack(self.Ys)
        t = np.concatenate(self.ts)
        if self.term is not RunEnd.FALL and self.term is not RunEnd.TRIP:
            ev = first_event(walker, t, Y[:, :n], limits, k0=1)
            if ev is not None:  # a trip or flight seen on the samples: the run ends there
                k = max(ev[1], 1)
                t, Y = t[:k], Y[:k]
                self.event, self.term = ev, RunEnd(ev[0])
                self.msg = f"{ev[0]}: on the samples of the powered run at t = {ev[2]:.4g} s"
        if self.event is not None and self.event[1] == -1:
            self.event = (*self.event[:1], len(t) - 1, *self.event[2:])
        return t, Y[:, :n], self.nfev, self.njev, self.term, self.msg, self.event, Y[:, n:]

    def _strike(self, t):
        """Heel strike at ``t`` [s]: the roles swap, the step's clock and ankle reset."""
        self.stance = 1 - self.stance
        self.t_strike = t
        self.step_s = t - self.t_origin
        self.t_origin, self.ankle_on = t, False

    def _back(self, te: float):
        """``(t, y)``: the last sample of the present compiled segment (or its start) at
        least :data:`RESUME_BACK_S` before the heel strike at ``te`` [s]."""
        t0, y0, sol = self.segment
        ok = np.flatnonzero(np.asarray(sol.t) <= te - RESUME_BACK_S)
        if not ok.size:
            return t0, np.asarray(y0, float).copy()
        return float(sol.t[ok[-1]]), sol.y[:, ok[-1]].copy()

    def segment_end(self, ta: float, span: float) -> float:
        """Where the loop's next chunk from ``ta`` [s] ends: ``ta + span`` on ``solve_ivp``;
        on compiled segments, which integrate to their end before their events are looked
        for, :data:`STEP_MARGIN` times the last step's duration after the present step's
        start (the integration past the touchdown is thrown away), at least
        :data:`MIN_SEGMENT_S` ahead; right after a push-off pulse, which ends at the
        predicted touchdown, :data:`AFTER_PULSE_S` ahead."""
        if self.segments is None:
            return ta + span
        if self.pulse_end is not None and ta <= self.pulse_end + 1e-12:
            # the pulse ended at the predicted touchdown: it comes within a few samples
            return ta + AFTER_PULSE_S
        if self.step_s is None:
            return ta + span
        return max(self.t_origin + STEP_MARGIN * self.step_s, ta + MIN_SEGMENT_S)

    def _keep_last(self, t, y):
        if t > self.ts[-1][-1] + 1e-12 if len(self.ts[-1]) else True:
            self.ts.append(np.array([t]))
            self.Ys.append(y[None])
