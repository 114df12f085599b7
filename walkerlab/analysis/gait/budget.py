"""The CPU-time budget of a gait search: every step map of a search counted and bounded
(:func:`search_budget`), a slow map said once, a spent budget raised as
:class:`SearchGaveUp` with why this walker's maps can crawl."""

from __future__ import annotations

import math
import re
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

from walkerlab import progress
from walkerlab.models.hybrid.base import HybridWalker

__all__ = ["ROOT_BUDGET_S", "SLOW_MAP_S", "SearchGaveUp", "clock", "deadline", "gave_up",
           "map_ended", "map_started", "search_budget", "slow_step_reason"]

#: longest CPU time of one search for a gait [s] (:func:`search_budget`; a fixed point, or
#: every start of :func:`walkerlab.analysis.gait.search.find_gaits`): the shipped scenes
#: need a small part of it; a spring or damper at its cap (1e6), or a virtual-constraint
#: controller started far from its designed step, makes the integrator crawl (stiff), and the
#: search's starts and MINPACK's own cap of 200 (n + 1) maps would keep it busy, silent, for
#: many minutes before it says "no gait found"
ROOT_BUDGET_S = 60.0
#: the budget's clock: this thread's CPU time, so that a loaded machine (other processes on
#: the same cores) does not make a search give up that would finish on a quiet one
_clock = time.thread_time
#: a step map slower than this [s] is said in one notice (the search is not silent)
SLOW_MAP_S = 5.0

class _Budget(threading.local):
    """The CPU-time budget of the search under way in this thread (:func:`search_budget`;
    per thread: the report runs the work-precision study in a thread of its own)."""

    deadline = math.inf  # _clock() after which no step map starts
    maps = 0  # step maps started under the budget
    slowest = 0.0  # slowest of them [s]
    started = 0.0


_BUDGET = _Budget()


class SearchGaveUp(Exception):
    """A search for a gait spent its CPU-time budget (:func:`search_budget`); raised
    before a step map would start, or from the step map under way (its integration checks
    the clock).  The message says after how many maps, how slow, and why a map of this
    walker can crawl (:func:`slow_step_reason`)."""


@contextmanager
def search_budget(seconds: float | None = None, fresh: bool = False) -> Iterator[None]:
    """Bound every step map started inside to ``seconds`` of this thread's CPU time from now
    (default :data:`ROOT_BUDGET_S`; nested budgets keep the earlier deadline, unless
    ``fresh``: a start tried after the search's own ones failed, with a budget of its own
    and the outer deadline back after it): past it,
    :func:`walkerlab.analysis.gait.poincare.poincare_map` raises :class:`SearchGaveUp`
    instead of starting a map, and stops
    the map under way (:func:`walkerlab.integrate.time_limit.integration_deadline`: its
    right-hand side looks at the clock every 64 evaluations; the compiled CyRK flow at each
    phase's start), so that a search ends within its budget and a few evaluations.  A map
    slower than :data:`SLOW_MAP_S` is said once in a notice
    (:func:`walkerlab.progress.note`)."""
    outer = _BUDGET.deadline
    now = _clock()
    if not math.isfinite(outer) or fresh:  # the outermost budget counts the maps inside
        _BUDGET.maps, _BUDGET.slowest, _BUDGET.started = 0, 0.0, now
    own = now + (ROOT_BUDGET_S if seconds is None else seconds)
    _BUDGET.deadline = own if fresh else min(outer, own)
    try:
        yield
    finally:
        _BUDGET.deadline = outer


def slow_step_reason(walker: HybridWalker) -> str:
    """Why a step map of ``walker`` can crawl, said in the gait search's notices: its
    virtual-constraint controller, its springs or dampers (``walker.springs`` and the knee's,
    generated parameters ``k_s<i>``, ``c_s<i>``, ``k_knee``, ``c_knee``; torque laws of
    ``walker.actuation.torques`` with a stiffness or damping), or, for a walker with
    neither, its rates alone."""
    acts = getattr(walker, "actuators", None)
    if getattr(acts, "controller", None) is not None:
        return ("the virtual-constraint controller drives a start far from its designed "
                "step to rates the integrator crawls through")
    params = getattr(walker, "params", None) or {}
    sprung = [k for k, v in params.items() if v and re.fullmatch(r"[kc]_(s\d+|knee)", k)]
    laws = [getattr(t, "law", None) for t in
            getattr(getattr(acts, "spec", None), "torques", None) or ()]
    if any(getattr(law, "stiffness_n_m_per_rad", 0.0) or getattr(law, "damping_n_m_s_per_rad",
                                                                 0.0) for law in laws):
        sprung.append("walker.actuation.torques")
    if sprung:
        where = ("walker.actuation.torques" if sprung == ["walker.actuation.torques"]
                 else "walker.springs or the knee's")
        return (f"a very stiff or heavily damped spring ({where}) makes the integrator "
                "crawl: soften it")
    return "the step's rates grow so large that the integrator crawls"


def gave_up(walker: HybridWalker | None, where: str = "") -> SearchGaveUp:
    """The :class:`SearchGaveUp` of a search whose budget is spent (``where``: how the map
    under way was stopped, if one was)."""
    where = where or f"the slowest map {_BUDGET.slowest:.1f} s"
    return SearchGaveUp(
        f"the search gave up after {_BUDGET.maps} step map(s), its "
        f"{_BUDGET.deadline - _BUDGET.started:.0f} s CPU budget spent ({where}): "
        f"{slow_step_reason(walker)}; start nearer the gait")


def map_started(walker: HybridWalker | None = None) -> float:
    """Count a step map starting now; its start on this thread's CPU clock [s].

    Raises
    ------
    SearchGaveUp
        The search's budget is spent: no map starts.
    """
    t = _clock()
    if t > _BUDGET.deadline:
        raise gave_up(walker)
    _BUDGET.maps += 1
    return t


def map_ended(walker: HybridWalker, t: float) -> None:
    """Record a step map started at ``t`` (:func:`map_started`) as ended; the first map
    slower than :data:`SLOW_MAP_S` is said in a notice."""
    dt = _clock() - t
    if dt > SLOW_MAP_S and _BUDGET.slowest <= SLOW_MAP_S and math.isfinite(_BUDGET.deadline):
        progress.note(f"gait search: one step map took {dt:.0f} s ({slow_step_reason(walker)});"
                      f" the search gives up once it has spent "
                      f"{_BUDGET.deadline - _BUDGET.started:.0f} s of CPU time (a step under "
                      "way included: on a busy machine the wall time is longer)")
    _BUDGET.slowest = max(_BUDGET.slowest, dt)


def clock() -> float:
    """This thread's CPU time [s]: the budget's clock."""
    return _clock()


def deadline() -> float:
    """The CPU time [s] (:func:`clock`) after which no step map starts (inf: no budget)."""
    return _BUDGET.deadline
