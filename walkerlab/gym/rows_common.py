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
    """The kernel's data rows (N, size) of N walkers' flows (one module and law block
    size), as :meth:`walkerlab.codegen.actuated.ActuatedFlow.data_rows` writes them: kept
    from the first period, this period's held torques (the law block's constants, each
    actuator's ``HEAD``-th slot from :data:`~walkerlab.gym.rigid_view._CONSTANT_0`) and step
    clocks (``t_origin``, the block's third slot) written as columns.  The first period
    writes the law blocks and compares these rows with ``data_rows``' bit for bit; rows
    that differ (a flow of another layout) are then ``data_rows``' every period."""

    def __init__(self, flows: list, k: int):
        self.flows = tuple(flows)  # (kept: their ids key this entry)
        nc = flows[0].constants().size
        self.base = np.empty((len(flows), flows[0].data_size()))
        flows[0].data_rows(flows, self.base)
        self.u_cols = nc + _CONSTANT_0 + HEAD * np.arange(k)
        self.t_col = nc + 2
        self.checked = False  # (the first period compares; False after: data_rows')
        self.same = True

    def rows(self, views, lanes: list, U: np.ndarray, origins: list) -> np.ndarray:
        """The data rows of this period's torques ``U`` (N, k) [N m] and step clocks
        ``origins`` (N) [s]."""
        if self.checked and self.same:
            D = self.base.copy()
            D[:, self.u_cols] = U
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


#: most entries of a vector env's data rows cache (cleared when full)
DATA_ROWS_KEPT = 256


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
        The vector env's own: the walkers' data rows (:class:`_DataRows`) by their flows.

    Returns
    -------
    strikes : list of list of float
        Each walker's heel-strike times inside its period [s].
    X : ndarray (N, 2n) or None
        The walkers' states at the period's end, rows of one array, when every walker
        reached it in the batch (``views[i].x`` is ``X[i]``); else None.
    """
    key0 = None
    lanes, guards, xs, caps, stops, flows, origins = [], [], [], [], [], [], []
    for v, t_end in zip(views, t_ends):  # (read only: a period not common is not touched)
        lane = v._lane
        if (lane is None or v.ended or not v.t < t_end or v.ground is not None
                or lane[0] is not v.walker or lane[1] != v.k or lane[2] != v.leg
                or lane[5] or lane[6] is None):
            return advance_rows(views, U, t_ends), None
        kg = v.row_keys.get(id(lane[6][0]))
        if kg is None:  # (no key kept yet, or a phase the kernel does not run)
            return advance_rows(views, U, t_ends), None
        if key0 is None:
            key0 = kg[0]
        elif kg[0] is not key0 and kg[0] != key0:  # (walkers of several flows)
            return advance_rows(views, U, t_ends), None
        flow = lane[6][0].compiled
        if not hasattr(flow, "data_rows"):
            return advance_rows(views, U, t_ends), None
        t_stop = v.t_step + v.max_step_time  # (next_piece's end of the piece)
        if not t_stop < t_end:
            t_stop = t_end
        lanes.append(lane)
        guards.append(kg[1])
        xs.append(v.x)
        caps.append(t_stop - v.t)
        stops.append(t_stop)
        flows.append(flow)
        origins.append(float(getattr(flow.actuators, "t_origin", 0.0)))
    key = key0
    N = len(views)
    rows_u = list(U)
    for v, lane, u, t_end in zip(views, lanes, rows_u, t_ends):  # (open_period, next_piece)
        per = (u, t_end)  # (u a float64 row, t_end a float)
        v._period = per
        v._log.append(per)
        lane[3].u = u
    on = [any(r) for r in U.tolist()]
    some_on = any(on)
    fid = tuple(map(id, flows))
    data = cache.get(fid)
    if data is None:
        if len(cache) >= DATA_ROWS_KEPT:
            cache.clear()
        data = cache[fid] = _DataRows(flows, U.shape[1])
    D = data.rows(views, lanes, U, origins)
    f, fs, fg, sel, rtol, atol, n_out = (_CFUNCS.get(key)
                                         or _kernel_args(key, lanes[0][6][0]))
    gcols, goffs, dirs, ng, gi = _guard_tables(guards)
    m = key[4]
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
        held = [r for r in range(N) if on[r]]
        maps = [_joint_map(views[r], lanes[r][3]) for r in held]
        if not any(M is None for M in maps):
            if held:
                _held_rows(views, list(range(N)), [(None, lanes[r][3]) if on[r] else None
                                                   for r in range(N)],
                           held, maps, Yev, Y, cap, Yn)
            for v, x, t_stop in zip(views, list(Yev), stops):  # RigidView.settle
                v.t, v.x = t_stop, x
                if t_stop >= v.t_step + v.max_step_time:
                    v.ended = "stall"
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
