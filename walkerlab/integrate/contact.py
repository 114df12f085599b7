"""Time integration of the compliant-contact walker: backends, chunks and event location.

Where this sits: :mod:`walkerlab.models.contact` is the model (laws, geometry, terrain, the floating
walker); this module advances a model's state and finds where its run-ending events are;
:mod:`walkerlab.analysis.contact.gait` says what the samples mean (touchdowns, heel strikes,
steps, the run's outcome) and :mod:`walkerlab.analysis.contact.sim` puts the two together
(``simulate_contact``, a scene's contact run).  This module knows no gait: the strides cap
reaches it as a ``stop`` predicate over the samples.

Backends (:class:`~walkerlab.integrate.solver.Solver` ``method``): ``"odeint"``
(scipy.integrate.odeint = LSODA with little overhead), ``"cyrk_bdf"`` (CyRK's BDF over a
compiled RHS, no Python per evaluation; :mod:`walkerlab.integrate._cyrk`), ``"numbalsoda"``
(numbalsoda's LSODA from compiled code; optional extra,
:mod:`walkerlab.integrate.numbalsoda_backend`)
or a ``solve_ivp`` method (``"LSODA"``, ``"Radau"``, ``"BDF"``, ...), these given the
model's analytic Jacobian.  All run in chunks so a fall, a trip, a flight, the work bound,
the wall-time limit or the strides cap stops the run.

Work bound (``ContactLimits.max_rhs_evaluations``, the scene's
``contact_sim.max_rhs_evaluations``): a run ends with ``work_limit`` once it has evaluated its
right-hand side that many times, the same end on any machine.  The Python right-hand sides
(odeint, solve_ivp, the pinned phase) count every call; the compiled backends are asked
between chunks (a CyRK call stops after :data:`CYRK_STEPS_PER_CALL` steps, well above what a
chunk of a walking run takes, so its samples do not change, and the chunk goes on in odeint,
whose RHS counts); a powered run's hook between its segments.

Wall-time limit (``ContactLimits.wall_time_limit_s``, none by default): checked where the
work bound is, on ``time.perf_counter``; a run it ends (``time_limit``) depends on the
machine's speed, and the stages never keep it as a scene's result.  numbalsoda's chunks are
sized in wall time (each aims at :data:`CHUNK_WALL_S` seconds from the cost of the chunk
before, the first is short): numbalsoda is an optional extra, never the default method.

One loop (:func:`integrate_contact`'s free run) serves every walker: a powered one (with
``actuators``) brings its actuation hook (:class:`walkerlab.integrate.contact_powered.
ActuationHook`: the stance leg switched at touchdown, the push-off pulse, the ankle push-off,
the work integrals, a compiled right-hand side where the walker has one), which integrates
each chunk on solve_ivp with event location; the loop asks the strides cap after each of its
heel strikes.

Contact is decided by geometry only (the model): a foot gets the IMPACT force whenever it
is below the top of a patch and inside its horizontal extent, in every state, so a step that
would carry a foot from above a patch to deep inside it sees the force jump and is rejected
by the integrator's local error test: no step jumps over a touchdown.

Events (a trip, a fall, a flight) are located on the cubic Hermite interpolant of the
samples and their time derivatives (the RHS at each sample).  A **trip** is a foot crossing
the side of a patch (its along-slope edge) while below the patch's top; a **fall** is the hip
crossing ``fall_hip_height_m`` downward (:meth:`ContactWalker.fall_margin`, the one fall
test); **airborne** is the hip crossing ``airborne_hip_height_m`` upward (no leg reaches the
ground any more).  Each ends the run at the event, whose state is appended as the last sample.
Termination names are those of :mod:`walkerlab.integrate.ends`.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from walkerlab.models.contact.energy import (
    energy_rise_bound,
    first_energy_violation,
    side_entry,
    total_energy,
)

from . import _cyrk
from .compiled_segments import grid_inside
from .contact_events import (
    ContactLimits,
    first_event,
    hermite_root,
    hermite_state,
    run_atol,
    sample_grid,
    trip_or_failure,
    work_limit_message,
)
from .contact_powered import ActuationHook
from .ends import RunEnd, solver_words
from .solver import Solver

__all__ = ["CHUNK_WALL_S", "CYRK_STEPS_PER_CALL", "METHODS", "ContactIntegration",
           "ContactLimits", "first_event", "hermite_root", "hermite_state",
           "integrate_contact", "run_atol", "run_powered", "sample_grid", "trip_or_failure",
           "work_limit_message"]

#: Solver methods this module runs.
METHODS = ("odeint", "numbalsoda", "LSODA", "Radau", "BDF", "RK45", "DOP853",
           *_cyrk.CYRK_METHODS)

#: Wall time [s] a numbalsoda chunk aims at (the limit is checked between chunks).
CHUNK_WALL_S = 0.5

#: Most CyRK BDF steps in one chunk call (a 1 s chunk of the paper's walk takes a few
#: thousand): past it the chunk continues in odeint, whose RHS checks the wall-time limit.
CYRK_STEPS_PER_CALL = 100_000


@dataclass
class ContactIntegration:
    """Samples of one contact integration and why it stopped.

    Attributes
    ----------
    t, X : ndarray (n,), ndarray (n, N)
        Sample times [s] (the last one the event time if an event ended the run) and the
        states there, columns named by ``walker.state_names()``.
    termination : str
        ``t_final``, ``heel_strike`` (the ``stop`` predicate held: strides cap), ``fall``,
        ``trip``, ``airborne``, ``solver_failure``, ``work_limit`` or ``time_limit``
        (:mod:`walkerlab.integrate.ends`).
    message : str
    event : tuple or None
        ``(kind, sample, time [s], foot, patch edge [m])`` of the trip / fall / flight.
    nfev, njev : int
    wall_time_s : float
        [s].
    pin_end_time : float
        End of the pinned phase [s] (= t0 if none).
    work : ndarray (n, 4) or None
        A powered walker's work integrals at the samples [J]
        (:data:`walkerlab.models.contact.actuation.WORK_NAMES`); None for a passive one.
    """

    t: np.ndarray
    X: np.ndarray
    termination: str
    message: str
    event: tuple | None
    nfev: int
    njev: int
    wall_time_s: float
    pin_end_time: float
    work: np.ndarray | None = None


class _TimeLimit(Exception):
    """Internal: the wall-time limit ran out inside a right-hand side."""


class _WorkLimit(Exception):
    """Internal: the work bound (right-hand-side evaluations) ran out inside a right-hand
    side."""


def _guarded(f, deadline, calls=None, most=None):
    """``f`` that raises :class:`_TimeLimit` once ``time.perf_counter()`` passes ``deadline``
    and :class:`_WorkLimit` on its call past ``most`` calls (None: no bound), counting its
    calls in ``calls[0]``, if given (the count of a cut chunk)."""
    if not np.isfinite(deadline) and most is None and calls is None:
        return f
    calls = [0] if calls is None else calls
    timed = np.isfinite(deadline)

    def g(t, x, *a):
        calls[0] += 1
        if most is not None and calls[0] > most:
            raise _WorkLimit
        if timed and time.perf_counter() > deadline:
            raise _TimeLimit
        return f(t, x, *a)
    return g


def _work_left(limits, nfev: int):
    """Right-hand-side evaluations the run may still make (None: no bound)."""
    most = getattr(limits, "max_rhs_evaluations", None)
    return None if most is None else max(int(most) - int(nfev), 0)


def _run_pinned(walker, x0, t0, t_end, until_touchdown, limits, solver, deadline):
    """Integrate with leg2's foot held fixed.  Returns (t, X, nfev, njev, termination, msg)."""
    foot2 = np.asarray(walker.foot_positions(x0)).reshape(-1, 2)[1]
    z0 = walker.pinned_state(x0)

    def f(t, z):
        return walker.rhs_pinned(t, z, foot2)

    def touch(t, z):
        x = walker.pinned_to_full(z, foot2)
        cq = walker.foot_quantities(x)["leg1"]
        return -cq["penetration"][0] if cq["on_ground"][0] > 0 else 1.0

    touch.terminal = True
    touch.direction = -1

    def fall(t, z):
        return walker.fall_margin(walker.pinned_to_full(z, foot2), limits.fall_hip_height_m)

    fall.terminal = True
    fall.direction = -1
    events = [fall] + ([touch] if until_touchdown else [])
    from scipy.integrate import solve_ivp  # here: the compiled backends need no scipy.integrate

    try:
        sol = solve_ivp(_guarded(f, deadline, most=_work_left(limits, 0)), (t0, t_end), z0,
                        method="LSODA",
                        rtol=solver.rtol, atol=solver.atol,
                        max_step=solver.max_step_s or np.inf,
                        t_eval=sample_grid(t0, t_end, limits.sample_rate_hz), events=events,
                        dense_output=True)
    except _TimeLimit:
        return (np.array([t0]), x0[None], 0, 0, RunEnd.TIME_LIMIT,
                "wall-time limit reached in the pinned phase")
    except _WorkLimit:
        return (np.array([t0]), x0[None], int(limits.max_rhs_evaluations), 0,
                RunEnd.WORK_LIMIT, work_limit_message(limits) + " in the pinned phase")
    t, Z = sol.t, sol.y.T
    if sol.status == 1:  # stopped on an event: append the event point
        te = (sol.t_events[1][0] if (until_touchdown and sol.t_events[1].size)
              else sol.t_events[0][0])
        if t.size == 0 or te > t[-1]:
            t = np.append(t, te)
            Z = np.vstack([Z, sol.sol(te)])
    X = np.array([walker.pinned_to_full(z, foot2) for z in Z])
    fell = sol.status == 1 and sol.t_events[0].size > 0
    term = (RunEnd.FALL if fell else RunEnd.T_FINAL if sol.status >= 0
            else RunEnd.SOLVER_FAILURE)
    return t, X, sol.nfev, sol.njev, term, sol.message


class _Backend:
    """One chunk of a backend: ``chunk(xa, tg) -> (t, X, ok, message, nfev, njev)`` with the
    samples reached after ``tg[0]``; raises :class:`_TimeLimit` from a Python RHS."""

    def __init__(self, walker, solver: Solver, use_jac: bool, deadline: float):
        self.walker, self.solver, self.method = walker, solver, solver.method
        self.max_step = solver.max_step_s if solver.max_step_s else np.inf
        self.calls = [0]  # RHS calls of the current chunk (Python backends)
        self.deadline = deadline
        self.frhs = _guarded(walker.rhs, deadline, self.calls)
        self.fjac = walker.jac if use_jac else None
        self.compiled = self.method == "numbalsoda" or self.method in _cyrk.CYRK_METHODS
        self.sized_by_wall = self.method == "numbalsoda"
        if self.method == "numbalsoda" and np.isfinite(self.max_step):
            raise ValueError("contact_solver.max_step_s is not supported by method numbalsoda")
        self.data = walker.pack() if self.compiled else None
        self.atol = run_atol(walker, solver.atol, self.method)

    def bound(self, most):
        """Count this chunk's Python RHS calls from 0 and allow ``most`` of them (None: no
        bound)."""
        self.calls[0] = 0
        self.frhs = _guarded(self.walker.rhs, self.deadline, self.calls, most)

    def odeint_chunk(self, xs, tg):
        from scipy.integrate import ODEintWarning, odeint

        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ODEintWarning)
            X, info = odeint(self.frhs, xs, tg, Dfun=self.fjac, tfirst=True,
                             rtol=self.solver.rtol, atol=self.atol,
                             hmax=self.max_step if np.isfinite(self.max_step) else 0.0,
                             full_output=True, mxstep=200000)
        ok = info["message"] == "Integration successful."
        # after a failure odeint's info arrays past the last sample reached are not filled in
        # (garbage was seen): use them up to that sample only
        reached = info["tcur"] >= tg[1:] - 1e-14
        nk = len(tg) if ok or reached.all() else int(np.argmin(reached)) + 1
        if nk < 2:
            return tg[1:1], X[1:1], ok, info["message"], 0, 0
        return (tg[1:nk], X[1:nk], ok, info["message"], int(info["nfe"][nk - 2]),
                int(info["nje"][nk - 2]))

    def chunk(self, xa, tg):
        s = self.solver
        if self.method == "odeint":
            return self.odeint_chunk(xa, tg)
        if self.method == "numbalsoda":  # whole chunk in compiled code (FD Jacobian)
            from . import numbalsoda_backend as lsoda

            X, ok, nf = lsoda.solve_chunk(xa, tg, self.data, s.rtol, s.atol,
                                            kernels=self.walker.kernels)
            nk = len(tg) if ok else 1  # rows after a failure are undefined: drop the chunk
            m = "Integration successful." if ok else "numbalsoda LSODA failed in this chunk"
            return tg[1:nk], X[1:nk], ok, m, nf, 0
        if self.method in _cyrk.CYRK_METHODS:  # whole chunk in compiled code (CyRK BDF)
            X, ok, nf, m = _cyrk.solve_chunk(self.method, xa, tg, self.data, s.rtol, self.atol,
                                             self.max_step, CYRK_STEPS_PER_CALL,
                                             kernels=self.walker.kernels,
                                             ready=getattr(self.walker, "rhs_ready", None))
            tn, Xn, nj = tg[1:len(X)], X[1:], 0
            if not ok:  # a force jump BDF cannot step over (a foot hitting the side of a
                # patch below its top): odeint, which grinds through it as a plain odeint run
                # does, from the last sample reached to the chunk end
                k = max(len(X) - 1, 0)
                tr, Xr, ok, m, nf2, nj = self.odeint_chunk(X[k] if len(X) else xa, tg[k:])
                nf += nf2
                tn, Xn = np.concatenate([tn, tr]), np.vstack([Xn, Xr])
            return tn, Xn, ok, m, nf, nj
        from scipy.integrate import solve_ivp

        kw = {"jac": self.fjac} if self.fjac is not None else {}
        sol = solve_ivp(self.frhs, (tg[0], tg[-1]), xa, method=self.method, rtol=s.rtol,
                        atol=self.atol, max_step=self.max_step, t_eval=tg, **kw)
        return sol.t[1:], sol.y.T[1:], sol.status == 0, sol.message, sol.nfev, sol.njev


def _run_free(walker, x0, t0, t1, solver, limits, deadline, stop, hook=None, spent=0):
    """Integrate the free walker until t1, an event, the deadline or ``stop``: the one
    contact integrator loop, passive or powered.

    ``hook``: a powered walker's actuation hook
    (:class:`walkerlab.integrate.contact_powered.ActuationHook`): it integrates each chunk
    (its discrete state, events and transitions), the loop asks ``stop`` after each of its
    heel strikes; None: the passive walker on the solver's backend, ``stop`` asked after each
    chunk, the energy guard and the events checked on each chunk's samples.  ``spent``:
    right-hand-side evaluations the run made before (its pinned phase), charged to the work
    bound.

    Returns (t, X, nfev, njev, termination, message, event, work), ``work`` None for a
    passive run (:class:`ContactIntegration`)."""
    if hook is not None:
        return _run_hooked(hook, x0, t0, t1, limits, stop)
    be = _Backend(walker, solver, limits.use_jacobian, deadline)
    rate = limits.sample_rate_hz
    ts, Xs, nfev, njev = [np.array([t0])], [x0[None]], 0, 0
    ta, xa = t0, x0
    term, msg, event = RunEnd.T_FINAL, "Integration successful.", None
    n_checked = 1
    # the energy guard (walkerlab.models.contact.energy): no sample above the start's energy + bound
    # (a powered walker gains energy: no guard)
    e_start = float(total_energy(walker, x0)[0])
    e_bound = energy_rise_bound(walker, x0, solver.rtol)
    guarded = False  # the energy guard ended the run (no event state to interpolate)
    # numbalsoda: the first chunk is short, later ones sized to CHUNK_WALL_S
    span = min(limits.chunk_s, 20.0 / rate) if be.sized_by_wall else limits.chunk_s
    while ta < t1 - 1e-12:
        tb = min(ta + span, t1)
        tg = sample_grid(ta, tb, rate)
        w0 = time.perf_counter()
        be.bound(_work_left(limits, spent + nfev))
        try:
            tn, Xn, ok, m, nf, nj = be.chunk(xa, tg)
        except _TimeLimit:
            nfev += be.calls[0]
            term, msg = RunEnd.TIME_LIMIT, "wall-time limit reached inside a chunk"
            break
        except _WorkLimit:
            nfev += be.calls[0] - 1  # the call that went past the bound was not made
            term, msg = RunEnd.WORK_LIMIT, work_limit_message(limits)
            break
        nfev += nf
        njev += nj
        if be.sized_by_wall and tn.size:
            per_s = (time.perf_counter() - w0) / max(tn[-1] - ta, 1e-12)
            left = max(min(CHUNK_WALL_S, deadline - time.perf_counter()), 1e-3)
            span = float(np.clip(left / max(per_s, 1e-12), 2.0 / rate, limits.chunk_s))
        bad = first_energy_violation(walker, Xn, e_start, e_bound) if tn.size else None
        n_prev = sum(len(t) for t in ts)
        ts.append(tn)
        Xs.append(Xn)
        t_all, X_all = np.concatenate(ts), np.vstack(Xs)
        event = _chunk_event(walker, t_all, X_all, limits, n_checked, n_prev, bad)
        n_checked = len(t_all)
        if event is None and bad is not None:  # blown-up samples are not data
            ts[-1], Xs[-1] = tn[:bad], Xn[:bad]
            event, term, msg = _energy_guard_end(walker, ta, xa, tn, Xn, bad, n_prev, e_bound,
                                                 rate)
            guarded = True
            break
        if event is not None:
            term = RunEnd(event[0])
            break
        if not ok:
            term, msg, event = trip_or_failure(walker, float(t_all[-1]), X_all[-1], str(m),
                                               len(t_all) - 1, 2.0 / rate)
            guarded = True  # the last sample is the run's end (no event state to interpolate)
            break
        if _work_left(limits, spent + nfev) == 0 and t_all[-1] < t1 - 1e-12:
            term, msg = RunEnd.WORK_LIMIT, work_limit_message(limits)
            break
        if time.perf_counter() > deadline and t_all[-1] < t1 - 1e-12:
            term, msg = RunEnd.TIME_LIMIT, "wall-time limit reached"
            break
        if stop is not None and stop(t_all, X_all):
            term, msg = RunEnd.HEEL_STRIKE, "the heel strikes asked for were made"
            break
        ta, xa = t_all[-1], X_all[-1]
    t_all, X_all = np.concatenate(ts), np.vstack(Xs)
    if event is not None and not guarded:  # cut at the event and append the event state
        t_all, X_all, msg = _cut_at_event(walker, t_all, X_all, event, term)
    return t_all, X_all, nfev, njev, term, msg, event, None


def _chunk_event(walker, t_all, X_all, limits, n_checked: int, n_prev: int, bad):
    """The first event (:func:`first_event`, from sample ``n_checked`` on) of a passive run's
    samples so far, ``n_prev`` of them before this chunk, ``bad`` the chunk's first sample
    over the energy guard (None: none): looked for among the trustworthy samples and the
    first one past them (a trip's first sample on the patch already carries the spring's
    energy); a fall or flight seen only on a blown-up sample is not one (None)."""
    n_ok = len(t_all) if bad is None else n_prev + bad + 1
    event = first_event(walker, t_all[:n_ok], X_all[:n_ok], limits, k0=n_checked)
    if event is not None and bad is not None and event[1] >= n_prev + bad \
            and event[0] != "trip":
        event = None  # a fall or flight seen only on a blown-up sample is not one
    return event


def _run_hooked(hook, x0, t0, t1, limits, stop):
    """:func:`_run_free`'s loop for a powered walker: ``hook`` integrates each chunk (segments
    between its events), ``stop`` asked after each of its heel strikes; returns
    ``hook.finish()``."""
    hook.start(x0, t0)
    ta, span = t0, limits.chunk_s
    while ta < t1 - 1e-12:
        tb = min(hook.segment_end(ta, span), t1)
        step = hook.advance(tb, t1)
        if step == "end":
            break
        ta = hook.t
        if step == "strike" and stop is not None and stop(*hook.samples()):
            if hook.t == hook.t_strike:  # the run stands at the touchdown: on to its next
                # sample, so that the samples show this heel strike (the touchdown event's
                # root has the swing foot's penetration 0 to rounding: a count on the
                # samples would take it either way)
                after = grid_inside(hook.grid, hook.t, t1)
                if hook.advance(float(after[0]) if after.size else t1, t1) == "end":
                    break
            hook.stopped()
            break
    return hook.finish()


def _energy_guard_end(walker, ta, xa, tn, Xn, bad: int, n_prev: int, e_bound: float,
                      rate: float):
    """How a run of :func:`_run_free` ends when the energy guard fires at sample ``bad`` of
    the chunk ``(tn, Xn)`` (started at ``ta``, ``xa``; ``n_prev`` samples before it): a
    solver failure at the last trustworthy sample (energy above the start's by more than
    ``e_bound`` [J]), or a trip when :func:`~walkerlab.models.contact.energy.side_entry`
    finds the cause, a foot below the patch tops in a gap that reaches a patch's side within
    ``2 / rate`` s of that sample.  Returns ``(event, termination, message)``, ``event``
    None but for a trip."""
    event = None
    last = Xn[bad - 1] if bad else xa
    trip = side_entry(walker, last, 2.0 / rate)
    msg = (f"total energy rose above its start by more than {e_bound:.3g} J at "
           f"t = {tn[bad]:.6g} s ({energy_source_words(walker)}): the run ends "
           "at the last trustworthy sample")
    term = RunEnd.SOLVER_FAILURE
    if trip is not None:  # the cause: a foot in a gap entered a patch's side
        foot, edge, ahead, depth = trip
        t_last = float(tn[bad - 1]) if bad else float(ta)
        event = ("trip", n_prev + bad - 1, t_last + ahead, foot, edge)
        term = RunEnd.TRIP
        msg = (f"trip: {foot}'s foot, {depth:.3g} m below the patch tops in a gap, "
               f"entered a patch from its side; {msg}")
    return event, term, msg


def energy_source_words(walker) -> str:
    """Why the energy guard's rise is not physics, from what the walker has: a passive
    walker cannot gain energy; one whose joints carry a law that does work (a hip-roll law,
    ``kernels.STANCE_LAW``) gains some from it, but not this much (the guard's bound allows
    for it: :func:`walkerlab.models.contact.energy.energy_rise_bound`)."""
    if getattr(getattr(walker, "kernels", None), "STANCE_LAW", False):
        return ("more than this walker's joint law can put in: a blow-up, not the law's "
                "work")
    return "a passive contact walker cannot gain energy"


def _cut_at_event(walker, t_all: np.ndarray, X_all: np.ndarray, event: tuple, term: RunEnd):
    """The samples of a :func:`_run_free` run cut at its ``event`` (a trip, fall or flight:
    ``(kind, k, time, foot, edge)`` of :func:`first_event`), with the event's state on the
    Hermite interpolant appended as the last sample when the event lies after sample
    ``k - 1``; returns ``(t, X, message)``, the message naming the termination ``term``."""
    _, k, te, _, _ = event
    k = max(k, 1)
    xe = hermite_state(walker, t_all[k - 1], t_all[k], X_all[k - 1], X_all[k], te) \
        if te > t_all[k - 1] else X_all[k - 1]
    t_all = np.append(t_all[:k], te) if te > t_all[k - 1] else t_all[:k]
    X_all = np.vstack([X_all[:k], xe[None]]) if len(t_all) > k else X_all[:k]
    msg = {RunEnd.TRIP: "trip: a foot hit the side of a patch below its top",
           RunEnd.FALL: "fall: hip below the fall height",
           RunEnd.AIRBORNE: "airborne: hip above the airborne height"}[term]
    return t_all, X_all, msg


def run_powered(walker, x0, t0, t1, solver, limits, deadline, stop):
    """A powered walker's free run (no pinned phase) on the one loop with its actuation hook
    (:class:`walkerlab.integrate.contact_powered.ActuationHook`).

    Parameters
    ----------
    walker : ContactWalker
        With ``actuators``; leg2 in stance at the start.
    x0 : ndarray, shape (2 nq,)
    t0, t1 : float
        [s].
    solver : Solver
    limits : ContactLimits
    deadline : float
        ``time.perf_counter()`` value past which the run stops (``time_limit``).
    stop : callable or None
        ``stop(t, X) -> bool``, asked after each heel strike (strides cap) on the samples
        so far (the heel strike just made not among them when the run stands at its
        touchdown); a run it stops there goes on to its next sample, so that the samples
        show that heel strike.

    Returns
    -------
    tuple
        ``(t (n,), X (n, 2 nq), nfev, njev, termination, message, event, work)``, ``work``
        (n, len(work_names)) [J] the integrals of ``walker.actuators.work_names`` at the
        samples.
    """

    hook = ActuationHook(walker, solver, limits, deadline,
                         sample_grid(t0, t1, limits.sample_rate_hz))
    return _run_free(walker, np.asarray(x0, float), t0, t1, solver, limits, deadline, stop,
                     hook)


def integrate_contact(walker, x0: np.ndarray, t0: float, t_final: float,
                      solver: Solver, limits: ContactLimits,
                      stop: Callable[[np.ndarray, np.ndarray], bool] | None = None
                      ) -> ContactIntegration:
    """Integrate the contact walker from ``x0`` at ``t0`` to ``t_final`` or an ending event.

    Parameters
    ----------
    walker : ContactWalker
    x0 : ndarray (N,)
        Initial state, columns named by ``walker.state_names()`` (SI).
    t0, t_final : float
        Start and end time [s].
    solver : Solver
        Method (:data:`METHODS`; ``backend`` is not read), tolerances (``atol`` well below
        the penetration depth, ~6e-5 m for the paper's contact), largest step.
    limits : ContactLimits
    stop : callable, optional
        ``stop(t (n,), X (n, N)) -> bool``, asked after each chunk (a powered walker's: after
        each heel strike, :func:`_run_hooked`); True ends the run with termination
        ``heel_strike`` (the strides cap of :mod:`walkerlab.analysis.contact.sim`).

    Returns
    -------
    ContactIntegration

    Raises
    ------
    ValueError
        Unknown method; ``max_step_s`` with numbalsoda; numbalsoda not installed
        (:class:`walkerlab.integrate.numbalsoda_backend.MissingNumbalsoda`, also an ImportError).
    """
    if solver.method not in METHODS:
        raise ValueError(f"contact_solver.method must be one of {', '.join(METHODS)}, "
                         f"not {solver.method!r}")
    x0 = np.asarray(x0, dtype=float)
    wall = time.perf_counter()
    deadline = wall + (limits.wall_time_limit_s if limits.wall_time_limit_s else np.inf)
    ts, Xs, nfev, njev = [], [], 0, 0
    term, msg, event = RunEnd.T_FINAL, "", None
    t_pin = t0
    if limits.pin_stance_until != "none":
        t_end = (t_final if limits.pin_stance_until == "first_touchdown"
                 else min(t0 + limits.pin_time_s, t_final))
        tp, Xp, nf, nj, term, msg = _run_pinned(
            walker, x0, t0, t_end, limits.pin_stance_until == "first_touchdown", limits,
            solver, deadline)
        ts.append(tp)
        Xs.append(Xp)
        nfev += nf
        njev += nj
        t_pin, x0 = tp[-1], Xp[-1]
        if term is RunEnd.FALL:
            event = (RunEnd.FALL.value, len(tp) - 1, float(tp[-1]), "", np.nan)
    work = None
    if term is RunEnd.T_FINAL and t_pin < t_final - 1e-12:
        hook = None
        if getattr(walker, "actuators", None) is not None:  # (never pinned: the scene refuses)

            hook = ActuationHook(walker, solver, limits, deadline,
                                 sample_grid(t_pin, t_final, limits.sample_rate_hz))
        tf, Xf, nf, nj, term, msg, event, work = _run_free(walker, x0, t_pin, t_final, solver,
                                                           limits, deadline, stop, hook,
                                                           spent=nfev)
        if ts:
            tf, Xf = tf[1:], Xf[1:]
        ts.append(tf)
        Xs.append(Xf)
        nfev += nf
        njev += nj
    return ContactIntegration(t=np.concatenate(ts), X=np.vstack(Xs), termination=term.value,
                              message=solver_words(str(msg)), event=event, nfev=int(nfev),
                              njev=int(njev),
                              wall_time_s=time.perf_counter() - wall,
                              pin_end_time=float(t_pin), work=work)
