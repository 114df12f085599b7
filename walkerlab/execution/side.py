"""One worker process beside this one, for untimed work on the second core.

:class:`SideWorker` is how ``walkerlab report`` uses a second core while its stages run one
after the other in this process: the side process compiles the contact model's numba
kernels into the user cache while the rigid stages run here, and draws half of the figures
(:meth:`SideWorker.share`).  It knows nothing of stages: it runs the functions it is given.

- The process is started on the first :meth:`~SideWorker.submit` (nothing to do, no
  process), by :func:`walkerlab.execution.workers.process_pool` (it ends when this process
  dies), and never with fewer than two cores, nor (``idle_only``) when the cores are busy
  (:func:`spare_core`: the load average of the last minute and the tasks running now both
  at least the number of cores): there it would only take turns with this process, and a
  second process costs CPU of its own (its imports).
- It ignores SIGINT: Ctrl-C reaches this process, which cancels what has not started and
  stops the task under way with SIGTERM (:meth:`~SideWorker.close` with ``cancel``; in the
  side process SIGTERM raises ``SystemExit``, so a file being written is removed, never
  left half-written: :func:`walkerlab.safefs.atomic_replace`, numba's cache writes through
  :func:`walkerlab.usercache.guard_numba_cache`); after the work is done, it waits for it.
- A side process that cannot start or breaks costs its work, never the run: results are
  then computed here.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from concurrent.futures import Future
from concurrent.futures.process import BrokenProcessPool

from walkerlab.execution.workers import process_pool

__all__ = ["SideWorker", "side_signals", "spare_core"]


def _exit(signum, frame):
    raise SystemExit(128 + signum)


def side_signals() -> None:
    """The side process's initializer: ignore SIGINT (Ctrl-C is this process's to handle),
    and end by ``SystemExit`` on SIGTERM (``finally`` clauses run: no half-written file)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _exit)


def _cores() -> int:
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1  # pragma: no cover - not Linux


#: looks at the tasks running now when the minute's load average says busy, and their spacing
SAMPLES, SAMPLE_PERIOD_S = 5, 0.005


def _running_now() -> int | None:
    """Processes and threads running or ready to run at this instant, this one included
    (Linux's ``/proc/loadavg``, its fourth field ``running/total``); None elsewhere."""
    try:
        with open("/proc/loadavg", encoding="ascii") as fh:
            return int(fh.read().split()[3].split("/")[0])
    except (OSError, ValueError, IndexError):
        return None


def spare_core(cores: int) -> bool:
    """Whether the machine seems to have a core to spare: the load average of the last
    minute is below ``cores``, or (it lags a burst that has ended by about a minute: a
    benchmark's or a user's previous command) fewer than ``cores`` tasks are running, this
    process included, at each of :data:`SAMPLES` looks over ~20 ms.  True where the system
    gives no load average."""
    try:
        if os.getloadavg()[0] < cores:
            return True
    except OSError:  # pragma: no cover - no load average
        return True
    import time

    for k in range(SAMPLES):  # a few looks, none of them busy: a snapshot may miss a task
        now = _running_now()
        if now is None or now >= cores:
            return False
        if k + 1 < SAMPLES:
            time.sleep(SAMPLE_PERIOD_S)
    return True


class SideWorker:
    """A worker process beside this one, started on first use.

    Parameters
    ----------
    enabled : bool
        False: no process is ever started (:meth:`submit` returns None, :meth:`share`
        computes everything here).  Also False with fewer than two cores.
    idle_only : bool
        Also False when the cores are busy (:func:`spare_core`).
    """

    def __init__(self, enabled: bool = True, idle_only: bool = False):
        cores = _cores()
        self.enabled = enabled and cores >= 2 and (not idle_only or spare_core(cores))
        self._pool = None

    @property
    def started(self) -> bool:
        """Whether the side process was asked to start (some work was submitted)."""
        return self._pool is not None

    def submit(self, fn: Callable, *args) -> Future | None:
        """``fn(*args)`` in the side process (``fn`` a top-level function, ``args``
        picklable); None when there is no side process (disabled, or it broke)."""
        if not self.enabled:
            return None
        try:
            if self._pool is None:
                self._pool = process_pool(1, initializer=side_signals)
            return self._pool.submit(fn, *args)
        except (BrokenProcessPool, OSError, RuntimeError):
            self.enabled = False
            return None

    @staticmethod
    def wait(fut: Future | None) -> bool:
        """Wait for ``fut`` (of :meth:`submit`); True if it returned a true value, False if
        it failed or was never started (the work is then done again where it is needed)."""
        if fut is None:
            return False
        try:
            return bool(fut.result())
        except Exception:  # noqa: BLE001 - best effort: whoever needs it does it again
            return False

    def share(self, items: Sequence, here: Callable, there: Callable, *args) -> list:
        """``here(item)`` for each of ``items``, shared with the side process, which runs
        ``there(*args, item)`` (the same work, from picklable arguments).

        The side process takes the items from the last one back, this process from the
        first one on; each item is done once, by whichever reaches it first.  Returns the
        results in the order of ``items``; an error of the side process's work is raised
        here, a broken side process only makes this process do its items.
        """
        futures = [None] * len(items)
        for k in reversed(range(len(items))):
            futures[k] = self.submit(there, *args, items[k])
        out = [None] * len(items)
        for k, item in enumerate(items):
            if futures[k] is None or futures[k].cancel():
                futures[k] = None
                out[k] = here(item)
        for k, fut in enumerate(futures):
            if fut is None:
                continue
            try:
                out[k] = fut.result()
            except BrokenProcessPool:
                self.enabled = False
                out[k] = here(items[k])
        return out

    def close(self, cancel: bool = False) -> None:
        """Cancel what has not started, wait for the task under way (``cancel``: stop it,
        by SIGTERM: after an error or an interrupt here) and end the process."""
        if self._pool is not None:
            if cancel:
                # the executor keeps its processes in a private mapping: no public way to
                # stop the task under way
                for proc in list(getattr(self._pool, "_processes", {}).values()):
                    proc.terminate()
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        self.enabled = False

    def __enter__(self) -> SideWorker:
        return self

    def __exit__(self, exc_type, *exc) -> None:
        self.close(cancel=exc_type is not None)
