"""Measures of a gait's robustness as design objectives (:mod:`walkerlab.optimal.design.search`),
each of the scene at the design point and its period-1 gait:

- ``gait_sensitivity_norm`` [indicator units per disturbance unit]: Hobbelen & Wisse's
  (2007) H2 norm from the scene's first ``robustness.disturbances`` (default ``slope``) to
  the step time, step length and stance angle
  (:func:`walkerlab.analysis.robustness.measures.linearise`); smooth, its gradient by
  central differences of the re-solved gait;
- ``basin_share`` [-]: the share of the scene's ``basin`` box (its axes, ranges and grid)
  whose cells walk back to the gait (:func:`walkerlab.studies.basin.compute_basin`);
  piecewise constant in the design: derivative-free;
- ``mfpt`` [steps]: Byl & Tedrake's (2009) mean first-passage time on rough ground, Monte
  Carlo at the scene's first ``mfpt.sigma_rad`` with its walks, step cap and seed (the same
  terrain draws at every design point: common random numbers); derivative-free.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from walkerlab.analysis.robustness.measures import linearise
from walkerlab.config.studies import MfptSettings
from walkerlab.integrate.python_step import make_step_map

__all__ = ["ROBUSTNESS_MEASURES", "robustness_measure"]

#: measure -> unit
ROBUSTNESS_MEASURES = {"gait_sensitivity_norm": "-", "basin_share": "-", "mfpt": "steps"}


def robustness_measure(name: str, scene, walker, x_star, A, *, plant) -> float:
    """The measure ``name`` (module docstring) of ``scene``'s gait ``x_star`` (2n,) with
    the Poincaré map's Jacobian ``A`` (2n, 2n) there; ``plant``: the design's
    :class:`~walkerlab.walker.plant.Plant`, handed down (``scene``'s is
    :meth:`~walkerlab.walker.plant.Plant.with_` of it).

    Raises
    ------
    ValueError
        An unknown measure, or a walker its study cannot carry (one line).
    """
    x_star = np.asarray(x_star, float)
    plant = plant.with_(scene)
    if name == "gait_sensitivity_norm":
        from walkerlab.studies.mfpt import scene_walker_at  # light

        dist = scene.robustness.disturbances[0] if scene.robustness is not None else "slope"
        sm = make_step_map(walker, scene_walker_at(scene, plant=plant), 1e-12, 1e-12)
        return linearise(sm, x_star, np.asarray(A, float), dist).gsn()
    if name == "basin_share":
        from walkerlab.studies.basin import CODE, compute_basin  # light

        with tempfile.TemporaryDirectory() as tmp:
            cells = compute_basin(scene, x_star, "design", Path(tmp) / "basin.h5",
                                  workers=1, resume=False, plant=plant)
        return float(np.mean(np.asarray(cells["outcome"]) == CODE["converged"]))
    if name == "mfpt":
        from walkerlab.studies.mfpt import monte_carlo  # light

        st = scene.mfpt or MfptSettings()
        return float(monte_carlo(scene, x_star, st.sigma_rad[0], st.walks, st.max_steps,
                                 st.seed, plant=plant).mfpt[0])
    raise ValueError(f"unknown robustness measure {name!r}")
