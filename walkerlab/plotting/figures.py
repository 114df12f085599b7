"""The paper's figures 7-10 and the work-precision diagram; the stick diagrams (Figs. 2, 6)
are :mod:`walkerlab.plotting.stick` (re-exported here).

Figures iterate over the named coordinates and points a trajectory has, so any walker
(compass gait, kneed, with a torso) is drawn without knowing its state size.

Every function takes data loaded from artifacts (:class:`NamedTrajectory`, dicts of arrays)
keyed by a *model label* (``"ideal (rigid)"``, ``"contact"``) and returns a matplotlib
Figure; :func:`save` writes it as PNG and SVG.  Legs are addressed by name.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

from walkerlab.plotting.figure_cache import KEY_CHUNK
from walkerlab.walker.planes import out_of_plane

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from walkerlab.io.trajectory import NamedTrajectory
from walkerlab.plotting.stick import draw_patches, stick_diagram  # noqa: F401 (part of this API)
from walkerlab.units import Units

SI_UNITS = Units()

LEG_COLORS = ["tab:blue", "tab:red", "tab:green", "tab:purple"]
MODEL_STYLES = ["-", "--", ":", "-."]
#: colours of the links of each owner (leg1, leg2, a torso, ...), in :data:`PARTS` order;
#: every colour once, the first of each leg LEG_COLORS'
PART_COLORS = [("tab:blue", "tab:green", "tab:cyan", "navy"),
               ("tab:red", "tab:purple", "tab:pink", "maroon"),
               ("tab:olive", "tab:brown", "tab:gray", "darkgoldenrod"),
               ("tab:orange", "black", "teal", "darkkhaki")]
#: the links of a leg in colour order: thigh, shank, the whole leg (a straight leg's
#: ``<leg>_angle``, or a kneed leg's hip-to-foot angle beside its links), a foot; others
#: after them by name
PARTS = ("thigh", "shank", "", "foot")


def save(fig, folder: Path, stem: str, svg: bool = True, key: str | None = None
         ) -> list[Path]:
    """Write ``stem.png`` (150 dpi) and ``stem.svg`` into ``folder``; close the figure.
    ``svg`` False: the PNG alone (an earlier ``stem.svg`` is removed: it would show an
    older result).  ``key``: what the figure was drawn from, stored in the PNG (a text
    chunk, :mod:`walkerlab.plotting.figure_cache`).

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
        # one and crops tick labels and colorbars; a figure without one (laid out by
        # tight_layout, or not at all) gets the same box without that draw
        from matplotlib.layout_engine import PlaceHolderLayoutEngine

        if not isinstance(fig.get_layout_engine(), (type(None), PlaceHolderLayoutEngine)):
            fig.draw_without_rendering()
        bbox = fig.get_tightbbox(fig.canvas.get_renderer()).padded(
            matplotlib.rcParams["savefig.pad_inches"])
        if not svg:
            (folder / f"{stem}.svg").unlink(missing_ok=True)
        for ext in ("png", "svg") if svg else ("png",):
            p = folder / f"{stem}.{ext}"
            meta = {KEY_CHUNK: key} if key is not None and ext == "png" else None
            atomic_write(p, lambda fh, ext=ext, meta=meta: fig.savefig(
                fh, format=ext, dpi=150, bbox_inches=bbox, metadata=meta))
            out.append(p)
    finally:
        plt.close(fig)
    return out


def _legend(ax, **kw):
    h, lab = ax.get_legend_handles_labels()
    if h:
        ax.legend(fontsize=8, **kw)


def _owners(names) -> list[str]:
    """The owners (first word of a coordinate name: ``leg1``, ``leg2``, ``torso``) in sorted
    order, so a leg has the same colour in every model's trajectory whatever order the
    model lists its coordinates in (the rigid kneed walker lists the stance leg first)."""
    return sorted({n.split("_", 1)[0] for n in names})


def _part_rank(stem: str) -> tuple:
    """Where a link (``leg1_thigh``, ``leg1``, ``torso``) comes among its owner's links:
    :data:`PARTS` order, then by name."""
    part = stem.split("_", 1)[1] if "_" in stem else ""
    return (PARTS.index(part), "") if part in PARTS else (len(PARTS), part)


def _coordinate_styles(names, model_index: int = 0) -> dict[str, dict]:
    """One colour per link, whatever the view and its coordinates' order (``leg1_thigh``
    blue, ``leg1_shank`` green, a straight ``leg1`` blue; ``leg2``'s in reds; first word of
    the name: ``leg1``, ``torso``; :data:`PART_COLORS`), line style per model
    (``model_index``: ideal solid, contact dashed), so every curve is told apart by colour
    *and* the models by style, also where the parts of one leg overlap (a locked knee).
    Give ``names`` of every view of a figure: the links are ranked over them all."""
    stems = sorted({n.rsplit("_", 1)[0] for n in names},
                   key=lambda s: (s.split("_", 1)[0], _part_rank(s)))
    owners = _owners(stems)
    out = {}
    for n in names:
        st = n.rsplit("_", 1)[0]
        owner = st.split("_", 1)[0]
        part = [x for x in stems if x.split("_", 1)[0] == owner].index(st)
        k = owners.index(owner)  # past the palettes (a 3D walker's heading, lean, rolls):
        shades = PART_COLORS[k % len(PART_COLORS)]  # the next shade of a palette reused
        out[n] = dict(color=shades[(part + k // len(PART_COLORS)) % len(shades)],
                      ls=MODEL_STYLES[model_index % len(MODEL_STYLES)])
    return out


def fig7_angles_rates(trajs: dict[str, NamedTrajectory], title: str = "walking",
                      units: Units = SI_UNITS):
    """Fig. 7: every named angle [rad] (a) and rate [rad/s] (b) over time, every model
    (``units``: the scene's unit labels).  The coordinates that turn out of the sagittal
    plane (a walker in 3D: its lean and rolls, a wheel's heading;
    :func:`walkerlab.walker.planes.out_of_plane`, by name) get panels of their own
    beside them, (c) and (d): their few hundredths of a radian would be flat lines on the
    pitches' axes.  A planar walker's figure has the two panels alone."""

    every = [n for tr in trajs.values() for n in tr.coordinates]  # one colour per link
    lateral = any(out_of_plane(n) for n in every)
    ncol = 2 if lateral else 1
    fig, axes = plt.subplots(2, ncol, figsize=(8 * ncol, 6.4), sharex=True,
                             layout="constrained", squeeze=False)
    for mi, (label, tr) in enumerate(trajs.items()):
        sty = {n: s for n, s in _coordinate_styles(every, mi).items() if n in tr.coordinates}
        for row, names in enumerate((tr.angle_names(), tr.rate_names())):
            for n in sorted(names, key=lambda n: n.split("_", 1)[0]):  # legend: leg by leg
                ax = axes[row, 1 if lateral and out_of_plane(n) else 0]
                ax.plot(tr.time, tr.coordinates[n], lw=1.2,
                        label=f"{n.rsplit('_', 1)[0]} - {label}", **sty[n])
    plane = " in the sagittal plane (pitches)" if lateral else ""
    axes[0, 0].set_ylabel("angle from vertical [rad]", fontsize=10)
    axes[1, 0].set_ylabel(f"angular rate [{units.rate}]", fontsize=10)
    axes[0, 0].set_title(f"(a) angles{plane}", fontsize=10)
    axes[1, 0].set_title(f"(b) angular rates{plane}", fontsize=10)
    if lateral:
        axes[0, 1].set_ylabel("angle [rad]", fontsize=10)
        axes[1, 1].set_ylabel(f"angular rate [{units.rate}]", fontsize=10)
        axes[0, 1].set_title("(c) angles out of the sagittal plane (lean, rolls, heading)",
                             fontsize=10)
        axes[1, 1].set_title("(d) their rates", fontsize=10)
    for ax in axes[1]:
        ax.set_xlabel(f"time [{units.time}]", fontsize=10)
    for ax in axes.flat:
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=9)
    h, lab = [], []
    for ax in axes[0]:
        hh, ll = ax.get_legend_handles_labels()
        h, lab = h + hh, lab + ll
    # below the panels, inside the figure with its margin (constrained layout makes room)
    # two columns (a model's legs side by side): no wider than the panels, so the report's
    # scaled image keeps its text size
    fig.legend(h, lab, loc="outside lower center", ncol=min(2 * ncol, len(h)), fontsize=9)
    fig.suptitle(f"Fig. 7 - {title}, angles and rates", fontsize=11)
    return fig


def fig8_errors(time: np.ndarray, errors: dict[str, np.ndarray], units: dict[str, str],
                label: str, scene_units: Units = SI_UNITS,
                phase: tuple[np.ndarray, dict[str, np.ndarray]] | None = None):
    """Fig. 8: error between two models (contact - ideal) of every angle [rad] and rate [rad/s].

    Left: time-aligned (both at the same time since the start: measures the phase drift as
    much as the model).  Right, with ``phase = (step_phase (m,), errors)``: phase-aligned
    (both at the same fraction of the same step: measures the gaits' shapes).
    """
    ncol = 1 if phase is None else 2
    fig, axes = plt.subplots(2, ncol, figsize=(9 if ncol == 1 else 13, 6), sharex="col",
                             squeeze=False)
    sty = _coordinate_styles(list(errors))
    panels = [(axes[:, 0], time, errors, f"time [{scene_units.time}]",
               "time-aligned (same time since the start)")]
    if phase is not None:
        panels.append((axes[:, 1], phase[0], phase[1], "step number + fraction of the step",
                       "phase-aligned (same fraction of the same step)"))
    for col, x, errs, xlabel, title in panels:
        for n, e in errs.items():
            ax = col[0] if units[n] == "rad" else col[1]  # rates: rad/s or its relabel
            ax.plot(x, e, label=n.rpartition("_")[0] or n, lw=1, **sty[n])
        col[0].set_ylabel("angle error [rad]")
        col[1].set_ylabel(f"rate error [{scene_units.rate}]")
        col[1].set_xlabel(xlabel)
        col[0].set_title(title, fontsize=10)
        for ax in col:
            ax.grid(alpha=0.3)
            _legend(ax)
    fig.suptitle(f"Fig. 8 - error {label}")
    return fig


def _phase_panels(tr: NamedTrajectory) -> dict[str, list[tuple[str, str, str]]]:
    """Phase-plane pairs grouped by part of the body: ``{panel: [(owner, angle, rate)]}``.

    A leg's coordinate ``<leg>_<part>_angle`` goes to panel ``<part>`` (``thigh``,
    ``shank``), a straight leg's ``<leg>_angle`` to panel ``leg``, anything else (a torso)
    to a panel of its own: both legs of a walker share a panel, so a kneed walker gets one
    panel per link, not one per leg and link."""
    out: dict[str, list] = {}
    for a, r in tr.phase_pairs():
        stem = a.removesuffix("_angle")
        owner = next((leg for leg in tr.legs if stem == leg or stem.startswith(leg + "_")),
                     None)
        panel = stem if owner is None else (stem[len(owner) + 1:] or "leg")
        out.setdefault(panel, []).append((owner or stem, a, r))
    return out


def _panel_title(panel: str, members: list[tuple[str, str, str]]) -> str:
    """A phase-plane panel's title: the link and whose it is (``"legs: leg1 and leg2"``,
    ``"thighs: leg1 and leg2"``, ``"torso"``), not the bare part name ``"leg"``."""
    owners = list(dict.fromkeys(o for o, _, _ in members))
    if owners == [panel]:  # a link of its own (a torso)
        return panel
    return f"{panel}s: {' and '.join(owners)}" if len(owners) > 1 else f"{panel}: {owners[0]}"


def fig9_limit_cycle(trajs: dict[str, NamedTrajectory], units: Units = SI_UNITS):
    """Fig. 9: limit cycles in the phase plane, rate [rad/s] vs angle [rad]: one panel per
    link (both legs drawn in it, colour per leg, line style per model)."""
    first = next(iter(trajs.values()))
    panels = _phase_panels(first)
    owners = _owners(o for v in panels.values() for o, _, _ in v)
    n = max(1, len(panels))
    fig, axes = plt.subplots(1, n, figsize=(5.5 * n, 4.8), squeeze=False,
                             layout="constrained")
    for k, (panel, members) in enumerate(panels.items()):
        ax = axes.flat[k]
        for mi, (label, tr) in enumerate(trajs.items()):
            for owner, a, r in members:
                if a in tr.coordinates and r in tr.coordinates:
                    ax.plot(tr.coordinates[a], tr.coordinates[r], ls=MODEL_STYLES[mi % 4],
                            color=LEG_COLORS[owners.index(owner.split("_", 1)[0]) % 4],
                            lw=1,
                            label=f"{owner} - {label}")
        ax.set_xlabel(f"{panel} angle [rad]")
        ax.set_ylabel(f"{panel} rate [{units.rate}]")
        ax.set_title(_panel_title(panel, members))
        ax.grid(alpha=0.3)
        _legend(ax)
    fig.suptitle("Fig. 9 - limit cycles in the phase plane\n(both legs per panel: in a "
                 "symmetric gait they trace one cycle)", fontsize=10)
    return fig


def fig10_energy(trajs: dict[str, NamedTrajectory], units: Units = SI_UNITS):
    """Fig. 10: kinetic, potential and total mechanical energy [J] over time."""
    fig, axes = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True)
    for mi, (label, tr) in enumerate(trajs.items()):
        kw = dict(ls=MODEL_STYLES[mi % 4], color=LEG_COLORS[mi % 4], lw=1.2, label=label)
        axes[0].plot(tr.time, tr.kinetic, **kw)
        axes[1].plot(tr.time, tr.potential, **kw)
        axes[2].plot(tr.time, tr.total, **kw)
    for ax, name in zip(axes, ("kinetic", "potential", "total mechanical")):
        ax.set_ylabel(f"{name} energy [{units.energy}]")
        ax.grid(alpha=0.3)
        _legend(ax)
    axes[2].set_xlabel(f"time [{units.time}]")
    fig.suptitle("Fig. 10 - energies (potential from the first stance foot's height)")
    return fig


def _place_labels(ax, points: list[tuple[float, float, str]], fontsize: float = 6,
                  avoid_legend: bool = False, marker_px: float = 0.0) -> list:
    """Annotate ``(x, y, text)`` points, skipping a label whose box would overlap one
    already placed (tried at four offsets first): labels never cover each other.

    ``avoid_legend``: a label never covers the legend either; ``marker_px`` > 0: nor the
    marker of another point (a square of that half-width [px] around it)."""
    from matplotlib.transforms import Bbox

    fig = ax.figure
    fig.canvas.draw()  # a renderer and the final axis limits
    renderer = fig.canvas.get_renderer()
    placed, boxes = [], []
    leg = ax.get_legend()
    if avoid_legend and leg is not None:
        boxes.append(leg.get_window_extent(renderer))
    pix = ax.transData.transform(np.array([(x, y) for x, y, _ in points], float)
                                 ) if points else np.zeros((0, 2))
    markers = [Bbox.from_extents(px - marker_px, py - marker_px, px + marker_px,
                                 py + marker_px) for px, py in pix] if marker_px > 0 else []
    for k, (x, y, text) in enumerate(points):
        others = boxes + [m for j, m in enumerate(markers) if j != k]
        for dx, dy, ha, va in ((4, 3, "left", "bottom"), (4, -3, "left", "top"),
                               (-4, 3, "right", "bottom"), (-4, -3, "right", "top")):
            a = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points",
                            fontsize=fontsize, alpha=0.7, ha=ha, va=va)
            bb = a.get_window_extent(renderer).expanded(1.05, 1.1)
            if not any(bb.overlaps(b) for b in others):
                boxes.append(bb)
                placed.append(a)
                break
            a.remove()
    return placed


def work_precision(rows: dict[str, dict[str, np.ndarray]], title: str, pareto: list | None = None,
                   units: Units = SI_UNITS):
    """Work-precision diagram: error vs CPU time of the integration (log-log; older
    artifacts: wall time), one line per method; the
    spread of the repeats (``time_min``..``time_max``) as horizontal bars, the tolerance
    next to each point where its label does not cover another.  The error is in the
    scene's units (``units``: rad, rad/s or rad/√(l/g)); the wall time in real seconds."""
    fig, ax = plt.subplots(figsize=(7, 5))
    labels = []
    for method, d in rows.items():
        ok = np.isfinite(d["error"]) & (d["error"] > 0)
        line, = ax.loglog(d["time"][ok], d["error"][ok], "o-", label=method, ms=4)
        if "time_min" in d and "time_max" in d:
            ax.errorbar(d["time"][ok], d["error"][ok],
                        xerr=[d["time"][ok] - d["time_min"][ok], d["time_max"][ok] - d["time"][ok]],
                        fmt="none", ecolor=line.get_color(), elinewidth=0.8, capsize=2)
        labels += [(t, e, f"{tol:.0e}") for t, e, tol in zip(d["time"][ok], d["error"][ok],
                                                             d["rtol"][ok])]
    if pareto:
        pt = np.array([(p["time"], p["error"]) for p in pareto])
        ax.loglog(pt[:, 0], pt[:, 1], "k--", lw=1, label="Pareto front (beyond the spread)")
    clock = ("CPU time of the integration" if any("wall_time" in d for d in rows.values())
             else "wall time")
    ax.set_xlabel(f"{clock} [s] (median of repeats; bars: fastest to slowest run)")
    ax.set_ylabel(f"max state error vs reference [rad, {units.rate}]")
    ax.set_title(title)
    ax.grid(alpha=0.3, which="both")
    _legend(ax)
    # labels cover neither each other, nor the legend, nor another setting's marker
    _place_labels(ax, labels, avoid_legend=True, marker_px=4.0)
    return fig
