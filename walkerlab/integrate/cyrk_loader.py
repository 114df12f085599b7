"""CyRK's ``pysolve_ivp`` without numba: a workaround of an eager import in ``CyRK/__init__.py``.

``import CyRK`` (0.20) imports its numba solvers (``CyRK.nb.nbrk``, ``CyRK.nb.numba_solver``)
and so numba and llvmlite, about 180 modules of start-up, although walkerlab's
rigid-walker integration only calls ``pysolve_ivp``, which lives in the compiled extension
``CyRK.cy.pysolver`` and needs no numba.  Python runs a package's ``__init__`` before any of
its submodules, so :func:`pysolve_ivp` does what ``CyRK/__init__.py`` does for that one
function, with the package module created but not yet executed:

1. ``sys.modules["CyRK"]`` = the package module from its import spec, not executed;
2. CyRK's own CPU check (``CyRK._cpu_check.check_cpu``: the wheels are built for AVX2; a
   CPU without it gets CyRK's ImportError, not an illegal instruction);
3. ``import CyRK.cy.pysolver`` (its compiled dependencies ``CyRK.cy.*`` come with it).

The package module stays in ``sys.modules`` and gets a module ``__getattr__`` (PEP 562): the
first use of any other name (``from CyRK import nbsolve2_ivp``, ``CyRK.__version__``,
``import CyRK; CyRK.anything``) runs CyRK's own ``__init__.py`` in that same module object, so
a later plain ``import CyRK`` elsewhere (the contact integrator, the sweep workers' warm-up)
sees the complete package, numba solvers included, with ``CyRK.cy`` the modules already
loaded (a compiled module cannot be loaded twice, so the package must not be re-created).
If ``CyRK`` is already imported, or any step of the shortcut fails (a CyRK release that moved
these modules), the plain ``from CyRK import pysolve_ivp`` is used: the shortcut can only
cost speed, never correctness.  A whole ``walkerlab fixedpoint --force`` process, paired
with the plain import: 1068 -> 859 modules, peak memory 162 -> 104 MiB.  No upstream issue
found; remove this module when CyRK imports its numba
solvers lazily.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
import threading

_LOCK = threading.RLock()
_PYSOLVE = None


def _complete_on_first_use(pkg, spec) -> None:
    """Give the not-yet-executed package module a PEP 562 ``__getattr__`` that runs CyRK's
    ``__init__.py`` in it on the first lookup of a name it does not have yet."""

    running = []  # non-empty while __init__.py runs (a lookup from inside it must not re-run it)

    def __getattr__(name: str):
        with _LOCK:  # another thread waits here until the package is complete
            if not running and pkg.__dict__.get("__getattr__") is __getattr__:
                running.append(True)
                try:
                    spec.loader.exec_module(pkg)
                finally:
                    del pkg.__getattr__
        try:
            return pkg.__dict__[name]
        except KeyError:
            raise AttributeError(f"module 'CyRK' has no attribute {name!r}") from None

    pkg.__getattr__ = __getattr__


def _forget() -> None:
    """Undo step 1 (and the pure-Python CPU-check module): a later import starts afresh."""
    for name in ("CyRK._cpu_check", "CyRK"):
        sys.modules.pop(name, None)


def _shortcut():
    """``pysolve_ivp`` through the steps of the module docstring, or None (use the plain
    import).  Raises CyRK's ImportError on a CPU without AVX2."""
    spec = importlib.util.find_spec("CyRK")
    if spec is None or spec.loader is None or not spec.submodule_search_locations:
        return None
    pkg = importlib.util.module_from_spec(spec)
    sys.modules["CyRK"] = pkg
    try:
        cpu = importlib.import_module("CyRK._cpu_check")
        check = cpu.check_cpu
    except (ImportError, AttributeError):
        _forget()  # nothing compiled is loaded yet: CyRK imports normally later
        return None
    try:
        check()
    except BaseException:
        _forget()
        raise
    try:
        solver = importlib.import_module("CyRK.cy.pysolver").pysolve_ivp
    except (ImportError, AttributeError):
        # some compiled CyRK.cy modules may be loaded: keep this module object and complete it
        _complete_on_first_use(pkg, spec)
        return None
    _complete_on_first_use(pkg, spec)
    return solver


def pysolve_ivp():
    """CyRK's ``pysolve_ivp`` function, loaded without numba where possible.

    Returns
    -------
    callable
        ``CyRK.pysolve_ivp`` (the same object a plain ``from CyRK import pysolve_ivp`` gives).

    Raises
    ------
    ImportError
        CyRK is not installed, or the CPU lacks AVX2 (CyRK's own check and message).
    """
    global _PYSOLVE
    if _PYSOLVE is None:
        with _LOCK:
            solver = None
            if "CyRK" not in sys.modules:
                solver = _shortcut()
        if solver is None:
            from CyRK import pysolve_ivp as solver
        _PYSOLVE = solver
    return _PYSOLVE
