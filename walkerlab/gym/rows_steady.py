"""The native vector environment's steady control period: a common period
(:func:`walkerlab.gym.rows_common.step_common`) that follows one whose every walker settled
at its piece's end, its walkers untouched since (:func:`step`, the vector env's physics).

After such a period what a common period reads of each walker is known from what it wrote:
its time is its piece's end, its state the very row of the kernel's output it was given, its
lane, flow key, step walker, phase, stance leg, step's start, steps, ledger and foot those it
had, its count of periods one more.  The walkers are untouched when each one's state ``x``
is still that very array (a reset, a heel strike, any absorbed piece gives a walker a new
one; :meth:`~walkerlab.gym.vector.WalkerVectorEnv.set_attr` and ``call`` give the vector env
new parameters and views); the period then skips reading and checking every walker
(:func:`walkerlab.gym.rows_common._common`) and runs the kernel on the kept batch.  It falls
back on the common period, before any walker is changed, whenever it may not be steady (a
walker's step at its time limit: a stall; torques held by walkers whose ledger is not taken
at once); the rows whose pieces ended otherwise than at their ends (a guard crossing, a
failed step, a state not finite) are taken as the common period takes them
(:func:`walkerlab.gym.rows_common.slow_period`).  The same operations on the same numbers as
the common period, so the same numbers bit for bit.
"""

from __future__ import annotations

import math
from operator import attrgetter, is_, itemgetter, le, sub

import numpy as np

from walkerlab.integrate.rows_dop853 import TIMEOUT

from .batch import _hips, end_periods, held_torques
from .infos import view_messages
from .rows_common import _integrate, _settle_rows, settle_all, slow_period, step_common
from .small_arrays import all_finite

__all__ = ["step"]

_X = attrgetter("x")
_WORK = itemgetter("action_work_positive")  # (a ledger's positive action work [J])


def step(envs, views, actions, p: dict, cache: dict):
    """One control period of every walker: the steady period when the last one left the
    walkers steady (module docstring), else :func:`walkerlab.gym.rows_common.step_common`
    (its arguments and outputs; None when the period is not common)."""
    st = cache.get("steady")
    if st is not None:
        if type(st) is tuple:  # (step_common's last period, read once)
            st = cache["steady"] = _Steady(*st)
        out = st.period(envs, views, actions, p, cache)
        if out is not None:
            return out
    return step_common(envs, views, actions, p, cache)


class _Steady:
    """What a steady period reads of the walkers, kept from the last common period
    (:func:`walkerlab.gym.rows_common.step_common`'s: its walkers, parameters, flow key,
    lane entries, lanes and batch, what it read of each walker and environment, the states
    ``Yev`` (N, m) and their rows ``X``, the times [s], counts and hips' x [m] it wrote) and
    from each steady period after it."""

    __slots__ = ("envs", "views", "p", "key", "entries", "lanes", "batch", "walker", "lim",
                 "lo", "dts", "seeds", "foot", "cols", "off", "known", "strikes", "obs",
                 "sums", "held", "Yev", "X", "T", "K", "hips")

    def __init__(self, envs, views, p, key, entries, lanes, batch, read, env_read, Yev, X,
                 stops, elapsed, hips):
        (_, walkers, ks, legs, _, _, t_steps, msts, _, ledgers, steps, feet) = zip(*read)
        self.envs, self.views, self.p = envs, views, p
        self.key, self.entries, self.lanes, self.batch = key, entries, lanes, batch
        self.walker = walkers[0]
        #: each piece's end at its step's time limit [s] (next_piece's t_step + max_step_time)
        self.lim = [a + b for a, b in zip(t_steps, msts)]
        #: the earliest of them (below every period's end: no stall, each piece to its
        #: period's end; -inf when one is NaN: each compared)
        self.lo = -math.inf if any(map(math.isnan, self.lim)) else min(self.lim)
        self.dts = [er[1] for er in env_read]
        self.seeds = [er[3] for er in env_read]
        self.foot = [f.item(0) for f in feet]
        self.cols = (legs, ks, t_steps, steps, ledgers)
        n = len(views)
        self.off = [False] * n  # (no row's torques on)
        #: end_periods' known columns: no episode ended, each view's own words (a failure's
        #: only on a piece not settled at its end), the ledger's terms
        self.known = ([""] * n, [False] * n,
                      view_messages(views), list(ledgers[0]))
        self.strikes = [[] for _ in views]  # (none: read, never written)
        m = Yev.shape[1]  # (the observations' buffer: its stance-leg and phase columns)
        self.obs = np.empty((n, m + 3))
        self.obs[:, m:m + 2] = batch[6]
        self.sums = None  # (the ledgers' copies as the last period ended)
        #: the last torques' bytes, their rows, whether some and which rows are on
        self.held: tuple = (None, None)
        self.Yev, self.X, self.T, self.K, self.hips = Yev, X, stops, elapsed, hips

    def period(self, envs, views, actions, p: dict, cache: dict):
        """:func:`walkerlab.gym.rows_common.step_common` of a steady period (its arguments
        and outputs), or None before anything changed when the period may not be steady
        (module docstring)."""
        if (envs is not self.envs or views is not self.views or p is not self.p
                or not all(map(is_, map(_X, views), self.X))):
            return None
        ks = [k + 1 for k in self.K]
        t_ends = [k * dt for k, dt in zip(ks, self.dts)]  # (begin_periods' k dt)
        if max(t_ends) < self.lo:  # (every piece to its period's end)
            stops = t_ends
        elif any(map(le, self.lim, t_ends)):  # (a stall: the common period's)
            return None
        else:  # (next_piece's min(t_end, t_step + max_step_time))
            stops = [t if t < te else te for t, te in zip(self.lim, t_ends)]
        U = held_torques(envs, actions, p)
        bits = U.tobytes()
        if bits == self.held[0]:  # (the last period's torques: its rows, which hold them)
            rows_u, some, on = self.held[1]
        else:
            some = any(U.ravel().tolist())
            rows_u = list(U)
            on = list(map(any, U.tolist())) if some else self.off
            self.held = (bits, (rows_u, some, on))
        batch = self.batch
        if some and not batch[7][1]:  # (a ledger not taken at once)
            return None
        w_before = list(map(_WORK, self.cols[4]))
        out = _integrate(views, self.entries, self.lanes, rows_u, U, on, self.key, batch,
                         self.X, list(map(sub, stops, self.T)), cache, self.Yev)
        which, _, Yev, Y, cap, Yn, _ = out
        ends = which.tolist()
        if not (min(ends) == TIMEOUT == max(ends) and all_finite(Yev)):
            # (rows not at their pieces' ends: the common period's slow rows, from here)
            cache["steady"] = None
            settled, slow = _settle_rows(views, on, ends, Yev, Y, cap, Yn, U, batch)
            return slow_period(envs, views, self.lanes, rows_u, on, stops, t_ends, settled,
                               slow, out, U, self.hips, w_before, p, (ks, self.seeds), cache)
        hx = _hips(self.walker, Yev)
        if hx is None:  # pragma: no cover - the common period's hips were made so
            return None
        if some:  # (their ledgers: _settle_rows' at once)
            _settle_rows(views, on, ends, Yev, Y, cap, Yn, U, batch)
        X = list(Yev)
        cache["X"] = (Yev, X)
        hips = [f + h for f, h in zip(self.foot, hx.tolist())]
        settle_all(envs, views, self.lanes, rows_u, t_ends, ks, X, stops, hips)
        x_before = self.hips
        self.Yev, self.X, self.T, self.K, self.hips = Yev, X, stops, ks, hips
        legs, kk, t_steps, steps, ledgers = self.cols
        sums = self.sums
        if some or sums is None:  # (no torque: the ledgers as the last period left them)
            sums = self.sums = list(map(dict.copy, ledgers))
        known = self.known
        return end_periods(envs, U, self.strikes, x_before, w_before, p, views, Yev,
                           (X, stops, legs, kk, t_steps, known[0], steps, ledgers), hips,
                           self.obs, (ks, self.seeds), True, (*known[1:], some, sums))
