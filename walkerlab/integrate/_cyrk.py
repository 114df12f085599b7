"""CyRK route for the contact walker: CyRK's C++ integrators called with a compiled RHS.

Internal module, imported by :mod:`walkerlab.integrate.contact`; CyRK itself is imported only
on the first chunk of a ``cyrk_*`` method.  CyRK (a main dependency, binary wheels, no
Fortran) takes the right-hand side as a C function pointer (its numba bridge,
``CyRK.nb.numba_solver``: ``cyjit_sig``, ``c_numba_cysolve_ivp``).  The walker's
generated RHS (:mod:`walkerlab.models.contact.generated`) is wrapped in a numba ``cfunc`` (compiled
once per walker structure, cached on disk), so CyRK integrates a whole chunk of samples
without re-entering Python.
The physics is not repeated here: the cfunc only unpacks its data vector and calls the
kernel.

CyRK's numba bridge passes no Jacobian (``numba_c_api_.cpp`` hands a null Jacobian to the
solver), so its implicit methods (LSODA, BDF, Radau) form the Jacobian by finite
differences; those RHS calls are counted in ``nfev`` like all others (the cfunc counts its
own calls).  ``max_step`` and a scalar or per-state ``atol`` are passed through.

The packed data vector is ``[n1, n2, PC, p, c1 (n1), c2 (n2), nfev]``; CyRK copies it
into its solver, so the call counter is read back from the solver's copy.
"""

from __future__ import annotations

import ctypes

import numpy as np

__all__ = ["CYRK_METHODS", "DenseInterval", "solve_chunk"]

#: walkerlab method name -> CyRK method name.  Only BDF pays on the contact walker (RHS calls
#: of ``walkerlab bench contact``): CyRK's LSODA needs ~1.3x the RHS calls of numbalsoda's, its
#: Radau 3x, and the explicit pairs (RK45, DOP853) are held by stability at >= 40k calls
#: for 5 strides whatever the tolerance (stance-contact eigenvalues ~ -3e3 1/s, impacts
#: ~ -1e5 1/s).
CYRK_METHODS = {"cyrk_bdf": "BDF"}

_FPTR: dict = {}
FIRST = [0.0]  # generated kernels module name -> cfunc address


def address(kernels, ready=None) -> int:
    """C address of the cfunc of ``kernels.rhs_packed`` (compiled once per walker structure,
    numba disk cache); ``ready``: a :class:`walkerlab.codegen.pending.CompiledElsewhere`
    (a side process compiling it: waited for first, then the kernel is loaded)."""
    if kernels.__name__ not in _FPTR:
        if ready is not None:  # a side process is compiling it (a cold contact run)
            ready.before_first_use(kernels.__name__, "build_cyrk")
        _FPTR[kernels.__name__] = kernels.build_cyrk()
    return _FPTR[kernels.__name__]


def solve_chunk(method: str, x0: np.ndarray, t_eval: np.ndarray, data: np.ndarray,
                rtol: float, atol, max_step: float = np.inf, max_num_steps: int = 0, *,
                kernels=None, ready=None, dense: bool = False):
    """Integrate from ``x0`` at ``t_eval[0]`` over the sample times ``t_eval`` (n,) [s].

    Parameters
    ----------
    method : str
        A key of :data:`CYRK_METHODS`.
    x0 : ndarray (N,)
    t_eval : ndarray (n,)
        Increasing sample times [s]; the first is the start time.
    data : ndarray
        From :meth:`walkerlab.models.contact.model.ContactWalker.pack` (or a powered
        walker's :meth:`walkerlab.models.contact.powered_data.PoweredData.data`).
    rtol : float
    atol : float or ndarray (N,)
        [m, rad, m/s, rad/s].
    max_step : float
        Largest step [s] (inf: none).
    max_num_steps : int
        Most solver steps in this call (0: CyRK's default); past it the call stops
        unsuccessfully at the last sample reached (how a caller bounds the wall time of a
        compiled chunk, which checks no clock).
    kernels : module
        The walker's generated kernels (``ContactWalker.kernels``), or a stand-in with
        ``__name__`` and ``build_cyrk()``.
    ready : walkerlab.codegen.pending.CompiledElsewhere, optional
        The caller's hand-off when a side process compiles the right-hand side
        (``ContactWalker.rhs_ready``).
    dense : bool
        Keep CyRK's dense output: a fifth value, the :class:`DenseInterval` over the
        samples reached (the caller frees it).

    Returns
    -------
    X : ndarray (m, N)
        States at ``t_eval[:m]`` (``m = n`` on success; fewer when the solver stopped early).
    ok : bool
        CyRK reported success.
    nfev : int
        RHS evaluations of this call (finite-difference Jacobian columns included).
    message : str
        CyRK's status message.
    """
    from CyRK.cy.pyhelpers import find_ode_method_int
    from CyRK.nb import numba_solver as ns

    fptr = address(kernels, ready)
    u0 = np.ascontiguousarray(x0, dtype=np.float64)
    te = np.ascontiguousarray(t_eval, dtype=np.float64)
    rt = np.array([float(rtol)])
    at = np.ascontiguousarray(np.atleast_1d(atol), dtype=np.float64)
    hmax = float(max_step) if np.isfinite(max_step) else ns.MAX_SIZE
    # the C entry point that CyRK's njit `nbsolve2_ivp` calls, called here through ctypes
    # (one call per chunk; avoids compiling that njit wrapper in every process)
    ptr = ns.c_numba_cysolve_ivp(
        fptr, te[0], te[-1], u0.ctypes.data, u0.size, find_ode_method_int(CYRK_METHODS[method]),
        0, 0, data.ctypes.data, data.size * 8, int(max_num_steps), 2000, bool(dense),
        te.ctypes.data, te.size, None, None, 0, rt.ctypes.data, rt.size, at.ctypes.data,
        at.size, hmax, float(FIRST[0]), True)
    if not ptr:  # pragma: no cover - allocation failure inside CyRK
        out = np.empty((0, u0.size)), False, 0, "CyRK returned no result"
        return (*out, None) if dense else out
    kept = False
    try:
        ok = bool(ns.c_get_success(ptr))
        n = int(ns.c_get_size(ptr))
        ndy = int(ns.c_get_num_dy(ptr))
        X = (np.ctypeslib.as_array(ns.c_get_y_ptr(ptr), (n, ndy))[:, :u0.size].copy() if n
             else np.empty((0, u0.size)))
        args = ctypes.cast(ns.c_get_args_ptr(ptr), ctypes.POINTER(ctypes.c_double))
        nfev = int(args[data.size - 1] - data[-1])
        buf = ctypes.create_string_buffer(256)
        ns.c_get_msg_buf(ptr, ctypes.addressof(buf), 256)
        msg = buf.value.decode(errors="replace")
        if dense:
            kept = True
            return X, ok, nfev, msg, DenseInterval(ptr, u0.size)
    finally:
        if not kept:
            ns.c_free(ptr)
    return X, ok, nfev, msg


class DenseInterval:
    """CyRK's dense output of one integration (:func:`solve_chunk` with ``dense``): call it
    at a time [s] inside the integrated span for the state (N,); :meth:`free` releases
    CyRK's solution."""

    def __init__(self, ptr, n: int):
        self.ptr, self.n = ptr, n

    def __call__(self, t: float) -> np.ndarray:
        from CyRK.nb import numba_solver as ns

        y = np.empty(self.n)
        ns.c_call(self.ptr, float(t), y.ctypes.data)
        return y

    def free(self) -> None:
        from CyRK.nb import numba_solver as ns

        if self.ptr:
            ns.c_free(self.ptr)
            self.ptr = None
