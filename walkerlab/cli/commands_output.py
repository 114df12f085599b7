"""Commands that write what is read: figures, the report, the animation, exported models,
benchmarks."""

from __future__ import annotations

from pathlib import Path

import typer

from walkerlab.cli.errors import guard
from walkerlab.cli.options import ForceOpt, RunsOpt, SceneArg, load
from walkerlab.export.mjcf_scene import MjcfOptions


@guard
def plot(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt) -> None:
    """Draw the figures (PNG + SVG) from the scene's existing artifacts."""
    from walkerlab.stages import plot as stage  # light

    for p in stage.run(load(scene), runs_dir):
        typer.echo(f"wrote {p}")


@guard
def report(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
           force: bool = ForceOpt,
           full: bool = typer.Option(False, "--full", help="also measure the work-precision "
                                     "diagram (times every solver setting; ~30 s) and compute "
                                     "the Section-5 attribution (contact scenes; ~17 s CPU)"),
           ) -> None:
    """Run every stage the scene needs (skipping up-to-date ones) and write the report."""
    from walkerlab.stages import report as stage  # light

    out = stage.run(load(scene), runs_dir, force, echo=typer.echo, full=full)
    typer.echo(f"report: {out}")




@guard
def animate(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt) -> None:
    """The walker walking (rigid, and contact beside it where contact_sim.h5 exists):
    report/figures/animation.gif, and .mp4 if ffmpeg is installed."""
    from walkerlab.stages import pipeline  # light

    out = pipeline.run("animate", load(scene), runs_dir)
    for p in out.paths:
        typer.echo(f"wrote {p}")
    if out.note:
        typer.echo(out.note)


@guard
def export(scene: Path | None = SceneArg,
           fmt: str = typer.Option("urdf", "--format", help="urdf (Drake, Pinocchio), mjcf "
                                   "(MuJoCo), adm (MSC Adams Solver .adm + .acf) or osim "
                                   "(OpenSim)"),
           runs_dir: Path = RunsOpt,
           walker_only: bool = typer.Option(
               False, "--walker-only", help="urdf/mjcf: the walker alone, without the rigid "
               "gait (no keyframe; the MJCF on a plane with MuJoCo's default contact)"),
           walk: bool = typer.Option(
               False, "--walk", help="walk the written file in its engine where it is "
               "installed (MJCF: MuJoCo; OpenSim), 10 heel strikes from its gait, and print "
               "its step period against the rigid gait's"),
           mjcf_tau: float | None = typer.Option(
               None, "--mjcf-contact-time-constant-s", min=1e-6, max=1.0,
               help="mjcf: the contact's solref time constant in s (default: the scene's "
               "contact law linearised at the walker's weight, shrunk 4x)"),
           mjcf_dt: float | None = typer.Option(
               None, "--mjcf-timestep-s", min=1e-7, max=0.01,
               help="mjcf: MuJoCo's timestep in s (default: a quarter of the contact's time "
               "constant, at most 1 ms)")) -> None:
    """Write the walker as a floating multibody model (planar, or in 3D for a walker in
    3D): runs/<scene>/walker.urdf,
    walker.xml, walker.adm + walker.acf (Adams Solver) or walker.osim (OpenSim).  The URDF,
    MJCF and OpenSim model carry the rigid gait (found as `walkerlab fixedpoint` finds it) as
    a keyframe (OpenSim: the default state).  What the file leaves out is printed, one line
    per item ("left out of walker.urdf: ..."), as the file's "Left out:" comments have it.
    --walk walks the MJCF in MuJoCo and the OpenSim model in OpenSim (where importable) for 10
    heel strikes and prints the step period against the rigid gait's (exit code 0 either way;
    a walk that falls or misses 1 % adds a warning on stderr)."""
    from walkerlab.stages import export as stage  # light

    sc = load(scene)
    out = stage.write(sc, runs_dir, fmt, walker_only=walker_only, walk=walk,
                      mjcf=MjcfOptions(mjcf_tau, mjcf_dt))
    typer.echo(f"wrote {out.path}")
    for line in out.left_out:  # what the file leaves out: here too, not only in a comment
        typer.echo(f"left out of {out.path.name}: {line}")
    if out.walk is not None:
        typer.echo(f"{out.path.name} {out.walk.line}")
        if out.walk.walked and not out.walk.ok:
            typer.echo(f"warning: {out.path.name} does not walk {out.walk.steps} steps "
                       f"within {100 * out.walk.tolerance:g} % of the rigid gait", err=True)
    if fmt == "adm":  # the dataset is not the scene's walker: say so here, not in a comment
        from walkerlab.export.adams import actuation_warning  # light

        if warning := actuation_warning(sc):
            typer.echo(warning, err=True)


@guard
def bench(what: str = typer.Argument("all", help="ideal | fixedpoint | fixedpoint-3d"
                                     " | sweep | sweep-workers"
                                     " | basin | contact | main-job | optimize | powered"
                                     " | powered-command | hzd | gym | gym-vector"
                                     " | all (ideal, fixedpoint, sweep and contact)"),
          scenes: list[Path] | None = typer.Argument(
              None, help="contact only: scene YAML files whose walkers are timed (5 contact "
              "strides at <= 1e-6 rad against a tight reference), e.g. configs/kneed.yaml "
              "configs/paper.yaml", show_default=False),
          out: Path = typer.Option(Path("runs/bench"), "--out", help="output folder")) -> None:
    """Benchmarks (wall time, RHS evaluations); results printed and stored as JSON."""
    from walkerlab.cli.bench import run_bench  # light

    for line in run_bench(what, out, scenes=scenes or None):
        typer.echo(line)
