"""numbalsoda route for the contact walker: LSODA called from compiled code.

Internal module, imported only when ``method="numbalsoda"`` is selected (numbalsoda is an
optional extra: ``pip install -e '.[numbalsoda]'``; building it from source needs a C++
and a Fortran compiler and cmake).  The walker's generated right-hand side
(:mod:`walkerlab.models.contact.generated`) is wrapped in a numba ``cfunc`` so that LSODA
(numbalsoda's C++ port) integrates a whole chunk of samples without re-entering Python.
numbalsoda's LSODA takes a scalar ``atol``, no largest step and no user Jacobian (it forms the
stiff-phase Jacobian by finite differences;
those RHS calls are counted in ``nfev``).

The packed data vector handed to the cfunc is ``[n1, n2, PC, p, c1 (n1), c2 (n2), nfev]``.
"""

from __future__ import annotations

import numpy as np


def _load_driver():
    """numbalsoda's LSODA driver module, or None when the package is not installed.

    Loaded from its file, not through ``import numbalsoda``: the package's ``__init__`` also
    imports its DOP853 ``solve_ivp`` driver, which compiles eagerly in every process, and
    only the LSODA driver (its ctypes entry point ``lsoda_wrapper`` and
    the cfunc signature ``lsoda_sig``) is used here.
    """
    import importlib.util
    from pathlib import Path

    spec = importlib.util.find_spec("numbalsoda")
    if spec is None or spec.origin is None:
        return None
    path = Path(spec.origin).parent / "driver.py"
    dspec = importlib.util.spec_from_file_location("_walkerlab_numbalsoda_driver", path)
    mod = importlib.util.module_from_spec(dspec)
    dspec.loader.exec_module(mod)
    return mod


try:
    _DRIVER = _load_driver()
except (ImportError, OSError):  # pragma: no cover - broken install
    _DRIVER = None
#: numbalsoda's C entry point (ctypes; called once per chunk from Python) or None.
lsoda = None if _DRIVER is None else _DRIVER.lsoda_wrapper
lsoda_sig = None if _DRIVER is None else _DRIVER.lsoda_sig

__all__ = ["MissingNumbalsoda", "available", "solve_chunk"]


class MissingNumbalsoda(ValueError, ImportError):
    """``method="numbalsoda"`` was selected but the package is not installed (a ValueError
    so that the CLI reports it as one line with exit code 1)."""


_FPTR: dict = {}  # generated kernels module name -> cfunc address


def available() -> bool:
    """Whether numbalsoda can be imported."""
    return lsoda is not None


def solve_chunk(x0: np.ndarray, t_eval: np.ndarray, data: np.ndarray, rtol: float,
                atol: float, mxstep: int = 500000, *, kernels=None):
    """LSODA from ``x0`` over the sample times ``t_eval`` (n,) [s].

    Returns
    -------
    X : ndarray (n, 2 nq)
        States at ``t_eval`` (rows after a failure are undefined).
    ok : bool
        LSODA reported success.
    nfev : int
        RHS evaluations of this call (finite-difference Jacobian columns included).

    Raises
    ------
    MissingNumbalsoda
        numbalsoda is not installed.
    """
    if lsoda is None:
        raise MissingNumbalsoda("contact_solver.method 'numbalsoda' needs the numbalsoda package: "
                          "pip install -e '.[numbalsoda]' (builds with cmake, g++, gfortran)")
    if kernels.__name__ not in _FPTR:
        _FPTR[kernels.__name__] = kernels.build_lsoda(lsoda_sig)
    n0 = data[-1]
    u0 = np.ascontiguousarray(x0, dtype=np.float64)
    te = np.ascontiguousarray(t_eval, dtype=np.float64)
    X = np.empty((len(te), len(u0)))
    flag = np.array(999, np.int32)
    # same call as numbalsoda.lsoda (its njit wrapper), without compiling that wrapper
    lsoda(_FPTR[kernels.__name__], len(u0), u0.ctypes.data, data.ctypes.data, len(te),
          te.ctypes.data, X.ctypes.data, float(rtol), float(atol), int(mxstep), flag.ctypes.data)
    return X, bool(flag == 1), int(data[-1] - n0)
