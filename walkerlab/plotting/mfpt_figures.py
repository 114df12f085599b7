"""Mean first-passage time against the terrain's roughness (the per-step slope's or landing
height's standard deviation), drawn from
``mfpt.h5`` only (as Byl & Tedrake 2009, Fig. 9: log MFPT against the terrain roughness)."""

from __future__ import annotations

import numpy as np


def plain_log_ticks(axis) -> None:
    """Label a log axis's ticks as plain numbers (``3``, ``40``, ``1,000``), not
    ``3×10^0``: a step count reads as a count.  Which ticks carry a label is matplotlib's
    own choice (minor ticks only where the axis spans few decades)."""
    from matplotlib.ticker import LogFormatter

    class Plain(LogFormatter):
        def _num_to_string(self, x, vmin, vmax):
            return f"{x:,.0f}" if x >= 1 else f"{x:.3g}"

    axis.set_major_formatter(Plain(labelOnlyBase=True))
    axis.set_minor_formatter(Plain(labelOnlyBase=False, minor_thresholds=(1, 0.4)))


def mfpt_figure(d, title: str = ""):
    """log10 MFPT [steps] against the roughness: the per-step slope's sigma [rad], or the
    per-step landing height's [mm] for a study of heights (``d.sigma_m``); Monte Carlo with
    2 standard errors, mesh.

    Parameters
    ----------
    d : walkerlab.io.schemas.mfpt.MfptData
    """
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.0, 4.2), layout="constrained")
    heights = getattr(d, "sigma_m", None) is not None  # a study of per-step heights
    s = 1e3 * np.asarray(d.sigma_m) if heights else np.asarray(d.sigma_rad)
    mc, se = d["mfpt_steps_montecarlo"], d["mfpt_steps_montecarlo_stderr"]
    ok = np.isfinite(mc)
    if ok.any():
        lo = np.clip(mc - 2 * np.nan_to_num(se), 1e-1, None)
        ax.errorbar(s[ok], mc[ok], yerr=[(mc - lo)[ok], (2 * np.nan_to_num(se))[ok]], fmt="o-",
                    capsize=3, color="#1f77b4", label="Monte Carlo (+/- 2 SE)")
    inf = np.isinf(mc)
    if inf.any():
        top = np.nanmax(np.where(np.isfinite(mc), mc, np.nan)) if ok.any() else 1.0
        ax.plot(s[inf], np.full(inf.sum(), 10 * top), "^", color="#1f77b4",
                label="Monte Carlo: no fall (beyond the cap)")
    me = d["mfpt_steps_mesh"]
    okm = np.isfinite(me)
    if okm.any():
        conv = d["mesh_converged"] > 0.5
        ax.plot(s[okm], me[okm], "s--", color="#d62728", mfc="none",
                label="mesh (open: not converged)")
        if (okm & conv).any():
            ax.plot(s[okm & conv], me[okm & conv], "s", color="#d62728",
                    label="mesh, converged (< 5 % on refinement)")
    ax.set_yscale("log")
    plain_log_ticks(ax.yaxis)
    ax.set_xlabel("per-step landing height standard deviation sigma [mm]" if heights else
                  "per-step slope standard deviation sigma [rad]")
    ax.set_ylabel("MFPT [steps before the fall]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    return fig
