"""Command-line interface (typer). Thin: parse arguments, call one stage, print a summary.

Every command takes an optional scene path (default: ``configs/paper.yaml``).

Errors and exit codes
---------------------
A traceback shown to a user is a bug.  Every command runs inside :func:`_guard`:

- a scene that does not validate: every error on its own line ``error: <file>: <field>:
  <message>``, unknown keys first (with the closest field name), exit code 1;
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


def _flags_take_no_value() -> None:
    """``--help`` lists an on/off flag (``--force``, ``--help``) without a value type: typer
    0.29 with click 8.2+ shows ``<bool>`` beside it, as if it took a value (issue 26)."""
    from typer.core import TyperOption

    shown = TyperOption.display_type_rich
    if getattr(shown, "_walkerlab", False):
        return

    def display_type_rich(self, ctx):
        return None if self.is_flag and self.metavar is None else shown(self, ctx)

    display_type_rich._walkerlab = True
    TyperOption.display_type_rich = display_type_rich


_flags_take_no_value()

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="walkerlab: passive-dynamic biped walkers, from fixed point to report.")

SceneArg = typer.Argument(None, help="scene YAML file (default: configs/paper.yaml, "
                          "the paper's walker)",
                          show_default=False)
def _runs_dir(value) -> Path:
    """``--runs-dir``: a folder name; an empty one (which would be the current folder) is
    refused."""
    if not str(value).strip():
        raise typer.BadParameter("empty folder name (it would write into the current folder); "
                                 "give a folder, e.g. --runs-dir runs")
    return Path(value)


RunsOpt = typer.Option("runs", "--runs-dir", parser=_runs_dir, metavar="PATH",
                       help="folder for artifacts (runs/<scene>/)")
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
#: values of ``WALKERLAB_DEBUG`` that show tracebacks (case-insensitive); anything else
#: (``0``, ``false``, ``no``, empty) keeps errors to one line
DEBUG_ON = ("1", "true", "yes")
#: longest error line; a longer message is cut at a sentence or field boundary
MAX_ERROR_CHARS = 300


def _debug() -> bool:
    return os.environ.get(DEBUG_ENV, "").strip().lower() in DEBUG_ON


def _one_line(text: str, limit: int = MAX_ERROR_CHARS) -> str:
    """A message as one line: its lines joined (a sentence wrapped over two lines stays
    whole); longer than ``limit``, it is cut after the last sentence or field boundary
    (``.``, ``;``, ``:``, ``,`` followed by a space) and says how to see the rest."""
    line = " ".join(ln.strip() for ln in str(text).strip().splitlines() if ln.strip())
    if len(line) <= limit:
        return line
    # a trailing "[detail]" (a solver's report) is cut first: the advice before it stays whole
    start = line.rfind(" [")
    if line.endswith("]") and 0 < start <= limit:
        more = f" ... rerun with {DEBUG_ENV}=1 for the rest]"
        detail = line[start:-1]
        # up to 80 characters past the limit for the detail's start (what was tried)
        cut = detail[:max(limit + 80 - start - len(more), 2)].rfind(" ")
        return line[:start] + (detail[:cut].rstrip(",;:( ") if cut > 2 else " [") + more
    head = line[:limit]
    cut = max(head.rfind(sep) for sep in (". ", "; ", ": ", ", "))
    head = head[:cut + 1] if cut > limit // 3 else head[:head.rfind(" ")].rstrip()
    return (f"{head} ... [{len(line) - len(head)} more characters: rerun with "
            f"{DEBUG_ENV}=1 for the full message]")


def _disk_full_line(exc: BaseException) -> str:
    where = f" {exc.filename}" if getattr(exc, "filename", None) else ""
    return (f"error: disk full: cannot write{where}; free some space (or raise the file-size "
            "limit) and rerun")


def _guard(fn):
    """Run a command so that every failure is one line on stderr and a non-zero exit code."""
    import functools

    @functools.wraps(fn)
    def wrapper(*a, **k):
        from walkerlab import progress
        from walkerlab.analysis.poincare import FixedPointNotFound
        from walkerlab.config import SceneError
        from walkerlab.io.artifacts import ArtifactError, is_disk_full
        from walkerlab.io.runpaths import ArtifactBusy
        from walkerlab.stages.common import StageError

        debug = _debug()
        try:
            # a spinner with the elapsed time on a terminal: never silent while it works
            with progress.task(f"walkerlab {fn.__name__.replace('_', '-')}"):
                return fn(*a, **k)
        except (typer.Exit, typer.Abort, SystemExit):
            raise
        except KeyboardInterrupt:
            typer.echo("interrupted", err=True)
            raise typer.Exit(code=130) from None
        except SceneError as exc:  # every config error, one line each
            if debug:
                raise
            for line in str(exc).splitlines() or [""]:
                typer.echo(f"error: {line.strip()}", err=True)
            raise typer.Exit(code=1) from None
        except (ArtifactError, ArtifactBusy, StageError, FixedPointNotFound,
                ValueError) as exc:
            if debug:
                raise
            typer.echo(f"error: {_one_line(exc)}", err=True)
            raise typer.Exit(code=1) from None
        except OSError as exc:  # read-only runs folder, disk full, ...
            if debug:
                raise
            if is_disk_full(exc):
                typer.echo(_disk_full_line(exc), err=True)
                raise typer.Exit(code=1) from None
            where = f"{exc.filename}: " if exc.filename else ""
            typer.echo(f"error: {where}{exc.strerror or _one_line(exc)}", err=True)
            raise typer.Exit(code=1) from None
        except Exception as exc:  # noqa: BLE001 - a traceback shown to a user is a bug
            if debug:
                raise
            if is_disk_full(exc):  # HDF5 reports a full disk as a RuntimeError too
                typer.echo(_disk_full_line(exc), err=True)
                raise typer.Exit(code=1) from None
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


#: cyclic garbage collector thresholds of a command's process (generation 0 allocations,
#: generation 1 and 2 collections; Python's are (700, 10, 10))
GC_THRESHOLDS = (20_000, 20, 20)


def _process_settings() -> None:
    """Settings every command (and every worker it starts) runs with:

    - numba's on-disk cache in the per-user cache (``NUMBA_CACHE_DIR``, unless set), never
      in the installed package (:func:`walkerlab.usercache.use_for_numba`); before numba is
      imported, and inherited by worker processes;
    - ``SIGXFSZ`` ignored (a file-size limit, ``ulimit -f``, then makes a write fail with
      EFBIG, reported as "disk full" in one line, instead of killing the process);
    - the cyclic garbage collector's thresholds raised to :data:`GC_THRESHOLDS` (this
      process only; its workers keep Python's): a command imports scipy, h5py, pydantic and
      its own schema after this point, and with Python's (700, 10, 10) the collector walks
      those long-lived objects again and again (issue 27: ~5 % of ``walkerlab fixedpoint``'s
      CPU time).  Reference counting still frees everything without cycles at once.
    """
    import gc
    import signal

    from walkerlab.usercache import use_for_numba

    use_for_numba()
    if hasattr(signal, "SIGXFSZ"):
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    gc.set_threshold(*GC_THRESHOLDS)


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
    _process_settings()
    from walkerlab import progress

    progress.install(progress.sink_for_terminal(quiet))


def _status(o) -> str:
    return (f"reused {o.path} ({o.note or 'inputs unchanged'})" if o.reused
            else f"wrote {o.path} (compute {o.wall_time_s:.3f} s)")


@app.command()
@_guard
def fixedpoint(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
               force: bool = ForceOpt,
               known: Path | None = typer.Option(None, "--from", help="a scene whose gait is "
                                                 "known: continue it along the straight line "
                                                 "between the two scenes' numeric fields to "
                                                 "this walker (homotopy)")) -> None:
    """Find the period-1 gait: fixed point of the Poincaré map, step period, Floquet multipliers."""
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.report.text import fixedpoint_text
    from walkerlab.stages import pipeline

    out = pipeline.run("fixedpoint", _load(scene), runs_dir, force, known=known)
    typer.echo(fixedpoint_text(load_fixedpoint(out.path)))
    typer.echo(_status(out))


@app.command()
@_guard
def simulate(scene: Path | None = SceneArg,
             strides: int | None = typer.Option(
                 None, "--strides", help="strides to simulate (1 stride = 2 steps) "
                 "(default: simulate.strides of the scene)"),
             runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Simulate N strides of the rigid walker from its fixed point (or from the state given
    as simulate.initial_state in the scene)."""
    from walkerlab.io.schemas.simulate import load_simulate
    from walkerlab.report.text import simulate_ending, simulate_text
    from walkerlab.stages import pipeline

    out = pipeline.run("simulate", _load(scene), runs_dir, force, strides=strides)
    sim = load_simulate(out.path)
    ending = simulate_ending(sim)  # a fall: no success-style summary (issue 26, item 5)
    if ending is None:
        typer.echo(simulate_text(sim))
    typer.echo(_status(out))
    if out.failure:  # recorded in the artifact, and an error: one line, exit 1
        _fail(RuntimeError(f"the walker {ending}" if ending else out.failure))


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
    from walkerlab.io.schemas.contact_sim import load_contact_sim
    from walkerlab.report.text import contact_text
    from walkerlab.stages import pipeline

    out = pipeline.run("contact-sim", _load(scene), runs_dir, force, adjust=adjust,
                       periodic=periodic)
    typer.echo(contact_text(load_contact_sim(out.path)))
    typer.echo(_status(out))
    if out.failure:
        _fail(RuntimeError(out.failure))


@app.command()
@_guard
def compare(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
            force: bool = ForceOpt,
            rigid_limit: bool = typer.Option(
                False, "--rigid-limit", help="instead: the contact periodic gait along the "
                "rigid-limit family (rigid_limit.h5 and its figure)")) -> None:
    """Compare the ideal and contact trajectories (errors, periods, speed, energy)."""
    from walkerlab.io.schemas.compare import load_compare
    from walkerlab.report.text import compare_text
    from walkerlab.stages import pipeline

    if rigid_limit:
        from walkerlab.io.schemas.rigid_limit import load_rigid_limit
        from walkerlab.report.text import rigid_limit_text
        from walkerlab.stages import rigid_limit as rl

        sc = _load(scene)
        out = rl.run(sc, runs_dir, force)
        for line in rigid_limit_text(load_rigid_limit(out.path)):
            typer.echo(line)
        for p in rl.draw(sc, runs_dir, out.path):
            typer.echo(f"wrote {p}")
        typer.echo(_status(out))
        return
    out = pipeline.run("compare", _load(scene), runs_dir, force)
    typer.echo(compare_text(load_compare(out.path)))
    typer.echo(_status(out))


@app.command()
@_guard
def workprecision(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
                  force: bool = ForceOpt) -> None:
    """Work-precision study: error vs wall time for every solver and tolerance."""
    from walkerlab.io.schemas.workprecision import load_workprecision
    from walkerlab.report.text import workprecision_text
    from walkerlab.stages import pipeline

    out = pipeline.run("workprecision", _load(scene), runs_dir, force)
    typer.echo(workprecision_text(load_workprecision(out.path)))
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
           force: bool = ForceOpt,
           full: bool = typer.Option(False, "--full", help="also measure the work-precision "
                                     "diagram (times every solver setting; ~30 s) and compute "
                                     "the Section-5 attribution (contact scenes; ~17 s CPU)"),
           ) -> None:
    """Run every stage the scene needs (skipping up-to-date ones) and write the report."""
    from walkerlab.stages import report as stage

    out = stage.run(_load(scene), runs_dir, force, echo=typer.echo, full=full)
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
    from walkerlab.report.sweep_text import sweep_text
    from walkerlab.stages import sweep as stage_mod

    sc = _load(scene)
    path = stage_mod.run(sc, param, stage=stage, workers=workers,
                         scheduler=scheduler, resume=resume, runs_root=runs_dir, name=name)
    typer.echo(sweep_text(path))
    typer.echo(f"wrote {path}")
    typer.echo(f"figure: {stage_mod.figure_path(sc, path, runs_dir)}")


@app.command()
@_guard
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
    from walkerlab.stages import bifurcation as stage
    from walkerlab.sweep.params import (
        SweepError,
        check_axes,
        parse_param,
        takes_whole_numbers,
    )

    if slopes is not None and param is not None:
        _fail(SweepError("--slopes and --param exclude each other (--slopes S is "
                         "--param slope.angle_deg=S)"))
    try:
        axis = parse_param(param if param is not None
                           else f"slope.angle_deg={slopes or '1:5.5:0.05'}")
    except SweepError as exc:  # name the option the user typed
        if param is not None:
            raise
        _fail(SweepError(str(exc).replace(f"--param 'slope.angle_deg={slopes}'",
                                          f"--slopes {slopes!r}")))
    sc = _load(scene)
    if param is not None:
        check_axes(sc, [axis], values=not takes_whole_numbers(sc, axis))
        if not axis.numeric:
            _fail(SweepError(f"--param {axis.spec!r}: a bifurcation needs numbers"))
        if takes_whole_numbers(sc, axis):
            _fail(SweepError(f"--param {axis.spec!r}: {axis.path} takes whole numbers; a "
                             "bifurcation continues over a real-valued field (e.g. "
                             "slope.angle_deg or a body's mass_kg)"))
    out = stage.run(sc, axis.values, runs_dir, transient, keep, workers, force=force,
                    param=axis.path)
    onset, unit = out.summary["onset"], out.summary["unit"]
    where = (f"{onset:.4f} deg" if axis.path == "slope.angle_deg"
             else f"{axis.path} = {onset:.6g} {unit}".removesuffix(" -"))
    typer.echo(f"period-doubling onset: {where}" if onset == onset
               else "period-doubling onset: none on the grid")
    typer.echo(_status(out))
    typer.echo("figures: " + ", ".join(str(p) for p in out.summary["figures"]))


def _range_spec(text: str, opt: str) -> tuple[str, float, float]:
    """``FIELD=START:STOP`` -> (field, start, stop); one-line error otherwise."""
    from walkerlab.sweep.params import SweepError

    path, _, rhs = text.partition("=")
    parts = rhs.split(":")
    try:
        if not path.strip() or len(parts) != 2:
            raise ValueError
        a, b = float(parts[0]), float(parts[1])
        if not (a == a and b == b) or a == b:
            raise ValueError
    except ValueError:
        raise SweepError(f"{opt} {text!r}: expected FIELD=START:STOP (two different "
                         "numbers in the field's unit)") from None
    return path.strip(), a, b


@app.command()
@_guard
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
    doublings, Neimark-Sacker points, branch ends; writes continuation_<FIELD>.h5."""
    from walkerlab.stages import continuation as stage

    path, a, b = _range_spec(param, "--param")
    p2 = _range_spec(param2, "--param2") if param2 else None
    out = stage.run(_load(scene), path, a, b, 2 if switch else 0,
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
    for c in data.curves:
        typer.echo(f"{c['kind']} curve over {c['path2']}: {len(c['param2'])} points")
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
    from walkerlab.stages import pipeline

    out = pipeline.run("basin", _load(scene), runs_dir, force, grid=g, workers=workers,
                       scheduler=scheduler, resume=resume)
    if out.summary:
        typer.echo(", ".join(f"{k}: {v}" for k, v in out.summary["counts"].items()))
    typer.echo(_status(out))
    from walkerlab.stages.basin import figure_path

    typer.echo(f"figure: {figure_path(_load(scene), runs_dir, g)}")


@app.command()
@_guard
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
    from walkerlab.stages import mfpt as stage

    sig = None
    if sigma_rad is not None:
        try:
            sig = [float(v) for v in sigma_rad.split(",") if v.strip()]
        except ValueError:
            _fail(ValueError(f"--sigma-rad: expected numbers separated by commas, got "
                             f"{sigma_rad!r}"))
    from walkerlab.stages import pipeline

    sc = _load(scene)
    out = pipeline.run("mfpt", sc, runs_dir, force, sigma_rad=sig, method=method,
                       workers=workers, scheduler=scheduler)
    if out.summary:
        for s, m, me in zip(out.summary["sigma_rad"], out.summary["mfpt_steps_montecarlo"],
                            out.summary["mfpt_steps_mesh"]):
            typer.echo(f"sigma {s:.4g} rad: MFPT Monte Carlo {m:.4g}, mesh {me:.4g} steps")
    typer.echo(_status(out))
    typer.echo(f"figure: {stage.figure_path(sc, runs_dir)}")


@app.command()
@_guard
def robustness(scene: Path | None = SceneArg,
               workers: int = typer.Option(2, "--workers", min=1,
                                           help="local worker processes (Monte Carlo)"),
               scheduler: str | None = typer.Option(None, "--scheduler",
                                                     help="Dask scheduler address"),
               runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Gait sensitivity norms, largest step-down/up and MFPT at the scene's sigma
    (the scene's robustness section); writes robustness.h5."""
    from walkerlab.io.schemas.robustness import per_unit
    from walkerlab.stages import pipeline

    out = pipeline.run("robustness", _load(scene), runs_dir, force, workers=workers,
                       scheduler=scheduler)
    d = out.summary.get("data")
    if d is not None:
        for k in d.disturbances:
            typer.echo(f"GSN {k}: {d.gsn[k]:.4g} {per_unit(d.units[k])}")
        typer.echo(f"step-down {1000 * d['step_down_m/lo']:.0f} mm, step-up "
                   f"{1000 * d['step_up_m/lo']:.0f} mm; MFPT {d['mfpt_steps']:.4g} "
                   f"± {d['mfpt_steps_stderr']:.2g} steps at sigma {d['sigma_rad']:g} rad")
        typer.echo(f"largest mid-stance push {d['push_forward_m_per_s/lo']:.3f} m/s forward, "
                   f"{d['push_backward_m_per_s/lo']:.3f} m/s backward (hip velocity change)")
    typer.echo(_status(out))


@app.command("stability-map")
@_guard
def stability_map(scene: Path | None = SceneArg,
                  kind: str = typer.Option("all", "--kind", help="stiffness | friction | "
                                           "patch_width | all (each against the slope)"),
                  n: int = typer.Option(8, "--n", min=2, help="grid size n x n"),
                  time_limit: float = typer.Option(60.0, "--time-limit", min=1.0,
                                                   help="wall-time limit per cell, in seconds"),
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
        if kind == "all" and stage.not_applicable(sc, k):
            typer.echo(f"{k}: skipped ({stage.not_applicable(sc, k).split(': ', 1)[1]})")
            continue
        out = stage.run(sc, runs_dir, force, kind=k, n=n, workers=workers,
                        time_limit_s=time_limit)
        s = out.summary
        typer.echo(f"{k}: " + (", ".join(f"{a}: {b:.3g}" if isinstance(b, float) else
                                         f"{a}: {b}" for a, b in s.items()) or "cached"))
        typer.echo(f"wrote {out.path}")


@app.command()
@_guard
def animate(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt) -> None:
    """The walker walking (rigid, and contact beside it where contact_sim.h5 exists):
    report/figures/animation.gif, and .mp4 if ffmpeg is installed."""
    from walkerlab.stages import pipeline

    out = pipeline.run("animate", _load(scene), runs_dir)
    for p in out.paths:
        typer.echo(f"wrote {p}")
    if out.note:
        typer.echo(out.note)


@app.command()
@_guard
def export(scene: Path | None = SceneArg,
           fmt: str = typer.Option("urdf", "--format", help="urdf (Drake, Pinocchio) or mjcf "
                                   "(MuJoCo)"),
           runs_dir: Path = RunsOpt) -> None:
    """Write the walker as a floating planar multibody model: runs/<scene>/walker.urdf or
    walker.xml."""
    from walkerlab.stages import export as stage

    typer.echo(f"wrote {stage.run(_load(scene), runs_dir, fmt)}")


@app.command()
@_guard
def bench(what: str = typer.Argument("all", help="ideal | fixedpoint | sweep | basin | contact"
                                     " | all (all but basin)"),
          scenes: list[Path] | None = typer.Argument(
              None, help="contact only: scene YAML files whose walkers are timed (5 contact "
              "strides at <= 1e-6 rad against a tight reference), e.g. configs/kneed.yaml "
              "configs/paper.yaml", show_default=False),
          out: Path = typer.Option(Path("runs/bench"), "--out", help="output folder")) -> None:
    """Benchmarks (wall time, RHS evaluations); results printed and stored as JSON."""
    from walkerlab.stages.bench import run_bench

    for line in run_bench(what, out, scenes=scenes or None):
        typer.echo(line)


def main() -> None:  # pragma: no cover
    app()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(app())
