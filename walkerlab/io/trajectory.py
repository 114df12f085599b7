"""The named trajectory layout shared by ``simulate.h5`` and ``contact_sim.h5``.

``samples/`` holds time series on one time axis, addressed by physical leg name so that the
rigid and the compliant-contact model can be laid one over the other:

==============================  ======  ============================================
``samples/time``                s       sample times
``samples/angle/<leg>``         rad     absolute leg angle from the vertical
``samples/rate/<leg>``          rad/s   its rate
``samples/stance_leg``          -       index into the ``legs`` attribute
``samples/step_index``          -       step each sample belongs to
``samples/energy/kinetic``      J
``samples/energy/potential``    J       relative to the first stance foot's height
``samples/energy/total``        J
``samples/points/<name>/x|y``   m       world positions (hip, <leg>_foot, <leg>_mass)
==============================  ======  ============================================
"""

from __future__ import annotations

from dataclasses import dataclass, field

import h5py
import numpy as np

from walkerlab.io.artifacts import put


@dataclass
class NamedTrajectory:
    """Sampled trajectory addressed by name (see module docstring for units)."""

    time: np.ndarray
    legs: list[str]
    angle: dict[str, np.ndarray]
    rate: dict[str, np.ndarray]
    stance_leg: np.ndarray
    step_index: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    points: dict[str, np.ndarray] = field(default_factory=dict)  # name -> (2, k)

    @property
    def total(self) -> np.ndarray:
        return self.kinetic + self.potential


def write_samples(f: h5py.Group, tr: NamedTrajectory) -> None:
    """Write ``tr`` under ``samples/``."""
    g = f.create_group("samples")
    g.attrs["legs"] = tr.legs
    put(g, "time", tr.time, "s", "sample time")
    for leg in tr.legs:
        put(g, f"angle/{leg}", tr.angle[leg], "rad", f"{leg} angle from the vertical")
        put(g, f"rate/{leg}", tr.rate[leg], "rad/s", f"{leg} angular rate")
    put(g, "stance_leg", tr.stance_leg.astype(np.int8), "-", "index into attribute 'legs'")
    put(g, "step_index", tr.step_index.astype(np.int32), "-", "step number of each sample")
    put(g, "energy/kinetic", tr.kinetic, "J", "kinetic energy")
    put(g, "energy/potential", tr.potential, "J",
        "gravitational potential energy relative to the first stance foot's height")
    put(g, "energy/total", tr.total, "J", "kinetic + potential")
    for name, xy in tr.points.items():
        put(g, f"points/{name}/x", xy[0], "m", f"{name} world x (downhill, horizontal)")
        put(g, f"points/{name}/y", xy[1], "m", f"{name} world y (up)")


def read_samples(f: h5py.Group) -> NamedTrajectory:
    """Read ``samples/`` back into a :class:`NamedTrajectory`."""
    g = f["samples"]
    legs = [str(x) for x in g.attrs["legs"]]
    pts = {}
    if "points" in g:
        for name in g["points"]:
            pts[name] = np.vstack([g[f"points/{name}/x"][()], g[f"points/{name}/y"][()]])
    return NamedTrajectory(
        time=g["time"][()], legs=legs,
        angle={leg: g[f"angle/{leg}"][()] for leg in legs},
        rate={leg: g[f"rate/{leg}"][()] for leg in legs},
        stance_leg=g["stance_leg"][()], step_index=g["step_index"][()],
        kinetic=g["energy/kinetic"][()], potential=g["energy/potential"][()], points=pts,
    )
