"""Where the rigid gait's feet land on a ground whose steps differ, for the contact view.

On footholds of several heights (``terrain.foothold_heights_m``, the list repeating) the
rigid gait is a fixed point of the map of ``p`` steps (:func:`walkerlab.models.hybrid.ground.
on_footholds`), whose steps are of different lengths (the paper walker on
``[-0.004, -0.006]``: 0.4449 and 0.4325 m).  The contact model's patches (and the MJCF's)
lie at these footfalls, step by step: :func:`rigid_step_lengths` walks one period of the
rigid gait from its fixed point and measures each step's advance along the slope with the
contact view's own geometry (:func:`walkerlab.models.contact.scene.ideal_step_length`: the
chord between the feet's reference points at heel strike along the slope, plus an arc
foot's roll), so footfall ``k`` lies at ``l_0 + ... + l_{k-1}``
(:func:`walkerlab.models.contact.terrain.footfall_positions`).  The same walk gives the
footfalls as points (:func:`rigid_footfalls`: the rigid model's own stance feet, their
lateral offsets and heights too), where a 3D walker's exports lay their patches (its steps
on footholds of several heights differ across the slope as well: it crabs).

The contact walker's steps differ from the rigid ones (the paper walker's are ~9 mm
shorter), so its footfalls drift off these patches; footholds are where the feet land (each
step's landing ``h_k`` below the stance foot's level), so a run that leaves them is run again
on patches at its own footfalls (:func:`own_footfall_lanes`; the ``contact-sim`` run,
:func:`walkerlab.analysis.contact.sim.simulate_from`).
"""

from __future__ import annotations

import numpy as np

from walkerlab.integrate.rigid import simulate_steps, walker_of_step
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.scene import ideal_step_length
from walkerlab.models.contact.terrain import footfall_positions, ground_drops

__all__ = ["MAX_RELAYS", "own_footfall_lanes", "rigid_footfalls", "rigid_step_lengths"]


def rigid_step_lengths(scene, walker, x_ideal, plant) -> tuple[float, ...] | None:
    """Each step's advance along the slope [m] of one period of the scene's rigid gait on a
    ground whose steps differ, from its fixed point ``x_ideal``; None on a ground whose every
    step is alike (the one spacing of
    :func:`walkerlab.models.contact.scene.ideal_step_length`).

    Parameters
    ----------
    scene : walkerlab.config.Scene
        Its rigid walker (:func:`walkerlab.models.registry.build_walker`, the footholds'
        cycle of per-step landings) and ``solver`` section.
    walker : walkerlab.models.contact.model.ContactWalker
        The contact walker whose geometry measures the steps (its reference points).
    x_ideal : ndarray (2n,)
        The rigid gait's fixed point (post-impact state before step 0 of the cycle, role
        order) [rad, rad/s].
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (:attr:`walkerlab.models.contact.scene.
        ContactSetup.plant`).

    Returns
    -------
    tuple of float or None
        ``(l_0, ..., l_{m-1})`` [m], ``m`` the steps of the rigid map (``p``, or ``2 p``
        for legs that differ on an odd ``p``); step ``k`` lands on footfall ``k + 1``.

    Raises
    ------
    ValueError
        The rigid gait does not make its steps from ``x_ideal`` (a fall: one line).
    """
    period = _rigid_period(scene, x_ideal, plant)
    if period is None:
        return None
    return tuple(float(ideal_step_length(walker, sg.x_next, along_slope=True))
                 for sg in period[1])


def rigid_footfalls(scene, x_ideal, plant, n_footfalls: int) -> np.ndarray | None:
    """The rigid gait's footfalls on a ground whose steps differ, as points in the rigid
    model's world axes [m] (walkerlab's: x downhill along the horizontal, y up, z across;
    footfall 0 the stance foot of ``x_ideal`` at the origin), from the walk of one period
    from its fixed point (each step's landing: the stance foot's world place the rigid walk
    carries, :func:`walkerlab.integrate.rigid.simulate_steps`), the period repeated
    (:func:`walkerlab.models.contact.terrain.footfall_positions`); None on a ground whose
    every step is alike.  The footfalls :func:`rigid_step_lengths` measures along the slope
    for the contact model, with their lateral offsets and heights: a 3D walker's steps on
    footholds of several heights differ across the slope too (its lean differs step by
    step: the walker crabs), which a 3D export's patches must follow.

    Parameters
    ----------
    scene : walkerlab.config.Scene
        Its rigid walker and ``solver`` section.
    x_ideal : ndarray (2n,)
        The rigid gait's fixed point (post-impact state before step 0 of the cycle, role
        order) [rad, rad/s].
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (handed down by the caller).
    n_footfalls : int
        Footfalls wanted (footfall 0 included).

    Returns
    -------
    ndarray (n_footfalls, d) or None
        Footfall ``k`` (``d`` 3 in 3D, 2 in the plane) [m]: footfall ``k`` is the landing of
        step ``k - 1``, the legs alternating (footfall 0 the stance leg's of ``x_ideal``).

    Raises
    ------
    ValueError
        The rigid gait does not make its steps from ``x_ideal`` (a fall: one line).
    """
    period = _rigid_period(scene, x_ideal, plant)
    if period is None:
        return None
    rigid, segs = period
    last = segs[-1]  # the period's last landing, as the walk carries its stance foot
    end = last.stance_foot_world + np.ravel(walker_of_step(rigid, last.index, last.stance_leg)
                                            .points(last.x_end)["swing_foot"])
    falls = np.array([sg.stance_foot_world for sg in segs] + [end], float)
    return footfall_positions(np.diff(falls, axis=0), n_footfalls)


def _rigid_period(scene, x_ideal, plant) -> tuple | None:
    """``(walker, segments)``: the scene's rigid walker (on its footholds' cycle of per-step
    landings) and the segments of one period of its gait walked from ``x_ideal``
    (:func:`walkerlab.integrate.rigid.simulate_steps`); None on a ground whose every step is
    alike; a walk that does not make its steps: one line (ValueError)."""
    from walkerlab.models.registry import build_walker

    if scene.terrain is None or scene.terrain.is_slope or len(ground_drops(scene.terrain)) < 2:
        return None
    rigid = build_walker(plant.with_(scene))
    m = len(rigid.cycle) if rigid.cycle is not None else 1
    traj = simulate_steps(rigid, np.asarray(x_ideal, float), m,
                          Solver.from_settings(scene.solver))
    segs = list(traj.segments)
    if len(segs) < m or any(sg.x_next is None for sg in segs):
        raise ValueError(f"scene '{scene.name}': fixedpoint: the rigid gait on "
                         "terrain.foothold_heights_m does not make its steps from its fixed "
                         "point (its footfalls lay the contact model's patches)")
    return rigid, segs


#: relays of the patches at the contact walker's own footfalls a run on footholds may take
#: (:func:`own_footfall_lanes`; each relay runs the walk again)
MAX_RELAYS = 4


def own_footfall_lanes(walker, result, period: int, initial_stance: str = "leg2"):
    """``walker`` with its patches moved to the contact run's own footfalls, where its steps
    drifted from the rigid gait's (footholds are where the feet land: each step's landing
    ``h_k`` below the stance foot's level, wherever that is); None when the run has too few
    alternating heel strikes to learn its steps from (fewer than ``period + 1``).

    Footfall ``j`` (the initial stance foot ``j = 0``, heel strike ``j`` after) keeps its
    patch's height and moves its centre to where the foot stood at that heel strike; the
    footfalls after the last heel strike advance by the run's last step of the same step of
    the cycle (step ``j`` of cycle step ``j mod period``), the contact gait's own.

    Parameters
    ----------
    walker : ContactWalker
        On checkerboard lanes (leg2's patches footfalls 0, 2, ..., leg1's 1, 3, ...).
    result : walkerlab.analysis.contact.result.ContactResult
        A run of ``walker`` (its ``feet[leg].s``, heel-strike times and legs).
    period : int
        Steps of the ground's cycle (``len(terrain.foothold_heights_m)``).
    initial_stance : str
        The leg in stance at the run's start (footfall 0).

    Returns
    -------
    ContactWalker or None
    """
    from dataclasses import replace

    legs = [initial_stance, *result.heel_strike_legs]
    if len(legs) < period + 2 or any(a == b for a, b in zip(legs, legs[1:])):
        return None
    t = np.asarray(result.t, float)
    s = [float(result.feet[initial_stance].s[0])]
    s += [float(np.interp(th, t, result.feet[leg].s))
          for th, leg in zip(result.heel_strike_times, result.heel_strike_legs)]
    steps = list(np.diff(s))  # step j - 1 lands footfall j
    n = walker.lane1.size + walker.lane2.size
    while len(s) < n:  # the next step as the last one of its cycle step
        steps.append(steps[-period])
        s.append(s[-1] + steps[-1])
    s = np.asarray(s[:n])
    # the legs alternate: footfall j is on the lane of legs[j % 2]
    on = {legs[0]: s[0::2], legs[1]: s[1::2]}
    lane1, lane2 = walker.lane1.copy(), walker.lane2.copy()
    k1, k2 = min(lane1.size, on["leg1"].size), min(lane2.size, on["leg2"].size)
    lane1[:k1], lane2[:k2] = on["leg1"][:k1], on["leg2"][:k2]
    return replace(walker, lane1=lane1, lane2=lane2)
