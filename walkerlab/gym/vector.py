"""``walkerlab/Walker-v0`` vectorised in one process: :class:`WalkerVectorEnv`, the id's
``vector_entry_point`` (``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")``).

N walkers of one scene are stepped per call, with gymnasium's batched spaces
(:func:`gymnasium.vector.utils.batch_space`), its autoreset convention (gymnasium 1.x:
``AutoresetMode.NEXT_STEP`` by default, declared in ``metadata["autoreset_mode"]``), the
id's time limit per sub-environment and ``SyncVectorEnv``'s seeding (``reset(seed=s)``
seeds sub-environment ``i`` with ``s + i``): for the same seeds and actions its
observations, rewards, flags and infos are those of ``gymnasium.make_vec(...,
vectorization_mode="sync")``, bit for bit with ``batched=False``, and with the batched
step (the default) to round-off (the same falls, resets and heel strikes).

The physics of one call is :meth:`WalkerVectorEnv._step_all`: the rigid view's walkers
(built as ``gym.make``'s entry point builds each :class:`~walkerlab.gym.env.WalkerEnv`:
:func:`~walkerlab.gym.env.registered_env`) are stepped as arrays over the walkers - the
held torques of all of them scaled and clipped at once
(:func:`~walkerlab.gym.batch.begin_periods`), their compiled pieces advanced together
(:func:`walkerlab.gym.rigid_rows.advance_rows`: one compiled call per flow), their
observations, rewards, flags and ledger read at once and their infos kept as columns
(:func:`~walkerlab.gym.batch.end_periods`), batched straight into gymnasium's form (an array
and a mask ``_key`` per key, as ``VectorEnv._add_info`` batches N dicts, without building
them); the same element-wise operations as each walker's own ``step``, so that these
numbers are those of each walker ending its own period on the same physics, bit for bit.
A common period (every stepped walker where its last period left it, in a compiled phase of
one flow: most periods) runs all of this in one pass over the walkers (``step_common``; after
one that settled them all, without reading them: :mod:`walkerlab.gym.rows_steady`).
A ``reward_fn`` (it is given each walker's info dict) has each walker begin and end its
own period around the batched physics; the contact view, or ``batched=False``, steps them
one after another.  The time limit, the autoreset and the batching of the infos are this
class's own and know nothing of the walker (its sizes are its spaces').
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space, create_empty_array

from .arguments import whole_number
from .batch import batch_parameters, begin_periods, end_periods
from .env import DEFAULT_EPISODE_STEPS, InvalidAction, WalkerEnv, registered_env
from .infos import LazyInfos, batch_columns, batch_infos
from .small_arrays import all_finite, any_true

__all__ = ["WalkerVectorEnv"]


def _advance_rows():
    """:func:`walkerlab.gym.rigid_rows.advance_rows` (its module imported on first use:
    the integrators it reads are not needed to build the environment), kept."""
    global _ADVANCE_ROWS
    if _ADVANCE_ROWS is None:
        from .rigid_rows import advance_rows as _ADVANCE_ROWS  # light
    return _ADVANCE_ROWS


_ADVANCE_ROWS = None


def _step_common():
    """:func:`walkerlab.gym.rows_common.step_common` (imported on first use, as
    :func:`_advance_rows`), kept."""
    global _STEP_COMMON
    if _STEP_COMMON is None:
        from .rows_steady import step as _STEP_COMMON  # light
    return _STEP_COMMON


_STEP_COMMON = None


class WalkerVectorEnv(VectorEnv):
    """``num_envs`` walkers of one scene stepped together in one process: the native
    vector form of ``walkerlab/Walker-v0`` (module docstring).

    ``reset`` returns ``(observations, infos)``, ``step`` ``(observations, rewards,
    terminations, truncations, infos)``, batched as gymnasium's vector environments batch
    them: ``observations`` (N, m) float64, ``rewards`` (N,) float64, ``terminations`` and
    ``truncations`` (N,) bool, ``infos`` a dict of arrays (N,) with a boolean mask
    ``_<key>`` each (:meth:`gymnasium.vector.VectorEnv._add_info`; the keys are
    :data:`walkerlab.gym.env.INFO_KEYS` and the ledger's, in their units: ``time_s`` [s],
    ``hip_x_m`` [m], ``ledger_<term>`` [J]; ``heel_strike_time_s`` is batched as gymnasium
    batches a value that may be None: an object array holding None, or a float array
    holding NaN when sub-environment 0's first value was a number; read ``heel_strike``).

    Parameters
    ----------
    num_envs : int
        Number of walkers N (>= 1).
    max_episode_steps : int or None
        Control periods after which each sub-environment is truncated (as gymnasium's
        ``TimeLimit`` truncates: also on a period that terminated); default the id's
        :data:`~walkerlab.gym.env.DEFAULT_EPISODE_STEPS`; None: no limit.
    autoreset_mode : gymnasium.vector.AutoresetMode or str
        ``"NextStep"`` (default: the step after an episode's end resets that walker and
        returns its reset observation with reward 0 and both flags False, ignoring its
        action), ``"SameStep"`` (reset within the ending step; ``infos["final_obs"]`` and
        ``infos["final_info"]`` hold the end) or ``"Disabled"`` (reset ended walkers with
        ``reset(options={"reset_mask": mask})``).
    batched : bool
        The rigid view's walkers advanced together (module docstring; default); False:
        one after another.
    **env_kwargs
        :class:`~walkerlab.gym.env.WalkerEnv`'s keywords, the same for every walker
        (``scene`` required; ``view``, ``control_period_s``, ``start_noise``, ...).

    Attributes
    ----------
    envs : list of WalkerEnv
        The sub-environments (no limit of their own: this class truncates them).
    single_observation_space, single_action_space : gymnasium.spaces.Box
        One walker's spaces: observation (m,) float64, action (k,) float32 (fractions of
        ``tau_max`` [-], or N m with ``normalize_action=False``).
    observation_space, action_space : gymnasium.spaces.Box
        The batched spaces, (N, m) and (N, k).

    Raises
    ------
    ValueError
        ``num_envs`` not a whole number >= 1, ``max_episode_steps`` not a whole number >= 1
        or None, an unknown ``autoreset_mode``, or a bad ``WalkerEnv`` keyword (one line).
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"],
                                "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 1,
                 max_episode_steps: int | None = DEFAULT_EPISODE_STEPS,
                 autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
                 batched: bool = True, **env_kwargs):
        super().__init__()
        #: the rigid view's walkers advanced together (:func:`walkerlab.gym.rigid_rows.
        #: advance_rows`: their compiled pieces in one compiled call per flow); False: one
        #: after another, each as ``gym.make``'s environment steps (sync's numbers bit for bit)
        self.batched = bool(batched)
        n = whole_number(num_envs, "num_envs", 1)
        self.max_episode_steps = whole_number(max_episode_steps, "max_episode_steps", 1,
                                        allow_none=True)
        try:
            self.autoreset_mode = AutoresetMode(autoreset_mode)
        except ValueError:
            raise ValueError(f"autoreset_mode={autoreset_mode!r}: give one of "
                             f"{[m.value for m in AutoresetMode]}") from None
        #: the sub-environments, each built as gym.make's entry point builds it
        self.envs: list[WalkerEnv] = [registered_env(**env_kwargs) for _ in range(n)]
        self.num_envs = n
        first = self.envs[0]
        self.metadata = {**first.metadata, "autoreset_mode": self.autoreset_mode}
        self.render_mode = first.render_mode
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(self.single_observation_space, n)
        self.action_space = batch_space(self.single_action_space, n)
        self._observations = create_empty_array(self.single_observation_space, n=n,
                                                fn=np.zeros)
        self._rewards = np.zeros(n, dtype=np.float64)
        self._terminations = np.zeros(n, dtype=np.bool_)
        self._truncations = np.zeros(n, dtype=np.bool_)
        self._autoreset_envs = np.zeros(n, dtype=np.bool_)
        self._lent = False  # (the last step's flags the caller's: copied to write, _own)
        self._every = np.ones(n, dtype=np.bool_)  # (every walker stepped; read only)
        self._every.flags.writeable = False
        #: control periods since each sub-environment's reset (its time limit's count)
        self._elapsed = np.zeros(n, dtype=np.int64)
        #: steps of every walker not yet added to ``_elapsed`` (:meth:`_counts`)
        self._pending = 0
        #: at least the largest of the counts (a reset only lowers a count)
        self._most = 0
        #: every row and sub-environment (a step of all of them)
        self._all = (np.arange(n), list(self.envs))
        self._views: list | None = None  # (each env.sim; None after set_attr or call)
        self._has_reset = False
        self._batched_before = False  # a batched step made (the first: compile_notice)
        #: :func:`walkerlab.gym.batch.batch_parameters` of the walkers (False: not yet read)
        self._params: dict | None | bool = False
        #: what a common period of the walkers reads, kept (:func:`walkerlab.gym.
        #: rows_common.step_common`)
        self._common: dict = {}

    def __getstate__(self) -> dict:
        """Its attributes for a copy or a pickle, without what it keeps of its walkers (by
        their objects' ids, or a list of them: the copy's walkers are its own)."""
        state = self.__dict__.copy()
        state["_common"] = {}
        state["_views"] = None
        return state

    # ------------------------------------------------------------------ the physics
    def _step_all(self, actions: np.ndarray, mask: np.ndarray, every: bool = False) -> dict:
        """Step the sub-environments ``i`` where ``mask[i]`` by one control period with
        ``actions[i]``, writing their observation, reward and termination into
        ``self._observations``, ``self._rewards``, ``self._terminations`` (and
        ``self._truncations``: False, the time limit being the caller's).

        The one place a walker is stepped.  The rigid view's walkers (batched) are stepped
        as arrays over the walkers: the held torques of all of them at once
        (:func:`walkerlab.gym.batch.begin_periods`), their compiled pieces integrated
        together (:func:`walkerlab.gym.rigid_rows.advance_rows`), and their observations,
        rewards, flags and infos at once (:func:`walkerlab.gym.batch.end_periods`); where
        that cannot be (a ``reward_fn``, the contact view, ``batched=False``) each
        :class:`~walkerlab.gym.env.WalkerEnv` steps (or begins and ends its period)
        itself.

        Parameters
        ----------
        actions : ndarray (N, k)
            Checked actions (:meth:`_actions`), unscaled.
        mask : ndarray (N,) bool
            The sub-environments to step.
        every : bool
            ``mask`` is known to be all True.

        Returns
        -------
        dict
            The stepped sub-environments' infos by row: ``{"rows": idx (r,),
            "make_columns": f}``, ``f()`` giving ``{key: r values}`` (the values
            ``WalkerEnv.step``'s info holds, in its key order; :meth:`_columns`), or
            ``{"rows": idx, "dicts": [info, ...]}``.
        """
        if every or mask.all():  # (every walker: the rows and walkers kept)
            idx, envs = self._all
        else:
            idx = np.flatnonzero(mask)
            envs = [self.envs[i] for i in idx]
        if not self.batched or self.envs[0].view != "rigid":
            self._own()
            dicts = []
            for i, env in zip(idx, envs):
                (self._observations[i], self._rewards[i], self._terminations[i],
                 self._truncations[i], info) = env.step(actions[i])
                dicts.append(info)
            return {"rows": idx, "dicts": dicts}
        first = not self._batched_before
        p = self._params
        if p is False:
            p = self._batch_parameters()
        if p is None:  # each walker's own begin and end of its period
            self._own()
            advance_rows = self._advancer(first)
            begun = [env.begin_period(actions[i]) for i, env in zip(idx, envs)]
            strikes = advance_rows([env.sim for env in envs], [u for u, _ in begun],
                                   [env.period_end_s for env in envs])
            dicts = []
            for i, env, (u, before), hs in zip(idx, envs, begun, strikes):
                (self._observations[i], self._rewards[i], self._terminations[i],
                 self._truncations[i], info) = env.end_period(u, hs, before)
                dicts.append(info)
            return {"rows": idx, "dicts": dicts}
        whole = idx.size == self.num_envs
        views = (self._views if whole and self._views is not None
                 else [env.sim for env in envs])
        if whole:  # (every walker's view, kept)
            self._views = views
        if not whole:  # (the stepped walkers' parameters, kept per set of rows)
            some = p.setdefault("some", {})
            rows = idx.tobytes()
            if rows not in some:
                if len(some) >= 256:
                    some.clear()
                some[rows] = {k: v[idx] for k, v in p.items() if isinstance(v, np.ndarray)}
            p = some[rows]
        # a step after the first: a common period's batch (walkerlab.gym.rows_common.
        # step_common), when it is one
        out = (None if first
               else _step_common()(envs, views, actions if whole else actions[idx], p,
                                   self._common))
        if out is None:
            advance_rows = self._advancer(first)
            # (begin_periods reads the actions into an array of its own: every row as given)
            U, x_before, w_before, t_ends = begin_periods(
                envs, actions if whole else actions[idx], p)
            out = end_periods(envs, U, advance_rows(views, U, t_ends), x_before, w_before, p,
                              views)
        obs, reward, term, trunc, columns = out
        if whole:  # (new arrays of this step's: kept as they are)
            self._observations, self._rewards = obs, reward
            self._terminations, self._truncations = term, trunc
            self._lent = False
        else:
            self._own()
            self._observations[idx] = obs
            self._rewards[idx] = reward
            self._terminations[idx] = term
            self._truncations[idx] = trunc
        return {"rows": idx, "make_columns": columns}

    def _advancer(self, first: bool):
        """:func:`walkerlab.gym.rigid_rows.advance_rows`; on the first batched step
        (``first``: its kernels compiled or loaded, a long wait said) through
        :func:`~walkerlab.gym.rigid_rows.compile_notice`."""
        advance_rows = _advance_rows()
        if first:
            self._batched_before = True
            from .rigid_rows import compile_notice  # (advance_rows' module: imported)

            advance_rows = compile_notice(advance_rows)
        return advance_rows

    @staticmethod
    def _columns(stepped: dict) -> dict:
        """The stepped walkers' info columns (:meth:`_step_all`'s ``make_columns()``, made
        once)."""
        if "columns" not in stepped:
            stepped["columns"] = stepped.pop("make_columns")()
        return stepped["columns"]

    def _batch_parameters(self) -> dict | None:
        """:func:`walkerlab.gym.batch.batch_parameters` of every walker, kept until
        :meth:`set_attr` or :meth:`call` may have changed them."""
        if self._params is False:
            self._params = batch_parameters(self.envs)
        return self._params

    def _reset_one(self, i: int, seed: int | None, options: dict | None) -> dict:
        """Reset sub-environment ``i`` (its row of the observations, its time limit's
        count; not its reward and flags); returns its info."""
        obs, info = self.envs[i].reset(seed=seed, options=options)
        self._observations[i] = obs
        self._counts()[i] = 0
        return info

    def _own(self) -> None:
        """The rewards and flags copied, before a write, when the last step returned them
        as they are (``_lent``; the caller may change them: each step writes all their
        rows before reading one; the observations, read by a partial reset, are copies)."""
        if self._lent:
            self._rewards, self._terminations, self._truncations = (
                self._rewards.copy(), self._terminations.copy(), self._truncations.copy())
            self._lent = False

    def _counts(self) -> np.ndarray:
        """The control periods since each sub-environment's reset (N,), all counted."""
        if self._pending:
            self._elapsed += self._pending
            self._pending = 0
        return self._elapsed

    # ------------------------------------------------------------------ checks
    def _actions(self, actions) -> np.ndarray:
        """``actions`` as an array (N, k) of finite real numbers, as given (not cast).

        Raises
        ------
        InvalidAction
            None, not real numbers, not of shape (N, k), or NaN/inf entries (one line
            naming the batched action space).
        """
        shape = self.action_space.shape
        if (type(actions) is np.ndarray and actions.shape == shape
                and actions.dtype.kind in "iuf" and all_finite(actions)):
            return actions  # the common case: no message built
        want = f"give {shape[0]} rows of {shape[1]} finite real numbers, {self.action_space}"
        if actions is None:
            raise InvalidAction(f"actions is None: {want}")
        try:
            a = np.asarray(actions)
        except (ValueError, TypeError):
            raise InvalidAction(f"actions of type {type(actions).__name__} is not an array "
                                f"of numbers: {want}") from None
        if a.dtype.kind not in "iuf":
            what = "complex" if a.dtype.kind == "c" else f"of dtype {a.dtype}"
            raise InvalidAction(f"actions is {what}: {want}")
        if a.shape != shape:
            raise InvalidAction(f"actions has shape {a.shape}: {want}")
        bad = np.argwhere(~np.isfinite(a))
        if bad.size:
            i, j = (int(v) for v in bad[0])
            raise InvalidAction(f"actions[{i}, {j}] is {a[i, j]}: {want}")
        return a

    def _seeds(self, seed) -> list[int | None]:
        n = self.num_envs
        if seed is None:
            return [None] * n
        if isinstance(seed, int | np.integer) and not isinstance(seed, bool):
            return [int(seed) + i for i in range(n)]
        if isinstance(seed, Sequence) and not isinstance(seed, str | bytes):
            if len(seed) != n:
                raise ValueError(f"reset: seed has {len(seed)} entries: give num_envs={n}")
            return list(seed)
        raise ValueError(f"reset: seed={seed!r}: give None, an int (sub-env i gets seed + i) "
                         f"or a list of {n} ints or None")

    # ------------------------------------------------------------------ gymnasium API
    def reset(self, *, seed: int | Sequence[int | None] | None = None,
              options: dict | None = None):
        """Reset every walker, or those of ``options["reset_mask"]``; returns
        ``(observations (N, m), infos)``.

        Parameters
        ----------
        seed : None, int or sequence of N (int or None)
            An int ``s`` seeds sub-environment ``i`` with ``s + i`` (as ``SyncVectorEnv``).
        options : dict, optional
            ``reset_mask``: ndarray (N,) bool, the walkers to reset (at least one); the
            other keys (``state``) go to every reset walker's ``WalkerEnv.reset``.

        Raises
        ------
        ValueError
            A seed list not of N entries, a bad seed, options not a dict, or a
            ``reset_mask`` not a bool array (N,) with a True (one line); a sub-environment's
            own refusals (``WalkerEnv.reset``).
        """
        seeds = self._seeds(seed)
        self._own()
        if options is not None and not isinstance(options, Mapping):
            raise ValueError(f"reset: options must be a dict or None, got a "
                             f"{type(options).__name__}")
        options = dict(options) if options is not None else None
        mask = np.ones(self.num_envs, dtype=np.bool_)
        if options is not None and "reset_mask" in options:
            m = options.pop("reset_mask")
            if not (isinstance(m, np.ndarray) and m.dtype == np.bool_
                    and m.shape == (self.num_envs,) and m.any()):
                raise ValueError(f"reset: options['reset_mask'] must be a bool ndarray of "
                                 f"shape ({self.num_envs},) with at least one True, got "
                                 f"{m!r}")
            mask = m
        infos: dict = {}
        for i in np.flatnonzero(mask):
            infos = self._add_info(infos, self._reset_one(int(i), seeds[i], options), int(i))
        self._terminations[mask] = self._truncations[mask] = False
        self._autoreset_envs[mask] = False
        self._has_reset = True
        return self._observations.copy(), infos

    def step(self, actions):
        """Hold ``actions[i]`` (k,) on walker ``i`` for one control period (a walker whose
        episode ended is reset instead, as ``autoreset_mode`` says); returns
        ``(observations (N, m), rewards (N,), terminations (N,), truncations (N,),
        infos)``, the caller's to keep or change (as gymnasium's vector environments
        return them by default: copies, or copied by this class to write, :meth:`_own`).

        Raises
        ------
        gymnasium.error.ResetNeeded
            Before the first :meth:`reset`.
        InvalidAction
            ``actions`` not (N, k) finite real numbers (one line).
        RuntimeError
            ``autoreset_mode="Disabled"`` and a walker whose episode ended not reset.
        """
        if not self._has_reset:
            raise gym.error.ResetNeeded("Cannot call step() before calling reset()")
        a = self._actions(actions)
        mode = self.autoreset_mode
        if mode == AutoresetMode.NEXT_STEP:  # (not copied: replaced below, not written)
            resetting = self._autoreset_envs
        else:
            resetting = np.zeros(self.num_envs, dtype=np.bool_)
            if mode == AutoresetMode.DISABLED and self._autoreset_envs.any():
                raise RuntimeError(
                    f"autoreset_mode=Disabled: sub-environments "
                    f"{np.flatnonzero(self._autoreset_envs).tolist()} ended; reset them with "
                    "reset(options={'reset_mask': mask}) before stepping")
        some_reset = any_true(resetting)
        if some_reset:  # (rows written below)
            self._own()
        stepping = ~resetting if some_reset else self._every  # (every walker: not read)
        stepped = (self._step_all(a, stepping, not some_reset)
                   if not some_reset or stepping.any()
                   else {"rows": np.zeros(0, np.int64), "dicts": []})
        if self.max_episode_steps is not None:  # gymnasium's TimeLimit, per walker
            self._most += 1  # (a bound on the counts: none can be at the limit below it)
            if some_reset:
                elapsed = self._counts()
                elapsed[stepping] += 1
                self._truncations |= stepping & (elapsed >= self.max_episode_steps)
            else:  # (every walker stepped: counted at once when read)
                self._pending += 1
                if self._most >= self.max_episode_steps:
                    elapsed = self._counts()
                    self._truncations |= elapsed >= self.max_episode_steps
                    self._most = int(elapsed.max())
        resets: dict = {}
        for i in np.flatnonzero(resetting).tolist() if some_reset else ():  # NEXT_STEP: the
            resets[i] = self._reset_one(i, None, None)  # reset is the outcome
            self._rewards[i] = 0.0
            self._terminations[i] = self._truncations[i] = False
        ends = ((self._terminations | self._truncations) & stepping
                if mode == AutoresetMode.SAME_STEP else None)
        if ends is not None and ends.any():
            # final observations and infos: gymnasium's own batching
            each = self._info_dicts(stepped, resets)
            infos: dict = {}
            for i in np.flatnonzero(ends).tolist():
                infos = self._add_info(infos, {"final_obs": self._observations[i].copy(),
                                               "final_info": each[i]}, i)
                each[i] = self._reset_one(i, None, None)  # the step's reward and flags kept
            for i, info in enumerate(each):
                infos = self._add_info(infos, info, i)
        else:
            infos = LazyInfos(lambda: self._batched_infos(stepped, resets))
        self._autoreset_envs = np.logical_or(self._terminations, self._truncations)
        self._lent = True  # (the caller's: copied before this class writes into them)
        return (self._observations.copy(), self._rewards, self._terminations,
                self._truncations, infos)

    def _info_dicts(self, stepped: dict, resets: dict) -> list[dict]:
        """Every sub-environment's info as a dict (N): the stepped ones' (:meth:`_step_all`'s
        rows), the reset ones' (``resets``: row -> info)."""
        each: list = [None] * self.num_envs
        rows = stepped["rows"].tolist()
        if "dicts" in stepped:
            for i, info in zip(rows, stepped["dicts"]):
                each[i] = info
        else:
            cols = self._columns(stepped)
            lists = {k: v.tolist() if isinstance(v, np.ndarray) else v
                     for k, v in cols.items()}
            for r, i in enumerate(rows):
                each[i] = {k: v[r] for k, v in lists.items()}
        for i, info in resets.items():
            each[i] = info
        return each

    def _batched_infos(self, stepped: dict, resets: dict) -> dict:
        """The step's infos (every sub-environment's: stepped or reset) batched as
        :meth:`gymnasium.vector.VectorEnv._add_info` batches them one by one
        (:func:`~walkerlab.gym.infos.batch_columns`, else
        :func:`~walkerlab.gym.infos.batch_infos`, else ``_add_info`` itself)."""
        n = self.num_envs
        if "dicts" not in stepped:
            cols = self._columns(stepped)
            if not resets:
                out = batch_columns(cols, n)
                if out is not None:
                    return out
            else:
                keys = list(cols)
                if all(list(info) == keys for info in resets.values()):
                    rows = stepped["rows"].tolist()
                    merged = {}
                    for k, v in cols.items():
                        vals: list = [None] * n
                        for i, x in zip(rows, v.tolist() if isinstance(v, np.ndarray)
                                        else v):
                            vals[i] = x
                        for i, info in resets.items():
                            vals[i] = info[k]
                        merged[k] = vals
                    out = batch_columns(merged, n)
                    if out is not None:
                        return out
        each = self._info_dicts(stepped, resets)
        out = batch_infos(each)
        if out is None:  # a nested dict: gymnasium's own recursion
            out = {}
            for i, info in enumerate(each):
                out = self._add_info(out, info, i)
        return out

    def render(self) -> tuple:
        """Each walker's frame (``WalkerEnv.render``: (H, W, 3) uint8 with
        ``render_mode="rgb_array"``, else None), as a tuple of N."""
        return tuple(env.render() for env in self.envs)

    def call(self, name: str, *args, **kwargs) -> tuple:
        """``getattr(env, name)(*args, **kwargs)`` on each walker (the attribute itself
        when not callable), as a tuple of N."""
        self._params = False  # (a method may change what the batched step reads)
        self._views = None
        out = []
        for env in self.envs:
            f = getattr(env, name)
            out.append(f(*args, **kwargs) if callable(f) else f)
        return tuple(out)

    def get_attr(self, name: str) -> tuple:
        """Each walker's attribute ``name``, as a tuple of N."""
        return tuple(getattr(env, name) for env in self.envs)

    def set_attr(self, name: str, values) -> None:
        """Set attribute ``name`` of each walker: ``values`` a list or tuple of N, or one
        value for all.

        Raises
        ------
        ValueError
            A list or tuple not of N values (one line).
        """
        if not isinstance(values, list | tuple):
            values = [values] * self.num_envs
        if len(values) != self.num_envs:
            raise ValueError(f"set_attr: {len(values)} values for num_envs={self.num_envs}")
        self._params = False  # read again by the next batched step
        self._views = None
        for env, v in zip(self.envs, values, strict=True):
            setattr(env, name, v)

    def close_extras(self, **kwargs) -> None:
        """Close every walker."""
        for env in self.envs:
            env.close()
