"""Atomic writing of output files (artifacts, figures, reports, JSON): a temporary file in
the same folder renamed over the target, created exclusively (never through a symbolic
link), mode 0644; a full disk is one line, the old file kept and nothing left behind
(:mod:`walkerlab.io.artifacts`'s layout conventions).  Its names are re-exported by
:mod:`walkerlab.io.artifacts`, where the rest of the code imports them.
"""

from __future__ import annotations

import errno
import os
from collections.abc import Callable
from pathlib import Path

from walkerlab.safefs import atomic_replace_all, refuse_link

__all__ = ["DISK_FULL_ERRNOS", "FILE_MODE", "ArtifactError", "atomic_write",
           "atomic_write_all", "disk_full_error", "is_disk_full"]


class ArtifactError(RuntimeError):
    """An artifact is missing, unreadable, of another stage or of another walkerlab version."""


#: the mode of every output file
FILE_MODE = 0o644


#: errno values that mean "no room": no space, file too large (``ulimit -f``), quota
DISK_FULL_ERRNOS = frozenset(e for e in (getattr(errno, n, None) for n in
                                         ("ENOSPC", "EFBIG", "EDQUOT")) if e is not None)


def is_disk_full(exc: BaseException) -> bool:
    """True for an OSError (or h5py's RuntimeError) that means the disk, the file-size limit
    or the quota is full, also as reported inside an HDF5 error message (``errno = 28``)."""
    if not isinstance(exc, (OSError, RuntimeError)):
        return False
    if getattr(exc, "errno", None) in DISK_FULL_ERRNOS:
        return True
    text = str(exc)
    return any(f"errno = {e}," in text for e in DISK_FULL_ERRNOS) or \
        "No space left on device" in text or "File too large" in text


def disk_full_error(path: Path, exc: OSError,
                    kept: str = "nothing was replaced") -> ArtifactError:
    """The one-line "disk full" error of a write to ``path``; ``kept`` says what is left."""
    why = os.strerror(exc.errno) if exc.errno in DISK_FULL_ERRNOS else "no space left"
    return ArtifactError(f"disk full: cannot write {path} ({why}); {kept} - "
                         "free some space (or raise the file-size limit) and rerun")


def _write_error(path: Path, exc: OSError) -> ArtifactError:
    if is_disk_full(exc):
        return disk_full_error(path, exc)
    return ArtifactError(f"{path}: cannot write ({exc.strerror or exc})")


def atomic_write(path: Path, write: Callable, mode: int = FILE_MODE) -> Path:
    """Write ``path`` atomically: ``write(binary file object)`` fills a temporary file in the
    same folder, which is then renamed over ``path`` (a crash leaves the old file or none,
    never a truncated one).

    The temporary file is created exclusively (``mkstemp``: ``O_CREAT | O_EXCL``, which does
    not follow a symbolic link) as ``.<name>.<pid>.*.tmp``; those of a killed earlier writer
    are removed first (:func:`walkerlab.safefs.remove_stale_temps`); ``path`` itself must not
    be a symbolic link.

    Raises
    ------
    ArtifactError
        The folder cannot be created or written; the disk is full ("disk full", the old file
        is kept and nothing is left behind) (one line).
    walkerlab.io.runpaths.RunPathError
        ``path`` is a symbolic link.
    """
    from walkerlab.safefs import atomic_replace, refuse_link

    path = refuse_link(Path(path))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        os.close(os.open(path.parent, os.O_RDONLY))  # a folder that cannot be opened: below
    except OSError as exc:
        if is_disk_full(exc):
            raise disk_full_error(path, exc) from None
        raise ArtifactError(f"{path.parent}: cannot write there ({exc.strerror})") from None

    def fill(fd, _tmp):
        with os.fdopen(fd, "wb") as fh:
            write(fh)

    try:
        atomic_replace(path, fill, mode=mode)
    except OSError as exc:
        raise _write_error(path, exc) from None
    return path


def atomic_write_all(items) -> list[Path]:
    """Write several files together, both or neither (:func:`walkerlab.safefs.
    atomic_replace_all`): ``items`` is a sequence of ``(path, write)``, ``write(binary file
    object)`` as :func:`atomic_write`'s.

    Raises
    ------
    ArtifactError
        A folder cannot be written, a folder stands in a file's place, the disk is full:
        one line; every file is left as it was.
    walkerlab.io.runpaths.RunPathError
        A path is a symbolic link.
    """
    paths = [refuse_link(Path(p)) for p, _ in items]
    for path in paths:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            os.close(os.open(path.parent, os.O_RDONLY))
        except OSError as exc:
            if is_disk_full(exc):
                raise disk_full_error(path, exc) from None
            raise ArtifactError(f"{path.parent}: cannot write there ({exc.strerror})") \
                from None

    def filler(write):
        def fill(fd, _tmp):
            with os.fdopen(fd, "wb") as fh:
                write(fh)
        return fill

    try:
        return atomic_replace_all([(p, filler(w)) for p, (_, w) in zip(paths, items)],
                                  mode=FILE_MODE)
    except OSError as exc:
        where = Path(exc.filename) if exc.filename else paths[0]
        names = " and ".join(p.name for p in paths)
        kept = (f"nothing was replaced ({names} kept as "
                f"{'it was' if len(paths) == 1 else 'they were'})")
        temporary = where.name.startswith(".") and where.name.endswith(".tmp")
        if is_disk_full(exc):
            raise disk_full_error(where.parent if temporary else where, exc, kept) from None
        if temporary:  # our own temporary name: the folder is at fault, name it
            raise ArtifactError(f"{where.parent}: cannot write there ({exc.strerror or exc}); "
                                f"{kept}") from None
        raise ArtifactError(f"{where}: cannot write ({exc.strerror or exc}); {kept}") from None
