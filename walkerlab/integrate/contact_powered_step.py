"""The powered contact step map's flows (:mod:`walkerlab.analysis.contact.step_map`): a powered
walker from a state through its next heel strike to a section (:func:`powered_to_section`),
and one push-off (:func:`push_off`), on the actuation hook's segments
(:class:`walkerlab.integrate.contact_powered.ActuationHook`, whose module docstring tells the
pulse's timing).

With a compiled method (``cyrk_bdf``) and torque laws that are data, the segments are compiled
(:class:`walkerlab.integrate.compiled_segments.CompiledSegments`: CyRK's BDF over the
generated powered right-hand side, the events bracketed on a :data:`SECTION_DT_S` grid and
located on the dense output), in chunks of at most :data:`SECTION_CHUNK_S`; otherwise (a
``solve_ivp`` method, a replay's Python laws) :func:`scipy.integrate.solve_ivp` with event
location.  The periodic-gait search evaluates this map some hundred times, so the compiled
map is what keeps a powered ``contact-sim`` as cheap as a passive one.
"""

from __future__ import annotations

import numpy as np

from .contact_powered import ActuationHook, compiled_segments, impulse_jump
from .ends import RunEnd
from .powered_events import pulse_event, pulse_lead_s

__all__ = ["SECTION_CHUNK_S", "SECTION_DT_S", "powered_to_section", "push_off"]

#: The compiled map's sample spacing [s]: its events (touchdown, pulse start, section, fall)
#: are bracketed on these samples (the passive map's grid,
#: :meth:`walkerlab.analysis.contact.step_map.StepMap.next_section`).
SECTION_DT_S = 2e-3
#: The compiled map's segments end this long after their start at most [s] (a compiled
#: segment integrates to its end before its events are looked for).
SECTION_CHUNK_S = 0.25


def _hook(walker, solver, limits, deadline, t0: float, t1: float):
    """An :class:`ActuationHook` over ``[t0, t1]`` [s] on compiled segments where they apply
    (:func:`~walkerlab.integrate.contact_powered.compiled_segments`, a :data:`SECTION_DT_S`
    grid), else on ``solve_ivp``."""
    k = max(int(np.ceil((t1 - t0) / SECTION_DT_S - 1e-9)), 1)
    grid = np.append(t0 + SECTION_DT_S * np.arange(k), t1)
    run = ActuationHook(walker, solver, limits, deadline, grid)
    run.segments = compiled_segments(walker, solver, grid)
    return run


def _section_run(walker, stance: int, section, solver, t_max: float, deadline: float,
                 fall_hip_height_m: float):
    """:func:`powered_to_section`'s run from t = 0 with leg ``stance`` in stance, its event
    of the section's upward zero and its pulse's lead event (None: a pulse that does not
    start ahead of the touchdown).

    Returns
    -------
    run : ActuationHook
    cross, lead : callable, callable or None
    """
    from .contact_events import ContactLimits

    limits = ContactLimits(fall_hip_height_m=fall_hip_height_m)
    run = _hook(walker, solver, limits, deadline, 0.0, t_max)
    run.stance, run.t_origin = stance, 0.0
    acts = walker.actuators
    cross = _section_event(section, 2 * walker.nq)
    lead = (pulse_event(walker, lambda: run.stance, acts.pulse_s) if pulse_lead_s(acts) > 0
            else None)
    return run, cross, lead


def powered_to_section(walker, x0, stance: int, section, solver, t_max: float,
                       deadline: float = np.inf, fall_hip_height_m: float = 0.5):
    """Integrate a powered walker from ``x0`` (leg ``stance`` in stance) through the next heel
    strike (the push-off pulse at the stance foot ending at the predicted touchdown of the
    other leg ahead, the touchdown, the roles swap; as a powered run of
    :func:`walkerlab.integrate.contact.integrate_contact`) to the next
    upward zero of ``section(x)``: the powered contact step map's flow
    (:mod:`walkerlab.analysis.contact.step_map`).

    Parameters
    ----------
    walker : ContactWalker
        With ``actuators``.
    x0 : ndarray, shape (2 nq,)
        State at t = 0 [m, rad, m/s, rad/s].
    stance : int
        The stance leg at the start (0: leg1, 1: leg2); time-based torque laws count from
        t = 0.
    section : callable
        ``section(x)``: a float of a state ``x`` (2 nq,), and, on compiled segments, the
        values (m,) of states (m, 2 nq) (e.g. ``x[..., i] - x[..., j]``); searched only
        after the heel strike (upward zero).
    solver : Solver
        A compiled method (:data:`walkerlab.integrate._cyrk.CYRK_METHODS`: compiled
        segments, module docstring) or a
        :data:`~walkerlab.integrate.contact_powered.IVP_METHODS` method (others run as
        ``LSODA``), ``rtol``, ``atol``.
    t_max : float
        Give up after this time [s].
    deadline : float
        ``time.perf_counter()`` value past which the run stops.
    fall_hip_height_m : float
        The fall height [m].

    Returns
    -------
    (t_e, x_e, end) : (float, ndarray (2 nq,), RunEnd)
        ``end`` ``T_FINAL`` at the section; ``FALL``, ``TIME_LIMIT``, ``SOLVER_FAILURE``
        (``t_e``, ``x_e`` then where the run stopped), or ``NO_HEEL_STRIKE`` when neither a
        heel strike and the section came within ``t_max``.
    """
    run, cross, lead = _section_run(walker, stance, section, solver, t_max, deadline,
                                    fall_hip_height_m)
    n, acts = 2 * walker.nq, walker.actuators
    y = np.concatenate([np.asarray(x0, float), np.zeros(len(acts.work_names))])
    # pushed: the pulse of the heel strike to come has run (or is running)
    t, struck, pushed = 0.0, False, False
    while t < t_max - 1e-12:
        arm = lead is not None and not struck and not pushed
        tb = t_max if run.segments is None else min(t + SECTION_CHUNK_S, t_max)
        sol = run._run(y, t, tb, None,
                       [run.fall, cross if struck else run.touch] + ([lead] if arm else []))
        if sol is None:
            return t, y[:n], run.term
        if sol.t_events[0].size:
            return float(sol.t_events[0][0]), sol.y_events[0][0][:n], RunEnd.FALL
        if arm and sol.t_events[2].size and not sol.t_events[1].size:
            # the pulse, pulse_s before the predicted touchdown (as ActuationHook.advance)
            pushed = True
            got, end = _lead_pulse(run, float(sol.t_events[2][0]), sol.y_events[2][0].copy())
            if got is None:
                return end
            t, y, struck = got
            continue
        if not sol.t_events[1].size:
            if tb < t_max - 1e-12:  # a compiled chunk's end: the next chunk
                t, y = float(sol.t[-1]), sol.y[:, -1].copy()
                continue
            return float(sol.t[-1]), sol.y[:n, -1], RunEnd.NO_HEEL_STRIKE
        t, y = float(sol.t_events[1][0]), sol.y_events[1][0].copy()
        if struck:
            return t, y[:n], RunEnd.T_FINAL
        struck, trailing = True, run.stance
        run.stance, run.t_origin = 1 - trailing, t  # heel strike: the roles swap
        P = 0.0 if pushed else acts.impulse(run.walker, y[:n])
        got, end = _touchdown_push(run, y, t, trailing, P)
        if got is None:
            return end
        t, y = got
    return t, y[:n], RunEnd.NO_HEEL_STRIKE


def _section_event(section, n: int):
    """Event: ``section`` of the walker's state (the first ``n`` entries) crosses 0 upwards
    (terminal); its ``values`` on states (m, n), ``-section``, cross 0 downwards (the
    compiled segments' direction)."""
    def cross(t, y):
        return section(y[:n])

    def values(X, tab=None):
        return -np.asarray(section(X), float)

    cross.values = values
    cross.terminal, cross.direction = True, 1.0
    return cross


def _pulse_segment(run, y, t, tp, trailing, force, events):
    """The push-off pulse ``force`` [N] along leg ``trailing`` from ``t`` to ``tp`` [s] on
    ``run`` (an :class:`~walkerlab.integrate.contact_powered.ActuationHook`), watching
    ``events`` (the fall first, then possibly the touchdown).  Returns ``((t, y, touched),
    None)``, or ``(None, (t, x, end))`` when the run ends here (:func:`powered_to_section`'s
    answer)."""
    n = 2 * run.walker.nq
    sol = run._run(y, t, tp, (trailing, force), events)
    if sol is None:
        return None, (t, y[:n], run.term)
    if sol.t_events[0].size:
        return None, (float(sol.t_events[0][0]), sol.y_events[0][0][:n], RunEnd.FALL)
    if len(events) > 1 and sol.t_events[1].size:
        return (float(sol.t_events[1][0]), sol.y_events[1][0].copy(), True), None
    return (float(sol.t[-1]), sol.y[:, -1].copy(), False), None


def _lead_pulse(run, t, y):
    """The pulse started ``pulse_s`` before the predicted touchdown at ``(t, y)``, its impulse
    from the hip speed there; the touchdown inside it swaps the roles and the pulse runs on
    to its end.  Returns ``((t, y, struck), None)`` or ``(None, end)`` as
    :func:`_pulse_segment`."""
    acts = run.walker.actuators
    P = acts.impulse(run.walker, y[:2 * run.walker.nq])
    if not P > 0.0:
        return (t, y, False), None
    tp, trailing = t + acts.pulse_s, run.stance
    got, end = _pulse_segment(run, y, t, tp, trailing, P / acts.pulse_s, [run.fall, run.touch])
    if got is None:
        return None, end
    t, y, touched = got
    if touched:  # the heel strike inside the pulse: the roles swap, its rest
        run.stance, run.t_origin = 1 - trailing, t
        if t < tp - 1e-12:
            got, end = _pulse_segment(run, y, t, tp, trailing, P / acts.pulse_s, [run.fall])
            if got is None:
                return None, end
            t, y = got[:2]
    return (t, y, touched), None


def _touchdown_push(run, y, t, trailing, P):
    """The push-off ``P`` [N s] of a heel strike at ``(t, y)`` with no pulse before it (it came
    too fast): the impulse at once (``pulse_s = 0``) or the pulse from the touchdown.
    Returns ``((t, y), None)`` or ``(None, end)`` as :func:`_pulse_segment`."""
    walker, acts = run.walker, run.walker.actuators
    n = 2 * walker.nq
    if P > 0.0 and acts.pulse_s == 0.0:
        y[:n] = impulse_jump(walker, y[:n], trailing, P)[0]
    elif P > 0.0:  # no pulse before the touchdown (it came too fast): from it
        got, end = _pulse_segment(run, y, t, t + acts.pulse_s, trailing, P / acts.pulse_s,
                                  [run.fall])
        if got is None:
            return None, end
        t, y = got[:2]
    return (t, y), None


def push_off(walker, x, t: float, trailing: int, solver, deadline: float = np.inf,
             fall_hip_height_m: float = 0.5):
    """The push-off of a heel strike from ``(t, x)``, the pulse's start (``pulse_s`` before
    the predicted touchdown, :func:`pulse_lead`): the pulse ``P / pulse_s`` along leg
    ``trailing`` for ``pulse_s`` seconds on the powered contact integrator (the touchdown
    inside it not looked for: a walker powered by push-off alone, whose flow does not depend
    on which leg is in stance), or, at the touchdown, with ``pulse_s = 0`` the impulse at
    once (:func:`impulse_jump`).

    Parameters
    ----------
    walker : ContactWalker
        With ``actuators``.
    x : ndarray, shape (2 nq,)
        The state at the pulse's start (the touchdown for ``pulse_s = 0``) [m, rad, m/s,
        rad/s].
    t : float
        Its time [s].
    trailing : int
        The trailing leg (0: leg1, 1: leg2), the old stance leg.
    solver, deadline, fall_hip_height_m
        As :func:`powered_to_section`.

    Returns
    -------
    (t_end, x_end, end) : (float, ndarray (2 nq,), RunEnd)
        After the pulse (``T_FINAL``), or where a fall, the deadline or a solver failure
        stopped it.
    """
    from .contact_events import ContactLimits

    acts = walker.actuators
    x = np.asarray(x, float)
    P = acts.impulse(walker, x)
    if P <= 0.0:
        return t, x, RunEnd.T_FINAL
    if acts.pulse_s == 0.0:
        return t, impulse_jump(walker, x, trailing, P)[0], RunEnd.T_FINAL
    n, nw = 2 * walker.nq, len(walker.actuators.work_names)
    run = _hook(walker, solver, ContactLimits(fall_hip_height_m=fall_hip_height_m), deadline,
                t, t + acts.pulse_s)
    run.stance, run.t_origin = 1 - trailing, t
    sol = run._run(np.concatenate([x, np.zeros(nw)]), t, t + acts.pulse_s,
                   (trailing, P / acts.pulse_s), [run.fall])
    if sol is None:
        return t, x, run.term
    if sol.t_events[0].size:
        return float(sol.t_events[0][0]), sol.y_events[0][0][:n], RunEnd.FALL
    return float(sol.t[-1]), sol.y[:n, -1], RunEnd.T_FINAL
