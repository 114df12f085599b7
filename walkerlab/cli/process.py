"""Settings of the process every command runs in, and ``--version``."""

from __future__ import annotations

import gc
import os
import threading

import typer


def versions() -> str:
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
    threads, but starting the thread pools of numpy's and scipy's OpenBLAS costs every
    command ~50-100 ms of start-up on the 2-core machine (3 OS threads -> 1).  Must
    run before numpy is imported; worker processes (sweeps, basin) inherit it, as the
    work-precision workers already set it for themselves.
    """
    os.environ.setdefault(BLAS_THREADS_ENV, "1")


#: cyclic garbage collector thresholds of a command's process (generation 0 allocations,
#: generation 1 and 2 collections; Python's are (700, 10, 10))
GC_THRESHOLDS = (20_000, 20, 20)
#: wall time [s] after a command's start during which the cyclic garbage collector does not
#: run (:func:`pause_collection`)
START_UP_S = 2.0


def process_settings() -> None:
    """Settings every command (and every worker it starts) runs with:

    - numba's on-disk cache in the per-user cache (``NUMBA_CACHE_DIR``, unless set), never
      in the installed package (:func:`walkerlab.usercache.use_for_numba`); before numba is
      imported, and inherited by worker processes;
    - ``SIGXFSZ`` ignored (a file-size limit, ``ulimit -f``, then makes a write fail with
      EFBIG, reported as "disk full" in one line, instead of killing the process);
    - the cyclic garbage collector's thresholds raised to :data:`GC_THRESHOLDS` (this
      process only; its workers keep Python's): a command imports scipy, h5py, pydantic and
      its own schema after this point, and with Python's (700, 10, 10) the collector walks
      those long-lived objects again and again (~5 % of ``walkerlab fixedpoint``'s
      CPU time).  Reference counting still frees everything without cycles at once;
    - no cyclic collection during the command's start-up (:func:`pause_collection`);
    - no collection at the interpreter's shutdown (:func:`no_collection_at_exit`).
    """
    import atexit
    import signal

    from walkerlab.usercache import use_for_numba

    use_for_numba()
    if hasattr(signal, "SIGXFSZ"):
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    gc.set_threshold(*GC_THRESHOLDS)
    pause_collection(START_UP_S)
    # once per process (a test suite runs many commands in one); registered before the
    # libraries the command imports, so their exit functions run before it
    atexit.unregister(no_collection_at_exit)
    atexit.register(no_collection_at_exit)


#: the process's one start-up pause (a test suite runs many commands in one process): its
#: timer, and whether the command's exit function has run (then the pause never ends)
_PAUSE: dict = {"timer": None, "exiting": False}
_PAUSE_LOCK = threading.Lock()


def pause_collection(seconds: float) -> None:
    """Turn the cyclic garbage collector off for the first ``seconds`` [s] (wall) of the
    process, once per process; then every object allocated so far goes into the
    collector's permanent generation (``gc.freeze``) and collection resumes
    (:func:`_resume_collection`, on a daemon timer thread).

    A command's start-up imports its libraries (typer, pydantic and the scene schema,
    h5py, scipy.optimize, numba and its target set-up, the generated kernels): about a
    million long-lived objects, which every generation-0 collection walked once more
    without finding garbage (``gc.callbacks`` show it: nearly all of the collector's time
    in a warm ``walkerlab contact-sim`` is spent during imports).  Frozen, they are never
    walked again.  Reference
    counting frees everything without cycles at once, as always; what is lost is only
    cyclic garbage made during the pause, which is kept (frozen) instead of freed.
    """
    with _PAUSE_LOCK:
        if _PAUSE["timer"] is not None or _PAUSE["exiting"]:
            return
        gc.disable()
        timer = threading.Timer(seconds, _resume_collection)
        timer.daemon = True
        timer.name = "walkerlab-gc-resume"
        _PAUSE["timer"] = timer
    timer.start()


def _resume_collection() -> None:
    """End of :func:`pause_collection`: freeze and collect again (not once the command's
    exit function has turned collection off for good)."""
    with _PAUSE_LOCK:
        if not _PAUSE["exiting"]:
            gc.freeze()
            gc.enable()


def no_collection_at_exit() -> None:
    """The command's exit function (the last to run, :func:`process_settings`): every
    object into the garbage collector's permanent generation (``gc.freeze``) and the
    collector off.  The interpreter's shutdown then frees what reference counting frees
    and no longer walks the objects of numba, scipy, sympy and matplotlib in its
    collections: measured ~0.4 s of a warm ``walkerlab contact-sim`` (2.2 -> 1.5 s wall)
    and ~0.8 s of a cold first ``walkerlab report``.  Nothing is lost: the command's files
    are written and closed before its exit functions run, and Python runs no finaliser
    of a reference cycle at shutdown for certain anyway."""
    with _PAUSE_LOCK:
        _PAUSE["exiting"] = True
        if _PAUSE["timer"] is not None:
            _PAUSE["timer"].cancel()
        gc.disable()
        gc.freeze()
