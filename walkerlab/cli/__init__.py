"""Command-line interface (typer). Thin: parse arguments, call one stage, print a summary.

Every command takes an optional scene path (default: ``configs/paper.yaml``).

========================  ===========================================================
module                    what
========================  ===========================================================
``commands_runs``         fixedpoint, simulate, contact-sim, compare, workprecision
``commands_output``       plot, report, animate, export, bench
``commands_families``     sweep, bifurcation, continuation
``commands_robustness``   basin, mfpt, robustness, stability-map
``commands_reference``    capabilities (the walker kinds' capability table)
``options``               the shared arguments, loading the scene, the status line,
                          ``--quiet``/``-q`` on every command (``with_quiet``)
``errors``                the exit policy (:func:`walkerlab.cli.errors.guard`)
``process``               process settings (OpenBLAS threads, numba cache) and --version
``typer_flags``           typer's usage errors as one line ``error: ...``
========================  ===========================================================

Errors and exit codes
---------------------
A traceback shown to a user is a bug.  Every command runs inside
:func:`walkerlab.cli.errors.guard`: one line ``error: ...`` on stderr and exit code 1 for
bad input or a walker that falls (the stage's ``StageOutcome.failure``), ``interrupted`` and
130 on Ctrl-C.  typer's own usage errors (unknown option, a value out of an option's range)
keep typer's message, as one line ``error: ...`` too, and exit code 2.
"""

from __future__ import annotations

import typer

from walkerlab import progress
from walkerlab.cli import (
    commands_families,
    commands_output,
    commands_reference,
    commands_robustness,
    commands_runs,
)
from walkerlab.cli.options import QUIET_HELP, with_quiet
from walkerlab.cli.process import process_settings, single_threaded_blas, version_callback
from walkerlab.cli.typer_flags import usage_errors_in_one_spelling

usage_errors_in_one_spelling()

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="walkerlab: biped walkers (planar; in 3D: space: 3d), passive and "
                  "powered, from fixed point to report.")


@app.callback()
def _main(ctx: typer.Context,
          version: bool = typer.Option(False, "--version", callback=version_callback,
                                       is_eager=True,
                                       help="print walkerlab, Python, numpy, scipy, numba "
                                       "and h5py versions and exit"),
          quiet: bool = typer.Option(False, "--quiet", "-q", help=QUIET_HELP)
          ) -> None:
    """walkerlab: biped walkers (planar; in 3D: space: 3d), passive and powered, from fixed point
    to report."""
    single_threaded_blas()
    process_settings()

    sink = progress.sink_for_terminal(quiet, label=f"walkerlab {ctx.invoked_subcommand}")
    progress.install(sink)
    beat = getattr(sink, "heartbeat", None)
    if beat is not None:  # no silence past progress.HEARTBEAT_S, and none after the command
        ctx.call_on_close(beat.stop)


#: every command in the order ``--help`` lists them: (command name, function)
COMMANDS = (
    ("fixedpoint", commands_runs.fixedpoint), ("simulate", commands_runs.simulate),
    ("contact-sim", commands_runs.contact_sim), ("compare", commands_runs.compare),
    ("workprecision", commands_runs.workprecision), ("plot", commands_output.plot),
    ("report", commands_output.report), ("sweep", commands_families.sweep),
    ("bifurcation", commands_families.bifurcation),
    ("continuation", commands_families.continuation),
    ("target", commands_families.target), ("optimize", commands_families.optimize),
    ("basin", commands_robustness.basin),
    ("mfpt", commands_robustness.mfpt), ("robustness", commands_robustness.robustness),
    ("stability-map", commands_robustness.stability_map),
    ("animate", commands_output.animate), ("export", commands_output.export),
    ("bench", commands_output.bench), ("capabilities", commands_reference.capabilities),
)
#: each command's line in ``walkerlab --help``: one sentence that fits beside its name on
#: an 80-column terminal (the command's own ``--help`` gives its whole docstring)
SHORT_HELP = {
    "fixedpoint": "Find the period-1 gait and its Floquet multipliers.",
    "simulate": "Simulate the rigid walker for N strides.",
    "contact-sim": "Simulate the compliant-contact walker on its terrain.",
    "compare": "Compare the rigid and the contact trajectories.",
    "workprecision": "Time every solver setting against its error.",
    "plot": "Draw the figures from the scene's artifacts.",
    "report": "Run what the scene needs and write the report.",
    "sweep": "Run a stage over a grid of scene fields.",
    "bifurcation": "Draw the bifurcation diagram over a scene field.",
    "continuation": "Follow the gait over a field, naming its special points.",
    "target": "Find the field value whose gait meets a target.",
    "optimize": "Optimise a gait, or design fields, by collocation.",
    "basin": "Map the basin of attraction of the gait.",
    "mfpt": "Mean first-passage time on random per-step slopes.",
    "robustness": "Gait sensitivity, step-down/up and MFPT at one sigma.",
    "stability-map": "Map where the contact gait exists and is stable.",
    "animate": "Animate the walker walking (GIF, and MP4 with ffmpeg).",
    "export": "Export the walker (URDF, MJCF, Adams, OpenSim).",
    "bench": "Benchmark wall time and right-hand-side evaluations.",
    "capabilities": "Show what each walker kind supports in each view.",
}
for _name, _command in COMMANDS:  # each with --quiet/-q of its own (options.with_quiet)
    app.command(_name, short_help=SHORT_HELP[_name])(with_quiet(_command))
