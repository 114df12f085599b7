"""The basin of attraction's area in a 2-D slice of the Poincaré section.

An area in the section depends on the coordinates it is measured in (Jin et al. 2021, R.
Soc. Open Sci. 8: 201122): this module states it as the *fraction of a stated box* - the
box the basin map covered (cell edges along its two state axes, in their units) - and, in
those units, as that fraction times the box's area.  Comparing walkers is meaningful only
on the same axes and box.  The basin exists when the cell holding the gait reaches it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["BasinArea", "basin_area"]


@dataclass(frozen=True)
class BasinArea:
    """The basin's share of a basin map's box.

    Attributes
    ----------
    x_axis, y_axis : str
        State names spanning the slice.
    x_unit, y_unit : str
    box : tuple of float
        ``(x_lo, x_hi, y_lo, y_hi)``: the cell edges of the map [x_unit, y_unit].
    fraction : float
        Cells that reach the period-1 gait / all cells of the box.
    area : float
        ``fraction`` times the box's area [x_unit y_unit].
    cells : int
        Cells of the map.
    exists : bool
        The cell holding the gait reaches it (False: no basin around the gait in this
        slice, or the gait outside the box).
    """

    x_axis: str
    y_axis: str
    x_unit: str
    y_unit: str
    box: tuple
    fraction: float
    area: float
    cells: int
    exists: bool


def _edges(c: np.ndarray) -> tuple[float, float]:
    c = np.asarray(c, float)
    h = 0.5 * (c[-1] - c[0]) / max(c.size - 1, 1)
    return float(c[0] - h), float(c[-1] + h)


def basin_area(b) -> BasinArea:
    """The basin's area in the slice of a loaded ``basin.h5``.

    Parameters
    ----------
    b : walkerlab.io.schemas.basin.BasinArtifact
        Uniform cell centres ``x`` (nx,), ``y`` (ny,); ``outcome`` (ny, nx).

    Returns
    -------
    BasinArea
    """
    conv = np.asarray(b.outcome) == b.outcomes.index("converged")
    x0, x1 = _edges(b.x)
    y0, y1 = _edges(b.y)
    frac = float(conv.mean())
    exists = False
    fx, fy = b.fixed_point.get(b.x_axis), b.fixed_point.get(b.y_axis)
    if fx is not None and fy is not None and x0 <= fx <= x1 and y0 <= fy <= y1:
        i = int(np.argmin(np.abs(np.asarray(b.x) - fx)))
        j = int(np.argmin(np.abs(np.asarray(b.y) - fy)))
        exists = bool(conv[j, i])
    return BasinArea(b.x_axis, b.y_axis, b.x_unit, b.y_unit, (x0, x1, y0, y1), frac,
                     frac * (x1 - x0) * (y1 - y0), int(conv.size), exists)
