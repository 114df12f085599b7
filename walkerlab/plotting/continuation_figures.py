"""Figures of a continuation artifact (:mod:`walkerlab.io.schemas.continuation`), drawn from
the loaded data only.

- :func:`continuation_figure`: the branches (stance-leg angle just after each of the ``k``
  heel strikes of a period-``k`` orbit) against the parameter, stable (max |Floquet
  multiplier| < 1, the line cut where it crosses 1) solid, unstable dashed, period 1/2/4 in
  colours; special points marked and labelled (inside the axes, clear of the markers); a
  branch of one point drawn as a marker; the steady states of a brute-force
  ``bifurcation`` artifact over the same field overlaid as dots; below, the largest
  |Floquet multiplier| of each branch.  Legends sit outside the axes, so they never cover
  data.
- :func:`two_parameter_figure`: fold / period-doubling curves in the plane of two fields.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from walkerlab.units import per_map

__all__ = ["continuation_figure", "two_parameter_figure", "stability_pieces"]

PERIOD_COLORS = {1: "tab:blue", 2: "tab:orange", 4: "tab:green", 8: "tab:purple"}
MARKERS = {"fold": ("s", "tab:red", "F"), "branch_point": ("^", "tab:red", "BP"),
           "period_doubling": ("o", "tab:red", "PD"),
           "neimark_sacker": ("D", "tab:brown", "NS"), "branch_end": ("X", "k", "end")}


def _y(data, states: dict) -> tuple[np.ndarray, str]:
    name = "stance_angle" if "stance_angle" in data.state_names else data.state_names[0]
    return np.degrees(np.asarray(states[name], float)), f"{name.replace('_', ' ')} just " \
        "after heel strike [deg]"


def stability_pieces(p: np.ndarray, ys: np.ndarray, mmax: np.ndarray):
    """A branch cut where its largest |Floquet multiplier| crosses 1: pieces ``(p, ys, mmax,
    stable)``, stable exactly where ``mmax < 1``; the crossing (linear in ``mmax`` between
    the two points that straddle it) ends one piece and starts the next, so the pieces
    meet and no stable line is drawn where |multiplier| > 1.

    Parameters
    ----------
    p : ndarray (N,)
        Parameter along the branch.
    ys : ndarray (N, k)
        The plotted state at each of the ``k`` heel strikes.
    mmax : ndarray (N,)
        Largest |Floquet multiplier| [-].
    """
    stable = mmax < 1.0
    pieces, start = [], (p[:1], ys[:1], mmax[:1])
    for i in range(1, p.size):
        if stable[i] == stable[i - 1]:
            start = tuple(np.concatenate([a, b[i:i + 1]]) for a, b in zip(start, (p, ys, mmax)))
            continue
        t = (1.0 - mmax[i - 1]) / (mmax[i] - mmax[i - 1]) if mmax[i] != mmax[i - 1] else 0.5
        t = float(np.clip(t, 0.0, 1.0))
        cross = (p[i - 1:i] + t * (p[i:i + 1] - p[i - 1:i]),
                 ys[i - 1:i] + t * (ys[i:i + 1] - ys[i - 1:i]), np.ones(1))
        pieces.append((*(np.concatenate([a, b]) for a, b in zip(start, cross)),
                       bool(stable[i - 1])))
        start = tuple(np.concatenate([c, b[i:i + 1]]) for c, b in zip(cross, (p, ys, mmax)))
    pieces.append((*start, bool(stable[-1])))
    return pieces


def _label_offset(ax, x: float, y: float, i: int) -> tuple[tuple[float, float], str, str]:
    """Where a special point's label goes (offset points, vertical and horizontal
    alignment): above a point in the lower half of the axes and below one in the upper
    half, right of a point in the left half and left of one in the right half, so it stays
    inside the axes; staggered by ``i`` so neighbouring labels do not overlap; clear of the
    marker."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    up, right = y < 0.5 * (y0 + y1), x < 0.5 * (x0 + x1)
    d = 9 + 11 * (i % 3)
    return ((7 if right else -7, d if up else -d), "bottom" if up else "top",
            "left" if right else "right")

def _finished(fig, ax, title: str):
    """``fig`` with ``ax``'s legend outside the axes on the right, ``title`` (if any) and a
    tight layout."""
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    if title:
        ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def _draw_branches(ax1, ax2, data, seen: set) -> str:
    """Each branch of ``data`` (a ContinuationData) in its period's colour, solid where
    stable and dashed where not: the state at every heel strike of the orbit on ``ax1``,
    the largest |Floquet multiplier| on ``ax2``; legend labels once (``seen``).  Returns the
    state axis' label ("" without branches)."""
    ylabel = ""
    for b in data.branches:
        k, p = b["period"], np.asarray(b["param"], float)
        ys, ylabel = _y(data, b.get("orbit", b["states"]))
        ys = ys.reshape(p.size, -1)
        mmax = np.max(np.abs(b["multipliers"]), axis=1)
        c = PERIOD_COLORS.get(k, "tab:gray")
        for pp, yy, mm, st in stability_pieces(p, ys, mmax):
            key = f"period {k}, {'stable' if st else 'unstable'}"
            lab = None if key in seen else key
            seen.add(key)
            ls = "-" if st else "--"
            if pp.size == 1:
                ax1.plot(pp, yy[:, 0], "o", color=c, mfc=c if st else "w", label=lab)
                ax2.plot(pp, mm, "o", color=c, mfc=c if st else "w")
            else:  # every heel strike of the period-k orbit: k curves
                for h in range(yy.shape[1]):
                    ax1.plot(pp, yy[:, h], ls, color=c, lw=1.4,
                             label=lab if h == 0 else None, zorder=3)
                ax2.plot(pp, mm, ls, color=c, lw=1.2, zorder=3)
    return ylabel


def _draw_special_points(ax1, ax2, data, seen: set) -> None:
    """The special points of ``data`` (folds, period doublings, Neimark-Sacker points,
    branch ends) marked on ``ax1`` and labelled inside the axes (:func:`_label_offset`),
    a dotted line each on ``ax2``; legend labels once (``seen``)."""
    sp = data.special
    labels = []
    for i, kind in enumerate(sp.get("kind", [])):
        mk, col, short = MARKERS.get(str(kind), ("*", "k", str(kind)))
        y, _ = _y(data, {n: np.atleast_1d(v)[i:i + 1] for n, v in sp["states"].items()})
        pv = float(sp["param"][i])
        lab = {"fold": "fold (multiplier +1, turning back)",
               "branch_point": "branch point (multiplier +1, passing through)",
               "period_doubling": "period doubling (-1)",
               "neimark_sacker": "Neimark-Sacker (|complex pair| 1)",
               "branch_end": "branch end"}.get(str(kind), str(kind))
        ax1.plot([pv], y, mk, color=col, ms=7, mfc="none", mew=1.6, zorder=5,
                 label=None if lab in seen else lab)
        seen.add(lab)
        if np.isfinite(y[0]):
            labels.append((f"{short}{int(sp['period'][i])} {pv:.5g}", pv, y[0], col))
        ax2.axvline(pv, color=col, lw=0.5, ls=":")
    for i, (text, pv, y0, col) in enumerate(labels):  # after the limits are known
        off, va, ha = _label_offset(ax1, pv, y0, i)
        ax1.annotate(text, (pv, y0), textcoords="offset points", xytext=off, fontsize=7,
                     color=col, va=va, ha=ha, zorder=6, annotation_clip=True,
                     bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                           "alpha": 0.85},
                     arrowprops={"arrowstyle": "-", "color": col, "lw": 0.5})


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
        from walkerlab.studies.bifurcation import parameter_values  # light

        s = parameter_values(brute)[0]
        st = np.asarray(brute["steady_state/stance_angle_after_impact"], float)
        ss, yy = np.repeat(s, st.shape[1]), st.ravel()
        m = np.isfinite(yy)
        ax1.plot(ss[m], yy[m], ".", ms=2.0, color="0.35", zorder=1,
                 label="steady state, simulated (bifurcation)")
    seen: set = set()
    ylabel = _draw_branches(ax1, ax2, data, seen)
    ax1.margins(x=0.04, y=0.15)
    _draw_special_points(ax1, ax2, data, seen)
    ax1.axvline(data.start, color="0.5", lw=0.6, ls="-.", label="start (the scene's gait)")
    ax1.set_ylabel(ylabel if data.branches else "")
    ax2.axhline(1.0, color="0.5", lw=0.8)
    big = [np.max(np.abs(b["multipliers"])) for b in data.branches if len(b["param"])]
    if big and max(big) > 20:  # an unstable branch far out: log scale keeps |mu| = 1 visible
        ax2.set_yscale("log")
    per = per_map(getattr(data, "steps_per_map", 0))  # the artifact's map: step or stride
    ax2.set_ylabel(f"max |Floquet multiplier|{' ' + per if per else ''} [-]")
    ax2.set_xlabel(f"{data.path}{unit}")
    return _finished(fig, ax1, title)


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
    return _finished(fig, ax, title)


def cost_of_transport_figure(data, title: str = ""):
    """Cost of transport against speed along every branch of a loaded continuation artifact
    that holds gait measures (``branches[i]["gait"]``), coloured by the continued field;
    stable points solid, unstable hollow.  None when no branch has a finite pair of them
    (a walker without a ledger: no empty figure)."""
    import matplotlib.pyplot as plt

    def finite(b):
        return np.any(np.isfinite(b["gait"]["speed"]) & np.isfinite(
            b["gait"]["cost_of_transport"]))

    branches = [b for b in data.branches if b.get("gait") and finite(b)]
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
