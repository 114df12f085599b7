"""The per-user cache: generated model code and numba's compiled machine code.

What the cache trusts
---------------------
walkerlab executes generated model code (:mod:`walkerlab.codegen.cache`) and lets numba load
machine code it compiled earlier.  Both live in one folder per user, never in a runs folder
(runs folders are shared and unpacked from others; nothing in them is ever executed):

- ``$WALKERLAB_CACHE_DIR`` if set, else the platform's user cache folder:
  ``$XDG_CACHE_HOME/walkerlab`` (``~/.cache/walkerlab`` when unset) on Linux,
  ``~/Library/Caches/walkerlab`` on macOS, ``%LOCALAPPDATA%\\walkerlab`` on Windows;
- sub-folders ``models/`` (generated Python), ``numba/<key>/`` (``NUMBA_CACHE_DIR``, keyed on
  the numba modules' sources: :func:`use_for_numba`), ``drop/``
  (drop tests of contact laws, JSON numbers: :mod:`walkerlab.analysis.contact.drop`) and
  ``hashes/`` (recomputed content hashes of artifacts by file stamp, JSON: never trusted
  for a file changed since, :mod:`walkerlab.io.artifacts`; at most 4096 entries, the
  oldest half removed past that), created
  with mode 0700; files are written 0600, atomically (temporary name, then rename);
- a folder or file is used only if it belongs to the current user, is not writable by group
  or others and is not a symbolic link (:func:`private_dir`, :func:`read_private`).  A file
  that fails the check is regenerated, never executed; a folder that fails it is not used.
  The trust is that of the user's own files: anyone who can write them can already run code
  as the user;
- every cache read is bounded and non-blocking (:func:`walkerlab.safefs.read_regular`): a
  FIFO, device or huge file in the cache is a miss, never a hang - numba's own reads of its
  index (``.nbi``) and data (``.nbc``) files included, and a damaged one (garbage, empty,
  truncated) is removed and rebuilt, never an ``UnpicklingError``, and numba's writes leave
  no temporary file when interrupted (SIGTERM, Ctrl-C) (:func:`guard_numba_cache`);
- without a usable folder (read-only, not private, a link) the run uses one private
  temporary folder (:func:`private_tmp`, ``walkerlab_gen_<pid>_*`` in the system temp
  folder, mode 0700), shared with its worker processes and removed when the process that
  made it exits; folders of processes that died (SIGKILL) are removed by the next run.
  numba therefore never writes machine code into the installed package's ``__pycache__``.

Importing this module has no side effects; :func:`use_for_numba` sets ``NUMBA_CACHE_DIR``
(the CLI at start, and every module of walkerlab that compiles with ``cache=True`` before it
imports numba), so numba never writes into the installed package.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import stat
import sys
from pathlib import Path

from walkerlab.safefs import NotARegularFile, atomic_replace, process_alive, read_regular

__all__ = ["ENV", "root", "private_dir", "is_private", "read_private", "write_private",
           "use_for_numba", "private_tmp", "guard_numba_cache", "MAX_CACHE_FILE_BYTES"]

ENV = "WALKERLAB_CACHE_DIR"
NUMBA_ENV = "NUMBA_CACHE_DIR"
#: the private temporary folder of this run, inherited by its worker processes
TMP_ENV = "WALKERLAB_PRIVATE_TMP"
TMP_PREFIX = "walkerlab_gen_"
#: largest cache file read (generated source, numba index or machine code) [bytes]
MAX_CACHE_FILE_BYTES = 256 << 20


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


def private_dir(name: str, writable: bool = False) -> Path | None:
    """``<root>/<name>``, created with mode 0700; None when it cannot be created or is not
    private (another owner, writable by group/others, a symbolic link) or, with
    ``writable``, cannot be written."""
    d = root() / name
    if os.path.islink(d.parent) or os.path.islink(d):
        return None  # nothing is created through a link
    try:
        d.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        d.mkdir(mode=0o700, exist_ok=True)
    except OSError:
        return None
    if not (is_private(d.parent) and is_private(d)):
        return None
    if writable and not os.access(d, os.W_OK | os.X_OK):
        return None
    return d


_tmp: list[Path] = []


def _remove_tmp(path: Path, pid: int) -> None:
    import shutil

    if os.getpid() == pid:  # the process that made it, not a forked child
        shutil.rmtree(path, ignore_errors=True)


def _remove_stale_tmp(base: Path) -> None:
    """Remove ``walkerlab_gen_<pid>_*`` folders of this user whose process is gone."""
    import shutil

    try:
        entries = list(os.scandir(base))
    except OSError:
        return
    for e in entries:
        if not e.name.startswith(TMP_PREFIX):
            continue
        pid = e.name[len(TMP_PREFIX):].split("_", 1)[0]
        try:
            if (not pid.isdigit() or process_alive(int(pid))
                    or not _private_stat(e.stat(follow_symlinks=False))
                    or not e.is_dir(follow_symlinks=False)):
                continue
        except OSError:
            continue
        shutil.rmtree(e.path, ignore_errors=True)


def private_tmp() -> Path:
    """The private temporary folder of this run (mode 0700, ``walkerlab_gen_<pid>_*``).

    Made once per run: a worker process uses its parent's (``$WALKERLAB_PRIVATE_TMP``, if
    private).  Removed at exit of the process that made it; left-overs of killed runs are
    removed here.
    """
    if _tmp:
        return _tmp[0]
    inherited = os.environ.get(TMP_ENV)
    if inherited and os.path.isdir(inherited) and is_private(inherited):
        _tmp.append(Path(inherited))
        return _tmp[0]
    import atexit
    import tempfile

    base = Path(tempfile.gettempdir())
    _remove_stale_tmp(base)
    d = Path(tempfile.mkdtemp(prefix=f"{TMP_PREFIX}{os.getpid()}_", dir=base))
    atexit.register(_remove_tmp, d, os.getpid())
    os.environ[TMP_ENV] = str(d)
    _tmp.append(d)
    return d


def read_private(path: Path) -> str | None:
    """Text of ``path`` if it is a private regular file in a private folder, else None.

    Read by :func:`walkerlab.safefs.read_regular` (non-blocking, bounded by
    :data:`MAX_CACHE_FILE_BYTES`, no link); the checks are made on the open file, so the
    file read is the file checked.  A FIFO or device in its place is a miss, never a hang.
    """

    if not is_private(path.parent):
        return None
    try:
        return read_regular(path, MAX_CACHE_FILE_BYTES, "cache file", follow_links=False,
                            check=_private_stat).decode()
    except (OSError, NotARegularFile, UnicodeDecodeError):
        return None


def write_private(path: Path, text: str, errors: list | None = None) -> bool:
    """Write ``path`` atomically with mode 0600; False (and nothing left behind) when the
    folder cannot be written (read-only, disk full, ...), the OSError appended to
    ``errors`` when given."""

    def fill(fd, _tmp):
        with os.fdopen(fd, "wb") as fh:
            fh.write(text.encode())

    try:
        atomic_replace(path, fill, mode=0o600, name=path.stem)
        return True
    except OSError as exc:
        if errors is not None:
            errors.append(exc)
        return False


def use_for_numba() -> None:
    """Point numba's on-disk cache at ``<root>/numba/<key>`` unless ``NUMBA_CACHE_DIR`` is
    set, and guard numba's cache reads (:func:`guard_numba_cache`).

    ``<key>`` is :func:`numba_sources_key`: numba stamps a cached function with its own
    source file only, so machine code that inlined a kernel of another module would
    outlive that kernel's change (an editable install updated in place, a developer's
    edit) and run the old physics; keyed on the numba modules' sources, any change starts
    a fresh cache.  Key folders not used for a day are removed (:func:`_prune`).

    Call before numba compiles a ``cache=True`` function (numba reads the variable when it is
    imported; if it already is, its configuration is updated too).  Without a private,
    writable folder the run's private temporary folder is used (:func:`private_tmp`), never
    numba's default next to the package's sources.
    """
    guard_numba_cache()
    if os.environ.get(NUMBA_ENV):
        return
    d = private_dir("numba", writable=True)
    if d is not None:
        d = _keyed(d, numba_sources_key())
    if d is None:
        d = private_tmp() / "numba"
        d.mkdir(mode=0o700, exist_ok=True)
    os.environ[NUMBA_ENV] = str(d)
    cfg = sys.modules.get("numba.core.config")
    if cfg is not None:
        cfg.CACHE_DIR = str(d)


@functools.cache
def numba_sources_key() -> str:
    """The first 16 hex digits of the sha256 of walkerlab's modules that name numba (their
    paths in the package and their bytes, in order): the numba cache's folder
    (:func:`use_for_numba`)."""
    pkg = Path(__file__).parent
    h = hashlib.sha256()
    for p in sorted(pkg.rglob("*.py")):
        body = p.read_bytes()
        if b"numba" in body or b"njit" in body:
            h.update(p.relative_to(pkg).as_posix().encode() + b"\0" + body)
    return h.hexdigest()[:16]


def _keyed(d: Path, key: str) -> Path | None:
    """``d / key``, created private (mode 0700) and writable, the other folders of ``d``
    pruned (:func:`_prune`); None where it cannot be (a link, another owner, read-only)."""
    sub = d / key
    if os.path.islink(sub):
        return None
    try:
        sub.mkdir(mode=0o700, exist_ok=True)
    except OSError:
        return None
    if not is_private(sub) or not os.access(sub, os.W_OK | os.X_OK):
        return None
    os.utime(sub)  # in use: its mtime is the day's
    _prune(d, key)
    return sub


def _prune(d: Path, key: str, age_s: float = 86400.0) -> None:
    """Remove the folders of ``d`` other than ``key`` not used for ``age_s`` [s] (other
    versions' numba caches: each key folder's mtime is refreshed by every run using it),
    never through a link; errors are ignored (another process may be at it)."""
    import shutil
    import time

    now = time.time()
    try:
        entries = list(os.scandir(d))
    except OSError:
        return
    for e in entries:
        try:
            if (e.name != key and e.is_dir(follow_symlinks=False)
                    and now - e.stat(follow_symlinks=False).st_mtime > age_s):
                shutil.rmtree(e.path, ignore_errors=True)
        except OSError:
            pass


# ------------------------------------------------------------------ numba's cache reads
_guarded: list[bool] = []


def _discard(path: str) -> None:
    """Remove a damaged or non-regular numba cache entry (it is rebuilt); a folder in its
    place too (the numba folder is private: nobody else put it there)."""
    import shutil

    try:
        if os.path.isdir(path) and not os.path.islink(path):
            shutil.rmtree(path, ignore_errors=True)
        else:
            os.unlink(path)
    except OSError:
        pass


def _load_index(self):
    """``IndexDataCacheFile._load_index``, bounded and non-blocking (a regular file of at
    most :data:`MAX_CACHE_FILE_BYTES`); a damaged index is discarded (a miss)."""
    import io
    import pickle

    try:
        raw = read_regular(self._index_path, MAX_CACHE_FILE_BYTES, "numba cache index",
                           follow_links=False)
    except FileNotFoundError:
        return {}
    except (OSError, NotARegularFile):  # FIFO, device, folder, huge, unreadable
        _discard(self._index_path)
        return {}
    try:
        f = io.BytesIO(raw)
        version = pickle.load(f)
        if version != self._version:
            return {}
        stamp, overloads = pickle.loads(f.read())
        if not isinstance(overloads, dict):
            raise TypeError("index is not a dict")
    except Exception:  # noqa: BLE001 - garbage, empty, truncated: rebuilt
        _discard(self._index_path)
        return {}
    return overloads if stamp == self._source_stamp else {}


def _load_data(self, name):
    """``IndexDataCacheFile._load_data``, bounded; a damaged entry is discarded and read as
    an OSError (numba recompiles)."""
    import pickle

    path = self._data_path(name)
    try:
        raw = read_regular(path, MAX_CACHE_FILE_BYTES, "numba cache data",
                           follow_links=False)
        return pickle.loads(raw)
    except FileNotFoundError:
        raise
    except Exception as exc:  # noqa: BLE001 - a damaged entry is a miss (recompiled)
        _discard(path)
        raise OSError(f"{path}: damaged numba cache file") from exc


@contextlib.contextmanager
def _open_for_write(self, filepath):
    """``IndexDataCacheFile._open_for_write``: numba's own, but an interrupt (SIGTERM of a
    side process, Ctrl-C) removes the temporary file too: nothing half-written stays in
    the cache."""
    import uuid

    tmp = f"{filepath}.tmp.{uuid.uuid4().hex[:16]}"
    try:
        with open(tmp, "wb") as f:
            yield f
        os.replace(tmp, filepath)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _patch_numba_caching(caching) -> None:
    """Make numba's cache reads bounded, non-blocking and tolerant of damage (a miss), and
    its writes leave no temporary file when interrupted."""
    cls = caching.IndexDataCacheFile
    if getattr(cls, "_walkerlab_guarded", False):
        return
    cls._load_index = _load_index
    cls._load_data = _load_data
    cls._open_for_write = _open_for_write
    original = caching.Cache.load_overload

    def load_overload(self, sig, target_context):
        try:
            return original(self, sig, target_context)
        except Exception:  # noqa: BLE001 - machine code that does not rebuild: recompile
            return None

    caching.Cache.load_overload = load_overload
    original_save = caching.Cache.save_overload

    def save_overload(self, sig, data):
        try:
            return original_save(self, sig, data)
        except OSError:  # a cache that cannot be written costs a recompile, not the run
            return None

    caching.Cache.save_overload = save_overload
    cls._walkerlab_guarded = True


class _NumbaCachingHook:
    """Import hook: patches ``numba.core.caching`` as soon as it is imported."""

    def find_spec(self, name, path=None, target=None):
        if name != "numba.core.caching":
            return None
        import importlib.machinery

        spec = importlib.machinery.PathFinder.find_spec(name, path)
        if spec is None or spec.loader is None:
            return None
        exec_module = spec.loader.exec_module

        def exec_and_patch(module):
            exec_module(module)
            _patch_numba_caching(module)

        spec.loader.exec_module = exec_and_patch
        return spec


def guard_numba_cache() -> None:
    """Route numba's cache reads through the bounded, non-blocking reader; a damaged index
    or data file is removed and rebuilt (numba alone fails for good with
    ``UnpicklingError``/``EOFError``).  Patches ``numba.core.caching`` now if it is loaded,
    else when it is imported (numba is not imported here)."""
    if _guarded:
        return
    _guarded.append(True)
    caching = sys.modules.get("numba.core.caching")
    if caching is not None:
        _patch_numba_caching(caching)
    else:
        sys.meta_path.insert(0, _NumbaCachingHook())
