"""Environment steps per second: walkerlab's ``walkerlab/Walker-v0`` (rigid view, the paper
walker and others) against MuJoCo's ``Walker2d-v5`` on the same machine, one environment and
a ``gymnasium.vector.SyncVectorEnv`` of 8.

Each run: reset (seed 0), then zero actions (walkerlab: the scene's own walk; Walker2d: its
passive collapse) for ``--periods`` control periods, restarting on an episode's end; the
time of the steps alone (the fixed point is found before the clock starts, once per scene).
Needs ``gymnasium[mujoco]`` for Walker2d (skipped with a note without it).

Usage::

    python scripts/bench_gym.py [--periods 2000] [--scenes paper powered_compass kneed]
    python scripts/bench_gym.py --scenes paper hip_width_stabilised kneed_3d   # 3D walkers
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _rate(make, periods: int) -> float:
    env = make()
    env.reset(seed=0)
    a = np.zeros(env.action_space.shape, env.action_space.dtype)
    t0 = time.perf_counter()
    for _ in range(periods):
        _, _, term, trunc, _ = env.step(a)
        if term or trunc:
            env.reset()
    rate = periods / (time.perf_counter() - t0)
    env.close()
    return rate


def _warm(make, steps: int = 5) -> None:
    """Build, reset and step an environment ``steps`` zero actions before any clock: the
    fixed point, the generated code and numba's compile (or cache load) of the compiled
    control step, which its first step makes, are set-up, not throughput."""
    env = make()
    env.reset(seed=0)
    a = np.zeros(env.action_space.shape, env.action_space.dtype)
    for _ in range(steps):
        env.step(a)
    env.close()


def _vector_rate(make, periods: int, n: int = 8) -> float:
    import gymnasium as gym

    env = gym.vector.SyncVectorEnv([make] * n)
    env.reset(seed=list(range(n)))
    a = np.zeros(env.action_space.shape, env.action_space.dtype)
    t0 = time.perf_counter()
    for _ in range(periods):
        env.step(a)  # autoreset on an episode's end
    rate = n * periods / (time.perf_counter() - t0)
    env.close()
    return rate


def main() -> None:
    import gymnasium as gym

    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=2000)
    ap.add_argument("--scenes", nargs="+", default=["paper", "powered_compass", "kneed"])
    args = ap.parse_args()
    rows = {}
    for name in args.scenes:
        def make(name=name):
            return gym.make("walkerlab/Walker-v0", scene=str(ROOT / "configs" / f"{name}.yaml"),
                            max_episode_steps=1000)
        _warm(make)  # the fixed point, generated code and compiled step, before the clock
        rows[f"walkerlab/{name}"] = {"env_steps_per_s": _rate(make, args.periods),
                                     "vector8_env_steps_per_s": _vector_rate(
                                         make, max(1, args.periods // 8))}
    try:
        def walker2d():
            return gym.make("Walker2d-v5")
        _warm(walker2d)
        rows["Walker2d-v5"] = {"env_steps_per_s": _rate(walker2d, args.periods),
                               "vector8_env_steps_per_s": _vector_rate(
                                   walker2d, max(1, args.periods // 8))}
    except Exception as exc:  # noqa: BLE001 - not installed: said, not raised
        rows["Walker2d-v5"] = {"skipped": f"{type(exc).__name__}: {exc}"}
    for k, v in rows.items():
        if "skipped" in v:
            print(f"{k:28s} skipped ({v['skipped']})")
        else:
            print(f"{k:28s} {v['env_steps_per_s']:10.0f} steps/s   vector of 8: "
                  f"{v['vector8_env_steps_per_s']:10.0f} steps/s")
    print(json.dumps(rows))


if __name__ == "__main__":
    main()
