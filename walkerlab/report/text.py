"""Plain-text summaries of artifacts, printed by the CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from walkerlab.io.artifacts import open_artifact


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
        lines.append(f"  step period     {f['step_period'][()]:.10f} s")
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
    return "\n".join(lines)


def simulate_text(path: Path) -> str:
    """Steps completed, per-step period/length/speed, energy."""
    with open_artifact(path, "simulate") as f:
        s = f["steps"]
        lines = [f"simulated {f.attrs['strides_requested']} strides: "
                 f"{int(np.sum(s['termination'][()] == b'heel_strike'))} heel strikes, "
                 f"ended by {f.attrs['termination']}"]
        lines.append(f"  mean step period  {f['summary/mean_period_s'][()]:.6f} s")
        lines.append(f"  mean step length  {f['summary/mean_step_length_m'][()]:.6f} m")
        lines.append(f"  mean hip speed    {f['summary/mean_hip_speed_m_per_s'][()]:.6f} m/s")
        lines.append(f"  mean total energy {f['summary/mean_total_energy_J'][()]:.4f} J "
                     "(potential from the first stance foot)")
        lines.append(f"  RHS evaluations   {int(f['summary/nfev'][()])}, "
                     f"integration {f['summary/wall_time_s'][()]:.3f} s")
    return "\n".join(lines)


def contact_text(path: Path) -> str:
    """Summary of a contact-sim artifact."""
    with open_artifact(path, "contact-sim") as f:
        lines = [f"contact walker: outcome {f.attrs.get('outcome', '?')} "
                 f"({f.attrs.get('outcome_message', f.attrs.get('termination', '?'))})"]
        if "initial_rate_scale" in f and "adjust" in f:  # --adjust: the scale it found
            s = np.atleast_1d(f["initial_rate_scale"][()])
            lines.append("adjusted initial rate scale (found by --adjust): "
                         + ", ".join(f"{v:.4g}" for v in s))
        if "summary" in f:
            for k in f["summary"]:
                ds = f["summary"][k]
                lines.append(f"  {k:<28s} {ds[()]} {ds.attrs.get('unit', '')}")
        if "periodic_gait" in f and "step_period" not in f["periodic_gait"]:
            g = f["periodic_gait"]
            lines.append(f"periodic contact gait: not found ({g.attrs.get('outcome', '?')}: "
                         f"{g.attrs.get('message', '')})")
        elif "periodic_gait" in f:
            g = f["periodic_gait"]
            mult = g["multipliers/real"][()] + 1j * g["multipliers/imag"][()]
            lines.append(f"periodic contact gait: step period {g['step_period'][()]:.6f} s, "
                         f"step length {g['step_length'][()]:.6f} m, "
                         f"{'stable' if g['stable'][()] else 'unstable'}")
            lines.append("  Floquet multipliers: " + ", ".join(f"{m:.5f}" for m in mult[:3])
                         + f" (+{len(mult) - 3} fast contact modes ~0)")
    return "\n".join(lines)
