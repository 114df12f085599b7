"""Dask client helpers of :class:`walkerlab.execution.executor.DaskExecutor`: never wait
forever, fail in one line (reliability).

Dask's scheduler keeps a task whose worker died and waits - silently, for ever - until
another worker joins; a scheduler that dies cancels every future and its client logs
tracebacks while it tries to reconnect.  Here:

- :func:`connect` checks a scheduler address before a ``Client`` exists and connects
  (one line when it cannot); :func:`quiet_distributed` keeps the ``distributed`` loggers
  quiet while the executor is open (their tracebacks are not for users);
- :func:`completed` yields futures as they finish, like ``distributed.as_completed``, but
  raises :class:`DaskLost` (a ``ValueError``, one line) when the scheduler has had no worker
  for :func:`worker_wait_s` seconds while work is pending, or when the connection to the
  scheduler is lost (cancelled futures); :func:`result` waits the same bounded way (a
  finished future whose data died with its worker is computed again and waits for a
  worker) and turns a cancelled or killed task into that line too.  Both share one wait,
  ``_WorkerWatch``.  A task that fails on its own raises its own error, unchanged.

The wait for workers is ``$WALKERLAB_DASK_WORKER_WAIT_S`` seconds (default
:data:`WORKER_WAIT_S`): long enough for a worker to be restarted by its nanny or a batch
system, short enough that a sweep whose workers are gone ends.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["DaskLost", "RERUN", "connect", "quiet_distributed", "completed", "result",
           "worker_wait_s", "WORKER_WAIT_S", "WAIT_ENV"]

#: default time a sweep waits for a Dask worker while none is connected [s]
WORKER_WAIT_S = 60.0
WAIT_ENV = "WALKERLAB_DASK_WORKER_WAIT_S"
#: how often finished futures are looked for [s]
POLL_S = 0.02
#: how often the scheduler is asked for its workers while nothing finishes [s]
CHECK_S = 1.0


#: how to continue after a lost cluster, unless the study says otherwise
#: (:meth:`DaskLost.advising`)
RERUN = "rerun with --resume"


class DaskLost(ValueError):
    """The Dask cluster cannot finish the work (no workers, scheduler gone); one line.

    Not bad input: the work finished before the loss is kept.  The message's ``{rerun}``
    is how to continue (default :data:`RERUN`); a study that continues some other way
    names it with :meth:`advising`.
    """

    def __init__(self, message: str, rerun: str = RERUN):
        super().__init__(message)
        self.message, self.rerun = message, rerun

    def __str__(self) -> str:
        return self.message.replace("{rerun}", self.rerun)

    def advising(self, rerun: str) -> DaskLost:
        """The same loss, advising ``rerun`` (e.g. ``"rerun the same command"``)."""
        return DaskLost(self.message, rerun)


def worker_wait_s() -> float:
    """Seconds to wait for a worker: ``$WALKERLAB_DASK_WORKER_WAIT_S`` or
    :data:`WORKER_WAIT_S`.

    Raises
    ------
    DaskLost
        The variable is not a positive number.
    """
    raw = os.environ.get(WAIT_ENV, "").strip()
    if not raw:
        return WORKER_WAIT_S
    try:
        v = float(raw)
    except ValueError:
        v = float("nan")
    if not (0 < v < 1e6):
        raise DaskLost(f"{WAIT_ENV}={raw!r}: give a number of seconds > 0")
    return v


@contextmanager
def quiet_distributed():
    """Silence the ``distributed`` loggers (each has a level of its own) until exit."""
    import distributed  # noqa: F401 - its loggers (and their levels) exist from here on

    names = ["distributed"] + [n for n in list(logging.root.manager.loggerDict)
                               if n.startswith("distributed.")]
    logs = [logging.getLogger(n) for n in names]  # children have levels of their own
    levels = [log.level for log in logs]
    for log in logs:
        log.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for log, level in zip(logs, levels):
            log.setLevel(level)


def _check_address(address: str) -> None:
    """Refuse an address the client cannot parse before a ``Client`` exists (a half-built
    client blocks the interpreter's exit for a minute, then prints a traceback)."""
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, loc = parse_address(address)
        if scheme not in ("tcp", "tls", "ws", "wss"):  # inproc:// etc.: not across processes
            raise ValueError(f"scheme {scheme}:// is not a network address")
        parse_host_port(loc)
    except (ValueError, TypeError) as exc:
        raise DaskLost(f"--scheduler {address!r}: not a Dask scheduler address ({exc}); give "
                       "tcp://host:port") from None


def connect(address: str):
    """A ``distributed.Client`` of the scheduler at ``address``.

    Raises
    ------
    DaskLost
        Not a network address, or the scheduler cannot be reached (one line naming it).
    """
    from distributed import Client

    _check_address(address)
    try:
        return Client(address, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise DaskLost(f"Dask scheduler {address}: cannot connect ({exc})") from None


def _lost(client) -> DaskLost:
    where = getattr(client.scheduler, "address", None) or "the Dask scheduler"
    return DaskLost(f"lost the connection to the Dask scheduler {where}; the work finished so "
                    "far is kept: restart the scheduler and its workers and {rerun}")


def _n_workers(client) -> int | None:
    """Workers the scheduler has now, asked over the wire; None when it does not answer.

    ``client.scheduler_info()`` is not used: it swallows a connection error and returns the
    cached worker list, so a dead scheduler looked alive (the session-6/7 flake of
    ``test_h1_dask_scheduler_killed``)."""
    try:
        ident = client.sync(client.scheduler.identity, callback_timeout=CHECK_S + 2.0)
        return len(ident.get("workers", {}))
    except Exception:  # noqa: BLE001 - the scheduler is unreachable: reported as lost
        return None


def completed(client, futures, wait_s: float | None = None) -> Iterator:
    """Yield ``futures`` as they finish, like ``distributed.as_completed`` (a future added
    with the iterator's ``add`` while iterating is waited for too); each yielded future is
    done and not cancelled.

    Parameters
    ----------
    client : distributed.Client
    futures : list of distributed.Future
    wait_s : float, optional
        Longest time without any worker while futures are pending [s]; default
        :func:`worker_wait_s`.

    Raises
    ------
    DaskLost
        No worker for ``wait_s`` seconds, or the scheduler is gone.
    """
    return _Completed(client, futures, worker_wait_s() if wait_s is None else wait_s)


class _WorkerWatch:
    """The one bounded wait on Dask futures (:func:`completed`, :func:`result`): between
    two looks for finished work, :meth:`check` asks the scheduler (at most every
    :data:`CHECK_S`) for its workers and raises :class:`DaskLost` once it has had none for
    ``wait_s`` seconds, or is gone."""

    def __init__(self, client, wait_s: float):
        self.client, self.wait_s = client, wait_s
        self.no_workers_since: float | None = None
        self.checked = time.monotonic()

    def check(self, waiting: int) -> None:
        """Raise :class:`DaskLost` when the wait must end (``waiting``: tasks waited for)."""
        now = time.monotonic()
        if now - self.checked < CHECK_S:
            return
        self.checked = now
        if self.client.status not in ("running", "connecting"):
            raise _lost(self.client)
        n = _n_workers(self.client)
        if n is None:
            raise _lost(self.client)
        if n:
            self.no_workers_since = None
        elif self.no_workers_since is None:
            self.no_workers_since = now
        elif now - self.no_workers_since >= self.wait_s:
            where = getattr(self.client.scheduler, "address", None) or "the scheduler"
            raise DaskLost(f"Dask scheduler {where} has had no worker for {self.wait_s:g} s "
                           f"({waiting} task(s) waiting); the work finished so far is kept: "
                           f"start workers (or raise {WAIT_ENV}) and {{rerun}}")


class _Completed:
    def __init__(self, client, futures, wait_s: float):
        from distributed import as_completed

        self.client, self.wait_s = client, wait_s
        self.ac = as_completed(list(futures), loop=client.loop)

    def add(self, fut) -> None:
        self.ac.add(fut)

    def __iter__(self):
        return self

    def __next__(self):
        watch = _WorkerWatch(self.client, self.wait_s)
        while not self.ac.is_empty():
            if self.ac.has_ready():
                fut = next(self.ac)
                if fut.status == "cancelled":
                    raise _lost(self.client)
                return fut
            time.sleep(POLL_S)
            watch.check(self.ac.count())
        raise StopIteration


def result(client, fut, wait_s: float | None = None):
    """``fut.result()``, waited for as :func:`completed` waits (a finished future whose data
    died with its worker is computed again, and waits for a worker): no worker for
    ``wait_s`` seconds (default :func:`worker_wait_s`), or the scheduler gone, raises
    :class:`DaskLost`; so does a task that killed its workers, or was cancelled or failed
    because the scheduler was lost (one line).  An error of the task itself (scheduler still
    there) propagates unchanged."""
    from distributed.client import FutureCancelledError
    from distributed.scheduler import KilledWorker

    watch = _WorkerWatch(client, worker_wait_s() if wait_s is None else wait_s)
    try:
        while True:
            try:
                return fut.result(timeout=CHECK_S)
            except TimeoutError:  # still waiting (asyncio's and distributed's are this one)
                watch.check(1)
    except KilledWorker as exc:
        raise DaskLost(f"a Dask task ended the worker running it, again and again "
                       f"({str(exc).replace('{', '(').replace('}', ')')}); the work finished "
                       "so far is kept: {rerun} (locally, without --scheduler, to see the "
                       "error)") from None
    except FutureCancelledError:
        raise _lost(client) from None
    except Exception:  # noqa: BLE001 - re-raised unless the scheduler is gone
        # a task that failed because its scheduler died mid-flight (the comm closed) is not
        # an error of the task: say the scheduler is lost, as for a cancelled future
        if client.status not in ("running", "connecting") or _n_workers(client) is None:
            raise _lost(client) from None
        raise
