"""The native vector environment's common control period: every walker in a compiled phase
of one flow, its first pieces integrated as one batch read from arrays over the walkers
(:class:`walkerlab.gym.vector.WalkerVectorEnv`'s physics; :func:`advance_common`).

:func:`walkerlab.gym.rigid_rows.advance_rows` advances any set of walkers piece by piece,
asking each walker for its piece (:meth:`~walkerlab.gym.rigid_view.RigidView.next_piece`),
grouping the pieces by flow, writing each walker's held torques into its law block and
reading the law blocks back into the kernel's data rows.  In a vector env's common period
every walker is where its last period left it - the same step walker, phase and stance leg,
its compiled phase and flow key known (kept in the walker: ``RigidView._lane``,
``row_keys``), all of one flow - so that work is the same every period: here the walkers'
states, times and caps are read in one pass, the data rows are the flows' rows kept from the
first such period (:class:`_DataRows`) with this period's torques and step clocks written
as columns over the walkers, and the kernel
(:func:`walkerlab.integrate.rows_dop853.period_rows`) is called on them; each row's piece is
then absorbed as :func:`walkerlab.gym.rigid_rows.advance_rows` absorbs it (the same code:
the ledger of the rows that reached the period's end at once, a guard crossing or a failed
step by its walker), and a walker whose period goes on (a heel strike inside it) goes on
through :func:`walkerlab.gym.rigid_rows.advance_live`.  The same kernel on the same rows,
states, data and caps, so the same numbers bit for bit as each walker's own period
(``gym.make``'s environment is :func:`~walkerlab.gym.rigid_rows.advance_rows` on one
walker); a period that is not common (a walker in a new step or phase, a height profile, a
fall guard checked at a phase's entry, walkers of several flows) is
:func:`~walkerlab.gym.rigid_rows.advance_rows`' own.
"""

from __future__ import annotations

import numpy as np

from walkerlab.codegen.torque_law import HEAD
from walkerlab.integrate.rows_dop853 import TIMEOUT

from .action import GL_X
from .rigid_rows import (_CFUNCS, _NO_NODES, _absorb_rows, _guard_tables, _held_rows,
                         _joint_map, _kernel_args, _period_rows, advance_live, advance_rows)
from .rigid_view import _CONSTANT_0
from .small_arrays import all_finite

__all__ = ["advance_common"]


def _hold(view, fast, u: np.ndarray) -> None:
    """Write the held torques ``u`` into the compiled phase ``fast``'s law block as
    :meth:`~walkerlab.gym.rigid_view.RigidView.next_piece` writes them (where it does not
    hold these very numbers), its memo kept."""
    held, bits = view._held, u.tobytes()
    if held[0] is not fast or held[1] != bits:
        fast[1][_CONSTANT_0:_CONSTANT_0 + HEAD * u.size:HEAD] = u
        view._held = (fast, bits)


class _DataRows:
    """What a common period of the same walkers' flows (one per walker, in order) reads
    every period, kept: the kernel's data rows (N, size) as
    :meth:`walkerlab.codegen.actuated.ActuatedFlow.data_rows` writes them, this period's
    held torques (the law block's constants, each actuator's ``HEAD``-th slot from
    :data:`~walkerlab.gym.rigid_view._CONSTANT_0`) and step clocks (``t_origin``, the
    block's third slot) written as columns; the kernel's compiled functions, tolerances and
    guard tables.  The first period writes the law blocks and compares these rows with
    ``data_rows``' bit for bit; rows that differ (a flow of another layout) are then
    ``data_rows``' every period."""

    def __init__(self, flows: list, k: int, key: tuple, fphase, guards: list):
        self.flows = tuple(flows)  # (kept: their ids key this entry)
        nc = flows[0].constants().size
        self.base = np.empty((len(flows), flows[0].data_size()))
        flows[0].data_rows(flows, self.base)
        first = nc + _CONSTANT_0
        self.u_cols = slice(first, first + HEAD * k, HEAD)
        self.t_col = nc + 2
        self.origins = self.base[:, self.t_col].tolist()
        self.checked = False  # (the first period compares; False after: data_rows')
        self.same = True
        self.kernel = _CFUNCS.get(key) or _kernel_args(key, fphase)
        self.guards = _guard_tables(guards)

    def rows(self, views, lanes: list, U: np.ndarray, origins: list) -> np.ndarray:
        """The data rows of this period's torques ``U`` (N, k) [N m] and step clocks
        ``origins`` (N) [s]."""
        if self.checked and self.same:
            D = self.base.copy()
            D[:, self.u_cols] = U
            if origins != self.origins:
                D[:, self.t_col] = origins
            return D
        for v, lane, u in zip(views, lanes, U):  # the law blocks written, as next_piece
            _hold(v, lane[6], u)
        D = np.empty_like(self.base)
        self.flows[0].data_rows(list(self.flows), D)
        if not self.checked:
            mine = self.base.copy()
            mine[:, self.u_cols] = U
            mine[:, self.t_col] = origins
            self.checked, self.same = True, mine.tobytes() == D.tobytes()
        return D


#: most entries of a vector env's caches (:func:`advance_common`'s ``cache``; cleared when
#: full)
KEPT = 256


def _lane_entry(v, lane, cache: dict):
    """``(lane, key, guards, flow)`` of a walker's kept lane (``RigidView._lane``: its step
    walker, phase and stance leg) when a common period can run it (its compiled phase on
    the kernel, a flow with a law block, no height profile, no fall guard checked at the
    phase's entry), the flow key one object for equal keys; ``(lane, None)`` when not;
    kept in ``cache`` by the lane's id (the lane kept with it: its id stays its own)."""
    lanes = cache.setdefault("lanes", {})
    if len(lanes) >= KEPT:
        lanes.clear()
    out = (lane, None)
    fast = lane[6]
    if v.ground is None and not lane[5] and fast is not None:
        kg = v.row_keys.get(id(fast[0]), v.row_keys)
        if kg is v.row_keys:  # (its key not made yet: made by advance_rows, asked again)
            return out
        flow = fast[0].compiled
        if kg is not None and hasattr(flow, "data_rows"):
            keys = cache.setdefault("keys", {})
            out = (lane, keys.setdefault(kg[0], kg[0]), kg[1], flow)
    lanes[id(lane)] = out
    return out


def advance_common(views, U: np.ndarray, t_ends: list, cache: dict) -> tuple:
    """:func:`walkerlab.gym.rigid_rows.advance_rows` of ``views`` with the held torques
    ``U`` (N, k) [N m] to ``t_ends`` (N) [s], its first pieces as one batch when the period
    is common (module docstring): the same numbers bit for bit.

    Parameters
    ----------
    views : sequence of walkerlab.gym.rigid_view.RigidView
    U : ndarray (N, k)
        The held torques [N m], float64 (its rows are held by the walkers: not written
        after).
    t_ends : list of float
        Each walker's period end [s].
    cache : dict
        The vector env's own (what a common period of its walkers reads, kept).

    Returns
    -------
    strikes : list of list of float
        Each walker's heel-strike times inside its period [s].
    X : ndarray (N, 2n) or None
        The walkers' states at the period's end, rows of one array, when every walker
        reached it in the batch (``views[i].x`` is ``X[i]``); else None.
    """
    lanes_kept = cache.get("lanes") or {}
    key = None
    entries, xs, caps, stops, origins = [], [], [], [], []
    for v, t_end in zip(views, t_ends):  # (read only: a period not common is not touched)
        lane = v._lane
        if (lane is None or lane[0] is not v.walker or lane[1] != v.k or lane[2] != v.leg
                or v.ended or not v.t < t_end):
            return advance_rows(views, U, t_ends), None
        e = lanes_kept.get(id(lane)) or _lane_entry(v, lane, cache)
        if e[1] is not key:
            if key is not None or e[1] is None:  # (walkers of several flows; a lane the
                return advance_rows(views, U, t_ends), None  # common period cannot run)
            key = e[1]
        elif key is None:  # (the first walker's lane: one the common period cannot run)
            return advance_rows(views, U, t_ends), None
        t_stop = v.t_step + v.max_step_time  # (next_piece's end of the piece)
        if not t_stop < t_end:
            t_stop = t_end
        entries.append(e)
        xs.append(v.x)
        caps.append(t_stop - v.t)
        stops.append(t_stop)
        origins.append(float(getattr(e[3].actuators, "t_origin", 0.0)))
    N = len(views)
    rows_u = list(U)
    lanes = []
    for v, e, u, t_end in zip(views, entries, rows_u, t_ends):  # (open_period, next_piece)
        per = (u, t_end)  # (u a float64 row, t_end a float)
        v._period = per
        v._log.append(per)
        lane = e[0]
        lane[3].u = u
        lanes.append(lane)
    on = [any(r) for r in U.tolist()]
    some_on = any(on)
    fid = tuple(map(id, entries))
    data = cache.get(fid)
    if data is None:
        if len(cache) >= KEPT:
            cache.clear()
        data = cache[fid] = _DataRows([e[3] for e in entries], U.shape[1], key,
                                      lanes[0][6][0], [e[2] for e in entries])
    D = data.rows(views, lanes, U, origins)
    f, fs, fg, sel, rtol, atol, n_out = data.kernel
    gcols, goffs, dirs, ng, gi = data.guards
    m = key[4]
    last = cache.get("X")  # (the last common period's states: the walkers' own rows)
    if last is not None and all(x is r for x, r in zip(xs, last[1])):
        Y = last[0]
    else:
        Y = np.array(xs, dtype=float)
    cap = np.array(caps, dtype=float)
    which = np.empty(N, np.int64)
    te = np.empty(N)
    Yev = np.empty((N, m))
    H = np.zeros(N)
    if some_on:  # the Gauss-Legendre nodes of the rows with the action on (_integrate_rows)
        half = 0.5 * cap[:, None]
        Tn = half * GL_X + half
        if not all(on):
            Tn[[not a for a in on]] = np.nan
        Yn = np.empty((N, GL_X.size, m))
    else:
        Tn, Yn = _NO_NODES.get((N, m)) or _NO_NODES.setdefault(
            (N, m), (np.empty((N, 0)), np.empty((N, 0, m))))
    _period_rows(key, (f, fs, fg, sel, Y, D, cap, gcols, goffs, dirs, ng, gi, rtol, atol,
                       n_out, which, te, Yev, H, Tn, Yn))
    ends = which.tolist()
    if min(ends) == TIMEOUT == max(ends) and all_finite(Yev):
        # every row reached its piece's end (_absorb_rows' settled rows, all of them)
        held = [r for r in range(N) if on[r]] if some_on else ()
        maps = [_joint_map(views[r], lanes[r][3]) for r in held]
        if not any(M is None for M in maps):
            if held:
                _held_rows(views, list(range(N)), [(None, lane[3]) for lane in lanes],
                           held, maps, Yev, Y, cap, Yn)
            X = list(Yev)
            for v, x, t_stop in zip(views, X, stops):  # RigidView.settle
                v.t, v.x = t_stop, x
                if t_stop >= v.t_step + v.max_step_time:
                    v.ended = "stall"
            cache["X"] = (Yev, X)
            return [[] for _ in views], Yev
    # some row absorbed by its walker (a crossing, a failed step, the ledger on the dense
    # output): it may integrate its piece again with the walker's own flow, whose law
    # block then holds the torques (as next_piece leaves it)
    for v, lane, u in zip(views, lanes, rows_u):
        _hold(v, lane[6], u)
    pieces = [(lane[0], lane[3], a, lane[4], t_stop, lane[6])
              for lane, a, t_stop in zip(lanes, on, stops)]
    rows = list(range(N))
    call = (key, (f, fs, fg, sel), Y, D, cap, (gcols, goffs, dirs, ng), gi, (rtol, atol, n_out))
    strikes: list[list[float]] = [[] for _ in views]
    _absorb_rows(views, rows, pieces, (which, te, Yev, Y, cap, Yn, call), strikes)
    live = [i for i in rows if views[i].t < t_ends[i] and not views[i].ended]
    if live:
        advance_live(views, rows_u, t_ends, live, strikes)
    return strikes, None
