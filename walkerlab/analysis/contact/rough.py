"""The compliant-contact walker on rough ground: walks on the footfall heights of
:mod:`walkerlab.models.contact.terrain` (the terrain as geometry).

Walks start on the contact model's own periodic gait
(:func:`walkerlab.analysis.contact.periodic.find_contact_periodic_gait`, at mid-stance on
footfall 0), as the rigid walks start on the rigid gait.  A walk that does not make its
heel strikes (fall, trip, flight, scuff, slip, stall, solver failure, time limit) fell; one
that makes ``max_steps`` is censored.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from walkerlab.analysis.contact.sim import scene_start, simulate_contact
from walkerlab.analysis.robustness.mfpt import draw_slopes
from walkerlab.config import scene_from_dict
from walkerlab.integrate.rigid import Solver, integrate_step
from walkerlab.models.contact.scene import contact_setup
from walkerlab.models.contact.terrain import footfall_lanes, slope_heights

__all__ = ["ContactStart", "contact_start", "contact_walk"]


@dataclass(frozen=True)
class ContactStart:
    """Where contact walks start (picklable, sent to workers).

    Attributes
    ----------
    scene : dict
        The scene (``model_dump(mode="json")``).
    x_ideal : tuple of float, length 2n
        The rigid gait's post-impact state (``state_names()`` of the rigid walker, [rad,
        rad/s]; sets the contact walker's parts).
    x0 : tuple of float, length 2 nq
        The contact periodic gait's full state at mid-stance on footfall 0
        (``ContactWalker.state_names()``, [m, rad, m/s, rad/s]).
    step_length_m, period_s : float
        Of the contact periodic gait (the patch spacing [m]; the time per step [s]).
    slope_rad : float
        The scene's slope [rad] (the mean of per-step slopes).
    plant : walkerlab.walker.plant.Plant
        The scene's plant (from the caller; it pickles with the start): a worker's walk
        describes nothing again.
    """

    scene: dict
    x_ideal: tuple
    x0: tuple
    step_length_m: float
    period_s: float
    slope_rad: float
    plant: Any = field(kw_only=True)


def contact_start(scene, x_ideal: np.ndarray, periodic: bool = True,
                  *, plant) -> ContactStart:
    """The contact periodic gait of ``scene`` found from the rigid gait ``x_ideal``
    (within ``contact_sim.periodic_max_step_maps``); ``periodic=False``: the contact run's
    own start instead (:func:`walkerlab.analysis.contact.sim.scene_start`: the rigid gait
    with ``contact_sim.initial_rate_scale``, the ideal step length, the rigid gait's step
    period; no periodic-gait search, so walks start with a transient).

    ``x_ideal`` (2n,): the rigid gait's post-impact state (the rigid walker's
    ``state_names()``, [rad, rad/s]).

    Raises
    ------
    walkerlab.analysis.contact.step_map.PeriodicGaitError
        No periodic gait.
    walkerlab.models.contact.scene.ContactSceneError
        No ``contact`` section.
    """
    from walkerlab.analysis.contact.periodic import (  # light
        converged_gait,
        find_contact_periodic_gait,
        search_bounds,
    )

    setup = contact_setup(scene, plant=plant)  # plant: the caller's
    cs = setup.sim
    probe, x0, _, step_length = scene_start(setup, x_ideal, 2)
    if not periodic:
        from walkerlab.models.registry import build_walker

        period = integrate_step(build_walker(setup.plant.with_(scene)),
                                np.asarray(x_ideal, float),
                                Solver("DOP853", 1e-10, 1e-10)).period
        return ContactStart(scene.model_dump(mode="json"), tuple(map(float, x_ideal)),
                            tuple(map(float, x0)), float(step_length), float(period),
                            float(scene.slope.phi_rad), plant=setup.plant)
    gait = converged_gait(find_contact_periodic_gait(probe, x_ideal, **search_bounds(cs)))
    return ContactStart(scene.model_dump(mode="json"), tuple(map(float, x_ideal)),
                        tuple(map(float, gait.full_state)), float(gait.step_length_m),
                        float(gait.period_s), float(scene.slope.phi_rad), plant=setup.plant)


#: work bound of one walk [right-hand-side evaluations]: WALK_RHS_EVALUATIONS +
#: WALK_RHS_EVALUATIONS_PER_STEP per step (a foot caught below a patch's top at its edge
#: makes the stiff solver grind until the bound: that walk has tripped; a walking step of the
#: paper's walker takes ~3,000, a small fraction of the bound); the same walks end the same
#: way on any machine
WALK_RHS_EVALUATIONS = 2_000_000
WALK_RHS_EVALUATIONS_PER_STEP = 200_000


def contact_walk(start: ContactStart, heights_m: np.ndarray, max_steps: int
                 ) -> tuple[int, bool, str]:
    """Walk the contact walker from ``start`` on footfalls at ``heights_m`` [m] until it
    makes ``max_steps`` heel strikes or stops otherwise (work bound
    ``WALK_RHS_EVALUATIONS + WALK_RHS_EVALUATIONS_PER_STEP max_steps`` right-hand-side
    evaluations, or the scene's ``contact_sim.max_rhs_evaluations`` if smaller).

    Returns
    -------
    (heel_strikes, fell, outcome) : int, bool, str
        ``fell`` False: the walk reached ``max_steps`` (censored); ``outcome`` the run's
        end (:data:`walkerlab.analysis.contact.verdict.CONTACT_OUTCOMES`).
    """
    scene = scene_from_dict(start.scene)  # the worker's scene: the start's plant, with_ it
    setup = contact_setup(scene, plant=start.plant.with_(scene))
    sv = setup.solver
    x_ideal = np.asarray(start.x_ideal, float)
    _, _, limits, _ = scene_start(setup, x_ideal, 2)
    cap = WALK_RHS_EVALUATIONS + WALK_RHS_EVALUATIONS_PER_STEP * max_steps
    limits = replace(limits, max_rhs_evaluations=min(limits.max_rhs_evaluations or cap, cap))
    walker, _ = setup.build(x_ideal, max_steps + 2, step_length_m=start.step_length_m)
    walker = footfall_lanes(walker, heights_m)
    res = simulate_contact(walker, np.asarray(start.x0, float),
                           (max_steps + 1.5) * start.period_s, sv, limits,
                           max_heel_strikes=max_steps)
    n = int(res.walked_steps)
    return min(n, max_steps), n < max_steps, str(res.outcome.kind)


def walk_heights(start: ContactStart, seed: int, walk: int, max_steps: int, sd: float,
                 distribution: str = "normal") -> np.ndarray:
    """Footfall heights [m] of Monte Carlo walk number ``walk``: its per-step slopes
    (:func:`walkerlab.analysis.robustness.mfpt.draw_slopes`, the same streams as the rigid walks)
    turned into heights (:func:`slope_heights`).

    Parameters
    ----------
    start : ContactStart
    seed, walk : int
        The run's seed and the walk's number (the rigid walks' streams).
    max_steps : int
        Step cap: ``max_steps + 2`` slopes are drawn.
    sd : float
        Slope standard deviation [rad].
    distribution : {"normal", "uniform"}

    Returns
    -------
    ndarray, shape (max_steps + 3,)
        Footfall heights [m], footfall 0 at 0.
    """
    g = draw_slopes(seed, walk, max_steps + 2, start.slope_rad, sd, distribution)
    return slope_heights(g, start.slope_rad, start.step_length_m)
