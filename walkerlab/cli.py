"""Command-line interface (typer). Thin: parse arguments, call one stage, print a summary.

Every command takes an optional scene path (default: ``configs/paper.yaml``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import typer

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="walkerlab: passive-dynamic biped walkers, from fixed point to report.")

SceneArg = typer.Argument(None, help="scene YAML file (default: configs/paper.yaml, the paper's walker)",
                          show_default=False)
RunsOpt = typer.Option(Path("runs"), "--runs-dir", help="folder for artifacts (runs/<scene>/)")
ForceOpt = typer.Option(False, "--force", help="recompute even if the artifact is up to date")


def default_scene() -> Path:
    here = Path("configs/paper.yaml")
    if here.is_file():
        return here
    import walkerlab

    return Path(walkerlab.__file__).resolve().parent.parent / "configs" / "paper.yaml"


def _load(scene: Path | None):
    from walkerlab.config import load_scene

    return load_scene(scene or default_scene())


def _fail(exc: Exception) -> None:
    typer.echo(f"error: {exc}", err=True)
    raise typer.Exit(code=1)


def _guard(fn):
    """Turn walkerlab's own errors into a one-line message and exit code 1."""
    import functools

    @functools.wraps(fn)
    def wrapper(*a, **k):
        from walkerlab.analysis.poincare import FixedPointNotFound
        from walkerlab.config import SceneError
        from walkerlab.io.artifacts import ArtifactError
        from walkerlab.stages.common import StageError

        try:
            return fn(*a, **k)
        except (SceneError, ArtifactError, StageError, FixedPointNotFound, ValueError) as exc:
            _fail(exc)
    return wrapper


def _status(o) -> str:
    return (f"reused {o.path} (inputs unchanged)" if o.reused
            else f"wrote {o.path} (compute {o.wall_time_s:.3f} s)")


@app.command()
@_guard
def fixedpoint(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
               force: bool = ForceOpt) -> None:
    """Find the period-1 gait: fixed point of the Poincaré map, step period, Floquet multipliers."""
    from walkerlab.report.text import fixedpoint_text
    from walkerlab.stages import fixedpoint as stage

    sc = _load(scene)
    out = stage.run(sc, runs_dir, force)
    typer.echo(fixedpoint_text(out.path))
    typer.echo(_status(out))


@app.command()
@_guard
def simulate(scene: Path | None = SceneArg,
             strides: int | None = typer.Option(
                 None, "--strides", min=1, help="strides to simulate (1 stride = 2 steps) "
                 "(default: simulate.strides of the scene)"),
             runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Simulate N strides of the rigid walker from its fixed point (or a given state)."""
    from walkerlab.report.text import simulate_text
    from walkerlab.stages import simulate as stage

    sc = _load(scene)
    out = stage.run(sc, runs_dir, force, strides=strides)
    typer.echo(simulate_text(out.path))
    typer.echo(_status(out))
    from walkerlab.io.artifacts import open_artifact

    with open_artifact(out.path, "simulate") as f:
        term = str(f.attrs["termination"])
    if term != "heel_strike":
        _fail(RuntimeError(f"the walker did not complete the run: {term}"))


@app.command("contact-sim")
@_guard
def contact_sim(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
                force: bool = ForceOpt,
                adjust: bool = typer.Option(False, "--adjust", help="search the initial rates "
                                            "that make the contact walker match the ideal gait"),
                periodic: bool = typer.Option(False, "--periodic", help="also find the contact "
                                              "walker's own periodic gait and its Floquet "
                                              "multipliers (about 10 s)")
                ) -> None:
    """Simulate the compliant-contact (MSC ADAMS style) walker on the scene's terrain."""
    from walkerlab.report.text import contact_text
    from walkerlab.stages import contact_sim as stage

    sc = _load(scene)
    out = stage.run(sc, runs_dir, force, adjust=adjust, periodic=periodic)
    typer.echo(contact_text(out.path))
    typer.echo(_status(out))


@app.command()
@_guard
def compare(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
            force: bool = ForceOpt) -> None:
    """Compare the ideal and contact trajectories (errors, periods, speed, energy)."""
    from walkerlab.stages import compare as stage

    out = stage.run(_load(scene), runs_dir, force)
    typer.echo(_status(out))


@app.command()
@_guard
def workprecision(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
                  force: bool = ForceOpt) -> None:
    """Work-precision study: error vs wall time for every solver and tolerance."""
    from walkerlab.stages import workprecision as stage

    out = stage.run(_load(scene), runs_dir, force)
    for model, s in out.summary.items():
        if s.get("best"):
            m, rtol, t, e = s["best"]
            typer.echo(f"{model}: Pareto-best setting reaching the target error: {m} "
                       f"rtol={rtol:g} ({t * 1e3:.1f} ms, error {e:.1e})")
    typer.echo(_status(out))


@app.command()
@_guard
def plot(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt) -> None:
    """Draw the figures (PNG + SVG) from the scene's existing artifacts."""
    from walkerlab.stages import plot as stage

    for p in stage.run(_load(scene), runs_dir):
        typer.echo(f"wrote {p}")


@app.command()
@_guard
def report(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
           force: bool = ForceOpt) -> None:
    """Run every stage the scene needs (skipping up-to-date ones) and write the report."""
    from walkerlab.stages import report as stage

    out = stage.run(_load(scene), runs_dir, force, echo=typer.echo)
    typer.echo(f"report: {out}")


@app.command()
@_guard
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
    from walkerlab.stages import sweep as stage_mod

    path = stage_mod.run(scene or default_scene(), param, stage=stage, workers=workers,
                         scheduler=scheduler, resume=resume, runs_root=runs_dir, name=name)
    typer.echo(f"wrote {path}")


@app.command()
@_guard
def bifurcation(scene: Path | None = SceneArg,
                slopes: str = typer.Option("1:5.5:0.05", "--slopes",
                                           help="slope grid [deg], start:stop:step or a,b,c"),
                transient: int = typer.Option(100, "--transient", min=1,
                                              help="steps discarded before sampling"),
                keep: int = typer.Option(30, "--keep", min=1, help="heel strikes kept per slope"),
                workers: int = typer.Option(2, "--workers", min=1, help="worker processes"),
                runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Bifurcation diagram over the slope: fixed points, multipliers, period-doubling onset."""
    from walkerlab.stages import bifurcation as stage
    from walkerlab.sweep.params import parse_param

    axis = parse_param(f"slope.angle_deg={slopes}")
    out = stage.run(_load(scene), axis.values, runs_dir, transient, keep, workers, force=force)
    typer.echo(f"period-doubling onset: {out.summary['onset_deg']:.4f} deg")
    typer.echo(_status(out))
    typer.echo("figures: " + ", ".join(str(p) for p in out.summary["figures"]))


@app.command("stability-map")
@_guard
def stability_map(scene: Path | None = SceneArg,
                  y: str = typer.Option("contact.stiffness=1e3,1e4,1e5,1e6,1e7,1e8,1e9", "--y",
                                        help="y axis, e.g. contact.stiffness=... (scene units) "
                                        "or contact.mu_static=..."),
                  x: str = typer.Option("slope.angle_deg=0.5:3:0.5", "--x",
                                        help="x axis (slope) [deg]"),
                  name: str = typer.Option("stability_stiffness", "--name", help="artifact name"),
                  workers: int = typer.Option(2, "--workers", min=1, help="worker processes"),
                  runs_dir: Path = RunsOpt) -> None:
    """Stability map of the contact walker: walks / falls / slips / bounces / solver failure."""
    from walkerlab.sweep.stability import stability_map as smap

    out = smap(_load(scene), y, x, runs_root=runs_dir, name=name, workers=workers)
    typer.echo(", ".join(f"{k}: {v}" for k, v in out["counts"].items()))
    typer.echo(f"wrote {out['artifact']}")


@app.command()
def bench(what: str = typer.Argument("all", help="ideal | contact | all"),
          out: Path = typer.Option(Path("runs/bench"), "--out", help="output folder")) -> None:
    """Benchmarks (wall time, RHS evaluations); results printed and stored as JSON."""
    from walkerlab.bench import run_bench

    for line in run_bench(what, out):
        typer.echo(line)


def main() -> None:  # pragma: no cover
    app()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(app())
