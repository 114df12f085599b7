"""``basin.h5``: the basin of attraction over a 2-D slice of the Poincaré section (writer
and loader side by side).

Layout: root attributes ``model``, ``state_names``, ``x_axis``, ``y_axis`` (the state
names spanning the slice), ``start`` ("fixed_point" or "heel_strike"), ``outcomes``,
``axis_order``; dimension scales ``x``, ``y`` (cell centres, in the axes' units);
``outcome`` (index into ``outcomes``), ``steps``, ``period`` on ``(y, x)``;
``fixed_point/<state>``; ``counts/<outcome>`` [cells]; ``settings/`` (max steps,
tolerances, integrator tolerances); ``stats/cells_computed``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader, put
from walkerlab.io.netcdf import coordinate

STAGE = "basin"


@dataclass
class BasinRun:
    """What the basin stage computed (the writer's input).

    Attributes
    ----------
    walker : HybridWalker
    result : dict
        :func:`walkerlab.studies.basin.compute_basin`'s result (``x``, ``y`` cell centres,
        ``outcome``, ``steps``, ``period`` arrays (ny, nx), ``cells_computed``).
    fixed_point : ndarray (2n,)
        The period-1 gait [rad, rad/s].
    settings : walkerlab.config.BasinSettings
    outcomes : list of str
    counts : dict[str, int]
        Cells per outcome.
    """

    walker: object
    result: dict
    fixed_point: np.ndarray
    settings: object
    outcomes: list
    counts: dict


def write_basin(f, run: BasinRun) -> None:
    """Fill an open (in-memory) artifact with ``run`` (layout in the module docstring)."""
    walker, st, res = run.walker, run.settings, run.result
    names = walker.state_names()
    units = walker.state_units() if hasattr(walker, "state_units") else [
        "rad" if n.endswith("_angle") else "rad/s" for n in names]
    unit = dict(zip(names, units))
    f.attrs["model"] = walker.name
    f.attrs["state_names"] = names
    f.attrs["x_axis"], f.attrs["y_axis"] = st.x_axis, st.y_axis
    f.attrs["start"] = st.start
    f.attrs["outcomes"] = run.outcomes
    f.attrs["axis_order"] = "outcome[j, i]: j along y_axis, i along x_axis"
    coordinate(f, "x", res["x"], unit[st.x_axis], f"cell centres, {st.x_axis}")
    coordinate(f, "y", res["y"], unit[st.y_axis], f"cell centres, {st.y_axis}")
    put(f, "outcome", res["outcome"], "-",
        "index into attrs['outcomes'] (converged = period-1 gait)", dims=("y", "x"))
    put(f, "steps", res["steps"], "steps", "steps until the outcome was decided",
        dims=("y", "x"))
    put(f, "period", res["period"], "steps", "period of the attractor reached "
        "(1 = fixed point, 0 = none)", dims=("y", "x"))
    for n, v in zip(names, run.fixed_point):
        put(f, f"fixed_point/{n}", float(v), unit[n], f"{n} of the period-1 gait")
    for o, c in run.counts.items():
        put(f, f"counts/{o}", c, "cells", f"cells whose outcome is {o}")
    put(f, "settings/max_steps", st.max_steps, "steps", "steps per cell at most")
    put(f, "settings/converge_tol", st.converge_tol, "rad, rad/s",
        "max|x - x*| that counts as converged")
    put(f, "settings/period_tol", st.period_tol, "rad, rad/s",
        "max|x_k - x_{k-p}| that counts as a period-p attractor")
    put(f, "settings/rtol", st.rtol, "-", "integrator relative tolerance (DOP853)")
    put(f, "settings/atol", st.atol, "rad, rad/s", "integrator absolute tolerance")
    put(f, "stats/cells_computed", res["cells_computed"], "cells",
        "cells computed by the last run (the rest came from a resumed partial file)")


@dataclass
class BasinArtifact:
    """A loaded ``basin.h5``.

    Attributes
    ----------
    x, y : ndarray (nx,), (ny,)
        Cell centres along ``x_axis`` and ``y_axis`` (units ``x_unit``, ``y_unit``).
    outcome, steps, period : ndarray (ny, nx)
        Outcome index into ``outcomes``; steps until decided; attractor period.
    fixed_point : dict[str, float]
        The period-1 gait by state name.
    counts : dict[str, int]
        Cells per outcome.
    max_steps : int
    start : str
        "fixed_point" or "heel_strike".
    scene : str
        The scene's name.
    """

    x: np.ndarray
    y: np.ndarray
    outcome: np.ndarray
    steps: np.ndarray
    period: np.ndarray
    x_unit: str
    y_unit: str
    x_axis: str
    y_axis: str
    outcomes: list
    fixed_point: dict
    max_steps: int
    start: str = "fixed_point"
    scene: str = ""
    counts: dict = field(default_factory=dict)


@artifact_loader(STAGE)
def load_basin(f, path: Path) -> BasinArtifact:
    """Load ``basin.h5``."""
    names = [str(n) for n in f.attrs["state_names"]]
    outcomes = [str(o) for o in f.attrs["outcomes"]]
    return BasinArtifact(
        **{k: f[k][()] for k in ("x", "y", "outcome", "steps", "period")},
        x_unit=str(f["x"].attrs["unit"]), y_unit=str(f["y"].attrs["unit"]),
        x_axis=str(f.attrs["x_axis"]), y_axis=str(f.attrs["y_axis"]), outcomes=outcomes,
        fixed_point={n: float(f[f"fixed_point/{n}"][()]) for n in names},
        max_steps=int(f["settings/max_steps"][()]),
        start=str(f.attrs.get("start", "fixed_point")),
        scene=str(f.attrs.get("scene_name", "")),
        counts={o: int(f[f"counts/{o}"][()]) for o in outcomes})
