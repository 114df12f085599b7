"""Figures of a continuation artifact (:mod:`walkerlab.io.schemas.continuation`), drawn from
the loaded data only.

- :func:`continuation_figure`: the branches (stance-leg angle just after each of the ``k``
  heel strikes of a period-``k`` orbit) against the parameter, stable solid, unstable
  dashed, period 1/2/4 in colours; special points marked and labelled; a branch of one
  point drawn as a marker; the steady states of a brute-force ``bifurcation`` artifact over
  the same field overlaid as dots; below, the largest |Floquet multiplier| of each branch.
  Legends sit outside the axes, so they never cover data.
- :func:`two_parameter_figure`: fold / period-doubling curves in the plane of two fields.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

__all__ = ["continuation_figure", "two_parameter_figure"]

PERIOD_COLORS = {1: "tab:blue", 2: "tab:orange", 4: "tab:green", 8: "tab:purple"}
MARKERS = {"fold": ("s", "tab:red", "F"), "period_doubling": ("o", "tab:red", "PD"),
           "neimark_sacker": ("D", "tab:brown", "NS"), "branch_end": ("X", "k", "end")}


def _y(data, states: dict) -> tuple[np.ndarray, str]:
    name = "stance_angle" if "stance_angle" in data.state_names else data.state_names[0]
    return np.degrees(np.asarray(states[name], float)), f"{name.replace('_', ' ')} just " \
        "after heel strike [deg]"


def _runs(mask: np.ndarray):
    """Index runs where ``mask`` is constant: (start, stop_inclusive, value)."""
    out, i = [], 0
    while i < mask.size:
        j = i
        while j + 1 < mask.size and mask[j + 1] == mask[i]:
            j += 1
        out.append((i, j, bool(mask[i])))
        i = j + 1
    return out


def continuation_figure(data, title: str = "", brute: dict | None = None):
    """Continuation diagram.

    Parameters
    ----------
    data : walkerlab.io.schemas.continuation.ContinuationData
    title : str
    brute : dict, optional
        :func:`walkerlab.io.schemas.bifurcation.load_bifurcation` data over the same field:
        its steady states are drawn as dots.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9.5, 7), sharex=True,
                                   gridspec_kw={"height_ratios": [3, 2]})
    unit = "" if data.unit in ("-", "") else f" [{data.unit}]"
    if brute is not None and "steady_state/stance_angle_after_impact" in brute:
        from walkerlab.studies.bifurcation import parameter_values

        s = parameter_values(brute)[0]
        st = np.asarray(brute["steady_state/stance_angle_after_impact"], float)
        ss, yy = np.repeat(s, st.shape[1]), st.ravel()
        m = np.isfinite(yy)
        ax1.plot(ss[m], yy[m], ".", ms=2.0, color="0.35", zorder=1,
                 label="steady state, simulated (bifurcation)")
    seen = set()
    for b in data.branches:
        k, p = b["period"], np.asarray(b["param"], float)
        ys, ylabel = _y(data, b.get("orbit", b["states"]))
        ys = ys.reshape(p.size, -1)
        y = ys[:, 0]
        mmax = np.max(np.abs(b["multipliers"]), axis=1)
        c = PERIOD_COLORS.get(k, "tab:gray")
        for i, j, st in _runs(np.asarray(b["stable"], bool)):
            sl = slice(i, j + 2)  # join to the next point, so runs meet
            lab = f"period {k}, {'stable' if st else 'unstable'}"
            lab = None if lab in seen else lab
            seen.add(f"period {k}, {'stable' if st else 'unstable'}")
            ls = "-" if st else "--"
            if p.size == 1:
                ax1.plot(p, y, "o", color=c, mfc=c if st else "w", label=lab)
                ax2.plot(p, mmax, "o", color=c, mfc=c if st else "w")
            else:  # every heel strike of the period-k orbit: k curves
                for h in range(ys.shape[1]):
                    ax1.plot(p[sl], ys[sl, h], ls, color=c, lw=1.4,
                             label=lab if h == 0 else None, zorder=3)
                ax2.plot(p[sl], mmax[sl], ls, color=c, lw=1.2, zorder=3)
    sp = data.special
    for i, kind in enumerate(sp.get("kind", [])):
        mk, col, short = MARKERS.get(str(kind), ("*", "k", str(kind)))
        y, _ = _y(data, {n: np.atleast_1d(v)[i:i + 1] for n, v in sp["states"].items()})
        pv = float(sp["param"][i])
        lab = {"fold": "fold (multiplier +1)", "period_doubling": "period doubling (-1)",
               "neimark_sacker": "Neimark-Sacker (|complex pair| 1)",
               "branch_end": "branch end"}.get(str(kind), str(kind))
        ax1.plot([pv], y, mk, color=col, ms=7, mfc="none", mew=1.6, zorder=5,
                 label=None if lab in seen else lab)
        seen.add(lab)
        if np.isfinite(y[0]):
            ax1.annotate(f"{short}{int(sp['period'][i])} {pv:.5g}", (pv, y[0]),
                         textcoords="offset points", xytext=(6, 8 + 12 * (i % 3)),
                         fontsize=7, color=col, annotation_clip=True,
                         ha="right" if i % 2 else "left")
        ax2.axvline(pv, color=col, lw=0.5, ls=":")
    ax1.margins(x=0.04, y=0.12)
    ax1.axvline(data.start, color="0.5", lw=0.6, ls="-.", label="start (the scene's gait)")
    ax1.set_ylabel(ylabel if data.branches else "")
    ax2.axhline(1.0, color="0.5", lw=0.8)
    big = [np.max(np.abs(b["multipliers"])) for b in data.branches if len(b["param"])]
    if big and max(big) > 20:  # an unstable branch far out: log scale keeps |mu| = 1 visible
        ax2.set_yscale("log")
    ax2.set_ylabel("max |Floquet multiplier| [-]")
    ax2.set_xlabel(f"{data.path}{unit}")
    ax1.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    if title:
        ax1.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def two_parameter_figure(data, title: str = ""):
    """Fold and period-doubling curves in the plane (``data.path``, the second field).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = plt.subplots(figsize=(8, 5))
    for c in data.curves:
        mk, col, short = MARKERS.get(c["kind"], ("*", "k", c["kind"]))
        ax.plot(c["param2"], c["param"], "-", marker=mk, ms=3, color=col,
                label=f"{c['kind'].replace('_', ' ')} of the period-{c['period']} gait")
    unit = "" if data.unit in ("-", "") else f" [{data.unit}]"
    if data.curves:
        c0 = data.curves[0]
        u2 = "" if c0["unit2"] in ("-", "") else f" [{c0['unit2']}]"
        ax.set_xlabel(f"{c0['path2']}{u2}")
    ax.set_ylabel(f"{data.path}{unit}")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    if title:
        ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def cost_of_transport_figure(data, title: str = ""):
    """Cost of transport against speed along every branch of a loaded continuation artifact
    that holds gait measures (``branches[i]["gait"]``), coloured by the continued field;
    stable points solid, unstable hollow.  None when no branch has them."""
    import matplotlib.pyplot as plt

    branches = [b for b in data.branches if b.get("gait")]
    if not branches:
        return None
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    sc = None
    for b in branches:
        v, c, st = b["gait"]["speed"], b["gait"]["cost_of_transport"], b["stable"]
        ax.plot(v, c, "-", color="0.6", lw=0.8)
        sc = ax.scatter(v[st], c[st], c=b["param"][st], s=18, cmap="viridis",
                        label=f"period {b['period']}, stable")
        if (~st).any():
            ax.scatter(v[~st], c[~st], facecolors="none", edgecolors="k", s=18,
                       label=f"period {b['period']}, unstable")
    if sc is not None:
        fig.colorbar(sc, ax=ax, label=f"{data.path} [{data.unit}]")
    ax.set_xlabel("speed [m/s]")
    ax.set_ylabel("cost of transport [-]")
    ax.set_title(title or "cost of transport along the branch")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
