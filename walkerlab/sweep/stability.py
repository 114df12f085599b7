"""Stability maps of the compliant-contact walker: outcome over (stiffness x slope) and
(friction x slope).

Each map is an ordinary ``contact-sim`` sweep (one artifact, one row per point: walks /
falls / slips / bounces / solver failure, and the run time per point) plus a figure drawn
from that artifact (:func:`walkerlab.plotting.sweep_figures.stability_map_figure`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.config import Scene
from walkerlab.sweep.outcomes import OUTCOMES
from walkerlab.sweep.params import parse_param

__all__ = ["stability_map", "outcome_counts", "DEFAULT_STIFFNESS", "DEFAULT_FRICTION",
           "DEFAULT_SLOPES"]

# contact.stiffness in the scene's contact.unit_system (default mm-kg-s: N/mm^e)
DEFAULT_STIFFNESS = "contact.stiffness=1e3,3e3,1e4,3e4,1e5,1e6"
# static friction; the base scene's mu_dynamic must not exceed the smallest value
DEFAULT_FRICTION = "contact.mu_static=0.1,0.2,0.3,0.5,0.7,0.9"
DEFAULT_SLOPES = "slope.angle_deg=0.5,1,1.5,2,2.5,3"


def outcome_counts(sweep: dict) -> dict[str, int]:
    """Points per outcome of a loaded sweep (only outcomes that occur)."""
    out = list(sweep["points"]["outcome"])
    return {o: out.count(o) for o in OUTCOMES if out.count(o)}


def stability_map(scene: Scene, y_param: str = DEFAULT_STIFFNESS,
                  x_param: str = DEFAULT_SLOPES, stage: str = "contact-sim",
                  runs_root: Path | str = "runs", name: str = "stability_stiffness",
                  workers: int = 2, scheduler=None, resume: bool = False,
                  progress: bool = True, options: dict | None = None) -> dict:
    """Run a 2-D sweep and draw its stability map.

    Parameters
    ----------
    scene : Scene
        Base scene (its ``fixedpoint`` section seeds the ideal gait at every slope).
    y_param, x_param : str
        ``--param`` strings of the map's y axis (stiffness or friction) and x axis (slope).
        The slope is the sweep's *first* axis, so the ideal fixed point that seeds each
        contact run is continued along the slope.
    stage : str
        Swept stage (``contact-sim``; ``simulate`` to exercise the machinery on the rigid
        model).
    runs_root, name : output ``runs/<scene>/<name>.h5`` and ``<name>.png/.svg``.

    Returns
    -------
    dict
        ``artifact``, ``figures``, ``counts`` (outcome -> points), ``wall_time_s``.
    """
    from walkerlab.plotting.sweep_figures import save, stability_map_figure
    from walkerlab.stages.sweep import run
    from walkerlab.sweep.store import load_sweep

    xa, ya = parse_param(x_param), parse_param(y_param)
    path = run(scene, [x_param, y_param], stage, workers=workers, scheduler=scheduler,
               resume=resume, runs_root=runs_root, name=name, options=options,
               progress=progress)
    data = load_sweep(path)
    counts = outcome_counts(data)
    title = f"{stage}: " + ", ".join(f"{k} {v}" for k, v in counts.items())
    fig = stability_map_figure(data, x_path=xa.path, y_path=ya.path, title=title)
    figs = save(fig, Path(path).parent, name)
    return {"artifact": path, "figures": figs, "counts": counts,
            "wall_time_s": float(data["attrs"]["wall_time_s"]),
            "point_wall_time_s": np.asarray(data["points"]["wall_time_s"], float)}
