"""Plain-text summaries of artifacts, printed by the CLI: the rigid walker's fixed point here
(gaits, Floquet multipliers, zero dynamics; what the gait asks of the ground in
:mod:`walkerlab.report.ground_text`), the runs' (simulate, contact-sim, compare, mfpt,
rigid-limit) in :mod:`walkerlab.report.run_text` (re-exported here)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from walkerlab.numerics import neutral_positions
from walkerlab.report.ground_text import (
    footholds_text,
    ground_contact_text,
    ground_word,
    twist_text,
)
from walkerlab.report.run_text import (  # noqa: F401 (part of this API)
    compare_text,
    contact_text,
    mfpt_text,
    rigid_limit_text,
    simulate_ending,
    simulate_text,
)
from walkerlab.units import per_map

if TYPE_CHECKING:  # the loaded artifacts these summaries print
    from walkerlab.io.schemas.fixedpoint import FixedPointArtifact


def _fmt_mult(re, im) -> str:
    return ", ".join(f"{a:+.6f}{b:+.6f}j" if abs(b) > 0 else f"{a:+.6f}" for a, b in zip(re, im))


def _massless_leg(walker: dict) -> bool:
    """Whether a walker (a scene's ``walker`` mapping) has a leg that carries no mass."""
    legs = walker.get("legs") or ([walker["leg"]] if walker.get("leg") else [])
    return any(sum(float(b.get("mass_kg", 0.0)) for b in leg.get("bodies", ())) == 0.0
               for leg in legs)


def _fixed_by_impacts(state_names: list[str], walker: dict) -> list[tuple[int, str]]:
    """The state combinations the impacts of this walker fix, as (how many, why)."""
    out = []
    if any("shank" in n for n in state_names):
        out.append((2, "the swing knee is straight and locked after heel strike, its angle "
                       "and rate fixed"))
    if any("ankle" in n for n in state_names):
        out.append((2, "the flat foot lands at its ankle's angle and its foot slap stops "
                       "the foot turning"))
    if _massless_leg(walker):
        out.append((1, "the swing leg has no mass: its rate after heel strike follows from "
                       "the stance leg's"))
    return out


def zero_multipliers_text(re, im, state_names: list[str] | None = None,
                          scene_json: str = "{}") -> str:
    """Why some Floquet multipliers are 0: the map lands on the heel-strike surface, and the
    impacts of this walker fix more combinations of the state (a kneed walker's locked
    swing knee, a flat foot's ankle, a massless swing leg's rate): only the reasons that
    apply to the walker (its ``state_names`` and the scene of ``scene_json``) are named."""
    import json

    n0 = int(np.sum(np.hypot(re, im) < 1e-9))
    if n0 <= 1:
        return "one multiplier is 0 by construction: the map lands on the heel-strike surface"
    walker = json.loads(scene_json or "{}").get("walker") or {}
    why = _fixed_by_impacts(list(state_names or []), walker)
    said = ("; ".join(w for _n, w in why) if sum(n for n, _w in why) == n0 - 1 else "")
    return (f"{n0} multipliers are 0 by construction: the map lands on the heel-strike surface "
            f"and the impacts fix {n0 - 1} more combination{'s' if n0 > 2 else ''} of the "
            "state" + (f" ({said})" if said else ""))


def neutral_multipliers_text(gait) -> str:
    """The neutral multipliers of a gait that lies in a family (``gait.neutral``: the
    coordinates along which the gaits form one, e.g. a 3D wheel's heading), set aside by
    the verdict."""
    mult = np.asarray(gait.multipliers)
    pos = neutral_positions(mult, len(gait.neutral))
    said = ", ".join(f"{mult[i].real:+.6f} ({name.removesuffix('_angle')})"
                     for i, name in zip(pos, gait.neutral))
    return (f"neutral, set aside: {said} - the gaits form a family along "
            f"{'it' if len(pos) == 1 else 'them'} (Coleman, Chatterjee & Ruina 1997)")


def unstable_modes_text(gait, state_names: list[str]) -> list[str]:
    """One line per multiplier outside the unit circle (the neutral ones set aside): its
    value and the state components its eigenvector (of the stored ``DP``) moves most - the
    lean for a 3D walker's lateral mode (Kuo 1999), the legs' rates for a planar one's."""
    J = getattr(gait, "jacobian", None)
    if J is None or not np.all(np.isfinite(J)):
        return []
    mu, V = np.linalg.eig(J)
    order = np.argsort(-np.abs(mu), kind="stable")
    skip = set(neutral_positions(mu, len(gait.neutral)).tolist())
    out = []
    for i in order:
        if abs(mu[i]) <= 1.0 or int(i) in skip:
            continue
        v = np.abs(V[:, i])
        v = v / v.max()
        names = [state_names[k] for k in np.argsort(-v, kind="stable") if v[k] >= 0.3]
        out.append(f"  unstable mode {mu[i].real:+.6g}"
                   + (f"{mu[i].imag:+.3g}j" if abs(mu[i].imag) > 1e-12 else "")
                   + f": its eigenvector moves {', '.join(names)} most")
    return out


def _terrain_kind(scene_json) -> str | None:
    """``terrain.kind`` of a stored scene (None: no terrain section, or unreadable)."""
    import json

    try:
        return (json.loads(scene_json or "{}").get("terrain") or {}).get("kind")
    except (TypeError, ValueError, AttributeError):
        return None


def _stride_reason(scene_json) -> str:
    """Why a gait's Poincaré map is a stride (from the stored scene): "the legs differ",
    "the footholds differ" or both; "its steps differ" when the scene does not say."""
    import json

    try:
        d = json.loads(scene_json or "{}")
        legs = (d.get("walker") or {}).get("legs") or []
        terrain = d.get("terrain") or {}
    except (TypeError, ValueError, AttributeError):
        return "its steps differ"
    why = []
    if len(legs) > 1 and any(leg != legs[0] for leg in legs[1:]):
        why.append("legs")
    if terrain.get("kind") == "footholds" and any(
            len(set(terrain.get(k) or ())) > 1
            for k in ("foothold_heights_m", "foothold_slopes_rad")):
        why.append("footholds")
    return f"the {' and the '.join(why)} differ" if why else "its steps differ"


def _fd_error_text(scene_json: str) -> str:
    """Which multipliers the verdict uses and why, with the central differences' own error
    bound ``10 max(rtol, atol) / h`` (:func:`walkerlab.analysis.gait.poincare.
    multiplier_check_tolerance`; a stiff closed loop, as a five-link walker's computed
    torque, brings its finite-difference multipliers that close to the bound)."""
    import json

    try:
        sc = json.loads(scene_json)
        solver, fpset = sc.get("solver") or {}, sc.get("fixedpoint") or {}
        err = 10.0 * max(float(solver["rtol"]), float(solver["atol"])) / float(
            fpset.get("fd_step", 1e-7))
        bound = f" = {err:.1g}"
    except (ValueError, KeyError, TypeError):
        bound = ""
    return ("the verdict uses the variational multipliers, the map's Jacobian to the "
            "integrator's tolerance; central differences err by up to 10 max(rtol, atol) / h"
            f"{bound} and only check them")


def fixedpoint_text(fp: FixedPointArtifact) -> str:
    """Fixed point by leg name with units, step period, Floquet multipliers, verdict."""
    u, legs = fp.units, fp.legs_by_role
    lines = [f"fixed point ({fp.model}, {fp.variant} equations), {fp.section_words}:"]
    for n, x, unit in zip(fp.state_names, fp.x, fp.state_units):
        coord = n.rsplit("_", 1)[0]
        role = next((r for r in sorted(legs, key=len, reverse=True)
                     if coord == r or coord.startswith(r + "_")), None)
        where = f"({legs[role]}, {role} leg)" if role else "(not on a leg)"
        lines.append(f"  {n:<14s} {where} {x: .10f} {unit}")
    lines.append(f"  step period     {fp.step_period_s:.10f} {u.time}")
    if fp.stride_period_s is not None:  # legs that differ: the Poincare map is a stride
        lines.append(f"  stride period   {fp.stride_period_s:.10f} {u.time} (the map is a "
                     f"stride: {_stride_reason(fp.scene_json)})")
        for leg, T, d in zip(fp.step_swing_legs, fp.step_periods_s, fp.step_lengths_m):
            lines.append(f"    step with {leg} swinging: period {T:.10f} {u.time}, "
                         f"length {d:.10f} {u.length}")
    lines.append(f"  residual        {fp.residual:.2e}  (max |P(x*) - x*|)")
    re, im = fp.multipliers.real, fp.multipliers.imag
    per = _per(fp)  # the artifact's map: " per step" or " per stride"
    lines.append(f"Floquet multipliers (variational{',' + per if per else ''}): "
                 f"{_fmt_mult(re, im)}")
    lines.append(f"Floquet multipliers (finite diff.): "
                 f"{_fmt_mult(fp.multipliers_fd.real, fp.multipliers_fd.imag)}")
    lines.append(f"  max difference {fp.max_difference:.2e} ({_fd_error_text(fp.scene_json)})")
    mod = fp.max_abs_multiplier()
    verdict = "STABLE" if fp.stable else "UNSTABLE"
    why = (zero_multipliers_text(re, im, fp.state_names, fp.scene_json)
           if fp.zero_dynamics is None else "the others are the output feedback's and the "
           "heel-strike surface's, besides delta^2 of the zero dynamics")
    if fp.neutral:
        why = f"{neutral_multipliers_text(fp)}; {why}"
    lines.append(f"verdict: {verdict} (largest variational |multiplier|{per} = {mod:.6f}; "
                 f"{why})")
    lines += unstable_modes_text(fp, fp.state_names)
    if fp.zero_dynamics is not None:
        lines += zero_dynamics_text(fp.zero_dynamics)
    if fp.ground_contact is not None:
        lines.append(ground_contact_text(fp.ground_contact, u))
        if fp.ground_contact.friction is not None:
            lines.append(fp.ground_contact.friction.text())
        twist = twist_text(fp.ground_contact, u)
        if twist is not None:
            lines.append(twist)
    if _terrain_kind(fp.scene_json) == "profile":
        lines.append("ground: terrain.kind: profile: this is the gait of the scene's slope, "
                     "where the walk on the profile starts (walkerlab simulate walks the "
                     "profile; its steps all differ, so it has no fixed point of its own)")
    if fp.footholds is not None:
        lines.append(footholds_text(fp.footholds))
    lines += gaits_text(fp)
    return "\n".join(lines)


def zero_dynamics_text(z: dict) -> list[str]:
    """Lines on the hybrid zero dynamics (``fixedpoint.h5``'s ``zero_dynamics/``), the
    restricted Poincare map's numbers side by side with the full-order fixed point's."""
    p, fo = z["phase_unit"], z.get("full_order", {})
    E = "kg^2 m^4/s^2"

    def vs(key, val, fmt, unit):
        if key not in fo:
            return f"{val:{fmt}} {unit}"
        f = fo[key]
        return (f"{val:{fmt}} {unit}   full order {f:{fmt}} {unit}   |diff| "
                f"{abs(val - f):.1e}")
    lines = ["zero dynamics (virtual constraints; restricted Poincare map rho(zeta) = "
             "delta^2 zeta - V(theta-), zeta = sigma^2/2):"]
    d2 = z["delta2"]
    m = fo.get("delta2_multiplier")
    lines.append(f"  delta^2          {d2:.10f}" + (
        "" if m is None else f"   full-order multiplier {m.real:.10f}"
        + (f"{m.imag:+.1e}j" if m.imag else "") + f"   |diff| {abs(d2 - m):.1e}"))
    if "other_multiplier" in fo:
        lines.append(f"  other full-order multipliers: |.| <= {fo['other_multiplier']:.2e} "
                     "(the output feedback's)")
    verdict = "exists" if z["exists"] else "DOES NOT EXIST"
    lines.append(f"  V(theta-)        {z['v_minus']:.6g} {E}   V_max {z['v_max']:.6g} {E}")
    lines.append(f"  existence        delta^2/(1-delta^2) V(theta-) + V_max = "
                 f"{z['existence_margin']:.6g} {E}: the fixed point {verdict}"
                 + (f", {'stable' if z['stable'] else 'UNSTABLE'} (delta^2 "
                    f"{'<' if z['stable'] else '>='} 1)" if z["exists"] else ""))
    lines.append(f"  zeta*            {z['zeta_star']:.10g} {E}")
    lines.append(f"  theta+ / theta-  {z['theta_plus']:.10f} / {z['theta_minus']:.10f} {p}")
    lines.append("  phase rate at impact " + vs("phase_rate_minus", z["phase_rate_minus"],
                                                  ".10f", f"{p}/s"))
    lines.append("  phase rate after     " + vs("phase_rate_plus", z["phase_rate_plus"],
                                                  ".10f", f"{p}/s"))
    lines.append("  step period (quadrature) " + vs("step_period_s", z["step_period_s"],
                                                      ".10f", "s"))
    if "output_plus" in fo:
        lines.append(f"  outputs after heel strike (full order): max |y| {fo['output_plus']:.1e}"
                     f" rad, max |y'| {fo['output_rate_plus']:.1e} rad/s")
    lines.append(f"  invariance residuals: {z['invariance_residual_position']:.1e} rad, "
                 f"{z['invariance_residual_rate']:.1e} rad/{p}")
    for name, c in zip(z.get("outputs", ()), z.get("bezier", ())):
        lines.append(f"  {name:<18s} bezier_rad in force: [{', '.join(f'{v:.6g}' for v in c)}]")
    sat = "BINDS: the zero dynamics is not the closed loop's" if z["saturates"] else \
        "within the saturation"
    lines.append(f"  max |u| along the orbit {z['max_torque_n_m']:.4g} N m ({sat}); lowest "
                 f"swing foot inside the step {z['min_clearance_m'] * 1e3:.4g} mm")
    lines.append(f"  timing: delta^2 {z['timing_delta2_s'] * 1e3:.3g} ms, zero dynamics "
                 f"{z['timing_total_s'] * 1e3:.3g} ms")
    return lines


def _per(gait) -> str:
    """``" per step"`` or ``" per stride"``: the map of a stored gait's multipliers
    (:attr:`~walkerlab.io.schemas.fixedpoint.GaitResult.steps_per_map`); ``""`` when not
    known."""
    per = per_map(getattr(gait, "steps_per_map", 0))
    return f" {per}" if per else ""


def unstable_gait_line(fp: FixedPointArtifact) -> str:
    """One line on an unstable selected gait: its largest |Floquet multiplier| and whether
    any stable period-1 gait was found (``walkerlab fixedpoint --require-stable``)."""
    mod = float(np.max(np.abs(fp.multipliers)))
    n = max(len(fp.gaits), 1)
    head = (f"the gait found is unstable (largest |Floquet multiplier|{_per(fp)} "
            f"{mod:.4g} > 1, step "
            f"period {fp.step_period_s:.6g} {fp.units.time}); ")
    stable = [lab.replace("_", "-") for lab, g in fp.gaits.items() if g.stable]
    if stable:  # the scene's policy chose another: say so
        return head + (f"the {stable[0]} gait is stable: set fixedpoint.gait: stable (the "
                       f"scene's {fp.gait_policy or 'policy'} chose the unstable one)")
    return head + (f"no stable period-1 gait was found ({n} gait{'s' if n > 1 else ''} "
                   "found, all unstable)")


_GAIT_SOURCES = {"initial_guess": "root finder from the initial guess",
                 "seed": "root finder from a scale-free seed",
                 "deflation": "deflated root finder near the other gait",
                 "stored_gait": "root finder from a stored gait carried here",
                 "planar_twin": "root finder from the planar twin's gait"}


def gaits_text(fp: FixedPointArtifact) -> list[str]:
    """Lines on the period-1 gaits recorded in ``fixedpoint.h5`` (every gait found, the one
    selected by ``fixedpoint.gait`` marked ``*``, and why)."""
    if not fp.gaits:
        return []
    labels, sel = list(fp.gaits), fp.gait
    skipped = any("other_gait: false" in n for n in fp.gait_notes)  # not looked for
    lines = [f"period-1 gaits found: {len(labels)}" + (
        "" if len(labels) > 1 else " (the other gait of the long/short-period pair, if it "
        f"exists, was {'not looked for' if skipped else 'not found'})")]
    for lab, g in fp.gaits.items():
        mod = g.max_abs_multiplier()  # the neutral ones (a family's) set aside
        lines.append(f"  {'*' if lab == sel else ' '} {lab.replace('_', '-'):<12s} step period "
                     f"{g.step_period_s:.6f} {fp.units.time}, max |multiplier|"
                     f"{_per(g)} {mod:.4g}, "
                     f"{'stable' if g.stable else 'UNSTABLE'}{ground_word(g, fp.units)} "
                     f"({_GAIT_SOURCES.get(g.source, g.source)})")
    notes = fp.gait_notes
    lines.append(f"selected (fixedpoint.gait: {fp.gait_policy}): "
                 f"{sel.replace('_', '-')} gait" + ("; " + "; ".join(notes) if notes else ""))
    return lines
