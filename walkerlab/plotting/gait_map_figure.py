"""The stability map of the contact gait, drawn from a loaded ``stability_map_<kind>.h5``
(:mod:`walkerlab.studies.stability`): per cell of slope and a second field (stiffness,
friction, ...) a stable or unstable gait with its largest |Floquet multiplier|, or why no
gait was found, the scene's own point marked (:func:`gait_map_figure`).
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap

from walkerlab.units import Units

__all__ = ["GAIT_CLASSES", "GAIT_COLORS", "gait_map_figure"]

#: the map's cell classes, in the colour map's order (:data:`GAIT_COLORS`)
GAIT_CLASSES = ("stable gait", "unstable gait", "off patch", "falls", "work limit",
                "no convergence", "other failure")
GAIT_COLORS = ("#2ca02c", "#ff7f0e", "#9467bd", "#d62728", "#17becf", "#7f7f7f", "#000000")
_REASON_CLASS = {"off_patch": 2, "fall": 3, "no_mid_stance": 3, "time_limit": 4,
                 "work_limit": 4, "not_converged": 5}
#: cell text of a cell without a gait (whole words, wrapped to fit a cell)
_REASON_TEXT = {"off_patch": "off\npatch", "fall": "falls", "no_mid_stance": "no mid-\nstance",
                "time_limit": "time\nlimit", "work_limit": "work\nlimit",
                "not_converged": "no con-\nvergence",
                "solver_failure": "solver\nfailure", "no_ideal_gait": "no ideal\ngait",
                "invalid_config": "invalid\nconfig", "error": "error",
                "unsupported": "not sup-\nported"}


def _scene_point(xv, yv, attrs) -> tuple[float, float] | None:
    """The scene's (slope, y) in the map's cell-index coordinates (interpolated, log on a
    log grid), or None when the artifact does not store it."""
    try:
        sx, sy = float(attrs["scene_slope_deg"]), float(attrs["scene_y"])
    except (KeyError, TypeError, ValueError):
        return None
    if not (np.isfinite(sx) and np.isfinite(sy)) or xv.size < 1 or yv.size < 1:
        return None
    log = yv.min() > 0 and sy > 0 and yv.max() / yv.min() > 100

    def idx(v, grid, take_log=False):
        g = np.log10(grid) if take_log else grid
        v = np.log10(v) if take_log else v
        order = np.argsort(g)
        return float(np.interp(v, g[order], np.arange(g.size)[order]))

    return idx(sx, xv), idx(sy, yv, log)


def gait_map_figure(data: dict):
    """Stability map of the contact gait from a loaded ``stability_map_<kind>.h5``.

    Per cell: stable / unstable gait (text: max |Floquet multiplier|) or why no gait was
    found (text: the reason in words).  Title: the fractions of cells where a gait exists
    and where it exists and is stable; the cells' wall time (median, max) in the subtitle.

    Parameters
    ----------
    data : walkerlab.io.schemas.stability_map.StabilityMap
        A loaded map: ``y_values`` (ny,), ``slopes_deg`` (nx,), (ny, nx) cell arrays
        ``exists``, ``stable``, ``max_abs_multiplier``, ``reason``, ``wall_time_s`` and
        ``attrs``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    yv, xv = np.asarray(data.y_values, float), np.asarray(data.slopes_deg, float)
    ex = np.asarray(data.cells["exists"], float) > 0.5
    st = np.asarray(data.cells["stable"], float) > 0.5
    mm = np.asarray(data.cells["max_abs_multiplier"], float)
    reason = np.asarray(data.cells["reason"], dtype=object)
    code = np.zeros(ex.shape)
    for (i, j), e in np.ndenumerate(ex):
        code[i, j] = (0 if st[i, j] else 1) if e else _REASON_CLASS.get(str(reason[i, j]), 6)
    attrs = data.attrs
    kind = str(attrs.get("kind", ""))
    # the label names its unit (the field's); a nondimensional scene's SI units read in l, M, g
    ylab = Units(str(attrs.get("scene_units", "SI")))(
        str(attrs.get("y_label", attrs.get("y_path", "y"))))
    if kind == "stiffness":
        ylab += f", {attrs.get('stiffness_family', 'paper')} family"
    cmap = ListedColormap(GAIT_COLORS)
    norm = BoundaryNorm(np.arange(len(GAIT_CLASSES) + 1) - 0.5, cmap.N)
    # cells wide enough for two short lines of text
    fig, a1 = plt.subplots(figsize=(max(6.5, 0.75 * xv.size + 3.5), max(3.8, 0.5 * yv.size + 1.6)),
                           layout="constrained")
    xi, yi = np.arange(xv.size), np.arange(yv.size)
    a1.pcolormesh(xi, yi, code, cmap=cmap, norm=norm, shading="nearest")
    for (i, j), c in np.ndenumerate(code):
        txt = f"{mm[i, j]:.2f}" if ex[i, j] else _REASON_TEXT.get(str(reason[i, j]), "?")
        a1.text(j, i, txt, ha="center", va="center", fontsize=6, linespacing=0.9,
                color="k" if c in (1, 4) else "w")
    for k, lab in enumerate(GAIT_CLASSES):
        if np.any(code == k):
            a1.plot([], [], "s", color=GAIT_COLORS[k], label=lab)
    at = _scene_point(xv, yv, attrs)
    if at is not None:  # the scene's own contact and slope, between cells if need be
        a1.plot(*at, marker="*", ms=16, mfc="none", mec="k", mew=1.6, ls="none",
                label="this scene", zorder=5)
    a1.plot([], [], " ", label="cell text: max |multiplier|\nor why no gait")
    a1.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    log_y = yv.min() > 0 and yv.max() / yv.min() > 100
    a1.set_xticks(xi, [f"{v:g}" for v in xv], fontsize=7)
    a1.set_yticks(yi, [f"{v:.3g}" for v in yv], fontsize=7)
    a1.set_xlabel("slope φ [deg]")
    a1.set_ylabel(ylab + (" (log grid)" if log_y else ""), fontsize=8)
    n = ex.size
    wall = np.asarray(data.cells["wall_time_s"], float)
    wall_txt = (f"; wall time per cell: median {np.nanmedian(wall):.3g} s, max "
                f"{np.nanmax(wall):.3g} s" if np.isfinite(wall).any() else "")
    a1.set_title(f"contact gait: exists in {ex.sum()}/{n} cells ({100 * ex.sum() / n:.0f} %), "
                 f"stable in {(ex & st).sum()}/{n} ({100 * (ex & st).sum() / n:.0f} %)"
                 f"\n{wall_txt.lstrip('; ')}", fontsize=9)
    return fig
