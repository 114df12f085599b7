"""How a periodic-gait search ends short of a gait, and what it may spend.

:class:`PeriodicGaitError` is the search's failure (its ``kind`` the reason);
:class:`SearchBudget` the bounds its step maps share
(:class:`walkerlab.analysis.contact.step_map.StepMap`): a work bound, the step-map
integrations, that ends a search the same way on any machine, and an optional wall-clock
deadline, whose end depends on the machine (``time_limit``: never kept as a scene's result).
Both are re-exported by :mod:`walkerlab.analysis.contact.step_map`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["PeriodicGaitError", "SearchBudget"]


class PeriodicGaitError(RuntimeError):
    """The step map or the search failed; ``kind`` is one of "fall", "no_mid_stance",
    "time_limit" (a wall-clock limit: depends on the machine), "work_limit" (the search's
    step-map integrations: :class:`SearchBudget`), "solver_failure", "not_converged" (the
    search ended away from a fixed point:
    :func:`walkerlab.analysis.contact.periodic.converged_gait`), "several_steps" (a ground
    whose steps differ: the one-step map does not apply, not searched)."""

    def __init__(self, kind: str, message: str):
        super().__init__(message)
        self.kind = kind


@dataclasses.dataclass
class SearchBudget:
    """What a periodic-gait search may spend, shared by its step maps (the tight, the coarse
    and the Jacobian's).

    Attributes
    ----------
    max_step_maps : int or None
        The most step-map integrations (each piece of a map evaluation counts) [-]; past it
        the search ends with a :class:`PeriodicGaitError` of kind ``work_limit``, the same on
        any machine (None: no bound; ``contact_sim.periodic_max_step_maps``).
    deadline : float
        ``time.perf_counter()`` value past which the search ends with kind ``time_limit``
        (inf: none; ``contact_sim.periodic_time_limit_s``).
    used : int
        Step-map integrations made so far [-].
    """

    max_step_maps: int | None = None
    deadline: float = np.inf
    used: int = 0

    def spend(self) -> None:
        """Count one step-map integration.

        Raises
        ------
        PeriodicGaitError
            ``work_limit``: this one would pass :attr:`max_step_maps`.
        """
        self.used += 1
        if self.max_step_maps is not None and self.used > self.max_step_maps:
            raise PeriodicGaitError(
                "work_limit", f"periodic-gait search: work bound reached, "
                f"{self.max_step_maps:,} step-map integrations (raise "
                "contact_sim.periodic_max_step_maps for a longer search)")
