"""Progress of long work, reported by libraries and rendered by the command line.

Libraries (basin, bifurcation, sweeps, stability maps, work-precision, the contact
adjustment, the report) never print progress themselves and never import ``rich``: they
open a :func:`task` and update it, and send one-line notices through :func:`note`.  What
happens with those calls is decided by the installed *sink* (:func:`use`):

- no sink (library use, tests): nothing is shown; notices go to stderr as one line;
- the CLI installs :class:`RichSink` when stderr is a terminal and ``--quiet`` is not given
  (a ``rich.progress`` display on stderr: what is being done, count, elapsed time and an
  estimate of what is left; a spinner with the elapsed time where no count is known),
  :class:`LineSink` when stderr is not a terminal (a pipe, ``nohup``, CI: one plain line per
  finished unit of a task of few units - a sigma, a controller, a stage - and per tenth of a
  longer one, and the notices), and ``QuietSink(silent=True)`` under ``--quiet`` (nothing).

No silence over :data:`HEARTBEAT_S`: the CLI's sinks keep a heartbeat (:class:`Heartbeat`)
that, when nothing was shown for that long, prints one line naming the innermost task under
way (or the command, where none is open) and how long the command has run: a derivation, a
compilation or an integration that reports no units is still seen to be working.

A sink is any object with the :class:`Sink` methods; a test can install a recorder.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Protocol

__all__ = ["HEARTBEAT_ENV", "HEARTBEAT_S", "Heartbeat", "heartbeat_s", "machine_note", "Sink",
           "Task", "task", "note", "use", "current", "install", "sink_for_terminal",
           "QuietSink", "RichSink", "LineSink"]

#: longest silence of a command [s]: past it the heartbeat prints a line (:class:`Heartbeat`);
#: ``$WALKERLAB_HEARTBEAT_S`` sets another (0: none, and no :func:`machine_note` either, as a
#: test suite that reads stderr sets it)
HEARTBEAT_S = 8.0
HEARTBEAT_ENV = "WALKERLAB_HEARTBEAT_S"


def heartbeat_s() -> float:
    """The heartbeat's period [s]: ``$WALKERLAB_HEARTBEAT_S`` when it is a number, else
    :data:`HEARTBEAT_S`; 0 or less: no heartbeat."""
    import os

    try:
        return float(os.environ.get(HEARTBEAT_ENV, HEARTBEAT_S))
    except ValueError:
        return HEARTBEAT_S


class Sink(Protocol):
    """Receives progress (one object per display)."""

    def start(self, key: int, description: str, total: int | None, completed: int) -> None:
        """A task began (``total`` None: unknown length)."""

    def update(self, key: int, completed: int, total: int | None, info: str) -> None:
        """``completed`` of ``total`` units are done (monotone within a task)."""

    def finish(self, key: int) -> None:
        """The task ended (normally or not)."""

    def note(self, message: str) -> None:
        """A one-line notice (e.g. rows of a resumed file that were dropped)."""


class QuietSink:
    """Shows no progress; notices go to stderr unless ``silent``."""

    def __init__(self, silent: bool = False):
        self.silent = silent

    def start(self, key, description, total, completed):
        pass

    def update(self, key, completed, total, info):
        pass

    def finish(self, key):
        pass

    def note(self, message):
        if not self.silent:
            print(message, file=sys.stderr, flush=True)


def _clock_text(seconds: float) -> str:
    s = int(seconds)
    return f"{s // 60}:{s % 60:02d}"


class Heartbeat:
    """A daemon thread that prints ``<what>: working (m:ss)`` through ``say`` whenever
    nothing was said for :data:`HEARTBEAT_S` (``beat()`` marks a line said; ``what()``
    names the work under way: the innermost open task, or the command's ``label``).

    The thread holds no lock the work needs and reads only the sink's own fields; a
    compiled call that holds the interpreter for longer delays its line until it returns.
    """

    def __init__(self, say, what, every_s: float | None = None):
        self._say, self._what = say, what
        self._every = HEARTBEAT_S if every_s is None else float(every_s)
        self.t0 = self.last = time.monotonic()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="walkerlab-heartbeat",
                                        daemon=True)
        self._thread.start()

    @classmethod
    def for_command(cls, label: str | None, say, what) -> Heartbeat | None:
        """The heartbeat of the command ``label`` (None: not a command's sink), at
        :func:`heartbeat_s`; None where there is none (no label, or the period is 0)."""
        period = heartbeat_s()
        return cls(say, what, period) if label and period > 0 else None

    def beat(self) -> None:
        """A line was shown now."""
        self.last = time.monotonic()

    def stop(self) -> None:
        """No more lines (the command ended)."""
        self._stop.set()

    def _run(self) -> None:
        while not self._stop.wait(min(1.0, self._every / 4)):
            now = time.monotonic()
            if now - self.last >= self._every:
                self.last = now
                try:
                    self._say(f"{self._what()}: working ({_clock_text(now - self.t0)})")
                except Exception:  # noqa: BLE001 - a closed stream at exit: no more lines
                    return


class LineSink:
    """Plain lines on ``stream`` (stderr) for a log without a terminal: a line per finished
    unit (``<task>: <done>/<total> <info> (<elapsed m:ss>)``) of a task of at most
    :attr:`EVERY_UNIT` units, else one per tenth of it (a task of no count, a spinner on a
    terminal, prints nothing), and the notices as they come."""

    #: tasks of at most this many units get a line per unit (sigmas, controllers, stages)
    EVERY_UNIT = 50

    def __init__(self, stream=None, label: str | None = None):
        self._stream = stream
        #: key -> (description, start [monotonic s], units shown, total)
        self._tasks: dict[int, tuple[str, float, int, int | None]] = {}
        self._label = label
        #: with a label (the CLI's command), a line at least every HEARTBEAT_S
        self.heartbeat = Heartbeat.for_command(label, self._print, self._under_way)

    def _under_way(self) -> str:
        """The innermost task open, or the command."""
        tasks = list(self._tasks.values())
        return tasks[-1][0] if tasks else str(self._label)

    def _print(self, line: str) -> None:
        print(line, file=sys.stderr if self._stream is None else self._stream, flush=True)
        if getattr(self, "heartbeat", None) is not None:
            self.heartbeat.beat()

    @staticmethod
    def _elapsed(t0: float) -> str:
        return _clock_text(time.monotonic() - t0)

    def start(self, key, description, total, completed):
        self._tasks[key] = (description, time.monotonic(), int(completed), total)

    def update(self, key, completed, total, info):
        if key not in self._tasks:
            return
        description, t0, shown, _ = self._tasks[key]
        if completed <= shown:
            return
        if total is not None and total > self.EVERY_UNIT and completed < total \
                and completed * 10 // total == shown * 10 // total:
            return  # a long task: a line per tenth
        self._tasks[key] = (description, t0, completed, total)
        done = f"{completed}/{total}" if total is not None else f"{completed}"
        self._print(f"{description}: {done}" + (f" {info}" if info else "")
                    + f" ({self._elapsed(t0)})")

    def finish(self, key):
        self._tasks.pop(key, None)  # a task of no count (a spinner) has no unit to report

    def note(self, message):
        self._print(message)


class RichSink:
    """``rich.progress`` on stderr (imported when the first task starts)."""

    def __init__(self, label: str | None = None):
        self._progress = None
        self._ids: dict[int, int] = {}
        self._label = label
        # with a label: a line when no task is open and nothing was shown for HEARTBEAT_S
        # (an open task's line is redrawn with its elapsed time by rich itself)
        self.heartbeat = Heartbeat.for_command(label, self._idle_line, lambda: str(label))

    def _idle_line(self, line: str) -> None:
        if self._progress is None:
            print(line, file=sys.stderr, flush=True)

    def _ensure(self):
        if self._progress is None:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                Progress,
                ProgressColumn,
                SpinnerColumn,
                TextColumn,
                TimeElapsedColumn,
            )
            from rich.text import Text

            class Left(ProgressColumn):
                """``done/total  ~m:ss left`` (nothing for a task of unknown length)."""

                def render(self, task):
                    if task.total is None:
                        return Text("")
                    r = task.time_remaining
                    left = ("estimating" if r is None else
                            f"~{int(r) // 60}:{int(r) % 60:02d} left")
                    return Text(f"{int(task.completed)}/{int(task.total)}  {left}")

            self._progress = Progress(
                SpinnerColumn(), TextColumn("{task.description}"), BarColumn(),
                Left(), TimeElapsedColumn(), TextColumn("{task.fields[info]}"),
                console=Console(stderr=True), transient=False, refresh_per_second=4)
            self._progress.start()
        return self._progress

    def start(self, key, description, total, completed):
        p = self._ensure()
        self._ids[key] = p.add_task(description, total=total, completed=completed, info="")

    def update(self, key, completed, total, info):
        if key in self._ids:
            self._progress.update(self._ids[key], completed=completed, total=total, info=info)

    def finish(self, key):
        tid = self._ids.pop(key, None)
        if tid is not None and self._progress is not None:
            self._progress.stop_task(tid)
        if not self._ids and self._progress is not None:
            self._progress.stop()
            self._progress = None

    def note(self, message):
        if self._progress is not None:
            self._progress.console.print(message, markup=False, highlight=False)
        else:
            print(message, file=sys.stderr, flush=True)
        if self.heartbeat is not None:
            self.heartbeat.beat()


_SINK: Sink = QuietSink()
_NEXT = [0]


def current() -> Sink:
    """The installed sink."""
    return _SINK


def install(sink: Sink) -> None:
    """Install ``sink`` for the rest of the process (the CLI, once per command)."""
    global _SINK
    _SINK = sink


def sink_for_terminal(quiet: bool, stream=None, label: str | None = None) -> Sink:
    """The CLI's sink: nothing under ``--quiet``, rich progress when ``stream`` (stderr) is a
    terminal, plain lines otherwise (:class:`LineSink`); with ``label`` (the command, e.g.
    ``"walkerlab fixedpoint"``) a :class:`Heartbeat`: never silent for more than
    :data:`HEARTBEAT_S`."""
    stream = sys.stderr if stream is None else stream
    if quiet:
        return QuietSink(silent=True)
    isatty = getattr(stream, "isatty", None)
    return RichSink(label) if isatty is not None and isatty() else LineSink(label=label)


@contextmanager
def use(sink: Sink) -> Iterator[Sink]:
    """Install ``sink`` for the duration of the block (the previous one is restored)."""
    global _SINK
    old, _SINK = _SINK, sink
    try:
        yield sink
    finally:
        _SINK = old


class Task:
    """Handle of a running task (see :func:`task`)."""

    def __init__(self, sink: Sink, key: int, total: int | None, completed: int):
        self._sink, self.key, self.total, self.completed = sink, key, total, completed

    def update(self, completed: int, total: int | None = None, info: str = "") -> None:
        """Set the count of completed units (and the total, when it became known)."""
        if total is not None:
            self.total = total
        self.completed = max(self.completed, int(completed))
        self._sink.update(self.key, self.completed, self.total, info)

    def advance(self, n: int = 1, info: str = "") -> None:
        """Add ``n`` completed units."""
        self.update(self.completed + n, info=info)


@contextmanager
def task(description: str, total: int | None = None, completed: int = 0) -> Iterator[Task]:
    """Report a unit of long work: ``with task("basin 200x200 cells", 40000) as t: ...``.

    Parameters
    ----------
    description : str
        What is being done (shown next to the bar).
    total : int, optional
        Units of work; None shows a spinner with the elapsed time.
    completed : int
        Units already done (a resumed run).
    """
    sink = _SINK
    _NEXT[0] += 1
    key = _NEXT[0]
    sink.start(key, description, total, int(completed))
    try:
        yield Task(sink, key, total, int(completed))
    finally:
        sink.finish(key)


def note(message: str) -> None:
    """Send a one-line notice to the installed sink."""
    _SINK.note(message)


def machine_note(message: str) -> None:
    """A notice of what this machine is doing once (a walker structure's first code
    generation: it depends on the user cache, not on the scene), sent as :func:`note`
    unless the heartbeat is off (``$WALKERLAB_HEARTBEAT_S`` = 0, as a test suite that reads
    stderr sets it: the lines that depend on the machine and its cache are left out)."""
    if heartbeat_s() > 0:
        _SINK.note(message)
