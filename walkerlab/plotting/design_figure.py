"""The figure of ``optimize_design.h5``: how the design optimiser went (the measure at each
evaluation) and, for each field, the measure against the field's value with the optimum and
its sensitivity (the tangent of slope d measure / d field there)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["save_design_figure"]


def save_design_figure(d, title: str, folder: Path,
                       stem: str = "optimize_design") -> list[Path]:
    """Draw ``<stem>.png`` / ``.svg`` from a loaded design artifact (``<stem>.h5``,
    :func:`walkerlab.io.runpaths.design_stem`).

    Parameters
    ----------
    d : walkerlab.io.schemas.optimize.DesignData
        Left panel: the measure [its unit] at each evaluation, in order (convergence); then
        one panel per field (k fields): every evaluated value against the measure, the
        optimum starred, and where the gradient is finite its tangent line.
    title : str
        The scene's name.
    folder : Path
        The figures folder.
    stem : str
        The files' stem (the artifact's).

    Returns
    -------
    list of Path
        The PNG and SVG written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from walkerlab.plotting.figures import save  # light

    k = len(d.fields)
    fig, axes = plt.subplots(1, 1 + k, figsize=(4.6 * (1 + k), 3.6), squeeze=False)
    axes = axes[0]
    label = f"{d.objective} [{d.objective_unit}]"
    axes[0].plot(np.arange(1, d.history_objective.size + 1), d.history_objective, "o-", ms=3)
    axes[0].set_xlabel("evaluation")
    axes[0].set_ylabel(label)
    axes[0].set_title(f"{d.evaluations} fixed points; {d.message}", fontsize=8)
    for j, (name, ax) in enumerate(zip(d.fields, axes[1:])):
        x = d.history_values[:, j]
        ax.plot(x, d.history_objective, "o", ms=3, color="tab:blue", label="evaluated")
        ax.plot(d.values[j], d.objective_value, "*", ms=12, color="tab:red",
                label=f"optimum {d.values[j]:.5g}: {d.objective_value:.6g}")
        g = float(d.gradient[j])
        if np.isfinite(g):
            span = np.array([x.min(), x.max()])
            ax.plot(span, d.objective_value + g * (span - d.values[j]), "--", color="0.4",
                    lw=1, label=f"sensitivity {g:.3g} per unit")
        ax.set_xlabel(name)
        ax.set_ylabel(label)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(f"{title}: design optimisation over its own gait", fontsize=10)
    fig.tight_layout()
    return save(fig, Path(folder), stem)
