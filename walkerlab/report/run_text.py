"""Plain-text summaries of runs, printed by the CLI: a rigid walk (``simulate``), a contact
run (``contact-sim``), the comparison of the two views (``compare``), the mean first-passage
time (``mfpt``) and the rigid limit of the contact model (``rigid-limit``).

Each takes a loaded artifact (or its summary dict) and returns text; the fixed point's
summaries are :mod:`walkerlab.report.text`'s, which re-exports these functions.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from walkerlab.integrate.ends import CONTACT_WALKED
from walkerlab.report.markdown import num
from walkerlab.units import per_map

if TYPE_CHECKING:  # the loaded artifacts these summaries print
    from walkerlab.io.schemas.compare import Comparison
    from walkerlab.io.schemas.contact_sim import ContactSimArtifact
    from walkerlab.io.schemas.simulate import SimulateArtifact


#: how a rigid run that did not complete its strides ended, as a verb
_ENDED = {"fall": "fell", "solver_failure": "stopped by a solver failure",
          "t_final": "stopped (a step took longer than max_step_time_s)",
          "no_heel_strike": "made no step (no_heel_strike)",
          "trip": "tripped (the swing foot went into the profile)"}


def simulate_ending(sim: SimulateArtifact) -> str | None:
    """``"fell after 17 heel strikes (8.5 strides of the 20 asked)"`` for a run that did not
    complete its strides (a trip on a height profile: where and when the swing foot met
    it); None for one that did."""
    if sim.termination == "heel_strike":
        return None
    n = sim.heel_strike_count()
    out = (f"{_ENDED.get(sim.termination, f'ended by {sim.termination}')} after {n} heel "
           f"strike{'' if n == 1 else 's'} ({n / 2:g} strides of the "
           f"{sim.strides_requested} asked)")
    s = sim.summary
    if sim.termination == "trip" and "trip_time_s" in s:
        u = sim.units
        out += (f": at t = {num(s['trip_time_s'], 6)} {u.time}, x = {num(s['trip_x_m'], 6)} "
                f"{u.length}, y = {num(s['trip_y_m'], 6)} {u.length}")
    return out


def simulate_text(sim: SimulateArtifact) -> str:
    """Steps completed, per-step period/length/speed, energy; for a run that did not
    complete its strides, only how it ended (:func:`simulate_ending`)."""
    ending = simulate_ending(sim)
    if ending is not None:
        return ending
    u, s = sim.units, sim.summary
    n = sim.heel_strike_count()
    if "ground_steps" in s:  # a finite foothold list, shorter than the strides asked
        lines = [f"the ground ends after its {int(s['ground_steps'])} footholds (terrain."
                 f"periodic: false): {n} heel strikes of the {2 * sim.strides_requested} "
                 f"asked ({sim.strides_requested} strides)"]
    elif n < 2 * sim.strides_requested:  # every step a heel strike, but fewer than asked
        lines = [f"the walk ended at the end of its terrain (the profile's last point or the "
                 f"last foothold: the next step would land past it) after {n} heel "
                 f"strike{'' if n == 1 else 's'} ({n / 2:g} stride{'' if n == 2 else 's'} of "
                 f"the {sim.strides_requested} asked)"]
    else:
        lines = [f"simulated {sim.strides_requested} strides: {n} heel strikes"]
    if u.nondimensional:
        lines.append(f"  ({u.sentence()})")
    lines.append(f"  mean step period  {num(s['mean_period_s'], 7)} {u.time}")
    lines.append(f"  mean step length  {num(s['mean_step_length_m'], 7)} {u.length}")
    lines.append(f"  mean hip speed    {num(s['mean_hip_speed_m_per_s'], 7)} {u.speed}")
    lines.append(f"  mean total energy {num(s['mean_total_energy_J'], 7)} "
                 f"{u.energy} (the mean of the samples over all {n} steps; potential "
                 "from the first stance foot; compare's E_avg: a time average over the "
                 "first 5)")
    if "midstance_scuff_depth_m" in s:  # the ideal model's foot-through, ignored
        lines.append(f"  mid-stance scuff  {num(s['midstance_scuff_depth_m'], 3)} {u.length} "
                     "deep at most (straight legs' swing foot below the profile as it passes "
                     "the stance foot: ignored, as the ideal model does)")
    lines.append(f"  RHS evaluations   {int(s['nfev'])}, "
                 f"integration {num(s['wall_time_s'], 3)} s (wall clock)"
                 + (f" of the run kept ({int(s['cut_from_strides'])} strides asked; the "
                    f"means above: its first {sim.strides_requested})"
                    if "cut_from_strides" in s else ""))
    return "\n".join(lines)


def contact_text(c: ContactSimArtifact) -> str:
    """Summary of a contact-sim artifact."""
    kind = c.outcome
    why = c.outcome_message
    # the message only when it says more than the outcome's name
    lines = [f"contact walker: outcome {kind}" + (f" ({why})" if why and why != kind else "")]
    if c.walks is False and kind in CONTACT_WALKED:  # the verdict from the steps says more
        lines.append(f"walks: no ({c.walks_reason})")
    if c.adjust is not None:  # --adjust: the scale it found
        s = np.atleast_1d(c.initial_rate_scale)
        # per named coordinate: the rates of leg1 (swing) and leg2 (stance) at the start
        names = c.rate_names or ["leg1 rates", "leg2 rates"]
        kept, why = str(c.adjust.get("kept", "adjusted")), str(c.adjust.get("kept_reason", ""))
        found = np.atleast_1d(c.adjust.get("scale", s))
        if kept == "scene":  # the adjusted start walked no better
            lines.append("--adjust: kept the scene's initial rate scale ("
                         + "; ".join(f"{n} × {v:.4g}" for n, v in zip(names, s))
                         + "), not the adjusted one ("
                         + ", ".join(f"{v:.4g}" for v in found) + f"): {why}")
        else:
            lines.append("--adjust: kept the adjusted initial rate scale: "
                         + "; ".join(f"{n} × {v:.4g}" for n, v in zip(names, s))
                         + (f" ({why})" if why else ""))
        for k in ("gave_up", "note"):  # a search that spent its runs, or cut short
            if str(c.adjust.get(k, "")):
                lines.append(f"--adjust: {c.adjust[k]}")
    for k, (v, unit) in c.summary.items():
        lines.append(f"  {k:<32s} {num(v)}" + (f" {unit}" if unit not in ("", "-") else ""))
    if "wall_time_s" in c.summary and np.isfinite(c.stage_wall_time_s):
        lines.append(f"  (wall_time_s: the walking run's integration; the whole stage "
                     f"took {num(c.stage_wall_time_s, 3)} s)")
    per = c.periodic
    if per is not None and not per.found:
        lines.append(f"periodic contact gait: not found ({periodic_not_found(per.outcome)}: "
                     f"{per.message})")
    elif per is not None:
        lines.append(f"periodic contact gait: step period {num(per.step_period_s, 6)} "
                     f"{c.units.time}, step length {num(per.step_length_m, 6)} "
                     f"{c.units.length}, "
                     f"{'stable' if per.stable else 'unstable'}")
        lines.append("  " + contact_multiplier_words(per, 5))
    return "\n".join(lines)


def contact_multiplier_words(per, digits: int) -> str:
    """``"Floquet multipliers per stride: 1.00180 (heading), 0.53995, ... (+10 fast contact
    modes ~0)"``: the contact periodic gait's (``per``, a loaded
    :class:`~walkerlab.io.schemas.contact_sim.PeriodicGait`) slow multipliers (modulus above
    1e-3, at least three) to ``digits`` decimals, the largest's mode named when it is above
    1 (a walker in 3D's heading), and how many fast contact modes there are."""
    mult, modes = per.multipliers, per.multiplier_modes
    n = min(len(mult), max(3, int(np.sum(np.abs(mult) > 1e-3))))
    shown = [f"{m:.{digits}f}" for m in mult[:n]]
    if modes and abs(mult[0]) > 1.0:
        shown[0] += f" ({modes[0]})"
    return (f"Floquet multipliers {per_map(per.steps_per_map)}: " + ", ".join(shown)
            + f" (+{len(mult) - n} fast contact modes ~0)")


def _e_avg_span(metrics: dict) -> str:
    """The steps compare's E_avg is a time average over, as each run's metrics say
    (``E_avg_steps``; an older artifact without it: the first 5): "the first 2 steps of each
    run", or each run's own count where they differ (a contact run of more steps than the
    rigid one)."""
    def steps(model):
        n = metrics.get(model, {}).get("E_avg_steps")
        return int(n) if n is not None and np.isfinite(n) else 5
    ni, nc = steps("ideal"), steps("contact")
    if ni == nc:
        return f"the first {ni} steps of each run"
    return f"the first {ni} steps of the ideal run and the first {nc} of the contact run"


def periodic_not_found(outcome: str) -> str:
    """Why a contact run's own periodic gait was not found, by the search's ``outcome`` (a
    :class:`walkerlab.analysis.contact.step_map.PeriodicGaitError` kind), in the words the
    summary, the gait table and the contact section share: a search a wall-clock limit cut
    short is named so (not a property of the scene), as is one its work bound ended."""
    if outcome == "time_limit":
        return ("time_limit: the search was cut short by a wall-clock limit, "
                "contact_sim.periodic_time_limit_s, not a property of the scene")
    if outcome == "work_limit":
        return ("work_limit: the search spent its work bound, "
                "contact_sim.periodic_max_step_maps")
    return outcome


def compare_text(c: Comparison) -> str:
    """Key errors of a compare artifact: largest angle and rate error contact − ideal per
    coordinate, the limit cycles' mean distance, and the gait metrics side by side."""
    u = c.units
    cut = getattr(c, "contact_cut_short", "")
    lines = ([f"the contact run was cut short by a wall-clock limit ({cut}): compared over "
              "what it ran before the limit (time_limit; not kept, the next run recomputes "
              "it)"] if cut else [])
    lines += [f"errors contact - ideal over the common span 0-{num(c.time[-1], 4)} {u.time}:",
             f"  max |angle error| {num(c.max_abs_angle_rad, 3)} rad, "
             f"max |rate error| {num(c.max_abs_rate_rad_per_s, 3)} {u.rate}"]
    for n, e in c.errors.items():
        lines.append(f"  {n:<22s} max |error| {num(np.max(np.abs(e)), 3)} "
                     f"{c.error_units[n]}")
    if c.limit_cycle_distance:
        lines.append("  limit cycles, mean distance ideal -> contact: " + ", ".join(
            f"{k} {num(v, 3)}" for k, v in c.limit_cycle_distance.items()))
    m = c.metrics
    if {"ideal", "contact"} <= set(m):
        lines.append(f"  {'gait metric':<22s} {'ideal':>11s} {'contact':>11s}")
        for k in m["ideal"]:
            if k in m["contact"]:
                unit = c.metric_units.get(k, "")
                lines.append(f"  {k:<22s} {num(m['ideal'][k]):>11s} "
                             f"{num(m['contact'][k]):>11s}"
                             + (f" {unit}" if unit not in ("", "-") else ""))
        if "E_avg_J" in m["ideal"]:
            lines.append(f"  (E_avg: time averages over {_e_avg_span(m)} (E_avg_steps); "
                         "simulate's 'mean total energy' is the mean of its samples over all "
                         "its steps)")
    return "\n".join(lines)


def mfpt_text(summary: dict) -> str:
    """One line per sigma of an MFPT study (:func:`walkerlab.studies.mfpt.mfpt_summary`):
    the Monte Carlo MFPT with its standard error and its falls, the mesh MFPT and why it may
    be off; a method that was not run is left out (no "mesh nan")."""
    n = len(summary["sigma_rad"])
    nan = [float("nan")] * n
    heights = summary.get("sigma_m")
    lines = []
    for i in range(n):
        label = (f"height sigma {1e3 * heights[i]:.4g} mm" if heights is not None
                 else f"sigma {summary['sigma_rad'][i]:.4g} rad")
        m, se = summary["mfpt_steps_montecarlo"][i], \
            summary.get("mfpt_steps_montecarlo_stderr", nan)[i]
        walks, falls = (summary.get(k, nan)[i] for k in ("montecarlo_walks",
                                                         "montecarlo_falls"))
        parts = []
        if np.isinf(m):
            parts.append(f"MFPT Monte Carlo: none of {walks:.0f} walks fell (beyond their "
                         "step cap)" if np.isfinite(walks) else "MFPT Monte Carlo: no walk fell")
        elif np.isfinite(m):
            parts.append(f"MFPT Monte Carlo {m:.4g}" + (f" ± {se:.2g}" if np.isfinite(se) else "")
                         + " steps" + (f" ({falls:.0f} of {walks:.0f} walks fell)"
                                       if np.isfinite(falls) and np.isfinite(walks) else ""))
        me = summary.get("mfpt_steps_mesh", nan)[i]
        if np.isfinite(me):
            why = summary.get("mesh_note", [""] * n)[i]
            parts.append(f"mesh {me:.4g} steps" + (f" - mesh {why}" if why else ""))
        lines.append(f"{label}: " + (", ".join(parts) or "no MFPT computed"))
    return "\n".join(lines)


def rigid_limit_text(d: dict) -> list[str]:
    """The convergence table of a loaded ``rigid_limit.h5`` (``d``:
    :func:`walkerlab.io.schemas.rigid_limit.load_rigid_limit`): per ``kappa`` the period and
    step-length gaps to the rigid gait [ms, mm], the stored observed orders, each multiplier."""
    gT = d["period"] - d["rigid_period"]
    gL = d["step_length"] - d["rigid_step_length"]
    oT, oL = d["observed_order"]["period"], d["observed_order"]["step_length"]
    lam = d["multipliers"]
    head = (f"{'kappa':>8} {'period gap [ms]':>16} {'order':>6} {'step gap [mm]':>14} "
            f"{'order':>6}  multipliers (rigid: "
            + ", ".join(f"{x:.4f}" for x in d["rigid_multipliers"]) + ")")
    out = [head]
    for i, k in enumerate(d["kappa"]):
        o1 = f"{oT[i - 1]:6.3f}" if i else " " * 6
        o2 = f"{oL[i - 1]:6.3f}" if i else " " * 6
        out.append(f"{k:8.3g} {gT[i] * 1e3:+16.4f} {o1} {gL[i] * 1e3:+14.4f} {o2}  "
                   + ", ".join(f"{x:.4f}" for x in lam[i]))
    return out
