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
    for label, tr in trajs.items():
        pts = {k: np.asarray(v) for k, v in tr.points.items() if len(v) > 2}
        hip = pts.get("hip")
        if hip is not None:
            top.plot(hip[0], hip[2], lw=1.5, label=f"{label}: hip")
            front.plot(hip[2], hip[1], lw=1.5, label=f"{label}: hip")
        for name, p in pts.items():
            if name.endswith("_foot"):
                # a foot's footfall: where it rests (its samples that do not move)
                rest = np.r_[False, np.all(np.abs(np.diff(p, axis=1)) < 1e-12, axis=0)]
                top.plot(p[0][rest], p[2][rest], "o", ms=3, label=f"{label}: {name} at rest")
                front.plot(p[2], p[1], lw=0.6, alpha=0.6, label=f"{label}: {name}")
    u = units.length
    top.set(xlabel=f"x downhill [{u}]", ylabel=f"z lateral [{u}]", title="top view")
    front.set(xlabel=f"z lateral [{u}]", ylabel=f"y up [{u}]", title="front view (uphill)")
    top.legend(fontsize=7)
    front.legend(fontsize=7)
    fig.suptitle(f"{title}: the gait in three dimensions")
    fig.tight_layout()
    return fig
