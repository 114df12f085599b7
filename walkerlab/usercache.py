"""The per-user cache: generated model code and numba's compiled machine code.

What the cache trusts
---------------------
walkerlab executes generated model code (:mod:`walkerlab.models.cache`) and lets numba load
machine code it compiled earlier.  Both live in one folder per user, never in a runs folder
(runs folders are shared and unpacked from others; nothing in them is ever executed):

- ``$WALKERLAB_CACHE_DIR`` if set, else the platform's user cache folder:
  ``$XDG_CACHE_HOME/walkerlab`` (``~/.cache/walkerlab`` when unset) on Linux,
  ``~/Library/Caches/walkerlab`` on macOS, ``%LOCALAPPDATA%\\walkerlab`` on Windows;
- sub-folders ``models/`` (generated Python) and ``numba/`` (``NUMBA_CACHE_DIR``), created
  with mode 0700; files are written 0600, atomically (temporary name, then rename);
- a folder or file is used only if it belongs to the current user, is not writable by group
  or others and is not a symbolic link (:func:`private_dir`, :func:`read_private`).  A file
  that fails the check is regenerated, never executed; a folder that fails it is not used
  (generated code then stays in memory).  The trust is that of the user's own files: anyone
  who can write them can already run code as the user.

Importing this module has no side effects; :func:`use_for_numba` sets ``NUMBA_CACHE_DIR``
(the CLI at start, and every module of walkerlab that compiles with ``cache=True`` before it
imports numba), so numba never writes into the installed package.
"""

from __future__ import annotations

import os
import stat
import sys
from pathlib import Path

__all__ = ["ENV", "root", "private_dir", "is_private", "read_private", "write_private",
           "use_for_numba"]

ENV = "WALKERLAB_CACHE_DIR"
NUMBA_ENV = "NUMBA_CACHE_DIR"


def root() -> Path:
    """The user cache folder of walkerlab (see the module docstring); not created here."""
    if os.environ.get(ENV):
        return Path(os.environ[ENV]).expanduser()
    if sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    elif os.name == "nt":  # pragma: no cover
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    else:
        xdg = os.environ.get("XDG_CACHE_HOME", "")
        base = Path(xdg) if os.path.isabs(xdg) else Path.home() / ".cache"
    return base / "walkerlab"


def _private_stat(st: os.stat_result) -> bool:
    if stat.S_ISLNK(st.st_mode):
        return False
    if hasattr(os, "geteuid") and st.st_uid != os.geteuid():
        return False
    return os.name == "nt" or not st.st_mode & 0o022


def is_private(path: Path | str) -> bool:
    """True if ``path`` exists, is not a symbolic link, belongs to this user and is not
    writable by group or others."""
    try:
        return _private_stat(os.lstat(path))
    except OSError:
        return False


def private_dir(name: str) -> Path | None:
    """``<root>/<name>``, created with mode 0700; None when it cannot be created or is not
    private (another owner, writable by group/others, a symbolic link)."""
    d = root() / name
    try:
        d.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        d.mkdir(mode=0o700, exist_ok=True)
    except OSError:
        return None
    return d if is_private(d.parent) and is_private(d) else None


def read_private(path: Path) -> str | None:
    """Text of ``path`` if it is a private regular file in a private folder, else None.

    The checks are made on the open file (``O_NOFOLLOW``, ``fstat``), so the file read is the
    file checked.
    """
    if not is_private(path.parent):
        return None
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        return None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or not _private_stat(st):
            return None
        with os.fdopen(fd, "rb", closefd=False) as fh:
            return fh.read().decode()
    except (OSError, UnicodeDecodeError):
        return None
    finally:
        os.close(fd)


def write_private(path: Path, text: str) -> bool:
    """Write ``path`` atomically with mode 0600; False (and nothing left behind) when the
    folder cannot be written (read-only, disk full, ...)."""
    import tempfile

    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(text.encode())
        os.chmod(tmp, 0o600)
        os.replace(tmp, path)
        return True
    except OSError:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
        return False


def use_for_numba() -> None:
    """Point numba's on-disk cache at ``<root>/numba`` unless ``NUMBA_CACHE_DIR`` is set.

    Call before numba compiles a ``cache=True`` function (numba reads the variable when it is
    imported; if it already is, its configuration is updated too).  Without a private folder
    numba's default applies.
    """
    if os.environ.get(NUMBA_ENV):
        return
    d = private_dir("numba")
    if d is None:
        return
    os.environ[NUMBA_ENV] = str(d)
    cfg = sys.modules.get("numba.core.config")
    if cfg is not None:
        cfg.CACHE_DIR = str(d)
