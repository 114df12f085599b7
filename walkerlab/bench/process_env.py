"""A timed whole process: its environment, as an installed walkerlab runs
(:func:`installed_env`, :func:`code_env`), and its wall time and the CPU of its whole
process tree, the orphans it leaves included (:func:`timed_run`).

An installed package has its bytecode: pip compiles every module of a wheel at install time,
and an editable install writes it on the first run.  A shell that sets
``PYTHONDONTWRITEBYTECODE`` (some containers and CI images do) makes every walkerlab process
compile each module it imports from source again (measured on ``walkerlab fixedpoint``:
~0.09 s of CPU in a 0.6 s process, ~0.3 s on the main job), a cost no user of an installed
walkerlab pays and the plain-library yardsticks never pay (numpy's and scipy's bytecode was
written when they were installed).  So a benchmark runs walkerlab's processes, and their
yardsticks, with the variable removed; the first (warming) run of a command writes the
bytecode.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import time
from pathlib import Path

__all__ = ["TREE", "cli_command", "code_env", "count_orphans", "installed_env", "reap",
           "timed_run"]

#: the code tree this walkerlab is imported from (the folder holding ``walkerlab/``)
TREE = Path(__file__).resolve().parents[2]


def installed_env(base: dict | None = None, **extra: str) -> dict:
    """A copy of ``base`` (default ``os.environ``) without ``PYTHONDONTWRITEBYTECODE``,
    with ``extra`` variables set (e.g. ``PYTHONPATH``, ``WALKERLAB_CACHE_DIR``)."""
    env = dict(os.environ if base is None else base)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env.update(extra)
    return env


def code_env(code: Path, cache: str | None = None) -> dict:
    """The environment of a process that runs the walkerlab of the code tree ``code`` (the
    folder holding ``walkerlab/``, on ``PYTHONPATH``), as installed (:func:`installed_env`),
    numba's cache left to walkerlab, and with ``cache`` its private user cache
    (``WALKERLAB_CACHE_DIR``)."""
    env = installed_env(PYTHONPATH=str(code))  # with its bytecode
    env.pop("NUMBA_CACHE_DIR", None)  # walkerlab sets it from its user cache
    if cache is not None:
        env["WALKERLAB_CACHE_DIR"] = cache
    return env


def count_orphans() -> None:
    """Become the reaper of this process's orphaned descendants (Linux
    ``PR_SET_CHILD_SUBREAPER``): the worker processes a command leaves to end after it
    (multiprocessing's forkserver and the workers it forked, which the command never waits
    for) are then reaped here (:func:`reap`) and their CPU counted in ``RUSAGE_CHILDREN``
    (without it, a command's side process or pool workers would not count)."""
    if sys.platform.startswith("linux"):
        import ctypes

        try:
            ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER
        except (OSError, AttributeError):  # pragma: no cover - no prctl
            pass


def reap(limit_s: float = 10.0) -> None:
    """Wait (at most ``limit_s`` [s]) for the remaining child processes and reap them."""
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            time.sleep(0.01)


def timed_run(cmd: list[str], env: dict, cwd: Path) -> tuple[float, float, str]:
    """Wall [s], CPU of the process tree [s] (its orphans included: :func:`count_orphans`)
    and stdout of one command ``cmd`` run in ``cwd`` with the environment ``env``.

    Raises
    ------
    RuntimeError
        The command failed (its exit status and the end of its stderr)."""
    count_orphans()
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    reap()
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode:
        raise RuntimeError(f"{' '.join(cmd[:5])}: exit {p.returncode}: {p.stderr[-400:]}")
    return wall, (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime), p.stdout


def cli_command(*args: str) -> list[str]:
    """The command line of ``walkerlab -q ARGS`` in this Python."""
    return [sys.executable, "-m", "walkerlab.cli", "-q", *args]
