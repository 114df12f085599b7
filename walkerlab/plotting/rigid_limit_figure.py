"""The contact periodic gait against the stiffness factor, rigid values as lines."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def rigid_limit_figure(d: dict, title: str):
    """Step period, step length and |multiplier - ...| parts against kappa (log axis).

    Parameters
    ----------
    d : dict
        :func:`walkerlab.io.schemas.rigid_limit.load_rigid_limit`.
    title : str
    """
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    k = d["kappa"]
    for ax, key, rigid, unit in ((axes[0], "period", d["rigid_period"], "s"),
                                 (axes[1], "step_length", d["rigid_step_length"], "m")):
        ax.semilogx(k, d[key], "o-", label="contact periodic gait")
        ax.axhline(rigid, color="k", lw=1, ls="--", label="rigid")
        ax.set_ylabel(f"{key.replace('_', ' ')} [{unit}]")
    ax = axes[2]
    for j, lam in enumerate(d["rigid_multipliers"]):
        if lam.imag < 0:  # the conjugate of a pair already drawn
            continue
        line, = ax.semilogx(k, d["multipliers"][:, j].real, "o-",
                            label=f"Re multiplier {j + 1}")
        ax.axhline(lam.real, color=line.get_color(), lw=1, ls="--")
        if abs(lam.imag) > 0:
            ax.semilogx(k, np.abs(d["multipliers"][:, j].imag), "s:", color=line.get_color(),
                        label=f"|Im| multiplier {j + 1}")
            ax.axhline(abs(lam.imag), color=line.get_color(), lw=1, ls=":")
    ax.set_ylabel("Floquet multiplier [-] (rigid: lines)")
    for ax in axes:
        ax.set_xticks(k, [f"{v:g}" for v in k])  # the factors computed, not the decades
        ax.minorticks_off()
        ax.set_xlabel("stiffness factor kappa [-]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle(f"Rigid limit - {title}: the contact gait along the rigid-limit family")
    fig.tight_layout()
    return fig
