"""
The Gymnasium environment: a PD hip policy on ``walkerlab/Walker-v0``
=====================================================================

:mod:`walkerlab.gym` registers ``walkerlab/Walker-v0``: a scene's walker as a Gymnasium
environment (the action a normalised torque per actuated joint, added to the scene's own
actuation; an all-zero action is the scene as written). Here the paper walker starts 10 %
off its gait's rates, once under the zero action (its passive dynamics) and once under a PD
hip controller, ``tau = Kp (delta* - delta) - Kd d(delta)/dt`` on the hip angle ``delta``
(swing minus stance leg angle). Needs the ``gym`` extra (gymnasium).
"""

from pathlib import Path

import gymnasium as gym
import matplotlib.pyplot as plt
import numpy as np

import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

ROOT = Path(walkerlab.__file__).resolve().parents[1]  # configs/ beside the package


def pd_policy(env, obs, kp=60.0, kd=6.0, target=0.35):
    names = env.observation_names
    sw, st = obs[names.index("swing_angle")], obs[names.index("stance_angle")]
    dsw, dst = obs[names.index("swing_rate")], obs[names.index("stance_rate")]
    tau = kp * (target - (sw - st)) - kd * (dsw - dst)
    return np.array([tau / env.tau_max[0]], np.float32)  # the action is tau / tau_max


def episode(policy, seconds=6.0, seed=0):
    env = gym.make("walkerlab/Walker-v0", scene=str(ROOT / "configs" / "paper.yaml"),
                   max_episode_steps=int(seconds / 0.01), start_noise=0.1)
    obs, info = env.reset(seed=seed)
    t, hip, strikes = [0.0], [info["hip_x_m"]], []
    while True:
        obs, reward, terminated, truncated, info = env.step(policy(env.unwrapped, obs))
        t.append(info["time_s"])
        hip.append(info["hip_x_m"])
        strikes += info["heel_strike_times_s"]
        if terminated or truncated:
            env.close()
            return np.array(t), np.array(hip), np.array(strikes), terminated


results = {"zero action": episode(lambda env, obs: np.zeros(1, np.float32)),
           "PD hip": episode(pd_policy)}
fig, ax = plt.subplots(figsize=(7, 3.4), layout="constrained")
for name, (t, hip, strikes, fell) in results.items():
    periods = np.diff(strikes)
    print(f"{name}: {len(strikes)} heel strikes, fell: {fell}, "
          f"last step periods {np.round(periods[-3:], 4)} s")
    ax.plot(t, hip, label=name)
ax.set(xlabel="time [s]", ylabel="hip x [m]", title="walkerlab/Walker-v0, paper walker")
ax.legend()
plt.show()
