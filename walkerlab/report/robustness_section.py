"""The report's robustness section, from a loaded ``robustness.h5``
(:class:`walkerlab.io.schemas.robustness.RobustnessData`) and, when the scene ran it, a loaded
``basin.h5`` (the basin's area, :mod:`walkerlab.analysis.robustness.basin_area`) only."""

from __future__ import annotations

import math

from walkerlab.io.schemas.robustness import per_unit
from walkerlab.report.markdown import num, table

_LABEL = {"slope": "slope change", "floor_height": "floor height step",
          "push": "mid-stance push", "lateral_push": "sideways push at heel strike"}


def _mm(lo: float, hi: float, scale: float = 1000) -> str:
    if not math.isfinite(hi):
        return f"≥ {num(scale * lo, 3)} (none falls up to the search cap)"
    return f"{num(scale * lo, 3)} (falls at {num(scale * hi, 3)})"


def _contact_steps(r) -> list[str]:
    """The contact model's step-down/up beside the rigid model's (when asked for)."""
    if not math.isfinite(r.scalars.get("contact_step_down_m/lo", math.nan)):
        return []
    return ["- the same for the contact model (patches at the step's height, from its own "
            "periodic gait): step-down "
            f"{_mm(r['contact_step_down_m/lo'], r['contact_step_down_m/hi'])} mm; step-up "
            f"{_mm(r['contact_step_up_m/lo'], r['contact_step_up_m/hi'])} mm."]


def _unstable(r) -> list[str]:
    """A line for an unstable gait (a multiplier outside the unit circle: infinite norms)."""
    if all(math.isfinite(r.gsn[d]) for d in r.disturbances):
        return []
    return ["- the gait is unstable (a multiplier outside the unit circle): the undisturbed "
            "walker leaves it within the survival steps, so its sensitivity norms are "
            "infinite and no disturbance is survived (each bracket's 0 falls too)."]


def _lateral_pushes(r) -> list[str]:
    """The largest sideways pushes (a walker in 3D: ``push_lateral_*`` in the artifact),
    as the hip's lateral velocity change [m/s] and the impulse [N·s]."""
    if "push_lateral_kg" not in r.scalars:
        return []
    kg = r["push_lateral_kg"]

    def side(name: str) -> str:
        lo, hi = r[f"push_lateral_{name}_m_per_s/lo"], r[f"push_lateral_{name}_m_per_s/hi"]
        return f"{_mm(lo, hi, 1)} m/s ({num(kg * lo, 3)} N·s)"
    return ["- largest sideways push survived (an impulsive push at the hip along the hip "
            "axis just after heel strike, the stance foot pinned; as the hip's lateral "
            f"velocity change, and its impulse at {num(kg, 3)} N·s per m/s): toward the "
            f"swing leg's side {side('out')}, toward the stance leg's side {side('in')}."]


def _basin_line(a) -> list[str]:
    """The basin's area ``a`` (:class:`walkerlab.analysis.robustness.basin_area.BasinArea`) in the
    basin map's slice (when the scene ran ``basin``)."""
    if a is None:
        return []
    x0, x1, y0, y1 = a.box
    where = (f"the box {a.x_axis} {num(x0)}…{num(x1)} {a.x_unit} × {a.y_axis} {num(y0)}…"
             f"{num(y1)} {a.y_unit} of the basin map ({a.cells} cells)")
    if not a.exists:
        return [f"- basin of attraction: the gait's cell of {where} does not reach the gait "
                f"(no basin around it in this slice; {num(100 * a.fraction, 3)} % of the "
                "cells reach it)."]
    return [f"- basin of attraction: {num(100 * a.fraction, 3)} % of {where} reaches the "
            f"period-1 gait, an area of {num(a.area, 3)} {a.x_unit}·{a.y_unit}.  An area in "
            "the section depends on its coordinates: compare walkers only on the same axes "
            "and box."]


def robustness_section(arts: dict, basin_area=None) -> list[str]:
    """|lambda|max and GSN in two state coordinates, the MFPT at the scene's sigma, the
    largest step-down/up (rigid model; empty when the scene ran no robustness stage), and
    the basin's area ``basin_area`` when the scene ran ``basin``."""
    r = arts.get("robustness")
    if r is None:
        return []
    lam = r.max_abs_multiplier
    rows = [[f"{_LABEL.get(d, d)} [{per_unit(r.units[d])}]", r.gsn[d],
             f"{abs(r.gsn[d] - r.gsn_nonlinear[d]) / r.gsn[d]:.0e}" if math.isfinite(r.gsn[d])
             else "unstable gait: no finite norm",
             r.state_norm["absolute"][d], r.state_norm["relative"][d]] for d in r.disturbances]
    m, se = r["mfpt_steps"], r["mfpt_steps_stderr"]
    mfpt = (f"≥ {num(r['montecarlo_walks'])} walks reached the step cap (no fall)"
            if not math.isfinite(m) else f"{num(m)} ± {num(se)} steps (standard error)")
    return ["## Robustness (rigid model; the contact model where it says so)", "",
            f"- largest |Floquet multiplier|: {num(lam['absolute'])} in absolute leg angles, "
            f"{num(lam['relative'])} in angles relative to the stance leg (the Jacobians "
            "are similar matrices: the multipliers do not depend on the coordinates).",
            f"- MFPT on per-step random slopes, σ = {num(r['sigma_rad'])} rad (Monte Carlo, "
            f"{num(r['montecarlo_walks'])} walks, {num(r['montecarlo_falls'])} fell): {mfpt}.",
            f"- largest single step-down survived: {_mm(r['step_down_m/lo'], r['step_down_m/hi'])}"
            f" mm; step-up: {_mm(r['step_up_m/lo'], r['step_up_m/hi'])} mm (bisection).",
            *_contact_steps(r), *_unstable(r),
            "- largest mid-stance push survived (an impulsive horizontal push at the hip when "
            "the stance leg is vertical, the stance foot pinned; as the hip's velocity change): "
            f"forward {_mm(r['push_forward_m_per_s/lo'], r['push_forward_m_per_s/hi'], 1)} "
            f"m/s, backward {_mm(r['push_backward_m_per_s/lo'], r['push_backward_m_per_s/hi'], 1)}"
            " m/s.", *_lateral_pushes(r), *_basin_line(basin_area), "",
            "Gait sensitivity norm (Hobbelen & Wisse 2007; indicators step time, step length, "
            f"stance angle{', step width' if 'push_lateral_kg' in r.scalars else ''} at heel "
            "strike), with the relative difference to the nonlinear "
            "response to a small impulse, and the norm with the post-impact state as "
            "indicator in two state coordinates.  Jin et al. (2021, R. Soc. Open Sci. 8: "
            "201122) caution that local measures like this can rank walkers differently in "
            "different state coordinates: compare walkers only in one stated choice.", "",
            table(["disturbance", "GSN", "linear vs nonlinear", "state norm (absolute)",
                   "state norm (relative)"], rows), ""]


def mfpt_section(arts: dict) -> list[str]:
    """The MFPT at each sigma of ``walkerlab mfpt`` (Monte Carlo and mesh), each mesh value
    that did not converge on refinement said so (empty when the scene ran no mfpt)."""
    d = arts.get("mfpt")
    if d is None:
        return []
    notes = d.mesh_notes()
    rows = [[num(float(s)), num(float(m)), num(float(me)), why or ("converged" if
                                                                   math.isfinite(me) else "-")]
            for s, m, me, why in zip(d.sigma_rad, d["mfpt_steps_montecarlo"],
                                     d["mfpt_steps_mesh"], notes)]
    out = ["## Mean first-passage time (`walkerlab mfpt`)", "",
           "Steps before the fall on per-step random slopes of standard deviation σ "
           "(Monte Carlo: censored geometric estimate; mesh: the step map's Markov chain "
           "on a refined mesh of visited states, Byl & Tedrake 2009).", "",
           table(["σ [rad]", "Monte Carlo [steps]", "mesh [steps]", "mesh refinement"], rows),
           ""]
    if any(notes):
        out += ["**The mesh MFPT did not converge on refinement at σ = "
                + ", ".join(num(float(s)) for s, w in zip(d.sigma_rad, notes) if w)
                + " rad**: its values there are as uncertain as their last change.", ""]
    return out
