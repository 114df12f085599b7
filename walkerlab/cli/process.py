"""Settings of the process every command runs in, and ``--version``."""

from __future__ import annotations

import os

import typer

import walkerlab
from walkerlab.safefs import note_interrupt
from walkerlab.usercache import use_for_numba


def versions() -> str:
    """walkerlab, Python and the numeric libraries' versions (for bug reports)."""
    import platform
    from importlib import metadata

    parts = [f"walkerlab {walkerlab.__version__}", f"python {platform.python_version()}"]
    for dist in ("numpy", "scipy", "numba", "h5py", "pydantic", "matplotlib"):
        try:
            parts.append(f"{dist} {metadata.version(dist)}")
        except metadata.PackageNotFoundError:
            parts.append(f"{dist} not installed")
    return ", ".join(parts) + f" ({platform.system()} {platform.machine()})"


def version_callback(value: bool) -> None:
    """``--version``: print :func:`versions` and exit."""
    if value:
        typer.echo(versions())
        raise typer.Exit()


#: OpenBLAS thread pools (numpy's and scipy's each start one when loaded)
BLAS_THREADS_ENV = "OPENBLAS_NUM_THREADS"


def single_threaded_blas() -> None:
    """Ask OpenBLAS for one thread unless the user chose a number (``OPENBLAS_NUM_THREADS``).

    walkerlab's matrices have at most a few dozen rows, which OpenBLAS never splits across
    threads, but starting the thread pools of numpy's and scipy's OpenBLAS adds to every
    command's start-up (3 OS threads -> 1).  Must
    run before numpy is imported; worker processes (sweeps, basin) inherit it, as the
    work-precision workers already set it for themselves.
    """
    os.environ.setdefault(BLAS_THREADS_ENV, "1")


#: cyclic garbage collector thresholds of a command's process (generation 0 allocations,
#: generation 1 and 2 collections; Python's are (700, 10, 10))
GC_THRESHOLDS = (20_000, 20, 20)


def process_settings() -> None:
    """Settings every command (and every worker it starts) runs with:

    - numba's on-disk cache in the per-user cache (``NUMBA_CACHE_DIR``, unless set), never
      in the installed package (:func:`walkerlab.usercache.use_for_numba`); before numba is
      imported, and inherited by worker processes;
    - ``SIGXFSZ`` ignored (a file-size limit, ``ulimit -f``, then makes a write fail with
      EFBIG, reported as "disk full" in one line, instead of killing the process);
    - ``SIGTERM`` handled as ``SIGINT``, and both recorded even when a library swallows
      their exception (:func:`terminate_as_interrupt`);
    - the cyclic garbage collector's thresholds raised to :data:`GC_THRESHOLDS` (this
      process only; its workers keep Python's): a command imports scipy, h5py, pydantic and
      its own schema after this point, and with Python's (700, 10, 10) the collector walks
      those long-lived objects again and again (~5 % of ``walkerlab fixedpoint``'s
      CPU time).  Reference counting still frees everything without cycles at once;
    - no collection at the interpreter's shutdown (:func:`no_collection_at_exit`).
    """
    import atexit
    import gc
    import signal

    use_for_numba()
    if hasattr(signal, "SIGXFSZ"):
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    terminate_as_interrupt()
    gc.set_threshold(*GC_THRESHOLDS)
    # once per process (a test suite runs many commands in one); registered before the
    # libraries the command imports, so their exit functions run before it
    atexit.unregister(no_collection_at_exit)
    atexit.register(no_collection_at_exit)


def _interrupt(signum, frame) -> None:

    note_interrupt()  # kept even if the exception below is swallowed on its way
    raise KeyboardInterrupt


def _unraisable(hook):
    """``sys.unraisablehook`` over ``hook``: a ``KeyboardInterrupt`` that could not be
    raised (the signal handler ran inside a ctypes callback, e.g. numba's compiler's, which
    prints and drops its exceptions) is recorded (:func:`walkerlab.safefs.note_interrupt`)
    instead of printed as a traceback; anything else goes to ``hook``."""
    def unraisable(args) -> None:
        if isinstance(args.exc_value, KeyboardInterrupt):

            note_interrupt()
            return
        hook(args)
    unraisable.walkerlab = True
    return unraisable


def terminate_as_interrupt() -> None:
    """``SIGTERM`` (``kill PID``, a scheduler's stop) raises ``KeyboardInterrupt`` as Ctrl-C
    does, so a write under way removes its temporary file and releases its lock as it does
    on Ctrl-C (the default action ends the process at once, leaving both behind).  Both
    signals also record the interrupt (:func:`walkerlab.safefs.note_interrupt`): one whose
    exception a library swallows (raised inside a ctypes callback while numba compiles)
    still ends the command with code 130 and writes no artifact
    (:func:`walkerlab.safefs.atomic_replace`).  Only in the main thread, and only over the
    default actions (a handler someone else installed is kept; an ignored SIGINT, as in a
    shell's background job, stays ignored)."""
    import signal
    import sys
    import threading

    if threading.current_thread() is not threading.main_thread():
        return
    if signal.getsignal(signal.SIGTERM) in (signal.SIG_DFL, _interrupt):
        signal.signal(signal.SIGTERM, _interrupt)
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _interrupt)
    if not getattr(sys.unraisablehook, "walkerlab", False):
        sys.unraisablehook = _unraisable(sys.unraisablehook)


def no_collection_at_exit() -> None:
    """The command's exit function (the last to run, :func:`process_settings`): every
    object into the garbage collector's permanent generation (``gc.freeze``) and the
    collector off.  The interpreter's shutdown then frees what reference counting frees
    and no longer walks the objects of numba, scipy, sympy and matplotlib in its
    collections (``walkerlab bench main-job`` times the commands it shortens: a warm
    ``walkerlab contact-sim``, a cold first ``walkerlab report``).  Nothing is lost: the
    command's files are written and closed before its exit functions run, and Python runs
    no finaliser of a reference cycle at shutdown for certain anyway."""
    import gc

    gc.disable()
    gc.freeze()
