"""The native vector environment's common control period, from the actions to the step's
outputs in one pass over the walkers (:class:`walkerlab.gym.vector.WalkerVectorEnv`'s
physics: :func:`step_common`).

:func:`walkerlab.gym.rigid_rows.advance_rows` advances any set of walkers piece by piece,
asking each walker for its piece (:meth:`~walkerlab.gym.rigid_view.RigidView.next_piece`),
grouping the pieces by flow, writing each walker's held torques into its law block and
reading the law blocks back into the kernel's data rows, around
:func:`~walkerlab.gym.batch.begin_periods` and :func:`~walkerlab.gym.batch.end_periods`, which
read the walkers again.  In a common period every walker is in a compiled phase whose flow
key is known (kept in the walker: ``RigidView._lane``, ``row_keys``; a walker whose step
walker, phase or stance leg is not its lane's - a reset walker - has its lane made first, as
``next_piece`` makes it as a period begins), all of one flow - so that work is the same
every period.  Here the walkers are read once (``operator.attrgetter``, one C call per
walker), the kernel's data rows are each walker's flow's row made once
(:func:`_flow_row`, checked against ``data_rows``) stacked per set of lanes with this
period's torques and step clocks written as columns, the states are the last common
period's array when the walkers still hold its rows, and the kernel
(:func:`walkerlab.integrate.rows_dop853.period_rows`) is called on them; the rows that
reached their piece's end are settled at once (their ledger by
:func:`~walkerlab.gym.rigid_rows._held_rows`, as the walker's own), the others (a guard
crossing, a failed step) absorbed by their walkers as
:func:`~walkerlab.gym.rigid_rows.advance_rows` absorbs them, their periods going on through
:func:`~walkerlab.gym.rigid_rows.advance_live`; the outputs are
:func:`~walkerlab.gym.batch.end_periods`' of what was read.  The same kernel on the same
rows, states, data and caps, and the same element-wise operations, so the same numbers bit
for bit as each walker's own period (``gym.make``'s environment is
:func:`~walkerlab.gym.rigid_rows.advance_rows` on one walker).  A period that is not common
(a walker whose episode ended, a phase whose flow key is not made yet, a height profile, a
fall guard checked at a phase's entry, walkers of several flows) is left to the general
step, nothing changed but the walkers' lanes made current.  Nothing here knows a walker's
size: the states' width is the flow key's, the torques' the action's.
"""

from __future__ import annotations

from operator import attrgetter, is_, itemgetter

import numpy as np

from walkerlab.codegen.torque_law import HEAD
from walkerlab.integrate.rows_dop853 import TIMEOUT

from .batch import _hips, end_periods, held_torques
from .rigid_rows import (
    _CFUNCS,
    _ENTRY,
    _absorb_rows,
    _guard_tables,
    _held_rows,
    _joint_map,
    _kernel_args,
    _period_rows,
    advance_live,
    period_buffers,
)
from .rigid_view import _CONSTANT_0
from .small_arrays import all_finite

__all__ = ["step_common"]


def _hold(view, fast, u: np.ndarray) -> None:
    """Write the held torques ``u`` into the compiled phase ``fast``'s law block as
    :meth:`~walkerlab.gym.rigid_view.RigidView.next_piece` writes them (where it does not
    hold these very numbers), its memo kept."""
    held, bits = view._held, u.tobytes()
    if held[0] is not fast or held[1] != bits:
        fast[1][_CONSTANT_0:_CONSTANT_0 + HEAD * u.size:HEAD] = u
        view._held = (fast, bits)


def _flow_row(flow, acts) -> tuple:
    """``(row, u_cols, t_col, same)``: the kernel's data row (1, size) of a walker's
    compiled flow as :meth:`walkerlab.models.compiled_flows.ActuatedFlow.data_rows` writes it
    (its constants, its law block, its step clock), where the held torques of ``acts``
    go (the law block's constants: each actuator's ``HEAD``-th slot from
    :data:`~walkerlab.gym.rigid_view._CONSTANT_0`, as columns ``u_cols``) and its step
    clock (``t_origin``, the block's third slot: column ``t_col``); ``same``: a torque
    written into the law block (as :meth:`~walkerlab.gym.rigid_view.RigidView.next_piece`
    writes it) gives ``data_rows``' row bit for bit as the row with the torque written
    into its columns (checked once, the law block put back as it was; False: a flow of
    another layout, whose rows are ``data_rows``' every period)."""
    nc = flow.constants().size
    row = np.empty((1, flow.data_size()))
    flow.data_rows([flow], row)
    k = acts.u.size
    u_cols = slice(nc + _CONSTANT_0, nc + _CONSTANT_0 + HEAD * k, HEAD)
    t_col = nc + 2
    laws = flow.laws
    kept = laws.copy()
    test = 0.5 + np.arange(k, dtype=float)
    laws[_CONSTANT_0:_CONSTANT_0 + HEAD * k:HEAD] = test
    ref = np.empty_like(row)
    flow.data_rows([flow], ref)
    laws[:] = kept
    mine = row.copy()
    mine[:, u_cols] = test
    mine[:, t_col] = float(getattr(flow.actuators, "t_origin", 0.0))
    return row, u_cols, t_col, mine.tobytes() == ref.tobytes()


#: most entries of a vector env's caches (:func:`step_common`'s ``cache``; cleared when
#: full)
KEPT = 256
#: most sets of lanes whose batch (:func:`_batch`) a vector env keeps (cleared when full:
#: 8 walkers out of step under random actions meet about 800 sets in 3,000 steps)
BATCHES_KEPT = 1024


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
            flows = cache.setdefault("flows", {})  # (a flow's row, once: the flow kept)
            row = flows.get(id(flow))
            if row is None:
                row = flows[id(flow)] = (flow, _flow_row(flow, lane[3]))
            out = (lane, keys.setdefault(kg[0], kg[0]), kg[1], flow, row[1])
    lanes[id(lane)] = out
    return out


#: what a common period reads of each walker (its view, its environment), in C
_VIEW = attrgetter("_lane", "walker", "k", "leg", "ended", "t", "t_step", "max_step_time",
                   "x", "ledger", "steps", "foot")
_ENV = attrgetter("_elapsed", "dt", "_hip_x", "terrain_seed")
_FIRST, _THIRD, _FOURTH = itemgetter(0), itemgetter(2), itemgetter(3)
_WORK = itemgetter("action_work_positive")  # (a ledger's positive action work [J])


def _common(envs, views, cache: dict):
    """What a common period reads of the walkers, in one pass, before anything changes:
    ``(key, entries, read, caps, stops, t_ends, env_read, stall, elapsed)`` (the flow key they
    share; each walker's lane entry (:func:`_lane_entry`), what is read of its view
    (:data:`_VIEW`), its piece's span [s] and end [s], its period's end [s]
    (:func:`~walkerlab.gym.batch.begin_periods`' ``k dt``), what is read of its
    environment (:data:`_ENV`); whether some walker's piece ends at its step's time limit
    (``t_step + max_step_time <= t_end``: settled there, it stalls); each environment's
    count of periods with this one (``_elapsed + 1``)); None when the period is not
    common."""
    lanes_kept = cache.get("lanes") or {}
    key = None
    stall = False
    entries, caps, stops, t_ends, elapsed = [], [], [], [], []
    read = list(map(_VIEW, views))
    env_read = list(map(_ENV, envs))
    for r, (got, er) in enumerate(zip(read, env_read)):
        lane, t = got[0], got[5]
        k = er[0] + 1
        t_end = k * er[1]
        if got[4] or not t < t_end:
            return None
        if lane is None or lane[0] is not got[1] or lane[1] != got[2] or lane[2] != got[3]:
            # a walker in another step or phase than its lane's (a reset walker, most
            # often): its lane made as next_piece makes it as the period begins
            v = views[r]
            lane = v._lane = v.lane_at(got[1])
        en = lanes_kept.get(id(lane)) or _lane_entry(views[r], lane, cache)
        if en[1] is not key:
            if key is not None or en[1] is None:  # (walkers of several flows; a lane the
                return None  # common period cannot run)
            key = en[1]
        elif key is None:  # (the first walker's lane: one the common period cannot run)
            return None
        t_stop = got[6] + got[7]  # (next_piece's end of the piece: t_step + max_step_time)
        if t_stop <= t_end:  # (RigidView.settle's stall: t_stop >= t_step + max_step_time)
            stall = True
        if not t_stop < t_end:
            t_stop = t_end
        entries.append(en)
        caps.append(t_stop - t)
        stops.append(t_stop)
        t_ends.append(t_end)
        elapsed.append(k)
    return key, entries, read, caps, stops, t_ends, env_read, stall, elapsed


def step_common(envs, views, actions: np.ndarray, p: dict, cache: dict):
    """One control period of every walker when it is common (module docstring), from the
    actions to the step's outputs: :func:`~walkerlab.gym.batch.begin_periods`,
    :func:`walkerlab.gym.rigid_rows.advance_rows` and
    :func:`~walkerlab.gym.batch.end_periods` of ``envs`` (their walkers ``views``), the same
    numbers bit for bit, with
    one read of the walkers before the period, one write as it opens and one read and
    write as it ends.

    Parameters
    ----------
    envs : sequence of walkerlab.gym.env.WalkerEnv
        N rigid-view environments, each reset.
    views : sequence of walkerlab.gym.rigid_view.RigidView
        ``[e.sim for e in envs]``.
    actions : ndarray (N, k)
        Checked finite actions (:func:`~walkerlab.gym.batch.begin_periods`).
    p : dict
        :func:`~walkerlab.gym.batch.batch_parameters` of ``envs``.
    cache : dict
        The vector env's own (what a common period of its walkers reads, kept).

    Returns
    -------
    tuple or None
        :func:`~walkerlab.gym.batch.end_periods`' ``(obs, reward, terminated, truncated,
        columns)``; None when the period is not common (nothing changed: the caller steps
        the walkers its own way).
    """
    cache["steady"] = None  # (what a steady period reuses: this one's, when it is one)
    got = _common(envs, views, cache)
    if got is None:
        return None
    key, entries, read, caps, stops, t_ends, env_read, stall, elapsed = got
    U = held_torques(envs, actions, p)  # (the policy's at the present states)
    rows_u = list(U)
    lanes = list(map(_FIRST, entries))
    (_, walkers, ks, legs, _, _, t_steps, msts, xs, ledgers, steps, feet) = zip(*read)
    x_before = list(map(_THIRD, env_read))  # (the reward's origins, before the period)
    w_before = list(map(_WORK, ledgers))
    on = list(map(any, U.tolist()))
    batch = _batch(cache, key, entries, lanes, walkers, views)
    out = _integrate(views, entries, lanes, rows_u, U, on, key, batch, xs, caps, cache)
    which, te, Yev, Y, cap, Yn, call = out
    env_cols = (elapsed, list(map(_FOURTH, env_read)))  # (counts and terrain seeds)
    settled, slow = _settle_rows(views, on, which.tolist(), Yev, Y, cap, Yn, U, batch)
    if not slow:
        X = list(Yev)
        cache["X"] = (Yev, X)
        # the hips' x: one call of the walkers' one points function on the states as
        # columns (hip_xs' numbers: the foot's x plus the hip's from the foot)
        hx = _hips(walkers[0], Yev) if batch[5] else None
        hips = (None if hx is None
                else [foot.item(0) + h for foot, h in zip(feet, hx.tolist())])
        settle_all(envs, views, lanes, rows_u, t_ends, elapsed, X, stops,
                   hips if hips is not None else [None] * len(views))
        ended = [""] * len(views)
        if stall:  # (RigidView.settle: a walker at its step's time limit)
            for r, (t_stop, t_step, mst) in enumerate(zip(stops, t_steps, msts)):
                if t_stop >= t_step + mst:
                    views[r].ended = ended[r] = "stall"
        elif hips is not None:  # (a steady period next: walkerlab.gym.rows_steady)
            cache["steady"] = (envs, views, p, key, entries, lanes, batch, read, env_read,
                               Yev, X, stops, elapsed, hips)
        return end_periods(envs, U, [[] for _ in views], x_before, w_before, p, views,
                           Yev, (X, stops, legs, ks, t_steps, ended, steps, ledgers), hips,
                           batch[6], env_cols, hips is not None)
    return slow_period(envs, views, lanes, rows_u, on, stops, t_ends, settled, slow, out, U,
                       x_before, w_before, p, env_cols, cache)


def slow_period(envs, views, lanes, rows_u, on, stops, t_ends, settled, slow, out, U,
                x_before, w_before, p, env_cols, cache) -> tuple:
    """A common period whose rows ``slow`` did not settle at their pieces' ends (a guard
    crossing, a failed step, a state not finite), its kernel's ``out`` run
    (:func:`_integrate`; the ledgers of the rows ``settled`` taken: :func:`_settle_rows`):
    each walker's period opened (:func:`settle_all`'s count, period and torques
    ``rows_u``), the rows settled or absorbed and their periods gone on
    (:func:`_absorb_slow`), and :func:`~walkerlab.gym.batch.end_periods`' outputs
    (``x_before``, ``w_before``: the reward's origins; ``env_cols``: the counts and terrain
    seeds) of the walkers read again."""
    elapsed = env_cols[0]
    for e, v, lane, u, t_end, k in zip(envs, views, lanes, rows_u, t_ends, elapsed):
        e._elapsed = k  # (begin_periods, open_period, next_piece)
        v._period = (u, t_end)  # (its step's log: a profile's alone, never common)
        lane[3].u = u
    # (the data rows as they are now: the batch's own array is written again next period,
    # a guard crossing's dense output may read them later)
    Yev, call = out[2], out[6]
    X = list(Yev)
    out = (*out[:6], (*call[:3], call[3].copy(), *call[4:]))
    strikes = _absorb_slow(views, lanes, rows_u, on, stops, t_ends, settled, slow, X, out)
    cache["X"] = (Yev, X)  # (the settled walkers' rows; the others' own: not reused)
    return end_periods(envs, U, strikes, x_before, w_before, p, views, env_cols=env_cols)


def settle_all(envs, views, lanes, rows_u, t_ends, elapsed, X, stops, hips) -> None:
    """Each walker's period opened (:func:`~walkerlab.gym.batch.begin_periods`' count,
    :meth:`~walkerlab.gym.rigid_view.RigidView.open_period`, ``next_piece``'s torques
    ``rows_u``) and settled at its piece's end ``stops`` [s] in the state ``X[r]``
    (:meth:`~walkerlab.gym.rigid_view.RigidView.settle`, no stall), in one pass; ``hips``
    [m]: each environment's next reward's origin (None:
    :func:`~walkerlab.gym.batch.end_periods`' to write)."""
    for e, v, lane, u, t_end, k, x, t_stop, h in zip(
            envs, views, lanes, rows_u, t_ends, elapsed, X, stops, hips):
        e._elapsed = k  # (begin_periods, open_period, next_piece)
        v._period = (u, t_end)  # (its step's log: a profile's alone, never common)
        lane[3].u = u
        v.t = t_stop
        v.x = x
        e._hip_x = h  # (the next period's reward's origin; None: end_periods' to write)


def _absorb_slow(views, lanes, rows_u, on, stops, t_ends, settled, slow, X, out) -> list:
    """The walkers ``settled`` settled at their pieces' ends ``stops`` [s] in the states
    ``X`` (:meth:`~walkerlab.gym.rigid_view.RigidView.settle`), the rows ``slow`` absorbed
    by their walkers (:func:`~walkerlab.gym.rigid_rows._absorb_rows` of the kernel's
    ``out``) and their periods gone on (:func:`~walkerlab.gym.rigid_rows.advance_live`);
    returns each walker's heel-strike times [s]."""
    for r in settled:  # RigidView.settle
        v, t_stop = views[r], stops[r]
        v.t, v.x = t_stop, X[r]
        if t_stop >= v.t_step + v.max_step_time:
            v.ended = "stall"
    # a walker's own absorbing may integrate its piece again with its own flow, whose law
    # block then holds the torques (as next_piece leaves it)
    pieces = []
    for r, (v, lane, u, a, t_stop) in enumerate(zip(views, lanes, rows_u, on, stops)):
        if r in slow:
            _hold(v, lane[6], u)
        pieces.append((lane[0], lane[3], a, lane[4], t_stop, lane[6]))
    strikes: list[list[float]] = [[] for _ in views]
    _absorb_rows(views, list(range(len(views))), pieces, out, strikes, set(slow))
    live = [i for i in slow if views[i].t < t_ends[i] and not views[i].ended]
    if live:
        advance_live(views, rows_u, t_ends, live, strikes)
    return strikes

def _batch(cache: dict, key: tuple, entries: list, lanes: list, walkers, views) -> tuple:
    """What a common period of these lanes reads every period, made once and kept by the
    lanes' ids: ``(base, clocks, same, kernel, guard_tables, one_points, fixed, maps,
    origins, held, entries)`` - the walkers' data rows stacked (:func:`_flow_row`) and
    their step clocks, whether each row takes its torques and clock as columns, the
    kernel's compiled functions and tolerances, its guard tables, whether the walkers share
    one ``points`` function, the observations' stance-leg and phase columns (N, 2), each
    walker's joints' map with whether every walker has one
    (:func:`~walkerlab.gym.rigid_rows._joint_map`: kept in the walker, for the lane's
    actuators), the flows' actuators (:func:`_origins`), the kernel's data rows of these
    walkers as last written (:func:`_integrate`: ``[D, step clocks written]``, empty until
    then), and the lane entries themselves (their ids, the key, stay theirs while it
    lives).  Made of each walker's own part (:func:`_part`, kept by its lane entry's id:
    the walkers falling out of step with each other make many sets of lanes, each walker
    few lanes: up to :data:`BATCHES_KEPT` sets kept)."""
    fid = tuple(map(id, entries))
    batches = cache.get("batches")
    if batches is None:
        batches = cache["batches"] = {}
    out = batches.get(fid)
    if out is None:
        if len(batches) >= BATCHES_KEPT:
            batches.clear()
        got = cache.get("parts")
        if got is None or len(got) >= KEPT:
            got = cache["parts"] = {}
        parts = [got.get(i) or _part(got, en, v, lane)
                 for i, en, v, lane in zip(fid, entries, views, lanes)]
        rows, clocks, oks, points, fixed, maps, acts, _ = zip(*parts)
        first = entries[0][4][1:3]
        out = batches[fid] = (
            np.concatenate(rows), list(clocks),
            all(ok and en[4][1:3] == first for ok, en in zip(oks, entries)),
            _CFUNCS.get(key) or _kernel_args(key, lanes[0][6][0]),
            _guard_tables([en[2] for en in entries]),
            all(f is points[0] for f in points),
            np.array(fixed),
            (list(maps), all(M is not None for M in maps)),
            _origins(list(acts)), [], tuple(entries))
    return out


def _part(parts: dict, en: tuple, v, lane: tuple) -> tuple:
    """One walker's part of :func:`_batch` (its lane entry ``en``, view ``v``, lane
    ``lane``): ``(data row (1, size), step clock [s], row takes its torques and clock as
    columns, points function, (leg1's stance as 1.0, phase's index), joints' map or None,
    its flow's actuators)``, kept in ``parts`` by the entry's id (the entry kept with it:
    its id stays its own)."""
    row = en[4][0]
    out: tuple = (row, float(row[0, en[4][2]]), en[4][3], lane[0].points,
           (1.0 if lane[2] == "leg1" else 0.0, lane[1]), _joint_map(v, lane[3]),
           en[3].actuators)
    out = parts[id(en)] = out + (en,)
    return out


#: a flow's actuators' step clock [s] (:func:`_integrate`)
_T_ORIGIN = attrgetter("t_origin")


def _origins(acts: list) -> tuple:
    """``(None, acts)`` when some of the flows' actuators ``acts`` have no step clock
    ``t_origin`` (read as 0.0 each period), else ``(True, acts)`` (each read with
    :data:`_T_ORIGIN`)."""
    return (True if all(hasattr(a, "t_origin") for a in acts) else None), acts


def _integrate(views, entries, lanes, rows_u, U, on, key, batch, xs, caps, cache,
               Y=None) -> tuple:
    """The kernel on every walker's piece: ``(which, te, Yev, Y, cap, Yn, call)`` as
    :func:`walkerlab.gym.rigid_rows._integrate_rows` gives them (its arguments the same:
    the data rows with this period's torques and clocks, the start states - the last
    common period's array when the walkers hold its rows -, the caps [s], the
    Gauss-Legendre nodes of the rows with the action on).  ``Y`` (N, m): the start states
    of a steady period (:mod:`walkerlab.gym.rows_steady`: the walkers untouched since the
    last period, their step clocks those it wrote into the data rows)."""
    base, clocks, same, kernel, (gcols, goffs, dirs, ng, gi) = batch[:5]
    if same:  # (the batch's data rows: this period's torques and clocks written in)
        held = batch[9]
        if not held:
            held += [base.copy(), clocks]
        D = held[0]
        D[:, entries[0][4][1]] = U
        if Y is None:  # (the flows' step clocks, written where they moved)
            acts = batch[8]
            origins = ([float(getattr(a, "t_origin", 0.0)) for a in acts[1]]
                       if acts[0] is None else list(map(float, map(_T_ORIGIN, acts[1]))))
            if origins != held[1]:
                D[:, entries[0][4][2]] = origins
                held[1] = origins
    else:  # (the law blocks written, as next_piece writes them, and read back)
        for v, lane, u in zip(views, lanes, rows_u):
            _hold(v, lane[6], u)
        D = np.empty_like(base)
        entries[0][3].data_rows([en[3] for en in entries], D)
    f, fs, fg, sel, rtol, atol, n_out = kernel
    N, m = len(views), key[4]
    if Y is None:
        last = cache.get("X")  # (the last common period's states: the walkers' own rows)
        if last is not None and len(last[1]) == N and all(map(is_, xs, last[1])):
            Y = last[0]
        else:
            Y = np.array(xs, dtype=float)
    cap, which, te, Yev, Tn, Yn = period_buffers(caps, on, N, m)
    args = (f, fs, fg, sel, Y, D, cap, gcols, goffs, dirs, ng, gi, rtol, atol, n_out, which,
            te, Yev, np.zeros(N), Tn, Yn)
    entry = _ENTRY.get(key)  # (the kernel's compiled entry for these types, once chosen)
    if entry is None:
        _period_rows(key, args)
    else:
        entry(*args)
    call = (key, (f, fs, fg, sel), Y, D, cap, (gcols, goffs, dirs, ng), gi, (rtol, atol, n_out))
    return which, te, Yev, Y, cap, Yn, call


def _settle_rows(views, on, ends, Yev, Y, cap, Yn, U, batch) -> tuple:
    """``(settled, slow)``: the rows that reached their piece's end, each to be settled
    there as :func:`~walkerlab.gym.rigid_rows._absorb_rows` settles it (the ledger of those
    with the action on taken here at once: :func:`~walkerlab.gym.rigid_rows._held_rows`,
    with the held torques ``U`` (N, k) [N m] and the joints' maps kept in ``batch``:
    :func:`_batch`), and the others (a guard crossing, a failed step, a state not finite,
    the ledger on the dense output), to be absorbed by their walkers."""
    N = len(views)
    finite = ([True] * N if all_finite(Yev) else np.isfinite(Yev).all(axis=1).tolist())
    maps_all, every_map = batch[7]
    if min(ends) == TIMEOUT == max(ends) and all(finite):
        if not any(on):
            return range(N), []
        if every_map and all(on):  # (every row's ledger at once: the same rows in order)
            _held_rows(views, range(N), None, list(range(N)), maps_all, Yev, Y, cap, Yn, U)
            return range(N), []
    settled, slow, held, maps = [], [], [], []
    for r in range(N):
        if ends[r] != TIMEOUT or not finite[r]:
            slow.append(r)
        elif on[r]:
            M = maps_all[r]
            if M is None:
                slow.append(r)
            else:
                settled.append(r)
                held.append(r)
                maps.append(M)
        else:
            settled.append(r)
    if held:
        _held_rows(views, range(N), None, held, maps, Yev, Y, cap, Yn,
                   U if len(held) == N else U[held])
    return settled, slow
