"""File-system primitives for files a user or another process may have replaced: bounded
regular files only when reading, never through a symbolic link when writing.

The lowest layer of walkerlab's I/O: the scene loader (:mod:`walkerlab.config`), the run
paths and locks (:mod:`walkerlab.io.runpaths`) and the atomic writer
(:mod:`walkerlab.io.artifacts`) all build on it; it imports nothing of walkerlab at import
time.

Temporary files are named ``.<name>.<pid>.<random><suffix>`` (:func:`temp_prefix`), so a
run removes those a killed run left (:func:`remove_stale_temps`: run folders when claimed,
the folder of each atomic write).

Reading:
Every file walkerlab reads from a runs folder or a scene path (the scene YAML, the
``runs/<name>/.scene`` marker, cache entries) goes through :func:`read_regular`: it is
opened without blocking (a FIFO in its place cannot hang the open), must be a regular file
(``S_ISREG`` of the *opened* file: a symlink to ``/dev/zero`` is refused, not read forever)
and no larger than the caller's cap, which is checked before a byte is read.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import time
from pathlib import Path

__all__ = ["NotARegularFile", "RunPathError", "read_regular", "refuse_link", "temp_prefix",
           "remove_stale_temps", "process_alive", "atomic_replace", "atomic_replace_all",
           "watching_interrupts", "note_interrupt", "interrupted", "raise_if_interrupted"]

#: when this process started (wall clock) [s]; a temporary file older than this whose
#: writer is gone is stale
PROCESS_START = time.time()


#: the interrupt watch of the command under way (:func:`watching_interrupts`): how many
#: watches are open, and whether this process was interrupted (Ctrl-C, SIGTERM) during
#: them.  Set by the command's signal handler (:func:`walkerlab.cli.process.
#: terminate_as_interrupt`), so an interrupt a library swallowed (a ``KeyboardInterrupt``
#: raised inside a ctypes callback, as numba's compiler runs them, is printed and dropped)
#: still stops every write; outside a command nothing is recorded
_WATCH = {"depth": 0, "interrupted": False}


@contextlib.contextmanager
def watching_interrupts():
    """Record interrupts (:func:`note_interrupt`) while the block runs (a command), and
    forget them after it.

    Yields
    ------
    None
    """
    _WATCH["depth"] += 1
    try:
        yield
    finally:
        _WATCH["depth"] -= 1
        if _WATCH["depth"] == 0:
            _WATCH["interrupted"] = False


def note_interrupt() -> None:
    """Record that this process was interrupted (the signal handler's first act; nothing
    outside :func:`watching_interrupts`)."""
    if _WATCH["depth"] > 0:
        _WATCH["interrupted"] = True


def interrupted() -> bool:
    """Whether this process was interrupted during the present :func:`watching_interrupts`
    block, even if the ``KeyboardInterrupt`` was swallowed on its way."""
    return _WATCH["interrupted"]


def raise_if_interrupted() -> None:
    """Raise ``KeyboardInterrupt`` if this process was interrupted (:func:`interrupted`).

    Raises
    ------
    KeyboardInterrupt
        An interrupt was received, whether or not its exception reached the caller.
    """
    if _WATCH["interrupted"]:
        raise KeyboardInterrupt


class RunPathError(ValueError):
    """A name or output path is not allowed (one-line message)."""


def refuse_link(path: Path | str) -> Path:
    """``path`` if it is not a symbolic link; walkerlab never writes through one.

    Raises
    ------
    RunPathError
        ``path`` is a symbolic link (one line: remove it and rerun).
    """
    path = Path(path)
    if os.path.islink(path):
        raise RunPathError(f"{path}: is a symbolic link; walkerlab does not write through "
                           "links (remove it and rerun)")
    return path


def temp_prefix(name: str) -> str:
    """Prefix of this process's temporary files for ``name``: ``.<name>.<pid>.`` (a
    rerun after a SIGKILL can then tell them from those of a live writer)."""
    return f".{name}.{os.getpid()}."


def remove_stale_temps(folder: Path | str, name: str | None = None,
                       suffixes: tuple[str, ...] = (".tmp",)) -> int:
    """Remove temporary files left by a killed writer: ``<folder>/.<name>.<pid>.<8
    characters><suffix>`` (:func:`temp_prefix` + ``mkstemp``) whose pid is not alive and
    which are older than this process.  ``name`` None: any name.  Another name, a live
    writer, a newer file, a folder: left alone.  Returns the number removed."""

    try:
        entries = list(os.scandir(folder))
    except OSError:
        return 0
    n = 0
    for e in entries:
        suffix = next((x for x in suffixes if e.name.endswith(x)), None)
        if suffix is None or not e.name.startswith("."):
            continue
        parts = e.name[1:len(e.name) - len(suffix)].rsplit(".", 2)
        if len(parts) != 3 or (name is not None and parts[0] != name) \
                or not parts[1].isdigit() or len(parts[2]) != 8:
            continue
        try:
            st = e.stat(follow_symlinks=False)
            if (stat.S_ISDIR(st.st_mode) or st.st_mtime >= PROCESS_START
                    or process_alive(int(parts[1]))):
                continue
            os.unlink(e.path)
            n += 1
        except OSError:
            continue
    return n


def atomic_replace(path: Path | str, fill, *, mode: int = 0o644, suffix: str = ".tmp",
                   name: str | None = None) -> Path:
    """Write ``path`` atomically: a temporary file in the same folder (``mkstemp``:
    ``O_CREAT | O_EXCL``, never through a symbolic link; named ``.<name>.<pid>.*<suffix>``,
    those of a killed earlier writer removed first) is filled by ``fill(fd, tmp_path)``,
    given ``mode`` and renamed over ``path`` (a crash leaves the old file or none, never a
    truncated one; an interrupt received while it was filled, even one a library swallowed,
    renames nothing: :func:`raise_if_interrupted`).  ``fill`` writes the open descriptor
    ``fd`` (and closes it, e.g. with ``os.fdopen``) or closes it and writes the file by
    name.  On any error the temporary file
    is removed and the error raised.

    Parameters
    ----------
    path : Path or str
        The file to replace; the caller refuses a symbolic link (:func:`refuse_link`).
    fill : callable ``(int, str) -> None``
    mode : int
        Permission bits of the new file.
    suffix : str
        Suffix of the temporary file (writers that choose a format by name need the real
        one).
    name : str, optional
        Name in the temporary file's prefix (default ``path``'s name).

    Returns
    -------
    Path

    Raises
    ------
    OSError
        The folder cannot be written, the disk is full, ... (nothing is left behind).
    KeyboardInterrupt
        The process was interrupted (:func:`interrupted`): nothing is replaced or left.
    """
    import tempfile

    path = Path(path)
    name = path.name if name is None else name
    remove_stale_temps(path.parent, name, (suffix,))
    fd, tmp = tempfile.mkstemp(prefix=temp_prefix(name), suffix=suffix, dir=path.parent)
    try:
        fill(fd, tmp)
        os.chmod(tmp, mode)
        raise_if_interrupted()  # a result computed across an interrupt is not kept
        os.replace(tmp, path)
    except BaseException:
        try:
            os.close(fd)
        except OSError:
            pass
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def atomic_replace_all(items, *, mode: int = 0o644, suffix: str = ".tmp") -> list[Path]:
    """Replace several files together, both or neither (an exported walker and its
    sidecar): every temporary file is filled first (as :func:`atomic_replace`), then each
    is renamed over its file; a rename that fails (a folder in the file's place, a full
    disk) puts back the files already replaced (from hard links to the old ones, made
    before the first rename) and removes the rest.

    Parameters
    ----------
    items : sequence of (Path, callable ``(int, str) -> None``)
        Each file and its ``fill``, as :func:`atomic_replace`'s.
    mode, suffix
        As :func:`atomic_replace`.

    Returns
    -------
    list of Path

    Raises
    ------
    OSError
        A temporary file cannot be filled or a file cannot be replaced: every file is left
        as it was, no temporary file or backup is left behind.
    """
    paths = [Path(p) for p, _ in items]
    temps: list[str] = []
    backups: list[tuple[Path, str | None]] = []  # (file, hard link to its old content)
    done: list[int] = []
    try:
        for path, (_, fill) in zip(paths, items):
            _fill_temp(path, fill, mode, suffix, temps)
        raise_if_interrupted()  # a result computed across an interrupt is not kept
        for path in paths:
            backups.append((path, _backup(path)))
        for i, (path, tmp) in enumerate(zip(paths, temps)):
            os.replace(tmp, path)
            done.append(i)
    except BaseException:
        _put_back(done, backups, temps)
        raise
    for _, old in backups:
        if old is not None:
            Path(old).unlink(missing_ok=True)
    return paths


def _fill_temp(path: Path, fill, mode: int, suffix: str, temps: list) -> None:
    """Fill a new temporary file beside ``path`` by ``fill(fd, name)`` with ``mode`` (its
    name appended to ``temps`` first, so a failure's clean-up removes it); a folder in
    ``path``'s place is refused before anything is written (:func:`atomic_replace_all`)."""
    import tempfile

    if path.is_dir():  # refused before anything is written
        raise IsADirectoryError(21, "a folder stands in the file's place", str(path))
    remove_stale_temps(path.parent, path.name, (suffix, ".bak"))
    fd, tmp = tempfile.mkstemp(prefix=temp_prefix(path.name), suffix=suffix,
                               dir=path.parent)
    temps.append(tmp)
    try:
        fill(fd, tmp)
    except BaseException:
        try:
            os.close(fd)
        except OSError:
            pass
        raise
    os.chmod(tmp, mode)


def _backup(path: Path) -> str | None:
    """A hard link (where the file system has none: a copy) to ``path``'s old content
    beside it, or None when there is no file (:func:`atomic_replace_all`)."""
    import tempfile

    old = None
    if os.path.lexists(path):
        _, old = tempfile.mkstemp(prefix=temp_prefix(path.name), suffix=".bak",
                                  dir=path.parent)
        os.unlink(old)
        try:
            os.link(path, old, follow_symlinks=False)
        except OSError as exc:  # a file system without hard links: a copy
            if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EXDEV,
                                 errno.EMLINK):
                raise
            import shutil

            shutil.copy2(path, old)
    return old


def _put_back(done: list, backups: list, temps: list) -> None:
    """Undo a failed :func:`atomic_replace_all`: the replaced files (indices ``done``) from
    their ``backups`` (a file that was not there removed), then every temporary file and
    backup removed."""
    for i in reversed(done):  # put back what was replaced
        path, old = backups[i]
        try:
            if old is None:
                path.unlink(missing_ok=True)
            else:
                os.replace(old, path)
        except OSError:
            pass
    for tmp in temps:
        Path(tmp).unlink(missing_ok=True)
    for _, old in backups:
        if old is not None:
            Path(old).unlink(missing_ok=True)


def process_alive(pid: int) -> bool:
    """True while process ``pid`` exists and is not a zombie (Linux: /proc state 'Z')."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return True


class NotARegularFile(ValueError):
    """The path is a device, FIFO, socket or directory, or larger than its cap (one line)."""


def read_regular(path: str | Path, max_bytes: int, what: str = "file",
                 follow_links: bool = True, check=None) -> bytes:
    """Contents of a regular file of at most ``max_bytes`` bytes.

    Parameters
    ----------
    path : str or Path
    max_bytes : int
        Largest accepted size [bytes].
    what : str
        What the file is, for the message (``"scene file"``).
    follow_links : bool
        False: a symbolic link at ``path`` is refused (``O_NOFOLLOW``: an ``OSError``).
    check : callable, optional
        ``check(os.stat_result) -> bool`` on the opened file; False refuses it
        (:class:`NotARegularFile`), e.g. a cache file that is not the user's own.

    Returns
    -------
    bytes

    Raises
    ------
    FileNotFoundError
        The path does not exist.
    NotARegularFile
        Not a regular file (FIFO, device, directory, socket), or larger than ``max_bytes``;
        the message names the path.
    OSError
        Other errors of ``open``/``read`` (permissions).
    """
    path = Path(path)
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0)
    if not follow_links:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    fd = os.open(path, flags)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = ("a directory" if stat.S_ISDIR(st.st_mode) else
                    "a FIFO" if stat.S_ISFIFO(st.st_mode) else
                    "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else
                    "not a regular file")
            raise NotARegularFile(f"{path}: {what} is {kind}, not a regular file")
        if check is not None and not check(st):
            raise NotARegularFile(f"{path}: {what} is not trusted (owner or mode)")
        if st.st_size > max_bytes:
            raise NotARegularFile(f"{path}: {what} is {st.st_size:,} bytes; at most "
                                  f"{max_bytes:,} are read")
        chunks, n = [], 0
        while True:  # the file may grow after fstat: never read past the cap
            b = os.read(fd, min(1 << 20, max_bytes + 1 - n))
            if not b:
                break
            chunks.append(b)
            n += len(b)
            if n > max_bytes:
                raise NotARegularFile(f"{path}: {what} is larger than {max_bytes:,} bytes")
        return b"".join(chunks)
    finally:
        os.close(fd)
