"""``mfpt.h5``: the mean first-passage time on per-step random slopes, writer and reader side
by side (the artifact's schema in one place, as a Touchstone reader/writer pair).

Layout (netCDF-4 conventions: ``sigma_rad`` is the coordinate / dimension scale)::

    sigma_rad                       (sigma,)  rad    per-step slope standard deviation
    mfpt_steps_montecarlo           (sigma,)  steps  censored geometric MLE (NaN: not run;
                                                     inf: no walk fell)
    mfpt_steps_montecarlo_stderr    (sigma,)  steps
    montecarlo_walks, montecarlo_falls, montecarlo_heel_strikes      (sigma,)
    mfpt_steps_mesh                 (sigma,)  steps  from the gait's node, finest mesh
    mfpt_steps_mesh_quasi_stationary(sigma,)  steps  1 / (1 - lambda_2) - 1
    mesh_cells                      (sigma,)  -      nodes (Voronoi cells) of the finest mesh
    mesh_change                     (sigma,)  -      relative MFPT change at the last refinement
    mesh_converged                  (sigma,)  -      change < the scene's mesh_rel_change
    mesh_escaped                    (sigma,)  -      off-mesh probability per step
    mesh_wall_time_s, montecarlo_wall_time_s (sigma,) s
    sigma_m                         (sigma,)  m      per-step landing height standard
                                                     deviation (a study of heights only:
                                                     sigma_rad is then the slope's, fixed)
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader

STAGE = "mfpt"

#: variable -> (unit, description); every one lies on the sigma_rad dimension
VARIABLES = {
    "mfpt_steps_montecarlo": ("steps", "Monte Carlo MFPT: heel strikes before the fall, "
                              "censored geometric MLE (heel strikes / falls)"),
    "mfpt_steps_montecarlo_stderr": ("steps", "standard error of mfpt_steps_montecarlo"),
    "montecarlo_walks": ("-", "Monte Carlo walks"),
    "montecarlo_falls": ("-", "walks that fell (the rest reached the step cap)"),
    "montecarlo_heel_strikes": ("steps", "heel strikes of all walks"),
    "montecarlo_wall_time_s": ("s", "Monte Carlo wall time"),
    "mfpt_steps_mesh": ("steps", "mesh MFPT from the gait's node (finest mesh)"),
    "mfpt_steps_mesh_quasi_stationary": ("steps", "mesh MFPT 1/(1 - lambda_2) - 1"),
    "mesh_cells": ("-", "nodes (Voronoi cells of visited post-impact states) of "
                   "the finest mesh"),
    "mesh_change": ("-", "relative MFPT change between the last two meshes"),
    "mesh_converged": ("-", "1 if mesh_change < mfpt.mesh_rel_change"),
    "mesh_escaped": ("-", "probability per step, from the quasi-stationary "
                     "distribution, of landing off the mesh (then on the nearest node; not "
                     "a fall)"),
    "mesh_wall_time_s": ("s", "mesh wall time (all refinements)"),
}


@dataclass
class MfptData:
    """The contents of ``mfpt.h5`` (arrays of shape (sigma,)).

    Attributes
    ----------
    sigma_rad : ndarray
    values : dict[str, ndarray]
        Every name of :data:`VARIABLES`.
    method : str
    state_names : list of str
    mesh_history : list of dict
        Every mesh of every sigma: ``sigma_rad, h, cells, mfpt_steps, change``.
    sigma_m : ndarray or None
        The roughness levels of a study of per-step landing heights [m] (``mfpt.sigma_m``);
        None: a study of per-step slopes.
    """

    sigma_rad: np.ndarray
    values: dict
    method: str
    state_names: list
    mesh_history: list
    sigma_m: np.ndarray | None = None

    def __getitem__(self, name: str) -> np.ndarray:
        return self.values[name]

    def mesh_notes(self, rel_change: float | None = None) -> list[str]:
        """For each sigma: '' for a converged mesh MFPT (or none computed), else one clause
        saying its refinement did not converge: the last relative change of the MFPT
        (against ``rel_change`` [-], ``mfpt.mesh_rel_change``, when given) and the cells of
        the finest mesh."""
        out = []
        for conv, change, cells in zip(self["mesh_converged"], self["mesh_change"],
                                       self["mesh_cells"]):
            if not np.isfinite(conv) or conv > 0.5:
                out.append("")
                continue
            last = (f"last refinement changed it by {100 * change:.3g} %"
                    if np.isfinite(change) else "one mesh only, no refinement to compare")
            limit = (f" > {100 * rel_change:.3g} %"
                     if rel_change is not None and np.isfinite(change) else "")
            out.append(f"refinement NOT converged ({last}{limit} at {int(cells)} cells, the "
                       "most mfpt.mesh_max_cells or the visited states allow): its error may "
                       "be that large")
        return out


def write(f, data: MfptData) -> None:
    """Fill an open artifact (``write_artifact``'s writer) with ``data``."""
    from walkerlab.io.artifacts import put
    from walkerlab.io.netcdf import coordinate

    coordinate(f, "sigma_rad", np.asarray(data.sigma_rad, float), "rad",
               "standard deviation of the per-step slope")
    for name, (unit, desc) in VARIABLES.items():
        put(f, name, np.asarray(data.values[name], float), unit, desc, dims=("sigma_rad",))
    if data.sigma_m is not None:
        put(f, "sigma_m", np.asarray(data.sigma_m, float), "m",
            "standard deviation of the per-step landing height", dims=("sigma_rad",))
    f.attrs["method"] = data.method
    f.attrs["state_names"] = list(data.state_names)
    hist = data.mesh_history
    cols = ("sigma_rad", "h", "cells", "mfpt_steps", "change")
    units = ("rad", "standard deviations", "-", "steps", "-")
    for c, u in zip(cols, units):
        put(f, f"mesh_history/{c}", np.array([r[c] for r in hist], float), u,
            f"every mesh computed: {c}", dims=("mesh",))


@artifact_loader(STAGE)
def load(f, path: Path) -> MfptData:
    """Read ``mfpt.h5``."""
    sigma = f["sigma_rad"][()]
    values = {k: f[k][()] for k in VARIABLES}
    hist_cols = ("sigma_rad", "h", "cells", "mfpt_steps", "change")
    arrays = {c: f[f"mesh_history/{c}"][()] for c in hist_cols}
    hist = [{c: float(arrays[c][i]) for c in hist_cols}
            for i in range(len(arrays["sigma_rad"]))]
    return MfptData(sigma, values, str(f.attrs["method"]),
                    [str(s) for s in f.attrs["state_names"]], hist,
                    f["sigma_m"][()] if "sigma_m" in f else None)
