"""Many contact-model walks on rough ground, on local processes or Dask: Monte Carlo
MFPT on per-step slopes and the largest single step-down / step-up by bisection.

Each walk is one task (:func:`run_contact_walk`, a full contact simulation) dealt out by
:func:`walkerlab.execution.executor.run_each` on
:func:`walkerlab.studies.runner.sweep_executor` (this process, a local pool or a Dask cluster,
unchanged).  The terrain of walk ``w`` is drawn from the same random stream as the rigid
model's walk ``w`` (:func:`walkerlab.analysis.robustness.mfpt.draw_slopes`), turned into patch
heights (:mod:`walkerlab.analysis.contact.rough`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.analysis.contact import rough as C
from walkerlab.analysis.robustness.measures import bracket_flip
from walkerlab.analysis.robustness.mfpt import MonteCarloResult
from walkerlab.execution.executor import run_each
from walkerlab.models.contact import terrain as T

__all__ = ["ContactWalkTask", "contact_monte_carlo", "contact_largest_step", "run_contact_walk"]


@dataclass(frozen=True)
class ContactWalkTask:
    """One contact walk (picklable): its start, footfall heights [m] and step cap."""

    start: C.ContactStart
    heights_m: tuple
    max_steps: int
    index: int


def run_contact_walk(task: ContactWalkTask):
    """``(index, heel strikes, fell, outcome)`` of one walk."""
    n, fell, kind = C.contact_walk(task.start, np.asarray(task.heights_m), task.max_steps)
    return task.index, n, fell, kind


def _walk_all(tasks, workers, scheduler, done=None):
    from walkerlab.studies.runner import sweep_executor  # light

    out = {}
    with sweep_executor(workers, scheduler) as ex:
        for _, (i, n, fell, kind) in run_each(ex, run_contact_walk, [(t,) for t in tasks]):
            out[i] = (n, fell, kind)
            if done is not None:
                done(i, n, fell, kind)
    return out


def contact_monte_carlo(start: C.ContactStart, sd: float, walks: int, max_steps: int,
                        seed: int, distribution: str = "normal", workers: int = 1,
                        scheduler=None, partial=None) -> tuple[MonteCarloResult, dict]:
    """Monte Carlo MFPT walks of the contact model at one sigma [rad].

    Parameters
    ----------
    start : ContactStart
        From :func:`walkerlab.analysis.contact.rough.contact_start`.
    sd : float
        Per-step slope standard deviation [rad] (as patch heights).
    walks, max_steps, seed, distribution
        As :func:`walkerlab.studies.mfpt.monte_carlo`.
    partial : walkerlab.io.mfpt_partial.MfptPartial, optional
        Walks stored there by an interrupted run are kept; each finished walk is stored.

    Returns
    -------
    (MonteCarloResult, outcome counts)
        The counts: how the walks that fell ended (``trip``, ``fall``, ``time_limit``...).
    """
    steps = np.zeros(walks, dtype=np.int64)
    fell = np.zeros(walks, dtype=bool)
    kinds: dict[str, int] = {}

    def name(w: int) -> str:
        return f"contact_montecarlo/sigma={float(sd)!r}/walk={w}"

    def keep(w, n, f, kind):
        steps[w], fell[w] = n, f
        if f:
            kinds[kind] = kinds.get(kind, 0) + 1

    def store(w, n, f, kind):
        if partial is not None:
            partial.put(name(w), {"steps": np.array([n], np.int64),
                                  "fell": np.array([int(f)], np.int8),
                                  "outcome": np.frombuffer(kind.encode().ljust(32), np.uint8)})

    todo = []
    for w in range(walks):
        got = partial.get(name(w)) if partial is not None else None
        if got is not None:
            keep(w, int(got["steps"][0]), bool(got["fell"][0]),
                 got["outcome"].tobytes().decode().strip())
            continue
        h = C.walk_heights(start, seed, w, max_steps, sd, distribution)
        todo.append(ContactWalkTask(start, tuple(map(float, h)), max_steps, w))

    def done(w, n, f, kind):
        keep(w, n, f, kind)
        store(w, n, f, kind)
    _walk_all(todo, workers, scheduler, done)
    return MonteCarloResult(steps, fell), kinds


def contact_largest_step(start: C.ContactStart, sign: float, max_value_m: float,
                         tol_m: float, steps: int, workers: int = 1, scheduler=None,
                         sections: int = 8) -> tuple[float, float]:
    """Bracket ``(lo, hi)`` [m] of the largest single step-down (``sign`` +1) or step-up
    (-1) at the first heel strike that the contact model survives for ``steps`` heel
    strikes (:func:`walkerlab.analysis.robustness.measures.bracket_flip`; the ``sections - 1``
    walks of a round run as tasks at once).  ``(nan, 0.0)``: the walker does not make
    ``steps`` heel strikes even without a step (its gait does not fit the lanes)."""
    n = steps + 6

    def survive(values):
        tasks = [ContactWalkTask(start, tuple(T.step_heights(n, -sign * float(v))), steps, i)
                 for i, v in enumerate(values)]
        out = _walk_all(tasks, workers, scheduler)
        return np.array([not out[i][1] for i in range(len(values))])
    if not survive(np.zeros(1))[0]:
        return float("nan"), 0.0
    return bracket_flip(survive, max_value_m, tol_m, sections)
