"""Run a timed study in a thread beside untimed work, on cores of its own.

:class:`BackgroundStudy` is how ``walkerlab report`` overlaps the work-precision study
(whose timed cases run in worker processes pinned to their own cores,
:class:`walkerlab.execution.lanes.Lanes`) with the stages that are not timed.  It knows
nothing of stages: it runs the callable it is given.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable

from walkerlab.execution.lanes import Lanes


class BackgroundStudy:
    """A timed study in a thread, overlapping the untimed work of this process.

    With two cores, the first core's lane starts at once; this process (every thread of it)
    stays on the second core for the untimed work, and that core's lane starts at
    :meth:`release`.  The cases of a model listed in ``pending`` wait until its compiled
    kernels are in numba's on-disk cache (:meth:`ready`), so no worker compiles them a
    second time.  With more cores this process keeps a core of its own; with one, the study
    runs at :meth:`join`, in this process.

    Created before the untimed work: on a ``first_run`` (no artifact yet) the first lane's
    worker process starts at once and imports its libraries on its core while this process
    works; :meth:`start` starts the study itself.

    Parameters
    ----------
    run : callable(lanes) -> result
        The study; ``lanes`` is None when it runs in this process.
    start_worker : callable(core) -> executor
        Starts a measuring worker process pinned to ``core``
        (:func:`walkerlab.bench.workprecision.start_worker`).
    first_run : bool
        Start the worker processes now (nothing is cached yet).
    pending : tuple of str
        Models whose cases wait for :meth:`ready`.
    workers : int
        Cores given to the study's lanes.
    """

    def __init__(self, run: Callable, start_worker: Callable, first_run: bool,
                 pending: tuple[str, ...] = (), workers: int = 2):
        self._run_study = run
        cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
        self.lanes = None
        self._affinity = None
        self.outcome = self.error = None
        self.thread = None
        if len(cores) < 2:
            return
        lanes = cores[:workers]
        mine = cores[workers] if len(cores) > workers else lanes[-1]
        self.lanes = Lanes(cores=lanes)
        if mine in lanes:
            self.lanes.gates[mine] = threading.Event()
        for model in pending:
            self.lanes.pending[model] = threading.Event()
        self._affinity = set(cores)
        os.sched_setaffinity(0, {mine})  # threads started later inherit it
        try:
            if first_run:
                self.lanes.workers = {c: start_worker(c) for c in lanes
                                      if c not in self.lanes.gates}
        except BaseException:
            self.release(cancel=True)
            raise
        self.thread = threading.Thread(target=self._run, name="study", daemon=True)

    def start(self) -> None:
        """Start the study."""
        if self.thread is not None:
            self.thread.start()

    def _run(self):
        try:
            self.outcome = self._run_study(self.lanes)
        except BaseException as exc:  # noqa: BLE001 - re-raised by join()
            self.error = exc

    def needs(self, model: str) -> bool:
        """Whether the study has ``model`` cases to measure (waits until it knows: a reused
        study or fully cached cases need none, and then nothing is warmed up)."""
        if self.lanes is None or model not in self.lanes.pending:
            return False
        while not self.lanes.todo_known.wait(0.02):
            if not self.thread.is_alive():
                return False
        return model in self.lanes.todo_models

    def ready(self, model: str) -> None:
        """``model``'s compiled code is on disk: its cases may start."""
        if self.lanes is not None and model in self.lanes.pending:
            self.lanes.pending[model].set()

    def release(self, cancel: bool = False) -> None:
        """This process is done with its core: the core's lane starts (``cancel``: no new
        case is started at all)."""
        if self.lanes is None:
            return
        if cancel:
            self.lanes.cancel.set()
        for ev in (*self.lanes.gates.values(), *self.lanes.pending.values()):
            ev.set()
        if self._affinity is not None:
            os.sched_setaffinity(0, self._affinity)
            self._affinity = None

    def join(self):
        """The study's result (runs it here when there is no second core)."""
        if self.thread is None:
            return self._run_study(None)
        if self.thread.ident is not None:  # started
            self.thread.join()
        for ex in self.lanes.workers.values():  # started but never used
            ex.shutdown(wait=True, cancel_futures=True)
        self.lanes.workers.clear()
        if self.error is not None:
            raise self.error
        return self.outcome

    def cancel(self) -> None:
        """Stop starting cases and wait for the study (after an error elsewhere)."""
        if self.thread is not None:
            self.release(cancel=True)
            try:
                self.join()
            except BaseException:  # noqa: BLE001 - the first error is the one to report
                pass
