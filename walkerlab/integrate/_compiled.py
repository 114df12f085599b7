"""``cyrk_compiled`` backend: one phase integrated by CyRK's C++ solver with a compiled RHS.

Internal module of :mod:`walkerlab.integrate.rigid`.  The phase's flow (or flow plus
variational equations) is the numba ``cfunc`` of
:class:`walkerlab.models.compiled_flows.CompiledFlow`, handed to CyRK's C entry point
(``CyRK.nb.numba_solver.c_numba_cysolve_ivp``, through ctypes as in
:mod:`walkerlab.models.contact._cyrk`), so the Runge-Kutta steps run without Python
callbacks.

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

from .work_limit import count

EPS = np.finfo(float).eps
_NS: list = []  # CyRK's numba bridge, once imported


def _numba_solver():
    """CyRK's numba bridge (``CyRK.nb.numba_solver``), imported on first use with numba's
    cache pointed at the user cache first (:func:`walkerlab.usercache.use_for_numba`)."""
    if not _NS:
        from walkerlab.usercache import use_for_numba

        use_for_numba()  # numba's cache in the user cache (before numba loads)
        from CyRK.nb import numba_solver

        _NS.append(numba_solver)
    return _NS[0]
FIRST_CHUNK_STEPS = 24
#: How a phase's step count n scales with the tolerance, ``n ~ rtol ** (-1 / order)``: DOP853
#: 9 (measured on the flat foot's modes from rtol 1e-8 to 1e-12: x1.29-1.35 per decade),
#: RK45 5 and RK23 3 (their error orders + 1).
STEP_COUNT_ORDER = {"DOP853": 9.0, "RK45": 5.0, "RK23": 3.0}
#: Span of the run that repeats a crossing step with dense output [steps of that size]:
#: just over the 2 CyRK needs to take the first step as given.
REDO_SPAN_STEPS = 2.0 + 1e-9


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
    ``(t,) -> (rows,)``, ``(k,) -> (rows, k)``: the integrated state's ``rows``, as the
    Python backends' dense output (the cfunc's ``m`` outputs end with the guards' values,
    its extra outputs, which stay inside).

    Pieces are ``(t_a, t_b, result or recipe)``; a recipe (the arguments of a CyRK run that
    repeats steps already taken, now with dense output) is run on the first call only, so a
    Poincaré map that never samples its trajectory does not pay for it."""

    def __init__(self, m: int, rows: int | None = None):
        self.m = m
        self.rows = m if rows is None else rows
        self.pieces: list[list] = []

    def _result(self, piece) -> _Result:
        if not isinstance(piece[2], _Result):
            piece[2] = _solve(*piece[2], *piece[3:])[0]
        return piece[2]

    def _fill(self, times: np.ndarray, out: np.ndarray) -> None:
        """The dense state at each of ``times`` (k,) into the columns of ``out`` (rows, k):
        one CyRK call per time, no Python per call beyond it."""
        ns = _numba_solver()

        call, last = ns.c_call, len(self.pieces) - 1
        if last < 0:
            raise ValueError("no dense output")  # pragma: no cover
        row = np.empty(self.m)
        addr = _address(row)
        for c, t in enumerate(times.tolist()):
            for j, piece in enumerate(self.pieces):
                ta, tb = piece[0], piece[1]
                if t <= tb or j == last:
                    call(self._result(piece).ptr, min(max(t, ta), tb), addr)
                    out[:, c] = row[:out.shape[0]]  # the state (the guards after it)
                    break

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        out = np.empty((self.rows, t.size))
        self._fill(t.ravel(), out)
        return out[:, 0] if t.ndim == 0 else out


_BYTE = ctypes.c_char.from_buffer
_ADDRESS = ctypes.addressof


def _address(a: np.ndarray) -> int:
    """The address of the data of the writable C-contiguous array ``a`` (as ``a.ctypes.data``,
    without building numpy's ctypes helper object per call)."""
    try:
        return _ADDRESS(_BYTE(a))
    except (TypeError, ValueError, BufferError):  # empty or read-only: numpy's way
        return a.ctypes.data


_NO_TIMES = np.empty(0)
_NO_TIMES_PTR = _NO_TIMES.ctypes.data


def _solve(addr, data, t0, t1, y0, method_int, tols, hmax, max_steps, first_step, dense,
           n_extra=0):
    """One CyRK run; returns ``(result, T (k,), Y (k, m + n_extra), ok, message, nfev)``.
    ``tols``: :attr:`_Plan.tols` (the tolerance arrays' addresses and sizes)."""
    ns = _numba_solver()

    y0 = np.ascontiguousarray(y0, dtype=np.float64)
    c0 = data[-1]
    ptr = ns.c_numba_cysolve_ivp(
        addr, float(t0), float(t1), _address(y0), y0.size, method_int, 0, n_extra,
        _address(data), data.size * 8, max_steps, 2000, dense, _NO_TIMES_PTR, 0,
        None, None, 0, tols[0], tols[1], tols[2], tols[3], hmax,
        float(first_step), False)
    if not ptr:  # pragma: no cover - allocation failure inside CyRK
        return None, np.empty(0), np.empty((0, y0.size)), False, "CyRK returned no result", 0
    res = _Result(ptr, ns)
    k = int(ns.c_get_size(ptr))
    ndy = int(ns.c_get_num_dy(ptr))
    if k:  # the times and states copied into one block (one allocation)
        out = np.empty(k * (1 + ndy))
        at = _ADDRESS(_BYTE(out))
        ctypes.memmove(at, ns.c_get_t_ptr(ptr), 8 * k)
        ctypes.memmove(at + 8 * k, ns.c_get_y_ptr(ptr), 8 * k * ndy)
        T, Y = out[:k], out[k:].reshape(k, ndy)
    else:
        T, Y = np.empty(0), np.empty((0, ndy))
    # the call counter: the last entry of CyRK's copy of the data vector
    args = ctypes.addressof(ns.c_get_args_ptr(ptr).contents)
    nfev = int(ctypes.c_double.from_address(args + 8 * (data.size - 1)).value - c0)
    buf = ctypes.create_string_buffer(256)
    ns.c_get_msg_buf(ptr, ctypes.addressof(buf), 256)
    return (res, T, Y, bool(ns.c_get_success(ptr)), buf.value.decode(errors="replace"), nfev)


def _piece(addr, data, ta, tb, ya, method_int, tols, hmax, h0) -> list:
    """A lazy dense-output piece: the run from ``ta`` to ``tb`` again, first step ``h0``."""
    h0 = h0 if 2 * h0 <= tb - ta else 0.0
    return [float(ta), float(tb), (addr, data, ta, tb, ya, method_int, tols, hmax, 0, h0,
                                   True)]


def guard_values(compiled, t: float, x: np.ndarray) -> np.ndarray | None:
    """The phase's guards at one state ``x`` (2n,) at time ``t`` [s], from its compiled
    flow's extra outputs (one cfunc call, no Python flow: what a mode's entry check needs);
    None when the flow has no guard outputs (:attr:`CompiledFlow.guards` None).  The same
    functions as the Python guards, to round-off."""
    cols = compiled.guard_columns()
    if cols is None:
        return None
    memo = compiled._memo  # noqa: SLF001 - the flow's own cache, shared with its backend
    if "entry" not in memo:
        proto = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_double, ctypes.c_void_p,
                                 ctypes.c_void_p)
        memo["entry"] = proto(compiled.address(False))
    fn, data = memo["entry"], compiled.data()  # a fresh copy: the cfunc counts its calls
    y = np.ascontiguousarray(x, dtype=np.float64)
    out = np.empty(y.size + cols[0])
    fn(out.ctypes.data, float(t), y.ctypes.data, data.ctypes.data)
    return out[y.size + cols[1]] + cols[2]


def callable_flow(compiled, n: int, variational: bool):
    """The compiled flow as Python callables for scipy's ``solve_ivp`` (a stiff method such
    as LSODA, which CyRK does not have): ``(rhs, jac)``, ``rhs(t, y)`` one cfunc call (the
    flow (n,), or with ``variational`` the flow and ``A(x) Phi`` (n + n^2,), ``Phi``
    row-major), ``jac(t, y)`` the flow's Jacobian ``A`` (n, n) from the variational cfunc at
    ``Phi = I`` (None with ``variational``: the solver takes none then).  The same
    functions as the phase's Python flow and its Jacobian, to round-off; the data vector is
    read once here (a time-based law's step start is fixed for the phase).
    """
    proto = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_double, ctypes.c_void_p,
                             ctypes.c_void_p)
    cols = compiled.guard_columns()
    extra = 0 if cols is None else cols[0]
    data = compiled.data()
    fn = proto(compiled.address(variational))
    m = n + n * n if variational else n
    # the call's buffers, their addresses read once (numpy's ``.ctypes.data`` costs more
    # than the cfunc's call): the state copied in, the flow copied out; each closure holds
    # every buffer whose address it passes (``_alive``: the data vector, which the cfunc
    # writes its call count into, must outlive this frame)
    y_in, out = np.empty(m), np.empty(m + extra)
    at_y, at_out, at_data = (int(a.ctypes.data) for a in (y_in, out, data))

    def rhs(t, y, _alive=data):
        y_in[:] = y
        fn(at_out, float(t), at_y, at_data)
        return out[:m].copy()

    if variational:
        return rhs, None
    fv = proto(compiled.address(True))
    y_jac, out_jac = np.empty(n + n * n), np.empty(n + n * n + extra)
    y_jac[n:] = np.eye(n).ravel()
    at_yj, at_oj = int(y_jac.ctypes.data), int(out_jac.ctypes.data)

    def jac(t, x, _alive=data):
        y_jac[:n] = x
        fv(at_oj, float(t), at_yj, at_data)
        return out_jac[n:n + n * n].reshape(n, n).copy()

    return rhs, jac


#: guard values up to which :func:`_first_crossing` compares in Python [-]
_SMALL_CROSSING = 48


def _first_crossing(G, dirs: np.ndarray):
    """First row ``k >= 1`` of guard values ``G`` (k, g) (an array, or its rows as lists)
    where a guard changes sign in its direction between rows ``k-1`` and ``k``
    (``solve_ivp``'s rule: ``up = g0 <= 0 <= g1``, ``down = g0 >= 0 >= g1``), and the mask
    of those guards; ``(None, None)`` if none.  A control period's few steps and guards are
    compared in Python (the same comparisons, without numpy's per-call overhead), a long
    chunk's by numpy."""
    if type(G) is list or G.size <= _SMALL_CROSSING:
        rows, ds = (G if type(G) is list else G.tolist()), dirs.tolist()
        before = rows[0]
        for k in range(1, len(rows)):
            after = rows[k]
            for g0, g1, d in zip(before, after, ds):
                if (d >= 0 and g0 <= 0 <= g1) or (d <= 0 and g0 >= 0 >= g1):
                    return k, np.array([(d >= 0 and a <= 0 <= b) or (d <= 0 and a >= 0 >= b)
                                        for a, b, d in zip(before, after, ds)])
            before = after
        return None, None
    nonpos, nonneg = G <= 0, G >= 0
    hit = nonpos[:-1] & nonneg[1:]
    hit &= dirs >= 0
    down = nonneg[:-1] & nonpos[1:]
    down &= dirs <= 0
    hit |= down
    rows = hit.any(axis=1)
    j = int(rows.argmax())
    if not rows[j]:
        return None, None
    return j + 1, hit[j]


def first_chunk(compiled, solver) -> int:
    """Steps of the first chunk of a phase [-]: the flow's ``first_chunk_steps`` (default
    :data:`FIRST_CHUNK_STEPS`), scaled, when the flow gives the tolerance it was measured at
    (``chunk_rtol``), as a phase's step count scales with the tolerance:
    ``(rtol / chunk_rtol) ** (-1 / STEP_COUNT_ORDER[method])``.  The chunk depends on the
    flow and the solver only, never on earlier runs (results do not depend on history)."""
    k = getattr(compiled, "first_chunk_steps", FIRST_CHUNK_STEPS)
    ref = getattr(compiled, "chunk_rtol", None)
    order = STEP_COUNT_ORDER.get(solver.method)
    if ref is None or order is None:
        return k
    return max(2, int(np.ceil(k * (float(solver.rtol) / ref) ** (-1.0 / order))))


class _Plan:
    """What every run of one compiled phase on one solver shares (built once, kept on the
    flow: its cfunc's address, CyRK's method and tolerances, the guards' columns; not the
    data vector, which a time-based torque law changes each step): a mode switch then costs
    the runs, not their set-up."""

    def __init__(self, compiled, variational: bool, solver, m: int):
        from CyRK.cy.pyhelpers import find_ode_method_int

        self.ns = ns = _numba_solver()
        self.addr = compiled.address(variational)
        self.method_int = find_ode_method_int(solver.method)
        self.rtol = np.array([float(solver.rtol)])
        self.atol = np.ascontiguousarray(np.atleast_1d(solver.atol), dtype=np.float64)
        #: the tolerances as CyRK takes them (addresses and sizes, read once), then the
        #: arrays themselves (kept alive by whatever holds the tuple: a lazy dense piece)
        self.tols = (self.rtol.ctypes.data, self.rtol.size, self.atol.ctypes.data,
                     self.atol.size, self.rtol, self.atol)
        self.hmax = float(solver.max_step_s) if solver.max_step_s else ns.MAX_SIZE
        self.K = first_chunk(compiled, solver)
        cols = compiled.guard_columns()
        self.cols = cols is not None
        self.n_extra, self.gcol, self.goff = (cols[0], cols[1] + m, cols[2]) if cols \
            else (0, None, None)
        self._guards = None  # (guards, their directions, their functions): guard_arrays
        #: each guard's (column, offset) as Python numbers (a few step points' values)
        self.guard_cols = list(zip(self.gcol.tolist(), self.goff.tolist())) if cols else []

    def guard_arrays(self, guards) -> tuple:
        """``(directions (g,), functions)`` of the phase's ``guards`` (the last guards'
        kept: the same guards, the same arrays)."""
        key, seen = tuple(guards), self._guards
        if seen is None or seen[0] != key:
            seen = self._guards = (key, np.array([g.direction for g in key]),
                                   [g.function for g in key])
        return seen[1], seen[2]

    def guard_values(self, T, Y):
        """The guards' values at the step points ``Y`` (k, m + n_extra): an array (k, g),
        or for a few step points their rows as lists (the same sums in Python), or None
        when no guard can change sign between them (each guard's values all above 0, or
        all below: :func:`_first_crossing` would find nothing)."""
        cols = self.guard_cols
        if T.size * len(cols) > _SMALL_CROSSING:
            return Y[:, self.gcol] + self.goff
        by_guard = [[v + o for v in Y[:, c].tolist()] for c, o in cols]
        for col in by_guard:  # (a NaN makes min or max NaN, or is left out of both)
            if not (min(col) > 0.0 or max(col) < 0.0):
                return [list(g) for g in zip(*by_guard)]
        return None

    def run(self, data, ta, tb, ya, max_steps, first_step, dense):
        """:func:`_solve` from ``ya`` at ``ta`` towards ``tb`` with the flow's ``data``."""
        return _solve(self.addr, data, ta, tb, ya, self.method_int, self.tols,
                      self.hmax, max_steps, first_step, dense, self.n_extra)

    def piece(self, data, ta, tb, ya, h0) -> list:
        """:func:`_piece` of this phase."""
        return _piece(self.addr, data, ta, tb, ya, self.method_int, self.tols,
                      self.hmax, h0) + [self.n_extra]


def _plan(compiled, variational: bool, solver, m: int) -> _Plan:
    """The :class:`_Plan` of ``compiled`` on ``solver`` (memoised on the flow)."""
    memo = getattr(compiled, "_memo", None)
    if memo is None:
        return _Plan(compiled, variational, solver, m)
    # this very (frozen) solver's plan first: its settings' key is built once
    seen = memo.get(("plan of", id(solver), variational, m))
    if seen is not None and seen[0] is solver:
        return seen[1]
    key = ("plan", variational, solver.method, float(solver.rtol),
           tuple(np.atleast_1d(solver.atol).tolist()), solver.max_step_s, m)
    if key not in memo:
        memo[key] = _Plan(compiled, variational, solver, m)
    memo[("plan of", id(solver), variational, m)] = (solver, memo[key])
    return memo[key]


def _crossing(plan: _Plan, data, T, Y, k: int, active, fns, n: int, m: int, dense, h0):
    """The phase's end at the first crossing, between steps ``k-1`` and ``k`` of the chunk
    ``(T, Y)``: that step again with dense output, the earliest root of the ``active``
    guards on it (Brent).  Returns ``(t, y (m,), failed, message or '', event, nfev)``."""
    from walkerlab.integrate.brentq import brentq

    # the step T[k-1] -> T[k] again, with dense output (CyRK wants a first step of at most
    # half the span, so the span is a little over 2 steps: T[k-1] + 2 hk can round below
    # 2 hk, and CyRK then refuses the first step; the step after it, about hk, is unused:
    # a longer span costs more unused steps)
    hk = T[k] - T[k - 1]
    step, _, _, ok1, msg1, nf1 = plan.run(data, T[k - 1], T[k - 1] + REDO_SPAN_STEPS * hk,
                                          Y[k - 1, :m], 0, hk, True)
    if not ok1:  # pragma: no cover - the step was accepted once already
        return float(T[k - 1]), Y[k - 1, :m], True, msg1, None, nf1
    if k > 1:  # the steps before it, run again with dense output on demand
        dense.pieces.append(plan.piece(data, T[0], T[k - 1], Y[0, :m], h0))
    dense.pieces.append([float(T[k - 1]), float(T[k]), step])
    out = np.empty(m + plan.n_extra)
    call, sp, op = plan.ns.c_call, step.ptr, _address(out)
    roots = []
    for i in np.flatnonzero(active):  # each g is used (by brentq) in its iteration only
        if plan.cols:
            def g(t, _c=int(plan.gcol[i]), _o=float(plan.goff[i]), _a=(call, sp, op), _y=out):
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
    return float(te), dense(te)[:m], False, "", i, nf1


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
    m = y0.size
    plan = _plan(compiled, variational, solver, m)
    data = compiled.data()  # CyRK copies it: never written here
    dirs, fns = plan.guard_arrays(guards)
    if plan.cols:
        values = plan.guard_values
    else:
        def values(T, Y):
            return np.array([[f(t, y[:n]) for f in fns] for t, y in zip(T, Y)])
    dense = CompiledDense(m + plan.n_extra, m)
    ta, ya, h0, nfev, K = float(t0), np.asarray(y0, float), 0.0, 0, plan.K
    while True:
        _res, T, Y, ok, msg, nf = plan.run(data, ta, t1, ya, K, h0, False)
        nfev += nf
        # the work bound (walkerlab.integrate.work_limit): no Python in the flow, so the
        # chunk's evaluations are counted after it, where it ended
        count(nf, float(T[-1]) if T.size else ta, Y[-1, :m] if T.size else ya)
        G = values(T, Y) if T.size > 1 else None
        k, active = (None, None) if G is None else _first_crossing(G, dirs)
        if k is not None:
            te, ye, failed, msg1, i, nf1 = _crossing(plan, data, T, Y, k, active, fns, n, m,
                                                     dense, h0)
            count(nf1, te, ye)
            return te, ye, failed, msg1 or msg, i, dense, nfev + nf1
        if T.size > 1:
            dense.pieces.append(plan.piece(data, T[0], T[-1], Y[0, :m], h0))
        if ok or T.size < 2 or T[-1] >= t1:
            return (float(T[-1]) if T.size else ta, Y[-1, :m] if T.size else ya, not ok, msg,
                    None, dense, nfev)
        # stopped on the step limit: continue from the last step
        ta, ya, h0, K = float(T[-1]), Y[-1, :m], float(T[-1] - T[-2]), 2 * K
        if 2 * h0 > t1 - ta:
            h0 = 0.0
