"""``compare.h5``: the contact walker against the rigid one (writer and loader side by side).

Layout: ``errors/`` (attributes ``legs``, ``coordinates``, ``definition``; dimension
``time``: the ideal sample times within the common span [s]; ``coordinates/<name>``: error
contact - ideal of each named coordinate, in its unit; ``limit_cycle_distance/<coordinate>``:
mean distance between the two phase curves; ``max_abs_angle`` [rad], ``max_abs_rate``
[rad/s]); ``errors_phase_aligned/`` (dimension ``step_phase``: step number + fraction of
the step [-]; ``coordinates/<name>``: error contact - ideal at the same fraction of the same
step, :func:`walkerlab.comparison.errors.phase_aligned_errors`); ``metrics/{ideal,contact}/
<name>``: the gait metrics of paper Table 3 (units in :data:`METRIC_UNITS`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import artifact_loader, put
from walkerlab.io.netcdf import coordinate
from walkerlab.units import Units, for_artifact

STAGE = "compare"
METRIC_UNITS = {"t_left_s": "s", "t_right_s": "s", "t_cycle_s": "s", "v_com_m_per_s": "m/s",
                "E_avg_J": "J", "E_avg_stance_frame_J": "J", "step_length_m": "m",
                "step_length_left_m": "m", "step_length_right_m": "m",
                "n_steps": "-", "E_avg_steps": "-"}


@dataclass
class Comparison:
    """Errors and metrics of a contact run against the rigid run (the writer's input, and
    what :func:`load_compare` returns with ``path`` and ``units`` set).

    Attributes
    ----------
    legs : list of str
    time : ndarray (k,)
        Ideal sample times within the common span [s].
    errors : dict[str, ndarray (k,)]
        Error contact - ideal per named coordinate.
    error_units : dict[str, str]
    limit_cycle_distance : dict[str, float]
        Per coordinate stem (``leg1`` ...): mean distance of the phase curves.
    max_abs_angle_rad, max_abs_rate_rad_per_s : float
    metrics : dict[str, dict[str, float]]
        ``{"ideal": {...}, "contact": {...}}`` gait metrics (units :data:`METRIC_UNITS`).
    metric_units : dict[str, str]
    step_phase : ndarray (m,) or None
        Step number + fraction of the step [-] of the phase-aligned errors.
    phase_errors : dict[str, ndarray (m,)] or None
        Error contact - ideal at the same fraction of the same step, per named coordinate.
    contact_cut_short : str
        What a wall-clock limit cut short in the contact run compared (its
        ``contact_sim.h5``'s ``not_final``; "" when nothing): such a comparison is over what
        the run did before the limit, and is never kept as a result either.
    """

    legs: list
    time: np.ndarray
    errors: dict
    error_units: dict
    limit_cycle_distance: dict
    max_abs_angle_rad: float
    max_abs_rate_rad_per_s: float
    metrics: dict
    metric_units: dict
    step_phase: np.ndarray | None = None
    phase_errors: dict | None = None
    path: Path | None = None
    units: Units | None = None
    contact_cut_short: str = ""


def write_compare(f, c: Comparison) -> None:
    """Fill an open (in-memory) artifact with ``c`` (layout in the module docstring)."""
    g = f.create_group("errors")
    g.attrs["legs"] = c.legs
    g.attrs["coordinates"] = list(c.errors)
    g.attrs["definition"] = "contact - ideal, on the ideal sample times"
    coordinate(g, "time", c.time, "s", "ideal sample times within the common span")
    for n, e in c.errors.items():
        put(g, f"coordinates/{n}", e, c.error_units[n], f"{n} error (contact - ideal)",
            dims=("time",))
    for stem, d in c.limit_cycle_distance.items():
        put(g, f"limit_cycle_distance/{stem}", d, "rad (rates in rad/s)",
            f"mean distance from the ideal phase curve of {stem} to the contact one")
    if c.phase_errors is not None:
        p = f.create_group("errors_phase_aligned")
        p.attrs["legs"] = c.legs
        p.attrs["coordinates"] = list(c.phase_errors)
        p.attrs["definition"] = ("contact - ideal at the same fraction of the same step (each "
                                 "step on normalised step time)")
        coordinate(p, "step_phase", c.step_phase, "-",
                   "step number + fraction of the step (heel strike to heel strike)")
        for n, e in c.phase_errors.items():
            put(p, f"coordinates/{n}", e, c.error_units[n],
                f"{n} error (contact - ideal) at the same step phase", dims=("step_phase",))
    put(g, "max_abs_angle", c.max_abs_angle_rad, "rad", "")
    put(g, "max_abs_rate", c.max_abs_rate_rad_per_s, "rad/s", "")
    for model, m in c.metrics.items():
        for k, v in m.items():
            put(f, f"metrics/{model}/{k}", v, METRIC_UNITS.get(k, "-"), k)


@artifact_loader(STAGE)
def load_compare(f, path: Path) -> Comparison:
    """Load ``compare.h5``."""
    g = f["errors"]
    names = [str(x) for x in g.attrs["coordinates"]]
    metrics, munits = {}, {}
    if "metrics" in f:
        for model in f["metrics"]:
            m = f["metrics"][model]
            metrics[model] = {k: m[k][()] for k in m}
            munits.update({k: str(m[k].attrs.get("unit", "")) for k in m})
    step_phase = phase_errors = None
    if "errors_phase_aligned" in f:
        p = f["errors_phase_aligned"]
        step_phase = p["step_phase"][()]
        phase_errors = {n: p[f"coordinates/{n}"][()] for n in
                        (str(x) for x in p.attrs["coordinates"])}
    return Comparison(
        legs=[str(x) for x in g.attrs["legs"]], time=g["time"][()],
        step_phase=step_phase, phase_errors=phase_errors,
        errors={n: g[f"coordinates/{n}"][()] for n in names},
        error_units={n: str(g[f"coordinates/{n}"].attrs["unit"]) for n in names},
        limit_cycle_distance=({k: float(g["limit_cycle_distance"][k][()])
                               for k in g["limit_cycle_distance"]}
                              if "limit_cycle_distance" in g else {}),
        max_abs_angle_rad=float(g["max_abs_angle"][()]),
        max_abs_rate_rad_per_s=float(g["max_abs_rate"][()]),
        metrics=metrics, metric_units=munits, path=Path(path), units=for_artifact(f),
        contact_cut_short=str(f.attrs.get("not_final", "")))
