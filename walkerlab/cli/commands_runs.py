"""Commands that run the walker once: fixed point, rigid and contact runs, their comparison,
the work-precision study."""

from __future__ import annotations

from pathlib import Path

import typer

from walkerlab.cli.errors import fail, guard
from walkerlab.cli.options import ForceOpt, RunsOpt, SceneArg, load, status


@guard
def fixedpoint(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
               force: bool = ForceOpt,
               known: Path | None = typer.Option(None, "--from", help="a scene whose gait is "
                                                 "known: continue it along the straight line "
                                                 "between the two scenes' numeric fields to "
                                                 "this walker (homotopy); the two walkers "
                                                 "must have the same structure (the same "
                                                 "legs and bodies, by name): only numbers "
                                                 "may differ"),
               require_stable: bool = typer.Option(False, "--require-stable",
                                                   help="exit non-zero (one line) when the "
                                                   "gait found is unstable: no stable "
                                                   "period-1 gait was found")) -> None:
    """Find the period-1 gait: fixed point of the Poincaré map, step period, Floquet multipliers."""
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint  # light
    from walkerlab.report.text import fixedpoint_text, unstable_gait_line  # light
    from walkerlab.stages import pipeline  # light

    out = pipeline.run("fixedpoint", load(scene), runs_dir, force, known=known)
    fp = load_fixedpoint(out.path)
    typer.echo(fixedpoint_text(fp))
    typer.echo(status(out))
    if require_stable and not fp.stable:  # the artifact stays: it holds what was found
        fail(RuntimeError(f"--require-stable: {unstable_gait_line(fp)}"))


@guard
def simulate(scene: Path | None = SceneArg,
             strides: int | None = typer.Option(
                 None, "--strides", help="strides to simulate (1 stride = 2 steps) "
                 "(default: simulate.strides of the scene)"),
             terrain_seed: int | None = typer.Option(
                 None, "--terrain-seed", help="walk the per-step ground of terrain.per_step "
                 "drawn from this seed (the same seed walks the same ground, bit for bit)"),
             runs_dir: Path = RunsOpt, force: bool = ForceOpt) -> None:
    """Simulate N strides of the rigid walker from its fixed point (or from the state given
    as simulate.initial_state in the scene)."""
    from walkerlab.io.schemas.simulate import load_simulate  # light
    from walkerlab.report.text import simulate_ending, simulate_text  # light
    from walkerlab.stages import pipeline  # light

    sc = load(scene)
    out = pipeline.run("simulate", sc, runs_dir, force, strides=strides,
                       terrain_seed=terrain_seed)
    # a longer run kept for the scene: its verdict and means over the scene's strides
    sim = load_simulate(out.path, strides or sc.simulate.strides)
    ending = simulate_ending(sim)  # a fall: no success-style summary
    if ending is None:
        typer.echo(simulate_text(sim))
    typer.echo(status(out))
    if out.failure:  # recorded in the artifact, and an error: one line, exit 1
        fail(RuntimeError(f"the walker {ending}" if ending else out.failure))


@guard
def contact_sim(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
                force: bool = ForceOpt,
                adjust: bool = typer.Option(False, "--adjust", help="search the initial rates "
                                            "that make the contact walker match the ideal gait"),
                periodic: bool = typer.Option(False, "--periodic", help="also find the contact "
                                              "walker's own periodic gait and its Floquet "
                                              "multipliers (about 10 s)"),
                strides: int | None = typer.Option(
                    None, "--strides", help="strides to simulate (1 stride = 2 steps) "
                    "(default: contact_sim.n_strides of the scene)")
                ) -> None:
    """Simulate the compliant-contact (MSC ADAMS style) walker on the scene's terrain."""
    from walkerlab.io.schemas.contact_sim import load_contact_sim  # light
    from walkerlab.io.stage_files import CONTACT_SIM  # light: as the pipeline below
    from walkerlab.report.text import contact_text  # light
    from walkerlab.stages import pipeline  # light

    out = pipeline.run(CONTACT_SIM.name, load(scene), runs_dir, force, adjust=adjust,
                       periodic=periodic, strides=strides)
    typer.echo(contact_text(load_contact_sim(out.path)))
    typer.echo(status(out))
    if out.failure:
        fail(RuntimeError(out.failure))


@guard
def compare(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
            force: bool = ForceOpt,
            rigid_limit: bool = typer.Option(
                False, "--rigid-limit", help="instead: the contact periodic gait along the "
                "rigid-limit family (rigid_limit.h5 and its figure)")) -> None:
    """Compare the ideal and contact trajectories (errors, periods, speed, energy)."""
    from walkerlab.io.schemas.compare import load_compare  # light
    from walkerlab.report.text import compare_text  # light
    from walkerlab.stages import pipeline  # light

    if rigid_limit:
        from walkerlab.io.schemas.rigid_limit import load_rigid_limit  # light
        from walkerlab.report.text import rigid_limit_text  # light
        from walkerlab.stages import rigid_limit as rl  # light

        sc = load(scene)
        out = rl.run(sc, runs_dir, force)
        for line in rigid_limit_text(load_rigid_limit(out.path)):
            typer.echo(line)
        for p in rl.draw(sc, runs_dir, out.path):
            typer.echo(f"wrote {p}")
        typer.echo(status(out))
        return
    out = pipeline.run("compare", load(scene), runs_dir, force)
    typer.echo(compare_text(load_compare(out.path)))
    typer.echo(status(out))


@guard
def workprecision(scene: Path | None = SceneArg, runs_dir: Path = RunsOpt,
                  force: bool = ForceOpt) -> None:
    """Work-precision study: error vs wall time for every solver and tolerance."""
    from walkerlab.io.schemas.workprecision import load_workprecision  # light
    from walkerlab.report.workprecision_section import workprecision_text  # light
    from walkerlab.stages import pipeline  # light

    out = pipeline.run("workprecision", load(scene), runs_dir, force)
    typer.echo(workprecision_text(load_workprecision(out.path)))
    typer.echo(status(out))
