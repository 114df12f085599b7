"""A CPU-time limit on each walking step integrated inside a block (the maps and walks of
the in-memory walker, :class:`walkerlab.api.walker.Walker`).

A state far from any gait (rates of 1e10 rad/s, a spring at its cap) can make the adaptive
integrator take steps so small that one walking step runs for minutes before it ends by
``max_step_time_s`` of *simulated* time.  Inside :func:`integration_time_limit` each walking
step (:func:`walkerlab.integrate.rigid.integrate_step` restarts the clock,
:func:`start_step_clock`) may use the limit's CPU time: every
right-hand-side evaluation of the ``scipy`` and ``cyrk`` backends (every 64th, and every
phase start of the ``cyrk_compiled`` backend, whose flow calls no Python) checks this
thread's CPU time, and past the limit raises :class:`IntegrationTimeLimit` out of the
integration.  Inside :func:`integration_deadline` (a gait search's CPU-time budget,
:func:`walkerlab.analysis.gait.budget.search_budget`) the same checks raise
:class:`IntegrationDeadline` once the thread's CPU clock passes an absolute deadline, so that
one walking step cannot outlast the budget of the search it belongs to.  Outside such blocks
nothing is checked and nothing is wrapped; inside them the right-hand side returns the same
values (the integrations are the same, bit for bit).
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["IntegrationDeadline", "IntegrationTimeLimit", "check_time_limit",
           "integration_deadline", "integration_time_limit", "limited", "start_step_clock"]

#: the clock: this thread's CPU time (a loaded machine does not trip the limit)
_clock = time.thread_time
#: right-hand-side evaluations between two looks at the clock
CHECK_EVERY = 64


class IntegrationTimeLimit(RuntimeError):
    """A walking step inside :func:`integration_time_limit` used up its CPU time."""

    def __init__(self, seconds: float):
        super().__init__(f"the walking step used up its {seconds:g} s of CPU time")
        self.seconds = seconds


class IntegrationDeadline(RuntimeError):
    """The thread's CPU clock passed the deadline of :func:`integration_deadline` during a
    walking step; ``t`` [s] and ``x`` (the state, [rad, rad/s]) are where the integration
    was."""

    def __init__(self, t: float, x):
        super().__init__(f"the walking step passed its deadline at t = {t:.4g} s")
        self.t, self.x = t, x


class _Limit(threading.local):
    deadline = math.inf  # this step's (integration_time_limit)
    seconds = math.inf
    hard = math.inf  # an absolute one on every step (integration_deadline)


_LIMIT = _Limit()


@contextmanager
def integration_time_limit(seconds: float) -> Iterator[None]:
    """Bound each walking step integrated inside to ``seconds`` of this thread's CPU time
    (nested limits keep the smaller).

    Raises
    ------
    IntegrationTimeLimit
        From the integration under way once its step's time is used up.
    """
    outer = (_LIMIT.deadline, _LIMIT.seconds)
    seconds = min(float(seconds), _LIMIT.seconds)
    _LIMIT.deadline, _LIMIT.seconds = min(_LIMIT.deadline, _clock() + seconds), seconds
    try:
        yield
    finally:
        _LIMIT.deadline, _LIMIT.seconds = outer


@contextmanager
def integration_deadline(at: float) -> Iterator[None]:
    """Stop every walking step integrated inside once this thread's CPU clock
    (``time.thread_time``) passes ``at`` [s] (nested deadlines keep the earlier; ``inf``:
    nothing checked).

    Raises
    ------
    IntegrationDeadline
        From the integration under way once the clock passes ``at``.
    """
    outer = _LIMIT.hard
    _LIMIT.hard = min(outer, float(at))
    try:
        yield
    finally:
        _LIMIT.hard = outer


def start_step_clock() -> None:
    """A walking step begins: inside a limit, its time counts from now (else nothing)."""
    if math.isfinite(_LIMIT.seconds):
        _LIMIT.deadline = _clock() + _LIMIT.seconds


def check_time_limit(t: float = math.nan, y=None) -> None:
    """Raise :class:`IntegrationDeadline` past the deadline of :func:`integration_deadline`
    (with the integration's time ``t`` [s] and state ``y``), :class:`IntegrationTimeLimit`
    when a step's limit is set and its time is used up."""
    if _LIMIT.hard == math.inf and _LIMIT.deadline == math.inf:
        return  # no limit in force: no clock read (a compiled control step calls this often)
    now = _clock()
    if now > _LIMIT.hard:
        raise IntegrationDeadline(t, y)
    if now > _LIMIT.deadline:
        raise IntegrationTimeLimit(_LIMIT.seconds)


def limited(rhs):
    """``rhs`` itself outside a limit; inside one, ``rhs`` checking the clock every
    :data:`CHECK_EVERY` evaluations (same values returned)."""
    if not math.isfinite(min(_LIMIT.deadline, _LIMIT.hard)):
        return rhs
    check_time_limit()
    calls = [0]

    def checked(t, y):
        calls[0] += 1
        if calls[0] % CHECK_EVERY == 0:
            check_time_limit(t, y)
        return rhs(t, y)
    return checked
