"""One executor protocol for every many-point study: in this process, a local pool, or Dask.

A study (a sweep, a basin map, a bifurcation diagram, a stability map) hands its work out as
*chains*: the jobs of one chain run one after the other, each starting from what its
predecessor carried over (a sweep's continuation guess); different chains run in parallel.
Independent jobs are chains of one job.  :func:`run_chains` and :func:`run_each` drive any
:class:`Executor`:

- :class:`InlineExecutor`: in this process, one job at a time (no start-up cost), the chains
  one after the other;
- :class:`PoolExecutor`: a local process pool (:func:`walkerlab.execution.workers.process_pool`:
  workers that end when this process dies, never forked);
- :class:`DaskExecutor`: a Dask ``distributed`` cluster at an address (or a ``Client``); a
  worker lost mid-study is replaced by Dask and its job recomputed elsewhere.

:func:`make_executor` picks one from the ``workers`` / ``scheduler`` / ``pool`` arguments the
studies share.  Every executor is a context manager: on exit (finished, interrupted, or an
exception) unfinished jobs are cancelled and a pool or a client opened here is shut down.
Importing this module loads nothing heavy.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Protocol

from walkerlab.execution.dask import completed, connect, quiet_distributed, result
from walkerlab.execution.workers import process_pool
from walkerlab.extras import require

__all__ = ["DaskExecutor", "Executor", "InlineExecutor", "PoolExecutor", "make_executor",
           "run_chains", "run_each"]


class Executor(Protocol):
    """Runs jobs ``fn(*args)`` and hands back each result once it is done.

    Attributes
    ----------
    slots : int or None
        Jobs in flight at most (None: as many as are submitted).
    """

    slots: int | None

    def submit(self, fn: Callable, *args) -> Any:
        """Start ``fn(*args)`` (a top-level, picklable function); returns a handle."""

    def next_done(self) -> tuple[Any, Any]:
        """``(handle, result)`` of a job that finished (blocks until one has).

        Raises
        ------
        Exception
            The job's own exception.
        """

    def close(self) -> None:
        """Cancel unfinished jobs and release the workers."""


class _Context:
    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class InlineExecutor(_Context):
    """Jobs run in this process, one at a time, when their result is asked for.

    Parameters
    ----------
    initializer : callable, optional
        Run once now (as a pool worker would at its start).
    initargs : tuple
    """

    slots = 1

    def __init__(self, initializer: Callable | None = None, initargs: tuple = ()):
        if initializer is not None:
            initializer(*initargs)
        self._jobs: deque = deque()
        self._n = 0

    def submit(self, fn: Callable, *args) -> int:
        self._n += 1
        self._jobs.append((self._n, fn, args))
        return self._n

    def next_done(self) -> tuple[int, Any]:
        handle, fn, args = self._jobs.popleft()
        return handle, fn(*args)

    def close(self) -> None:
        self._jobs.clear()


class PoolExecutor(_Context):
    """A local process pool whose workers end with this process.

    Parameters
    ----------
    workers : int
        Worker processes.
    context : multiprocessing context, optional
        Default :func:`walkerlab.execution.workers.mp_context`.
    initializer : callable, optional
        Run in each worker at its start (top-level, picklable).
    initargs : tuple
    """

    slots = None

    def __init__(self, workers: int, context=None, initializer: Callable | None = None,
                 initargs: tuple = ()):
        self._ex = process_pool(workers, context, initializer, initargs)
        self._pending: set = set()
        self._done: deque = deque()

    def submit(self, fn: Callable, *args):
        fut = self._ex.submit(fn, *args)
        self._pending.add(fut)
        return fut

    def next_done(self) -> tuple[Any, Any]:
        from concurrent.futures import FIRST_COMPLETED, wait

        if not self._done:
            done, _ = wait(self._pending, return_when=FIRST_COMPLETED)
            self._pending -= done
            self._done.extend(done)
        fut = self._done.popleft()
        return fut, fut.result()

    def close(self) -> None:
        self._ex.shutdown(wait=True, cancel_futures=True)


class DaskExecutor(_Context):
    """Jobs on a Dask ``distributed`` cluster.

    Never waits for ever: with no worker connected for ``$WALKERLAB_DASK_WORKER_WAIT_S``
    seconds (default 60) while jobs are pending, or with the scheduler gone,
    :meth:`next_done` raises :class:`walkerlab.execution.dask.DaskLost` (one line suggesting
    ``--resume``); ``distributed``'s own log lines are kept quiet while it is open.

    Parameters
    ----------
    scheduler : str or distributed.Client
        Scheduler address (``"tcp://..."``; a client is opened here and closed on exit) or
        an existing client (left open).

    Raises
    ------
    walkerlab.execution.dask.DaskLost
        The address is not one, or the scheduler cannot be reached (one line).
    walkerlab.extras.MissingExtra
        Dask is not installed (one line naming the ``dask`` extra).
    """

    slots = None

    def __init__(self, scheduler):
        require("distributed", "dask", "--scheduler")

        self._own = isinstance(scheduler, str)
        self._quiet = quiet_distributed()
        self._quiet.__enter__()
        try:
            self.client = connect(scheduler) if self._own else scheduler
        except BaseException:
            self._quiet.__exit__(None, None, None)
            raise
        self._futures: list = []
        self._ac = None

    def submit(self, fn: Callable, *args):
        fut = self.client.submit(fn, *args, pure=False)
        self._futures.append(fut)
        if self._ac is None:
            self._ac = completed(self.client, [fut])
        else:
            self._ac.add(fut)
        return fut.key

    def next_done(self) -> tuple[Any, Any]:
        fut = next(self._ac)
        return fut.key, result(self.client, fut)

    def close(self) -> None:
        try:
            try:
                self.client.cancel([f for f in self._futures if not f.done()])
            except Exception:  # noqa: BLE001 - a lost scheduler: nothing left to cancel
                pass
            if self._own:
                try:
                    self.client.close(timeout=5)
                except Exception:  # noqa: BLE001 - closing a client whose scheduler died
                    pass
        finally:
            self._quiet.__exit__(None, None, None)


def make_executor(workers: int = 1, scheduler=None, pool: bool | None = None,
                  initializer: Callable | None = None, initargs: tuple = (),
                  context: Callable | None = None):
    """The executor of a study's ``workers`` / ``scheduler`` / ``pool`` arguments.

    Parameters
    ----------
    workers : int
        Local processes (ignored with a scheduler).
    scheduler : str or distributed.Client, optional
        Dask scheduler address or client: a :class:`DaskExecutor`.
    pool : bool, optional
        Force (True) or forbid (False) a process pool; default: a pool when ``workers > 1``.
    initializer : callable, optional
        Run at each local worker's start (in this process for :class:`InlineExecutor`).
    initargs : tuple
    context : callable, optional
        ``() -> multiprocessing context`` of the pool (asked only when a pool is made).

    Returns
    -------
    InlineExecutor, PoolExecutor or DaskExecutor
    """
    if scheduler is not None:
        return DaskExecutor(scheduler)
    if pool if pool is not None else workers > 1:
        return PoolExecutor(workers, context() if context is not None else None,
                            initializer, initargs)
    return InlineExecutor(initializer, initargs)


def run_chains(executor: Executor, fn: Callable, chains: Sequence[Sequence],
               carries: Sequence | None = None) -> Iterator[tuple[int, int, Any, Any]]:
    """Run chains of jobs; yield ``(chain, position, output, carry)`` as each job returns.

    ``fn(job, carry) -> (output, carry)``: a chain's next job is submitted with the carry of
    the job before it as soon as that one returns (before it is yielded).  With a limited
    number of :attr:`Executor.slots` a chain's next job goes before a new chain's first
    (in this process: one chain after the other).

    Parameters
    ----------
    executor : Executor
    fn : callable
        Top-level (picklable) function.
    chains : sequence of sequence
        The jobs of each chain, in order; empty chains are skipped.
    carries : sequence, optional
        What each chain's first job starts from (default None).
    """
    first = list(carries) if carries is not None else [None] * len(chains)
    waiting = deque(ci for ci, c in enumerate(chains) if c)
    slots = executor.slots
    where: dict = {}

    def start(ci: int, k: int, carry) -> None:
        where[executor.submit(fn, chains[ci][k], carry)] = (ci, k)

    def fill() -> None:
        while waiting and (slots is None or len(where) < slots):
            ci = waiting.popleft()
            start(ci, 0, first[ci])

    fill()
    while where:
        handle, (out, carry) = executor.next_done()
        ci, k = where.pop(handle)
        if k + 1 < len(chains[ci]):
            start(ci, k + 1, carry)
        fill()
        yield ci, k, out, carry


def _one(job, carry):
    fn, args = job
    return fn(*args), None


def run_each(executor: Executor, fn: Callable, jobs: Sequence[tuple]
             ) -> Iterator[tuple[int, Any]]:
    """Run ``fn(*args)`` for every ``args`` of ``jobs``; yield ``(index, result)`` as each
    returns (chains of one job, :func:`run_chains`)."""
    for i, _k, out, _c in run_chains(executor, _one, [[(fn, tuple(a))] for a in jobs]):
        yield i, out
