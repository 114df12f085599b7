"""scipy's Brent root finder without ``scipy.optimize``'s package import: a workaround of
an import cost.

``from scipy.optimize import brentq`` runs ``scipy/optimize/__init__.py``, which imports the
whole package (minimisers, least squares, linear programming, and through them
``scipy.special`` and ``scipy.fft``): about 0.22-0.26 s of a process on a 2-core machine
whose scipy.linalg is already loaded, measured with ``python -X importtime``.  The event
location of the compiled integrators (:mod:`walkerlab.integrate._compiled`,
:mod:`walkerlab.integrate.compiled_segments`) needs only Brent's method, whose
implementation is the compiled extension ``scipy.optimize._zeros`` (Brent 1973, ch. 4;
scipy's ``zeros.c``) behind a thin Python wrapper.  A whole ``walkerlab optimize
configs/compass_optimal.yaml --force`` imported ``scipy.optimize`` only for the contact
replay's one located event.

:func:`brentq` gives ``scipy.optimize.brentq``'s root bit for bit (the same compiled
routine, the same arguments; ``tests/test_brentq_loader.py`` compares the two):

1. if ``scipy.optimize`` is already imported, its ``brentq`` is called;
2. else the extension ``scipy.optimize._zeros`` is loaded from its file under its own name
   (and taken out of ``sys.modules`` again: a later ``import scipy.optimize`` loads it as
   usual, the package's ``_zeros`` set) and
   its ``_brentq`` called as scipy's wrapper calls it (the function value checked for NaN,
   scipy's defaults ``rtol = 4 eps``, 100 iterations);
3. if step 2 fails in any way (a scipy release that moved or renamed the extension), the
   plain import is used: the shortcut can only cost speed, never correctness.

No upstream issue found; remove this module if ``scipy.optimize`` imports its submodules
lazily.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import math
import sys
import threading
from pathlib import Path

__all__ = ["brentq"]

#: scipy.optimize.brentq's defaults (``scipy/optimize/_zeros_py.py``: ``_rtol``, ``_iter``)
DEFAULT_RTOL = 4 * sys.float_info.epsilon
DEFAULT_MAXITER = 100

_LOCK = threading.Lock()
_CORE: list = []  # [the extension's _brentq, or None: use scipy.optimize]


def _load_core():
    """``scipy.optimize._zeros._brentq`` loaded from the extension's file, or None."""
    try:
        spec = importlib.util.find_spec("scipy")
        if spec is None or not spec.submodule_search_locations:
            return None
        folder = Path(next(iter(spec.submodule_search_locations))) / "optimize"
        for suffix in importlib.machinery.EXTENSION_SUFFIXES:
            path = folder / f"_zeros{suffix}"
            if path.is_file():
                break
        else:
            return None
        name = "scipy.optimize._zeros"
        had = name in sys.modules
        loader = importlib.machinery.ExtensionFileLoader(name, str(path))
        ext = importlib.util.spec_from_file_location(name, str(path), loader=loader)
        try:
            module = importlib.util.module_from_spec(ext)
            loader.exec_module(module)
        finally:
            if not had:  # CPython enters a single-phase extension in sys.modules: taken
                sys.modules.pop(name, None)  # out, so a later ``import scipy.optimize``
                # loads it as usual (and sets the package's ``_zeros``)
        return module._brentq
    except Exception:  # any failure: the plain import (speed only)
        return None


def _core():
    with _LOCK:
        if not _CORE:
            _CORE.append(_load_core())
    return _CORE[0]


def brentq(f, a: float, b: float, xtol: float, rtol: float = DEFAULT_RTOL) -> float:
    """A root of ``f`` in ``[a, b]`` by Brent's method: ``scipy.optimize.brentq(f, a, b,
    xtol=xtol, rtol=rtol)`` bit for bit, without importing ``scipy.optimize`` (module
    docstring).

    Parameters
    ----------
    f : callable
        ``f(x) -> float``, of opposite signs at ``a`` and ``b``.
    a, b : float
        The bracket.
    xtol : float
        Absolute tolerance on the root (> 0), in ``x``'s unit.
    rtol : float
        Relative tolerance (>= 4 eps).

    Returns
    -------
    float
        The root.

    Raises
    ------
    ValueError
        ``f`` has the same sign at both ends, a function value is NaN, or a tolerance is out
        of range (scipy's messages).
    RuntimeError
        No convergence in 100 iterations (scipy's message).
    """
    if "scipy.optimize" in sys.modules:
        return sys.modules["scipy.optimize"].brentq(f, a, b, xtol=xtol, rtol=rtol)
    core = _core()
    if core is None:
        from scipy.optimize import brentq as plain

        return plain(f, a, b, xtol=xtol, rtol=rtol)
    return _with_core(core, f, a, b, xtol, rtol)


def _with_core(core, f, a: float, b: float, xtol: float, rtol: float) -> float:
    """scipy's ``brentq`` wrapper (``scipy/optimize/_zeros_py.py``) around the extension's
    ``_brentq`` ``core``."""
    if xtol <= 0:
        raise ValueError(f"xtol too small ({xtol:g} <= 0)")
    if rtol < DEFAULT_RTOL:
        raise ValueError(f"rtol too small ({rtol:g} < {DEFAULT_RTOL:g})")

    def checked(x):  # scipy's _wrap_nan_raise
        fx = f(x)
        if math.isnan(fx):
            raise ValueError(f"The function value at x={x} is NaN; solver cannot continue.")
        return fx

    return core(checked, a, b, xtol, rtol, DEFAULT_MAXITER, (), False, True)
