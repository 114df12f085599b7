"""Arguments and options shared by the commands, loading the scene, the status line."""

from __future__ import annotations

from pathlib import Path

import typer

from walkerlab import progress

SceneArg = typer.Argument(None, help="scene YAML file, or a shipped scene's name (paper, "
                          "kneed, rabbit, ...) (default: configs/paper.yaml, the paper's walker)",
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
    from walkerlab.config import default_scene_path  # light

    return default_scene_path()


def load(scene: Path | None):
    """The scene at ``scene`` (default :func:`default_scene`), validated (SceneError)."""
    from walkerlab.config import load_scene  # light

    return load_scene(scene or default_scene())


def status(o) -> str:
    """The line saying what a stage did: ``wrote <path> (compute ...)`` or ``reused ...``."""
    return (f"reused {o.path} ({o.note or 'inputs unchanged'})" if o.reused
            else f"wrote {o.path} (compute {o.wall_time_s:.3f} s)")


#: ``--quiet`` / ``-q``: accepted before the command (``walkerlab -q report``) and after it
#: (``walkerlab report -q``), so every command's ``--help`` lists it
QUIET_HELP = ("no progress display and no notices on stderr (errors are still shown); when "
              "stderr is not a terminal, progress is a plain line per finished unit")


def with_quiet(command):
    """``command`` with a ``--quiet``/``-q`` option of its own: the one of ``walkerlab
    --quiet``, listed by the command's ``--help`` (typer lists a group's options only in
    the group's help).  Given, it installs the silent progress sink before the command runs
    (:func:`walkerlab.progress.sink_for_terminal`).

    Parameters
    ----------
    command : callable
        A command function (already wrapped by :func:`walkerlab.cli.errors.guard`).

    Returns
    -------
    callable
        The function typer registers: ``command``'s parameters and ``quiet``.
    """
    import functools
    import inspect

    sig = inspect.signature(command, eval_str=True)
    if "quiet" in sig.parameters:
        raise TypeError(f"{command.__name__}: has a 'quiet' parameter of its own")
    option = typer.Option(False, "--quiet", "-q", help=QUIET_HELP)

    @functools.wraps(command)
    def quieted(*args, quiet: bool = False, **kwargs):
        if quiet:

            progress.install(progress.sink_for_terminal(True))
        return command(*args, **kwargs)

    quieted.__signature__ = sig.replace(parameters=[
        *sig.parameters.values(),
        inspect.Parameter("quiet", inspect.Parameter.KEYWORD_ONLY, default=option,
                          annotation=bool)])
    quieted.__annotations__ = {**getattr(command, "__annotations__", {}), "quiet": bool}
    return quieted
