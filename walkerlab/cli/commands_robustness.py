"""Commands that measure how robust the gait is: basin of attraction, mean first-passage
time, robustness measures, contact stability maps."""

from __future__ import annotations

from pathlib import Path

import typer

from walkerlab.cli.errors import fail, guard
from walkerlab.cli.options import ForceOpt, RunsOpt, SceneArg, load, status


@guard
def basin(scene: Path | None = SceneArg,
          grid: str | None = typer.Option(None, "--grid", help="cells NXxNY, e.g. 200x200 "
                                          "(default: basin.grid of the scene, 200x200)"),
          workers: int = typer.Option(2, "--workers", min=1, help="local worker processes"),
          scheduler: str | None = typer.Option(None, "--scheduler",
                                                help="Dask scheduler address (tcp://host:port)"),
          resume: bool = typer.Option(True, "--resume/--no-resume",
                                      help="continue an interrupted map with the same inputs"),
          runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Basin of attraction of the period-1 gait over a 2-D slice of the Poincaré section."""

    g = None
    if grid is not None:
        try:
            nx, ny = (int(v) for v in grid.lower().split("x"))
            if nx < 2 or ny < 2:
                raise ValueError
        except ValueError:
            fail(ValueError(f"--grid: expected NXxNY with NX, NY >= 2 (e.g. 200x200), "
                             f"got {grid!r}"))
        g = (nx, ny)
    from walkerlab.stages import pipeline  # light

    out = pipeline.run("basin", load(scene), runs_dir, force, grid=g, workers=workers,
                       scheduler=scheduler, resume=resume)
    if out.summary:
        typer.echo(", ".join(f"{k}: {v}" for k, v in out.summary["counts"].items()))
    typer.echo(status(out))
    from walkerlab.stages.basin import figure_path  # light

    typer.echo(f"figure: {figure_path(load(scene), runs_dir, g)}")


@guard
def mfpt(scene: Path | None = SceneArg,
         sigma_rad: str | None = typer.Option(None, "--sigma-rad", help="per-step slope "
                                              "standard deviations in rad, e.g. "
                                              "0.002,0.003,0.004 (default: mfpt.sigma_rad)"),
         method: str | None = typer.Option(None, "--method", help="mesh | montecarlo | both "
                                           "(default: mfpt.method, both)"),
         workers: int = typer.Option(2, "--workers", min=1, help="local worker processes"),
         scheduler: str | None = typer.Option(None, "--scheduler",
                                               help="Dask scheduler address (tcp://host:port)"),
         runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Mean first-passage time (steps before the fall) on per-step random slopes."""
    from walkerlab.stages import mfpt as stage  # light

    sig = None
    if sigma_rad is not None:
        try:
            sig = [float(v) for v in sigma_rad.split(",") if v.strip()]
        except ValueError:
            fail(ValueError(f"--sigma-rad: expected numbers separated by commas, got "
                             f"{sigma_rad!r}"))
    from walkerlab.stages import pipeline  # light

    sc = load(scene)
    out = pipeline.run("mfpt", sc, runs_dir, force, sigma_rad=sig, method=method,
                       workers=workers, scheduler=scheduler)
    from walkerlab.report.text import mfpt_text  # light

    summary = out.summary
    if not summary and out.path.is_file():  # reused: the same lines from the artifact
        from walkerlab.io.schemas.mfpt import load as load_mfpt  # light
        from walkerlab.studies.mfpt import mfpt_summary  # light

        summary = mfpt_summary(load_mfpt(out.path), stage.check(sc)[0].mesh_rel_change)
    if summary:
        typer.echo(mfpt_text(summary))
    typer.echo(status(out))
    typer.echo(f"figure: {stage.figure_path(sc, runs_dir)}")


@guard
def robustness(scene: Path | None = SceneArg,
               workers: int = typer.Option(2, "--workers", min=1,
                                           help="local worker processes (Monte Carlo)"),
               scheduler: str | None = typer.Option(None, "--scheduler",
                                                     help="Dask scheduler address"),
               runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Gait sensitivity norms, largest step-down/up and MFPT at the scene's sigma
    (the scene's robustness section); writes robustness.h5."""
    from walkerlab.io.schemas import robustness as schema  # light
    from walkerlab.io.schemas.robustness import per_unit  # light
    from walkerlab.stages import pipeline  # light

    out = pipeline.run("robustness", load(scene), runs_dir, force, workers=workers,
                       scheduler=scheduler)
    # computed now: the study's numbers; reused: the artifact's (the same numbers)
    d = out.summary.get("data") or schema.load(out.path)
    if d is not None:
        for k in d.disturbances:
            typer.echo(f"GSN {k}: {d.gsn[k]:.4g} {per_unit(d.units[k])}")
        typer.echo(f"step-down {1000 * d['step_down_m/lo']:.0f} mm, step-up "
                   f"{1000 * d['step_up_m/lo']:.0f} mm; MFPT {d['mfpt_steps']:.4g} "
                   f"± {d['mfpt_steps_stderr']:.2g} steps at sigma {d['sigma_rad']:g} rad")
        typer.echo(f"largest mid-stance push {d['push_forward_m_per_s/lo']:.3f} m/s forward, "
                   f"{d['push_backward_m_per_s/lo']:.3f} m/s backward (hip velocity change)")
        if "push_lateral_kg" in d.scalars:  # a walker with a lateral axis (3D)
            kg, swing, stance = (d["push_lateral_kg"], d["push_lateral_out_m_per_s/lo"],
                                 d["push_lateral_in_m_per_s/lo"])
            typer.echo(f"largest sideways push at heel strike {swing:.3f} m/s "
                       f"({kg * swing:.3f} N s) toward the swing leg, {stance:.3f} m/s "
                       f"({kg * stance:.3f} N s) toward the stance leg (hip lateral velocity "
                       "change)")
    typer.echo(status(out))


@guard
def stability_map(scene: Path | None = SceneArg,
                  kind: str = typer.Option("all", "--kind", help="stiffness | friction | "
                                           "patch_width | all (each against the slope)"),
                  n: int = typer.Option(8, "--n", min=2, help="grid size n x n"),
                  max_step_maps: int = typer.Option(
                      2_000, "--max-step-maps", min=1, help="work bound of each search of a "
                      "cell: its step-map integrations (the same answer on any machine)"),
                  workers: int = typer.Option(2, "--workers", min=1, help="worker processes"),
                  runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Stability maps of the contact gait: does a periodic gait exist, is it stable, max
    |Floquet multiplier|, or why not (cached stage)."""
    from walkerlab.config.options import map_not_applicable  # light
    from walkerlab.stages import stability_map as stage  # light
    from walkerlab.studies.stability import MAP_KINDS  # light

    sc = load(scene)
    kinds = list(MAP_KINDS) if kind == "all" else [kind]
    for k in kinds:
        if k not in MAP_KINDS:
            fail(ValueError(f"--kind: unknown map {k!r} (stiffness, friction, patch_width, all)"))
        if kind == "all" and map_not_applicable(sc, k):
            typer.echo(f"{k}: skipped ({map_not_applicable(sc, k).split(': ', 1)[1]})")
            continue
        out = stage.run(sc, runs_dir, force, kind=k, n=n, workers=workers,
                        max_step_maps=max_step_maps)
        s = out.summary
        typer.echo(f"{k}: " + (", ".join(f"{a}: {b:.3g}" if isinstance(b, float) else
                                         f"{a}: {b}" for a, b in s.items()) or "cached"))
        typer.echo(f"wrote {out.path}")
        typer.echo(f"figure: {stage.figure_path(sc, runs_dir, out.path)}")
