"""The work budget of a gait search: every step map of a search counted, and the
right-hand-side evaluations of their integrations bounded (:func:`search_budget`); a map
far costlier than the search's others said once; a spent budget raised as
:class:`SearchGaveUp`, saying from the counts whether one map crawled or the root finder
wandered.

The budget counts work, never seconds (:mod:`walkerlab.integrate.work_limit`): the same scene
gives the same search, and the same outcome, on a quiet machine, a busy one, and on its first
run while the walker's code is being generated and compiled.
"""

from __future__ import annotations

import math
import re
import threading
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

from walkerlab import progress
from walkerlab.integrate import work_limit
from walkerlab.models.hybrid.base import HybridWalker

__all__ = ["CRAWL_SHARE", "ROOT_BUDGET_EVALUATIONS", "SLOW_MAP_EVALUATIONS", "SearchGaveUp",
           "deadline", "evaluations", "gave_up", "map_ended", "map_started", "rates_words",
           "search_budget", "slow_step_reason"]

#: most right-hand-side evaluations of one search for a gait (:func:`search_budget`; a fixed
#: point, or every start of :func:`walkerlab.analysis.gait.search.find_gaits`).  The shipped
#: scenes' searches use at most about 260,000 (``hip_width_powered``, 3D: 61 maps of at most
#: 4,664 each; a planar scene at most 116,000, ``flat_feet_footholds``); a spring or damper
#: at its cap (1e6), or a virtual-constraint controller started far from its designed step,
#: makes the integrator crawl (stiff), and the search's starts and MINPACK's own cap of
#: 200 (n + 1) maps would keep it busy for many minutes before it says "no gait found".  At
#: about 30 us an evaluation (a planar walker's Python flow) the budget is a minute, at
#: 300 us (a 3D walker's) ten; the compiled flow takes the same steps, hence the same count
ROOT_BUDGET_EVALUATIONS = 2_000_000
#: a step map of more evaluations than this is said in one notice (the search is not silent;
#: a shipped gait's map takes at most about 5,300)
SLOW_MAP_EVALUATIONS = 100_000
#: a search whose costliest map used this share of its budget or more gave up because that
#: map crawled (else: the root finder wandered over many maps of ordinary cost)
CRAWL_SHARE = 0.25


class _Budget(threading.local):
    """The work budget of the search under way in this thread (:func:`search_budget`;
    per thread: the report runs the work-precision study in a thread of its own)."""

    deadline = math.inf  # work_limit.done() after which no step map starts
    maps = 0  # step maps started under the budget
    costliest = 0  # evaluations of the costliest of them
    started = 0  # work_limit.done() when the outermost budget began
    size = 0.0  # evaluations the outermost budget allows


_BUDGET = _Budget()


class SearchGaveUp(Exception):
    """A search for a gait spent its work budget (:func:`search_budget`); raised before a
    step map would start, or from the step map under way (its integration counts its
    right-hand-side evaluations).  The message says after how many maps and evaluations,
    and, from those counts, whether one map crawled (:func:`slow_step_reason`) or the root
    finder went on over many maps."""


@contextmanager
def search_budget(evaluations: float | None = None, fresh: bool = False) -> Iterator[None]:
    """Bound every step map started inside to ``evaluations`` right-hand-side evaluations
    of this thread's integrations from now (default :data:`ROOT_BUDGET_EVALUATIONS`; nested
    budgets keep the earlier end, unless ``fresh``: a start tried after the search's own
    ones failed, with a budget of its own and the outer one back after it).

    Past it, :func:`walkerlab.analysis.gait.poincare.poincare_map` raises
    :class:`SearchGaveUp` instead of starting a map, and stops the map under way
    (:func:`walkerlab.integrate.work_limit.work_bound`: the right-hand side counts each of
    its evaluations; the compiled CyRK flow after each integration chunk), so that a search
    ends within its budget and one chunk.  A map of more than :data:`SLOW_MAP_EVALUATIONS`
    is said once in a notice (:func:`walkerlab.progress.note`).  Code generation and
    compilation do no counted work: a walker's first run on a machine ends as its tenth.
    """
    outer = (_BUDGET.deadline, _BUDGET.maps, _BUDGET.costliest, _BUDGET.started, _BUDGET.size)
    now = work_limit.done()
    size = float(ROOT_BUDGET_EVALUATIONS if evaluations is None else evaluations)
    if not math.isfinite(outer[0]) or fresh:  # the outermost budget counts the maps inside
        _BUDGET.maps, _BUDGET.costliest, _BUDGET.started, _BUDGET.size = 0, 0, now, size
    own = now + size
    _BUDGET.deadline = own if fresh else min(outer[0], own)
    try:
        yield
    finally:
        if fresh:
            (_BUDGET.deadline, _BUDGET.maps, _BUDGET.costliest, _BUDGET.started,
             _BUDGET.size) = outer
        else:
            _BUDGET.deadline = outer[0]


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


def _count(n: float) -> str:
    """``n`` evaluations, digits grouped (1234567 -> '1,234,567')."""
    return f"{n:,.0f}"


def gave_up(walker: HybridWalker | None, where: str = "",
            costliest: float | None = None) -> SearchGaveUp:
    """The :class:`SearchGaveUp` of a search whose budget is spent (``where``: how the map
    under way was stopped, if one was; ``costliest``: the evaluations of the costliest map,
    the one under way included)."""
    worst = float(_BUDGET.costliest if costliest is None else max(costliest, _BUDGET.costliest))
    where = where or f"the costliest map {_count(worst)}"
    if worst >= CRAWL_SHARE * _BUDGET.size:
        why = f"{slow_step_reason(walker)}; start nearer the gait"
    else:  # many maps of ordinary cost: the root finder went on without converging
        why = ("the root finder did not converge from the starts tried (no single map "
               "crawled); start nearer the gait or check that the walker has one")
    return SearchGaveUp(
        f"the search gave up after {_BUDGET.maps} step map(s), its budget of "
        f"{_count(_BUDGET.size)} right-hand-side evaluations spent ({where}): {why}")


def map_started(walker: HybridWalker | None = None) -> int:
    """Count a step map starting now; its start on this thread's work count
    (:func:`walkerlab.integrate.work_limit.done`).

    Raises
    ------
    SearchGaveUp
        The search's budget is spent: no map starts.
    """
    n = work_limit.done()
    if n >= _BUDGET.deadline:  # spent (a budget of 0 starts no map)
        raise gave_up(walker)
    _BUDGET.maps += 1
    return n


def map_ended(walker: HybridWalker, n: int, x_end=None) -> None:
    """Record a step map started at count ``n`` (:func:`map_started`) as ended (``x_end``:
    its end state, if it has one); the first map of more than :data:`SLOW_MAP_EVALUATIONS`
    is said in a notice, with the rates it reached."""
    cost = work_limit.done() - n
    if (cost > SLOW_MAP_EVALUATIONS and _BUDGET.costliest <= SLOW_MAP_EVALUATIONS
            and math.isfinite(_BUDGET.deadline)):
        progress.note(f"gait search: one step map took {_count(cost)} right-hand-side "
                      f"evaluations{rates_words(x_end, np.size(x_end) // 2)} "
                      f"({slow_step_reason(walker)}); the search "
                      f"gives up once it has spent {_count(_BUDGET.size)}")
    _BUDGET.costliest = max(_BUDGET.costliest, cost)


def rates_words(y, n: int) -> str:
    """Where a map's integration was, in words: ``', rates R rad/s'`` (the largest of the
    rates ``y[n:2n]``, [rad/s]; ``y`` may carry variational rows after them), ``', its state
    no longer finite'``, or ``''`` without a state (never "nan")."""
    if y is None:
        return ""
    rates = np.asarray(y, float).ravel()[n:2 * n]
    if not rates.size:
        return ""
    if not np.all(np.isfinite(rates)):
        return ", its state no longer finite"
    return f", rates {float(np.max(np.abs(rates))):.2g} rad/s"


def evaluations() -> int:
    """This thread's right-hand-side evaluations counted so far (the budget's measure)."""
    return work_limit.done()


def deadline() -> float:
    """The count (:func:`evaluations`) after which no step map starts (inf: no budget)."""
    return _BUDGET.deadline
