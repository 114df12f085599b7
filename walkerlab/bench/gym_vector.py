"""Benchmark ``gym-vector``: environment steps per second of ``walkerlab/Walker-v0``
(rigid view) as one environment and as N of them in gymnasium's three vector forms: the
native :class:`walkerlab.gym.vector.WalkerVectorEnv` (``make_vec(...,
vectorization_mode="vector_entry_point")``), ``"sync"`` (``SyncVectorEnv``, one process)
and ``"async"`` (``AsyncVectorEnv``, one process per walker).

Each form is built and reset (seed 0) and stepped ``warmup`` times before its clock starts
(the walker's build and gait search, and the compiled kernels' first load, are not
throughput); then ``steps`` calls of ``step`` under each kind of action: ``zero`` (the
scene as written, without a feedback controller for a scene that has one: such a walker
falls and is reset, the resets being timed as part of the stepping, in every form alike)
and ``random`` (uniform over the action space, ``numpy`` generator seeded 0: the walkers
fall out of step with each other, as a policy's early episodes do), the single environment
reset on an episode's end as the vector forms autoreset.  A rate counts walker control
periods: ``steps / t`` for the single environment, ``num_envs * steps / t`` for the vector
forms.  Medians of ``repeats`` runs, wall time (:func:`time.perf_counter`), each clock
started after a full garbage collection (the forms built and closed before it leave
theirs; a run's own garbage is collected inside its clock as it comes).  A speedup is
the median over the rounds of the form's rate over the single environment's in the same
round (each round times the forms in turn, so a pair meets the same load of a shared
machine; the rates' own medians, taken apart, may come from different rounds).

Needs gymnasium (the ``gym`` extra).
"""

from __future__ import annotations

import gc
import statistics
import time
from pathlib import Path

import numpy as np

__all__ = ["ACTIONS", "FORMS", "bench_vector", "lines"]

#: the forms timed, in the order :func:`lines` prints them
FORMS = ("single", "native", "sync", "async")

_ROOT = Path(__file__).resolve().parents[2]


def _scene_path(scene) -> str:
    """``scene`` as given, or, a relative path that is no file in the working folder, the
    repository's (``configs/threelink_hzd.yaml`` from any working folder)."""
    p = Path(scene)
    if not p.is_absolute() and not p.exists() and (_ROOT / p).exists():
        return str(_ROOT / p)
    return str(scene)


#: the kinds of action timed
ACTIONS = ("zero", "random")


def _prefix(action: str) -> str:
    """The result's key prefix of ``action`` (none for ``zero``)."""
    return "" if action == "zero" else f"{action}_"


def _time(make, steps: int, vector: bool = False, action: str = "zero",
          warmup: int = 0) -> float:
    """Control periods per second of ``make()`` under ``action`` (module docstring): one
    environment (reset on an episode's end) or a vector form (``vector``: it autoresets;
    ``num_envs`` periods a call), after ``warmup`` untimed calls."""
    env = make()
    try:
        env.reset(seed=0)
        space = env.action_space
        rng = np.random.default_rng(0)
        zero = np.zeros(space.shape, space.dtype)

        def act():
            if action == "random":
                return rng.uniform(space.low, space.high).astype(space.dtype)
            return zero

        for k in range(warmup + steps):
            if k == warmup:  # the garbage of the forms built and closed before this one
                gc.collect()  # collected now, not inside this one's clock
                t0 = time.perf_counter()
            _, _, term, trunc, _ = env.step(act())
            if not vector and (term or trunc):
                env.reset()
        return (env.num_envs if vector else 1) * steps / (time.perf_counter() - t0)
    finally:
        env.close()


def bench_vector(scene="configs/threelink_hzd.yaml", num_envs: int = 8, steps: int = 300,
                 repeats: int = 5, warmup: int = 20, **env_kwargs) -> dict:
    """Environment steps per second of one ``walkerlab/Walker-v0`` and of ``num_envs`` of
    them in the native, sync and async vector forms (module docstring).

    Parameters
    ----------
    scene : str or Path
        The scene (a relative path missing from the working folder is read from the
        repository: the default is the shipped three-link walker).
    num_envs : int
        Walkers N of each vector form (>= 1).
    steps : int
        ``step`` calls timed per run (>= 1).
    repeats : int
        Runs per form; the rate reported is their median (>= 1).
    warmup : int
        Untimed ``step`` calls before each run's clock starts (>= 0).
    **env_kwargs
        More :class:`walkerlab.gym.env.WalkerEnv` keywords (``view``, ``control_period_s``,
        ...), the same in every form.

    Returns
    -------
    dict
        ``scene``, ``num_envs``, ``steps``, ``repeats``, ``warmup``; under zero actions
        ``<form>_steps_per_s`` for each of :data:`FORMS` [walker control periods / s,
        median], ``<form>_runs`` (every run's rate), ``speedup_<form>`` (the median over
        the rounds of the form's rate over the single environment's in the same round)
        [-] for the vector forms; the same under random
        actions as ``random_<form>_steps_per_s``, ``random_<form>_runs`` and
        ``random_speedup_<form>``.

    Raises
    ------
    ValueError
        ``num_envs``, ``steps`` or ``repeats`` not a whole number >= 1, or ``warmup`` not
        one >= 0 (one line).
    """
    import gymnasium as gym

    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

    for name, v, low in (("num_envs", num_envs, 1), ("steps", steps, 1),
                         ("repeats", repeats, 1), ("warmup", warmup, 0)):
        if isinstance(v, bool) or not isinstance(v, int) or v < low:
            raise ValueError(f"{name}={v!r}: give a whole number >= {low}")
    kw = {"scene": _scene_path(scene), **env_kwargs}
    env_id = walkerlab.gym.ENV_ID
    makers = {
        "single": lambda: gym.make(env_id, **kw),
        "native": lambda: gym.make_vec(env_id, num_envs, "vector_entry_point", **kw),
        "sync": lambda: gym.make_vec(env_id, num_envs, "sync", **kw),
        "async": lambda: gym.make_vec(env_id, num_envs, "async", **kw),
    }
    _time(makers["single"], 1)  # the walker built and its gait found, not timed
    runs: dict[tuple, list[float]] = {(a, f): [] for a in ACTIONS for f in FORMS}
    for _ in range(repeats):  # the forms in turn, each round (a shared machine's load
        for action, form in runs:  # drifts alike over all of them)
            runs[action, form].append(_time(makers[form], steps, form != "single", action,
                                            warmup))
    res: dict = {"scene": kw["scene"], "num_envs": num_envs, "steps": steps,
                 "repeats": repeats, "warmup": warmup}
    for action in ACTIONS:
        pre = _prefix(action)
        for form in FORMS:
            res[f"{pre}{form}_steps_per_s"] = statistics.median(runs[action, form])
            res[f"{pre}{form}_runs"] = runs[action, form]
        for form in FORMS[1:]:  # paired: the same round's single environment
            res[f"{pre}speedup_{form}"] = statistics.median(
                v / s for v, s in zip(runs[action, form], runs[action, "single"]))
    return res


def lines(res: dict) -> list[str]:
    """Printable lines of :func:`bench_vector`'s result: one per form and kind of
    action."""
    out = [f"gym-vector: {Path(res['scene']).name}, {res['num_envs']} walkers, "
           f"{res['steps']} steps a run after {res.get('warmup', 0)}, medians of "
           f"{res['repeats']} (walker control periods per second; a speedup: the median "
           f"of the rounds' ratios to the same round's one env)"]
    for action in ACTIONS:
        pre = _prefix(action)
        if f"{pre}single_steps_per_s" not in res:
            continue
        for form in FORMS:
            rate = res[f"{pre}{form}_steps_per_s"]
            tail = ("" if form == "single"
                    else f" ({res[f'{pre}speedup_{form}']:.2f}x one env)")
            out.append(f"gym-vector: {action:>6} {form:>6}: {rate:10.1f} steps/s{tail}")
    return out
