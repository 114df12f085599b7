"""Report sections of the rigid walker (summary, fixed point, gait table), from loaded
artifacts and the numbers computed from them.

Every function takes the scene, the report's inputs (:class:`walkerlab.report.build.
ReportInputs`: the loaded artifacts by stage name and the numbers computed from them) and
the published-number module of the scene (or None) and returns Markdown lines; a section
whose artifact is absent returns ``[]``, so a scene gets only what it produces.  Published
values come from :mod:`walkerlab.published`, never from literals here.
"""

from __future__ import annotations

import math
from types import ModuleType

import numpy as np

from walkerlab.integrate.ends import CONTACT_WALKED
from walkerlab.io.stage_files import CONTACT_SIM, SIMULATE
from walkerlab.report.ground_text import ground_contact_text, twist_text
from walkerlab.report.markdown import num, printed, sig_digits, table
from walkerlab.report.run_text import periodic_not_found
from walkerlab.report.text import (
    neutral_multipliers_text,
    zero_dynamics_text,
    zero_multipliers_text,
)
from walkerlab.units import Units, for_scene, per_map

#: Table 3 rows (keys of :func:`walkerlab.comparison.tables.gait_metrics`): name, symbol, unit
TABLE3_ROWS = {
    "t_left_s": ("Left step period", "t_left", "s"),
    "t_right_s": ("Right step period", "t_right", "s"),
    "t_cycle_s": ("One cycle period", "t_cycle = t_left + t_right", "s"),
    "v_com_m_per_s": ("Average velocity of robot", "v_com", "m/s"),
    "E_avg_J": ("Average mechanical energy (5 steps)", "E_avg = KE + PE", "J"),
}


# --------------------------------------------------------------------------- data
def published_fixed_point(pub: ModuleType | None) -> tuple[tuple, tuple]:
    """``(state names, values)`` of a published fixed point (``FIXED_POINT_NAMES/STATE``,
    or the ``EQ11_NAMES/STATE`` spelling), empty when the source prints none."""
    names = getattr(pub, "FIXED_POINT_NAMES", getattr(pub, "EQ11_NAMES", ()))
    state = getattr(pub, "FIXED_POINT_STATE", getattr(pub, "EQ11_STATE", ()))
    return tuple(names), tuple(state)


# --------------------------------------------------------------------------- summary
def clearance_text(lowest: float, u: Units, ground: str = "slope") -> str:
    """The swing foot's lowest height above the ground (scene length unit) in words:
    clearance when positive, penetration depth below the ground (foot scuffing) when
    negative; ``u``: the scene's units (shown in mm in SI); ``ground``: what the ground is
    (:attr:`walkerlab.models.ground.Ground.name`: ``slope``, ``treads``, ...)."""
    v, unit = num(abs(lowest) * u.small_scale, 3), u.small_length
    if lowest > 0:
        return f"lowest {v} {unit} above the {ground} inside the steps: no scuffing"
    return (f"the swing foot dips up to {v} {unit} below the {ground} inside the steps "
            "(penetration): foot scuffing, which the rigid model ignores")

def _fixedpoint_summary(fp, pub, u, bullets: list, rows: list) -> None:
    """The fixed point's verdicts (gait found, stable, ground reaction) appended to
    ``bullets`` and its numbers (state, step period, largest multiplier) with the published
    fixed point's to ``rows`` (:func:`summary_section`)."""
    bullets.append(f"- **Gait found**: yes, period-1 fixed point (residual "
                   f"{num(fp.residual, 2)}), step period "
                   f"{num(fp.step_period_s)} {u.time}.")
    per = per_map(getattr(fp, "steps_per_map", 0))  # the artifact's map: step or stride
    bullets.append(f"- **Stable**: {'yes' if fp.stable else 'no'} (largest "
                   f"|Floquet multiplier|{' ' + per if per else ''} "
                   f"{num(fp.max_abs_multiplier())}).")
    g = getattr(fp, "ground_contact", None)
    if g is not None:  # a gait that needs the ground to pull is no gait on real ground
        bullets.append("- **Ground reaction**: " + ground_contact_text(g, u).split(
            ": ", 1)[1] + ".")
        twist = twist_text(g, u)
        if twist is not None:  # a 3D gait: the stance foot's moment about the normal
            bullets.append("- **Stance foot twist**: " + twist.split(": ", 1)[1] + ".")
    eq = dict(zip(*published_fixed_point(pub)))
    for n, v, un in zip(fp.state_names, fp.x, fp.state_units):
        # as many digits as the published value has, so the two can be compared digit by digit
        dig = max(4, sig_digits(printed(eq[n]))) if n in eq else 4
        rows.append([f"fixed point {n}", un, num(v, dig),
                     printed(eq[n]) if n in eq else "—"])
    rows.append(["step period", u.time, num(fp.step_period_s), "—"])
    rows.append([f"max abs(multiplier){' ' + per if per else ''}", "-",
                 num(fp.max_abs_multiplier()), "—"])


def _contact_verdict(c) -> str:
    """The contact walker's verdict (:func:`summary_section`): whether it walks, from the
    steps stored with the run (an older artifact: its outcome), and its own periodic gait."""
    walks = c.walks if c.walks is not None else c.outcome in CONTACT_WALKED
    extra = ""
    if c.periodic is not None and c.periodic.found:
        extra = ("; its own periodic gait is " + ("stable" if c.periodic.stable
                                                  else "unstable"))
    elif c.periodic is not None:
        extra = ("; its own periodic gait was not found "
                 f"({periodic_not_found(c.periodic.outcome)})")
    why = f": {c.walks_reason}" if not walks and c.walks_reason else ""
    return (f"- **Contact walker walks**: {'yes' if walks else 'no'} "
            f"({len(c.heel_strike_times)} heel strikes, outcome {c.outcome}"
            f"{why}){extra}.")


def _gait_rows(ideal: dict, pub, u) -> list:
    """The rigid gait's cycle time, speed, mean energy and step length beside the
    published values (Table 3 of ``pub`` where it has one; :func:`summary_section`)."""
    rows = []
    t3 = getattr(pub, "TABLE3", {})
    for key in ("t_cycle_s", "v_com_m_per_s"):
        name, _sym, unit = TABLE3_ROWS[key]
        rows.append([name, u(unit), num(ideal[key]),
                     _published(ideal[key], t3[key][0]) if key in t3 else "—"])
    if "E_avg_J" in t3:
        ours = ideal.get("E_avg_stance_frame_J", np.nan)
        rows.append(["average mechanical energy, PE from the stance foot", u.energy,
                     num(ours), _published(ours, t3["E_avg_J"][0])])
    step_pub = getattr(pub, "STEP_LENGTH_M", None)
    rows.append(["step length", u.length, num(ideal["step_length_m"]),
                 _published(ideal["step_length_m"], step_pub) if step_pub is not None
                 else "—"])
    return rows


#: how far apart ours and a published value may be before the summary's row flags it: a
#: factor (a value off by more than this is no rounding or modelling difference)
FLAG_FACTOR = 2.0


def _published(ours: float, value: float) -> str:
    """The published value as printed, flagged in its row when ours is more than
    :data:`FLAG_FACTOR` times it or less than its inverse (the gait section, three
    sections below, explains the difference: :func:`gait_section`)."""
    ratio = abs(ours / value) if value and np.isfinite(ours) else 1.0
    if 1 / FLAG_FACTOR <= ratio <= FLAG_FACTOR:
        return printed(value)
    return (f"{printed(value)} ⚠ ours is {ratio:.3g}× this (explained under gait "
            "characteristics, below)")


def summary_section(scene, inputs, pub: ModuleType | None) -> list[str]:
    """Short verdicts and headline numbers, with the published values where they exist."""
    arts = inputs.artifacts
    out = ["## Summary", ""]
    u = for_scene(scene)
    bullets = []
    rows = []
    pub_name = f"published ({pub.SHORT})" if pub is not None else None
    fp = arts.get("fixedpoint")
    if fp is not None:
        _fixedpoint_summary(fp, pub, u, bullets, rows)
    elif "fixedpoint" not in arts and scene.fixedpoint is not None:
        bullets.append("- **Gait found**: no fixed point artifact.")
    sim = arts.get("simulate")
    if sim is not None:
        term, n_hs = sim.termination, sim.heel_strike_count()
        energy, energy_rows = energy_check(sim, inputs.energy_drift, u)
        bullets.append(f"- **Rigid walker walks**: {'yes' if term == 'heel_strike' else 'no'} "
                       f"({n_hs} heel strikes, ended by {term}); {energy}.")
        rows += energy_rows
        clear = inputs.swing_clearance
        if np.isfinite(clear):
            bullets.append("- **Swing-foot clearance**: "
                           + clearance_text(clear, u, inputs.clearance_ground) + ".")
            rows.append(["lowest swing-foot clearance (negative: penetration)", u.small_length,
                         num(u.small_scale * clear, 3), "—"])
    c = arts.get(CONTACT_SIM.name)
    if c is not None:
        bullets.append(_contact_verdict(c))
    cols = inputs.gait_columns
    ideal = cols.get("ours, ideal")
    if ideal:
        rows += _gait_rows(ideal, pub, u)
    out += bullets
    if rows:
        header = ["quantity", "unit", "ours"]
        if pub_name:
            header.append(pub_name)
        else:
            rows = [r[:3] for r in rows]
        out += ["", table(header, rows)]
        if pub is not None:
            out += ["", f"Published values: {pub.CITATION} (`walkerlab.published.{pub.SHORT}`); "
                    "the sections below explain each difference."]
    out.append("")
    return out


# --------------------------------------------------------------------------- fixed point
def fixedpoint_section(fp, pub: ModuleType | None) -> list[str]:
    """Fixed point of every equation variant, Floquet multipliers, verdict (``fp``: the loaded
    ``fixedpoint.h5``)."""
    pub_fp = dict(zip(*published_fixed_point(pub)))
    out = ["## Fixed point of the Poincaré map", ""]
    names, units, main = fp.state_names, fp.state_units, fp.variant
    # the published state in this walker's state order (None if it does not name them all)
    eq = np.array([pub_fp[n] for n in names], float) if pub_fp and set(names) <= set(
        pub_fp) else None
    rows = []
    if eq is not None:
        label = getattr(pub, "FIXED_POINT_LABEL", "published")
        rows.append([f"{pub.SHORT}: {label}", *[printed(v) for v in eq], "—", "—", "—"])
    fps = {}
    for v, g in fp.variants.items():
        if g.error:
            rows.append([v, *(["—"] * len(names)), "—", "—", g.error])
            continue
        fps[v] = g.x
        re, im = g.multipliers.real, g.multipliers.imag
        rows.append([f"walkerlab `{v}`" + (" (this scene)" if v == main else ""),
                     *[num(a) for a in g.x], num(float(g.step_period_s)),
                     num(float(np.max(np.hypot(re, im)))), num(g.residual, 2)])
    per = per_map(getattr(fp, "steps_per_map", 0))  # the artifact's map: step or stride
    out.append(table(["model", *[f"{n} [{u}]" for n, u in zip(names, units)],
                      f"step period [{fp.units.time}]",
                      f"max abs(multiplier){' ' + per if per else ''}", "residual"], rows))
    out.append("")
    out.append("State right after heel strike, role-ordered (the swing leg is the one that "
               "just left the ground).")
    if eq is not None and getattr(pub, "FIXED_POINT_NOTE", None):
        out += ["", f"**Why the numbers differ.** {pub.FIXED_POINT_NOTE}"]
    if eq is not None and "appendix_a" in fps and "derived" in fps:
        d = fps["derived"] - eq
        a = fps["appendix_a"] - eq
        ang = np.array([u == "rad" for u in units])
        i_sr = names.index("stance_rate")
        fmt = ", ".join
        out.append("")
        out.append(
            "**Why the numbers differ.** The printed Appendix A (variant `appendix_a`) "
            "reproduces Eq. (11): its deviation from the printed digits is "
            f"[{fmt(num(v, 2) for v in a)}] (the stance rate {num(fps['appendix_a'][i_sr])} "
            f"is printed as {eq[i_sr]:.2f}, i.e. truncated, not rounded). Its Coriolis matrix "
            "(A.5) has the wrong sign in C[1,0] (+m L b θ̇1 sin(θ2−θ1) instead of −), so "
            "energy is not conserved in swing. The energy-consistent derived model "
            "(`derived`, the default) gives a different gait: deviation from Eq. (11) "
            f"[{fmt(num(v, 2) for v in d)}], i.e. up to {num(np.max(np.abs(d[ang])), 2)} rad "
            f"in the angles and {num(np.max(np.abs(d[~ang])), 2)} rad/s in the rates. Taking "
            "the printed y-component of A.55 literally (`appendix_a_literal`) does not "
            "reproduce Eq. (11) at all, so that sign is a typesetting error only.")
    re, im = fp.multipliers.real, fp.multipliers.imag
    re2, im2 = fp.multipliers_fd.real, fp.multipliers_fd.imag
    out += ["", f"### Floquet multipliers (`{main}`{', ' + per if per else ''})", "",
            table(["#", "variational equations", "finite differences", "abs value"],
                  [[i + 1, f"{a:+.6f}{b:+.6f}j", f"{c:+.6f}{d:+.6f}j",
                    num(float(np.hypot(a, b)))]
                   for i, (a, b, c, d) in enumerate(zip(re, im, re2, im2))]),
            "", f"Max difference between the two: {num(fp.max_difference, 2)}. "
            f"Verdict: **{'stable' if fp.stable else 'unstable'}** "
            f"({zero_multipliers_text(re, im, fp.state_names, fp.scene_json)}"
            + (f"; {neutral_multipliers_text(fp)}" if fp.neutral else "") + ").", ""]
    if fp.zero_dynamics is not None:  # virtual constraints: the restricted map beside
        out += ["### Hybrid zero dynamics", "", "```text",
                *zero_dynamics_text(fp.zero_dynamics), "```", ""]
    return out


def gait_note(inputs) -> list[str]:
    """The gait table's note on its contact columns (none without a contact run): what
    *ours, contact* averages and the contact model's own periodic gait: its column, why it
    was not found (a search cut short named so, as the summary says it:
    :func:`walkerlab.report.run_text.periodic_not_found`), or that the scene asks for none."""
    cols, arts = inputs.gait_columns, inputs.artifacts
    if "ours, contact" not in cols:
        return []
    per = getattr(arts.get(CONTACT_SIM.name), "periodic", None)
    if "ours, contact periodic gait" in cols:
        own = ("; *ours, contact periodic gait* is the contact model's own periodic gait "
               "(the fixed point of its step-to-step map: no start-up, energies not "
               "defined).")
    elif per is not None:  # searched, not found: say why, as the summary does
        own = (" (the contact model's own periodic gait was not found: "
               f"{periodic_not_found(per.outcome)}).")
    else:
        own = " (the scene computes no contact periodic gait: contact_sim.periodic_gait)."
    return ["", "*ours, contact* averages every complete step of the contact run, which "
            "starts from the rigid gait, so its start-up steps are included" + own]


# --------------------------------------------------------------------------- gait table
def gait_section(scene, inputs, pub: ModuleType | None) -> list[str]:
    """Gait characteristics (paper Table 3 rows), ours beside the published ones."""
    cols, arts = inputs.gait_columns, inputs.artifacts
    if not cols:
        return []
    u = for_scene(scene)
    t3 = getattr(pub, "TABLE3", None)
    header = ["quantity", "symbol", "unit"]
    if t3:
        header += [f"{pub.SHORT} MATLAB", f"{pub.SHORT} ADAMS"]
    header += list(cols)
    rows = []
    for key, (name, sym, unit) in TABLE3_ROWS.items():
        pubv = [printed(v) for v in t3[key]] if t3 else []
        rows.append([name, sym, u(unit), *pubv, *(num(c[key]) for c in cols.values())])
    blank = ["", ""] if t3 else []
    rows.append(["Average mechanical energy, PE from the current stance foot", "E_avg'", u.energy,
                 *blank, *(num(c.get("E_avg_stance_frame_J", np.nan)) for c in cols.values())])
    step_pub = getattr(pub, "STEP_LENGTH_M", None)
    rows.append(["Step length", "Δx", u.length, *([printed(step_pub)] * 2 if t3 else []),
                 *(num(c["step_length_m"]) for c in cols.values())])
    per_leg = [(c.get("step_length_left_m", np.nan), c.get("step_length_right_m", np.nan))
               for c in cols.values()]
    if any(abs(a - b) > 1e-4 for a, b in per_leg):  # legs that differ: each leg's step
        for i, side in enumerate(("Left", "Right")):
            rows.append([f"{side} step length", f"Δx_{side[0].lower()}", u.length, *blank,
                         *(num(v[i]) for v in per_leg)])
    title = "## Table 3 — gait characteristics" if t3 else "## Gait characteristics"
    out = [title, "", "Recomputed from the trajectory artifacts ("
           + ", ".join(f"`{arts[s].path.name}`" for s in (SIMULATE.name, CONTACT_SIM.name)
                       if s in arts)
           + ").", "", table(header, rows)]
    out += gait_note(inputs)
    ideal = cols.get("ours, ideal")
    eq = getattr(pub, "EQ11_STATE", None)  # the paper's Eq. (11) specifically
    if ideal and t3 and eq is not None and step_pub is not None:
        dx_eq11 = inputs.published_step_length_m
        e_pub = t3["E_avg_J"][0]
        e_st = ideal.get("E_avg_stance_frame_J", np.nan)
        out += ["", "**Differences from the published Table 3, measured:**", "",
                f"- *Left/right step periods.* A period-1 gait has identical steps: ours are "
                f"{num(ideal['t_left_s'])} s and {num(ideal['t_right_s'])} s. The published "
                f"{printed(t3['t_left_s'][0])} s and {printed(t3['t_right_s'][0])} s cannot "
                f"both belong to the period-1 fixed point of Eq. (11); their sum "
                f"{printed(t3['t_cycle_s'][0])} s "
                f"is within {num(abs(t3['t_cycle_s'][0] - ideal['t_cycle_s']), 2)} s of our "
                f"cycle period {num(ideal['t_cycle_s'])} s.",
                f"- *Step length Δx.* Eq. (11) itself implies Δx = 2 L sin((θ2 − θ1)/2) = "
                f"{num(dx_eq11)} m (ours: {num(ideal['step_length_m'])} m), about "
                f"{dx_eq11 / step_pub:.0f}× the printed {printed(step_pub)} m. With the printed Δx "
                f"the speed formula gives {printed(step_pub)}/{printed(t3['t_cycle_s'][0])} = "
                f"{num(step_pub / t3['t_cycle_s'][0])} m/s, the printed v_com; the walker "
                f"actually advances at {num(ideal['v_com_m_per_s'])} m/s (hip displacement over "
                "whole cycles / time).",
                f"- *Energy.* With the potential energy measured from the current stance foot "
                f"we get E_avg' = {num(e_st)} J, within {num(abs(e_pub - e_st), 2)} J of the "
                f"printed {printed(e_pub)} J; measured from a fixed datum (first stance foot) the "
                f"average over 5 steps is {num(ideal['E_avg_J'])} J because the walker descends "
                f"the {num(scene.slope.phi_rad)} rad slope by Δx sin φ per step."]
    out.append("")
    return out


#: ledger columns of work done between impacts (the energy is not conserved there)
_NON_CONSERVATIVE = {"damper_work": "the dampers dissipate",
                     "actuator_work_positive": "the actuators add",
                     "actuator_work_negative": "the actuators take"}


def energy_check(sim, drift: tuple, u) -> tuple[str, list[list]]:
    """The report's energy check of the rigid run: ``(clause, summary-table rows)``.

    A passive walker without dampers conserves its energy between impacts, so the largest
    change within a phase (``drift``: [J], relative) is the integration error.  With a
    damper (or joint torques) that change is physics: the clause names the work of each
    (mean per step, from the energy ledger ``sim.ledger``) and checks the balance with it
    (the ledger's ``closure``, largest per step)."""
    led = sim.ledger or {}
    work = {k: [float(v) for v in led.get(k, []) if math.isfinite(float(v))]
            for k in _NON_CONSERVATIVE}
    work = {k: v for k, v in work.items() if v and max(abs(x) for x in v) > 0}
    closure = [abs(float(v)) for v in led.get("closure", []) if math.isfinite(float(v))]
    if not work or not closure:
        d, rel = drift
        return (f"energy drift between impacts {num(d, 2)} {u.energy} ({num(rel, 2)} "
                "relative)"), [["energy drift between impacts", u.energy, num(d, 2), "—"]]
    parts = [f"{_NON_CONSERVATIVE[k]} {num(abs(sum(v) / len(v)), 3)} {u.energy} per step"
             for k, v in work.items()]
    rows = [[f"{k.replace('_', ' ')} per step (energy ledger)", u.energy,
             num(sum(v) / len(v), 3), "—"] for k, v in work.items()]
    rows.append(["energy balance closure, largest per step (ledger)", u.energy,
                 num(max(closure), 2), "—"])
    return (f"energy between impacts is not conserved: {', '.join(parts)} (energy ledger); "
            f"the balance with {'it' if len(parts) == 1 else 'them'} closes to "
            f"{num(max(closure), 2)} {u.energy} (largest per step)"), rows
