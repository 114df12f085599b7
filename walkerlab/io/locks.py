"""One writer per artifact across processes: :func:`artifact_lock`.

The lock is an ``flock`` on a hidden ``.<name>.lock`` file next to the artifact, which records
the holder's pid and host; the kernel releases it when a process dies, even by SIGKILL, and a
lock kept by a dead holder's descendant is taken over, never waited on.  Lock files are opened
with ``O_NOFOLLOW`` (a symbolic link in their place is a one-line
:class:`~walkerlab.safefs.RunPathError`).  The run paths themselves are built by
:mod:`walkerlab.io.runpaths`, which re-exports :func:`artifact_lock` and :class:`ArtifactBusy`.
"""

from __future__ import annotations

import errno
import os
import stat
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from walkerlab.safefs import RunPathError, process_alive, refuse_link

try:  # POSIX; elsewhere runs are not locked
    import fcntl
except ImportError:  # pragma: no cover
    fcntl = None


class ArtifactBusy(RuntimeError):
    """Another process is writing the same artifact (one-line message)."""


#: polling period while waiting for another writer's lock [s]
LOCK_POLL_S = 0.2


def _open_lock(lock: Path) -> int:
    """Open (create) a lock file without following a symbolic link in its place."""
    try:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            refuse_link(lock)
        raise RunPathError(f"{lock.parent}: cannot write the run folder ({exc.strerror})") \
            from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):  # a FIFO, device, ... in its place
        os.close(fd)
        raise RunPathError(f"{lock}: not a regular file; remove it and rerun")
    return fd


def _same_file(fd: int, lock: Path) -> bool:
    """True while the name ``lock`` still refers to the file open as ``fd``."""
    try:
        a, b = os.fstat(fd), os.lstat(lock)
    except OSError:
        return False
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


def _host() -> str:
    import socket

    return socket.gethostname() or "?"


def _holder(fd: int, local_only: bool = False) -> int | None:
    """The pid recorded in a lock file (``"<pid> <host>"``); with ``local_only``, None
    unless it was recorded on this host (a pid from another machine sharing the folder
    cannot be checked here)."""
    try:
        parts = os.pread(fd, 300, 0).decode(errors="replace").split()
        pid = int(parts[0])
    except (OSError, ValueError, IndexError):
        return None
    if local_only and len(parts) > 1 and parts[1] != _host():
        return None
    return pid


@contextmanager
def _folder_locked(folder: Path) -> Iterator[None]:
    """Serialise lock-file take-overs and claims in ``folder`` (``flock`` on the folder)."""
    try:
        dfd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    except OSError:
        yield
        return
    try:
        fcntl.flock(dfd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(dfd)


def _take_over(fd: int, lock: Path) -> bool:
    """Remove a lock file whose recorded holder process is dead, though its lock is held
    (by a descendant that inherited it).  True when the name was removed (the caller then
    starts over on a new file)."""
    with _folder_locked(lock.parent):
        pid = _holder(fd, local_only=True)
        if pid is None or pid == os.getpid() or process_alive(pid) or not _same_file(fd, lock):
            return False
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            fcntl.flock(fd, fcntl.LOCK_UN)  # released meanwhile: no take-over needed
            return False
        except BlockingIOError:
            pass
        try:
            os.unlink(lock)
        except OSError:
            return False
        return True


@contextmanager
def artifact_lock(path: Path, wait: bool = True,
                  on_wait: Callable[[str], None] | None = None) -> Iterator[None]:
    """Hold an exclusive lock on ``path`` (a hidden ``.<name>.lock`` next to it).

    The lock is an ``flock`` on the lock file, which records the holder's pid and host.
    The kernel releases it when the holder dies; a lock still held although the recorded
    process (of this host) is dead - a descendant kept the file open - is *taken over*: the
    file is removed and a new one locked, never waited on.  The lock file is opened without
    following a symbolic link (a link in its place is a one-line error) and removed again on
    release; a waiter that wins the lock of a removed file starts over on the current one.

    Parameters
    ----------
    path : Path
        The artifact the caller is about to write.
    wait : bool
        Block until the other writer is done (stages: they then find its result up to date)
        or raise at once (sweeps: a second identical sweep must not run).
    on_wait : callable(str), optional
        Told once, in one line, that the caller waits.

    Raises
    ------
    ArtifactBusy
        ``wait=False`` and another (live) process holds the lock.
    RunPathError
        The lock file is a symbolic link or not a regular file, or the folder cannot be
        written.
    """
    path = Path(path)
    if fcntl is None:  # pragma: no cover
        yield
        return
    lock = path.with_name(f".{path.name}.lock")
    told = False
    while True:
        fd = _open_lock(lock)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            if _take_over(fd, lock):
                os.close(fd)
                continue
            holder = _holder(fd)
            os.close(fd)
            msg = (f"{path}: another walkerlab process (pid {holder or '?'}) is writing it")
            if not wait:
                raise ArtifactBusy(f"{msg}; wait for it to finish (or stop it) and rerun") \
                    from None
            if on_wait is not None and not told:
                on_wait(f"{msg}; waiting")
                told = True
            time.sleep(LOCK_POLL_S)
            continue
        except BaseException:
            os.close(fd)
            raise
        with _folder_locked(lock.parent):  # a take-over sees a pid or the file removed
            mine = _same_file(fd, lock)
            if mine:
                os.ftruncate(fd, 0)
                os.pwrite(fd, f"{os.getpid()} {_host()}\n".encode(), 0)
        if not mine:  # removed by its last holder (or taken over): start over
            os.close(fd)
            continue
        break
    try:
        yield
    finally:
        try:
            if _same_file(fd, lock):
                os.unlink(lock)  # while still held: a waiter on this file starts over
        except OSError:
            pass
        os.close(fd)
