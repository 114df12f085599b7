"""One phase of many rows, each integrated on its own by a compiled DOP853 to its first guard
crossing: the inner loop of :class:`walkerlab.integrate.batch_step.BatchStepMap`.

Every row is integrated alone (its own step sizes; no stacked system), by Dormand & Prince's
DOP853 (Hairer, Nørsett & Wanner, "Solving Ordinary Differential Equations I", 2nd ed. 1993,
sec. II.10) with scipy's coefficients (``scipy.integrate.DOP853``'s class attributes) and
scipy's step-size control (safety 0.9, factor in [0.2, 10], exponent -1/8, the first step
by ``select_initial_step``'s rule).  The error norm is the 2-norm over the row's components of
the scaled error (``atol + rtol max(|y|, |y_new|)``): the criterion
:class:`~walkerlab.integrate.batch_step.BatchStepMap` has always asked of each row (the 2-norm
equals scipy's RMS norm at tolerances divided by ``sqrt(2n)``).

The flow is the walker's compiled ``cfunc`` ``(dy, t, y, d)``
(:class:`walkerlab.models.compiled_flows.CompiledFlow`), called as a first-class function or by
its process address (an ``int``: :func:`_call_address`, the same machine code); its
extra outputs are the guards (``G[gcols] + goffs``).  Where the generated module has them
(:func:`cfuncs`), a step's inner stages call the flow without its guard outputs and a
crossing is located on one guard's cfunc: the same values bit for bit, fewer operations
(the guards are needed only at the ends of a step).  Where the generated module has them
(:func:`kernels`), the same loops are compiled with that
module's functions as ``@njit`` functions on arrays instead (:func:`_call` takes either kind): numba
compiles a loop once per function it is given, so the flow is inlined into the loop
(measured on the paper walker's Monte Carlo walks: ~40 % less CPU per heel strike than
calling the cfunc), with the same numbers bit for bit.  The functions that hand the flow on
are inlined into their callers by numba (``inline="always"``): a function value passed from
one compiled function to another is a process address in the machine code, which numba
will not cache, and inlined it is only called.  A guard ends the phase when it changes
sign in its direction over an accepted step (``up``: from <= 0 to >= 0, ``down``: from >= 0 to
<= 0, ``solve_ivp``'s rule); the crossing is located on the step's 7th-order dense output by
the Illinois method (bracketing regula falsi) to 1e-15 s, and the first crossing of all the
row's guards wins (ties: the first guard).

Row outcomes (``which``): the guard index, :data:`TIMEOUT` (``t`` reached the row's cap
without a crossing) or :data:`FAILED` (the step size fell below 10 ulp of ``t``).

Why not CyRK's DOP853 (a dependency, compiled, with dense output): the one CyRK entry point
a compiled loop can call, its numba bridge (``CyRK.nb.numba_solver.c_numba_cysolve_ivp``,
what ``nbsolve2_ivp`` calls), takes no events, and CyRK's events exist only for
``pysolve_ivp`` (a Python right-hand side, called per stage) and ``cysolve_ivp`` (Cython
callers only).  A Monte Carlo walk on CyRK therefore calls the solver once per time span
of a step, has it build a solver and keep every step and its dense output on the heap,
checks the guards on the kept steps and locates the heel strike through CyRK's
dense-output calls; every call restarts the step-size selection.  How long a span should
be depends on the gait: too short and a step takes a second call, too long and the walker
(no impact applied) is integrated on past the heel strike into its fall.  Measured side by
side in one process (``scripts/bench_mc_cyrk.py``: the same slopes, start, step cap and
accuracy; the same walks and falls), CyRK with the span tuned to the paper walker's step
was no faster than this module and at the Monte Carlo's allowance over the minimal numba
loop (:mod:`walkerlab.bench.monte_carlo_yardstick`), and several times slower with a span that
does not suit the step; a span rule for every walker and every phase of this module's
rows (several guards, the kneed and flat-foot phases) would have to be found first.  So
this loop stays.  It is also what every stored Monte Carlo result was computed with
(CyRK's step-size control and error norm differ: its numbers would not be bit-identical).
"""

from __future__ import annotations

from walkerlab import codestore
from walkerlab.usercache import use_for_numba

use_for_numba()  # cache=True below: numba's cache in the user cache, not in the package

import functools  # noqa: E402
import hashlib  # noqa: E402
import inspect  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from llvmlite import ir  # noqa: E402
from numba import njit, types  # noqa: E402
from numba.extending import intrinsic, overload  # noqa: E402
from scipy.integrate import DOP853 as _SCIPY_DOP853  # noqa: E402

__all__ = ["TIMEOUT", "FAILED", "cfuncs", "kernels", "kernels_source", "period_rows",
           "phase_rows", "reset_rows", "source_hash", "walk_rows"]

#: ``which`` of a row that reached its time cap / whose step size collapsed
TIMEOUT, FAILED = -1, -2

NS = _SCIPY_DOP853.n_stages  # 12
A = np.zeros((16, 16))
A[:NS, :NS] = _SCIPY_DOP853.A
A[NS + 1:, :] = _SCIPY_DOP853.A_EXTRA
C = np.concatenate([_SCIPY_DOP853.C, [1.0], _SCIPY_DOP853.C_EXTRA])
B = np.ascontiguousarray(_SCIPY_DOP853.B)
E3 = np.ascontiguousarray(_SCIPY_DOP853.E3)
E5 = np.ascontiguousarray(_SCIPY_DOP853.E5)
DD = np.ascontiguousarray(_SCIPY_DOP853.D)


def cfuncs(module, name: str, flow) -> tuple:
    """``(f, fs, fg, sel)`` of :func:`phase_rows` for the cfunc ``flow`` named ``name`` of
    the compiled ``module`` (:mod:`walkerlab.codegen.compiled`): with its guard-free twin and the
    one-guard cfunc when the module has them (``plain_flow``, ``guard_one``: the same
    values bit for bit), else ``flow`` for every role."""
    if hasattr(module, "plain_flow") and hasattr(module, "guard_one"):
        return (flow, module.plain_flow(name), module.guard_one(), True)
    return (flow, flow, flow, False)


def _call(fn, dy, t, y, d):
    """The flow ``fn`` of the walker at ``(t, y)`` (data vector ``d``) into ``dy``, in
    compiled code only (:func:`_call_impl`)."""
    raise TypeError("rows_dop853._call runs compiled only")  # pragma: no cover


@intrinsic
def _call_address(typingctx, addr, dy, t, y, d):  # pragma: no cover - compiled
    """The cfunc at the process address ``addr`` (``int``: its ``.address``, C signature
    ``void (double *dy, double t, double *y, double *d)``) on the arrays' data: the call a
    first-class function argument makes, without numba's boxing of that argument on every
    call of the compiled caller (:func:`walkerlab.gym.rigid_rows._period_rows`: ~3 us per
    function per call)."""
    if not (isinstance(addr, types.Integer) and all(
            isinstance(a, types.Array) and a.dtype == types.float64 for a in (dy, y, d))):
        return None
    sig = types.void(addr, dy, types.float64, y, d)

    def codegen(context, builder, signature, args):
        a, dya, tv, ya, da = args
        dbl = ir.DoubleType()
        fnty = ir.FunctionType(ir.VoidType(), [dbl.as_pointer(), dbl, dbl.as_pointer(),
                                                dbl.as_pointer()])
        fp = builder.inttoptr(a, fnty.as_pointer())

        def data(ty, val):
            return context.make_array(ty)(context, builder, val).data
        builder.call(fp, [data(signature.args[1], dya), tv, data(signature.args[3], ya),
                          data(signature.args[4], da)])
        return context.get_dummy_value()
    return sig, codegen


@overload(_call, inline="always", jit_options={"error_model": "numpy"})
def _call_impl(fn, dy, t, y, d):  # pragma: no cover - compiled
    """:func:`_call` for a cfunc ``(dy, t, y, d)`` (a first-class function on pointers) or
    an ``@njit`` function on the arrays (then compiled into its caller: one specialisation
    of the loop per function), inlined into the caller either way."""
    if isinstance(fn, types.Dispatcher):
        def on_arrays(fn, dy, t, y, d):
            fn(dy, t, y, d)
        return on_arrays
    if isinstance(fn, types.Integer):
        def at_address(fn, dy, t, y, d):
            _call_address(fn, dy, t, y, d)
        return at_address

    def on_pointers(fn, dy, t, y, d):
        fn(dy.ctypes, t, y.ctypes, d.ctypes)
    return on_pointers


@njit(cache=True, error_model="numpy")
def _guards(buf, m, gcols, goffs, g):  # pragma: no cover - compiled
    for j in range(gcols.size):
        g[j] = buf[m + gcols[j]] + goffs[j]


@njit(cache=True, error_model="numpy")
def _dense_at(F, y_old, x, out):  # pragma: no cover - compiled
    """Dense output at the fraction ``x`` of the step (scipy's ``Dop853DenseOutput``)."""
    m = out.size
    for k in range(m):
        out[k] = 0.0
    nF = F.shape[0]
    for i in range(nF):
        for k in range(m):
            out[k] += F[nF - 1 - i, k]
            out[k] *= x if i % 2 == 0 else (1.0 - x)
    for k in range(m):
        out[k] += y_old[k]


@njit(cache=True, error_model="numpy", inline="always")
def _stage(fs, t, h, y, K, d, s, out):  # pragma: no cover - compiled
    """Stage ``s`` of the step (the flow ``fs``): its state ``out = y + h sum_j A[s, j]
    K[j]`` (j < s), its slope into ``K[s]``."""
    for k in range(y.size):
        acc = 0.0
        for j in range(s):
            acc += A[s, j] * K[j, k]
        out[k] = y[k] + h * acc
    _call(fs, K[s], t + C[s] * h, out, d)


@njit(cache=True, error_model="numpy", inline="always")
def _dense_coeffs(fs, t, h, y, ynew, K, d, F, tmp):  # pragma: no cover - compiled
    """The 3 extra stages (flow ``fs``) and the interpolant's coefficients ``F`` (7, m)
    of the step."""
    m = y.size
    for s in range(NS + 1, 16):
        _stage(fs, t, h, y, K, d, s, tmp)
    for k in range(m):
        dy = ynew[k] - y[k]
        F[0, k] = dy
        F[1, k] = h * K[0, k] - dy
        F[2, k] = 2.0 * dy - h * (K[NS, k] + K[0, k])
        for r in range(4):
            acc = 0.0
            for j in range(16):
                acc += DD[r, j] * K[j, k]
            F[3 + r, k] = h * acc


@njit(cache=True, error_model="numpy", inline="always")
def _guard_at(f, fg, sel, t, y, d, buf, gcols, goffs, j, gv):  # pragma: no cover - compiled
    """Guard ``j``'s value at ``(t, y)``: by the guard cfunc ``fg`` alone when ``sel``,
    else from the flow ``f``'s extra outputs (the same value)."""
    if sel:
        buf[0] = gcols[j]
        _call(fg, buf, t, y, d)
        return buf[0] + goffs[j]
    _call(f, buf, t, y, d)
    _guards(buf, y.size, gcols, goffs, gv)
    return gv[j]


@njit(cache=True, error_model="numpy", inline="always")
def _locate(f, fg, sel, F, y_old, t_old, h, d, buf, gcols, goffs, j, g0, g1, tmp,
            gv):  # pragma: no cover - compiled
    """Time of guard ``j``'s crossing in the step ``[t_old, t_old + h]`` (values ``g0``,
    ``g1`` at its ends), by the Illinois method on the dense output (guard values by
    :func:`_guard_at`)."""
    if g1 == 0.0:
        return t_old + h
    if g0 == 0.0:
        return t_old
    a, b, fa, fb = 0.0, 1.0, g0, g1
    x = 1.0
    side = 0
    for _ in range(200):
        x = (a * fb - b * fa) / (fb - fa)
        if not a < x < b:
            x = 0.5 * (a + b)
        _dense_at(F, y_old, x, tmp)
        fx = _guard_at(f, fg, sel, t_old + x * h, tmp, d, buf, gcols, goffs, j, gv)
        if fx == 0.0:
            break
        if (fx > 0.0) == (fb > 0.0):
            b, fb = x, fx
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            a, fa = x, fx
            if side == 1:
                fb *= 0.5
            side = 1
        if (b - a) * abs(h) <= 1e-15 + 4.4e-16 * abs(t_old):
            break
    return t_old + x * h


@njit(cache=True, error_model="numpy", inline="always")
def _attempt(f, fs, t, y, h, K, d, ynew, rtol, atol):  # pragma: no cover - compiled
    """One DOP853 step of size ``h`` from ``(t, y)`` (``K[0]`` = f(t, y)), its stages by the
    flow ``fs``: ``ynew`` and the FSAL evaluation by ``f`` (flow and extra outputs) into
    ``K[NS]``; returns the error norm."""
    m = y.size
    for s in range(1, NS):
        _stage(fs, t, h, y, K, d, s, ynew)
    for k in range(m):
        acc = 0.0
        for j in range(NS):
            acc += B[j] * K[j, k]
        ynew[k] = y[k] + h * acc
    _call(f, K[NS], t + h, ynew, d)
    e5, e3 = 0.0, 0.0
    for k in range(m):
        sc = atol + rtol * max(abs(y[k]), abs(ynew[k]))
        a5, a3 = 0.0, 0.0
        for j in range(NS + 1):
            a5 += E5[j] * K[j, k]
            a3 += E3[j] * K[j, k]
        e5 += (a5 / sc) ** 2
        e3 += (a3 / sc) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / np.sqrt(e5 + 0.01 * e3)


@njit(cache=True, error_model="numpy", inline="always")
def _first_step(f, y, f0, d, buf, tmp, rtol, atol, span):  # pragma: no cover - compiled
    """scipy's ``select_initial_step`` (order 7, RMS norms)."""
    m = y.size
    d0, d1 = 0.0, 0.0
    for k in range(m):
        sc = atol + abs(y[k]) * rtol
        d0 += (y[k] / sc) ** 2
        d1 += (f0[k] / sc) ** 2
    d0, d1 = np.sqrt(d0 / m), np.sqrt(d1 / m)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, span)
    for k in range(m):
        tmp[k] = y[k] + h0 * f0[k]
    _call(f, buf, h0, tmp, d)
    d2 = 0.0
    for k in range(m):
        sc = atol + abs(y[k]) * rtol
        d2 += ((buf[k] - f0[k]) / sc) ** 2
    d2 = np.sqrt(d2 / m) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, span)


@njit(cache=True, error_model="numpy")
def _work(m, n_out, ng):  # pragma: no cover - compiled
    """The scratch arrays of :func:`_row` for rows of ``m`` states, ``n_out`` cfunc outputs
    and at most ``ng`` guards: ``K`` (16, n_out) stages (flow then extra outputs), ``F``
    (7, m) interpolant, ``buf`` (n_out,), ``ynew``, ``tmp`` (m,), ``G`` (3, ng) guard
    values (step start, step end, probe)."""
    return (np.empty((16, n_out)), np.empty((7, m)), np.empty(n_out), np.empty(m),
            np.empty(m), np.empty((3, ng)))


@njit(cache=True, error_model="numpy", inline="always")
def _row(f, fs, fg, sel, y, d, cap, gcols, goffs, dirs, rtol, atol, yev, h_first,
         work, exact, tn, yn):  # pragma: no cover - compiled
    """One row to its first guard crossing: ``(which, t_event, next step size)``, the state
    into ``yev``; ``f, fs, fg, sel``: the cfuncs (:func:`phase_rows`); ``h_first`` > 0: the
    first step size [s] (else scipy's choice); ``work``: :func:`_work`'s scratch arrays
    (allocated once per call of the caller, not per row).  ``exact``: the last step ends on
    ``cap`` (``solve_ivp``'s ``t_bound``) and a :data:`TIMEOUT` row's state there goes into
    ``yev``; else the steps run past ``cap`` as if unbounded (a cap is a walk's give-up
    time, not a sample) and ``yev`` is left as it was.  ``tn`` (q,) [s]: times inside the
    row's span (NaN: none) whose states the accepted steps' dense output writes into ``yn``
    (q, m) as the steps pass them, up to a guard crossing (the steps are the same with or
    without them)."""
    m = y.size
    ng = gcols.size
    K, F, buf, ynew, tmp, G = work
    g0, g1, gv = G[0], G[1], G[2]
    t, t_bound = 0.0, (cap if exact else cap + 1.0)
    _call(f, K[0], t, y, d)
    _guards(K[0], m, gcols, goffs, g0)
    if h_first > 0.0:
        h_abs = min(h_first, t_bound)
    else:
        h_abs = _first_step(fs, y, K[0], d, buf, tmp, rtol, atol, t_bound)
    while True:
        rejected = False
        while True:
            min_step = 10.0 * (np.nextafter(t, np.inf) - t)
            if h_abs < min_step:
                return FAILED, t, h_abs
            t_new = min(t + h_abs, t_bound)
            h = t_new - t
            err = _attempt(f, fs, t, y, h, K, d, ynew, rtol, atol)
            if err < 1.0:
                fac = 10.0 if err == 0.0 else min(10.0, 0.9 * err ** (-1.0 / 8.0))
                if rejected:
                    fac = min(1.0, fac)
                h_abs = h * fac
                break
            h_abs = h * max(0.2, 0.9 * err ** (-1.0 / 8.0))
            rejected = True
        _guards(K[NS], m, gcols, goffs, g1)
        best, te = -1, np.inf
        dense = False
        for j in range(ng):
            hit = ((g0[j] <= 0.0 and g1[j] >= 0.0 and dirs[j] >= 0)
                   or (g0[j] >= 0.0 and g1[j] <= 0.0 and dirs[j] <= 0))
            if not hit:
                continue
            if not dense:
                _dense_coeffs(fs, t, h, y, ynew, K, d, F, tmp)
                dense = True
            tj = _locate(f, fg, sel, F, y, t, h, d, buf, gcols, goffs, j, g0[j], g1[j], tmp,
                         gv)
            if tj < te:
                best, te = j, tj
        t_hi = te if best >= 0 else t_new
        for q in range(tn.size):  # the samples inside this step, up to a crossing
            if t < tn[q] <= t_hi:
                if not dense:
                    _dense_coeffs(fs, t, h, y, ynew, K, d, F, tmp)
                    dense = True
                _dense_at(F, y, (tn[q] - t) / h, yn[q])
        if best >= 0:
            _dense_at(F, y, (te - t) / h, yev)
            return best, te, h_abs
        if t_new >= cap:
            if exact:
                for k in range(m):
                    yev[k] = ynew[k]
            return TIMEOUT, t_new, h_abs
        for k in range(m):
            y[k] = ynew[k]
        K[0, :] = K[NS, :]
        for j in range(ng):
            g0[j] = g1[j]
        t = t_new


@njit(cache=True, error_model="numpy", inline="always")
def phase_rows(f, fs, fg, sel, Y, D, cap, gcols, goffs, dirs, rtol, atol, n_out, which, te,
               Yev, H, hs, hoff):  # pragma: no cover - compiled
    """Integrate every row of ``Y`` (N, m) [state units] with its data vector ``D[i]`` from
    phase time 0 to its first guard crossing (module docstring): ``f, fs, fg, sel``
    (:func:`cfuncs`; separate arguments: a tuple of functions is an experimental numba
    type), the cfuncs ``(dy, t, y, d)`` of the flow with its guard outputs ``f`` (a step's
    first and last evaluation), the flow alone ``fs`` (its other stages) and, when ``sel``,
    ``fg`` writing the guard column ``int(dy[0])`` into ``dy[0]`` (a crossing's location;
    else ``f``'s guard outputs); guard index or
    :data:`TIMEOUT` / :data:`FAILED` into ``which`` (N,), the time [s] into ``te`` (N,) and
    the state there into ``Yev`` (N, m).  ``cap`` (N,) [s]: time limits; ``gcols``, ``goffs``,
    ``dirs`` (g,): guard columns among the cfunc's extra outputs, offsets, directions;
    ``n_out``: outputs the cfunc writes (m + extra); ``H`` (N,) [s]: each row's first step
    size (<= 0: scipy's choice), overwritten with the step size it would take next (a row
    going on to the next phase starts with it).  ``hs`` >= 0: guard ``hs`` (the heel
    strike) of row ``i`` has ``hoff[i]`` added to its offset (a per-row landing height, the
    ground of that row's step: :meth:`walkerlab.integrate.batch_step.BatchStepMap.step`)."""
    work = _work(Y.shape[1], n_out, gcols.size)
    y = np.empty(Y.shape[1])
    go = goffs.copy()
    tn, yn = np.empty(0), np.empty((0, Y.shape[1]))
    for i in range(Y.shape[0]):
        y[:] = Y[i]
        if hs >= 0:
            go[hs] = goffs[hs] + hoff[i]
        w, t, h = _row(f, fs, fg, sel, y, D[i], cap[i], gcols, go, dirs, rtol, atol, Yev[i],
                       H[i], work, False, tn, yn)
        which[i] = w
        te[i] = t
        H[i] = h


@njit(cache=True, error_model="numpy", inline="always")
def period_rows(f, fs, fg, sel, Y, D, cap, gcols, goffs, dirs, ng, gi, rtol, atol, n_out,
                which, te, Yev, H, Tn, Yn):  # pragma: no cover - compiled
    """:func:`phase_rows` over control periods: every row of ``Y`` (N, m) from phase time 0
    to its first guard crossing or exactly to ``cap[i]`` [s] (its period's end: the last
    step cut to end there, the state there into ``Yev[i]``, ``which[i]`` :data:`TIMEOUT`),
    each with its own data vector ``D[i]`` (its held torques) and its own guards: the set
    ``gi[i]`` of the guard sets ``gcols``, ``goffs``, ``dirs`` (S, g), set ``s`` the first
    ``ng[s]`` of its row (the phases of one flow: the same cfunc, guards of their own);
    ``H`` (N,) [s]: first step sizes (<= 0: scipy's choice), overwritten with the next.
    ``Tn`` (N, q) [s]: times of each row (NaN: none) whose states its dense output writes
    into ``Yn`` (N, q, m) (the native vector environment's Gauss-Legendre nodes of the
    period: :func:`_row`)."""
    work = _work(Y.shape[1], n_out, gcols.shape[1])
    y = np.empty(Y.shape[1])
    for i in range(Y.shape[0]):
        y[:] = Y[i]
        s, k = gi[i], ng[gi[i]]
        w, t, h = _row(f, fs, fg, sel, y, D[i], cap[i], gcols[s, :k], goffs[s, :k],
                       dirs[s, :k], rtol, atol, Yev[i], H[i], work, True, Tn[i], Yn[i])
        which[i] = w
        te[i] = t
        H[i] = h


@njit(cache=True, error_model="numpy")
def reset_rows(reset, X, D, out):  # pragma: no cover - compiled
    """The reset cfunc ``reset`` (``(dy, t, y, d)``, the generated module's ``reset_flow``)
    of every row of ``X`` (N, m) with its data vector ``D[i]`` into ``out`` (N, m)."""
    for i in range(X.shape[0]):
        x = np.ascontiguousarray(X[i])
        d = np.ascontiguousarray(D[i])
        o = np.empty(X.shape[1])
        _call(reset, o, 0.0, x, d)
        out[i] = o


@njit(cache=True, error_model="numpy", inline="always")
def walk_rows(f, fs, fg, sel, reset, X, D, n_steps, max_time, gstart, gcols, goffs, dirs,
              gout, rtol, atol, n_out, steps, fell, per_step,
              hoff):  # pragma: no cover - compiled
    """Walk every row of ``X`` (W, m) up to ``n_steps`` steps, step ``s`` of walk ``w`` on
    the data vector ``D[w, s]`` (its slope): the phases of a step in turn (phase ``p``'s
    guards ``gstart[p]:gstart[p + 1]`` of the flat arrays ``gcols``, ``goffs``, ``dirs``
    and ``gout``: 0 heel strike, 1 fall, 9 next phase, guards without intra-step reset),
    each integrated by :func:`_row` as :func:`phase_rows` does (the step size carried from
    phase to phase), a heel strike reset by ``reset`` and counted in ``steps`` (W,); a fall,
    a step longer than ``max_time`` [s] or a failed integration sets ``fell`` (W,) and ends
    the walk.  ``f, fs, fg, sel``: the flow's cfuncs (:func:`phase_rows`).  ``X`` is
    overwritten with each walk's last post-impact state.  ``per_step``: ``hoff[w, s]``
    ((W, n_steps) [m]) is added to the heel-strike guards' offsets of step ``s`` of walk
    ``w`` (its landing height); else ``hoff`` is not read."""
    W, m = X.shape
    n_ph = gstart.size - 1
    yev = np.empty(m)
    x = np.empty(m)
    y = np.empty(m)
    work = _work(m, n_out, np.max(gstart[1:] - gstart[:-1]))
    go = goffs.copy()
    tn, yn = np.empty(0), np.empty((0, m))
    for w in range(W):
        x[:] = X[w]
        for s in range(n_steps):
            T, h, ended = 0.0, 0.0, False
            d = np.ascontiguousarray(D[w, s])
            y[:] = x
            if per_step:
                for j in range(go.size):
                    go[j] = goffs[j] + hoff[w, s] if gout[j] == 0 else goffs[j]
            for p in range(n_ph):
                a, b = gstart[p], gstart[p + 1]
                if max_time - T <= 0.0:
                    ended = True
                    break
                which, te, h = _row(f, fs, fg, sel, y, d, max_time - T, gcols[a:b], go[a:b],
                                    dirs[a:b], rtol, atol, yev, h, work, False, tn, yn)
                if which < 0 or gout[a + which] == 1:
                    ended = True
                    break
                T += te
                if gout[a + which] == 0:
                    _call(reset, x, 0.0, yev, d)
                    steps[w] += 1
                    break
                y[:] = yev
                if p == n_ph - 1:
                    ended = True  # a last phase that leads nowhere
            if ended:
                fell[w] = True
                break
        X[w] = x


@functools.cache
def source_hash() -> str:
    """sha256 (12 hex digits) of this module's source (once per process): :func:`kernels`
    compile its loops into their own machine code, which numba's cache keeps against the
    kernels' file alone, so the file's name carries it (a changed loop: a new file,
    compiled afresh)."""
    return hashlib.sha256(Path(__file__).read_bytes()).hexdigest()[:12]


#: the loops :func:`kernels` specialises, each with the functions it takes first (its other
#: arguments passed on as they are)
_LOOPS = {"walk_rows": (walk_rows, ("f", "fs", "fg", "sel", "reset")),
          "phase_rows": (phase_rows, ("f", "fs", "fg", "sel"))}


def kernels_source(module_name: str, flows) -> str:
    """Source of the kernels module of the compiled module ``module_name`` (imported; its
    flows ``flows``): for each flow ``k`` and each loop of :data:`_LOOPS`, ``<loop>_<k>``,
    an ``@njit(cache=True)`` entry point calling that loop of this module with the
    compiled module's ``_<k>_full``, ``_<k>_plain``, ``_guard_one`` and ``_reset_flow``
    made ``@njit`` functions on arrays, its other arguments named as the loop names them
    (read from its signature)."""
    out = [f"# walkerlab per-row kernels of {module_name} (walkerlab.integrate.rows_dop853 "
           f"{source_hash()})",
           "# Do not edit: regenerated when the model or walkerlab/integrate/rows_dop853.py "
           "changes.",
           "import sys", "", "from numba import njit", "",
           "from walkerlab.integrate import rows_dop853 as _rows", "",
           f"_m = sys.modules[{module_name!r}]",
           "_NJ = njit(error_model='numpy')",
           "_guard_one = _NJ(_m._guard_one)", "_reset_flow = _NJ(_m._reset_flow)"]
    for k in flows:
        out += [f"_{k}_full = _NJ(_m._{k}_full)", f"_{k}_plain = _NJ(_m._{k}_plain)"]
    for k in flows:
        fns = (f"_{k}_full", f"_{k}_plain", "_guard_one", "True", "_reset_flow")
        for loop, (fn, first) in _LOOPS.items():
            params = list(inspect.signature(fn.py_func).parameters)
            if tuple(params[:len(first)]) != first:  # pragma: no cover - a changed loop
                raise RuntimeError(f"rows_dop853.{loop}{tuple(params)}: not {first} first")
            args = ", ".join(params[len(first):])
            out += ["", "", "@njit(cache=True, error_model='numpy')",
                    f"def {loop}_{k}({args}):  # pragma: no cover - runs compiled",
                    f"    _rows.{loop}({', '.join(fns[:len(first)])}, {args})"]
    return "\n".join(out) + "\n"


def kernels(structure, name: str) -> tuple | None:
    """``(walk_rows, phase_rows)`` specialised to the flow ``name`` of ``structure``'s
    compiled module (:func:`walkerlab.codegen.compiled.compiled_module`), or None for a
    module without the plain functions they need (a flat foot's): :func:`kernels_source`'s
    entry points, their arguments those of :func:`walk_rows` and :func:`phase_rows` after
    the functions, the same numbers bit for bit (the flow inlined into the loop).  The
    kernels module is generated and imported once (``<key>_rows_<source_hash()>_nb.py``
    beside the compiled module, :func:`walkerlab.codestore.import_generated`'s checks)
    and compiled on first call or loaded from numba's cache (``cache=True``: its file)."""
    from walkerlab.codegen import cache
    from walkerlab.codegen.compiled import compiled_module

    mod = compiled_module(structure)
    flows = getattr(mod, "FLOWS", ())
    if name not in flows:
        return None
    key = cache.cache_key(structure)
    kern = codestore.import_generated(f"{key}_rows_{source_hash()}_nb.py",
                                      f"walkerlab_rows_{key}_{source_hash()}",
                                      lambda: kernels_source(mod.__name__, flows))
    return tuple(getattr(kern, f"{loop}_{name}") for loop in _LOOPS)
