"""One HDF5 file per stage.

Layout conventions
------------------
- Root attributes: ``stage``, ``walkerlab_version``, ``scene_name``, ``scene_json`` (the
  resolved scene), ``input_hash`` (content hash of config sections, upstream artifacts and
  code), ``created_utc``, ``wall_time_s`` (compute part of the stage).
- Every dataset has ``unit`` and ``description`` attributes; time series are 1-D along
  ``time``; state is addressed by *name* (``samples/angle/leg1``), never by row number.
- Files are written to a temporary name in the same folder and renamed, so a crash never
  leaves a half-written artifact and never overwrites a good one
  (:func:`~walkerlab.io.atomic_files.atomic_write`, for artifacts, figures, reports and
  JSON).  An artifact is built in memory and written as one
  image: a full disk is the one-line "disk full" error, the old artifact kept and nothing
  left behind.  Nothing is written through a symbolic link (the temporary file is created
  exclusively; a link in place of the target is a one-line error).  Every output file is
  mode 0644.
- ``content_hash`` (root attribute): SHA-256 over every dataset and attribute of the file
  that holds a *result*: run-dependent records are left out, i.e. the
  root attributes in :data:`VOLATILE_ATTRS` (``content_hash``, ``created_utc``,
  ``wall_time_s``, ``workers``, ``scheduler``, ``hostname``) and every dataset or attribute
  whose own name is in :data:`VOLATILE_NAMES` (wall times such as ``stats/wall_time``,
  ``summary/wall_time_s`` or a sweep's ``points/wall_time_s``, and ``cells_computed``), so
  a bit-identical recomputation keeps its hash and nothing downstream is recomputed.
  Timings that *are* the result (the work-precision study's ``time``) are hashed.
  A stage reuses its artifact only if the stored hash still matches the content, and the
  cache key of a downstream stage includes its upstream artifacts' *recomputed* content
  hashes, so an artifact edited by hand (h5py) is detected, never trusted.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import inspect
import itertools
import os
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import lru_cache, wraps
from pathlib import Path

import h5py
import numpy as np

import walkerlab
from walkerlab.io import netcdf
from walkerlab.io.atomic_files import (  # noqa: F401  (re-exported: imported from here)
    DISK_FULL_ERRNOS,
    FILE_MODE,
    ArtifactError,
    atomic_write,
    atomic_write_all,
    disk_full_error,
    is_disk_full,
)
from walkerlab.units import for_scene, relabel_artifact
from walkerlab.usercache import private_dir, read_private, write_private

#: what h5py raises reading a file that opens but is damaged inside (HDF5's error stack
#: surfaces as OSError, RuntimeError such as "Iteration operator failed", KeyError or
#: ValueError): such an artifact counts as damaged, never as a result
READ_ERRORS = (OSError, RuntimeError, KeyError, ValueError)


def raised_by_hdf5(exc: BaseException) -> bool:
    """Whether ``exc`` was raised inside h5py (its innermost frame is h5py's: HDF5 failed to
    read the file), not by the code reading the values."""
    tb = exc.__traceback__
    if tb is None:
        return False
    while tb.tb_next is not None:
        tb = tb.tb_next
    return "h5py" in Path(tb.tb_frame.f_code.co_filename).parts


def damaged_error(path: Path, exc: BaseException) -> ArtifactError:
    """The one-line error of an artifact that opens but whose content HDF5 cannot read."""
    why = " ".join(str(exc).split()) or type(exc).__name__
    return ArtifactError(f"{path}: damaged (HDF5 cannot read it: {why}); rerun its stage "
                         "with --force (or delete it and rerun)")


#: root attributes that record the run, not its result (not hashed)
VOLATILE_ATTRS = frozenset({"content_hash", "created_utc", "wall_time_s", "workers",
                            "scheduler", "hostname"})
#: dataset / attribute names (last path component) that record timings or how much this
#: run computed (resumed runs), not results (not hashed)
VOLATILE_NAMES = frozenset({"wall_time", "wall_time_s", "integration_wall_time_s",
                            "cells_computed"})


# HDF5 dimension-scale bookkeeping (netCDF-4 conventions): object references whose printed
# form depends on the open file handle, not on the content; the scales themselves are hashed.
_REFERENCE_ATTRS = frozenset({"DIMENSION_LIST", "REFERENCE_LIST"})


def _hash_value(h, v) -> None:
    if isinstance(v, h5py.Empty):
        h.update(b"<empty>")
        return
    a = np.asarray(v)
    if a.dtype.kind in "OSU":
        h.update(repr([x.decode() if isinstance(x, bytes) else x
                       for x in np.ravel(a).tolist()]).encode())
        h.update(repr(a.shape).encode())
    else:
        h.update(a.dtype.str.encode() + repr(a.shape).encode())
        h.update(np.ascontiguousarray(a).tobytes())


#: h5py's variable-length UTF-8 string: how walkerlab stores a text attribute
_VLEN_STR = h5py.string_dtype()


@lru_cache(maxsize=1)
def _vlen_str_type():
    """The HDF5 memory type h5py reads a variable-length string attribute with."""
    return h5py.h5t.py_create(_VLEN_STR)


def _attributes(oid) -> list:
    """``(name, low-level attribute)`` of the object ``oid`` (an h5py ObjectID), sorted by
    name as ``sorted(obj.attrs)``; opened by index (no name lookup each)."""
    out = []
    for i in range(h5py.h5a.get_num_attrs(oid)):
        attr = h5py.h5a.open(oid, index=i, index_type=h5py.h5.INDEX_NAME,
                             order=h5py.h5.ITER_INC)
        out.append((attr.name.decode("utf-8", "surrogateescape"), attr))
    out.sort(key=lambda item: item[0])
    return out


def _attr_value(obj, key: str, attr):
    """``obj.attrs[key]`` as h5py reads it (``attr``: that attribute, opened); a scalar
    variable-length string (most of an artifact's attributes: units, descriptions) read
    through h5py's low-level interface, as the same ``str`` at a fraction of the high-level
    reader's cost (which converts the attribute's HDF5 type to a numpy dtype and back)."""
    tid = attr.get_type()
    if (tid.get_class() == h5py.h5t.STRING and tid.is_variable_str()
            and attr.get_space().get_simple_extent_type() == h5py.h5s.SCALAR):
        out = np.zeros((), dtype=_VLEN_STR)  # one element: the dataspace is scalar
        attr.read(out, mtype=_vlen_str_type())
        value = out[()]
        # h5py's high-level reader decodes every variable-length string this way
        return value.decode("utf-8", "surrogateescape") if isinstance(value, bytes) else value
    return obj().attrs[key]


def content_hash_of(f: h5py.File) -> str:
    """SHA-256 of an open file's datasets and attributes (volatile root attributes excluded).

    What is hashed, in order: each root attribute ``@/<name>`` and its value (sorted by name),
    then each object ``/<path>`` (sorted by path): a dataset's value, then its attributes
    ``@<name>`` and values; the objects are opened through h5py's low-level interface, a
    high-level object only where a value is read with it (a dataset, an attribute other
    than a scalar text)."""
    h = hashlib.sha256()
    names: list[str] = []
    f.visit(names.append)
    for key, attr in _attributes(f.id):
        if key not in VOLATILE_ATTRS:
            h.update(f"@/{key}".encode())
            _hash_value(h, _attr_value(lambda: f, key, attr))
    for name in sorted(names):
        if name.rsplit("/", 1)[-1] in VOLATILE_NAMES:
            continue
        oid = h5py.h5o.open(f.id, name.encode())
        kind = h5py.h5i.get_type(oid)
        dataset = kind == h5py.h5i.DATASET
        held: list = []

        def obj(oid=oid, kind=kind, name=name, held=held):  # the high-level object, made
            if not held:  # once, when needed
                held.append(h5py.Dataset(oid) if kind == h5py.h5i.DATASET else
                            h5py.Group(oid) if kind == h5py.h5i.GROUP else f[name])
            return held[0]

        h.update(f"/{name}".encode())
        if dataset:
            _hash_value(h, obj()[()])
        for key, attr in _attributes(oid):
            if key in _REFERENCE_ATTRS or key in VOLATILE_NAMES:
                continue
            h.update(f"@{key}".encode())
            _hash_value(h, _attr_value(obj, key, attr))
    return h.hexdigest()


# Recomputed content hashes, keyed by the file's identity and modification stamp (path,
# inode, size, modification and status-change times [ns]): a report checks the same
# upstream files several times, and every command checks the artifacts it reads (a
# contact run its fixedpoint.h5).  Any rewrite or edit of a file changes its stamp - the
# status-change time is set by the kernel on every change and cannot be set back - so it
# is hashed again.  Kept per process and across processes in the private user cache
# (``hashes/``, one small JSON file per artifact path: :func:`_disk_memo`).
_HASH_MEMO: dict[tuple, str] = {}
#: a file changed less than this long ago [ns] is always hashed: a second edit within the
#: file system's time-stamp resolution could keep the same stamp
RECENT_NS = 2_000_000_000
#: most entries kept in the user cache's ``hashes/`` (one a distinct artifact path; a test
#: suite or a sweep writes thousands of temporary ones): past it the oldest half goes
MAX_HASH_ENTRIES = 4096


def _stamp(path: Path) -> tuple:
    st = os.stat(path)
    return (os.path.realpath(path), st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)


@lru_cache(maxsize=1)
def _hash_scheme() -> str:
    """What a remembered hash is valid for: this module's source (the hashing code) and the
    walkerlab and h5py versions (how values are read)."""
    try:
        h = hashlib.sha256(Path(__file__).read_bytes())
    except OSError:  # no source file (a frozen or zipped install): never trust a memo
        h = hashlib.sha256(os.urandom(16))
    h.update(f"{walkerlab.__version__} {h5py.__version__}".encode())
    return h.hexdigest()[:32]


def _disk_memo(key: tuple, value: str | None = None) -> str | None:
    """The content hash remembered for the stamp ``key`` in the private user cache (None: not
    remembered, another stamp, no usable cache); with ``value``: remember it (if the cache
    can be written) and return it."""
    import json

    d = private_dir("hashes", writable=value is not None)
    if d is None:
        return value
    entry = d / f"{hashlib.sha256(os.fsencode(key[0])).hexdigest()[:32]}.json"
    stamp = [list(key), _hash_scheme()]
    if value is not None:
        if write_private(entry, json.dumps({"stamp": stamp, "content_hash": value})):
            _prune(d, MAX_HASH_ENTRIES)
        return value
    try:
        got = json.loads(read_private(entry) or "null")
    except ValueError:  # damaged: a miss (rewritten after hashing)
        return None
    if isinstance(got, dict) and got.get("stamp") == stamp \
            and isinstance(got.get("content_hash"), str):
        return got["content_hash"]
    return None


def _prune(folder: Path, keep: int) -> int:
    """Remove the oldest (by modification time) ``*.json`` entries of ``folder`` down to
    ``keep // 2`` when it holds more than ``keep``; returns how many went.  A remembered
    hash is only a shortcut: a removed one is recomputed when next asked."""
    try:
        with os.scandir(folder) as it:
            entries = [e for e in it if e.name.endswith(".json")]
        if len(entries) <= keep:
            return 0
        stamped = []
        for e in entries:
            try:
                stamped.append((e.stat(follow_symlinks=False).st_mtime_ns, e.path))
            except OSError:  # gone meanwhile (another process pruning)
                continue
        stamped.sort()
        gone = 0
        for _t, p in stamped[:len(stamped) - keep // 2]:
            try:
                os.unlink(p)
                gone += 1
            except OSError:
                pass
        return gone
    except OSError:
        return 0


def _content_hash_memo(path: Path, f: h5py.File) -> str:
    key = _stamp(path)
    if time.time_ns() - max(key[3], key[4]) < RECENT_NS:
        # changed in the last 2 s: a second edit could keep the same coarse time stamp
        return content_hash_of(f)
    if key not in _HASH_MEMO:
        _HASH_MEMO[key] = _disk_memo(key) or _disk_memo(key, content_hash_of(f))
    return _HASH_MEMO[key]


def content_hash(path: Path) -> str | None:
    """Recomputed content hash of an artifact, or None when it is absent or unreadable."""
    try:
        with h5py.File(path, "r") as f:
            return _content_hash_memo(Path(path), f)
    except READ_ERRORS:  # absent, truncated, or damaged inside
        return None


def require_unedited(path: Path) -> Path:
    """``path`` if its content still matches the content hash stored when it was written.

    Raises
    ------
    ArtifactError
        It was changed afterwards (one line naming it and the command that rewrites it):
        figures and reports are drawn only from what a stage wrote.
    """
    if not stored_content_hash_matches(path):
        stage = Path(path).stem.replace("_", "-")
        raise ArtifactError(f"{path}: changed after it was written (its content no longer "
                            f"matches its stored content hash); figures are drawn only from "
                            f"what a stage wrote: rerun 'walkerlab {stage} --force' (or "
                            "'walkerlab report')")
    return path


def stored_content_hash_matches(path: Path) -> bool:
    """True when the artifact's content equals the content hash stored when it was written
    (False: changed afterwards - edited by hand or with h5py - or unreadable)."""
    try:
        with h5py.File(path, "r") as f:
            stored = f.attrs.get("content_hash")
            return stored is not None and str(stored) == _content_hash_memo(Path(path), f)
    except READ_ERRORS:  # absent, truncated, or damaged inside
        return False


def verified_hash(path: Path) -> str | None:
    """``input_hash`` of an artifact whose content still matches its stored content hash.

    None when the file is absent, unreadable, of another walkerlab version, or was modified
    after it was written (edited with h5py, truncated, damaged inside: any dataset or
    attribute HDF5 cannot read, :data:`READ_ERRORS`).
    """
    try:
        with h5py.File(path, "r") as f:
            if f.attrs.get("walkerlab_version") != walkerlab.__version__:
                return None
            stored = f.attrs.get("content_hash")
            if stored is None or str(stored) != _content_hash_memo(Path(path), f):
                return None
            return str(f.attrs.get("input_hash"))
    except READ_ERRORS:  # absent, truncated, or damaged inside (a recompute replaces it)
        return None


@lru_cache(maxsize=1)
def code_hash() -> str:
    """SHA-256 over the package's Python sources (a code change invalidates cached stages)."""
    root = Path(walkerlab.__file__).parent
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py")):
        h.update(str(f.relative_to(root)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def put(group: h5py.Group, name: str, data, unit: str = "", description: str = "",
        dims: tuple[str | None, ...] | None = None, **attrs) -> h5py.Dataset:
    """Create dataset ``name`` (intermediate groups allowed) with unit and description.

    Strings and lists of strings are stored as UTF-8 variable-length strings.  ``dims``
    names the dimension of each axis (netCDF-4 dimension scales, see
    :mod:`walkerlab.io.netcdf`); ``units`` and ``long_name`` are added for netCDF readers.
    """
    if isinstance(data, str) or (isinstance(data, (list, tuple)) and data
                                 and isinstance(data[0], str)):
        data = np.asarray(data, dtype=h5py.string_dtype())
    ds = group.create_dataset(name, data=data)
    netcdf.set_attrs(ds, {"unit": unit, "description": description,
                          "units": netcdf.cf_units(unit),
                          "long_name": description or name.rsplit("/", 1)[-1], **attrs})
    if dims is not None:
        netcdf.attach(ds, dims)
    return ds


def read_named(group: h5py.Group, name: str):
    """Read a dataset as numpy (or str for string scalars/arrays)."""
    ds = group[name]
    val = ds[()]
    if isinstance(val, bytes):
        return val.decode()
    if isinstance(val, np.ndarray) and val.dtype.kind == "O":
        return [v.decode() if isinstance(v, bytes) else v for v in val.tolist()]
    return val


_MEMORY_FILES = itertools.count()  # unique names of in-memory HDF5 files (core driver)


def write_artifact(path: Path, stage: str, scene, input_hash: str,
                   writer: Callable[[h5py.File], None], wall_time_s: float,
                   extra_attrs: dict | None = None) -> Path:
    """Write an artifact atomically.

    Parameters
    ----------
    path : Path
        Final file name (e.g. ``runs/paper/fixedpoint.h5``).
    stage : str
        Stage name stored in the file.
    scene : walkerlab.config.Scene
        Resolved scene, stored as JSON.
    input_hash : str
        Content hash deciding whether the stage can be skipped next time.
    writer : callable(h5py.File)
        Fills the file's contents.
    wall_time_s : float
        Compute wall time of the stage [s].

    Raises
    ------
    ArtifactError
        The folder cannot be created or written, or the disk is full (one line; the old
        artifact is kept, nothing is left behind).
    walkerlab.io.runpaths.RunPathError
        ``path`` is a symbolic link.
    """
    # built in memory (HDF5 core driver) and written as one image by atomic_write: HDF5 never
    # writes the disk itself, so a full disk is one OSError with its errno (no HDF5 error
    # stack, no half-closed file), and the file written is atomic_write's exclusive temporary
    f = h5py.File(f"<memory {os.getpid()}.{next(_MEMORY_FILES)}: {Path(path).name}>", "w",
                  driver="core", backing_store=False)
    try:
        f.attrs["stage"] = stage
        f.attrs["walkerlab_version"] = walkerlab.__version__
        f.attrs["scene_name"] = scene.name or ""
        f.attrs["scene_json"] = scene.model_dump_json()
        f.attrs["input_hash"] = input_hash
        f.attrs["created_utc"] = _dt.datetime.now(_dt.UTC).isoformat()
        f.attrs["wall_time_s"] = float(wall_time_s)
        for k, v in (extra_attrs or {}).items():
            f.attrs[k] = v
        writer(f)

        relabel_artifact(f, for_scene(scene))  # unit labels follow the scene's system
        netcdf.finish(f)
        f.attrs["content_hash"] = content_hash_of(f)
        f.flush()
        image = f.id.get_file_image()
    finally:
        f.close()
    return atomic_write(Path(path), lambda fh: fh.write(image))


@contextmanager
def open_artifact(path: Path, stage: str | None = None,
                  check_version: bool = True) -> Iterator[h5py.File]:
    """Open an artifact read-only after checking it is complete and of the expected kind.

    Raises
    ------
    ArtifactError
        Missing file, not a readable HDF5 file (e.g. truncated), another stage's file, a
        file written by another walkerlab version, or a dataset or attribute HDF5 cannot
        read while the body of the ``with`` reads it (a file damaged inside; h5py's
        OSError, RuntimeError or ValueError) (one line naming the file).
    """
    path = Path(path)
    if not path.is_file():
        if path.is_dir():
            raise ArtifactError(f"{path}: is a directory, not an artifact")
        if path.exists():  # a FIFO, socket or device: opening it could block or read forever
            raise ArtifactError(f"{path}: not a regular file; give an HDF5 artifact")
        raise ArtifactError(f"{path}: artifact not found (run its stage first)")
    try:
        f = h5py.File(path, "r")
    except (OSError, RuntimeError):
        raise ArtifactError(f"{path}: not a readable HDF5 artifact (truncated or damaged); "
                            "delete it and rerun its stage") from None
    try:
        try:
            got = f.attrs.get("stage")
            ver = f.attrs.get("walkerlab_version")
        except READ_ERRORS as exc:
            raise damaged_error(path, exc) from None
        if stage is not None and got != stage:
            raise ArtifactError(f"{path}: expected a '{stage}' artifact, found '{got}'")
        if check_version and ver != walkerlab.__version__:
            raise ArtifactError(f"{path}: written by walkerlab {ver}, this is "
                                f"{walkerlab.__version__}; rerun the stage to refresh it")
        try:
            yield f
        except KeyError as exc:  # a dataset or attribute the reader needs is missing
            what = str(exc.args[0]) if exc.args else "?"
            if "(" in what and what.endswith(")"):  # h5py: "Unable to ... (object 'x' ...)"
                what = what[what.rindex("(") + 1:-1]
            raise ArtifactError(f"{path}: {what} (the artifact is damaged or lacks what "
                                "this reader needs); rerun its stage with --force") from None
        except (OSError, RuntimeError, ValueError) as exc:
            if isinstance(exc, ArtifactError) or not raised_by_hdf5(exc):
                raise  # the reader's own error, not the file's
            raise damaged_error(path, exc) from None
    finally:
        f.close()



#: the ``Raises`` section :func:`artifact_loader` gives every loader it makes
_LOADER_RAISES = """

    Raises
    ------
    walkerlab.io.artifacts.ArtifactError
        Missing or unreadable (truncated or damaged), written by another walkerlab version,
        lacking a dataset or attribute this reader needs, or not {stage} (one line
        naming the file; as :func:`walkerlab.io.artifacts.open_artifact`).
"""


def artifact_loader(stage: str | None) -> Callable:
    """Make a schema's reading of an open artifact into its loader: the one place a loader
    opens its file, checks its stage and version and turns a missing dataset or a damaged
    file into one line (:func:`open_artifact`), its ``Raises`` written once.

    Decorates ``read(f, path, *args, **kwargs)`` (``f``: the open :class:`h5py.File`;
    ``path``: its :class:`~pathlib.Path`); the loader takes ``(path, *args, **kwargs)``,
    keeps ``read``'s name and docstring and adds the ``Raises`` section.

    Parameters
    ----------
    stage : str or None
        The artifact's ``stage`` attribute (None: any stage's).
    """
    what = "an HDF5 artifact" if stage is None else f"a ``{stage}`` artifact"

    def make(read: Callable) -> Callable:
        @wraps(read)
        def load(path, *args, **kwargs):
            path = Path(path)
            with open_artifact(path, stage) as f:
                return read(f, path, *args, **kwargs)

        load.__doc__ = (read.__doc__ or "").rstrip() + _LOADER_RAISES.format(stage=what)
        sig = inspect.signature(read)
        params = list(sig.parameters.values())
        load.__signature__ = sig.replace(parameters=params[1:])  # help(): (path, ...)
        return load

    return make

def stored_hash(path: Path) -> str | None:
    """``input_hash`` of an artifact, or None when it is absent or unreadable."""
    try:
        with h5py.File(path, "r") as f:
            if f.attrs.get("walkerlab_version") != walkerlab.__version__:
                return None
            return str(f.attrs.get("input_hash"))
    except READ_ERRORS:
        return None


def root_attrs(path: Path, *names: str) -> dict:
    """The root attributes ``names`` of an artifact that has them (strings decoded), without
    any check of version or content: what an out-of-date artifact was written with.  {} when
    the file is absent or unreadable."""
    try:
        with h5py.File(path, "r") as f:
            out = {n: f.attrs[n] for n in names if n in f.attrs}
    except READ_ERRORS:
        return {}
    return {k: v.decode() if isinstance(v, bytes) else v for k, v in out.items()}
