"""Stick diagrams (the paper's Figs. 2, 6): snapshots of a walker's links over a stride,
coloured by time, on the slope line and, for a contact run on patches, its ground patches.

The links are drawn as chains of named points (:func:`stick_diagram`): for each leg hip ->
its points -> its foot, a round foot as its arc (never a stub to the off-axis contact point);
any walker (compass gait, kneed, with a torso) is drawn without knowing its state size.
Takes a :class:`~walkerlab.io.trajectory.NamedTrajectory` loaded from an artifact and returns
a matplotlib Figure (:func:`walkerlab.plotting.figures.save` writes it; the module re-exports
:func:`stick_diagram` and :func:`draw_patches`).
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from walkerlab.io.trajectory import NamedTrajectory
from walkerlab.units import Units

SI_UNITS = Units()


def _chains(tr: NamedTrajectory) -> list[tuple[str, list[str]]]:
    """Point chains to draw as sticks: for each leg, hip -> its points (ordered by distance
    from the hip at the first sample) -> its foot; other points hang from the hip.  A round
    foot's leg ends at its arc centre (``<leg>_foot_centre``; the arc is drawn by
    :func:`_arc_feet`), not at the contact point, which lies off the leg axis."""
    hip = tr.points["hip"]
    out = []
    used = {"hip"}
    for leg in tr.legs:
        names = [n for n in tr.points if n.startswith(leg + "_") and not n.endswith("_mass")
                 and not n.endswith("_com")]
        if f"{leg}_foot_centre" in names:  # round feet: the leg axis ends at the arc centre
            names = [n for n in names if not n.endswith(("_foot", "_contact"))]
        names.sort(key=lambda n: (n.endswith(("_foot", "_foot_centre")),
                                  float(np.hypot(*(tr.points[n][:, 0] - hip[:, 0])))))
        used.update(n for n in tr.points if n.startswith(leg + "_"))
        out.append((leg, ["hip", *names]))
    for n in tr.points:
        if n not in used and not n.endswith(("_mass", "_com")) and not n.startswith(
                ("stance_", "swing_")):
            out.append((n, ["hip", n]))
    return out


#: half the opening of a drawn round foot's arc about the leg axis [rad]
ARC_HALF_ANGLE_RAD = np.radians(45.0)


def _arc_feet(tr: NamedTrajectory, i: int, n_pts: int = 25) -> list[np.ndarray]:
    """Round feet at sample ``i``, each a polyline (2, n_pts + 3): the leg axis continued from
    the arc centre to the arc, a break (NaN), then the arc of radius |contact - centre|
    opening ±:data:`ARC_HALF_ANGLE_RAD` about the leg axis (hip -> arc centre)."""
    arcs = []
    hip = tr.points["hip"][:, i]
    for leg in tr.legs:
        c, p = tr.points.get(f"{leg}_foot_centre"), tr.points.get(f"{leg}_contact")
        if c is None or p is None:
            continue
        r = float(np.hypot(*(p[:, i] - c[:, i])))
        axis = c[:, i] - hip
        a0 = np.arctan2(axis[1], axis[0])
        ang = a0 + np.linspace(-ARC_HALF_ANGLE_RAD, ARC_HALF_ANGLE_RAD, n_pts)
        arc = c[:, i, None] + r * np.vstack([np.cos(ang), np.sin(ang)])
        spoke = np.column_stack([c[:, i], arc[:, n_pts // 2], [np.nan, np.nan]])
        arcs.append(np.hstack([spoke, arc]))
    return arcs


def draw_patches(ax, terrain: dict, slope_rad: float, depth: float,
                 xlim: tuple[float, float] | None = None) -> None:
    """The checkerboard's ground patches (:func:`walkerlab.io.terrain.load_terrain`) as
    slabs under the slope line ``y = -x tan(phi)``: each leg's lane in its own shade (leg1
    light, leg2 dark), ``depth`` deep; patches outside ``xlim`` are left out."""
    from matplotlib.patches import Polygon

    c, s = np.cos(slope_rad), np.sin(slope_rad)
    w = float(terrain["half_width"])
    for k, (_leg, centres) in enumerate(sorted(terrain["lanes"].items())):
        for sc in np.asarray(centres, float):
            corners = np.array([[sc - w, 0.0], [sc + w, 0.0], [sc + w, -depth],
                                [sc - w, -depth]])  # along-slope, normal
            xy = np.column_stack([corners[:, 0] * c + corners[:, 1] * s,
                                  -corners[:, 0] * s + corners[:, 1] * c])
            if xlim is not None and (xy[:, 0].max() < xlim[0] or xy[:, 0].min() > xlim[1]):
                continue
            ax.add_patch(Polygon(xy, closed=True, lw=0.6, ec="0.25",
                                 fc=("0.8", "0.45")[k % 2], zorder=1))


def stick_diagram(tr: NamedTrajectory, label: str, n_snapshots: int = 14,
                  slope_rad: float | None = None, units: Units = SI_UNITS,
                  terrain: dict | None = None):
    """Stick diagram of the first gait cycle (two steps), as the paper's Figs. 2 and 6.

    Draws whatever named points the walker has: per leg a chain hip -> knee/shank points ->
    foot (sorted by distance from the hip), round feet as arcs about their centre, other
    points (torso ...) from the hip; point masses and centres of mass (``*_mass``,
    ``*_com``) as dots.  The snapshots' colour is the time, shown by a colour bar.
    ``terrain`` (the contact walker's checkerboard, :func:`walkerlab.io.terrain.
    load_terrain`): its ground patches drawn under the slope line (:func:`draw_patches`).
    A 3D walker's points are drawn in the sagittal plane (x, y).
    """
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    if any(len(p) > 2 for p in tr.points.values()):  # a 3D walker: its sagittal view
        from dataclasses import replace

        tr = replace(tr, points={k: np.asarray(v)[:2] for k, v in tr.points.items()})
    steps = np.unique(tr.step_index)
    sel = np.isin(tr.step_index, steps[:2])
    idx = np.flatnonzero(sel)
    picks = idx[np.linspace(0, idx.size - 1, n_snapshots).astype(int)]
    fig, ax = plt.subplots(figsize=(10, 3.8), layout="constrained")
    cmap = plt.get_cmap("viridis")
    norm = Normalize(float(tr.time[picks[0]]), float(tr.time[picks[-1]]))
    hip = tr.points["hip"]
    chains = _chains(tr)
    dots = [n for n in tr.points if n.endswith(("_mass", "_com"))]
    for i in picks:
        c = cmap(norm(float(tr.time[i])))
        for k, (_owner, chain) in enumerate(chains):
            xy = np.array([tr.points[n][:, i] for n in chain])
            ax.plot(xy[:, 0], xy[:, 1], color=c, lw=2.2 if k == 0 else 1.2)
        for k, arc in enumerate(_arc_feet(tr, i)):
            ax.plot(arc[0], arc[1], color=c, lw=2.2 if k == 0 else 1.2)
        for n in dots:
            ax.plot(*tr.points[n][:, i], ".", color=c, ms=4)
        ax.plot(hip[0, i], hip[1, i], "o", color=c, ms=6)
    xs = np.array([hip[0, idx].min() - 0.4, hip[0, idx].max() + 0.4])
    if slope_rad is not None:
        ax.plot(xs, -np.tan(slope_rad) * xs, color="k", lw=1)
        if terrain is not None and not terrain["continuous"]:
            draw_patches(ax, terrain, slope_rad, 0.04 * _hip_height(tr), tuple(xs))
            label += ", ground patches shaded by lane"
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [{units.length}] (downhill)")
    ax.set_ylabel(f"y [{units.length}]")
    ax.set_title(f"stick diagram, one gait cycle - {label} (thick: {tr.legs[0]})")
    ax.grid(alpha=0.3)
    fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.8,
                 label=f"time [{units.time}]")
    return fig


def _hip_height(tr: NamedTrajectory) -> float:
    """Largest hip-to-point distance at the first sample (about the leg length)."""
    hip = tr.points["hip"][:, 0]
    return max(float(np.hypot(*(p[:, 0] - hip))) for p in tr.points.values()) or 1.0
