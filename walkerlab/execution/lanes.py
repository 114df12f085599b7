"""Pinned lanes: one single-threaded worker process per core, for timing work side by side.

A timed job (a work-precision case, :mod:`walkerlab.bench.workprecision`) must not share
its core with another timed job or with the caller's own work.  :func:`run_on_lanes` runs a
list of jobs on :class:`Lanes`: one thread per core, each feeding one worker process pinned
to that core (``os.sched_setaffinity``) and started with single-threaded BLAS/OpenMP, one
job at a time.  Gates and pending groups let a caller (``walkerlab report``) hold a lane
back while it uses the core itself, or hold back jobs of one group until their compiled
code is in the on-disk cache.  Workers are :func:`walkerlab.execution.workers.process_pool`
processes: they end with this process, even after SIGKILL or SIGTERM.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from walkerlab.execution.workers import mp_context, process_pool

__all__ = ["Lanes", "THREAD_VARS", "pinned_worker", "run_on_lanes"]

#: Thread-count variables set to 1 in the environment a pinned worker starts with.
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
_ENV_LOCK = threading.Lock()


def _pin(core: int, warm: Callable | None) -> None:
    """Worker initializer: stay on ``core``, then ``warm()`` (load the libraries the jobs use:
    a worker started ahead does this while its caller works)."""
    try:
        os.sched_setaffinity(0, {core})
    except Exception:  # noqa: BLE001 - pinning is best effort (not on every OS)
        pass
    if warm is not None:
        warm()


def pinned_worker(core: int, warm: Callable | None = None, context=None):
    """A one-process pool pinned to ``core``, started now with single-threaded BLAS/OpenMP
    (a thread pool is sized when numpy loads, before any initializer runs, so the limit
    must be in the environment the process starts with).

    Parameters
    ----------
    core : int
        CPU the worker stays on.
    warm : callable, optional
        Top-level function run in the worker after pinning.
    context : multiprocessing context, optional
        Default ``spawn`` (:func:`walkerlab.execution.workers.mp_context`).

    Returns
    -------
    concurrent.futures.ProcessPoolExecutor
    """
    ex = process_pool(1, context or mp_context("spawn"), _pin, (core, warm))
    with _ENV_LOCK:
        old = {v: os.environ.get(v) for v in THREAD_VARS}
        os.environ.update({v: "1" for v in THREAD_VARS})
        try:
            ex.submit(int)  # a spawn-context pool starts its process in submit()
        finally:
            for v, val in old.items():
                if val is None:
                    os.environ.pop(v, None)
                else:
                    os.environ[v] = val
    return ex


@dataclass
class Lanes:
    """Where timed jobs run: one single-threaded worker process per core, pinned to it.

    Attributes
    ----------
    cores : list of int
        One lane (worker process) per core.
    gates : dict[int, threading.Event]
        A lane whose core is listed starts only once its event is set (``walkerlab report``
        runs its untimed stages on that core meanwhile).
    pending : dict[str, threading.Event]
        Jobs of a listed group are taken only once its event is set (the report sets it
        when the group's compiled code is in numba's on-disk cache, so a worker loads it
        instead of compiling it a second time); other groups' jobs go first.
    cancel : threading.Event
        Set: the lanes take no new job.
    todo_known : threading.Event
        Set once the caller knows which jobs are left (after its cache lookup).
    todo_models : set
        Groups with jobs to run.
    workers : dict[int, ProcessPoolExecutor]
        Worker processes started ahead (:func:`pinned_worker`), by core; a lane takes its own.
    """

    cores: list
    gates: dict = field(default_factory=dict)
    pending: dict = field(default_factory=dict)
    cancel: threading.Event = field(default_factory=threading.Event)
    todo_known: threading.Event = field(default_factory=threading.Event)
    todo_models: set = field(default_factory=set)
    workers: dict = field(default_factory=dict)


def run_on_lanes(lanes: Lanes, jobs: list, fn: Callable, on_result: Callable[[Any], None],
                 group: Callable[[Any], str], warm: Callable | None = None,
                 name: str = "lanes") -> None:
    """Run ``fn(job)`` for every job on the lanes, in list order as far as the gates allow.

    Parameters
    ----------
    lanes : Lanes
    jobs : list
        Picklable jobs, taken from the front (the list is emptied as they are taken).
    fn : callable
        Top-level function run in a lane's worker.
    on_result : callable
        Called with each result, from the lane's thread.
    group : callable
        ``group(job)``: the key of :attr:`Lanes.pending` the job waits for.
    warm : callable, optional
        Run in each worker a lane starts itself (:func:`pinned_worker`).
    name : str
        The study's name (threads ``<name>-core<k>``, the cancellation message).

    Raises
    ------
    Exception
        The first error of any lane (the others then take no new job).
    RuntimeError
        The lanes were cancelled with jobs left.
    """
    lock = threading.Lock()
    errors: list[BaseException] = []

    def take():
        """Next job whose group is ready; None: nothing left; False: wait."""
        with lock:
            if not jobs or lanes.cancel.is_set():
                return None
            for i, job in enumerate(jobs):
                ev = lanes.pending.get(group(job))
                if ev is None or ev.is_set():
                    return jobs.pop(i)
            return False

    def nothing_left() -> bool:
        with lock:
            return not jobs or lanes.cancel.is_set()

    def lane(core):
        gate = lanes.gates.get(core)
        while gate is not None and not gate.wait(0.1):
            if nothing_left():
                return
        ex = None  # the worker starts with the lane's first job
        try:
            while (job := take()) is not None:
                if job is False:
                    time.sleep(0.05)
                    continue
                if ex is None:
                    ex = lanes.workers.pop(core, None) or pinned_worker(core, warm)
                on_result(ex.submit(fn, job).result())
        except BaseException as exc:  # noqa: BLE001 - re-raised in the calling thread
            lanes.cancel.set()
            errors.append(exc)
        finally:
            if ex is not None:
                ex.shutdown(wait=True, cancel_futures=True)

    threads = [threading.Thread(target=lane, args=(c,), name=f"{name}-core{c}")
               for c in lanes.cores]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    if errors:
        raise errors[0]
    if lanes.cancel.is_set() and jobs:
        raise RuntimeError(f"{name}: cancelled")
