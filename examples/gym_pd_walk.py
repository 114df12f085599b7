"""Training-free policies on ``walkerlab/Walker-v0``: the paper's compass-gait walker
(configs/paper.yaml) started 10 % off its gait's rates (``start_noise``), under the zero
action (its passive dynamics), a random policy, and a PD hip controller that drives the hip
angle (swing minus stance leg angle) towards a swing target ``delta* = 0.35 rad`` with
``tau = Kp (delta* - delta) - Kd d(delta)/dt``.  Printed: the heel strikes, the hip's
travel, the step period, the action's positive work (the ledger) and the return.

Usage::

    python examples/gym_pd_walk.py [--seconds 8]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import gymnasium as gym
import numpy as np

import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

ROOT = Path(__file__).resolve().parents[1]


def pd_policy(env, obs, kp=60.0, kd=6.0, target=0.35):
    names = env.observation_names
    sw, st = obs[names.index("swing_angle")], obs[names.index("stance_angle")]
    dsw, dst = obs[names.index("swing_rate")], obs[names.index("stance_rate")]
    tau = kp * (target - (sw - st)) - kd * (dsw - dst)
    return np.array([tau / env.tau_max[0]], np.float32)  # the action is tau / tau_max


def run(policy, seconds: float, seed: int = 0):
    env = gym.make("walkerlab/Walker-v0", scene=str(ROOT / "configs" / "paper.yaml"),
                   max_episode_steps=int(seconds / 0.01), start_noise=0.1)
    env.action_space.seed(seed)
    obs, info = env.reset(seed=seed)
    strikes, total = [], 0.0
    while True:
        obs, r, term, trunc, info = env.step(policy(env.unwrapped, obs))
        total += r
        strikes += info["heel_strike_times_s"]
        if term or trunc:
            break
    return strikes, info, total


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=8.0)
    args = ap.parse_args()
    policies = {"zero": lambda env, obs: np.zeros(1, np.float32),
                "random": lambda env, obs: env.action_space.sample(),
                "PD hip": pd_policy}
    for name, pol in policies.items():
        strikes, info, total = run(pol, args.seconds)
        d = info["hip_x_m"]
        work = info["ledger_action_work_positive"]
        periods = np.diff(strikes)
        print(f"{name:7s}: {len(strikes):3d} heel strikes in {info['time_s']:.2f} s "
              f"({info['termination'] or 'truncated'}), hip travelled {d:.3f} m, "
              f"step period {np.mean(periods) if len(periods) else float('nan'):.3f} s, "
              f"positive work {work:.2f} J ({work / d if d > 0.05 else float('nan'):.2f} J/m), "
              f"return {total:.1f}")


if __name__ == "__main__":
    main()
