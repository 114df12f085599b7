"""The rigid view's control periods of many walkers at once: the compiled pieces of every
walker integrated in one compiled call per flow (the native vector environment's physics,
:class:`walkerlab.gym.vector.WalkerVectorEnv`).

Each walker (:class:`walkerlab.gym.rigid_view.RigidView`; its own
:meth:`~walkerlab.gym.rigid_view.RigidView.advance` is this function on it alone) is advanced
piece by piece - the same pieces
(:meth:`~walkerlab.gym.rigid_view.RigidView.next_piece`), the same handling of each piece's
end (:meth:`~walkerlab.gym.rigid_view.RigidView.absorb`: the ledger, a knee strike, a heel
strike and the next step, a fall) - but the pieces that run the compiled control step (the
flow with the held torques compiled in) are integrated together: the walkers whose pieces
share a flow (one cfunc and tolerances; each phase's own guards) are the rows of one call of
:func:`walkerlab.integrate.rows_dop853.period_rows`, each row with its own data vector (its
torques in the law block), its own state and its own end (the period's end or its step's
time limit).  That kernel runs scipy's DOP853 (Hairer, Nørsett & Wanner 1993, sec. II.10) as
CyRK's does, its error norm scaled to theirs (the 2-norm at tolerances times ``sqrt(2n)`` is
the root-mean-square norm at the tolerances), so a row's steps are CyRK's to round-off
(measured: the states after a 10 ms period within 4.4e-16 of CyRK's; CyRK still runs a
profile's compiled pieces); the guard crossings are located on the step's dense output by
the Illinois method to 1e-15 s (CyRK's runs: Brent's method to 4 eps).  Pieces that do
not run the compiled step (flat feet's modes, torque laws of the walker's own, a height
profile's walk, which keeps each piece's dense output) are integrated one by one as the
walker itself integrates them.

The ledger of a row that reaches its period's end with the action on is taken for all such
rows at once (:func:`_held_rows`), as each walker's
:meth:`~walkerlab.gym.rigid_view.RigidView._held_work` takes it: the held torques' exact
work ``sum_k u_k Delta delta_k`` where their power has one sign at both ends, else the
power at the piece's 4 Gauss-Legendre nodes, whose states the kernel's dense output wrote as
its steps passed them (the same steps: the period's states are those without the nodes).
The same sums as the walker's own to round-off (its nodes are read from CyRK's dense output
of the same DOP853 steps, its joint maps applied state by state).  Other rows (a guard
crossing, a failed step, a walker whose joints are not affine in its coordinates) are
absorbed walker by walker; the Gauss-Legendre nodes of such a row's piece read a dense
output made on first use: a row ended by a guard crossing integrated again by the same
kernel, its nodes as samples (:class:`_RowRedo`: the same steps), a failed row by the
single walker's integrator (:class:`_Redo`).
"""

from __future__ import annotations

import threading

import numpy as np

from walkerlab import progress
from walkerlab.integrate.rigid_phase import PhaseRun, integrate_phase
from walkerlab.integrate.rows_dop853 import FAILED, TIMEOUT, cfuncs, period_rows

from .action import GL_W, GL_X  # the ledger's Gauss-Legendre rule, the walker's own
from .small_arrays import all_finite

__all__ = ["COMPILE_NOTICE_S", "advance_live", "advance_rows", "compile_notice"]

#: a first batched call still running after this long [s] is compiling its kernels (numba:
#: about 13 s on an idle 2-core machine; about 2 s when its cache holds them): said in one line
COMPILE_NOTICE_S = 3.0

#: :func:`compile_notice`'s line
COMPILE_NOTICE = ("walkerlab.gym: compiling the native vector env's batched step for this "
                  "walker (numba, about 13 s once: numba's cache in the user cache keeps it)")


def compile_notice(call, after_s: float | None = None):
    """``call`` (:func:`advance_rows`) whose run says :data:`COMPILE_NOTICE` in one line
    (:func:`walkerlab.progress.note`: stderr unless a sink takes it) when it is still running
    after ``after_s`` [s] (default :data:`COMPILE_NOTICE_S`): the native vector env's first
    batched step, whose kernels numba compiles (or loads from its cache) on first call."""
    def first(*args, **kwargs):
        wait = COMPILE_NOTICE_S if after_s is None else after_s
        timer = threading.Timer(wait, progress.note, (COMPILE_NOTICE,))
        timer.daemon = True
        timer.start()
        try:
            return call(*args, **kwargs)
        finally:
            timer.cancel()
    return first


#: the ledger's 4-point Gauss-Legendre weights as floats (the walker's own rule)
_GL_WL = GL_W.tolist()


class _Redo:
    """A piece's dense output made on first call: the piece from ``(t0, x0)`` integrated
    again to ``t1`` by the walker's compiled step (CyRK's DOP853), the call answered on it
    (scipy's ``OdeSolution`` convention)."""

    def __init__(self, view, fphase, t0: float, x0: np.ndarray, t1: float):
        self.args = (view, fphase, t0, x0, t1)  # (x0: the view's state, replaced, not
        self.dense = None                       # written in place, when it moves on)

    def __call__(self, t):
        if self.dense is None:
            view, fphase, t0, x0, t1 = self.args
            self.dense = integrate_phase(fphase, t0, x0, None, t1, x0.size,
                                         view.compiled_solver, "cyrk_compiled", None, None,
                                         False).dense
        return self.dense(t)


def _flow_key(view, fphase) -> tuple:
    """``(key, guards)``: what the rows of one kernel call share (the cfunc, the
    tolerances) and the number of this phase's guards (columns, offsets, directions: each
    row's own; :data:`_GUARDS`), kept in the view per compiled phase, which lives as long
    as the view; None for a compiled phase without guard outputs (integrated by the
    walker itself)."""
    keys = view.row_keys
    out = keys.get(id(fphase), keys)  # (the dict itself: no entry yet)
    if out is keys:
        out = keys[id(fphase)] = _make_key(fphase, view.compiled_solver, 2 * view.n)
    return out


def _make_key(fphase, solver, m: int) -> tuple | None:
    flow = fphase.compiled
    if flow.guard_columns() is None:  # (no guard outputs: not a row of the kernel)
        return None
    n_extra, gcols, goffs = flow.guard_columns()
    dirs = tuple(float(g.direction) for g in fphase.guards)
    guards = (tuple(gcols.tolist()), tuple(goffs.tolist()), dirs)
    return ((flow.address(False), n_extra, float(solver.rtol),
             tuple(np.atleast_1d(solver.atol).tolist()), m),
            _GUARDS.setdefault(guards, len(_GUARDS)))


_CFUNCS: dict = {}  # flow key -> (f, fs, fg, sel, rtol, atol, n_out)
_GUARDS: dict = {}  # a phase's guards (columns, offsets, directions) -> their number
_ENTRY: dict = {}  # flow key -> period_rows' compiled entry for its argument types


def _period_rows(key: tuple, args: tuple) -> None:
    """:func:`walkerlab.integrate.rows_dop853.period_rows` of ``args``, through its compiled
    entry for their types once the dispatcher has chosen it: numba's dispatcher types every
    argument of every call (21 here); the arrays are made alike on every call (C order,
    writable, one dtype) and the flow's cfuncs are given by address (integers:
    :func:`walkerlab.integrate.rows_dop853._call_address`; as first-class functions their
    boxing cost about 50 us a call of the 8-walker benchmark, more than its 8 rows), so the
    types, and the entry, are the first call's."""
    entry = _ENTRY.get(key)
    if entry is not None:
        entry(*args)
        return
    period_rows(*args)
    cres = period_rows.overloads.get(tuple(period_rows.typeof_pyval(a) for a in args))
    if cres is not None:
        _ENTRY[key] = cres.entry_point


def _kernel_args(key: tuple, fphase) -> tuple:
    """:func:`walkerlab.integrate.rows_dop853.period_rows`'s shared arguments for ``key``."""
    if key not in _CFUNCS:
        flow = fphase.compiled
        module = flow.module()
        f = module.cfunc_of(flow.name)
        n_extra, rtol, atol, m = key[1], key[2], key[3], key[4]
        # the kernel's 2-norm at tolerances * sqrt(m) is CyRK's RMS norm at the tolerances
        scale = np.sqrt(m)
        if len(atol) != 1:  # pragma: no cover - the scenes' solvers give one atol
            raise ValueError("rigid rows: one absolute tolerance for every state")
        f, fs, fg, sel = cfuncs(module, flow.name, f)
        # the cfuncs by address (rows_dop853._call_address): no boxing of three function
        # values on every call
        _CFUNCS[key] = (f.address, fs.address, fg.address, sel, rtol * scale,
                        atol[0] * scale, m + n_extra)
    return _CFUNCS[key]


#: most entries of :data:`_GUARD_ROWS` (rows' guard numbers in order; cleared when full)
GUARD_ROWS_KEPT = 4096
_GUARD_ROWS: dict = {}  # rows' guard numbers (tuple) -> _guard_tables' answer
#: ``(number of guard sets, tables)``: :func:`_guard_sets`' tables of every set numbered
#: in :data:`_GUARDS` so far
_ALL_SETS: list = [0, None]


def _guard_tables(guards: list) -> tuple:
    """:func:`walkerlab.integrate.rows_dop853.period_rows`' guard arguments for rows whose
    phases have the guards numbered ``guards`` (:data:`_GUARDS`): every set numbered so
    far as tables (S, g) (padded), their sizes (S,) (:func:`_guard_sets`) and each row's
    set (N,) (its number), kept per rows' numbers (:data:`_GUARD_ROWS`: the kernel only
    reads them; rows of any sets in any order share the tables)."""
    key = tuple(guards)
    out = _GUARD_ROWS.get(key)
    if out is None:
        if len(_GUARD_ROWS) >= GUARD_ROWS_KEPT:
            _GUARD_ROWS.clear()
        if _ALL_SETS[0] != len(_GUARDS):  # (sets numbered since: the tables made again)
            _ALL_SETS[:] = [len(_GUARDS), _guard_sets()]
        out = _GUARD_ROWS[key] = (*_ALL_SETS[1], np.array(key, np.int64))
    return out


def _guard_sets() -> tuple:
    """The guard sets of :data:`_GUARDS` as tables, row ``j`` set number ``j``: its
    columns, offsets and directions (S, g) (padded with zeros) and sizes (S,)."""
    chosen = sorted(_GUARDS, key=_GUARDS.__getitem__)
    g = max(len(c) for c, _, _ in chosen)
    tables = (np.zeros((len(chosen), g), np.int64), np.zeros((len(chosen), g)),
              np.zeros((len(chosen), g)))
    for s, entry in enumerate(chosen):
        for table, values in zip(tables, entry):
            table[s, :len(values)] = values
    return (*tables, np.array([len(c) for c, _, _ in chosen], np.int64))


#: (rows, states) -> period_rows' node arguments for no nodes (zero-size: never written)
_NO_NODES: dict = {}


def _integrate_rows(views, rows: list, pieces: list, key: tuple, guards: list) -> tuple:
    """The compiled pieces ``pieces`` of walkers ``rows`` (one flow; the guards of each
    row's phase numbered ``guards``) in one kernel call: ``(which, te, Yev, Y, cap, Yn,
    call)`` (:func:`walkerlab.integrate.rows_dop853.period_rows`'s outcome, time from the
    piece's start [s] and state of each row; the rows' start states, time caps [s] and
    Gauss-Legendre nodes' states; the call's arguments, for :class:`_RowRedo`)."""
    fphase = pieces[0][5][0]
    f, fs, fg, sel, rtol, atol, n_out = _CFUNCS.get(key) or _kernel_args(key, fphase)
    gcols, goffs, dirs, ng, gi = _guard_tables(guards)
    N, m = len(rows), key[4]
    xs, caps, flows = [], [], []  # each row's state, time cap [s] and flow, in one pass
    for i, piece in zip(rows, pieces):
        v = views[i]
        xs.append(v.x)
        caps.append(piece[4] - v.t)
        flows.append(piece[5][0].compiled)
    Y = np.array(xs, dtype=float)
    if Y.shape != (N, m):  # pragma: no cover - every view's state is (2n,)
        raise ValueError(f"rigid rows: states of shape {Y.shape[1:]}, not ({m},)")
    if hasattr(flows[0], "data_rows"):  # each walker's torques in its law block
        D = np.empty((N, flows[0].data_size()))
        flows[0].data_rows(flows, D)
    else:
        D = np.array([flow.data() for flow in flows], dtype=float)
    cap, which, te, Yev, Tn, Yn = period_buffers(caps, [piece[2] for piece in pieces], N, m)
    _period_rows(key, (f, fs, fg, sel, Y, D, cap, gcols, goffs, dirs, ng, gi, rtol, atol,
                       n_out, which, te, Yev, np.zeros(N), Tn, Yn))
    call = (key, (f, fs, fg, sel), Y, D, cap, (gcols, goffs, dirs, ng), gi, (rtol, atol, n_out))
    return which, te, Yev, Y, cap, Yn, call


def period_buffers(caps, on, N: int, m: int) -> tuple:
    """The period kernel's caps ``(N,)`` [s] and output buffers (the event's row ``which``
    (N,), time ``te`` (N,) and state ``Yev`` (N, m)), and the Gauss-Legendre nodes ``Tn``
    (N, k) [s] and their states ``Yn`` (N, k, m) of the rows with the action on (``on``,
    per row: their ledger's, should the power change sign over the period: _held_rows),
    NaN for the others; none (k = 0) when no row's action is on."""
    cap = np.array(caps, dtype=float)
    which, te, Yev = np.empty(N, np.int64), np.empty(N), np.empty((N, m))
    if any(on):
        half = 0.5 * cap[:, None]
        Tn = half * GL_X + half
        if not all(on):
            Tn[[not a for a in on]] = np.nan
        Yn = np.empty((N, GL_X.size, m))
    else:
        Tn, Yn = _NO_NODES.get((N, m)) or _NO_NODES.setdefault(
            (N, m), (np.empty((N, 0)), np.empty((N, 0, m))))
    return cap, which, te, Yev, Tn, Yn


class _RowRedo:
    """The dense output of row ``r`` of a kernel call (``call``: what
    :func:`_integrate_rows` gave it) up to its guard crossing, made when called: the row
    integrated again by the same kernel from the same state, data and cap (the same steps)
    with the asked times as its samples (:func:`walkerlab.integrate.rows_dop853._row`);
    ``t0`` [s]: the row's start.  Called as ``dense(t)`` with times ``t`` (q,) [s] inside
    the row's span up to its crossing: the states (m, q); a time not reached falls back on
    ``fallback`` (a :class:`_Redo`)."""

    def __init__(self, call, r: int, t0: float, fallback):
        self.args = (call, r, t0, fallback)

    def __call__(self, t):
        call, r, t0, fallback = self.args
        key, fns, Y, D, cap, guards, gi, tol = call
        m = Y.shape[1]
        Tn = np.atleast_2d(np.asarray(t, dtype=float) - t0).copy()
        Yn = np.full((1, Tn.shape[1], m), np.nan)
        out = np.empty(1, np.int64), np.empty(1), np.empty((1, m)), np.zeros(1)
        rows = slice(r, r + 1)
        _period_rows(key, (*fns, np.ascontiguousarray(Y[rows]), np.ascontiguousarray(D[rows]),
                           np.ascontiguousarray(cap[rows]), *guards,
                           np.ascontiguousarray(gi[rows]), *tol, *out, Tn, Yn))
        if not np.isfinite(Yn).all():  # pragma: no cover - a time past the crossing
            return fallback(t)
        return Yn[0].T


def _held_rows(views, rows: list, pieces: list, sel: list, maps: list, X: np.ndarray,
               Y: np.ndarray, cap: np.ndarray, Yn: np.ndarray, U=None) -> None:
    """The ledger of the rows ``sel`` (indices into ``rows``), each of which reached its
    period's end with the action on (its walker's
    :meth:`~walkerlab.gym.rigid_view.RigidView._held_work`, all at once): from ``Y`` to
    ``X`` (r, 2n) over ``cap`` [s], the held torques' exact work ``u . (delta_b -
    delta_a)`` where their power ``u . ddelta`` has one sign at both ends, else the power
    at the Gauss-Legendre nodes' states ``Yn`` (r, 4, 2n) weighted (module docstring).
    With the joints' map ``ddelta = Bt dq`` (``delta = Bt q + c``), both are ``w . dq``
    and ``w . Delta q`` with ``w = Bt^T u`` (n,) [N m]; ``maps``: each selected row's
    ``Bt`` (:func:`_joint_map`).

    The three sums of each row (the work and the power at both ends) are one reduction
    over a stacked (3, r, n) array: numpy's reduction along the last axis of each row,
    the same sums bit for bit as three of an (r, n) array (checked on 40,000 random
    cases, n up to 23); the comparisons on Python floats are numpy's.  ``U`` (r, k)
    [N m]: the selected rows' held torques (``pieces[r][1].u``' numbers), when the caller
    has them stacked."""
    n = X.shape[1] // 2
    if U is None:
        U = np.array([pieces[r][1].u for r in sel])  # (r, k) [N m]
    if all(M is maps[0] for M in maps):  # one walker's map for all (its rows (k, n))
        W = U @ maps[0]  # (r, n)
    else:
        W = np.array([u @ M for u, M in zip(U, maps)])
    Xa, Xb = (Y, X) if len(sel) == len(Y) else (Y[sel], X[sel])  # (every row: in order)
    P = np.empty((3, len(sel), n))
    np.subtract(Xb[:, :n], Xa[:, :n], out=P[0])
    np.multiply(P[0], W, out=P[0])  # the work's terms
    np.multiply(Xa[:, n:], W, out=P[1])  # the power's at both ends [W]
    np.multiply(Xb[:, n:], W, out=P[2])
    exact, pa, pb = P.sum(axis=2).tolist()
    for j, r in enumerate(sel):
        ledger = views[rows[r]].ledger
        if pa[j] * pb[j] > 0.0:  # one sign at both ends
            ledger["action_work_positive" if pa[j] > 0.0 else "action_work_negative"] += \
                exact[j]
            continue
        h = 0.5 * float(cap[r])
        for w, p in zip(_GL_WL, (Yn[r, :, n:] @ W[j]).tolist()):  # at the nodes [W]
            ledger["action_work_positive" if p > 0 else "action_work_negative"] += h * w * p


def _absorb_rows(views, rows: list, pieces: list, out: tuple, strikes: list,
                 only=None) -> None:
    """Each row's piece ended (:func:`_integrate_rows`' ``out``) taken by its walker, as
    :meth:`~walkerlab.gym.rigid_view.RigidView.absorb` takes a run: a row that reached its
    period's end settles there (:meth:`~walkerlab.gym.rigid_view.RigidView.settle`, the
    states' finiteness checked for all rows at once), the ledger of those with the action
    on taken for all of them (:func:`_held_rows`); any other is absorbed as a
    :class:`PhaseRun`, its dense output made on first use (:class:`_RowRedo` for a guard
    crossing, else :class:`_Redo`).  ``only``: the rows (indices into ``rows``) to absorb,
    when not all (the others taken by the caller: :mod:`walkerlab.gym.rows_common`)."""
    which, te, Yev, Y, cap, Yn, call = out
    X = Yev  # (each settled walker's state: its row; the array is this call's own)
    finite = ([True] * len(rows) if all_finite(X)
              else np.isfinite(X).all(axis=1).tolist())
    ends = which.tolist()
    held: list | set = []
    if Yn.shape[1]:  # rows with the action on
        maps = []
        for r, (i, piece, w) in enumerate(zip(rows, pieces, ends)):
            if only is not None and r not in only:
                continue
            if w == TIMEOUT and piece[2] and finite[r]:
                M = _joint_map(views[i], piece[1])
                if M is not None:
                    held.append(r)
                    maps.append(M)
        if held:
            _held_rows(views, rows, pieces, held, maps, X, Y, cap, Yn)
        held = set(held)
    for r, (i, piece, w) in enumerate(zip(rows, pieces, ends)):
        if only is not None and r not in only:
            continue
        v = views[i]
        if w == TIMEOUT and (not piece[2] or r in held):
            v.settle(float(piece[4]), X[r], finite[r])
            continue
        failed = w == FAILED
        event = w if w >= 0 else None
        # a row that reached its end stops on it exactly (its time is the period's)
        t_last = v.t + float(te[r]) if (event is not None or failed) else float(piece[4])
        redo = _Redo(v, piece[5][0], v.t, v.x, t_last)
        if event is not None and not failed:  # its dense output: the kernel's, run again
            redo = _RowRedo(call, r, v.t, redo)
        run = PhaseRun(t_last, Yev[r], failed,
                       "the step size fell below 10 ulp of t" if failed else "", event,
                       redo, 0)
        strikes[i] += v.absorb(piece, run, piece[3])


#: the action's joint maps ``Bt`` (k, n), one array per value (the walkers of a scene share it)
_MAPS: dict = {}


def _joint_map(view, acts):
    """The rows ``Bt`` (k, n) of the joints' map ``ddelta = Bt dq`` of the action ``acts``
    (an :class:`walkerlab.gym.action.ActionTorques` of ``view``), one array for every
    walker with the same map (:data:`_MAPS`), kept in the view; None where the ledger is
    not :func:`_held_rows`': the action not alone, its joints not affine in the
    coordinates, or its torques scaled by a massless foot's mass (they do no work)."""
    key = ("map", id(acts))
    if key not in view.row_keys:  # (acts lives as long as the view)
        Bt = None
        if acts.affine is not None and not acts.first and not acts.limit:
            Bt = np.ascontiguousarray(acts.affine[0], dtype=float)
            Bt = _MAPS.setdefault((Bt.shape, Bt.tobytes()), Bt)
        view.row_keys[key] = Bt
    return view.row_keys[key]


def advance_rows(views, actions, t_ends) -> list[list[float]]:
    """Advance every walker ``views[i]`` to ``t_ends[i]`` [s] with the torques
    ``actions[i]`` (k,) [N m] held, the compiled pieces of all of them integrated together
    (module docstring; one walker's :meth:`~walkerlab.gym.rigid_view.RigidView.advance`
    is this function on it alone).

    Parameters
    ----------
    views : sequence of walkerlab.gym.rigid_view.RigidView
    actions : sequence of ndarray (k,)
        The held torques [N m].
    t_ends : sequence of float
        Each walker's period end [s].

    Returns
    -------
    list of list of float
        Each walker's heel-strike times inside its period [s]; its ``ended`` is set when
        its episode ended there.
    """
    strikes: list[list[float]] = [[] for _ in views]
    if type(actions) is np.ndarray:  # (its rows made once: each is read twice)
        actions = list(actions)
    live = []
    for i, v in enumerate(views):
        t_end = t_ends[i]
        v.open_period(actions[i], t_end)
        if v.t < t_end and not v.ended:
            live.append(i)
    advance_live(views, actions, t_ends, live, strikes)
    return strikes


def advance_live(views, actions, t_ends, live: list, strikes: list) -> None:
    """:func:`advance_rows`' pieces of the walkers ``live`` (indices into ``views``,
    their periods opened), each walker's heel-strike times added to ``strikes[i]``, until
    every one reached its period's end or its episode's (the native vector env's common
    step, :func:`walkerlab.gym.rows_common.step_common`, goes on here after its first
    pieces)."""
    while live:
        groups: dict = {}
        for i in live:
            v = views[i]
            piece = v.next_piece(actions[i], t_ends[i])
            if piece is None:
                continue
            fast = piece[5]
            if fast is None or v.ground is not None:
                kg = None
            else:  # (_flow_key's entry, read here: once per walker and piece)
                keys = v.row_keys
                kg = keys.get(id(fast[0]), keys)
                if kg is keys:
                    kg = _flow_key(v, fast[0])
            if kg is None:  # the walker's own integration
                run, phase = v.integrate_piece(piece)
                strikes[i] += v.absorb(piece, run, phase)
                continue
            key, guards = kg
            group = groups.get(key)
            if group is None:
                groups[key] = ([i], [piece], [guards])
            else:
                group[0].append(i)
                group[1].append(piece)
                group[2].append(guards)
        for key, (rows, pieces, gs) in groups.items():
            _absorb_rows(views, rows, pieces, _integrate_rows(views, rows, pieces, key, gs),
                         strikes)
        live = [i for i in live if views[i].t < t_ends[i] and not views[i].ended]
