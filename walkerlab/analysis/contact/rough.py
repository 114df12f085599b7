"""The compliant-contact walker on rough ground: the terrain as geometry.

The contact model walks on the checkerboard lanes of :mod:`walkerlab.models.contact.model`: footfall
``k`` of the gait lands on a patch centred at ``s = k l`` (``l`` the gait's step length;
leg2's lane holds the even footfalls, leg1's the odd ones; footfall 0 is the stance foot the
walk starts on).  Rough ground gives each patch a height ``h_k`` along the slope's outward
normal (:attr:`walkerlab.models.contact.model.ContactWalker.heights1`), so

* a single step-down of ``h`` at the first heel strike is ``h_k = -h`` for every ``k >= 1``
  (a step-up: ``+h``), as the rigid model's swing-foot clearance guard meets the ground
  ``h`` below the slope line through the stance foot
  (:meth:`walkerlab.integrate.batch_step.BatchStepMap.step`, ``drop_m``);
* per-step slopes ``gamma_k`` (Byl & Tedrake 2009) are the heights at which the line
  through footfall ``k`` at slope ``gamma_k`` meets the next footfall,
  ``h_{k+1} = h_k - l tan(gamma_k - gamma)`` (``gamma`` the scene's slope): the swing foot
  lands where it would on the rigid model's per-step slope.  Between footfalls the patches
  stay parallel to the scene's slope and gravity keeps its direction (the rigid model's
  per-step slope also turns gravity within the step); the two terrains agree to first
  order in ``gamma_k - gamma`` at the footfalls only.

Walks start on the contact model's own periodic gait
(:func:`walkerlab.analysis.contact.periodic.find_contact_periodic_gait`, at mid-stance on
footfall 0), as the rigid walks start on the rigid gait.  A walk that does not make its
heel strikes (fall, trip, flight, scuff, slip, stall, solver failure, time limit) fell; one
that makes ``max_steps`` is censored.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

__all__ = ["ContactStart", "contact_start", "contact_walk", "footfall_lanes",
           "slope_heights", "step_heights"]


def slope_heights(slopes_rad: np.ndarray, mean_rad: float, step_length_m: float
                  ) -> np.ndarray:
    """Footfall heights [m] (n + 1,) of per-step slopes ``slopes_rad`` (n,) about
    ``mean_rad``: ``h_0 = 0``, ``h_{k+1} = h_k - l tan(gamma_k - mean)``."""
    d = -step_length_m * np.tan(np.asarray(slopes_rad, float) - float(mean_rad))
    return np.concatenate([[0.0], np.cumsum(d)])


def step_heights(n_footfalls: int, height_m: float) -> np.ndarray:
    """Footfall heights [m] (n_footfalls,) of one step of ``height_m`` (< 0 a step-down)
    at the first heel strike: 0 for footfall 0, ``height_m`` from footfall 1 on."""
    h = np.full(int(n_footfalls), float(height_m))
    h[0] = 0.0
    return h


def footfall_lanes(walker, heights_m: np.ndarray):
    """``walker`` with patch ``k`` of the footfall order at height ``heights_m[k]`` [m]
    (footfalls past the given heights keep the last one).

    Parameters
    ----------
    walker : ContactWalker
        With checkerboard lanes (:func:`walkerlab.models.contact.model.checkerboard_lanes`):
        leg2's patches are footfalls 0, 2, 4, ..., leg1's 1, 3, ....
    heights_m : ndarray (k,)

    Continuous ground (``terrain.kind: continuous``, the kneed walker's) becomes contiguous
    patches: each lane's patches widen to twice the step length, so every lane is ground
    everywhere (from its first footfall's patch on) and a height changes half-way between
    that lane's footfalls.

    Raises
    ------
    ValueError
        Lanes without patches.
    """
    if walker.lane1.size == 0 or walker.lane2.size == 0:
        raise ValueError("terrain: rough ground for the contact model needs the lanes of "
                         "footfalls (ContactWalker.from_settings)")
    h = np.asarray(heights_m, float)
    n = 2 * max(walker.lane1.size, walker.lane2.size)
    h = np.concatenate([h, np.full(max(0, n - h.size), h[-1] if h.size else 0.0)])
    ground = {}
    if walker.continuous:
        ground = {"continuous": False,
                  "patch_half_width": float(walker.lane1[0] - walker.lane2[0])}
    return replace(walker, heights2=h[0:2 * walker.lane2.size:2],
                   heights1=h[1:2 * walker.lane1.size:2], **ground)


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
    """

    scene: dict
    x_ideal: tuple
    x0: tuple
    step_length_m: float
    period_s: float
    slope_rad: float


def contact_start(scene, x_ideal: np.ndarray, periodic: bool = True) -> ContactStart:
    """The contact periodic gait of ``scene`` found from the rigid gait ``x_ideal``
    (within ``contact_sim.periodic_time_limit_s``); ``periodic=False``: the contact run's
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
    from walkerlab.analysis.contact.periodic import find_contact_periodic_gait
    from walkerlab.analysis.contact.sim import scene_start
    from walkerlab.models.contact.scene import contact_setup

    setup = contact_setup(scene)
    cs = setup.sim
    probe, x0, _, step_length = scene_start(setup, x_ideal, 2)
    if not periodic:
        from walkerlab.integrate.rigid import Solver, integrate_step
        from walkerlab.models.registry import build_walker

        period = integrate_step(build_walker(scene), np.asarray(x_ideal, float),
                                Solver("DOP853", 1e-10, 1e-10)).period
        return ContactStart(scene.model_dump(mode="json"), tuple(map(float, x_ideal)),
                            tuple(map(float, x0)), float(step_length), float(period),
                            float(scene.slope.phi_rad))
    gait = find_contact_periodic_gait(probe, x_ideal, time_limit_s=cs.periodic_time_limit_s)
    return ContactStart(scene.model_dump(mode="json"), tuple(map(float, x_ideal)),
                        tuple(map(float, gait.full_state)), float(gait.step_length_m),
                        float(gait.period_s), float(scene.slope.phi_rad))


#: wall-time limit of one walk [s]: WALK_TIME_LIMIT_S + WALK_TIME_PER_STEP_S per step (a
#: foot caught below a patch's top at its edge makes the stiff solver grind until the
#: limit: that walk has tripped; a step takes ~0.05 s on a quiet core)
WALK_TIME_LIMIT_S = 10.0
WALK_TIME_PER_STEP_S = 2.0


def contact_walk(start: ContactStart, heights_m: np.ndarray, max_steps: int
                 ) -> tuple[int, bool, str]:
    """Walk the contact walker from ``start`` on footfalls at ``heights_m`` [m] until it
    makes ``max_steps`` heel strikes or stops otherwise (wall-time limit
    ``WALK_TIME_LIMIT_S + WALK_TIME_PER_STEP_S max_steps``, or the scene's if smaller).

    Returns
    -------
    (heel_strikes, fell, outcome) : int, bool, str
        ``fell`` False: the walk reached ``max_steps`` (censored); ``outcome`` the run's
        end (:data:`walkerlab.analysis.contact.gait.CONTACT_OUTCOMES`).
    """
    from walkerlab.analysis.contact.sim import scene_start, simulate_contact
    from walkerlab.config import scene_from_dict
    from walkerlab.models.contact.scene import contact_setup

    setup = contact_setup(scene_from_dict(start.scene))
    sv = setup.solver
    x_ideal = np.asarray(start.x_ideal, float)
    _, _, limits, _ = scene_start(setup, x_ideal, 2)
    cap = WALK_TIME_LIMIT_S + WALK_TIME_PER_STEP_S * max_steps
    limits = replace(limits, wall_time_limit_s=min(limits.wall_time_limit_s or cap, cap))
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
    from walkerlab.analysis.robustness.mfpt import draw_slopes

    g = draw_slopes(seed, walk, max_steps + 2, start.slope_rad, sd, distribution)
    return slope_heights(g, start.slope_rad, start.step_length_m)
