"""The store of generated Python modules in the per-user cache: the one way generated code
is written, checked and executed (the rigid model's module, :mod:`walkerlab.codegen.cache`;
the compiled flows, the floating view, the contact kernels, the controllers).

Where: the per-user cache, ``<user cache>/models`` (:mod:`walkerlab.usercache`:
``$WALKERLAB_CACHE_DIR`` or the platform's user cache folder, e.g. ``~/.cache/walkerlab``),
never a runs folder: runs folders are shared, and code in them would run as whoever opens
them.  The folder is created 0700 and files are written 0600; a file is executed only if it
belongs to the current user and is not writable by group or others (else it is regenerated);
without a private folder the code goes to the run's private temporary folder.  Files are
written atomically (temporary name, then ``os.replace``; a failed write - disk full,
read-only - leaves nothing behind); each starts with a sha256 of its body: a truncated or
damaged file is regenerated.  (The header detects damage, not tampering: trust comes from
the file's owner and mode.)  What a file holds and its key (the walker's structure, the
generator's sources) are its writer's; this module knows neither walkers nor sympy.
"""

from __future__ import annotations

import functools
import hashlib
from pathlib import Path

from walkerlab import progress, usercache

#: what each generated module of the cache folder is, by a part of its file name (the first
#: key here that is a part of it: ``<key>_act_<tag>_nb.py`` is an actuated flow, not ``nb``)
WHAT = {"rows": "the batched step kernels", "act": "the actuated compiled flow",
         "vcnb": "the compiled virtual-constraint controller",
         "vc": "the virtual-constraint outputs", "vcflow": "the virtual-constraint flow",
         "vcrhs": "the contact model's virtual-constraint controller",
         "contact": "the contact model's kernels",
         "floating": "the floating-base (contact) view", "nb": "the compiled flow"}
#: the documentation page that says what a first run of a new structure costs
FIRST_RUN_DOC = "docs/user_guide/first_run.md"


def what(filename: str) -> str:
    """What the generated module ``filename`` is, in words (:data:`WHAT`)."""
    parts = filename.rsplit(".", 1)[0].split("_")[1:]
    return next((words for part, words in WHAT.items() if part in parts),
                "a generated module")


def first_time(making: str) -> None:
    """Say, in one notice, that ``making`` of this walker structure is being made: the first
    time on this machine (or after an upgrade), kept in the user cache after."""
    progress.machine_note(f"{making} of this walker structure: first time on this machine (or "
                          "since an upgrade), seconds to a few minutes; kept in the user "
                          f"cache for later runs ({FIRST_RUN_DOC})")


def cache_dir() -> Path | None:
    """The private folder generated model code is read from and written to (created 0700),
    or None when there is none (the code is then kept in memory)."""
    return usercache.private_dir("models")


@functools.cache  # a package's sources do not change within a process
def source_hash(*paths) -> str:
    """sha256 (hex) of the files ``paths`` in order: the part of a generated module's key
    that its generator's sources make, so that editing a generator regenerates its modules."""
    h = hashlib.sha256()
    for p in paths:
        h.update(Path(p).read_bytes())
    return h.hexdigest()


def _digest(body: str) -> str:
    return hashlib.sha256(body.encode()).hexdigest()



def read_source(path: Path) -> str | None:
    """Body of a cache file that may be executed: private (this user's, not writable by
    group/others, no link) and intact (its sha256 header matches), else None."""
    text = usercache.read_private(path)
    if text is None or "\n" not in text:
        return None
    first, body = text.split("\n", 1)
    return body if first == f"# sha256 {_digest(body)}" else None



def write_source(path: Path, body: str, errors: list | None = None) -> bool:
    """Write a cache file (sha256 header + body) atomically, mode 0600; False when the
    folder cannot be written (nothing is left behind; the OSError appended to ``errors``)."""
    return usercache.write_private(path, f"# sha256 {_digest(body)}\n{body}", errors)



_imported: dict[str, object] = {}
#: generated modules whose source this process made (numba compiles them at their import)
_generated_now: set[str] = set()


def generated_source(filename: str, build) -> tuple[str, Path]:
    """The checked text of the generated module ``filename`` of the cache folder and the
    file it is in: read (:func:`read_source`), or on a miss, a damaged or an untrusted file
    made by ``build() -> str`` and written atomically (mode 0600); without a private cache
    folder, or one that cannot be written, written to the run's private temporary folder
    (:func:`walkerlab.usercache.private_tmp`, removed at exit).

    Raises
    ------
    OSError
        Neither folder can be written (its errno kept: a full disk reads "disk full"),
        named by the cache file first tried.
    """
    folder = cache_dir()
    path = folder / filename if folder is not None else None
    body = read_source(path) if path is not None else None  # None: missing, damaged, untrusted
    if body is None:
        label = what(filename)
        with progress.task(f"generating {label} of this walker structure"):
            first_time(f"generating {label}")
            body = build()
        _generated_now.add(filename)
        errors: list = []
        first = path
        if path is None or not write_source(path, body, errors):
            path = usercache.private_tmp() / filename
            if not write_source(path, body, errors):
                # the cause kept (its errno: a full disk or a file-size limit reads "disk
                # full" as every other write), named by the cache file first tried
                err = errors[-1] if errors else OSError()
                raise OSError(err.errno, "cannot write the generated module "
                              f"({err.strerror or err})", str(first or path)) from err
    return body, path


def import_generated(filename: str, module_name: str, build):
    """Import the generated module ``filename`` of the cache folder as a real module (so that
    numba's ``cache=True`` keeps its machine code, in the user cache:
    :func:`walkerlab.usercache.use_for_numba`); memoised per process by ``filename``.

    ``build() -> str`` gives the source on a miss, a damaged or an untrusted file (see
    :func:`read_source`); it is written atomically (mode 0600).  Without a private cache
    folder, or one that cannot be written, the module is written to the run's private
    temporary folder (:func:`walkerlab.usercache.private_tmp`, removed at exit).  The module
    is executed from the text that was read and checked (never re-read by an import loader:
    no ``__pycache__``, no second open of a file that may have been replaced).  Used by
    :mod:`walkerlab.codegen.compiled` and :mod:`walkerlab.codegen.floating` (and through it
    :mod:`walkerlab.models.contact.generated`).
    """
    if filename in _imported:
        return _imported[filename]
    import importlib.util
    import sys

    usercache.use_for_numba()  # numba's cache in the user cache, not in a runs folder
    body, path = generated_source(filename, build)
    spec = importlib.util.spec_from_loader(module_name, loader=None, origin=str(path))
    mod = importlib.util.module_from_spec(spec)
    mod.__file__ = str(path)
    sys.modules[module_name] = mod
    # numba compiles the module's cfuncs as it runs (from its cache, where it has them)
    how = "compiling" if filename in _generated_now else "loading"
    with progress.task(f"{how} {what(filename)} of this walker structure (numba)"):
        exec(compile(body, str(path), "exec"), mod.__dict__)  # generated by walkerlab.codegen
    _imported[filename] = mod
    return mod
