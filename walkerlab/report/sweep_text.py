"""Plain-text summary of a sweep artifact, printed by ``walkerlab sweep``: the points per
outcome and the range of the stage's main results over the points that walk."""

from __future__ import annotations

import numpy as np

from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.report.markdown import num
from walkerlab.units import Units, field_unit, per_map

#: the main results of each swept stage (columns of ``points``), in the order printed
MAIN_COLUMNS = {
    "fixedpoint": ("step_period_s", "max_abs_multiplier"),
    "simulate": ("steps_completed", "mean_step_period_s", "mean_hip_speed_m_per_s"),
    CONTACT_SIM.name: ("heel_strikes", "mean_step_period_s", "max_slip_mm",
                    "peak_penetration_mm"),
}
#: columns of a Poincaré map's Floquet multipliers: labelled with the sweep's one map
#: (the artifact's ``steps_per_map``: "per step", "per stride")
PER_MAP_COLUMNS = ("max_abs_multiplier",)
#: SI unit of a result column by its suffix (labelled through :class:`Units`)
_SUFFIX = (("_m_per_s", "m/s"), ("_mm", "mm"), ("_s", "s"), ("_m", "m"))


def column_unit(name: str, units: Units) -> str:
    """Label of a result column's unit (``step_period_s`` -> ``s`` or ``√(l/g)``)."""
    for suffix, si in _SUFFIX:
        if name.endswith(suffix):
            return units(si)
    return ""


def main_columns(data: dict) -> list[str]:
    """The stage's main result columns present in a loaded sweep (``load_sweep``)."""
    stage = str(data["attrs"].get("sweep_stage", ""))
    return [c for c in MAIN_COLUMNS.get(stage, ()) if c in data["points"]]


def sweep_text(data: dict) -> str:
    """``5 points: ok 5``, then for each main result its range over the points that walk
    (``step_period_s 0.7036 .. 0.7343 s over slope.angle_deg 1 .. 3 deg``), of a loaded
    sweep (:func:`walkerlab.io.sweep_store.load_sweep`)."""
    units = Units(str(data["attrs"].get("scene_units", "SI")))
    outcome = np.asarray(data["points"]["outcome"]).astype(str)
    kinds, counts = np.unique(outcome, return_counts=True)
    order = np.argsort(-counts, kind="stable")
    lines = [f"{outcome.size} points: " + ", ".join(f"{kinds[i]} {counts[i]}" for i in order)]
    ok = outcome == "ok"
    for path_, _values in data["axes"]:
        v = np.asarray(data["points"][f"param/{path_}"])
        if v.dtype.kind in "fi" and v.size:
            u = units(field_unit(path_) or "-")
            lines.append(f"  {path_:<28s} {num(np.min(v))} .. {num(np.max(v))}"
                         + (f" {u}" if u not in ("", "-") else ""))
    for c in main_columns(data):
        v = np.asarray(data["points"][c], float)[ok]
        v = v[np.isfinite(v)]
        u = column_unit(c, units)
        rng = (f"{num(v.min())} .. {num(v.max())}" + (f" {u}" if u else "")
               if v.size else "no point walks")
        if c in PER_MAP_COLUMNS and per_map(data["attrs"].get("steps_per_map")):
            rng += f" ({per_map(data['attrs']['steps_per_map'])}, every point)"
        lines.append(f"  {c:<28s} {rng}")
    lines += _failed_points(data, outcome)
    return "\n".join(lines)


#: the most failed points a sweep's summary names one by one
NAMED_FAILURES = 10


def _failed_points(data: dict, outcome: np.ndarray) -> list[str]:
    """One line per outcome other than ``ok`` naming its points by their parameter values
    (``  no_fixed_point at slope.angle_deg = 1.2; 1.4``; the first :data:`NAMED_FAILURES`,
    then how many more)."""
    params = [(p, np.asarray(data["points"][f"param/{p}"])) for p, _ in data["axes"]]
    out = []
    for kind in dict.fromkeys(str(k) for k in outcome if k != "ok"):
        idx = np.flatnonzero(outcome == kind)
        named = "; ".join(", ".join(f"{p} = {num(v[i]) if v.dtype.kind in 'fi' else v[i]}"
                                    for p, v in params) for i in idx[:NAMED_FAILURES])
        more = f" (and {idx.size - NAMED_FAILURES} more)" if idx.size > NAMED_FAILURES else ""
        out.append(f"  {kind} at {named}{more}")
    return out
