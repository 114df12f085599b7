"""``stability_map_<kind>.h5``: where the contact model has a periodic gait, over one
contact parameter × the slope (writer and loader side by side).

Layout: root attributes ``kind``, ``y_path`` (the scene field varied), ``y_label``,
``stiffness_family``, ``max_step_maps``, ``method``; ``y_values`` (ny,)
and ``slopes_deg`` (nx,) [deg]; one (ny, nx) array per cell field
(:data:`walkerlab.studies.stability.CELL_FIELDS`: ``exists``, ``stable``,
``max_abs_multiplier``, ``step_period_s`` [s], ``patch_margin_m`` [m], ``residual``,
``reason`` (why no gait, text), ``wall_time_s`` [s] ...); ``summary/<fraction>``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from walkerlab.io.artifacts import artifact_loader, put

_UNITS = {"max_abs_multiplier": "-", "step_period_s": "s", "patch_margin_m": "m",
          "residual": "-", "wall_time_s": "s", "exists": "-", "stable": "-"}


@dataclass
class StabilityMapRun:
    """What the stability-map stage computed (the writer's input).

    Attributes
    ----------
    spec : walkerlab.studies.stability.MapSpec
    cells : dict[str, ndarray]
        :func:`walkerlab.studies.stability.gait_map`'s result.
    cell_fields : tuple of str
        The per-cell arrays written, in order (:data:`walkerlab.studies.stability.CELL_FIELDS`).
    y_label : str
        Axis label of the varied parameter, with its unit.
    fractions : dict[str, float]
        :func:`walkerlab.studies.stability.stable_fraction` of the cells.
    stiffness_family : str
        Of the scene's contact law.
    scene_point : (float, float), optional
        The scene's own slope [deg] and y value (``scene_slope_deg``, ``scene_y``).
    """

    spec: object
    cells: dict
    fractions: dict
    stiffness_family: str
    cell_fields: tuple = ()
    y_label: str = ""
    #: the scene's own point (slope [deg], y in the map's unit), marked on the map
    scene_point: tuple[float, float] | None = None


def write_stability_map(f, run: StabilityMapRun) -> None:
    """Fill an open (in-memory) artifact with ``run`` (layout in the module docstring)."""
    f.attrs["kind"] = run.spec.kind
    f.attrs["y_path"] = run.spec.y_path
    f.attrs["y_label"] = run.y_label
    f.attrs["stiffness_family"] = run.stiffness_family
    f.attrs["max_step_maps"] = int(run.spec.max_step_maps)
    if run.scene_point is not None:  # marked on the map wherever the grid lies
        f.attrs["scene_slope_deg"], f.attrs["scene_y"] = (float(v) for v in run.scene_point)
    f.attrs["method"] = ("each cell: fixed point of the contact walker's mid-stance "
                         "step map, continued from its neighbour along the slope, "
                         "else from the ideal fixed point at that slope")
    put(f, "y_values", run.cells["y_values"],
        {"patch_width": "m", "friction": "-"}.get(run.spec.kind, "scene units"),
        run.spec.y_path)
    put(f, "slopes_deg", run.cells["slopes_deg"], "deg", "slope angle")
    for fld in run.cell_fields:
        v = run.cells[fld]
        if v.dtype == object:
            put(f, fld, np.asarray([[str(x) for x in r] for r in v],
                                   dtype=h5py.string_dtype()), "-", fld)
        else:
            put(f, fld, np.asarray(v, float), _UNITS.get(fld, "-"), fld)
    for k, v in run.fractions.items():
        put(f, f"summary/{k}", v, "-", k)


@dataclass
class StabilityMap:
    """A loaded stability map: ``attrs`` (root attributes, strings decoded), ``y_values``
    (ny,), ``slopes_deg`` (nx,) [deg], ``cells`` (each cell field, (ny, nx); ``reason`` as
    str), ``summary`` (``exists_fraction``, ``stable_fraction``, ``cells`` ...)."""

    attrs: dict
    y_values: np.ndarray
    slopes_deg: np.ndarray
    cells: dict
    summary: dict = field(default_factory=dict)


@artifact_loader(None)
def load_stability_map(f, path: Path | str) -> StabilityMap:
    """Load a ``stability_map_<kind>.h5``."""
    cells = {}
    for k in f:  # every (ny, nx) cell array (the writer's cell fields)
        if k in ("y_values", "slopes_deg") or not hasattr(f[k], "shape") \
                or f[k].ndim != 2:
            continue
        v = f[k][()]
        if v.dtype.kind in ("S", "O"):
            v = np.array([[x.decode() if isinstance(x, bytes) else str(x) for x in r]
                          for r in v], dtype=object)
        cells[k] = v
    return StabilityMap(
        attrs={k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()},
        y_values=f["y_values"][()], slopes_deg=f["slopes_deg"][()], cells=cells,
        summary={k: f["summary"][k][()] for k in f["summary"]} if "summary" in f else {})
