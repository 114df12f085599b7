"""Command-line interface (typer). Thin: parse arguments, call one stage, print a summary.

Every command takes an optional scene path (default: ``configs/paper.yaml``).

Errors and exit codes
---------------------
A traceback shown to a user is a bug.  Every command runs inside :func:`_guard`:

- bad input (scene, names, paths, artifacts, a busy artifact, a read-only runs folder) and
  a walker that falls (``simulate``, ``contact-sim``): one line ``error: ...`` on stderr,
  exit code 1;
- an unexpected exception: one line ``error: internal error (<type>): <message>`` and a hint
  to rerun with ``WALKERLAB_DEBUG=1``, which shows the traceback instead; exit code 1;
- Ctrl-C: ``interrupted``, exit code 130.

typer's own usage errors (unknown option, a value out of an option's range) keep typer's
message and exit code 2.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import typer

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="walkerlab: passive-dynamic biped walkers, from fixed point to report.")

SceneArg = typer.Argument(None, help="scene YAML file (default: configs/paper.yaml, "
                          "the paper's walker)",
                          show_default=False)
RunsOpt = typer.Option(Path("runs"), "--runs-dir", help="folder for artifacts (runs/<scene>/)")
ForceOpt = typer.Option(False, "--force", help="recompute even if the artifact is up to date")


def default_scene() -> Path:
    """``configs/paper.yaml`` (see :func:`walkerlab.config.default_scene_path`)."""
    from walkerlab.config import default_scene_path

    return default_scene_path()


def _load(scene: Path | None):
    from walkerlab.config import load_scene

    return load_scene(scene or default_scene())


def _fail(exc: Exception) -> None:
    typer.echo(f"error: {exc}", err=True)
    raise typer.Exit(code=1)


DEBUG_ENV = "WALKERLAB_DEBUG"


def _one_line(text: str) -> str:
    lines = [ln.strip() for ln in str(text).strip().splitlines() if ln.strip()]
    return (lines[0] + (f" (+{len(lines) - 1} more lines)" if len(lines) > 1 else "")) \
        if lines else ""


def _guard(fn):
    """Run a command so that every failure is one line on stderr and a non-zero exit code."""
    import functools

    @functools.wraps(fn)
    def wrapper(*a, **k):
        from walkerlab import progress
        from walkerlab.analysis.poincare import FixedPointNotFound
        from walkerlab.config import SceneError
        from walkerlab.io.artifacts import ArtifactError
        from walkerlab.io.runpaths import ArtifactBusy
        from walkerlab.stages.common import StageError

        debug = os.environ.get(DEBUG_ENV, "") not in ("", "0")
        try:
            # a spinner with the elapsed time on a terminal: never silent while it works
            with progress.task(f"walkerlab {fn.__name__.replace('_', '-')}"):
                return fn(*a, **k)
        except (typer.Exit, typer.Abort, SystemExit):
            raise
        except KeyboardInterrupt:
            typer.echo("interrupted", err=True)
            raise typer.Exit(code=130) from None
        except (SceneError, ArtifactError, ArtifactBusy, StageError, FixedPointNotFound,
                ValueError) as exc:
            if debug:
                raise
            typer.echo(f"error: {_one_line(exc)}", err=True)
            raise typer.Exit(code=1) from None
        except OSError as exc:  # read-only runs folder, disk full, ...
            if debug:
                raise
            where = f"{exc.filename}: " if exc.filename else ""
            typer.echo(f"error: {where}{exc.strerror or _one_line(exc)}", err=True)
            raise typer.Exit(code=1) from None
        except Exception as exc:  # noqa: BLE001 - a traceback shown to a user is a bug
            if debug:
                raise
            typer.echo(f"error: internal error ({type(exc).__name__}): {_one_line(exc)} "
                       f"[rerun with {DEBUG_ENV}=1 for the traceback]", err=True)
            raise typer.Exit(code=1) from None
    return wrapper


def _versions() -> str:
    """walkerlab, Python and the numeric libraries' versions (for bug reports)."""
    import platform
    from importlib import metadata

    import walkerlab

    parts = [f"walkerlab {walkerlab.__version__}", f"python {platform.python_version()}"]
    for dist in ("numpy", "scipy", "numba", "h5py", "pydantic", "matplotlib"):
        try:
            parts.append(f"{dist} {metadata.version(dist)}")
        except metadata.PackageNotFoundError:
            parts.append(f"{dist} not installed")
    return ", ".join(parts) + f" ({platform.system()} {platform.machine()})"


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(_versions())
        raise typer.Exit()


#: OpenBLAS thread pools (numpy's and scipy's each start one when loaded)
BLAS_THREADS_ENV = "OPENBLAS_NUM_THREADS"


def _single_threaded_blas() -> None:
    """Ask OpenBLAS for one thread unless the user chose a number (``OPENBLAS_NUM_THREADS``).

    walkerlab's matrices have at most a few dozen rows, which OpenBLAS never splits across
    threads, but starting the thread pools of numpy's and scipy's OpenBLAS costs every
    command ~50-100 ms of start-up on the 2-core machine (issue 10: 3 OS threads -> 1).  Must
    run before numpy is imported; worker processes (sweeps, basin) inherit it, as the
    work-precision workers already set it for themselves.
    """
    os.environ.setdefault(BLAS_THREADS_ENV, "1")


@app.callback()
def _main(version: bool = typer.Option(False, "--version", callback=_version_callback,
                                       is_eager=True,
                                       help="print walkerlab, Python, numpy, scipy, numba "
                                       "and h5py versions and exit"),
          quiet: bool = typer.Option(False, "--quiet", "-q",
                                     help="no progress display and no notices on stderr "
                                     "(errors are still shown); progress is also off when "
                                     "stderr is not a terminal")) -> None:
    """walkerlab: passive-dynamic biped walkers, from fixed point to report."""
    _single_threaded_blas()
    from walkerlab import progress

    progress.install(progress.sink_for_terminal(quiet))


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
    from walkerlab.io.artifacts import open_artifact

    with open_artifact(out.path, "contact-sim") as f:
        kind = str(f.attrs.get("outcome", f.attrs["termination"]))
        why = str(f.attrs.get("outcome_message", ""))
    # like simulate: a walker that does not finish the run exits 1 (typed outcome of
    # walkerlab.contact.simulate: trip, fall, solver_failure, time_limit)
    if kind not in ("completed", "scuff", "slip", "t_final", "stride_cap"):
        _fail(RuntimeError(f"the contact walker did not complete the run: {kind}"
                           + (f" ({why})" if why else "")))


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


@app.command()
@_guard
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
    from walkerlab.stages import basin as stage

    g = None
    if grid is not None:
        try:
            nx, ny = (int(v) for v in grid.lower().split("x"))
            if nx < 2 or ny < 2:
                raise ValueError
        except ValueError:
            _fail(ValueError(f"--grid: expected NXxNY with NX, NY >= 2 (e.g. 200x200), "
                             f"got {grid!r}"))
        g = (nx, ny)
    out = stage.run(_load(scene), runs_dir, force, grid=g, workers=workers,
                    scheduler=scheduler, resume=resume)
    if out.summary:
        typer.echo(", ".join(f"{k}: {v}" for k, v in out.summary["counts"].items()))
    typer.echo(_status(out))
    typer.echo(f"figure: {stage.figure_path(_load(scene), runs_dir)}")


@app.command("stability-map")
@_guard
def stability_map(scene: Path | None = SceneArg,
                  kind: str = typer.Option("all", "--kind", help="stiffness | friction | "
                                           "patch_width | all (each against the slope)"),
                  n: int = typer.Option(8, "--n", min=2, help="grid size n x n"),
                  time_limit: float = typer.Option(60.0, "--time-limit", min=1.0,
                                                   help="wall-time limit per cell [s]"),
                  workers: int = typer.Option(2, "--workers", min=1, help="worker processes"),
                  runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Stability maps of the contact gait: does a periodic gait exist, is it stable, max
    |Floquet multiplier|, or why not (cached stage)."""
    from walkerlab.stages import stability_map as stage
    from walkerlab.sweep.stability import MAP_KINDS

    sc = _load(scene)
    kinds = list(MAP_KINDS) if kind == "all" else [kind]
    for k in kinds:
        if k not in MAP_KINDS:
            _fail(ValueError(f"--kind: unknown map {k!r} (stiffness, friction, patch_width, all)"))
        out = stage.run(sc, runs_dir, force, kind=k, n=n, workers=workers,
                        time_limit_s=time_limit)
        s = out.summary
        typer.echo(f"{k}: " + (", ".join(f"{a}: {b:.3g}" if isinstance(b, float) else
                                         f"{a}: {b}" for a, b in s.items()) or "cached"))
        typer.echo(f"wrote {out.path}")


@app.command()
@_guard
def bench(what: str = typer.Argument("all", help="ideal | fixedpoint | sweep | basin | contact"
                                     " | all (all but basin)"),
          out: Path = typer.Option(Path("runs/bench"), "--out", help="output folder")) -> None:
    """Benchmarks (wall time, RHS evaluations); results printed and stored as JSON."""
    from walkerlab.stages.bench import run_bench

    for line in run_bench(what, out):
        typer.echo(line)


def main() -> None:  # pragma: no cover
    app()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(app())
