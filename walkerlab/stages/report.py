"""Stage ``report``: run what the scene needs (reusing up-to-date artifacts), draw the
figures and write ``runs/<scene>/report/report.html`` (self-contained) and ``report.md``.

Sections appear only when the scene produces their data: an ideal-only scene gets an
ideal-only report, with no empty contact panels.
"""

from __future__ import annotations

import datetime as _dt
import json
import platform
from collections.abc import Callable
from pathlib import Path

import numpy as np

import walkerlab
from walkerlab.config import Scene
from walkerlab.io.artifacts import open_artifact
from walkerlab.report.markdown import table as _table
from walkerlab.report.markdown import to_html as _to_html
from walkerlab.stages.common import StageOutcome, artifact_path
from walkerlab.stages.plot import figures_dir


def _run_stages(scene: Scene, runs_root, force: bool, echo) -> list[StageOutcome]:
    from walkerlab.stages import fixedpoint, simulate

    done: list[StageOutcome] = []
    if scene.fixedpoint is not None:
        done.append(fixedpoint.run(scene, runs_root, force, compare_variants=True))
    if scene.simulate is not None:
        done.append(simulate.run(scene, runs_root, force))
    if scene.contact is not None:
        from walkerlab.stages import contact_sim

        done.append(contact_sim.run(scene, runs_root, force))
        if scene.simulate is not None:
            from walkerlab.stages import compare

            done.append(compare.run(scene, runs_root, force))
    if getattr(scene, "workprecision", None) is not None:
        from walkerlab.stages import workprecision

        done.append(workprecision.run(scene, runs_root, force))
    for o in done:
        echo(f"{o.stage:>13s}: " + ("reused (inputs unchanged)" if o.reused
                                    else f"computed in {o.wall_time_s:.2f} s") + f" -> {o.path}")
    return done


def _fixedpoint_section(path: Path) -> str:
    from walkerlab.stages.fixedpoint import PAPER_EQ11

    out = ["## Fixed point of the Poincaré map (paper Sec. 3.3, Eq. 11)", ""]
    with open_artifact(path, "fixedpoint") as f:
        names = [str(n) for n in f.attrs["state_names"]]
        main = str(f.attrs["variant"])
        rows = [["paper Eq. (11) (printed)", *PAPER_EQ11, "—", "—", "—"]]
        fps = {}
        for v in f["variants"]:
            g = f["variants"][v]
            if "error" in g.attrs:
                rows.append([v, *(["—"] * 4), "—", "—", g.attrs["error"]])
                continue
            x = np.array([g[f"fixed_point/{n}"][()] for n in names])
            fps[v] = x
            re, im = g["floquet/variational/real"][()], g["floquet/variational/imag"][()]
            rows.append([f"walkerlab `{v}`" + (" (this scene)" if v == main else ""), *x,
                         float(g["step_period"][()]), float(np.max(np.hypot(re, im))),
                         f"{g['residual'][()]:.1e}"])
        out.append(_table(["model", *[f"{n}" for n in names], "step period [s]",
                           "max abs(multiplier)", "residual"], rows))
        out.append("")
        out.append("Units: angles in rad, rates in rad/s; state right after heel strike, "
                   "θ1 = swing leg (leg1), θ2 = stance leg (leg2).")
        if "appendix_a" in fps and "derived" in fps:
            d = fps["derived"] - PAPER_EQ11
            a = fps["appendix_a"] - PAPER_EQ11
            out.append("")
            out.append(
                "**Why the numbers differ.** The printed Appendix A (variant `appendix_a`) "
                "reproduces Eq. (11): its deviation from the printed digits is "
                f"{np.array2string(a, precision=5)} (θ̇2 = {fps['appendix_a'][3]:.4f} is printed "
                "as −0.84, i.e. truncated, not rounded). Its Coriolis matrix (A.5) has the wrong "
                "sign in C[1,0] (+m L b θ̇1 sin(θ2−θ1) instead of −), so energy is not conserved "
                "in swing. The energy-consistent derived model (`derived`, the default) gives a "
                f"different gait: deviation from Eq. (11) {np.array2string(d, precision=5)}, "
                f"i.e. up to {np.max(np.abs(d[:2])):.4f} rad in the angles and "
                f"{np.max(np.abs(d[2:])):.4f} rad/s in the rates. Taking the printed y-component "
                "of A.55 literally (`appendix_a_literal`) does not reproduce Eq. (11) at all, so "
                "that sign is a typesetting error only.")
        re, im = f["floquet/variational/real"][()], f["floquet/variational/imag"][()]
        re2, im2 = f["floquet/finite_difference/real"][()], f["floquet/finite_difference/imag"][()]
        out += ["", f"### Floquet multipliers (`{main}`)", "",
                _table(["#", "variational equations", "finite differences", "abs value"],
                       [[i + 1, f"{a:+.10f}{b:+.10f}j", f"{c:+.10f}{d:+.10f}j",
                         float(np.hypot(a, b))]
                        for i, (a, b, c, d) in enumerate(zip(re, im, re2, im2))]),
                "", f"Max difference between the two: {f['floquet/max_difference'][()]:.2e}. "
                f"Verdict: **{'stable' if f['floquet/stable'][()] else 'unstable'}** "
                "(one multiplier is 0 by construction: the map lands on the heel-strike "
                "surface)."]
    return "\n".join(out)


def _table3_section(scene: Scene, runs_root) -> str:
    from walkerlab.analysis.tables import PAPER_DELTA_X_M, PAPER_TABLE3, TABLE3_ROWS, table3

    paths = {}
    sim = artifact_path(scene, runs_root, "simulate")
    con = artifact_path(scene, runs_root, "contact-sim")
    if sim.is_file():
        paths["ours, ideal"] = ("simulate", sim)
    if con.is_file():
        paths["ours, contact"] = ("contact-sim", con)
    if not paths:
        return ""
    w = scene.walker
    cols = table3(paths, w.hip_mass_kg + 2 * w.leg_mass_kg, w.gravity_m_per_s2)
    header = ["quantity", "symbol", "unit", "paper MATLAB", "paper ADAMS", *cols]
    rows = []
    for key, (name, sym, unit) in TABLE3_ROWS.items():
        rows.append([name, sym, unit, *PAPER_TABLE3[key], *(c[key] for c in cols.values())])
    rows.append(["Average mechanical energy, PE from the current stance foot", "E_avg'", "J",
                 "", "", *(c.get("E_avg_stance_frame_J", np.nan) for c in cols.values())])
    rows.append(["Step length", "Δx", "m", PAPER_DELTA_X_M, PAPER_DELTA_X_M,
                 *(c["step_length_m"] for c in cols.values())])
    ideal = cols.get("ours, ideal")
    out = ["## Table 3 — gait characteristics", "",
           "Recomputed from the trajectory artifacts ("
           + ", ".join(f"`{p.name}`" for _, p in paths.values()) + ").", "",
           _table(header, rows)]
    if ideal:
        from walkerlab.stages.fixedpoint import PAPER_EQ11

        L = w.leg_length_m
        dx_eq11 = 2 * L * np.sin((PAPER_EQ11[1] - PAPER_EQ11[0]) / 2)
        out += ["", "**Differences from the published Table 3, measured:**", "",
                f"- *Left/right step periods.* A period-1 gait has identical steps: ours are "
                f"{ideal['t_left_s']:.4f} s and {ideal['t_right_s']:.4f} s. The published 0.60 s "
                "and 0.79 s cannot both belong to the period-1 fixed point of Eq. (11); their "
                f"sum 1.39 s is within {abs(1.39 - ideal['t_cycle_s']):.3f} s of our cycle "
                f"period {ideal['t_cycle_s']:.4f} s.",
                f"- *Step length Δx.* Eq. (11) itself implies Δx = 2 L sin((θ2 − θ1)/2) = "
                f"{dx_eq11:.4f} m (ours: {ideal['step_length_m']:.4f} m), about 11× the printed "
                f"0.0342 m. With the printed Δx the speed formula gives 0.0342/1.39 = 0.0246 m/s, "
                f"the printed v_com; the walker actually advances at {ideal['v_com_m_per_s']:.4f}"
                " m/s (hip displacement over whole cycles / time).",
                f"- *Energy.* With the potential energy measured from the current stance foot "
                f"we get E_avg' = {ideal.get('E_avg_stance_frame_J', np.nan):.2f} J, within "
                f"{abs(150.13 - ideal.get('E_avg_stance_frame_J', np.nan)):.2f} J of the "
                f"printed 150.13 J; measured from a fixed datum (first stance foot) the average "
                f"over 5 steps is {ideal['E_avg_J']:.2f} J because the walker descends "
                f"{scene.slope.phi_rad:.4f} rad slope by Δx sin φ per step."]
    return "\n".join(out)


def _figures(scene: Scene, runs_root) -> list[tuple[str, Path]]:
    d = figures_dir(scene, runs_root)
    captions = [
        ("fig7_angles_rates", "Fig. 7 — leg angles and angular rates over the simulated strides."),
        ("fig8_errors", "Fig. 8 — error contact − ideal, angles and rates."),
        ("fig9_limit_cycles", "Fig. 9 — limit cycles in the phase plane (rate vs angle, per leg)."),
        ("fig10_energy", "Fig. 10 — kinetic, potential and total mechanical energy."),
        ("fig2_stick_ideal", "Fig. 2 — stick diagram of one gait cycle, ideal model."),
        ("fig6_stick_contact", "Fig. 6 — stick diagram of one gait cycle, contact model."),
        ("work_precision_ideal", "Work-precision diagram, ideal model."),
        ("work_precision_contact", "Work-precision diagram, contact model."),
        ("bifurcation", "Bifurcation diagram over the slope."),
    ]
    return [(cap, d / f"{stem}.png") for stem, cap in captions if (d / f"{stem}.png").is_file()]


def _extra_sections(scene: Scene, runs_root) -> list[str]:
    """Sections contributed by other stages' artifacts (contact, compare, work-precision)."""
    out = []
    try:
        from walkerlab.report import contact_sections
    except ImportError:  # pragma: no cover - contact report not available
        return out
    out += contact_sections.sections(scene, runs_root)
    return out


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        echo: Callable[[str], None] = print) -> Path:
    """Run the needed stages, draw figures, write ``report.md`` and ``report.html``.

    Returns
    -------
    Path
        The HTML report.
    """
    from walkerlab.stages import plot

    done = _run_stages(scene, runs_root, force, echo)
    figs = plot.run(scene, runs_root) if any(
        o.stage in ("simulate", "contact-sim") for o in done) else []
    echo(f"         plot: {len([p for p in figs if p.suffix == '.png'])} figures")
    rep_dir = Path(runs_root) / (scene.name or "scene") / "report"
    rep_dir.mkdir(parents=True, exist_ok=True)
    import scipy

    md = [f"# walkerlab report — scene `{scene.name}`", "",
          f"- source: {scene.source or '—'}",
          f"- walkerlab {walkerlab.__version__}, Python {platform.python_version()}, "
          f"numpy {np.__version__}, scipy {scipy.__version__}, machine {platform.machine()} "
          f"({platform.processor() or platform.system()})",
          f"- generated {_dt.datetime.now(_dt.UTC).strftime('%Y-%m-%d %H:%M UTC')}",
          f"- slope φ = {scene.slope.phi_rad:.6f} rad ({np.degrees(scene.slope.phi_rad):.4f}°); "
          f"ideal equations: `{scene.ideal.variant}`; solver {scene.solver.method} "
          f"rtol {scene.solver.rtol:g} atol {scene.solver.atol:g}",
          "", "## What ran", "",
          _table(["stage", "artifact", "status", "compute [s]"],
                 [[o.stage, f"`{o.path}`", "reused" if o.reused else "computed",
                   float(o.wall_time_s)] for o in done]), ""]
    fp = artifact_path(scene, runs_root, "fixedpoint")
    if fp.is_file():
        md += [_fixedpoint_section(fp), ""]
    t3 = _table3_section(scene, runs_root)
    if t3:
        md += [t3, ""]
    md += _extra_sections(scene, runs_root)
    figs = _figures(scene, runs_root)
    if figs:
        md += ["## Figures", ""]
        for cap, p in figs:
            md += [f"![{cap}](figures/{p.name})", "", f"*{cap}*", ""]
    md += ["## Scene", "", "```json", json.dumps(scene.model_dump(mode="json", exclude_none=True),
                                                  indent=1), "```", ""]
    text = "\n".join(md)
    (rep_dir / "report.md").write_text(text)
    html_path = rep_dir / "report.html"
    html_path.write_text(_to_html(text, rep_dir))
    return html_path
