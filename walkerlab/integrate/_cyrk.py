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

__all__ = ["CYRK_METHODS", "ChunkSolver", "DenseInterval", "solve_chunk"]

#: walkerlab method name -> CyRK method name.  Only BDF pays on the contact walker (RHS calls
#: of ``walkerlab bench contact``): CyRK's LSODA needs ~1.3x the RHS calls of numbalsoda's, its
#: Radau 3x, and the explicit pairs (RK45, DOP853) are held by stability at >= 40k calls
#: for 5 strides whatever the tolerance (stance-contact eigenvalues ~ -3e3 1/s, impacts
#: ~ -1e5 1/s).
CYRK_METHODS = {"cyrk_bdf": "BDF"}

_FPTR: dict = {}  # generated kernels module name -> cfunc address
FIRST = [0.0]  # CyRK's first step [s] of every call (0: its own estimate)


def address(kernels, ready=None) -> int:
    """C address of the cfunc of ``kernels.rhs_packed`` (compiled once per walker structure,
    numba disk cache); ``ready``: a :class:`walkerlab.execution.pending.CompiledElsewhere`
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
    ready : walkerlab.execution.pending.CompiledElsewhere, optional
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
    return ChunkSolver(method, rtol, atol, max_step, max_num_steps, kernels=kernels,
                       ready=ready)(x0, t_eval, data, dense)


_API: list = []  # CyRK's numba bridge and the method numbers, imported on first use


def _api():
    """``(numba_solver module, {walkerlab method: CyRK method number})``, imported once."""
    if not _API:
        from CyRK.cy.pyhelpers import find_ode_method_int
        from CyRK.nb import numba_solver as ns

        _API.append((ns, {k: find_ode_method_int(v) for k, v in CYRK_METHODS.items()}))
    return _API[0]


_ADDRESSES: list = []  # the result's solution and argument addresses as integers


def _addresses():
    """``(solution address, arguments address)``: CyRK's getters of a result's solution
    and its copy of the arguments (the numba bridge's ``get_y_func_ptr`` and
    ``get_args_ptr_func_ptr``) called as functions that return the address as an integer
    (the bridge's own prototypes return typed pointers, read through ``.contents``)."""
    if not _ADDRESSES:
        from CyRK.nb import numba_c_api as api

        sig = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_void_p)
        _ADDRESSES.append((sig(api.get_y_func_ptr()), sig(api.get_args_ptr_func_ptr())))
    return _ADDRESSES[0]


class _Buffer:
    """A float64 array whose C address is read once (not at every call): the inputs CyRK
    copies (the start state, the sample times, the data vector) are copied into it."""

    def __init__(self):
        self.array, self.address = np.empty(0), 0

    def reserve(self, n: int) -> None:
        """Room for at least ``n`` numbers."""
        if n > self.array.size:
            self.array = np.empty(max(n, 2 * self.array.size))
            self.address = self.array.ctypes.data

    def put(self, values: np.ndarray) -> int:
        """Copy ``values`` (1-D) in; returns the address of the copy."""
        n = len(values)
        self.reserve(n)
        self.array[:n] = values
        return self.address


class ChunkSolver:
    """:func:`solve_chunk` with the method, tolerances, step limits and right-hand side
    fixed: the arguments that do not change between calls are converted once (a run that
    calls CyRK for every short segment, such as a Gymnasium control period).  Calling it
    as ``solver(x0, t_eval, data, dense=False)`` answers as :func:`solve_chunk` does.

    Parameters
    ----------
    method, rtol, atol, max_step, max_num_steps, kernels, ready
        As :func:`solve_chunk`'s.
    """

    def __init__(self, method: str, rtol: float, atol, max_step: float = np.inf,
                 max_num_steps: int = 0, *, kernels=None, ready=None):
        ns, methods = _api()
        self._ns, self._method = ns, methods[method]
        self._fptr = address(kernels, ready)
        self._rt = np.array([float(rtol)])
        self._at = np.ascontiguousarray(np.atleast_1d(atol), dtype=np.float64).copy()
        self._rt_p, self._at_p = self._rt.ctypes.data, self._at.ctypes.data
        self._hmax = float(max_step) if np.isfinite(max_step) else ns.MAX_SIZE
        self._steps = int(max_num_steps)
        self._y0, self._te, self._data = _Buffer(), _Buffer(), _Buffer()
        self._msg = ctypes.create_string_buffer(256)
        self._msg_p = ctypes.addressof(self._msg)
        self._messages: dict = {}  # CyRK's status code -> its message (a function of it)
        self._dense_y = _Buffer()  # the dense outputs' state (each of their calls copies it)
        self._out = _Buffer()  # the solution copied out of CyRK's result
        self._y_at, self._args_at = _addresses()

    def __call__(self, x0: np.ndarray, t_eval: np.ndarray, data: np.ndarray,
                 dense: bool = False):
        ns = self._ns
        ny, nt, nd = len(x0), len(t_eval), len(data)
        # the C entry point that CyRK's njit `nbsolve2_ivp` calls, called here through
        # ctypes (one call per chunk; avoids compiling that njit wrapper in every process)
        ptr = ns.c_numba_cysolve_ivp(
            self._fptr, float(t_eval[0]), float(t_eval[-1]), self._y0.put(x0), ny,
            self._method, 0, 0, self._data.put(data), nd * 8, self._steps, 2000, bool(dense),
            self._te.put(t_eval), nt, None, None, 0, self._rt_p, 1, self._at_p,
            self._at.size, self._hmax, float(FIRST[0]), True)
        if not ptr:  # pragma: no cover - allocation failure inside CyRK
            out = np.empty((0, ny)), False, 0, "CyRK returned no result"
            return (*out, None) if dense else out
        kept = False
        try:
            ok = bool(ns.c_get_success(ptr))
            n = int(ns.c_get_size(ptr))
            if n:  # the solution (n, ndy) copied into a kept buffer, then out of it
                ndy = int(ns.c_get_num_dy(ptr))
                out = self._out
                out.reserve(n * ndy)
                ctypes.memmove(out.address, self._y_at(ptr), 8 * n * ndy)
                X = out.array[:n * ndy].reshape(n, ndy)[:, :ny].copy()
            else:
                X = np.empty((0, ny))
            nfev = int(ctypes.c_double.from_address(self._args_at(ptr) + 8 * (nd - 1)).value
                       - float(data[-1]))
            status = int(ns.c_get_status(ptr))
            msg = self._messages.get(status)
            if msg is None:  # (CyRK sets the message from the status code: read once each)
                ns.c_get_msg_buf(ptr, self._msg_p, 256)
                msg = self._messages[status] = self._msg.value.decode(errors="replace")
            if dense:
                kept = True
                return X, ok, nfev, msg, DenseInterval(ptr, ny, self._dense_y)
        finally:
            if not kept:
                ns.c_free(ptr)
        return X, ok, nfev, msg


class DenseInterval:
    """CyRK's dense output of one integration (:func:`solve_chunk` with ``dense``): call it
    at a time [s] inside the integrated span for the state (N,); :meth:`free` releases
    CyRK's solution."""

    def __init__(self, ptr, n: int, buffer: _Buffer | None = None):
        self.ptr, self.n = ptr, n
        # where CyRK writes the state (a caller's buffer that dense outputs may share: each
        # call copies the state out at once)
        self._buffer = _Buffer() if buffer is None else buffer
        self._buffer.reserve(n)

    def __call__(self, t: float) -> np.ndarray:
        _api()[0].c_call(self.ptr, float(t), self._buffer.address)
        return self._buffer.array[:self.n].copy()

    def free(self) -> None:
        if self.ptr:
            _api()[0].c_free(self.ptr)
            self.ptr = None
