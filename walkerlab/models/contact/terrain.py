"""Rough ground for the compliant-contact walker, as geometry: footfall heights and the
checkerboard lanes that carry them.

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
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

__all__ = ["footfall_lanes", "slope_heights", "step_heights"]


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
