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
(:func:`walkerlab.models.contact.terrain.footfall_positions`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["rigid_step_lengths"]


def rigid_step_lengths(scene, walker, x_ideal) -> tuple[float, ...] | None:
    """Each step's advance along the slope [m] of one period of the scene's rigid gait on a
    ground whose steps differ, from its fixed point ``x_ideal``; None on a ground whose every
    step is alike (the one spacing of :func:`walkerlab.models.contact.scene.
    ideal_step_length`).

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
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.contact.scene import ideal_step_length
    from walkerlab.models.contact.terrain import check_ground
    from walkerlab.models.registry import build_walker

    if scene.terrain is None or scene.terrain.is_slope or len(check_ground(scene.terrain)) < 2:
        return None
    rigid = build_walker(scene)
    m = len(rigid.cycle) if rigid.cycle is not None else 1
    traj = simulate_steps(rigid, np.asarray(x_ideal, float), m,
                          Solver.from_settings(scene.solver))
    segs = list(traj.segments)
    if len(segs) < m or any(sg.x_next is None for sg in segs):
        raise ValueError(f"scene '{scene.name}': fixedpoint: the rigid gait on "
                         "terrain.foothold_heights_m does not make its steps from its fixed "
                         "point (its footfalls lay the contact model's patches)")
    return tuple(float(ideal_step_length(walker, sg.x_next, along_slope=True)) for sg in segs)
