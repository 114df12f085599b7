"""Exit policy of every command: one line on stderr and exit code 1 for a failure.

- a scene that does not validate: every error on its own line ``error: <file>: <field>:
  <message>``, unknown keys first (with the closest field name), exit code 1;
- bad input (scene, names, paths, artifacts, a busy artifact, a read-only runs folder) and
  a walker that falls (``simulate``, ``contact-sim``: the stage's ``StageOutcome.failure``):
  one line ``error: ...`` on stderr (a reason longer than :data:`MAX_ERROR_CHARS` takes a
  second line: never cut), exit code 1;
- an unexpected exception: one line ``error: internal error (<type>): <message>`` and a hint
  to rerun with ``WALKERLAB_DEBUG=1``, which shows the traceback instead; exit code 1;
- Ctrl-C or SIGTERM: ``interrupted``, exit code 130, also when a library swallowed the
  interrupt's exception (:func:`walkerlab.safefs.interrupted`; whatever failed after it is
  not reported, and no artifact is written: :func:`walkerlab.safefs.atomic_replace`).
"""

from __future__ import annotations

import os
import sys

import typer

from walkerlab import progress
from walkerlab.safefs import interrupted, raise_if_interrupted, watching_interrupts


def fail(exc: Exception) -> None:
    """Print ``error: <exc>`` on stderr and exit with code 1."""
    typer.echo(f"error: {exc}", err=True)
    raise typer.Exit(code=1)


DEBUG_ENV = "WALKERLAB_DEBUG"
#: values of ``WALKERLAB_DEBUG`` that show tracebacks (case-insensitive); anything else
#: (``0``, ``false``, ``no``, empty) keeps errors to one line
DEBUG_ON = ("1", "true", "yes")
#: longest error line; a longer message takes a second line (never cut)
MAX_ERROR_CHARS = 300


def _debug() -> bool:
    return os.environ.get(DEBUG_ENV, "").strip().lower() in DEBUG_ON


def one_line(text: str, limit: int = MAX_ERROR_CHARS) -> str:
    """A message as one line (its lines joined: a sentence wrapped over two lines stays
    whole), never cut: longer than ``limit``, it takes a second line, broken after the last
    sentence or field boundary (``.``, ``;``, ``:``, ``,`` followed by a space) within the
    limit.  A message ending in a ``[detail]`` (what a search tried) keeps its advice on the
    first line, however long, and the detail on the second."""
    line = " ".join(ln.strip() for ln in str(text).strip().splitlines() if ln.strip())
    if len(line) <= limit:
        return line
    start = line.rfind(" [")
    if line.endswith("]") and start > 0:  # the advice, then what was tried
        return f"{line[:start]}\n  {line[start + 1:]}"
    head = line[:limit]
    cut = max(head.rfind(sep) for sep in (". ", "; ", ": ", ", "))
    if cut <= limit // 3:
        cut = head.rfind(" ")
    if cut <= 0:
        return line
    return f"{line[:cut + 1].rstrip()}\n  {line[cut + 1:].lstrip()}"


def _disk_full_line(exc: BaseException) -> str:
    where = f" {exc.filename}" if getattr(exc, "filename", None) else ""
    return (f"error: disk full: cannot write{where}; free some space (or raise the file-size "
            "limit) and rerun")


#: errors shown as one line that live in modules a command may never import: looked up in
#: ``sys.modules`` when an exception is handled (a module never imported raised nothing), so
#: the guard does not import the rigid walker's analysis into every command
_ONE_LINE_ERRORS = (("walkerlab.analysis.gait.poincare", "FixedPointNotFound"),
                    ("walkerlab.analysis.gait.poincare", "MultipliersDisagree"))


def _loaded_errors(names) -> tuple[type, ...]:
    """The exception classes ``(module, name)`` of ``names`` whose module is imported."""
    mods = ((sys.modules.get(m), n) for m, n in names)
    return tuple(getattr(m, n) for m, n in mods if m is not None and hasattr(m, n))


def guard(fn):
    """Run a command so that every failure is one line on stderr and a non-zero exit code."""
    import functools

    @functools.wraps(fn)
    def wrapper(*a, **k):
        from walkerlab.config import SceneError  # light
        from walkerlab.io.artifacts import ArtifactError, is_disk_full  # light
        from walkerlab.io.runpaths import ArtifactBusy  # light
        from walkerlab.stages.common import StageError  # light

        debug = _debug()

        def watched():
            with watching_interrupts():
                try:
                    # a spinner with the elapsed time on a terminal: never silent while it
                    # works
                    with progress.task(f"walkerlab {fn.__name__.replace('_', '-')}"):
                        out = fn(*a, **k)
                except Exception:
                    if interrupted():  # what followed an interrupt a library swallowed
                        raise KeyboardInterrupt from None
                    raise
                raise_if_interrupted()  # swallowed on its way (a ctypes callback's)
                return out

        try:
            return watched()
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
        except (ArtifactError, ArtifactBusy, StageError, ValueError,
                *_loaded_errors(_ONE_LINE_ERRORS)) as exc:
            if debug:
                raise
            typer.echo(f"error: {one_line(exc)}", err=True)
            raise typer.Exit(code=1) from None
        except OSError as exc:  # read-only runs folder, disk full, ...
            if debug:
                raise
            if is_disk_full(exc):
                typer.echo(_disk_full_line(exc), err=True)
                raise typer.Exit(code=1) from None
            where = f"{exc.filename}: " if exc.filename else ""
            typer.echo(f"error: {where}{exc.strerror or one_line(exc)}", err=True)
            raise typer.Exit(code=1) from None
        except Exception as exc:  # noqa: BLE001 - a traceback shown to a user is a bug
            if debug:
                raise
            if is_disk_full(exc):  # HDF5 reports a full disk as a RuntimeError too
                typer.echo(_disk_full_line(exc), err=True)
                raise typer.Exit(code=1) from None
            typer.echo(f"error: internal error ({type(exc).__name__}): {one_line(exc)} "
                       f"[rerun with {DEBUG_ENV}=1 for the traceback]", err=True)
            raise typer.Exit(code=1) from None
    return wrapper
