"""Report section of the figures: every figure the run folder holds, in the paper's order,
with its caption and, where it is long, its raw data folded underneath (the rigid walker's
per-step table, every work-precision point); from loaded artifacts only."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.report.markdown import details, num, table
from walkerlab.report.workprecision_section import workprecision_table
from walkerlab.units import Units

if TYPE_CHECKING:  # loaded artifacts (walkerlab.io.schemas)
    from walkerlab.io.schemas.simulate import SimulateArtifact


CAPTIONS = [  # paper order: Figs. 2 and 6, then 7-10, then the studies beyond the paper
    ("fig2_stick_ideal", "Fig. 2 — stick diagram of one gait cycle, ideal model."),
    ("fig6_stick_contact", "Fig. 6 — stick diagram of one gait cycle, contact model."),
    ("fig7_angles_rates", "Fig. 7 — angles and angular rates over the simulated strides."),
    ("fig8_errors", "Fig. 8 — error contact − ideal, angles and rates: left time-aligned "
     "(both at the same time since the start, so a different step period shows as a growing "
     "phase drift), right phase-aligned (both at the same fraction of the same step: the "
     "difference of the gaits themselves)."),
    ("fig9_limit_cycles", "Fig. 9 — limit cycles in the phase plane (rate vs angle; both "
                          "legs in each panel: one panel for straight legs, thigh and shank "
                          "panels for a kneed walker)."),
    ("fig10_energy", "Fig. 10 — kinetic, potential and total mechanical energy."),
    ("energy_ledger", "Energy ledger of the rigid walker: the sources (push-off, actuators' "
                      "positive work, gravity) and sinks (heel-strike and knee-strike "
                      "collisions, actuators' negative work, dampers) of each step, and the "
                      "cost of transport per step."),
    ("work_precision_ideal", "Work-precision diagram, ideal model."),
    ("work_precision_contact", "Work-precision diagram, contact model."),
    ("bifurcation", "Bifurcation diagram over the slope."),
    ("basin", "Basin of attraction: where each cell of the Poincaré-section slice goes "
              "(left) and how many steps the converged cells take (right)."),
    ("mfpt", "Mean first-passage time against the terrain's roughness, the per-step "
             "slope's σ or landing height's σ (`walkerlab mfpt`); "
             "open squares: mesh values whose refinement did not converge."),
    ("optimize", "Optimised step (direct collocation, `walkerlab optimize`): the torques "
                 "at the collocation points (left) and the link angles over the step "
                 "(middle; a five-link biped: the step as stop action, right; legs that "
                 "differ: the stride, its inner heel strike dotted)."),
]


def steps_table(sim: SimulateArtifact) -> str:
    """Per-step table of ``simulate.h5`` (period, step length, hip speed, impact loss)."""
    u, s = sim.units, sim.steps
    cols = ("period", "step_length", "hip_speed", "impact_energy_loss")
    head = [f"period [{u.time}]", f"step length [{u.length}]", f"hip speed [{u.speed}]",
            f"impact loss [{u.energy}]"]
    pushed = np.asarray((sim.ledger or {}).get("push_off_impulse", [0.0]), float)
    if "transition_energy_change" in s and np.nanmax(np.abs(pushed), initial=0.0) > 0:
        cols += ("transition_energy_change",)  # the push-off's gain, the collision's loss
        head += [f"net, push-off + heel strike [{u.energy}]"]
    rows = [[int(i), str(leg), *[num(s[c][k]) for c in cols], str(term)]
            for k, (i, leg, term) in enumerate(zip(s["step"], s["stance_leg"],
                                                   s["termination"]))]
    return table(["step", "stance leg", *head, "ended by"], rows)


def spring_law_note(scene) -> str:
    """A sentence when a joint-torque law of ``scene`` is a spring (stiffness, no
    reference to track, not scaled by a massless foot's mass - that one does no work): its
    work enters the ledger and the cost of transport as motor work without regeneration
    (what it stores counts as positive work when released), where a spring in
    ``walker.springs`` is passive (its energy is potential energy); "" when none is."""
    act = scene.walker.actuation if scene is not None else None
    springs = [f"walker.actuation.torques.{i} ({t.joint})"
               for i, t in enumerate(act.torques if act is not None else ())
               if t.law.stiffness_n_m_per_rad > 0 and t.law.reference is None
               and t.law.time_reference is None and t.scaled_by == "none"]
    if not springs:
        return ""
    return (f" {', '.join(springs)}: a spring-like torque law, counted as motor work, no "
            "regeneration - its positive work enters the cost of transport and its negative "
            "work is lost; a passive spring (energy stored and returned, no cost) is written "
            "in walker.springs (`springs:`).")


def energy_section(sim: SimulateArtifact, scene=None) -> list[str]:
    """The energy ledger of ``simulate.h5`` per step, and its closure (``scene``: its
    spring-like torque laws are named, :func:`spring_law_note`)."""
    import math

    led, u = sim.ledger, sim.units
    if not led:
        return []
    keys = ("push_off_work", "actuator_work_positive", "actuator_work_negative",
            "heel_strike_loss", "internal_collision_loss", "damper_work", "potential_work",
            "closure", "cost_of_transport")
    head = ["step", "push-off", "actuators +", "actuators -", "heel strike", "knee/foot",
            "dampers", "gravity+springs", "closure", "cost of transport"]
    rows = [[k, *[num(led[c][k]) for c in keys]] for k in range(len(led["closure"]))]
    cot = [v for v in led["cost_of_transport"] if math.isfinite(v)]
    mean = sum(cot) / len(cot) if cot else math.nan
    note = (" Flat feet: the ankle push-off's torque is in the actuator columns; the heel "
            "strike's loss includes the trailing ankle spring's energy (its massless foot "
            "leaves the ground and snaps to its rest angle); knee/foot is the foot slaps."
            if sim.samples is not None
            and any(c.endswith("_ankle_angle") for c in sim.samples.coordinates) else "")
    return [f"Cost of transport (positive actuator and push-off work + the potential energy "
            f"the slope releases, per weight and distance along the ground), mean over the "
            f"steps: **{num(mean)}**. Energies in {u.energy}; the collisions, dampers and "
            "negative actuator work are the sinks; closure = the energy change minus the "
            "sum of the terms." + spring_law_note(scene) + note, "",
            *details("Energy ledger per step (simulate.h5, ledger/)", table(head, rows))]


def ledger_section(scene, fig_dir: Path, rel: str, arts: dict) -> list[str]:
    """The rigid walker's energy ledger and cost of transport (``simulate.h5``): a section
    of its own, beside the gait (its figure and its per-step table); [] without a
    ledger."""
    if "simulate" not in arts:
        return []
    text = energy_section(arts["simulate"], scene)
    if not text:
        return []
    out = ["## Energy ledger and cost of transport", ""]
    png = Path(fig_dir) / "energy_ledger.png"
    if png.is_file():
        cap = dict(CAPTIONS)["energy_ledger"]
        out += [f"![{cap}]({rel}/{png.name})", "", f"*{cap}*", ""]
    return out + text


def optimize_lines(d, units: Units = Units()) -> list[str]:
    """The optimised step of a loaded ``optimize.h5`` in words (times, lengths, speeds and
    impulses in ``units``: the scene's system)."""
    import numpy as np

    t, m, v, imp = units.time, units.length, units.speed, units("N s")

    mu = float(np.max(np.abs(d.multipliers))) if len(d.multipliers) else float("nan")
    five_link = bool(d.phase_replays) and d.torque_names != ("hip",)  # contact: its PD law
    peaks = np.abs(np.asarray(d.torque).reshape(len(d.time), -1)).max(axis=0)
    peak = ", ".join(f"{n} {num(float(v))}" for n, v in zip(d.torque_names, peaks))
    closed = ("" if not np.isfinite(d.start_shift) else
              f" The torques are open loop and the gait unstable under them: from the "
              f"collocated start the step returns {num(d.collocated_start_error, 2)} away, so "
              f"the step is first closed by shooting under the same torques (start moved "
              f"{num(d.start_shift, 2)}, step period {num(d.replay_step_period_s, 9)} {t}), "
              f"then replayed.")
    return [f"IPOPT: {d.status} ({d.iterations} iterations, {num(d.wall_time_s, 3)} s). Step "
            f"period {num(d.step_period_s)} {t}, step length {num(d.step_length_m)} {m}, speed "
            f"{num(d.step_length_m / d.step_period_s)} {v}, push-off {num(d.push_off_n_s)} "
            f"{imp}, "
            f"peak torque [{d.torque_unit}]: {peak}; objective {d.objective_name} = "
            f"{num(d.objective)} {d.objective_unit}{cot_terms_text(d, units)}.{closed} Replayed on "
            f"the rigid model (the "
            f"torques as a function of time): return error {num(d.replay_error, 2)}, largest "
            f"|Floquet multiplier| {num(mu)}: "
            + ("**a gait**." if d.gait else f"**not a gait**: {not_a_gait_reason(d)}.")
            + phase_replay_text(d, units)
            + (f" In the contact model{' (the feed-forward + PD law)' if five_link else ''}"
               f": step period {num(d.contact_step_period_s)} {t} "
               f"({num(100 * (d.contact_step_period_s / d.step_period_s - 1), 2)} %)"
               + ("." if d.contact_outcome == "heel_strike"
                  else f" (the run ended short of its strides: {d.contact_outcome}).")
               if d.contact_step_period_s == d.contact_step_period_s
               else f" Contact model: {d.contact_outcome}.")
            + _phases_line(d, t),
            ""]


def _phases_line(d, t: str = "s") -> str:
    """The step's phases and their durations (a step of phases, e.g. a kneed walker's; a
    stride of legs that differ: each step's period too)."""
    if not getattr(d, "phase_names", ()):
        return ""
    parts = ", ".join(f"{n} {num(float(dt), 6)} {t}" for n, dt in zip(d.phase_names,
                                                                       d.phase_duration_s))
    steps = int(getattr(d, "steps", 1))
    stride = ""
    if steps > 1:  # legs that differ: the steps' own periods, the mean above
        per = len(d.phase_names) // steps
        each = ", ".join(num(float(sum(d.phase_duration_s[k * per:(k + 1) * per])), 9)
                         for k in range(steps))
        stride = (f" A stride of {steps} different steps (legs that differ; step period "
                  f"and length above: the mean step's; return error and multipliers: the "
                  f"stride map's): step periods {each} {t}.")
    return f" Phases (each with its own mesh and free duration): {parts}.{stride}"


def phase_replay_text(d, units: Units = Units()) -> str:
    """The phase-variable replays of a loaded ``optimize.h5`` in words (a step of phases:
    one law per phase); why there are none, or "" when they were not asked for."""
    import numpy as np

    t = units.time

    fb, ff = d.phase_replays.get("feedback"), d.phase_replays.get("feedforward")
    out = f" Phase-variable replay: {d.phase_replay_outcome}." if getattr(
        d, "phase_replay_outcome", "") else ""
    if fb is not None and getattr(d, "phase_names", ()):
        out += " One phase-variable law per phase (the phase in force: the one whose stretch " \
               "of the phase variable holds its present value)."
    if fb is not None:
        out += (f" Replayed as virtual constraints (the torques as a function of the phase "
                f"variable, the stance leg's angle, plus PD tracking of the collocated joint "
                f"trajectory): from the collocated start the step returns "
                f"{num(fb.collocated_start_error, 2)} away; closed (start moved "
                f"{num(fb.start_shift, 2)}) it returns to {num(fb.return_error, 2)}, step "
                f"period {num(fb.step_period_s, 9)} {t}, largest |multiplier| "
                f"{num(float(np.max(np.abs(fb.multipliers))))} ("
                f"{'stable' if np.max(np.abs(fb.multipliers)) < 1 else 'unstable'} under the "
                f"law), the "
                f"law's torque within {num(fb.torque_error, 2)} {units('N m')} of the optimal "
                "one.")
    if ff is not None:
        out += (f" The phase-variable feed-forward alone (no PD): one step from the "
                f"collocated start returns {num(ff.collocated_start_error, 2)} away, largest "
                f"|multiplier| of its step map there {num(float(np.max(np.abs(ff.multipliers))))}.")
    return out


def _drawn_from(stem: str, arts: dict) -> bool:
    """Whether a figure's artifacts are among the report's (a figure an earlier ``walkerlab
    plot`` drew from an artifact the report leaves out is not shown)."""
    for prefix, stages in (("fig2_", ("simulate",)), ("energy_ledger", ("simulate",)),
                           ("fig6_", (CONTACT_SIM.name,)),
                           ("fig8_", ("compare",)), ("fig", ("simulate", CONTACT_SIM.name)),
                           ("work_precision", ("workprecision",)),
                           ("bifurcation", ("bifurcation",)), ("basin", ("basin",)),
                           ("mfpt", ("mfpt",)), ("optimize", ("optimize",))):
        if stem.startswith(prefix):
            return any(s in arts for s in stages)
    return True


def figures_section(fig_dir: Path, rel: str, arts: dict, units: Units = Units(),
                    animation: bool = True) -> list[str]:
    """Every figure that exists, with its raw data folded underneath where it is long
    (``arts``: the loaded artifacts by stage name; ``units``: the scene's), but the energy
    ledger's (its own section, :func:`ledger_section`, beside the gait); the animation only
    when ``animation`` (drawn from the current artifacts)."""
    out = []
    gif = fig_dir / "animation.gif"  # written by `walkerlab animate`
    if gif.is_file() and animation:
        cap = ("The walker walking (`walkerlab animate`; rigid model, and the contact model "
               "beside it where it was simulated).")
        out += [f"![{cap}]({rel}/{gif.name})", "", f"*{cap}*", ""]
    extra = [(png.stem, f"Bifurcation diagram over {png.stem.removeprefix('bifurcation_')} "
                        "(`walkerlab bifurcation --param`).")
             for png in sorted(fig_dir.glob("bifurcation_*.png"))]
    for stem, cap in CAPTIONS + extra:
        png = fig_dir / f"{stem}.png"
        if not png.is_file() or not _drawn_from(stem, arts):
            continue
        if stem == "energy_ledger" and ledger_section(None, fig_dir, rel, arts):
            continue  # shown in its own section, with the ledger's table
        out += [f"![{cap}]({rel}/{png.name})", "", f"*{cap}*", ""]
        if stem == "optimize" and "optimize" in arts:
            out += optimize_lines(arts["optimize"], units)
        if stem == "fig7_angles_rates" and "simulate" in arts:
            out += details("Per-step data of the rigid walker (simulate.h5)",
                           steps_table(arts["simulate"]))
        if stem.startswith("work_precision_") and "workprecision" in arts:
            out += details("All (method, tolerance) points",
                           workprecision_table(arts["workprecision"],
                                               stem.removeprefix("work_precision_")))
    return ["## Figures", "", *out] if out else []


def cot_terms_text(d, units: Units = Units()) -> str:
    """The cost of transport's objective of ``optimize.h5`` (``d``) split into its terms
    (it carries a small effort regularisation, ``optimize.cost_of_transport_effort_weight``:
    ``" (cost of transport C, effort E (N m)^2 s)"``), else ``""``."""
    if d.objective_name != "cost_of_transport" or "cost_of_transport" not in d.terms:
        return ""
    return (f" (cost of transport {float(d.terms['cost_of_transport']):.6g}, effort "
            f"{float(d.terms.get('effort', float('nan'))):.4g} ({units(d.torque_unit)})^2 "
            f"{units.time})")


#: IPOPT's statuses that say the constraints cannot hold together
INFEASIBLE = ("Infeasible_Problem_Detected", "Restoration_Failed",
              "Error_In_Step_Computation")


def not_a_gait_reason(d) -> str:
    """Why an ``optimize.h5`` (``d``) is not called a gait, and what helps (one clause):
    IPOPT did not converge, or the replay does not return to its start within
    ``optimize.replay_tolerance`` - on an open-loop unstable gait (a multiplier outside the
    unit circle) the replay amplifies the collocation's own error, which more intervals
    shrink (Hermite-Simpson: O(h^4))."""
    if getattr(d, "controllers", ()) and d.status != "Solve_Succeeded":  # a design
        verdict = ("infeasible" if d.status in INFEASIBLE else "not converged")
        return (f"the design is {verdict} ({d.violations or 'IPOPT ' + d.status}): relax "
                "optimize.max_multiplier, the target speeds, max_torque_n_m or "
                "friction_coefficient, or start from a controller that walks nearer them")
    if getattr(d, "controllers", ()):  # a design that converged: its closed loop
        c = d.controllers[0]
        return ("controller 1's closed loop has no fixed point"
                + (f" ({c.note})" if getattr(c, "note", "") else "")
                if c.full_order_step_period_s != c.full_order_step_period_s else
                f"controller 1's restricted map's delta^2 {c.delta2_restricted:.10g} is not "
                f"the collocation's {c.delta2:.10g} within optimize.replay_tolerance")
    if d.status != "Solve_Succeeded":
        worst = getattr(d, "violations", "")
        return f"IPOPT did not converge ({d.status})" + (
            f"; largest constraint violations: {worst}" if worst else "")
    mu = float(np.max(np.abs(d.multipliers))) if len(d.multipliers) else float("nan")
    text = (f"the replay returns {d.replay_error:.2g} away from its start, more than "
            "optimize.replay_tolerance")
    if mu > 1.0:
        text += (f"; the gait is unstable open loop (max |multiplier| {mu:.3g}), so the "
                 "replay amplifies the collocation's error: more optimize.intervals shrink it")
    return text
