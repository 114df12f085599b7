"""Commands over a family of scenes: sweeps, bifurcation diagrams, continuation."""

from __future__ import annotations

from pathlib import Path

import typer

from walkerlab.cli.errors import fail, guard
from walkerlab.cli.options import ForceOpt, RunsOpt, SceneArg, load, status
from walkerlab.units import map_name, per_map


@guard
def sweep(scene: Path | None = SceneArg,
          param: list[str] = typer.Option(..., "--param", help="dotted scene field and values, "
                                          "e.g. slope.angle_deg=0.5:5:0.05 or a,b,c"),
          stage: str = typer.Option("fixedpoint", "--stage",
                                    help="fixedpoint | simulate | contact-sim"),
          workers: int = typer.Option(2, "--workers", min=1, help="local worker processes"),
          scheduler: str | None = typer.Option(None, "--scheduler",
                                                  help="Dask scheduler address (tcp://host:port)"),
          resume: bool = typer.Option(False, "--resume", help="continue an interrupted sweep"),
          name: str | None = typer.Option(None, "--name", help="artifact name"),
          runs_dir: Path = RunsOpt) -> None:
    """Run a stage over a grid of scene fields; one row per point, failures recorded."""
    from walkerlab.io.sweep_store import load_sweep  # light
    from walkerlab.report.sweep_text import sweep_text  # light
    from walkerlab.stages import sweep as stage_mod  # light

    sc = load(scene)
    path = stage_mod.run(sc, param, stage=stage, workers=workers,
                         scheduler=scheduler, resume=resume, runs_root=runs_dir, name=name)
    typer.echo(sweep_text(load_sweep(path)))
    typer.echo(f"wrote {path}")
    typer.echo(f"figure: {stage_mod.figure_path(sc, path, runs_dir)}")


@guard
def bifurcation(scene: Path | None = SceneArg,
                slopes: str | None = typer.Option(None, "--slopes",
                                                  help="slope grid in degrees: start:stop:step "
                                                  "or a,b,c (default 1:5.5:0.05)",
                                                  show_default=False),
                param: str | None = typer.Option(None, "--param",
                                                 help="continue over another numeric scene "
                                                 "field instead of the slope, in the field's "
                                                 "unit: FIELD=start:stop:step or FIELD=a,b,c "
                                                 "(e.g. walker.leg.bodies.thigh_mass.mass_kg"
                                                 "=0.3:0.7:0.05); writes "
                                                 "bifurcation_<FIELD>.h5"),
                transient: int = typer.Option(100, "--transient", min=1,
                                              help="steps discarded before sampling"),
                keep: int = typer.Option(30, "--keep", min=1,
                                         help="heel strikes kept per grid value"),
                workers: int = typer.Option(2, "--workers", min=1, help="worker processes"),
                runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Bifurcation diagram over the slope (or any numeric scene field, --param): fixed
    points, multipliers, period-doubling onset."""
    from walkerlab.stages import bifurcation as stage  # light
    from walkerlab.studies.params import (  # light
        SweepError,
        check_axes,
        parse_param,
        takes_whole_numbers,
    )

    if slopes is not None and param is not None:
        fail(SweepError("--slopes and --param exclude each other (--slopes S is "
                         "--param slope.angle_deg=S)"))
    try:
        axis = parse_param(param if param is not None
                           else f"slope.angle_deg={slopes or '1:5.5:0.05'}")
    except SweepError as exc:  # name the option the user typed
        if param is not None:
            raise
        fail(SweepError(str(exc).replace(f"--param 'slope.angle_deg={slopes}'",
                                          f"--slopes {slopes!r}")))
    sc = load(scene)
    if param is not None:
        check_axes(sc, [axis], values=not takes_whole_numbers(sc, axis))
        if not axis.numeric:
            fail(SweepError(f"--param {axis.spec!r}: a bifurcation needs numbers"))
        if takes_whole_numbers(sc, axis):
            fail(SweepError(f"--param {axis.spec!r}: {axis.path} takes whole numbers; a "
                             "bifurcation continues over a real-valued field (e.g. "
                             "slope.angle_deg or a body's mass_kg)"))
    out = stage.run(sc, axis.values, runs_dir, transient, keep, workers, force=force,
                    param=axis.path)
    onset, unit = out.summary["onset"], out.summary["unit"]
    where = (f"{onset:.4f} deg" if axis.path == "slope.angle_deg"
             else f"{axis.path} = {onset:.6g} {unit}".removesuffix(" -"))
    typer.echo(f"period-doubling onset: {where}" if onset == onset
               else "period-doubling onset: none on the grid")
    typer.echo(status(out))
    typer.echo("figures: " + ", ".join(str(p) for p in out.summary["figures"]))


def _range_spec(text: str, opt: str) -> tuple[str, float, float]:
    """``FIELD=START:STOP`` -> (field, start, stop); one-line error otherwise (the numbers
    are checked by the stage, as for a call from Python)."""
    from walkerlab.studies.params import SweepError  # light

    path, _, rhs = text.partition("=")
    parts = rhs.split(":")
    try:
        if not path.strip() or len(parts) != 2:
            raise ValueError
        a, b = float(parts[0]), float(parts[1])
    except ValueError:
        raise SweepError(f"{opt} {text!r}: expected FIELD=START:STOP (two different "
                         "numbers in the field's unit)") from None
    return path.strip(), a, b


@guard
def continuation(scene: Path | None = SceneArg,
                 param: str = typer.Option(..., "--param", help="FIELD=START:STOP, any "
                                           "numeric scene field in its unit (e.g. "
                                           "slope.angle_deg=0.5:5.2)"),
                 switch: bool = typer.Option(False, "--switch", help="switch at period "
                                             "doublings to the period-2 and period-4 "
                                             "branches"),
                 param2: str | None = typer.Option(None, "--param2", help="FIELD2=START:STOP: "
                                                   "continue each fold and period doubling "
                                                   "in the plane of both fields"),
                 runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Pseudo-arclength continuation of the scene's gait over a field: folds, period
    doublings, Neimark-Sacker points, branch ends; writes continuation_<FIELD>.h5
    (continuation_<FIELD>+<FIELD2>.h5 with --param2)."""
    from walkerlab.stages import continuation as stage  # light

    path, a, b = _range_spec(param, "--param")
    p2 = _range_spec(param2, "--param2") if param2 else None
    out = stage.run(load(scene), path, a, b, 2 if switch else 0,
                    p2[0] if p2 else None, p2[1:] if p2 else None, runs_dir, force)
    data = out.summary["data"]
    sp = data.special
    unit = "" if data.unit == "-" else f" {data.unit}"
    for i, kind in enumerate(sp["kind"]):
        cause = f" ({sp['cause'][i]})" if kind == "branch_end" else ""
        typer.echo(f"{kind:16s} period {int(sp['period'][i])}  {path} = "
                   f"{float(sp['param'][i]):.10g}{unit}{cause}")
    if not len(sp["kind"]):
        typer.echo("no special point in the range")
    if map_name(data.steps_per_map):  # the one map of every branch: multipliers per it
        typer.echo(f"Poincaré map: one {map_name(data.steps_per_map)} on every branch "
                   f"(period k: k {map_name(data.steps_per_map)}s; Floquet multipliers "
                   f"{per_map(data.steps_per_map)} for period 1)")
    for c in data.curves:
        typer.echo(f"{c['kind']} curve over {c['path2']}: {len(c['param2'])} points")
    typer.echo(status(out))
    typer.echo("figures: " + ", ".join(str(p) for p in out.summary["figures"]))


@guard
def target(scene: Path | None = SceneArg,
           vary: str = typer.Option(..., "--vary", help="the numeric scene field to solve for "
                                    "(e.g. walker.actuation.push_off.impulse_n_s)"),
           speed: float | None = typer.Option(None, "--speed-m-per-s", help="target speed, m/s"),
           step_length: float | None = typer.Option(None, "--step-length-m",
                                                    help="target step length, m"),
           step_period: float | None = typer.Option(None, "--step-period-s",
                                                    help="target step period, s")) -> None:
    """Find the value of one field (an actuation parameter) whose period-1 gait has a target
    speed, step length or step period (solved with the fixed point); prints it and the gait.
    Writes nothing: set the value in the scene (or pass it to sweep/continuation)."""
    import walkerlab as wl

    given = {k: v for k, v in (("speed_m_per_s", speed), ("step_length_m", step_length),
                               ("step_period_s", step_period)) if v is not None}
    if len(given) != 1:
        fail(ValueError("target: give exactly one of --speed-m-per-s, --step-length-m, "
                        f"--step-period-s (got {len(given) or 'none'})"))
    from walkerlab.analysis.continuation.target import TargetNotReached  # light
    from walkerlab.analysis.gait.search import GaitNotFound  # light

    try:
        w, gait = wl.Walker.from_scene(load(scene)).find_gait_for(vary, **given)
    except (TargetNotReached, GaitNotFound) as exc:
        raise ValueError(f"target: {exc}; try a target nearer the scene's own gait, or "
                         f"follow it with walkerlab continuation --param {vary}=...") from None
    (name, value), = given.items()
    from walkerlab.studies.continuation import scene_value  # light
    from walkerlab.units import field_unit, for_scene

    u = for_scene(w.scene)
    typer.echo(f"{vary} = {scene_value(w.scene, vary):.10g} {u(field_unit(vary) or '-')} "
               f"gives {name.rsplit('_', 1)[0].rsplit('_m', 1)[0]} = {value:g} "
               f"{u(field_unit(name) or '-')}")
    per = per_map(w.model.steps_per_map)  # the walker's own map: a step or a stride
    typer.echo(f"  step period {gait.step_period:.6g} {u.time}, max |Floquet multiplier| "
               f"{per} {gait.max_abs_multiplier:.4g} "
               f"({'stable' if gait.stable else 'unstable'})")
    for n, v in gait.state.items():
        typer.echo(f"  {n:14s} {v:+.8f}")


@guard
def optimize(scene: Path | None = SceneArg,
             design: list[str] = typer.Option(None, "--design", help="a numeric scene field "
                                              "and its bounds, FIELD=LO:HI (repeatable): "
                                              "optimise the design instead of the gait"),
             objective: str = typer.Option("max_abs_multiplier", "--objective",
                                           help="with --design: step_period | step_length "
                                           "| speed | cost_of_transport | "
                                           "max_abs_multiplier | gait_sensitivity_norm | "
                                           "basin_share | mfpt"),
             maximize: bool = typer.Option(False, "--maximize", help="with --design: "
                                           "maximise the objective"),
             require_gait: bool = typer.Option(False, "--require-gait",
                                               help="exit non-zero (one line) when the "
                                               "optimum is not a gait (IPOPT did not "
                                               "converge or the rigid replay does not "
                                               "close); optimize.h5 stays"),
             svg: bool = typer.Option(False, "--svg", help="also write the figure as "
                                      "SVG (walkerlab report always does)"),
             runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """A periodic gait of a walker with a hip torque (a five-link biped: hip and knee
    torques) by direct collocation (CasADi + IPOPT; the scene's optimize section): least
    int u^2 dt, the targets and limits given, replayed on the rigid model; writes
    optimize.h5.  With --design: the fields within
    their bounds that minimise (--maximize: maximise) a measure of the scene's own gait,
    followed from the scene's values, gradients through the fixed point; writes
    optimize_design_<fields>_<objective>[_maximize].h5 (one per fields and objective)."""
    from walkerlab.stages import pipeline  # light

    if design:
        if require_gait:
            raise ValueError("--require-gait: with the gait's optimisation, not --design "
                             "(a design follows the scene's own gait)")
        _optimize_design(scene, design, objective, maximize, runs_dir, force)
        return

    from walkerlab.report.figures_section import not_a_gait_reason  # light

    sc = load(scene)
    out = pipeline.run("optimize", sc, runs_dir, force)
    d = out.summary.get("data")
    if d is not None:
        _echo_optimum(sc, d)
    typer.echo(status(out))
    from walkerlab.stages.optimize import draw  # light

    typer.echo(f"figure: {draw(load(scene), runs_dir, svg, keep_current=True)[0]}")
    if require_gait:  # the artifact stays: it holds what was found
        from walkerlab.io.schemas.optimize import load as load_optimize  # light

        d = d if d is not None else load_optimize(out.path)
        if not d.gait:
            fail(RuntimeError(f"--require-gait: the optimum is NOT a gait: "
                              f"{not_a_gait_reason(d)}"))


def _echo_optimum(sc, d) -> None:
    """Print the optimum ``d`` (an ``OptimizeData``) of ``walkerlab optimize`` in the scene's
    units: IPOPT's status, the step, the objective, the replays (rigid, phase-variable laws,
    contact model) and whether it is a gait."""
    from walkerlab.report.figures_section import cot_terms_text, not_a_gait_reason  # light
    from walkerlab.units import for_scene

    u = for_scene(sc)  # the scene's units (a nondimensional scene: l, sqrt(l/g), ...)
    t = u.time
    mu = max(abs(d.multipliers)) if len(d.multipliers) else float("nan")
    cpu = "" if d.cpu_time_s != d.cpu_time_s else f", CPU {d.cpu_time_s:.2f} s"
    typer.echo(f"IPOPT: {d.status} after {d.iterations} iterations ({d.wall_time_s:.2f} s"
               f"{cpu})")
    peak = ", ".join(f"{n} {v:.4g}" for n, v in zip(
        d.torque_names, abs(d.torque.reshape(len(d.time), -1)).max(axis=0)))
    typer.echo(f"  step period {d.step_period_s:.6g} {t}, step length "
               f"{d.step_length_m:.5g} {u.length}, speed "
               f"{d.step_length_m / d.step_period_s:.5g} {u.speed}, push-off "
               f"{d.push_off_n_s:.5g} {u('N s')}, peak |torque| [{u(d.torque_unit)}]: "
               f"{peak}")
    if d.start_shift == d.start_shift:  # closed by shooting (a five-link biped)
        typer.echo(f"  open loop from the collocated start: return error "
                   f"{d.collocated_start_error:.2g}; closed by shooting under the same "
                   f"torques: start moved {d.start_shift:.2g}, step period "
                   f"{d.replay_step_period_s:.9g} {t}")
    typer.echo(f"  objective {d.objective_name} = {d.objective:.6g} {u(d.objective_unit)}"
               + cot_terms_text(d, u) + f"; replay return error {d.replay_error:.2g}; "
               f"max |Floquet multiplier| {mu:.4g}")
    if d.phase_replay_outcome:  # asked for, and refused (a non-monotonic phase variable)
        typer.echo(f"  phase-variable replay: {d.phase_replay_outcome}")
    for i, c in enumerate(d.controllers):  # optimize.design: virtual_constraints
        loop = c.full_order_step_length_m / c.full_order_step_period_s
        typer.echo(f"  controller {i + 1} ({c.scene_file}): collocated {c.step_length_m:.5g} m"
                   f" in {c.step_period_s:.6g} s ({c.step_length_m / c.step_period_s:.6g} m/s,"
                   f" the targets'), delta^2 {c.delta2:.10g} (its restricted map "
                   f"{c.delta2_restricted:.10g}, the full-order multiplier "
                   f"{abs(c.delta2_multiplier):.10g}), closed loop "
                   + (f"{c.full_order_step_length_m:.6g} m in {c.full_order_step_period_s:.6g}"
                      f" s ({loop:.6g} m/s)" if loop == loop else "without a fixed point")
                   + f", IPOPT {c.status}"
                   + ("" if c.status == "Solve_Succeeded" else ": NOT a designed controller"))
    for law, r in d.phase_replays.items():  # the phase-variable laws (when asked for)
        typer.echo(f"  phase-variable {law} law: from the collocated start "
                   f"{r.collocated_start_error:.2g}; "
                   + (f"closed (start moved {r.start_shift:.2g}): return error "
                      f"{r.return_error:.2g}, step period {r.step_period_s:.9g} {t}, "
                      if r.closed else "not closed, ")
                   + f"max |multiplier| {max(abs(r.multipliers)):.4g}, torque within "
                   f"{r.torque_error:.2g} {u('N m')} of the optimal")
    if d.contact_step_period_s == d.contact_step_period_s:  # not NaN: replayed
        typer.echo(f"  contact model driven by the optimised torque: step period "
                   f"{d.contact_step_period_s:.5g} {t} "
                   f"({100 * (d.contact_step_period_s / d.step_period_s - 1):+.2f} %)"
                   + ("" if d.contact_outcome == "heel_strike" else
                      f"; the run ended short of its strides: {d.contact_outcome}"))
    else:
        typer.echo(f"  contact model: {d.contact_outcome}")
    typer.echo("  a gait (the replay closes)" if d.gait else
               f"  NOT a gait: {not_a_gait_reason(d)}")


def _optimize_design(scene, design, objective, maximize, runs_dir, force) -> None:
    """``walkerlab optimize --design``: parse FIELD=LO:HI, run, print the optimum."""
    from walkerlab.optimal.design.search import MEASURES, design_bounds  # light
    from walkerlab.stages import optimize as stage  # light
    from walkerlab.stages import pipeline  # light

    if objective not in MEASURES:
        raise ValueError(f"--objective: one of {', '.join(MEASURES)}, not {objective!r}")
    sc = load(scene)
    bounds = design_bounds(sc, design)  # every field checked before the upstream stages
    for up in pipeline.order("fixedpoint", sc):  # the design follows the scene's own gait
        pipeline.stage_module(up).run(sc, runs_dir)  # (a five-link biped's optimize needs none)
    out = stage.run_design(sc, runs_dir, force, bounds, objective, maximize)
    r = out.summary.get("design")
    if r is not None:
        typer.echo(f"{'maximised' if maximize else 'minimised'} {r.objective}: "
                   f"{r.value:.8g} after {r.evaluations} fixed points ({r.message})")
        for f, v, g in zip(r.fields, r.values, r.gradient):
            typer.echo(f"  {f} = {v:.8g}   d{r.objective}/d field = {g:.4g}")
    typer.echo(status(out))
    for path in stage.draw_design(sc, runs_dir, list(bounds), objective, maximize)[:1]:
        typer.echo(f"figure: {path}")
