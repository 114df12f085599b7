"""Report sections of the many-point studies: the bifurcation diagrams (over the slope and
over other fields, ``bifurcation --param``) and the basin of attraction."""

from __future__ import annotations

from types import ModuleType

import numpy as np

from walkerlab.report.markdown import num, printed, table
from walkerlab.units import per_map


# --------------------------------------------------------------------------- bifurcation
def bifurcation_section(arts: dict, onsets: dict, pub: ModuleType | None = None) -> list[str]:
    """Period-doubling onset from ``bifurcation.h5`` (when the scene ran that stage) and from
    each ``bifurcation_<field>.h5`` (``bifurcation --param``), the grid named by its field
    and unit (``arts``: loaded :class:`walkerlab.io.schemas.bifurcation.BifurcationSummary`
    by artifact key; ``onsets``: ``{artifact key: (period-doubling onset, fall onset)}`` in
    the grid's unit, NaN: none, :attr:`walkerlab.report.build.ReportInputs.bifurcation_onsets`)."""
    out = []
    b = arts.get("bifurcation")
    if b is not None:
        out += _bifurcation_lines(b, onsets["bifurcation"], pub)
    for key in sorted(k for k in arts if k.startswith("bifurcation_")):
        out += _bifurcation_lines(arts[key], onsets[key], None)
    return out


def _bifurcation_lines(b, onsets: tuple[float, float], pub: ModuleType | None) -> list[str]:
    from walkerlab.io.schemas.bifurcation import SLOPE_PATH  # light

    p, data, values, per = b.path, b.data, b.values, b.attractor_period
    path, unit = data["parameter_path"], data["parameter_unit"]
    onset, falls = onsets
    periods = sorted(set(int(v) for v in per if v > 0))
    mult = " ".join(filter(None, ("the most negative real Floquet multiplier",  # its map
                                  per_map(data.get("steps_per_map")))))
    if path == SLOPE_PATH:
        text = (f"period-doubling onset at slope {num(onset)}° ({num(np.radians(onset))} rad), "
                f"where {mult} crosses −1"
                if np.isfinite(onset) else "no period doubling on the grid")
        out = ["## Bifurcation over the slope", "",
               f"Grid {printed(values[0])}–{printed(values[-1])}° ({values.size} slopes): "
               f"{text}; steady-state periods seen: {periods}"
               + (f"; from {num(falls)}° on the walker falls (no steady gait)."
                  if np.isfinite(falls) else "; the walker walks up to the largest slope.")]
        rng = getattr(pub, "STABLE_SLOPE_RANGE_RAD", None)
        if rng is not None:
            out.append(f"Published ({pub.SHORT}): the period-1 gait is stable for "
                       f"{printed(rng[0])} < γ < {printed(rng[1])} rad "
                       f"({printed(round(np.degrees(rng[1]), 4))}°).")
        return out + [""]
    u = "" if unit in ("", "-") else f" {unit}"
    text = (f"period-doubling onset at {path} = {num(onset)}{u}, where {mult} crosses −1"
            if np.isfinite(onset)
            else "no period doubling on the grid")
    return [f"## Bifurcation over `{path}`", "",
            f"Grid {printed(values[0])}–{printed(values[-1])}{u} ({values.size} values, "
            f"`{p.name}`): {text}; steady-state periods seen: {periods}"
            + (f"; from {num(falls)}{u} on the walker falls (no steady gait)."
               if np.isfinite(falls) else "; the walker walks up to the largest value."), ""]


# --------------------------------------------------------------------------- basin
def basin_section(arts: dict) -> list[str]:
    """Outcome shares of ``basin.h5`` (when the scene ran that stage)."""
    b = arts.get("basin")
    if b is None:
        return []
    counts, xa, ya, xc, yc = b.counts, b.x_axis, b.y_axis, b.x, b.y
    xu, yu, start, max_steps = b.x_unit, b.y_unit, b.start, b.max_steps
    n = sum(counts.values())
    how = ("each cell a state just after a heel strike (the heel-strike image of a pre-impact "
           "state on the guard)" if start == "heel_strike"
           else "the other coordinates from the fixed point, projected on the heel-strike "
           "surface")
    rows = [[o.replace("_", " "), str(c), num(100 * c / n, 3)] for o, c in counts.items() if c]
    return ["## Basin of attraction", "",
            f"{xc.size} × {yc.size} cells over {xa} {printed(xc.min())}…{printed(xc.max())} {xu} × "
            f"{ya} {printed(yc.min())}…{printed(yc.max())} {yu} (cell centres), {how}; at most "
            f"{max_steps} steps a cell.  {num(100 * counts.get('converged', 0) / n, 3)} % of "
            "the cells reach the period-1 gait.", "",
            table(["outcome", "cells", "share [%]"], rows), ""]
