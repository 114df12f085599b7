"""The named trajectory layout shared by ``simulate.h5`` and ``contact_sim.h5``.

``samples/`` holds time series on one time axis (netCDF dimension ``time``), addressed by
*physical* coordinate name so that the rigid and the compliant-contact model can be laid one
over the other, whatever the walker (compass gait: ``leg1_angle``, ``leg2_angle``,
``leg1_rate``, ``leg2_rate``; a kneed walker adds ``leg1_shank_angle`` ...):

===================================  ======  ============================================
``samples/time``                     s       sample times (dimension scale ``time``)
``samples/coordinates/<name>``       rad...  each named coordinate (its own ``unit``), from
                                             ``HybridWalker.leg_coordinates``
``samples/stance_leg``               -       index into the ``legs`` attribute
``samples/step_index``               -       step each sample belongs to
``samples/phase``                    -       continuous phase of the step (index into the
                                             ``phases`` attribute; rigid walkers only)
``samples/energy/kinetic``           J
``samples/energy/potential``         J       relative to the first stance foot's height
``samples/energy/total``             J
``samples/points/<name>/x|y``        m       world positions (hip, <leg>_foot, ...)
===================================  ======  ============================================

The ``samples`` group's ``coordinates`` attribute lists the coordinate names in order.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import h5py
import numpy as np

from walkerlab.io.artifacts import put
from walkerlab.io.netcdf import coordinate


@dataclass
class NamedTrajectory:
    """Sampled trajectory addressed by name (see module docstring for units).

    Attributes
    ----------
    time : ndarray (k,)
        Sample times [s].
    legs : list of str
        Physical leg names; ``stance_leg`` indexes into it.
    coordinates : dict[str, ndarray (k,)]
        Named coordinate series (angles [rad] and rates [rad/s] for the rigid walkers).
    units : dict[str, str]
        Unit of each coordinate.
    stance_leg, step_index : ndarray (k,) int
    kinetic, potential : ndarray (k,)
        Energies [J]; potential relative to the first stance foot's height.
    points : dict[str, ndarray (2, k)]
        World positions [m] of named points.
    """

    time: np.ndarray
    legs: list[str]
    coordinates: dict[str, np.ndarray]
    units: dict[str, str]
    stance_leg: np.ndarray
    step_index: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    points: dict[str, np.ndarray] = field(default_factory=dict)  # name -> (2, k)
    phase: np.ndarray | None = None  # (k,) index into phase_names; None: not phased
    phase_names: list[str] = field(default_factory=list)

    @property
    def total(self) -> np.ndarray:
        """Total mechanical energy ``kinetic + potential`` (k,) [J]."""
        return self.kinetic + self.potential

    def angle_names(self) -> list[str]:
        """Coordinates measured in rad (positions), in order."""
        return [n for n in self.coordinates if self.units.get(n) == "rad"]

    def rate_names(self) -> list[str]:
        """Coordinates measured in rad/s (velocities; rad per time unit in a nondimensional
        scene), in order."""
        return [n for n in self.coordinates if str(self.units.get(n, "")).startswith("rad/")]

    def phase_pairs(self) -> list[tuple[str, str]]:
        """``(angle name, rate name)`` pairs of the same coordinate (``x_angle``/``x_rate``)."""
        out = []
        for a in self.angle_names():
            r = a.removesuffix("_angle") + "_rate"
            if a.endswith("_angle") and r in self.coordinates:
                out.append((a, r))
        return out


def write_samples(f: h5py.Group, tr: NamedTrajectory) -> None:
    """Write ``tr`` under ``samples/`` (every series on the ``time`` dimension)."""
    g = f.create_group("samples")
    g.attrs["legs"] = tr.legs
    g.attrs["coordinates"] = list(tr.coordinates)
    coordinate(g, "time", tr.time, "s", "sample time")
    t = ("time",)
    for name, v in tr.coordinates.items():
        unit = tr.units[name]
        what = "angle from the vertical" if unit == "rad" else "angular rate" \
            if unit == "rad/s" else "coordinate"
        put(g, f"coordinates/{name}", v, unit, f"{name}: {what}", dims=t)
    put(g, "stance_leg", tr.stance_leg.astype(np.int8), "-", "index into attribute 'legs'",
        dims=t)
    put(g, "step_index", tr.step_index.astype(np.int32), "-", "step number of each sample",
        dims=t)
    if tr.phase is not None:
        g.attrs["phases"] = list(tr.phase_names)
        put(g, "phase", tr.phase.astype(np.int8), "-", "continuous phase of the step "
            "(index into attribute 'phases'); energy is conserved within a phase", dims=t)
    put(g, "energy/kinetic", tr.kinetic, "J", "kinetic energy", dims=t)
    put(g, "energy/potential", tr.potential, "J",
        "gravitational potential energy relative to the first stance foot's height", dims=t)
    put(g, "energy/total", tr.total, "J", "kinetic + potential", dims=t)
    for name, xy in tr.points.items():
        put(g, f"points/{name}/x", xy[0], "m", f"{name} world x (downhill, horizontal)", dims=t)
        put(g, f"points/{name}/y", xy[1], "m", f"{name} world y (up)", dims=t)
        if len(xy) > 2:  # a walker in 3D
            put(g, f"points/{name}/z", xy[2], "m", f"{name} world z (lateral: to the right "
                "of a walker facing downhill)", dims=t)


def read_samples(f: h5py.Group) -> NamedTrajectory:
    """Read ``samples/`` back into a :class:`NamedTrajectory`."""
    g = f["samples"]
    legs = [str(x) for x in g.attrs["legs"]]
    names = [str(x) for x in g.attrs["coordinates"]]
    pts = {}
    if "points" in g:
        for name in g["points"]:
            pts[name] = np.vstack([g[f"points/{name}/{c}"][()] for c in "xyz"
                                   if c in g[f"points/{name}"]])
    return NamedTrajectory(
        time=g["time"][()], legs=legs,
        coordinates={n: g[f"coordinates/{n}"][()] for n in names},
        units={n: str(g[f"coordinates/{n}"].attrs["unit"]) for n in names},
        stance_leg=g["stance_leg"][()], step_index=g["step_index"][()],
        kinetic=g["energy/kinetic"][()], potential=g["energy/potential"][()], points=pts,
        phase=g["phase"][()] if "phase" in g else None,
        phase_names=[str(x) for x in g.attrs.get("phases", [])],
    )
