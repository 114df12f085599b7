"""``cyrk_compiled`` backend: one phase integrated by CyRK's C++ solver with a compiled RHS.

Internal module of :mod:`walkerlab.integrate.rigid`.  The phase's flow (or flow plus
variational equations) is the numba ``cfunc`` of :class:`walkerlab.codegen.compiled.CompiledFlow`,
handed to CyRK's C entry point (``CyRK.nb.numba_solver.c_numba_cysolve_ivp``, through ctypes
as in :mod:`walkerlab.models.contact._cyrk`), so the Runge-Kutta steps run without Python callbacks.

CyRK's numba bridge takes no events, so guards are located here with scipy's rules:

1. integrate towards ``t1`` at most ``K`` steps at a time (``K = K0, 2 K0, ...``, ``K0`` the
   flow's ``first_chunk_steps``, :data:`FIRST_CHUNK_STEPS` by default; a chunk that
   stops on the step limit continues from its last step, with that step's size as first step);
   the chunk boundaries depend on the step count only, so results do not depend on history;
2. evaluate the phase's guards (Python functions) at the step points and find the first step
   whose end changes a guard's sign in its direction (``solve_ivp``'s ``find_active_events``:
   ``up = g0 <= 0 <= g1``, ``down = g0 >= 0 >= g1``);
3. redo that one step (same start, same step size: the same step, now with dense output, which
   CyRK gives only for a finished run) and locate the root with ``scipy.optimize.brentq``
   (``xtol = rtol = 4 eps``, as ``solve_ivp``) on the dense output; the earliest root ends the
   phase.
"""

from __future__ import annotations

import ctypes

import numpy as np

EPS = np.finfo(float).eps
FIRST_CHUNK_STEPS = 24


class _Result:
    """Owns one CyRK ``CySolverResult*`` (freed with the object)."""

    def __init__(self, ptr, ns):
        self.ptr, self._ns = ptr, ns

    def __del__(self):
        if self.ptr:
            self._ns.c_free(self.ptr)
            self.ptr = None


class CompiledDense:
    """Dense output of a compiled phase, scipy's ``OdeSolution`` calling convention:
    ``(t,) -> (m,)``, ``(k,) -> (m, k)``.

    Pieces are ``(t_a, t_b, result or recipe)``; a recipe (the arguments of a CyRK run that
    repeats steps already taken, now with dense output) is run on the first call only, so a
    Poincaré map that never samples its trajectory does not pay for it."""

    def __init__(self, m: int):
        self.m = m
        self.pieces: list[list] = []

    def _result(self, piece) -> _Result:
        if not isinstance(piece[2], _Result):
            piece[2] = _solve(*piece[2], *piece[3:])[0]
        return piece[2]

    def _one(self, t: float) -> np.ndarray:
        from walkerlab.usercache import use_for_numba

        use_for_numba()  # numba's cache in the user cache (before numba loads)
        from CyRK.nb import numba_solver as ns

        for j, piece in enumerate(self.pieces):
            ta, tb = piece[0], piece[1]
            if t <= tb or j == len(self.pieces) - 1:
                out = np.empty(self.m)
                ns.c_call(self._result(piece).ptr, float(min(max(t, ta), tb)), out.ctypes.data)
                return out  # state, then the guards (extra outputs) if any
        raise ValueError("no dense output")  # pragma: no cover

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        if t.ndim == 0:
            return self._one(float(t))
        return np.stack([self._one(float(s)) for s in t.ravel()], axis=1)


def _solve(addr, data, t0, t1, y0, method_int, rtol, atol, hmax, max_steps, first_step, dense,
           n_extra=0):
    """One CyRK run; returns ``(result, T (k,), Y (k, m + n_extra), ok, message, nfev)``."""
    from walkerlab.usercache import use_for_numba

    use_for_numba()  # numba's cache in the user cache (before numba loads)
    from CyRK.nb import numba_solver as ns

    y0 = np.ascontiguousarray(y0, dtype=np.float64)
    te = np.empty(0)
    c0 = data[-1]
    ptr = ns.c_numba_cysolve_ivp(
        addr, float(t0), float(t1), y0.ctypes.data, y0.size, method_int, 0, n_extra,
        data.ctypes.data, data.size * 8, max_steps, 2000, dense, te.ctypes.data, 0,
        None, None, 0, rtol.ctypes.data, rtol.size, atol.ctypes.data, atol.size, hmax,
        float(first_step), False)
    if not ptr:  # pragma: no cover - allocation failure inside CyRK
        return None, np.empty(0), np.empty((0, y0.size)), False, "CyRK returned no result", 0
    res = _Result(ptr, ns)
    k = int(ns.c_get_size(ptr))
    ndy = int(ns.c_get_num_dy(ptr))
    T = np.ctypeslib.as_array(ns.c_get_t_ptr(ptr), (k,)).copy() if k else np.empty(0)
    Y = (np.ctypeslib.as_array(ns.c_get_y_ptr(ptr), (k, ndy)).copy() if k
         else np.empty((0, ndy)))
    args = ctypes.cast(ns.c_get_args_ptr(ptr), ctypes.POINTER(ctypes.c_double))
    nfev = int(args[data.size - 1] - c0)
    buf = ctypes.create_string_buffer(256)
    ns.c_get_msg_buf(ptr, ctypes.addressof(buf), 256)
    return (res, T, Y, bool(ns.c_get_success(ptr)), buf.value.decode(errors="replace"), nfev)


def _piece(addr, data, ta, tb, ya, method_int, rtol, atol, hmax, h0) -> list:
    """A lazy dense-output piece: the run from ``ta`` to ``tb`` again, first step ``h0``."""
    h0 = h0 if 2 * h0 <= tb - ta else 0.0
    return [float(ta), float(tb), (addr, data, ta, tb, ya, method_int, rtol, atol, hmax, 0, h0,
                                   True)]


def _first_crossing(G: np.ndarray, dirs: np.ndarray):
    """First row ``k >= 1`` of guard values ``G`` (k, g) where a guard changes sign in its
    direction between rows ``k-1`` and ``k`` (``solve_ivp``'s rule), and the mask of those
    guards; ``(None, None)`` if none."""
    a, b = G[:-1], G[1:]
    up = (a <= 0) & (b >= 0) & (dirs >= 0)
    down = (a >= 0) & (b <= 0) & (dirs <= 0)
    hit = up | down
    rows = np.flatnonzero(hit.any(axis=1))
    if rows.size == 0:
        return None, None
    return int(rows[0]) + 1, hit[rows[0]]


def solve_phase(compiled, variational: bool, t0: float, t1: float, y0: np.ndarray, guards,
                n: int, solver):
    """Integrate one phase with the compiled RHS until its first guard fires or ``t1``.

    Parameters
    ----------
    compiled : CompiledFlow
        With ``guards``, the guards are the cfunc's extra outputs; else the Python functions
        of ``guards`` are called at each step point.
    variational : bool
        ``y0`` is ``[x (n,), Phi (n*n,)]`` and the variational cfunc is used.
    t0, t1 : float
        Start and latest end time [s].
    y0 : ndarray (m,)
    guards : sequence of Guard
        The phase's guards (functions of ``y[:n]``).
    n : int
        State dimension.
    solver : Solver
        ``method`` (a CyRK explicit pair), ``rtol``, ``atol``, ``max_step_s``.

    Returns
    -------
    t_last, y_last (m,), failed, message, event index or None, dense, nfev
    """
    from walkerlab.usercache import use_for_numba

    use_for_numba()  # numba's cache in the user cache (before numba loads)
    from CyRK.cy.pyhelpers import find_ode_method_int
    from CyRK.nb import numba_solver as ns
    from scipy.optimize import brentq

    addr = compiled.address(variational)
    data = compiled.data()
    method_int = find_ode_method_int(solver.method)
    rtol = np.array([float(solver.rtol)])
    atol = np.ascontiguousarray(np.atleast_1d(solver.atol), dtype=np.float64)
    hmax = float(solver.max_step_s) if solver.max_step_s else ns.MAX_SIZE
    m = y0.size
    cols = compiled.guard_columns()
    dirs = np.array([g.direction for g in guards])
    fns = [g.function for g in guards]
    if cols is not None:
        n_extra, gcol, goff = cols
        gcol = gcol + m

        def values(T, Y):
            return Y[:, gcol] + goff
    else:
        n_extra = 0

        def values(T, Y):
            return np.array([[f(t, y[:n]) for f in fns] for t, y in zip(T, Y)])
    dense = CompiledDense(m + n_extra)
    ta, ya, h0, nfev = float(t0), np.asarray(y0, float), 0.0, 0
    K = getattr(compiled, "first_chunk_steps", FIRST_CHUNK_STEPS)
    while True:
        res, T, Y, ok, msg, nf = _solve(addr, data, ta, t1, ya, method_int, rtol, atol, hmax,
                                        K, h0, False, n_extra)
        nfev += nf
        k, active = _first_crossing(values(T, Y), dirs) if T.size > 1 else (None, None)
        if k is not None:
            # the step T[k-1] -> T[k] again, with dense output (CyRK wants a first step of
            # at most half the span, so the span is 3 steps: T[k-1] + 2 hk can round below
            # 2 hk, and CyRK then refuses the first step; the steps after it are unused)
            hk = T[k] - T[k - 1]
            step, _, _, ok1, msg1, nf1 = _solve(addr, data, T[k - 1], T[k - 1] + 3 * hk,
                                                 Y[k - 1, :m], method_int, rtol, atol, hmax, 0,
                                                 hk, True, n_extra)
            nfev += nf1
            if not ok1:  # pragma: no cover - the step was accepted once already
                return float(T[k - 1]), Y[k - 1, :m], True, msg1, None, dense, nfev
            if k > 1:  # the steps before it, run again with dense output on demand
                dense.pieces.append(_piece(addr, data, T[0], T[k - 1], Y[0, :m], method_int,
                                           rtol, atol, hmax, h0) + [n_extra])
            dense.pieces.append([float(T[k - 1]), float(T[k]), step])
            out = np.empty(m + n_extra)
            call, sp, op = ns.c_call, step.ptr, out.ctypes.data
            roots = []
            for i in np.flatnonzero(active):  # each g is used (by brentq) in its iteration only
                if cols is not None:
                    def g(t, _c=int(gcol[i]), _o=float(goff[i]), _a=(call, sp, op), _y=out):
                        _a[0](_a[1], t, _a[2])
                        return _y[_c] + _o
                else:
                    def g(t, _f=fns[i], _a=(call, sp, op), _y=out):
                        _a[0](_a[1], t, _a[2])
                        return _f(t, _y[:n])
                gk = g(T[k])
                roots.append((float(T[k]) if gk == 0.0 else
                              brentq(g, T[k - 1], T[k], xtol=4 * EPS, rtol=4 * EPS), int(i)))
            te, i = min(roots)
            return float(te), dense(te)[:m], False, msg, i, dense, nfev
        if T.size > 1:
            dense.pieces.append(_piece(addr, data, T[0], T[-1], Y[0, :m], method_int, rtol, atol,
                                       hmax, h0) + [n_extra])
        if ok or T.size < 2 or T[-1] >= t1:
            return (float(T[-1]) if T.size else ta, Y[-1, :m] if T.size else ya, not ok, msg,
                    None, dense, nfev)
        # stopped on the step limit: continue from the last step
        ta, ya, h0, K = float(T[-1]), Y[-1, :m], float(T[-1] - T[-2]), 2 * K
        if 2 * h0 > t1 - ta:
            h0 = 0.0
