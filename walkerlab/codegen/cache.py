"""On-disk cache of generated model code, so a process start does not re-derive.

Where: the per-user cache, ``<user cache>/models`` (:mod:`walkerlab.usercache`:
``$WALKERLAB_CACHE_DIR`` or the platform's user cache folder, e.g. ``~/.cache/walkerlab``),
never a runs folder: runs folders are shared, and code in them would run as whoever opens
them.  The folder is created 0700 and files are written 0600; a file is executed only if it
belongs to the current user and is not writable by group or others (else it is regenerated);
without a private folder the code stays in memory.

Key: sha256 of the walker :class:`~walkerlab.walker.description.Structure` (no numbers: a
sweep over masses shares one file) and of the generator's own source files (``legged.py``,
``source.py``, ``walker/description.py``, ``cache.py``, ``equations.py``, the tree's modules)
and the sympy version, so editing the generator regenerates.  Files are written atomically
(temporary name, then ``os.replace``; a failed write - disk full, read-only - leaves nothing
behind); each starts with a sha256 of its body: a truncated or damaged file is regenerated,
as is one that fails to compile.  (The header detects damage, not tampering: trust comes
from the file's owner and mode.)
"""

from __future__ import annotations

import hashlib
from functools import cache
from importlib import metadata
from pathlib import Path

from walkerlab import progress, usercache

ENV = usercache.ENV
_GENERATOR_FILES = ("codegen/legged.py", "codegen/tree_derive.py", "walker/tree.py",
                    "walker/trees.py", "codegen/seeded.py", "codegen/source.py",
                    "walker/description.py", "codegen/cache.py", "codegen/equations.py",
                    "codegen/lagrange.py", "codegen/compiled_source.py", "codegen/frames.py",
                    # the parts trees.py hangs on a biped (arms, a torus' stance side) and
                    # the torus' rolling: an edit there changes the equations too
                    "walker/arm_trees.py", "walker/foot_trees.py", "codegen/rolling_feet.py")
_memo: dict[str, dict] = {}
#: what each generated module of the cache folder is, by a part of its file name (the first
#: key here that is a part of it: ``<key>_act_<tag>_nb.py`` is an actuated flow, not ``nb``)
_WHAT = {"rows": "the batched step kernels", "act": "the actuated compiled flow",
         "vcnb": "the compiled virtual-constraint controller",
         "vc": "the virtual-constraint outputs", "vcflow": "the virtual-constraint flow",
         "vcrhs": "the contact model's virtual-constraint controller",
         "contact": "the contact model's kernels",
         "floating": "the floating-base (contact) view", "nb": "the compiled flow"}
#: the documentation page that says what a first run of a new structure costs
FIRST_RUN_DOC = "docs/user_guide/first_run.md"


def _what(filename: str) -> str:
    """What the generated module ``filename`` is, in words (:data:`_WHAT`)."""
    parts = filename.rsplit(".", 1)[0].split("_")[1:]
    return next((words for part, words in _WHAT.items() if part in parts),
                "a generated module")


def _first_time(what: str) -> None:
    """Say, in one notice, that ``what`` of this walker structure is being made: the first
    time on this machine (or after an upgrade), kept in the user cache after."""
    progress.machine_note(f"{what} of this walker structure: first time on this machine (or "
                          "since an upgrade), seconds to a few minutes; kept in the user "
                          f"cache for later runs ({FIRST_RUN_DOC})")


def cache_dir() -> Path | None:
    """The private folder generated model code is read from and written to (created 0700),
    or None when there is none (the code is then kept in memory)."""
    return usercache.private_dir("models")


@cache
def _generator_hash() -> str:
    """sha256 of the generator's sources and the sympy version (once per process)."""
    h = hashlib.sha256()
    here = Path(__file__).parents[1]  # walkerlab/
    for name in _GENERATOR_FILES:
        h.update((here / name).read_bytes())
    try:
        h.update(metadata.version("sympy").encode())
    except metadata.PackageNotFoundError:  # pragma: no cover
        pass
    return h.hexdigest()


@cache
def _flat_generator_hash() -> str:
    """sha256 of the flat-foot generator's sources (once per process)."""
    return _source_hash("codegen/foot_modes.py", "codegen/double_support.py")


def _source_hash(*names: str) -> str:
    """sha256 of the sources ``names`` (paths in ``walkerlab/``), in order."""
    h = hashlib.sha256()
    for name in names:
        h.update((Path(__file__).parents[1] / name).read_bytes())
    return h.hexdigest()


@cache
def _spoked_generator_hash() -> str:
    """sha256 of the spoked wheel's derivation (once per process)."""
    return _source_hash("codegen/derive_3d.py", "walker/walker_trees.py")


def cache_key(structure) -> str:
    """Cache key (hex, 24 characters) of a structure for the current generator (every
    biped's derivation from its body tree, :mod:`walkerlab.codegen.legged`; a flat-footed
    walker's also covers :mod:`walkerlab.codegen.foot_modes` (with
    :mod:`~walkerlab.codegen.double_support` and :mod:`~walkerlab.codegen.push_off`), a
    spoked wheel's :mod:`walkerlab.codegen.derive_3d` and its planar tree, which no other
    structure's key reads)."""
    h = hashlib.sha256(structure.key().encode())
    h.update(_generator_hash().encode())
    if structure.foot == "flat":
        h.update(_flat_generator_hash().encode())
    if structure.spokes:
        h.update(_spoked_generator_hash().encode())
    return h.hexdigest()[:24]


def _digest(body: str) -> str:
    return hashlib.sha256(body.encode()).hexdigest()


def _exec(source: str, origin: str) -> dict:
    ns: dict = {}
    exec(compile(source, origin, "exec"), ns)  # generated by walkerlab.codegen.source
    if not callable(ns.get("make")):
        raise ValueError("generated module has no make()")
    return ns


def read_source(path: Path) -> str | None:
    """Body of a cache file that may be executed: private (this user's, not writable by
    group/others, no link) and intact (its sha256 header matches), else None."""
    text = usercache.read_private(path)
    if text is None or "\n" not in text:
        return None
    first, body = text.split("\n", 1)
    return body if first == f"# sha256 {_digest(body)}" else None


def _read(path: Path) -> dict | None:
    """The namespace of a valid cache file, or None (missing, corrupt, untrusted, stale)."""
    body = read_source(path)
    if body is None:
        return None
    try:
        return _exec(body, str(path))
    except (ValueError, SyntaxError):
        return None


def write_source(path: Path, body: str, errors: list | None = None) -> bool:
    """Write a cache file (sha256 header + body) atomically, mode 0600; False when the
    folder cannot be written (nothing is left behind; the OSError appended to ``errors``)."""
    return usercache.write_private(path, f"# sha256 {_digest(body)}\n{body}", errors)


def generated_module(structure) -> dict:
    """Namespace of the generated module of ``structure`` (its ``make(p)`` builds functions).

    Reads the cache; on a miss (or a corrupt or untrusted file) derives with sympy,
    generates, writes.
    """
    key = cache_key(structure)
    if key in _memo:
        return _memo[key]
    folder = cache_dir()
    path = folder / f"{key}.py" if folder is not None else None
    ns = _read(path) if path is not None else None
    if ns is None:
        with progress.task("deriving the equations of this walker structure"):
            _first_time("deriving the equations")
            ns = _derive_module(structure, key, path)
    _memo[key] = ns
    return ns


def _derive_module(structure, key: str, path: Path | None) -> dict:
    """:func:`generated_module`'s miss: derive, generate, execute and write the module."""
    ns = None
    if structure.foot == "flat":
        from walkerlab.codegen import foot_modes as flatfoot  # light

        body = flatfoot.generate_flat(structure, key)
        ns = _exec(body, str(path or f"<walkerlab model {key}>"))
        if path is not None:
            write_source(path, body)
    if ns is None:
        from walkerlab.codegen import source as codegen  # light

        eq = derive_equations(structure)
        body = codegen.generate(eq, structure.param_names, key)
        ns = _exec(body, str(path or f"<walkerlab model {key}>"))
        if path is not None:
            write_source(path, body)
    return ns


#: the symbolic equations derived in this process, by cache key: every generated module of
#: a structure (the Python model, its compiled twin, the actuated flow, the collocation's
#: functions) is printed from one derivation; the last :data:`_EQUATIONS_MAX` structures'
#: are kept (a 3D walker's hold tens of MB of sympy expressions)
_equations: dict[str, object] = {}
_EQUATIONS_MAX = 4


def derive_equations(structure):
    """The symbolic :class:`~walkerlab.codegen.equations.Equations` of ``structure`` that the
    printers of :mod:`walkerlab.codegen.source` take: a spoked wheel's, planar or 3D
    (:func:`walkerlab.codegen.derive_3d.derive_spoked`) or a biped's
    (:func:`walkerlab.codegen.legged.derive_legged`); derived once per process and cache
    key (sympy's expressions are immutable: the printers share them)."""
    key = cache_key(structure)
    if key not in _equations:
        if structure.spokes:
            from walkerlab.codegen import derive_3d  # light

            _equations[key] = derive_3d.derive_spoked(structure)
        else:
            from walkerlab.codegen import legged  # light

            _equations[key] = legged.derive_legged(structure)
        while len(_equations) > _EQUATIONS_MAX:
            _equations.pop(next(iter(_equations)))
    return _equations[key]


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
        what = _what(filename)
        with progress.task(f"generating {what} of this walker structure"):
            _first_time(f"generating {what}")
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
    with progress.task(f"{how} {_what(filename)} of this walker structure (numba)"):
        exec(compile(body, str(path), "exec"), mod.__dict__)  # generated by codegen.source
    _imported[filename] = mod
    return mod


def clear_memo() -> None:
    """Forget modules loaded (and functions bound) in this process (tests)."""
    _memo.clear()
    _bound.clear()
    _equations.clear()


#: the bound functions of recent (structure, parameters): a walker rebuilt with the same
#: numbers (a Gymnasium environment's reset, a study's points) binds them once
_bound: dict = {}
_BOUND_MAX = 64


def functions(data) -> dict:
    """Generated functions of ``data`` with its parameters bound (see codegen's table); a
    new dict each call (its functions shared with earlier calls of the same structure and
    parameters: they are pure functions of the state)."""
    key = (cache_key(data.structure), tuple(data.params))
    fns = _bound.get(key)
    if fns is None:
        fns = generated_module(data.structure)["make"](data.params)
        if len(_bound) >= _BOUND_MAX:
            _bound.pop(next(iter(_bound)))
        _bound[key] = fns
    return dict(fns)
