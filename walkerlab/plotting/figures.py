"""The paper's figures 7-10, stick diagrams (Figs. 2, 6) and the work-precision diagram.

Figures iterate over the named coordinates and points a trajectory has, so any walker
(compass gait, kneed, with a torso) is drawn without knowing its state size.

Every function takes data loaded from artifacts (:class:`NamedTrajectory`, dicts of arrays)
keyed by a *model label* (``"ideal (rigid)"``, ``"contact"``) and returns a matplotlib
Figure; :func:`save` writes it as PNG and SVG.  Legs are addressed by name.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from walkerlab.io.trajectory import NamedTrajectory

LEG_COLORS = ["tab:blue", "tab:red", "tab:green", "tab:purple"]
MODEL_STYLES = ["-", "--", ":", "-."]


def save(fig, folder: Path, stem: str) -> list[Path]:
    """Write ``stem.png`` (150 dpi) and ``stem.svg`` into ``folder``; close the figure.

    Each file is written atomically (temporary name, then rename; mode 0644): an
    interrupted save leaves the previous figure or none, never a truncated file.

    Raises
    ------
    walkerlab.io.artifacts.ArtifactError
        The folder cannot be written (one line).
    """
    from walkerlab.io.artifacts import atomic_write

    folder = Path(folder)
    out = []
    try:
        # the tight bounding box (what bbox_inches="tight" finds: a tick and text layout
        # pass as long as a draw) once for both files instead of once per file; the layout
        # engine (constrained_layout) must have run first, else the box is the pre-layout
        # one and crops tick labels and colorbars
        fig.draw_without_rendering()
        bbox = fig.get_tightbbox(fig.canvas.get_renderer()).padded(
            matplotlib.rcParams["savefig.pad_inches"])
        for ext in ("png", "svg"):
            p = folder / f"{stem}.{ext}"
            atomic_write(p, lambda fh, ext=ext: fig.savefig(fh, format=ext, dpi=150,
                                                            bbox_inches=bbox))
            out.append(p)
    finally:
        plt.close(fig)
    return out


def _legend(ax, **kw):
    h, lab = ax.get_legend_handles_labels()
    if h:
        ax.legend(fontsize=8, **kw)


def _coordinate_styles(names: list[str], model_index: int = 0) -> dict[str, dict]:
    """Colour per leg (first word of the name: ``leg1``, ``torso``), line style per part of
    that leg (``leg1_thigh`` solid, ``leg1_shank`` dashed) shifted by the model index, so
    the parts of one leg stay distinguishable where they overlap (a locked knee)."""
    stems = list(dict.fromkeys(n.rsplit("_", 1)[0] for n in names))
    owners = list(dict.fromkeys(st.split("_", 1)[0] for st in stems))
    out = {}
    for n in names:
        st = n.rsplit("_", 1)[0]
        owner = st.split("_", 1)[0]
        part = [x for x in stems if x.split("_", 1)[0] == owner].index(st)
        out[n] = dict(color=LEG_COLORS[owners.index(owner) % len(LEG_COLORS)],
                      ls=MODEL_STYLES[(model_index + part) % len(MODEL_STYLES)])
    return out


def fig7_angles_rates(trajs: dict[str, NamedTrajectory], title: str = "walking"):
    """Fig. 7: every named angle [rad] (a) and rate [rad/s] (b) over time, every model."""
    fig, axes = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for mi, (label, tr) in enumerate(trajs.items()):
        sty = _coordinate_styles(list(tr.coordinates), mi)
        for ax, names in zip(axes, (tr.angle_names(), tr.rate_names())):
            for n in names:
                ax.plot(tr.time, tr.coordinates[n], lw=1.2,
                        label=f"{n.rsplit('_', 1)[0]} - {label}", **sty[n])
    axes[0].set_ylabel("angle from vertical [rad]")
    axes[1].set_ylabel("angular rate [rad/s]")
    axes[1].set_xlabel("time [s]")
    axes[0].set_title("(a) angles")
    axes[1].set_title("(b) angular rates")
    for ax in axes:
        ax.grid(alpha=0.3)
    h, lab = axes[0].get_legend_handles_labels()
    fig.legend(h, lab, loc="lower center", ncol=min(4, len(h)), fontsize=8)
    fig.subplots_adjust(bottom=0.16 + 0.03 * ((len(h) - 1) // 4), hspace=0.3)
    fig.suptitle(f"Fig. 7 - {title}, angles and rates")
    return fig


def fig8_errors(time: np.ndarray, errors: dict[str, np.ndarray], units: dict[str, str],
                label: str):
    """Fig. 8: error between two models (contact - ideal) of every angle [rad] and rate [rad/s]."""
    fig, axes = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    sty = _coordinate_styles(list(errors))
    for n, e in errors.items():
        ax = axes[0] if units[n] == "rad" else axes[1]
        ax.plot(time, e, label=n.rsplit("_", 1)[0], lw=1, **sty[n])
    axes[0].set_ylabel("angle error [rad]")
    axes[1].set_ylabel("rate error [rad/s]")
    axes[1].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
        _legend(ax)
    fig.suptitle(f"Fig. 8 - error {label}")
    return fig


def fig9_limit_cycle(trajs: dict[str, NamedTrajectory]):
    """Fig. 9: limit cycles in the phase plane, rate [rad/s] vs angle [rad], per coordinate."""
    pairs = next(iter(trajs.values())).phase_pairs()
    ncol = min(3, len(pairs))
    nrow = -(-len(pairs) // ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5 * ncol, 4.5 * nrow), squeeze=False,
                             layout="constrained")
    for mi, (label, tr) in enumerate(trajs.items()):
        for k, (a, r) in enumerate(pairs):
            if a in tr.coordinates and r in tr.coordinates:
                axes.flat[k].plot(tr.coordinates[a], tr.coordinates[r], ls=MODEL_STYLES[mi % 4],
                                  color=LEG_COLORS[mi % 4], lw=1, label=label)
    for k, (a, r) in enumerate(pairs):
        ax = axes.flat[k]
        ax.set_xlabel(f"{a} [rad]")
        ax.set_ylabel(f"{r} [rad/s]")
        ax.set_title(a.removesuffix("_angle"))
        ax.grid(alpha=0.3)
        _legend(ax)
    for ax in list(axes.flat)[len(pairs):]:
        ax.set_visible(False)
    fig.suptitle("Fig. 9 - limit cycles in the phase plane")
    return fig


def fig10_energy(trajs: dict[str, NamedTrajectory]):
    """Fig. 10: kinetic, potential and total mechanical energy [J] over time."""
    fig, axes = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True)
    for mi, (label, tr) in enumerate(trajs.items()):
        kw = dict(ls=MODEL_STYLES[mi % 4], color=LEG_COLORS[mi % 4], lw=1.2, label=label)
        axes[0].plot(tr.time, tr.kinetic, **kw)
        axes[1].plot(tr.time, tr.potential, **kw)
        axes[2].plot(tr.time, tr.total, **kw)
    for ax, name in zip(axes, ("kinetic", "potential", "total mechanical")):
        ax.set_ylabel(f"{name} energy [J]")
        ax.grid(alpha=0.3)
        _legend(ax)
    axes[2].set_xlabel("time [s]")
    fig.suptitle("Fig. 10 - energies (potential from the first stance foot's height)")
    return fig


def _chains(tr: NamedTrajectory) -> list[tuple[str, list[str]]]:
    """Point chains to draw as sticks: for each leg, hip -> its points (ordered by distance
    from the hip at the first sample) -> its foot; other points hang from the hip."""
    hip = tr.points["hip"]
    out = []
    used = {"hip"}
    for leg in tr.legs:
        names = [n for n in tr.points if n.startswith(leg + "_") and not n.endswith("_mass")
                 and not n.endswith("_com")]
        if any(n.endswith("_contact") for n in names):  # round feet: end at the contact,
            names = [n for n in names if not n.endswith("_foot")]  # not the reference point
        names.sort(key=lambda n: (n.endswith("_foot"), float(np.hypot(*(tr.points[n][:, 0]
                                                                          - hip[:, 0])))))
        used.update(n for n in tr.points if n.startswith(leg + "_"))
        out.append((leg, ["hip", *names]))
    for n in tr.points:
        if n not in used and not n.endswith(("_mass", "_com")) and not n.startswith(
                ("stance_", "swing_")):
            out.append((n, ["hip", n]))
    return out


def stick_diagram(tr: NamedTrajectory, label: str, n_snapshots: int = 14,
                  slope_rad: float | None = None):
    """Stick diagram of the first gait cycle (two steps), as the paper's Figs. 2 and 6.

    Draws whatever named points the walker has: per leg a chain hip -> knee/shank points ->
    foot (sorted by distance from the hip), other points (torso ...) from the hip; point
    masses and centres of mass (``*_mass``, ``*_com``) as dots.
    """
    steps = np.unique(tr.step_index)
    sel = np.isin(tr.step_index, steps[:2])
    idx = np.flatnonzero(sel)
    picks = idx[np.linspace(0, idx.size - 1, n_snapshots).astype(int)]
    fig, ax = plt.subplots(figsize=(10, 3.8))
    cmap = plt.get_cmap("viridis")
    hip = tr.points["hip"]
    chains = _chains(tr)
    dots = [n for n in tr.points if n.endswith(("_mass", "_com"))]
    for j, i in enumerate(picks):
        c = cmap(j / max(1, len(picks) - 1))
        for k, (_owner, chain) in enumerate(chains):
            xy = np.array([tr.points[n][:, i] for n in chain])
            ax.plot(xy[:, 0], xy[:, 1], color=c, lw=2.2 if k == 0 else 1.2)
        for n in dots:
            ax.plot(*tr.points[n][:, i], ".", color=c, ms=4)
        ax.plot(hip[0, i], hip[1, i], "o", color=c, ms=6)
    xs = np.array([hip[0, idx].min() - 0.4, hip[0, idx].max() + 0.4])
    if slope_rad is not None:
        ax.plot(xs, -np.tan(slope_rad) * xs, color="k", lw=1)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m] (downhill)")
    ax.set_ylabel("y [m]")
    ax.set_title(f"stick diagram, one gait cycle - {label} (thick: {tr.legs[0]}; "
                 "colour: time)")
    ax.grid(alpha=0.3)
    return fig


def work_precision(rows: dict[str, dict[str, np.ndarray]], title: str, pareto: list | None = None):
    """Work-precision diagram: error vs wall time (log-log), one line per method."""
    fig, ax = plt.subplots(figsize=(7, 5))
    for method, d in rows.items():
        ok = np.isfinite(d["error"]) & (d["error"] > 0)
        ax.loglog(d["time"][ok], d["error"][ok], "o-", label=method, ms=4)
        for t, e, tol in zip(d["time"][ok], d["error"][ok], d["rtol"][ok]):
            ax.annotate(f"{tol:.0e}", (t, e), fontsize=6, alpha=0.6)
    if pareto:
        pt = np.array([(p["time"], p["error"]) for p in pareto])
        ax.loglog(pt[:, 0], pt[:, 1], "k--", lw=1, label="Pareto front")
    ax.set_xlabel("wall time (median of repeats) [s]")
    ax.set_ylabel("max state error vs reference [rad, rad/s]")
    ax.set_title(title)
    ax.grid(alpha=0.3, which="both")
    _legend(ax)
    return fig
