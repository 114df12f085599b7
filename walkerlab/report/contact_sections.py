"""Report sections of the contact model (contact-sim, compare), from loaded artifacts only.

Each function takes the scene and the loaded artifacts by stage name (``contact-sim``,
``simulate``, ``compare``, ``stability_map_<kind>``) and returns Markdown, or an empty list
when its artifact does not exist, so a scene gets only the sections it produces.
"""

from __future__ import annotations

import numpy as np

from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.published import for_scene
from walkerlab.report.markdown import num, printed
from walkerlab.report.markdown import table as _table
from walkerlab.report.run_text import contact_multiplier_words, periodic_not_found
from walkerlab.units import for_scene as units_for
from walkerlab.units import map_name


def _table2_note(pub) -> str:
    """The printed rate increases of Table 2 against the ones its own columns imply."""
    if not hasattr(pub, "TABLE2_RATE_INCREASE_PERCENT"):
        return ""
    rates = [v for k, v in pub.TABLE2.items() if k.endswith("_rate")]
    said = pub.TABLE2_RATE_INCREASE_PERCENT
    got = [100 * (abs(pa) - abs(pm)) / abs(pm) for _s, pm, pa in rates]
    return (" Note that the paper's ADAMS column is not the stated "
            + " / ".join(f"+{v:.0f} %" for v in said) + ": "
            + " and ".join(f"{pm:.2f} → {pa:.2f} is {g:+.0f} %"
                           for (_s, pm, pa), g in zip(rates, got)) + ".")


def initial_states_section(scene, arts) -> list[str]:
    """The initial states of the ideal and contact walkers (the paper's Table 2 where the
    scene has published ones): before the gait characteristics (Table 3), in the paper's
    order."""
    c = arts.get(CONTACT_SIM.name)
    if c is None:
        return []
    pub = for_scene(scene)
    table2 = getattr(pub, "TABLE2", {})
    return _initial_state_lines(c, arts, pub, table2)[:-1] + [
        "", "(% columns: change of magnitude relative to the ideal value: ours, or the "
        "published MATLAB one.)" if table2 else
        "(% column: change of magnitude relative to our ideal value.)", ""]



def _outcome_sentence(outcome: tuple, walks: bool | None, reason: str) -> str:
    """The contact run's outcome in one sentence: how it ended (``outcome``: the run end's
    name and message) and whether the walker walks by the verdict from its steps
    (``walks``; None: no verdict)."""
    kind, message = outcome[0], outcome[1]
    out = f"Outcome: the run ended by **{kind}**" + (
        f" ({message})" if message and message != kind else "")
    if walks is None:
        return out + "."
    return out + (", and by the verdict from its steps the walker walks." if walks else
                  f", and by the verdict from its steps the walker **does not walk** "
                  f"({reason}).")


def contact_section(scene, arts) -> list[str]:
    """The contact walker's run: its summary, parameters, outcome, slips, periodic gait,
    drop test and stability maps (the initial states: :func:`initial_states_section`)."""
    c = arts.get(CONTACT_SIM.name)
    if c is None:
        return []
    summ, stage_wall, cp = c.summary, c.stage_wall_time_s, c.contact_params_si
    term = c.termination
    outcome = (c.outcome, c.outcome_message)
    slips = c.steps["stance_slip_mm"]
    creep = c.steps.get("double_support_creep_mm")
    drop = c.drop
    periods = c.steps["period"]
    per = per_fail = None
    if c.periodic is not None and not c.periodic.found:
        per_fail = (periodic_not_found(c.periodic.outcome), c.periodic.message)
    elif c.periodic is not None:
        g = c.periodic
        per = (g.step_period_s, g.step_length_m, contact_multiplier_words(g, 4), g.stable,
               map_name(g.steps_per_map))
    out = [
           "## Contact walker (MSC ADAMS-style model)", "",
           _table(["quantity", "value", "unit"], _summary_rows(summ, stage_wall)
                  + [["termination", term, ""]]),
           "", "Contact parameters in SI (converted from the scene's unit system): "
           + ", ".join(f"{k} = {num(v)}" + (f" {u}" if u not in ("", "-") else "")
                       for k, (v, u) in cp.items()) + ".", "",
           _outcome_sentence(outcome, c.walks, c.walks_reason), "",
           "Per-step stance slip [mm] (touchdown to lift-off of the stance foot; nan: the "
           "phase had not ended when the run did): " + ", ".join(num(v, 3) for v in slips)
           + (("; creep of both feet during double support [mm]: "
               + ", ".join(num(v, 3) for v in creep)) if creep is not None else "")
           + "; step periods [s]: " + ", ".join(num(v, 4) for v in periods) + ".", ""]
    out += _slip_path_lines(c)
    if c.ledger is not None:
        w = c.ledger
        terms = (f"push-off {num(w['push_off'][-1], 4)}, joint torques "
                 f"+{num(w['hip_torque_positive'][-1], 4)} / "
                 f"{num(w['hip_torque_negative'][-1], 4)}" if "push_off" in w else
                 f"hip torques +{num(w['hip_torque_positive'][-1], 4)} / "
                 f"{num(w['hip_torque_negative'][-1], 4)}, ankle dampers "
                 f"{num(w['damper'][-1], 4)}" if "hip_torque_positive" in w else
                 f"ankle push-off +{num(w['ankle_torque_positive'][-1], 4)} / "
                 f"{num(w['ankle_torque_negative'][-1], 4)}, ankle dampers "
                 f"{num(w['damper'][-1], 4)}")
        out += ["**Energy ledger of the powered contact run** (work integrals carried with the "
                f"state; J over the whole run): {terms}, contact forces (normal + friction, "
                f"their dissipation and the energy their springs hold) "
                f"{num(w['contact'][-1], 4)}"
                + (f", knee stops {num(w['knee_stop'][-1], 4)}" if "knee_stop" in w else "")
                + (f", the hip-roll law +{num(w['hip_roll_positive'][-1], 4)} / "
                   f"{num(w['hip_roll_negative'][-1], 4)}" if "hip_roll_positive" in w
                   else "")
                + "; closure (kinetic + potential energy change minus "
                f"these) at most {num(float(abs(w['residual']).max()), 2)} J.", ""]
        out += _cost_of_transport_lines(c, arts.get("simulate"))
    if per_fail is not None:
        out += [f"**Periodic gait of the contact model**: not found ({per_fail[0]}: "
                f"{per_fail[1]}).", ""]
    if drop is not None:
        out += _drop_lines(scene, drop, c.stiffness_family)
    out += _map_lines(arts)
    if per is not None:
        out += [f"**Periodic gait of the contact model** (fixed point of its Poincaré map at "
                f"mid-stance, a {per[4]}'s): step period {num(per[0], 6)} s, step length "
                f"{num(per[1], 6)} m, "
                f"{'stable' if per[3] else 'unstable'}; {per[2]}.", ""]
    return out


def _slip_path_lines(c) -> list[str]:
    """The stance foot's slip path and friction work per step (``steps/``; none in an
    artifact written before they were), and the friction work against the push-off's."""
    path, work = c.steps.get("stance_slip_path_mm"), c.steps.get("friction_work_j")
    if path is None or work is None:
        return []
    line = ("Slip path of the stance foot per step [mm] (integral of |slip velocity| over its "
            "stance: the to-and-fro creep of the regularised friction law that the net slip "
            "hides): " + ", ".join(num(v, 3) for v in path) + "; friction work per stance "
            "[J] (dissipated): " + ", ".join(num(v, 3) for v in work) + ".")
    push = (c.ledger_steps or {}).get("push_off_work")
    if push is not None and _mean(push) > 0 and np.isfinite(_mean(work)):
        line += (f" Friction takes {num(_mean(work), 3)} J a stance, "
                 f"{100 * _mean(work) / _mean(push):.0f} % of the push-off's "
                 f"{num(_mean(push), 3)} J.")
    return [line, ""]


def _mean(v) -> float:
    v = np.asarray(v, float)
    v = v[np.isfinite(v)]
    return float(v.mean()) if v.size else float("nan")


def _cost_of_transport_lines(c, sim) -> list[str]:
    """The rigid and the contact view's energetics side by side: step period, distance per
    step, push-off and positive actuator work per step, cost of transport (means over the
    steps; the contact view's from mid-step to mid-step, ``ledger/steps``)."""
    led = c.ledger_steps
    if not led or not len(led.get("cost_of_transport", ())):
        return []
    hs = np.asarray(c.heel_strike_times, float)
    contact = [_mean(np.diff(hs)) if hs.size > 1 else float("nan"), _mean(led["distance"]),
               _mean(led["push_off_work"]), _mean(led["actuator_work_positive"]),
               _mean(led["cost_of_transport"])]
    rigid = [float("nan")] * 5
    if sim is not None and sim.ledger:
        r = sim.ledger
        rigid = [_mean(sim.steps.get("period", [])), _mean(sim.steps.get("step_length", [])),
                 _mean(r.get("push_off_work", [])), _mean(r.get("actuator_work_positive", [])),
                 _mean(r.get("cost_of_transport", []))]
    names = [("step period", "s"), ("step length (contact: hip travel per step)", "m"),
             ("push-off work per step", "J"), ("positive actuator work per step", "J"),
             ("cost of transport", "-")]

    def diff(a, b):
        return f"{100 * (b / a - 1):+.1f} %" if np.isfinite(a) and np.isfinite(b) and a else "—"

    rows = [[n, u, num(a), num(b), diff(a, b)] for (n, u), a, b in zip(names, rigid, contact)]
    return ["**Energetics, rigid and contact view** (means per step: the rigid run's energy "
            "ledger, the contact run's from mid-step to mid-step; cost of transport = (positive "
            "actuator work + push-off work + the potential energy the slope releases) / (M g "
            "distance); the contact push-off is a pulse ending at the touchdown, "
            "contact.push_off_duration_s):", "",
            _table(["quantity", "unit", "rigid", "contact", "contact vs rigid"], rows), ""]


def _initial_state_lines(c, arts, pub, table2: dict) -> list[str]:
    """Table 2 (initial states: the paper's MATLAB and ADAMS columns where the scene has
    published ones, ours ideal and contact) and the sentence on the contact walker's start
    (its rate scale, and what ``--adjust`` found)."""
    scale = c.initial_rate_scale
    scaled = c.rate_names or ["leg1", "leg2"]
    adj = dict(c.adjust) if c.adjust is not None else None
    if adj is not None:
        adj.update(kept=str(adj.get("kept", "adjusted")), why=str(adj.get("kept_reason", "")))
    # initial states by name: the first sample of each trajectory artifact
    c0 = {n: float(v[0]) for n, v in c.samples.coordinates.items()}
    i0 = {}
    if "simulate" in arts:
        i0 = {n: float(v[0]) for n, v in arts["simulate"].samples.coordinates.items()}
    rows = []
    for key in [k for k in table2 if k in c0] + [k for k in c0 if k not in table2]:
        sym, pm, pa = table2.get(key, (key, np.nan, np.nan))
        oi = i0.get(key, np.nan)
        pd = f"{100 * (abs(pa) - abs(pm)) / abs(pm):+.1f}%" if key in table2 else "—"
        od = (f"{100 * (abs(c0[key]) - abs(oi)) / abs(oi):+.1f}%" if abs(oi) > 0.0
              else "—")  # an ideal state of 0 (a 3D wheel's upright lean): no relative change
        rows.append([sym, printed(pm), printed(pa), pd, oi, c0[key], od])
    head = ["state", "paper MATLAB", "paper ADAMS", "paper diff.", "ours ideal",
            "ours contact", "ours diff."]
    if not table2:
        head, rows = [head[0], *head[4:]], [[r[0], *r[4:]] for r in rows]
    return [("## Table 2 — initial states" if table2 else "## Initial states")
            + " (ideal vs contact model)",
            "", _table(head, rows), "",
            f"Our contact walker starts from our ideal fixed point with the initial rates scaled "
            f"by [{', '.join(num(v, 3) for v in np.atleast_1d(scale))}] ("
            + "; ".join(f"{n} × {num(v, 3)}" for n, v in zip(scaled, np.atleast_1d(scale)))
            + ")"
            + (f" (found by `--adjust`: objective {num(adj['objective'], 3)} after "
               f"{int(adj['evaluations'])} simulations)" if adj and adj["kept"] != "scene"
               else f" (the scene's own: `--adjust` found no scale that walks better; {adj['why']})"
               if adj else "")
            + (f"; `--adjust`: {adj['gave_up']}" if adj and str(adj.get("gave_up", "")) else "")
            + "." + _table2_note(pub), ""]


def _summary_rows(summ: dict, stage_wall_s: float) -> list[list]:
    """Rows ``[quantity, value, unit]`` of the contact artifact's summary: counts as integers,
    the walking run's integration time told apart from the stage's whole compute time."""
    rows = []
    for k, (v, unit) in summ.items():
        if np.ndim(v) != 0:
            rows.append([k, str(v), unit])
            continue
        label = k
        if k == "wall_time_s":
            label = ("wall time of the walking run's integration"
                     + (f" (the whole stage, with drop test and periodic-gait search, took "
                        f"{num(stage_wall_s, 3)} s)" if np.isfinite(stage_wall_s) else ""))
        rows.append([label, num(v), "" if unit == "-" else unit])
    return rows


def _drop_lines(scene, drop, family: str) -> list[str]:
    """Text and table of the drop test stored in contact_sim.h5 (its restitution-vs-stiffness
    figure, ``figures/drop_restitution.png``, is drawn by the plot stage)."""
    ks, unit, curves, mass_kg = drop.stiffness, drop.unit, drop.restitution, drop.mass_kg
    rows = [[float(k), float(curves["paper"][i]), float(curves["rigid_limit"][i])]
            for i, k in enumerate(ks)]
    u = units_for(scene)
    cap = (f"Drop test — the walker's mass ({num(mass_kg, 3)} {u('kg')}) meeting flat ground at "
           f"0.3 {u('m/s')}: coefficient of restitution against stiffness, paper family "
           "(damping and dmax fixed) and rigid-limit family (damping and dmax scaled with k "
           "from the scene's contact).")
    return ["### Stiffness is not rigidity (drop test)", "",
            f"This scene follows the **{family}** family. With damping fixed, a stiffer IMPACT "
            "contact is *more elastic*, not closer to the rigid model's plastic impact; the "
            "rigid-limit family scales c ~ k^(1/(e+1)) and dmax ~ k^(-1/(e+1)), which keeps "
            "the restitution of the reference contact (near-plastic) at every k.", "",
            f"![{cap}](figures/drop_restitution.png)", "", f"*{cap}*", "",
            "<details><summary>drop-test table</summary>", "",
            _table([f"stiffness [{unit}]", "restitution, paper family",
                    "restitution, rigid-limit family"], rows), "", "</details>", ""]


def _map_lines(arts) -> list[str]:
    """Stability maps of the contact gait (``arts["stability_map_<kind>"]``: loaded maps whose
    figure exists)."""
    out = []
    for kind in ("stiffness", "friction", "patch_width"):
        m = arts.get(f"stability_map_{kind}")
        if m is None:
            continue
        png_name = f"stability_map_{kind}.png"  # the stage draws it from the artifact
        ex = float(m.summary["exists_fraction"])
        stab = float(m.summary["stable_fraction"])
        n = int(m.summary["cells"])
        cap = (f"Stability map of the contact gait over {kind.replace('_', ' ')} × slope "
               f"({n} cells): a periodic gait exists in {100 * ex:.0f} % of the cells and is "
               f"stable in {100 * stab:.0f} %.")
        if not out:
            out += ["### Stability maps of the contact gait", "",
                    "Each cell: the contact model's own periodic gait (fixed point of its "
                    "mid-stance step map) continued from its neighbour along the slope, else "
                    "from the ideal fixed point at that slope; cell text: max |Floquet "
                    "multiplier|, or why no gait was found (`walkerlab stability-map`).", ""]
        out += [f"![{cap}](figures/{png_name})", "", f"*{cap}*", ""]
    return out


def compare_section(scene, inputs) -> list[str]:
    """Fig. 8's numbers, every one read from the loaded ``compare`` / ``contact-sim``
    artifacts or computed from them before (``inputs``:
    :class:`walkerlab.report.build.ReportInputs`) in the scene's units; the sentence on the
    paper's printed error only with ``published: paper``."""
    c = inputs.artifacts.get("compare")
    if c is None:
        return []
    u = units_for(scene)
    rows = [[s, float(np.max(np.abs(c.errors[f"{s}_angle"]))),
             float(np.max(np.abs(c.errors[f"{s}_rate"]))), float(d)]
            for s, d in c.limit_cycle_distance.items()
            if f"{s}_angle" in c.errors and f"{s}_rate" in c.errors]
    t_end = float(c.time[-1])
    cyc = {m: float(c.metrics[m]["t_cycle_s"]) for m in ("ideal", "contact")
           if "t_cycle_s" in c.metrics.get(m, {})}
    phase = inputs.phase_error
    slip = None
    if np.isfinite(inputs.mean_stance_slip_mm):
        slip = inputs.mean_stance_slip_mm * 1e-3 * u.small_scale
    prose = []
    if len(cyc) == 2:
        prose.append(f"The contact walker's stride lasts {num(cyc['contact'], 4)} "
                     f"{u.time} against the ideal {num(cyc['ideal'], 4)} {u.time} "
                     f"({100 * (cyc['contact'] / cyc['ideal'] - 1):+.2f} %), so the "
                     "time-aligned errors (left panels) grow with the phase drift as much as "
                     "with the difference of the gaits.")
    if phase is not None:
        prose.append(f"Phase-aligned (right panels: the same fraction of the same step) the "
                     f"largest angle error is {num(phase[0], 3)} rad, {num(phase[1], 3)} rad "
                     f"over the last compared step (step {phase[2]}).")
    if slip is not None:
        prose.append(f"The stance foot creeps {num(slip, 3)} {u.small_length} per step on "
                     "average (the regularised friction has no true stiction).")
    if getattr(scene, "published", None) == "paper":
        from walkerlab.published import paper as pub

        prose.append(f"The paper reports a maximum error 'around {pub.FIG8_MAX_ERROR:g}' "
                     "(Sec. 5, MATLAB vs ADAMS, time-aligned).")
    return ["## Comparison ideal vs contact (Fig. 8)", "",
            f"Errors contact − ideal over the common span 0–{t_end:.2f} {u.time}:", "",
            _table(["leg", "max abs angle error [rad]",
                    f"max abs rate error [{u.rate}]",
                    f"mean limit-cycle distance [rad, {u.rate}: in the (angle, rate) plane]"],
                   rows), "",
            " ".join(prose), ""]


def sections(scene, inputs) -> list[str]:
    """The contact sections after the gait characteristics, in report order (``inputs``:
    :class:`walkerlab.report.build.ReportInputs`; the initial states come before them,
    :func:`initial_states_section`)."""
    return contact_section(scene, inputs.artifacts) + compare_section(scene, inputs)
