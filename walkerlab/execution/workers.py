"""Worker processes that never outlive the process that started them (one place, every pool).

Every local process pool of walkerlab (the pool executor of sweeps, basin maps, bifurcation
diagrams and stability maps: :mod:`walkerlab.execution.executor`; the work-precision study's
pinned lanes: :mod:`walkerlab.execution.lanes`) is built by :func:`process_pool`:

- workers are started by ``forkserver`` (Linux) or ``spawn``, never by ``fork``: a forked
  worker would inherit the parent's open files, among them the artifact lock (it then held
  the lock after the parent died);
- each worker runs :func:`watch_parent` first: a daemon thread that checks every
  :data:`WATCH_PERIOD_S` whether the process that built the pool still exists and ends the
  worker (``os._exit``) when it does not - after SIGKILL or SIGTERM of the parent as well as
  after a crash.  The forkserver and multiprocessing's resource tracker end on their own once
  the parent and the workers are gone (their pipes close);
- the parent watch asks :func:`walkerlab.safefs.process_alive`, the PID check the artifact
  locks and stale temporary files use (:func:`walkerlab.io.runpaths.artifact_lock`);
- Ctrl-C reaches every process of the terminal's foreground group, the workers and the
  forkserver too, but only the command reports it (``interrupted``, exit code 130): a
  worker ends at once and silently on SIGINT (:func:`quiet_interrupt`; a
  ``KeyboardInterrupt`` raised in it would print its traceback, an llvmlite one while
  numba compiles, from the worker's bootstrap or from inside a ctypes callback), and the
  forkserver starts with SIGINT ignored (:func:`start_forkserver`: it would print the
  traceback of the preload it was importing, numba's compiler's).

Importing this module loads nothing heavy.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Callable

from walkerlab.safefs import process_alive

__all__ = ["watch_parent", "mp_context", "process_pool", "quiet_interrupt", "start_forkserver",
           "WATCH_PERIOD_S", "INTERRUPTED_EXIT"]

#: how often a worker checks that its parent is alive [s]
WATCH_PERIOD_S = 0.5
#: a worker's exit status after SIGINT (128 + SIGINT, as a shell reports it)
INTERRUPTED_EXIT = 130


def _exit_quietly(signum, frame) -> None:
    os._exit(INTERRUPTED_EXIT)


def quiet_interrupt() -> None:
    """A worker's SIGINT handler: end the worker at once, printing nothing (``os._exit``).

    The command that started it got the same Ctrl-C and reports it in one line; a pool
    that loses a worker fails in the command, which the interrupt it recorded turns into
    ``interrupted`` (:func:`walkerlab.safefs.interrupted`).  Only in the worker's main
    thread (where Python runs signal handlers)."""
    import signal

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, _exit_quietly)


def start_forkserver() -> None:
    """Start multiprocessing's forkserver (if it is not running) with SIGINT ignored, so
    that Ctrl-C while it imports its preload (numba compiling the model functions) prints
    no traceback; its workers then start with SIGINT ignored too, until
    :func:`quiet_interrupt`.  Ignored only for the start (a fork and exec: a Ctrl-C in
    that moment is lost) and only from the main thread (elsewhere it starts as it would
    on the first job)."""
    import signal
    from multiprocessing import forkserver

    if threading.current_thread() is not threading.main_thread():
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        forkserver.ensure_running()
    finally:
        signal.signal(signal.SIGINT, old)


def _watch(pid: int, period_s: float) -> None:
    while process_alive(pid):
        time.sleep(period_s)
    os._exit(1)  # the parent is gone: nobody will read our result


def watch_parent(parent_pid: int, period_s: float = WATCH_PERIOD_S) -> None:
    """Start the daemon thread that ends this process once ``parent_pid`` is gone."""
    threading.Thread(target=_watch, args=(parent_pid, period_s), daemon=True,
                     name="walkerlab-parent-watch").start()


def _init(parent_pid: int, period_s: float, initializer: Callable | None,
          initargs: tuple) -> None:
    quiet_interrupt()
    watch_parent(parent_pid, period_s)
    if initializer is not None:
        initializer(*initargs)


def mp_context(method: str | None = None, preload: tuple[str, ...] = ()):
    """The multiprocessing context of walkerlab's pools: ``forkserver`` on Linux (with the
    modules ``preload`` imported once in the server), else ``spawn``; ``method`` forces one
    (``"spawn"``).  Never ``fork`` (see the module docstring)."""
    if method is None:
        method = "forkserver" if sys.platform.startswith("linux") else "spawn"
    if method == "fork":
        raise ValueError("walkerlab pools do not fork (a forked worker inherits open locks)")
    import multiprocessing as mp

    ctx = mp.get_context(method)
    if method == "forkserver" and preload:
        ctx.set_forkserver_preload(list(preload))
    return ctx


def process_pool(workers: int, context=None, initializer: Callable | None = None,
                 initargs: tuple = (), period_s: float = WATCH_PERIOD_S):
    """A ``ProcessPoolExecutor`` whose workers watch this process (see the module docstring).

    Parameters
    ----------
    workers : int
        Worker processes (at least 1).
    context : multiprocessing context, optional
        Default :func:`mp_context`.
    initializer, initargs
        Run in each worker after its watch has started (a top-level, picklable function).
    period_s : float
        Watch period [s].
    """
    from concurrent.futures import ProcessPoolExecutor

    context = context or mp_context()
    if context.get_start_method() == "forkserver":
        start_forkserver()
    return ProcessPoolExecutor(max_workers=max(1, int(workers)),
                               mp_context=context, initializer=_init,
                               initargs=(os.getpid(), period_s, initializer, tuple(initargs)))
