"""Figures of sweeps, drawn from loaded artifacts only.

- :func:`bifurcation_figure`: steady-state inter-leg angle at heel strike vs the slope or
  any scene field (the period-doubling cascade), the period-1 branch, and its Floquet
  multipliers with the -1 line; the axis named by the field and its unit.
- :func:`stability_map_figure`: outcome per grid point of a 2-D sweep (categorical map) and
  the run time per point.
- :func:`restitution_figure`: drop-test restitution against stiffness, both families.
- :func:`save`: PNG (150 dpi) + SVG.

The contact gait's stability map (a study of its own, not a sweep's artifact):
:mod:`walkerlab.plotting.gait_map_figure`.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap

from walkerlab.config.contact import CONTACT_QUANTITIES
from walkerlab.io.schemas.bifurcation import SLOPE_PATH
from walkerlab.plotting.figures import save  # noqa: F401  (re-exported for callers)
from walkerlab.studies.bifurcation import fall_onset, onset_value, parameter_values
from walkerlab.studies.outcomes import OUTCOMES
from walkerlab.units import Units, per_map

OUTCOME_COLORS = {
    "ok": "#2ca02c", "no_fixed_point": "#7f7f7f", "fall": "#d62728", "scuff": "#9467bd",
    "slip": "#ff7f0e", "bounce": "#e7ba52", "solver_failure": "#000000", "max_steps": "#17becf",
    "invalid_config": "#c7c7c7", "error": "#8c564b", "trip": "#bcbd22", "time_limit": "#aec7e8",
    "airborne": "#f7b6d2", "no_heel_strike": "#dbdb8d",
}
OUTCOME_LABELS = {"ok": "walks (ok)", "fall": "falls", "slip": "slips", "bounce": "bounces"}


def bifurcation_figure(data: dict, title: str = ""):
    """Bifurcation diagram from :func:`walkerlab.io.schemas.bifurcation.load_bifurcation` data.

    Parameters
    ----------
    data : dict
        Keys ``slope`` (n,) [deg] (or, with ``parameter_path`` and ``parameter_unit``, the
        field's dotted path), ``steady_state/interleg_angle`` (n, k) [deg],
        ``fixed_point/interleg_angle`` (n,) [deg], ``floquet/real``, ``floquet/imag``
        (n, 2m), ``onset/onset_slope`` [deg] (``onset/onset_value`` for another field).

    Returns
    -------
    matplotlib.figure.Figure
    """
    s, path, unit = parameter_values(data)
    xlabel = "slope φ [deg]" if path == SLOPE_PATH else f"{path} [{unit}]"

    def at(v: float, fmt: str) -> str:  # a grid value with its unit, for the legend
        return f"{v:{fmt}}°" if path == SLOPE_PATH else f"{v:.4g} {unit}".removesuffix(" -")
    il = np.asarray(data["steady_state/interleg_angle"], float)
    fp_il = np.asarray(data["fixed_point/interleg_angle"], float)
    mult = np.asarray(data["floquet/real"]) + 1j * np.asarray(data["floquet/imag"])
    stable = np.max(np.abs(mult), axis=1) < 1
    onset = onset_value(data)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9.5, 7), sharex=True,
                                   gridspec_kw={"height_ratios": [3, 2]})
    ss, yy = np.repeat(s, il.shape[1]), il.ravel()
    m = np.isfinite(yy)
    # on top of the fixed-point line: a period-1 steady state sits on it and stays visible
    ax1.plot(ss[m], yy[m], ".", ms=2.5, color="k", zorder=4,
             label="steady state (last heel strikes)")
    # markers on every fixed point: a single stable or unstable point (no neighbour to draw
    # a line to) is drawn too
    ax1.plot(np.where(stable, s, np.nan), np.where(stable, fp_il, np.nan), "-", color="tab:blue",
             lw=1.2, marker="o", ms=2.5, label="period-1 fixed point, stable")
    ax1.plot(np.where(~stable, s, np.nan), np.where(~stable, fp_il, np.nan), "--",
             color="tab:blue", lw=1.0, marker="o", ms=3, mfc="w",
             label="period-1 fixed point, unstable")
    ax1.set_ylabel("inter-leg angle at heel strike [deg]")
    for k, ax in enumerate((ax1, ax2)):
        if np.isfinite(onset):  # named in the legend: a text label ran over the frame
            ax.axvline(onset, color="tab:red", lw=0.8, ls=":",
                       label=f"period doubling at {at(onset, '.3f')}" if k == 0 else None)
    falls = fall_onset(data)
    if np.isfinite(falls):
        half = 0.5 * float(np.min(np.diff(s))) if s.size > 1 else 0.0
        for k, ax in enumerate((ax1, ax2)):
            ax.axvspan(falls - half, s.max() + half, color="0.85", hatch="//", ec="0.6", lw=0,
                       zorder=0, label=f"walker falls (no steady gait) from {at(falls, '.3g')}"
                       if k == 0 else None)
    # legends outside the axes: they never cover data
    ax1.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    if title:
        ax1.set_title(title)
    for k in range(mult.shape[1]):
        ax2.plot(s, mult[:, k].real, ".", ms=3, label=f"Re multiplier {k}")
    ax2.plot(s, np.max(np.abs(mult), axis=1), "-", color="0.4", lw=1, label="max |multiplier|")
    ax2.axhline(-1.0, color="tab:red", lw=0.8)
    ax2.axhline(1.0, color="0.6", lw=0.6)
    ax2.set_xlabel(xlabel)
    per = per_map(data.get("steps_per_map"))  # the artifact's map: step or stride
    ax2.set_ylabel(f"Floquet multiplier{' ' + per if per else ''} [-]")
    ax2.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    fig.tight_layout()
    return fig


def stability_map_figure(sweep: dict, x_path: str | None = None, y_path: str | None = None,
                         title: str = "", log_y: bool | None = None,
                         annotate: str | None = "heel_strikes"):
    """Outcome map and run time per point of a 2-D sweep (from :func:`load_sweep`).

    Parameters
    ----------
    sweep : dict
        :func:`walkerlab.io.sweep_store.load_sweep` output; 2 axes.
    x_path, y_path : str, optional
        Which axis is drawn along x / y (default: second axis on x, first on y).
    log_y : bool, optional
        Logarithmic y axis (default: when the y values span more than a factor 100).
    annotate : str, optional
        Numeric column written into each cell of the outcome map (default: heel strikes
        before the run ended), if the sweep has it.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        The sweep does not have 2 axes.
    """
    axes = dict(sweep["axes"])
    paths = [p for p, _ in sweep["axes"]]
    if len(paths) != 2:
        raise ValueError("stability map needs a 2-D sweep")
    x_path = x_path or paths[1]
    y_path = y_path or [p for p in paths if p != x_path][0]
    xv, yv = np.asarray(axes[x_path], float), np.asarray(axes[y_path], float)
    pts = sweep["points"]
    code = np.full((yv.size, xv.size), np.nan)
    wall = np.full((yv.size, xv.size), np.nan)
    note = np.full((yv.size, xv.size), np.nan)
    for k in range(pts["index"].size):
        i = int(np.argmin(np.abs(yv - pts[f"param/{y_path}"][k])))
        j = int(np.argmin(np.abs(xv - pts[f"param/{x_path}"][k])))
        code[i, j] = OUTCOMES.index(pts["outcome"][k])
        wall[i, j] = pts["wall_time_s"][k]
        if annotate and annotate in pts:
            note[i, j] = pts[annotate][k]
    if log_y is None:
        log_y = yv.min() > 0 and yv.max() / yv.min() > 100
    cmap = ListedColormap([OUTCOME_COLORS[o] for o in OUTCOMES])
    norm = BoundaryNorm(np.arange(len(OUTCOMES) + 1) - 0.5, cmap.N)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    xi, yi = np.arange(xv.size), np.arange(yv.size)
    a1.pcolormesh(xi, yi, code, cmap=cmap, norm=norm, shading="nearest")
    present = [o for o in OUTCOMES if np.any(code == OUTCOMES.index(o))]
    for o in present:
        a1.plot([], [], "s", color=OUTCOME_COLORS[o], label=OUTCOME_LABELS.get(o, o))
    for (i, j), v in np.ndenumerate(note):
        if np.isfinite(v):
            a1.text(j, i, f"{v:g}", ha="center", va="center", fontsize=6, color="w")
    if annotate and np.isfinite(note).any():
        a1.plot([], [], " ", label=f"cell text: {annotate}")
    a1.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    im = a2.pcolormesh(xi, yi, wall, shading="nearest", cmap="viridis")
    fig.colorbar(im, ax=a2, label="wall time per point [s]")
    ylab = _label(y_path)
    for ax in (a1, a2):
        ax.set_xticks(xi, [f"{v:g}" for v in xv], fontsize=7)
        ax.set_yticks(yi, [f"{v:.3g}" for v in yv], fontsize=7)
        ax.set_xlabel(_label(x_path))
        ax.set_ylabel(ylab + (" (log grid)" if log_y else ""))
    a1.set_title(title or "outcome per point", fontsize=9)
    a2.set_title("run time per point", fontsize=9)
    fig.tight_layout()
    return fig


_UNITS = {"slope.angle_deg": "slope φ [deg]", "slope.angle_rad": "slope φ [rad]",
          **{f"contact.{name}": f"contact stiffness k [{unit}]"
             for name, unit in CONTACT_QUANTITIES["stiffness"].values()},
          "contact.mu_static": "static friction μs [-]",
          "contact.mu_dynamic": "dynamic friction μd [-]"}


def _label(path: str) -> str:
    return _UNITS.get(path, path)


def restitution_figure(stiffness, curves: dict, unit: str = "N/mm^e", k_paper=None,
                       mass_kg: float = 20.0, speed_m_per_s: float = 0.3,
                       units: Units | None = None):
    """Drop-test coefficient of restitution against stiffness for each family.

    Parameters
    ----------
    stiffness : ndarray (n,)
        Stiffness values (scene units).
    curves : dict
        ``{family: restitution (n,)}``.
    unit : str
        Label of the stiffness unit.
    k_paper : float, optional
        Stiffness of the scene, marked with a vertical line.
    mass_kg, speed_m_per_s : float
        The dropped mass (the walker's) [kg] and its speed at first contact [m/s].
    units : Units, optional
        The scene's unit labels (default SI).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = plt.subplots(figsize=(5.5, 4.2), layout="constrained")
    labels = {"paper": "paper family (damping, dmax fixed)",
              "rigid_limit": "rigid-limit family (c ~ k^(1/(e+1)), dmax ~ k^(-1/(e+1)))"}
    for fam, e in curves.items():
        ax.semilogx(stiffness, e, "o-", label=labels.get(fam, fam), ms=4)
    if k_paper is not None:
        ax.axvline(k_paper, color="0.5", ls=":", lw=1, label="scene stiffness")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel(f"stiffness k [{unit}]")
    ax.set_ylabel("coefficient of restitution [-]")
    ax.set_ylim(-0.03, 1.03)
    u = units or Units()
    ax.set_title(f"drop test: {mass_kg:.3g} {u('kg')} at {speed_m_per_s:g} {u('m/s')} (rigid "
                 "plastic impact: 0)", fontsize=9)
    # below the axes: inside them the legend covered the scene's stiffness line
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", fontsize=8,
               ncol=1, frameon=False)
    return fig


_COLUMN_LABELS = {"max_abs_multiplier": "max |Floquet multiplier|\n(dashed: 1)",
                  "steps_completed": "steps completed", "heel_strikes": "heel strikes"}


def sweep_figure(data: dict, title: str = ""):
    """The main results of a sweep against its first swept field, from a loaded sweep
    (:func:`walkerlab.io.sweep_store.load_sweep`).

    One panel per main result column (:data:`walkerlab.report.sweep_text.MAIN_COLUMNS`);
    points that walk (outcome ``ok``) joined by a line, one line per value of the other
    swept fields; a point that does not walk is a cross at the panel's foot in its outcome's
    colour (legend).  Axis labels carry the scene's units.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from walkerlab.report.sweep_text import column_unit, main_columns
    from walkerlab.units import field_unit

    units = Units(str(data["attrs"].get("scene_units", "SI")))
    pts = data["points"]
    (xpath, _), *others = data["axes"]
    x = np.asarray(pts[f"param/{xpath}"])
    numeric = x.dtype.kind in "fi"
    if not numeric:
        cats = list(dict.fromkeys(x.tolist()))
        x = np.array([cats.index(v) for v in x], float)
    outcome = np.asarray(pts["outcome"]).astype(str)
    ok = outcome == "ok"
    groups = [tuple(str(pts[f"param/{p}"][i]) for p, _ in others) for i in range(x.size)]
    cols = main_columns(data)
    fig, axes = plt.subplots(max(len(cols), 1), 1, figsize=(6.4, 1.2 + 1.9 * max(len(cols), 1)),
                             sharex=True, constrained_layout=True, squeeze=False)
    xunit = units(field_unit(xpath) or "-")
    xlabel = _label(xpath) if xpath in _UNITS else f"{xpath} [{xunit}]"
    for ax, c in zip(axes[:, 0], cols):
        y = np.asarray(pts[c], float)
        for gi, g in enumerate(dict.fromkeys(groups)):
            sel = ok & np.array([gg == g for gg in groups])
            o = np.argsort(x[sel], kind="stable")
            lab = ", ".join(f"{p} = {v}" for (p, _), v in zip(others, g)) or None
            ax.plot(x[sel][o], y[sel][o], "o-", ms=3, lw=1.2, color=f"C{gi % 10}", label=lab)
        unit = column_unit(c, units)
        name = _COLUMN_LABELS.get(c) or c.removesuffix("_mm").removesuffix("_s") \
            .removesuffix("_m_per_s").replace("_", " ")
        if c == "max_abs_multiplier" and per_map(data["attrs"].get("steps_per_map")):
            # the map every point's multipliers are of (the sweep's one: a stride if any
            # point's is); an artifact without the attribute says nothing it does not know
            name = name.replace("|\n", f"|\n{per_map(data['attrs']['steps_per_map'])} ")
        ax.set_ylabel(name + (f" [{unit}]" if unit else ""))
        if c == "max_abs_multiplier":
            ax.axhline(1.0, color="0.4", ls="--", lw=0.8)
        ax.grid(alpha=0.3)
        for kind in dict.fromkeys(outcome[~ok]):
            sel = outcome == kind
            ax.plot(x[sel], np.zeros(sel.sum()), "x", transform=ax.get_xaxis_transform(),
                    color=OUTCOME_COLORS.get(kind, "k"), ms=6, clip_on=False,
                    label=OUTCOME_LABELS.get(kind, kind))
    ax0 = axes[0, 0]
    if any(h.get_label() and not h.get_label().startswith("_")
           for h in ax0.get_lines()):
        ax0.legend(fontsize=8, loc="best")
    last = axes[-1, 0]
    last.set_xlabel(xlabel)
    if not numeric:
        last.set_xticks(range(len(cats)), cats)
    ok_n = int(ok.sum())
    fig.suptitle((title + "\n" if title else "")
                 + f"{data['attrs'].get('sweep_stage', '')} sweep: {ok_n} of {x.size} points "
                 "ok (crosses: the others, by outcome)", fontsize=10)
    return fig
