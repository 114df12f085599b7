"""Bounds on the work of the walking steps integrated inside a block, counted in
right-hand-side evaluations, never in seconds.

A state far from any gait (rates of 1e10 rad/s, a spring at its cap) can make the adaptive
integrator take steps so small that one walking step runs for minutes before it ends by
``max_step_time`` of *simulated* time.  A bound on CPU or wall seconds ends such a step, but
where it ends depends on the machine and on what else the machine is doing: the same scene
would give another answer on a busy machine, or on its first run while its code is being
compiled.  Here the bound is the number of right-hand-side evaluations, which the integrator
spends the same way on any machine:

- inside :func:`work_bound` (a gait search's budget,
  :func:`walkerlab.analysis.gait.budget.search_budget`) every evaluation of the ``scipy``
  and ``cyrk`` backends is counted (:func:`counted` wraps the right-hand side) and the
  ``cyrk_compiled`` backend, whose flow calls no Python, adds its evaluations after each of
  its integration chunks (:func:`count`); past the bound :class:`WorkBoundReached` is raised
  out of the integration, with where it was;
- inside :func:`step_work_limit` (the in-memory walker's
  :class:`walkerlab.api.walker.Walker`) each walking step
  (:func:`walkerlab.integrate.rigid.integrate_step` restarts its count,
  :func:`start_step`) may use that many evaluations, past which :class:`StepWorkLimit` is
  raised.

Outside such blocks nothing is wrapped; inside them the right-hand side returns the same
values (the integrations are the same, bit for bit).  The compiled backend checks between
its chunks, so that it may pass a bound by at most one chunk, the same chunk on any machine.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["StepWorkLimit", "WorkBoundReached", "count", "counted", "done",
           "start_step", "step_work_limit", "work_bound"]


class StepWorkLimit(RuntimeError):
    """A walking step inside :func:`step_work_limit` used up its right-hand-side
    evaluations."""

    def __init__(self, evaluations: float):
        super().__init__(f"the walking step used up its {evaluations:.3g} right-hand-side "
                         "evaluations")
        self.evaluations = evaluations


class WorkBoundReached(RuntimeError):
    """The evaluations counted on this thread passed the bound of :func:`work_bound` during
    a walking step; ``t`` [s] and ``x`` (the state, [rad, rad/s]) are where the integration
    was (NaN and None where the count was looked at before the integration moved)."""

    def __init__(self, t: float, x):
        super().__init__(f"the walking step passed its work bound at t = {t:.4g} s")
        self.t, self.x = t, x


class _Work(threading.local):
    done = 0  # right-hand-side evaluations counted on this thread
    hard = math.inf  # the count past which work_bound raises
    step_limit = math.inf  # evaluations of one walking step (step_work_limit)
    step_end = math.inf  # the count past which this walking step raises


_WORK = _Work()


def done() -> int:
    """Right-hand-side evaluations counted on this thread so far (inside bounds: the
    count's differences are the work of what ran in between)."""
    return _WORK.done


def _bounded() -> bool:
    return _WORK.hard != math.inf or _WORK.step_end != math.inf


@contextmanager
def work_bound(at: float) -> Iterator[None]:
    """Stop every walking step integrated inside once this thread's count (:func:`done`)
    passes ``at`` evaluations (nested bounds keep the lower; ``inf``: none).

    Raises
    ------
    WorkBoundReached
        From the integration under way once the count passes ``at``.
    """
    outer = _WORK.hard
    _WORK.hard = min(outer, float(at))
    try:
        yield
    finally:
        _WORK.hard = outer


@contextmanager
def step_work_limit(evaluations: float) -> Iterator[None]:
    """Bound each walking step integrated inside to ``evaluations`` right-hand-side
    evaluations (nested limits keep the smaller).

    Raises
    ------
    StepWorkLimit
        From the integration under way once its step's evaluations are used up.
    """
    outer = (_WORK.step_end, _WORK.step_limit)
    limit = min(float(evaluations), _WORK.step_limit)
    _WORK.step_end, _WORK.step_limit = min(_WORK.step_end, _WORK.done + limit), limit
    try:
        yield
    finally:
        _WORK.step_end, _WORK.step_limit = outer


def start_step() -> None:
    """A walking step begins: inside a :func:`step_work_limit`, its count starts now."""
    if _WORK.step_limit != math.inf:
        _WORK.step_end = _WORK.done + _WORK.step_limit


def count(n: int = 0, t: float = math.nan, y=None) -> None:
    """Add ``n`` evaluations to this thread's count (an integration that calls no Python:
    after each chunk, ``t`` [s] and ``y`` where it ended) and raise past a bound.

    Raises
    ------
    WorkBoundReached
        Past :func:`work_bound`'s bound.
    StepWorkLimit
        Past :func:`step_work_limit`'s.
    """
    _WORK.done += int(n)
    if _WORK.done > _WORK.hard:
        raise WorkBoundReached(t, y)
    if _WORK.done > _WORK.step_end:
        raise StepWorkLimit(_WORK.step_limit)


def counted(rhs):
    """``rhs`` itself outside a bound; inside one, ``rhs`` with each call counted
    (:func:`count`; the same values returned)."""
    if not _bounded():
        return rhs
    count(0)
    w = _WORK

    def checked(t, y):
        w.done += 1
        if w.done > w.hard or w.done > w.step_end:
            count(0, t, y)
        return rhs(t, y)
    return checked
