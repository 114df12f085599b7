"""A walker's gait in three dimensions, drawn from its stored trajectory: the top view (the
footprints and the hip's path on the ground's plan) and the front view (looking uphill: the
roll of the legs and the hip's sway), as a researcher checks a 3D gait's lateral motion."""

from __future__ import annotations

import numpy as np

from walkerlab.io.trajectory import NamedTrajectory
from walkerlab.units import Units


def top_and_front(trajs: dict[str, NamedTrajectory], title: str, units: Units):
    """Top and front views of each 3D trajectory in ``trajs`` (points with a ``z`` row).

    Parameters
    ----------
    trajs : dict
        ``{model label: NamedTrajectory}``; each point (3, k): world x (downhill,
        horizontal), y (up), z (to the right of a walker facing downhill) [m].
    title : str
    units : Units
        The scene's units (lengths in :attr:`Units.length`).

    Returns
    -------
    matplotlib.figure.Figure
        Two panels: top view (x against z, footfalls marked), front view (z against y).
    """
    import matplotlib.pyplot as plt

    fig, (top, front) = plt.subplots(1, 2, figsize=(10, 4.2))
    spans = []
    for label, tr in trajs.items():
        pts = {k: np.asarray(v) for k, v in tr.points.items() if len(v) > 2}
        hip = pts.get("hip")
        if hip is not None:
            top.plot(hip[0], hip[2], lw=1.5, label=f"{label}: hip")
            front.plot(hip[2], hip[1], lw=1.5, label=f"{label}: hip")
            spans.append(float(np.ptp(hip[1])) + float(np.max(np.abs(hip[1] - hip[1][0]))))
        feet = [p for name, p in pts.items() if name.endswith("_foot")]
        falls = []
        for p in feet:
            # a foot's footfalls: where it rests (the samples at which it does not move)
            rest = np.r_[False, np.all(np.abs(np.diff(p, axis=1)) < 1e-12, axis=0)]
            falls.append(p[:, rest])
        if falls:
            f = np.hstack(falls)
            top.plot(f[0], f[2], "o", ms=3, label=f"{label}: footfalls")
        for k, p in enumerate(feet):
            front.plot(p[2], p[1], lw=0.5, color="0.6",
                       label=f"{label}: feet" if k == 0 else None)
    # a lateral axis of at least a tenth of the walk's height range: a gait that stays in
    # its plane (to round-off) shows as one, not as its round-off magnified
    half = 0.05 * max(spans) if spans and max(spans) > 0 else 0.05
    for get, setter in ((top.get_ylim, top.set_ylim), (front.get_xlim, front.set_xlim)):
        lo, hi = get()
        mid = 0.5 * (lo + hi)
        if hi - lo < 2 * half:
            setter(mid - half, mid + half)
    u = units.length
    top.set(xlabel=f"x downhill [{u}]", ylabel=f"z lateral [{u}]", title="top view")
    front.set(xlabel=f"z lateral [{u}]", ylabel=f"y up [{u}]", title="front view (uphill)")
    top.legend(fontsize=7)
    front.legend(fontsize=7)
    fig.suptitle(f"{title}: the gait in three dimensions")
    fig.tight_layout()
    return fig
