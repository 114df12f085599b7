"""Basin-of-attraction figure, drawn from ``basin.h5`` only (as Schwab & Wisse 2001, Fig. 4)."""

from __future__ import annotations

import numpy as np

OUTCOME_COLORS = {
    "converged": "#2ca02c", "other_attractor": "#9467bd", "fell_forward": "#d62728",
    "fell_backward": "#1f77b4", "max_steps": "#ff7f0e", "stalled": "#7f7f7f",
    "unreachable": "#e8e8e8",
}


def basin_figure(d, title: str = ""):
    """Outcome map (left) and steps to convergence of the converged cells (right).

    Parameters
    ----------
    d : walkerlab.io.schemas.basin.BasinArtifact
        A loaded ``basin.h5``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    xc, yc, out = d.x, d.y, d.outcome  # cell centres (grid axes, not states)
    dx = np.ptp(xc) / (xc.size - 1) / 2 if xc.size > 1 else 0.5
    dy = np.ptp(yc) / (yc.size - 1) / 2 if yc.size > 1 else 0.5
    extent = (xc.min() - dx, xc.max() + dx, yc.min() - dy, yc.max() + dy)
    names = d.outcomes
    cmap = ListedColormap([OUTCOME_COLORS.get(n, "k") for n in names])
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6), constrained_layout=True)
    ax = axes[0]
    masked = np.ma.masked_less(out, 0)
    ax.imshow(masked, origin="lower", extent=extent, aspect="auto", cmap=cmap,
              vmin=-0.5, vmax=len(names) - 0.5, interpolation="nearest")
    fp = d.fixed_point
    for a in axes:
        a.plot(fp[d.x_axis], fp[d.y_axis], marker="*", color="k", ms=12, mec="w",
               ls="none", label="period-1 fixed point")
        a.set_xlabel(f"{d.x_axis.replace('_', ' ')} [{d.x_unit}]")
        a.set_ylabel(f"{d.y_axis.replace('_', ' ')} [{d.y_unit}]")
    n_cells = out.size
    handles = [Patch(color=OUTCOME_COLORS.get(n, "k"),
                     label=f"{n.replace('_', ' ')} ({100 * np.mean(out == i):.1f} %)")
               for i, n in enumerate(names) if np.any(out == i)]
    ax.legend(handles=handles, fontsize=7, loc="best", framealpha=0.85)
    start = ("cells: states just after a heel strike" if d.start == "heel_strike"
             else "other coordinates from the fixed point")
    ax.set_title(f"outcome after at most {d.max_steps} steps ({n_cells} cells)\n{start}",
                 fontsize=10)
    ax = axes[1]
    conv = names.index("converged") if "converged" in names else -1
    steps = np.ma.masked_where(out != conv, d.steps.astype(float))
    im = ax.imshow(steps, origin="lower", extent=extent, aspect="auto", cmap="viridis",
                   interpolation="nearest")
    fig.colorbar(im, ax=ax, label="steps to converge")
    ax.set_title("steps to reach the period-1 gait (converged cells)", fontsize=10)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig
