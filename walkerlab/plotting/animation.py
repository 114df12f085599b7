"""The walker walking: a matplotlib animation drawn from named trajectories.

Everything is read from the trajectory's named points (``samples/points/<name>`` of
``simulate.h5`` / ``contact_sim.h5``), so any walker is drawn right without knowing its state:

- each leg is a chain ``hip -> <leg>_knee (if any) -> <leg>_foot``; with arc feet
  (points ``<leg>_foot_centre`` and ``<leg>_contact``) the chain runs through the arc's centre
  on to the arc, drawn as a circular arc of radius ``R = |contact - centre|`` about the leg's
  axis (McGeer 1990), its contact point (lowest point relative to the slope) a small dot;
- every other point of a leg (point masses, rods' centres) is a dot; the hip a larger dot;
- an upper body (points ``torso_<body>``) is a line from the hip through its bodies to the
  farthest one, each body a dot (:func:`torso_parts`);
- the ground is the slope line ``y = -x tan(phi)`` through the first stance foot (world
  frame, x downhill, y up), shaded below.

Several trajectories (rigid and contact) are drawn side by side at the same times, each panel
following its own hip.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import matplotlib

from walkerlab.plotting.figures import draw_patches

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from walkerlab.io.trajectory import NamedTrajectory

__all__ = ["ARC_HALF_ANGLE_RAD", "WalkerFrames", "frame_times", "gif_writer", "leg_parts",
           "save_frames", "torso_parts", "walker_animation", "write_frames"]

#: Half the angle the drawn foot arc spans about the leg axis [rad] (the stance arc's contact
#: stays within about 0.3 rad of the axis for the shipped walkers).
ARC_HALF_ANGLE_RAD = 0.6
#: Points on a drawn arc.
ARC_POINTS = 25
LEG_COLOURS = ("tab:blue", "tab:orange")


def leg_parts(tr: NamedTrajectory, leg: str) -> dict:
    """Names of the points that draw one leg.

    Returns
    -------
    dict
        ``chain``: point names from the hip to the leg's end (knee if any, then the foot,
        the arc's centre or a flat foot's ankle); ``arc``: ``(centre, contact)`` names or
        None; ``sole``: a flat foot's ``(heel, toe)`` names or None; ``bodies``: the leg's
        other points (masses), drawn as dots.
    """
    p = tr.points
    knee, foot = f"{leg}_knee", f"{leg}_foot"
    centre, contact = f"{leg}_foot_centre", f"{leg}_contact"
    heel, toe, ankle = f"{leg}_heel", f"{leg}_toe", f"{leg}_ankle"
    arc = (centre, contact) if centre in p and contact in p else None
    sole = (heel, toe) if heel in p and toe in p and ankle in p else None
    end = centre if arc else ankle if sole else foot
    chain = ["hip"] + ([knee] if knee in p else []) + [end]
    skip = {knee, foot, centre, contact, heel, toe, ankle}
    bodies = [n for n in p if n.startswith(leg + "_") and n not in skip]
    return {"chain": chain, "arc": arc, "sole": sole, "bodies": bodies}


def torso_parts(tr: NamedTrajectory) -> list[str]:
    """Names of the upper body's points (``torso_<body>``), nearest the hip first (empty:
    no upper body)."""
    hip = tr.points["hip"][:, 0]
    names = [n for n in tr.points if n.startswith("torso_")]
    return sorted(names, key=lambda n: float(np.hypot(*(tr.points[n][:, 0] - hip))))


def frame_times(trajs: dict[str, NamedTrajectory], fps: float, max_frames: int) -> np.ndarray:
    """Frame times [s]: every ``1/fps`` over the time all trajectories cover, at most
    ``max_frames`` (then spread evenly over that time: the animation runs faster)."""
    t_end = min(float(tr.time[-1]) for tr in trajs.values())
    t0 = max(float(tr.time[0]) for tr in trajs.values())
    n = int(min(max_frames, max(2, np.floor((t_end - t0) * fps) + 1)))
    return np.linspace(t0, t_end, n)


def _leg_length(tr: NamedTrajectory) -> float:
    """Hip to the farthest leg point at the first sample, plus the arc radius [m]."""
    hip = tr.points["hip"][:, 0]
    out = 0.0
    for leg in tr.legs:
        parts = leg_parts(tr, leg)
        end = tr.points[parts["chain"][-1]][:, 0]
        r = 0.0
        if parts["arc"]:
            c, k = parts["arc"]
            r = float(np.hypot(*(tr.points[k][:, 0] - tr.points[c][:, 0])))
        out = max(out, float(np.hypot(*(end - hip))) + r)
    return out


@dataclass
class WalkerFrames:
    """A figure and how to draw its frame ``j`` (``draw(j)``) at ``times[j]``."""

    fig: object
    times: np.ndarray
    draw: Callable[[int], None]
    dpi: int


def gif_writer(fps: float, colours: int = 64):
    """matplotlib's Pillow (GIF) writer, mapping every frame onto one palette taken from the
    first frame (``colours`` entries, no dithering).

    ``PillowWriter`` itself quantizes each frame separately (median cut), which was most
    of the time of an animation; the frames here share their colours
    (legs, ground, text), so one palette serves them all.
    """
    from io import BytesIO

    from matplotlib.animation import PillowWriter
    from PIL import Image

    class PaletteWriter(PillowWriter):
        palette = None

        def grab_frame(self, **savefig_kwargs):
            buf = BytesIO()
            self.fig.savefig(buf, **{**savefig_kwargs, "format": "rgba", "dpi": self.dpi})
            im = Image.frombuffer("RGBA", self.frame_size, buf.getbuffer(), "raw", "RGBA", 0,
                                  1).convert("RGB")
            if self.palette is None:
                self.palette = im.quantize(colours, method=Image.Quantize.MEDIANCUT)
            self._frames.append(im.quantize(palette=self.palette, dither=Image.Dither.NONE))

    return PaletteWriter(fps=fps)


def write_frames(frames: WalkerFrames, path: Path | str, writer) -> None:
    """Draw every frame and hand it to a matplotlib animation writer (``PillowWriter``,
    ``FFMpegWriter``): one figure draw per frame (``FuncAnimation.save`` draws each frame
    three times)."""
    with writer.saving(frames.fig, str(path), frames.dpi):
        for j in range(len(frames.times)):
            frames.draw(j)
            writer.grab_frame()


#: width of the animation [px] at least (two panels side by side: 480 px each)
MIN_WIDTH_PX = 960


def walker_animation(trajs: dict[str, NamedTrajectory], slope_rad: float, fps: float = 20.0,
                     max_frames: int = 150, time_unit: str = "s", dpi: int = 100,
                     terrain: dict | None = None):
    """The walkers walking side by side, one panel per trajectory.

    Parameters
    ----------
    trajs : dict[str, NamedTrajectory]
        Panel title -> trajectory with named points (``hip`` and each leg's points).
    slope_rad : float
        Slope angle phi [rad] (ground line ``y = -x tan(phi)``).
    fps : float
        Frames per second of the animation [1/s]; one frame per ``1/fps`` of walker time
        unless that gives more than ``max_frames``.
    max_frames : int
        Cap on the number of frames (keeps GIFs small and quick to write).
    time_unit : str
        Unit of the trajectories' time (for the clock in the title).
    dpi : int
        Resolution of the saved frames; the figure is at least :data:`MIN_WIDTH_PX` wide.
    terrain : dict, optional
        Panel title -> the contact walker's ground (:func:`walkerlab.io.terrain.
        load_terrain`): its checkerboard patches are drawn under that panel's slope line;
        or ``{"stairs": (riser_m, tread_m, direction, first_foothold_m)}``: the stairs.

    Returns
    -------
    WalkerFrames
        Write with :func:`write_frames`; close ``.fig`` afterwards.

    Raises
    ------
    KeyError
        A trajectory without a ``hip`` point.
    """
    from dataclasses import replace

    # a walker in 3D is drawn in the sagittal plane (its top and front views: the report's
    # gait_3d_top_front figure)
    trajs = {k: replace(tr, points={n: np.asarray(p)[:2] for n, p in tr.points.items()})
             if any(len(p) > 2 for p in tr.points.values()) else tr
             for k, tr in trajs.items()}
    times = frame_times(trajs, fps, max_frames)
    n = len(trajs)
    L = max(_leg_length(tr) for tr in trajs.values())
    width = max(MIN_WIDTH_PX / dpi, 4.8 * n)
    fig, axes = plt.subplots(1, n, figsize=(width, 0.92 * width / n), dpi=dpi,
                             squeeze=False)
    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.01, top=0.88, wspace=0.03)
    xmin = min(float(tr.points["hip"][0].min()) for tr in trajs.values()) - 3 * L
    xmax = max(float(tr.points["hip"][0].max()) for tr in trajs.values()) + 3 * L
    gx = np.array([xmin, xmax])
    panels = []
    for ax, (title, tr) in zip(axes[0], trajs.items()):
        _draw_ground(ax, gx, slope_rad, L, (terrain or {}).get(title))
        panels.append(_panel(ax, title, tr, times))

    def draw(j: int) -> None:
        for ax, tr, idx, legs, hip, label, title in panels:
            i = idx[j]
            P = {n: tr.points[n][:, i] for n in tr.points}
            for lg in legs:
                (_draw_torso if "torso" in lg else _draw_leg)(lg, P)
            hx, hy = P["hip"]
            hip.set_data([hx], [hy])
            ax.set_xlim(hx - 1.1 * L, hx + 1.1 * L)
            ax.set_ylim(hy - 1.35 * L, hy + 0.45 * L)
            label.set_text(f"{title}\nt = {times[j]:.2f} {time_unit}")

    return WalkerFrames(fig, times, draw, dpi)


def stairs_polyline(riser_m: float, tread_m: float, direction: str, first_m: float,
                    gx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Stairs as a polyline in world axes over ``[gx.min(), gx.max()]`` [m]: the first
    stance foot at the origin, ``first_m`` from the back of its tread; each tread
    ``tread_m`` deep, ``riser_m`` lower (``direction`` "down") or higher ("up") than the last.

    Returns
    -------
    x, y : ndarray, shape (2k,)
        Vertices (each tread's back and front end).
    """
    sign = 1.0 if direction == "up" else -1.0
    k0 = int(np.floor((gx.min() + first_m) / tread_m))
    k1 = int(np.ceil((gx.max() + first_m) / tread_m))
    ks = np.arange(k0, k1 + 1)
    xs = np.column_stack([ks * tread_m - first_m, (ks + 1) * tread_m - first_m]).ravel()
    ys = np.repeat(sign * riser_m * ks, 2).astype(float)
    return xs, ys


def _draw_ground(ax, gx: np.ndarray, slope_rad: float, L: float, ground: dict | None) -> None:
    """The slope line ``y = -x tan(phi)`` over ``gx`` (shaded below), the contact walker's
    patches over gaps (``ground``: :func:`walkerlab.io.terrain.load_terrain`) or stairs
    (``ground = {"stairs": (riser_m, tread_m, direction, first_foothold_m)}``,
    :func:`stairs_polyline`)."""
    gy = -np.tan(slope_rad) * gx
    if ground is not None and "stairs" in ground:  # the treads and risers, shaded below
        sx, sy = stairs_polyline(*ground["stairs"], gx)
        ax.fill_between(sx, sy, sy.min() - 3 * L, color="0.85", lw=0)
        ax.plot(sx, sy, color="k", lw=1)
    elif ground is not None and not ground["continuous"]:  # patches over gaps

        draw_patches(ax, ground, slope_rad, 0.12 * L)
        ax.plot(gx, gy, color="0.6", lw=0.8, ls=":")
    else:
        ax.fill_between(gx, gy, gy - 3 * L, color="0.85", lw=0)
        ax.plot(gx, gy, color="k", lw=1)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def _panel(ax, title: str, tr: NamedTrajectory, times: np.ndarray) -> tuple:
    """One panel's artists: ``(ax, tr, sample index per frame, legs, hip, title, text)``."""
    idx = np.clip(np.searchsorted(tr.time, times), 0, tr.time.size - 1)
    legs = []
    for k, leg in enumerate(tr.legs):
        c = LEG_COLOURS[k % len(LEG_COLOURS)]
        parts = leg_parts(tr, leg)
        legs.append({
            "parts": parts,
            "line": ax.plot([], [], color=c, lw=3, solid_capstyle="round")[0],
            "arc": ax.plot([], [], color=c, lw=3)[0] if parts["arc"] else None,
            "contact": ax.plot([], [], "o", color=c, ms=3)[0] if parts["arc"] else None,
            "sole": ax.plot([], [], color=c, lw=3)[0] if parts["sole"] else None,
            "dots": ax.plot([], [], "o", color=c, ms=6)[0],
        })
    torso = torso_parts(tr)
    if torso:  # drawn with the legs' artists (the last entry)
        legs.append({"torso": torso,
                     "line": ax.plot([], [], color="tab:green", lw=4,
                                     solid_capstyle="round")[0],
                     "dots": ax.plot([], [], "o", color="tab:green", ms=7)[0]})
    hip = ax.plot([], [], "o", color="k", ms=9)[0]
    label = ax.set_title(title, fontsize=13)
    return ax, tr, idx, legs, hip, label, title


def _draw_torso(tb: dict, P: dict[str, np.ndarray]) -> None:
    """Move the upper body's artists (``tb``, from :func:`_panel`) to the points ``P``."""
    xy = np.array([P["hip"], *(P[n] for n in tb["torso"])])
    tb["line"].set_data(xy[:, 0], xy[:, 1])
    tb["dots"].set_data(xy[1:, 0], xy[1:, 1])


def _draw_leg(lg: dict, P: dict[str, np.ndarray]) -> None:
    """Move one leg's artists (``lg``, from :func:`_panel`) to the points ``P`` of a frame."""
    parts = lg["parts"]
    xy = np.array([P[n] for n in parts["chain"]])
    if parts["arc"]:
        c, k = (P[n] for n in parts["arc"])
        r = float(np.hypot(*(k - c)))
        u = (c - xy[-2]) / np.hypot(*(c - xy[-2]))  # the leg's (shank's) axis
        a = np.arctan2(u[1], u[0]) + np.linspace(-ARC_HALF_ANGLE_RAD,
                                                 ARC_HALF_ANGLE_RAD, ARC_POINTS)
        lg["arc"].set_data(c[0] + r * np.cos(a), c[1] + r * np.sin(a))
        lg["contact"].set_data([k[0]], [k[1]])
        xy = np.vstack([xy, c + r * u])  # the leg runs on to its arc
    lg["line"].set_data(xy[:, 0], xy[:, 1])
    if parts["sole"]:  # a flat foot: heel to toe through the ankle
        sole = np.array([P[n] for n in parts["sole"]])
        lg["sole"].set_data(sole[:, 0], sole[:, 1])
    b = np.array([P[n] for n in parts["bodies"]]).reshape(-1, 2)
    lg["dots"].set_data(b[:, 0], b[:, 1])


def save_frames(frames: WalkerFrames, path: Path, writer) -> Path:
    """Write the frames to a temporary file of the same suffix in the same folder, then rename
    (matplotlib's writers pick the format from the file name), mode 0644.  ``path`` must not
    be a symbolic link (RunPathError, one line); temporary files of a killed earlier run
    (``.animation.<pid>.*.gif``) are removed first."""
    import os

    from walkerlab.safefs import atomic_replace, refuse_link

    def fill(fd, tmp):
        os.close(fd)
        write_frames(frames, tmp, writer)

    refuse_link(path)
    atomic_replace(path, fill, mode=0o644, suffix=path.suffix, name=path.stem)
    return path
