"""Benchmark ``gym-vector``: environment steps per second of ``walkerlab/Walker-v0``
(rigid view) as one environment and as N of them in gymnasium's three vector forms: the
native :class:`walkerlab.gym.vector.WalkerVectorEnv` (``make_vec(...,
vectorization_mode="vector_entry_point")``), ``"sync"`` (``SyncVectorEnv``, one process)
and ``"async"`` (``AsyncVectorEnv``, one process per walker).

Each form is built and reset (seed 0) before its clock starts (the walker's build and gait
search are not throughput); then ``steps`` calls of ``step`` with zero actions (the scene
as written, without a feedback controller for a scene that has one: such a walker falls and
is reset, the resets being timed as part of the stepping, in every form alike), the single
environment reset on an episode's end as the vector forms autoreset.  A rate counts walker
control periods: ``steps / t`` for the single environment, ``num_envs * steps / t`` for
the vector forms.  Medians of ``repeats`` runs, wall time (:func:`time.perf_counter`).

Needs gymnasium (the ``gym`` extra).
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import numpy as np

__all__ = ["FORMS", "bench_vector", "lines"]

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


def _time(make, steps: int, vector: bool = False) -> float:
    """Control periods per second of ``make()`` under zero actions: one environment (reset
    on an episode's end) or a vector form (``vector``: it autoresets; ``num_envs`` periods a
    call)."""
    env = make()
    try:
        env.reset(seed=0)
        zero = np.zeros(env.action_space.shape, env.action_space.dtype)
        t0 = time.perf_counter()
        for _ in range(steps):
            _, _, term, trunc, _ = env.step(zero)
            if not vector and (term or trunc):
                env.reset()
        return (env.num_envs if vector else 1) * steps / (time.perf_counter() - t0)
    finally:
        env.close()


def bench_vector(scene="configs/threelink_hzd.yaml", num_envs: int = 8, steps: int = 200,
                 repeats: int = 3, **env_kwargs) -> dict:
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
    **env_kwargs
        More :class:`walkerlab.gym.env.WalkerEnv` keywords (``view``, ``control_period_s``,
        ...), the same in every form.

    Returns
    -------
    dict
        ``scene``, ``num_envs``, ``steps``, ``repeats``; ``<form>_steps_per_s`` for each of
        :data:`FORMS` [walker control periods / s, median], ``<form>_runs`` (every run's
        rate), ``speedup_<form>`` (the form's rate over the single environment's) [-] for
        the vector forms.

    Raises
    ------
    ValueError
        ``num_envs``, ``steps`` or ``repeats`` not a whole number >= 1 (one line).
    """
    import gymnasium as gym

    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

    for name, v in (("num_envs", num_envs), ("steps", steps), ("repeats", repeats)):
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            raise ValueError(f"{name}={v!r}: give a whole number >= 1")
    kw = {"scene": _scene_path(scene), **env_kwargs}
    env_id = walkerlab.gym.ENV_ID
    makers = {
        "single": lambda: gym.make(env_id, **kw),
        "native": lambda: gym.make_vec(env_id, num_envs, "vector_entry_point", **kw),
        "sync": lambda: gym.make_vec(env_id, num_envs, "sync", **kw),
        "async": lambda: gym.make_vec(env_id, num_envs, "async", **kw),
    }
    _time(makers["single"], 1)  # the walker built and its gait found, not timed
    runs: dict[str, list[float]] = {f: [] for f in FORMS}
    for _ in range(repeats):  # the forms in turn, each round (a shared machine's load
        for form in FORMS:    # drifts alike over all of them)
            runs[form].append(_time(makers[form], steps, vector=form != "single"))
    res: dict = {"scene": kw["scene"], "num_envs": num_envs, "steps": steps,
                 "repeats": repeats}
    for form in FORMS:
        res[f"{form}_steps_per_s"] = statistics.median(runs[form])
        res[f"{form}_runs"] = runs[form]
    for form in FORMS[1:]:
        res[f"speedup_{form}"] = res[f"{form}_steps_per_s"] / res["single_steps_per_s"]
    return res


def lines(res: dict) -> list[str]:
    """Printable lines of :func:`bench_vector`'s result: one per form."""
    out = [f"gym-vector: {Path(res['scene']).name}, {res['num_envs']} walkers, "
           f"{res['steps']} steps a run, medians of {res['repeats']} (walker control "
           f"periods per second)"]
    for form in FORMS:
        rate = res[f"{form}_steps_per_s"]
        tail = "" if form == "single" else f" ({res[f'speedup_{form}']:.2f}x one env)"
        out.append(f"gym-vector: {form:>6}: {rate:10.1f} steps/s{tail}")
    return out
