"""The rigid closed loop under virtual constraints, compiled: a numba ``cfunc`` right-hand
side (the signature of :mod:`walkerlab.codegen.compiled`'s flows) of the walker's flow with
the computed torque of its controller, and its variational equations.

Equations (Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56, Sec. IV-V)::

    q'' = M^-1 (-C q' - G) + M^-1 B u(x),
    u = (L_g L_f h)^-1 (-L_f^2 h - kp y - kd y')   (saturated at max_torque_n_m)

with ``M`` and ``-C q' - G`` the controller's compiled ``flow_terms`` and ``u``, ``M^-1 B u``
its compiled ``law`` (:func:`walkerlab.codegen.virtual_constraints.compiled_controller`: the
same derivation as the walker's generated flow, and the same law the Python flow adds, so
the two right-hand sides agree to round-off).  The variational right-hand side gives
``dPhi/dt = A(x) Phi`` with the closed loop's Jacobian ``A`` by the complex step (Squire &
Trapp 1998, SIAM Rev. 40(1):110-112) through the same compiled functions, which take complex
states: exact to round-off, as the Python flow's complex-step Jacobian.

The module is generated per compiled controller module (file ``<hash>_vcflow.py`` in the
user cache, its hash of the controller module's name and this module's source); its data
vector (:meth:`walkerlab.models.compiled_flows.VirtualConstraintFlow.data`): ``[theta+,
theta- - theta+, kp, kd, limit (-1: none), M + 1, B (n k, row-major), alpha (k (M + 1),
row-major), call counter]``.
"""

from __future__ import annotations

import hashlib

from walkerlab import codestore

__all__ = ["closed_loop_module"]

#: The module of :func:`closed_loop_module` (``{law}``: the compiled controller's module name).
_SOURCE = '''# walkerlab: the rigid closed loop under virtual constraints, compiled
# (walkerlab.codegen.virtual_constraint_flow.closed_loop_module)
import numpy as np
from numba import carray, cfunc, njit, types

from {law} import K, N, flow_terms as _flow_terms, law as _law

SIG = types.void(types.CPointer(types.float64), types.float64,
                 types.CPointer(types.float64), types.CPointer(types.float64))
#: entries of the data vector before B: theta+, theta- - theta+, kp, kd, limit, M + 1
HEAD = 6
#: the complex step of the variational equations' Jacobian
STEP = 1e-30


@njit(cache=True, error_model="numpy")
def data_size(d):
    """The data vector's length (its call counter last) from its head."""
    return HEAD + N * K + K * int(d[5]) + 1


@njit(cache=True, error_model="numpy")
def closed_loop(x, d, dx):
    """``dx`` (2N,) = ``(q', M^-1 (-C q' - G) + M^-1 B u)`` at ``x`` (2N,), real or
    complex."""
    m1 = int(d[5])
    B = d[HEAD:HEAD + N * K].copy().reshape((N, K))
    alpha = d[HEAD + N * K:HEAD + N * K + K * m1].copy().reshape((K, m1))
    Mm = np.empty((N, N), dtype=x.dtype)
    f = np.empty(N, dtype=x.dtype)
    _flow_terms(x, Mm, f)
    _u, acc = _law(x, alpha, d[0], d[1], B, d[2], d[3], d[4])
    qdd = np.linalg.solve(Mm, f)
    for i in range(N):
        dx[i] = x[N + i]
        dx[N + i] = qdd[i] + acc[i]


@njit(cache=True, error_model="numpy")
def closed_loop_variational(y, d, dy):
    """``dy`` = the flow (2N,) and ``A(x) Phi`` (row-major) at ``y = [x, Phi]``."""
    m = 2 * N
    x = y[:m].copy()
    f = np.empty(m)
    closed_loop(x, d, f)
    dy[:m] = f
    A = np.empty((m, m))
    xc = x.astype(np.complex128)
    fc = np.empty(m, dtype=np.complex128)
    for c in range(m):
        xc[c] = x[c] + 1j * STEP
        closed_loop(xc, d, fc)
        for r in range(m):
            A[r, c] = fc[r].imag / STEP
        xc[c] = x[c]
    for i in range(m):
        for j in range(m):
            s = 0.0
            for k in range(m):
                s += A[i, k] * y[m + k * m + j]
            dy[m + i * m + j] = s


def flow(dy, t, y, d):  # pragma: no cover - runs compiled
    size = data_size(carray(d, (HEAD,)))
    dd = carray(d, (size,))
    closed_loop(carray(y, (2 * N,)), dd, carray(dy, (2 * N,)))
    dd[size - 1] += 1.0


def flow_variational(dy, t, y, d):  # pragma: no cover - runs compiled
    size = data_size(carray(d, (HEAD,)))
    dd = carray(d, (size,))
    m = 2 * N
    closed_loop_variational(carray(y, (m + m * m,)), dd, carray(dy, (m + m * m,)))
    dd[size - 1] += 1.0


_LAZY = {{}}


def cfunc_of(name):
    """The cfunc ``name`` (compiled, or loaded from numba's cache, on first use)."""
    if name not in _LAZY:
        _LAZY[name] = cfunc(SIG, cache=True, error_model="numpy")(globals()[name])
    return _LAZY[name]
'''


def closed_loop_module(law_module):
    """The generated module of the compiled closed loop (module docstring) of the compiled
    controller module ``law_module``
    (:meth:`walkerlab.models.virtual_constraints.VirtualConstraintController.
    compiled_module`): ``flow`` and ``flow_variational`` made cfuncs by ``cfunc_of(name)``.

    Raises
    ------
    ImportError
        numba is not installed.
    """
    source = _SOURCE.format(law=law_module.__name__)
    h = hashlib.sha256(source.encode())
    h.update(codestore.source_hash(__file__).encode())
    tag = h.hexdigest()[:24]
    return codestore.import_generated(f"{tag}_vcflow.py", f"walkerlab_vcflow_{tag}",
                                      lambda: source)
