"""The native vector environment's steps of many rigid-view walkers at once
(:class:`walkerlab.gym.vector.WalkerVectorEnv`): what they read of each environment stacked
(:func:`batch_parameters`), the held torques of all of them (:func:`begin_periods`), and, once
their walkers are advanced (:func:`walkerlab.gym.rigid_rows.advance_rows`), their
observations, rewards, flags and infos as columns (:func:`end_periods`, the hips' x of all
of them at once: :func:`hip_xs`) - the same element-wise operations as each
:class:`~walkerlab.gym.env.WalkerEnv`'s own ``step``, bit for bit."""

from __future__ import annotations

from operator import attrgetter, itemgetter

import numpy as np

from .infos import view_messages

__all__ = ["batch_parameters", "begin_periods", "end_periods", "held_torques", "hip_xs"]


def batch_parameters(envs) -> dict | None:
    """What :func:`begin_periods` and :func:`end_periods` read of each environment, stacked
    over ``envs`` (N rigid-view :class:`~walkerlab.gym.env.WalkerEnv`); None when they
    cannot step these walkers together (a contact view, a ``reward_fn``, or action sizes
    that differ): each is then stepped by its own
    :meth:`~walkerlab.gym.env.WalkerEnv.step`.

    Returns
    -------
    dict or None
        ``tau`` (N, k) [N m] the action bounds; ``scale`` (N, k) [N m or -] what an action
        is multiplied by (``tau`` with ``normalize_action``, else 1); ``policy`` (N,) bool
        ``policy="scene"``; ``fw``, ``healthy``, ``cw``, ``ww``, ``dt`` (N,) the reward's
        weights and the control period [s]; ``limit`` (N,) int the environment's own
        ``max_episode_steps`` (-1: none); ``low``, ``high`` (N, m + 3) the observation's
        bounds.  :func:`begin_periods` and :func:`end_periods` keep Python forms of some of
        them in it (``flags``, ``lists``: not arrays over the walkers).
    """
    if any(e.view != "rigid" or e.reward_fn is not None for e in envs):
        return None
    if len({e.tau_max.shape for e in envs}) != 1 or len(
            {e.observation_space.shape for e in envs}) != 1:
        return None
    tau = np.array([e.tau_max for e in envs], dtype=np.float64)
    w = np.array([e.weights for e in envs], dtype=np.float64)
    return {"tau": tau,
            "scale": np.where(np.array([[e.normalize_action] for e in envs]), tau, 1.0),
            "normalize": np.array([e.normalize_action for e in envs]),
            "policy": np.array([e.policy == "scene" for e in envs]),
            "fw": w[:, 0], "healthy": w[:, 1], "cw": w[:, 2], "ww": w[:, 3],
            "dt": np.array([e.dt for e in envs], dtype=np.float64),
            "limit": np.array([-1 if e.max_episode_steps is None else e.max_episode_steps
                               for e in envs], dtype=np.int64),
            "low": np.array([e.observation_space.low for e in envs]),
            "high": np.array([e.observation_space.high for e in envs])}


def _flags(p: dict) -> tuple:
    """``(every walker's action normalised, some are, some run the scene's policy)`` of
    :func:`batch_parameters`' ``p``, kept in it (as Python values: they are read every
    period)."""
    flags = p.get("flags")
    if flags is None:
        norm = p["normalize"]
        flags = p["flags"] = (bool(norm.all()), bool(norm.any()), bool(p["policy"].any()))
    return flags


def _lists(p: dict) -> tuple:
    """The reward's weights and the limits of :func:`batch_parameters`' ``p`` as lists of
    Python numbers ``(fw, healthy, cw, ww, dt, limit)``, kept in it."""
    lists = p.get("lists")
    if lists is None:
        lists = p["lists"] = tuple(p[k].tolist() for k in ("fw", "healthy", "cw", "ww",
                                                           "dt", "limit"))
    return lists


def _no_limit(p: dict, limits: list) -> bool:
    """Whether no environment of :func:`batch_parameters`' ``p`` has a limit of its own
    (``limits``: its ``limit`` as a list), kept in it."""
    out = p.get("no_limit")
    if out is None:
        out = p["no_limit"] = all(lim < 0 for lim in limits)
    return out


def begin_periods(envs, actions: np.ndarray, p: dict) -> tuple:
    """:meth:`~walkerlab.gym.env.WalkerEnv.begin_period` of N rigid-view environments at
    once: the held torques of every row of ``actions``, each period counted.

    Parameters
    ----------
    envs : sequence of walkerlab.gym.env.WalkerEnv
        N environments, each reset.
    actions : ndarray (N, k)
        Checked finite actions (fractions of ``tau_max``, or N m), any real dtype.
    p : dict
        :func:`batch_parameters` of ``envs``.

    Returns
    -------
    U : ndarray (N, k)
        The held torques [N m] (the action scaled, the scene policy's added, clipped to the
        bounds: the same operations as one environment's, element by element).
    x_before, w_before : list of float (N)
        The hip's x at the period's start [m] and the positive action work so far [J].
    t_ends : list of float
        Each period's end [s].
    """
    U = held_torques(envs, actions, p)
    x_before, w_before, t_ends = [], [], []
    for e in envs:
        x_before.append(e._hip_x)
        w_before.append(e.sim.ledger["action_work_positive"])
        e._elapsed = k = e._elapsed + 1
        t_ends.append(k * e.dt)
    return U, x_before, w_before, t_ends


def held_torques(envs, actions: np.ndarray, p: dict) -> np.ndarray:
    """The held torques (N, k) [N m] of ``actions`` (N, k) (:func:`begin_periods`' first
    half: scaled, the scene policy's added at the walkers' present states, clipped; a new
    array)."""
    norm = p["normalize"]
    every, some, policy = p.get("flags") or _flags(p)
    tau = p["tau"]
    if every:  # (the actions read as float64, then scaled: numpy's casting of any real
        # dtype, in one operation; float32 or float64 ones are cast so by the product)
        a = (np.multiply(actions, tau) if actions.dtype in _PROMOTED
             else np.multiply(actions, tau, dtype=np.float64))
    else:
        a = np.asarray(actions).astype(np.float64)
    if not every and some:
        a[norm] = a[norm] * tau[norm]
    if policy:
        for r in np.flatnonzero(p["policy"]):
            e = envs[r]
            s = e.sim
            a[r] = a[r] + e._controller_torques(s.x, s.leg == "leg1")
    # (np.clip's own ufunc, into the new array a: ndarray.clip(-tau, tau)'s numbers)
    return _CLIP(a, _neg_tau(p), tau, out=a)


#: actions' dtypes whose product with float64 torques is float64 (numpy's promotion)
_PROMOTED = frozenset({np.dtype(np.float32), np.dtype(np.float64)})
#: the ufunc ``ndarray.clip(lo, hi)`` calls (numpy's ``_methods._clip``: ``umath.clip``),
#: without its Python layer (numpy's own function where its module is not there)
_CLIP = getattr(getattr(getattr(np, "_core", None), "umath", None), "clip", np.clip)


def _neg_tau(p: dict) -> np.ndarray:
    """``-p["tau"]``, kept in :func:`batch_parameters`' ``p``."""
    neg = p.get("neg_tau")
    if neg is None:
        neg = p["neg_tau"] = -p["tau"]
    return neg


def _observations(X: np.ndarray, ts, legs, ks, t_steps, p: dict, fixed=None) -> np.ndarray:
    """The observations (N, m + 3) of the states ``X`` (N, m): each state, then leg1's
    stance as 1.0, the phase's index as a float and the time in the step [s] (``ts``
    minus ``t_steps``; the float64 of each; the first two ``fixed`` (N, 2) when given, or
    a buffer ``fixed`` (N, m + 3) holding them in its columns ``m, m + 1``, the others
    written here), clipped to :func:`batch_parameters`' bounds (a new array)."""
    m = X.shape[1]
    if fixed is not None and fixed.shape[1] == m + 3:
        obs = fixed
    else:
        obs = np.empty((X.shape[0], m + 3))
        if fixed is None:
            obs[:, :m] = X
            obs[:, m:] = [(1.0 if leg == "leg1" else 0.0, k, tv - ts0) for leg, k, tv, ts0
                          in zip(legs, ks, ts, t_steps)]
            return _CLIP(obs, p["low"], p["high"], out=obs)  # (ndarray.clip's ufunc)
        obs[:, m:m + 2] = fixed
    obs[:, :m] = X
    obs[:, m + 2] = [tv - ts0 for tv, ts0 in zip(ts, t_steps)]
    return _CLIP(obs, p["low"], p["high"], out=None if obs is fixed else obs)


#: a ledger's positive action work [J]
_WORK = itemgetter("action_work_positive")
#: what :func:`end_periods` reads of each environment
_ENV_READ = attrgetter("_elapsed", "terrain_seed")


def end_periods(envs, U: np.ndarray, strikes: list, x_before: list, w_before: list,
                p: dict, views=None, X: np.ndarray | None = None,
                cols: tuple | None = None, hips: list | None = None,
                fixed: np.ndarray | None = None, env_cols: tuple | None = None,
                written: bool = False, known: tuple | None = None) -> tuple:
    """:meth:`~walkerlab.gym.env.WalkerEnv.end_period` of N rigid-view environments at
    once, their walkers advanced (:func:`walkerlab.gym.rigid_rows.advance_rows`):
    observations, rewards, flags and the infos as columns.

    Parameters
    ----------
    envs : sequence of walkerlab.gym.env.WalkerEnv
    U : ndarray (N, k)
        The held torques [N m] (:func:`begin_periods`).
    strikes : list of list of float
        Each walker's heel-strike times in the period [s].
    x_before, w_before : list of float (N)
        :func:`begin_periods`' hip x [m] and positive work [J] at the period's start.
    p : dict
        :func:`batch_parameters` of ``envs``.
    views : list of RigidView, optional
        ``[e.sim for e in envs]``, when the caller has it.
    X : ndarray (N, 2n), optional
        The walkers' states stacked, when the caller has them (``views[i].x`` is
        ``X[i]``: :func:`walkerlab.gym.rows_common.step_common`).
    cols : tuple, optional
        What is read of the walkers (below: states, times, stance legs, phases, steps'
        starts, ends, steps, ledgers, each a sequence of N), when the caller has read it.
    hips : list of float, optional
        The hips' world x [m] (:func:`hip_xs`' numbers), when the caller has them.
    fixed : ndarray (N, 2) or (N, m + 3), optional
        The observations' stance-leg and phase columns (leg1's stance as 1.0, the phase's
        index), when the caller has them; or a buffer holding them in its columns ``m, m +
        1`` (its other columns written here: the caller's, kept from call to call).
    env_cols : tuple, optional
        ``(elapsed, seeds)``: each environment's period count (``_elapsed``, this period
        counted) and ``terrain_seed``, sequences of N, when the caller has read them.
    written : bool
        The caller has written ``hips`` into each environment (its next period's reward's
        origin).
    known : tuple, optional
        ``(terminated, messages, terms, some, sums)``, when the caller knows them: each
        episode's end as a bool (list of N; ``cols``' ends), each view's solver words
        (:func:`~walkerlab.gym.infos.view_messages`), the ledgers' terms in order,
        whether some torque in ``U`` is not zero, the ledgers' copies (list of N dicts,
        never written: ``ledgers``' numbers now).

    Returns
    -------
    obs : ndarray (N, m + 3) float64
    reward : ndarray (N,) float64
    terminated, truncated : ndarray (N,) bool
    columns : callable
        ``columns()``: the infos by key (:data:`~walkerlab.gym.env.INFO_KEYS`, then
        ``ledger_<term>``, in the order of :meth:`~walkerlab.gym.env.WalkerEnv._info`'s
        dict), each a list or array of N values of the types that dict holds (floats,
        bools, ints, text, None, lists), made when called (a step whose infos are not read
        does not make them) from what this call read of the walkers: the same entries
        whenever called.
    """
    if views is None:
        views = [e.sim for e in envs]
    # what is read of each walker, in one pass: its state, time, stance leg, phase, its
    # step's start, how its episode ended, its steps and ledger
    if cols is None:
        cols = zip(*[(v.x, v.t, v.leg, v.k, v.t_step, v.ended, v.steps, v.ledger)
                     for v in views])
    xs, ts, legs, ks, t_steps, ended, steps, ledgers = cols  # (sequences)
    if X is None:
        X = np.array(xs)
    obs = _observations(X, ts, legs, ks, t_steps, p, fixed)
    if hips is None:
        hip = hip_xs(views, X)
        hips = hip.tolist()
    else:
        hip = None  # (made of hips when the infos are)
    if not written:
        for e, h in zip(envs, hips):
            e._hip_x = h  # the next period's start (its reward's origin)
    # (each environment's count and seed)
    elapsed, seeds = zip(*map(_ENV_READ, envs)) if env_cols is None else env_cols
    if known is None:
        terminated = list(map(bool, ended))  # (an end's text: "" while the episode goes on)
        messages = view_messages(views)
        terms = list(ledgers[0])  # (every walker's ledger holds LEDGER_TERMS in order)
        some = any(U.ravel().tolist())
        sums = list(map(dict.copy, ledgers))  # (the ledgers now: copies, read as lists)
    else:
        terminated, messages, terms, some, sums = known
    fws, healthy, cws, wws, dts, limits = _lists(p)
    if _no_limit(p, limits):  # (no environment's own limit: a vector env's walkers)
        truncated = np.zeros(len(terminated), dtype=np.bool_)
    else:
        truncated = np.array([not te and lim >= 0 and el >= lim
                              for te, lim, el in zip(terminated, limits, elapsed)],
                             dtype=np.bool_)
    # the reward of each walker as its own end_period computes it, on Python floats (the
    # same IEEE operations in the same order as there)
    if some:
        effort = U / p["tau"]
        effort = np.add.reduce(np.square(effort, out=effort), axis=1).tolist()  # (** 2)
    else:  # (no torque: each walker's sum of (0 / tau)^2 is 0.0)
        effort = [0.0] * len(views)
    work = list(map(_WORK, sums))
    reward = np.array([
        fw * (h - xb) / dt + (0.0 if te else hl) - cw * c - ww * (wa - wb) / dt
        for fw, h, xb, dt, te, hl, cw, c, ww, wa, wb in zip(
            fws, hips, x_before, dts, terminated, healthy, cws, effort, wws, work,
            w_before)], dtype=np.float64)

    def columns() -> dict:  # (of the values read above, whenever called)
        L = np.array(list(map(list, map(dict.values, sums))), dtype=np.float64).T.copy()
        out = {"time_s": np.array(ts, dtype=np.float64),
               "heel_strike": [bool(s) for s in strikes],
               "heel_strike_time_s": [float(s[-1]) if s else None for s in strikes],
               "heel_strike_times_s": [[float(x) for x in s] for s in strikes],
               "steps": [int(s) for s in steps],
               "stance_leg": list(legs),
               "hip_x_m": np.array(hips, dtype=np.float64) if hip is None else hip,
               "termination": list(ended),
               "solver_message": [str(m) for m in messages],
               "terrain_seed": [int(s) for s in seeds]}
        out.update({f"ledger_{k}": L[j] for j, k in enumerate(terms)})
        return out

    return obs, reward, np.array(terminated, dtype=np.bool_), truncated, columns


#: per ``points`` function (by id): ``(points, the hips' x of states as columns or None)``
_COLUMN_POINTS: dict = {}


def _hips(walker, X: np.ndarray):
    """The hip's x relative to the stance foot [m] of the states ``X`` (r, 2n), one call on
    the states as columns (the contract of ``points``: :mod:`walkerlab.models.hybrid.base`)
    of the walker's generated hip's x alone (:attr:`HybridWalker.hip_x`) or of its whole
    ``points``; None when neither takes them (checked once per function against a call of
    ``points`` per state: the same numbers bit for bit - numpy's vector loops may round
    differently from its scalar ones - or not used)."""
    points = walker.points
    entry = _COLUMN_POINTS.get(id(points))
    if entry is None:
        fns = [] if walker.hip_x is None else [walker.hip_x]
        fns.append(lambda Xt: points(Xt)["hip"][0])
        each = [float(points(x)["hip"][0]) for x in X]
        fn = None
        for f in fns:
            try:
                hx = np.asarray(f(X.T), float)
                if hx.shape == (X.shape[0],) and np.array_equal(hx, each):
                    fn = f
                    break
            except Exception:  # noqa: BLE001 - a function of one state only
                pass
        entry = _COLUMN_POINTS[id(points)] = (points, fn)  # (kept: its id stays its own)
    if entry[1] is None:
        return None
    return np.asarray(entry[1](X.T), float)


def hip_xs(views, X: np.ndarray | None = None) -> np.ndarray:
    """:meth:`walkerlab.gym.rigid_view.RigidView.hip_x` of every view in ``views`` (N),
    the views whose step walkers share a ``points`` function in one call of it where it
    takes states as columns (the same numbers).

    Parameters
    ----------
    views : sequence of walkerlab.gym.rigid_view.RigidView
    X : ndarray (N, 2n), optional
        Their states (``views[i].x``), when already stacked.

    Returns
    -------
    ndarray (N,)
        The hips' world x [m].
    """
    if len(views) > 1 and X is not None:
        first = views[0].walker.points
        if all(v.walker.points is first for v in views):
            hx = _hips(views[0].walker, X)  # one step walker's points for all: one call
            if hx is not None:
                return np.array([v.foot.item(0) for v in views]) + hx  # (x's floats)
    pts = [v.walker.points for v in views]
    out = np.empty(len(views))
    groups: dict = {}
    for i, f in enumerate(pts):
        groups.setdefault(id(f), []).append(i)
    for rows in groups.values():
        if len(rows) < 2:
            hx = None
        elif X is not None and len(rows) == len(views):
            hx = _hips(views[rows[0]].walker, X)
        else:
            hx = _hips(views[rows[0]].walker, np.array([views[i].x for i in rows]))
        if hx is None:
            out[rows] = [views[i].hip_x() for i in rows]
        else:
            out[rows] = np.array([views[i].foot[0] for i in rows]) + hx
    return out
