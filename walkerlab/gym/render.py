"""The environment's frame: the walker's legs and bodies on the slope, drawn with
matplotlib's Agg canvas into an RGB array."""

from __future__ import annotations

import numpy as np

__all__ = ["FRAME_PX", "draw"]

#: frame size (width, height) [px]
FRAME_PX = (480, 360)


def _chains(points: dict) -> list[list[str]]:
    """Polylines of named points: each leg foot - knee - hip (rigid roles or physical legs),
    the torso hip - torso body."""
    out = []
    for leg in ("stance", "swing", "leg1", "leg2"):
        chain = [p for p in (f"{leg}_foot", f"{leg}_knee", "hip") if p in points]
        if len(chain) > 1:
            out.append(chain)
    torso = [k for k in points if k.startswith("torso")]
    if torso:
        out.append(["hip", torso[0]])
    return out


def draw(points: dict, slope_rad: float, leg_length_m: float, t: float) -> np.ndarray:
    """An RGB frame (H, W, 3) uint8 of the walker.

    Parameters
    ----------
    points : dict[str, ndarray]
        World positions [m] (x horizontal downhill, y up; a 3D walker's lateral z is not
        drawn: its sagittal view) of the walker's named points.
    slope_rad : float
        The ground's slope [rad] (the ground line through the origin, falling with x).
    leg_length_m : float
        Sets the view's size [m].
    t : float
        Time [s], printed in the corner.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    w, h = FRAME_PX
    fig = Figure(figsize=(w / 100, h / 100), dpi=100)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes((0, 0, 1, 1))
    hip = np.asarray(points["hip"], float)
    L = 1.4 * leg_length_m
    xs = np.array([hip[0] - 2 * L, hip[0] + 2 * L])
    ax.fill_between(xs, -np.tan(slope_rad) * xs, hip[1] - 3 * L, color="0.8")
    ax.plot(xs, -np.tan(slope_rad) * xs, color="0.3", lw=1)
    for chain in _chains(points):
        p = np.array([points[k] for k in chain], float)
        ax.plot(p[:, 0], p[:, 1], "-", color="tab:blue", lw=3)
    bodies = np.array([v for k, v in points.items() if not k.endswith(("foot", "knee"))],
                      float)
    ax.plot(bodies[:, 0], bodies[:, 1], "o", color="tab:red", ms=6)
    ax.text(0.02, 0.95, f"t = {t:.2f} s", transform=ax.transAxes)
    ax.set_xlim(hip[0] - 1.33 * L, hip[0] + 1.33 * L)
    ax.set_ylim(hip[1] - 1.5 * L, hip[1] + 0.5 * L)
    ax.set_aspect("equal", adjustable="box")
    ax.axis("off")
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[:, :, :3].copy()
