"""Plain-text summaries of artifacts, printed by the CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import open_artifact
from walkerlab.report.markdown import num
from walkerlab.units import for_artifact


def _fmt_mult(re, im) -> str:
    return ", ".join(f"{a:+.6f}{b:+.6f}j" if abs(b) > 0 else f"{a:+.6f}" for a, b in zip(re, im))


def zero_multipliers_text(re, im) -> str:
    """Why some Floquet multipliers are 0: the map lands on the heel-strike surface (and, for a
    kneed walker, on the straight-knee surface; for the simplest walker, whose swing leg has
    no mass, the post-impact swing rate is a function of the stance-leg state)."""
    n0 = int(np.sum(np.hypot(re, im) < 1e-9))
    if n0 <= 1:
        return "one multiplier is 0 by construction: the map lands on the heel-strike surface"
    return (f"{n0} multipliers are 0 by construction: the map lands on the heel-strike surface "
            f"and the impact fixes {n0 - 1} more combination(s) of the state (e.g. a kneed "
            "walker's straight, locked swing knee; the simplest walker's massless swing leg, "
            "whose rate after heel strike follows from the stance leg's)")


def fixedpoint_text(path: Path) -> str:
    """Fixed point by leg name with units, step period, Floquet multipliers, verdict."""
    with open_artifact(path, "fixedpoint") as f:
        u = for_artifact(f)
        names = [str(n) for n in f.attrs["state_names"]]
        legs = json.loads(f.attrs["legs_by_role"]) if "legs_by_role" in f.attrs else {}
        lines = [f"fixed point ({f.attrs['model']}, {f.attrs['variant']} equations), "
                 "state just after heel strike:"]
        for n in names:
            coord = n.rsplit("_", 1)[0]
            role = next((r for r in sorted(legs, key=len, reverse=True)
                         if coord == r or coord.startswith(r + "_")), None)
            where = f"({legs[role]}, {role} leg)" if role else "(not on a leg)"
            unit = f["fixed_point/" + n].attrs["unit"]
            lines.append(f"  {n:<14s} {where} {f['fixed_point/' + n][()]: .10f} {unit}")
        lines.append(f"  step period     {f['step_period'][()]:.10f} {u.time}")
        lines.append(f"  residual        {f['residual'][()]:.2e}  (max |P(x*) - x*|)")
        re, im = f["floquet/variational/real"][()], f["floquet/variational/imag"][()]
        lines.append(f"Floquet multipliers (variational): {_fmt_mult(re, im)}")
        re2, im2 = f["floquet/finite_difference/real"][()], f["floquet/finite_difference/imag"][()]
        lines.append(f"Floquet multipliers (finite diff.): {_fmt_mult(re2, im2)}")
        lines.append(f"  max difference {f['floquet/max_difference'][()]:.2e}")
        mod = float(np.max(np.hypot(re, im)))
        verdict = "STABLE" if f["floquet/stable"][()] else "UNSTABLE"
        lines.append(f"verdict: {verdict} (largest |multiplier| = {mod:.6f}; "
                     f"{zero_multipliers_text(re, im)})")
        lines += gaits_text(f)
    return "\n".join(lines)


_GAIT_SOURCES = {"initial_guess": "root finder from the initial guess",
                 "seed": "root finder from a scale-free seed",
                 "deflation": "deflated root finder near the other gait"}


def gaits_text(f) -> list[str]:
    """Lines on the period-1 gaits recorded in an open ``fixedpoint.h5`` (every gait found,
    the one selected by ``fixedpoint.gait`` marked ``*``, and why)."""
    if "gaits" not in f:
        return []
    u = for_artifact(f)
    labels = [str(s) for s in f.attrs["gaits"]]
    sel = str(f.attrs["gait"])
    lines = [f"period-1 gaits found: {len(labels)}" + (
        "" if len(labels) > 1 else " (the other gait of the long/short-period pair, if it "
        "exists, was not found)")]
    for lab in labels:
        g = f[f"gaits/{lab}"]
        mod = float(np.max(np.hypot(g["floquet/variational/real"][()],
                                    g["floquet/variational/imag"][()])))
        lines.append(f"  {'*' if lab == sel else ' '} {lab.replace('_', '-'):<12s} step period "
                     f"{g['step_period'][()]:.6f} {u.time}, max |multiplier| {mod:.4g}, "
                     f"{'stable' if g['floquet/stable'][()] else 'UNSTABLE'} "
                     f"({_GAIT_SOURCES.get(str(g.attrs['source']), g.attrs['source'])})")
    notes = json.loads(f.attrs.get("gait_notes", "[]"))
    lines.append(f"selected (fixedpoint.gait: {f.attrs['gait_policy']}): "
                 f"{sel.replace('_', '-')} gait" + ("; " + "; ".join(notes) if notes else ""))
    return lines


#: how a rigid run that did not complete its strides ended, as a verb
_ENDED = {"fall": "fell", "solver_failure": "stopped by a solver failure",
          "t_final": "stopped (a step took longer than max_step_time_s)"}


def simulate_ending(path: Path) -> str | None:
    """``"fell after 17 heel strikes (8.5 strides of the 20 asked)"`` for a run that did not
    complete its strides; None for one that did."""
    with open_artifact(path, "simulate") as f:
        term = str(f.attrs["termination"])
        if term == "heel_strike":
            return None
        n = int(np.sum(f["steps"]["termination"][()] == b"heel_strike"))
        asked = int(f.attrs["strides_requested"])
    return (f"{_ENDED.get(term, f'ended by {term}')} after {n} heel strike"
            f"{'' if n == 1 else 's'} ({n / 2:g} strides of the {asked} asked)")


def simulate_text(path: Path) -> str:
    """Steps completed, per-step period/length/speed, energy; for a run that did not
    complete its strides, only how it ended (:func:`simulate_ending`)."""
    ending = simulate_ending(path)
    if ending is not None:
        return ending
    with open_artifact(path, "simulate") as f:
        u = for_artifact(f)
        s = f["steps"]
        lines = [f"simulated {f.attrs['strides_requested']} strides: "
                 f"{int(np.sum(s['termination'][()] == b'heel_strike'))} heel strikes"]
        if u.nondimensional:
            lines.append(f"  ({u.sentence()})")
        lines.append(f"  mean step period  {num(f['summary/mean_period_s'][()], 7)} {u.time}")
        lines.append(f"  mean step length  {num(f['summary/mean_step_length_m'][()], 7)} "
                     f"{u.length}")
        lines.append(f"  mean hip speed    {num(f['summary/mean_hip_speed_m_per_s'][()], 7)} "
                     f"{u.speed}")
        lines.append(f"  mean total energy {num(f['summary/mean_total_energy_J'][()], 7)} "
                     f"{u.energy} (potential from the first stance foot)")
        lines.append(f"  RHS evaluations   {int(f['summary/nfev'][()])}, "
                     f"integration {num(f['summary/wall_time_s'][()], 3)} s (wall clock)")
    return "\n".join(lines)


def contact_text(path: Path) -> str:
    """Summary of a contact-sim artifact."""
    with open_artifact(path, "contact-sim") as f:
        kind = str(f.attrs.get("outcome", "?"))
        why = str(f.attrs.get("outcome_message", f.attrs.get("termination", "")))
        # the message only when it says more than the outcome's name
        lines = [f"contact walker: outcome {kind}" + (f" ({why})" if why and why != kind
                                                      else "")]
        if "initial_rate_scale" in f and "adjust" in f:  # --adjust: the scale it found
            s = np.atleast_1d(f["initial_rate_scale"][()])
            # per named coordinate: the rates of leg1 (swing) and leg2 (stance) at the start
            names = ([str(v) for v in f["rate"][()].astype(str)] if "rate" in f
                     else ["leg1 rates", "leg2 rates"])
            kept = str(f["adjust"].attrs.get("kept", "adjusted"))
            why = str(f["adjust"].attrs.get("kept_reason", ""))
            found = np.atleast_1d(f["adjust/scale"][()]) if "scale" in f["adjust"] else s
            if kept == "scene":
                lines.append("--adjust: kept the scene's initial rate scale ("
                             + "; ".join(f"{n} × {v:.4g}" for n, v in zip(names, s))
                             + "), which walks better than the adjusted one ("
                             + ", ".join(f"{v:.4g}" for v in found) + f"): {why}")
            else:
                lines.append("--adjust: kept the adjusted initial rate scale: "
                             + "; ".join(f"{n} × {v:.4g}" for n, v in zip(names, s))
                             + (f" ({why})" if why else ""))
        if "summary" in f:
            for k in f["summary"]:
                ds = f["summary"][k]
                unit = str(ds.attrs.get("unit", ""))
                lines.append(f"  {k:<32s} {num(ds[()])}" + (f" {unit}" if unit not in
                                                              ("", "-") else ""))
            if "wall_time_s" in f["summary"] and "wall_time_s" in f.attrs:
                lines.append(f"  (wall_time_s: the walking run's integration; the whole stage "
                             f"took {num(f.attrs['wall_time_s'], 3)} s)")
        if "periodic_gait" in f and "step_period" not in f["periodic_gait"]:
            g = f["periodic_gait"]
            lines.append(f"periodic contact gait: not found ({g.attrs.get('outcome', '?')}: "
                         f"{g.attrs.get('message', '')})")
        elif "periodic_gait" in f:
            g = f["periodic_gait"]
            mult = g["multipliers/real"][()] + 1j * g["multipliers/imag"][()]
            u = for_artifact(f)
            lines.append(f"periodic contact gait: step period {num(g['step_period'][()], 6)} "
                         f"{u.time}, step length {num(g['step_length'][()], 6)} {u.length}, "
                         f"{'stable' if g['stable'][()] else 'unstable'}")
            lines.append("  Floquet multipliers: " + ", ".join(f"{m:.5f}" for m in mult[:3])
                         + f" (+{len(mult) - 3} fast contact modes ~0)")
    return "\n".join(lines)


def compare_text(path: Path) -> str:
    """Key errors of a compare artifact: largest angle and rate error contact − ideal per
    coordinate, the limit cycles' mean distance, and the gait metrics side by side."""
    with open_artifact(path, "compare") as f:
        u = for_artifact(f)
        g = f["errors"]
        t = g["time"][()]
        lines = [f"errors contact - ideal over the common span 0-{num(t[-1], 4)} {u.time}:",
                 f"  max |angle error| {num(g['max_abs_angle'][()], 3)} rad, "
                 f"max |rate error| {num(g['max_abs_rate'][()], 3)} {u.rate}"]
        for n in [str(x) for x in g.attrs["coordinates"]]:
            ds = g[f"coordinates/{n}"]
            lines.append(f"  {n:<22s} max |error| {num(np.max(np.abs(ds[()])), 3)} "
                         f"{ds.attrs['unit']}")
        if "limit_cycle_distance" in g:
            lines.append("  limit cycles, mean distance ideal -> contact: " + ", ".join(
                f"{k} {num(g['limit_cycle_distance'][k][()], 3)}"
                for k in g["limit_cycle_distance"]))
        if "metrics" in f and {"ideal", "contact"} <= set(f["metrics"]):
            m = f["metrics"]
            lines.append(f"  {'gait metric':<22s} {'ideal':>11s} {'contact':>11s}")
            for k in m["ideal"]:
                if k in m["contact"]:
                    unit = str(m["ideal"][k].attrs.get("unit", ""))
                    lines.append(f"  {k:<22s} {num(m['ideal'][k][()]):>11s} "
                                 f"{num(m['contact'][k][()]):>11s}"
                                 + (f" {unit}" if unit not in ("", "-") else ""))
    return "\n".join(lines)


def _ms(t: float) -> str:
    return f"{num(1e3 * t, 3)} ms"


def workprecision_choice(attrs) -> str:
    """The work-precision study's choice for one model (attributes of its group), in one
    sentence that says how noisy the timing was: a setting is named fastest only when its
    slowest run beats every other qualifying setting's fastest run; otherwise the
    timings cannot separate them."""
    if "best_method" not in attrs:
        return f"no setting reaches the target error {attrs['target_error']:.0e}."
    target = f"{attrs['target_error']:.0e}"  # settings, printed as given
    name = f"{attrs['best_method']} rtol {attrs['best_rtol']:.0e}"
    if "best_separated" not in attrs:  # an artifact from before the spread was stored
        return (f"fastest median run reaching the target error {target}: {name} "
                f"({_ms(attrs['best_time'])}; timing spread not recorded).")
    spread = (f"median {_ms(attrs['best_time'])}, {_ms(attrs['best_time_min'])}–"
              f"{_ms(attrs['best_time_max'])} over {int(attrs['best_repeats'])} runs")
    if bool(attrs["best_separated"]):
        return (f"fastest setting reaching the target error {target}: **{name}** ({spread}; "
                "faster than every run of any other setting that reaches it).")
    tied = [f"{m} rtol {r:.0e} ({_ms(a)}–{_ms(b)})" for m, r, a, b in zip(
        attrs["tied_methods"], attrs["tied_rtol"], attrs["tied_time_min"],
        attrs["tied_time_max"])]
    return (f"the timings cannot separate the settings reaching the target error {target}: "
            + ", ".join(tied) + " (min–max wall time over the repeats overlap, or a setting "
            "was timed once); the lowest median is " + name + ".")


def workprecision_text(path: Path) -> str:
    """One line per model of a workprecision artifact: its choice and the timing noise."""
    with open_artifact(path, "workprecision") as f:
        return "\n".join(f"{model}: {workprecision_choice(f[model].attrs)}" for model in f)
