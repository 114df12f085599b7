"""``bifurcation.h5`` / ``bifurcation_<field>.h5``: what the report reads of a bifurcation
diagram (the writer, :func:`walkerlab.sweep.bifurcation.bifurcation_writer`, and the full
reader :func:`walkerlab.sweep.bifurcation.load_bifurcation` still live with the sweep).

Layout read here: root attribute ``parameter_path`` (the scene field of the grid; the slope
[deg] when absent); the grid coordinate (``slope``, or the field's dotted path) with its
``unit``; ``onset/onset_slope`` or ``onset/onset_value`` (period-doubling onset, in the
grid's unit); ``steady_state/attractor_period`` and ``steady_state/outcome`` per grid value.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import open_artifact

STAGE = "bifurcation"
#: the grid of ``bifurcation --slopes``: its coordinate is named ``slope`` (any other
#: field's grid is named by the field's dotted path; as
#: :func:`walkerlab.sweep.bifurcation.parameter_dim` writes it)
SLOPE_PATH = "slope.angle_deg"


@dataclass
class BifurcationSummary:
    """A loaded bifurcation diagram, as far as the report uses it.

    Attributes
    ----------
    path : Path
    data : dict
        ``parameter_path``, ``parameter_unit``, the grid (ndarray (n,), under its coordinate
        name), ``onset/onset_slope`` or ``onset/onset_value`` where stored, and
        ``steady_state/outcome`` (list of str, or None in an artifact without it): the
        input of :func:`walkerlab.sweep.bifurcation.onset_value` and ``fall_onset``.
    values : ndarray (n,)
        The grid, in ``data["parameter_unit"]``.
    attractor_period : ndarray (n,)
        Period of the steady state at each grid value (0: none).
    """

    path: Path
    data: dict
    values: np.ndarray
    attractor_period: np.ndarray


def load_bifurcation_summary(path: Path) -> BifurcationSummary:
    """Load what the report shows of a bifurcation artifact.

    Raises
    ------
    walkerlab.io.artifacts.ArtifactError
        Missing, unreadable, of another stage or version, or lacking a dataset (one line).
    """
    with open_artifact(path, STAGE) as f:
        ppath = f.attrs.get("parameter_path", SLOPE_PATH)
        ppath = ppath.decode() if isinstance(ppath, bytes) else str(ppath)
        dim = "slope" if ppath == SLOPE_PATH else ppath
        values = f[dim][()]
        data = {"parameter_path": ppath, "parameter_unit": str(f[dim].attrs.get("unit", "deg")),
                dim: values}
        for name in ("onset/onset_slope", "onset/onset_value"):
            if name in f:
                data[name] = f[name][()]
        data["steady_state/outcome"] = (list(f["steady_state/outcome"].asstr()[()])
                                        if "steady_state/outcome" in f else None)
        return BifurcationSummary(Path(path), data, values,
                                  f["steady_state/attractor_period"][()])
