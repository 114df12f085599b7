"""A scene's walker as a Gymnasium environment: :class:`~walkerlab.gym.env.WalkerEnv`,
registered as ``walkerlab/Walker-v0`` (keyword ``scene``) when this package is imported,
with :class:`~walkerlab.gym.vector.WalkerVectorEnv` (N walkers stepped in one process) as
its ``vector_entry_point``.

Needs gymnasium (``pip install -e '.[gym]'``); nothing else in walkerlab imports this
package, so the library runs without it.

Example
-------
>>> import gymnasium as gym
>>> import walkerlab.gym  # registers walkerlab/Walker-v0
>>> env = gym.make("walkerlab/Walker-v0", scene="configs/paper.yaml")   # doctest: +SKIP
>>> obs, info = env.reset(seed=0)                                       # doctest: +SKIP
>>> out = env.step(env.action_space.sample() * 0)     # doctest: +SKIP
>>> envs = gym.make_vec("walkerlab/Walker-v0", num_envs=8,               # doctest: +SKIP
...                     vectorization_mode="vector_entry_point", scene="configs/paper.yaml")
"""

from walkerlab.extras import require

gymnasium = require("gymnasium", "gym", "walkerlab.gym")

from walkerlab.gym.env import DEFAULT_EPISODE_STEPS, InvalidAction, WalkerEnv  # noqa: E402
from walkerlab.gym.vector import WalkerVectorEnv  # noqa: E402

__all__ = ["ENV_ID", "InvalidAction", "WalkerEnv", "WalkerVectorEnv"]

#: the registered id
ENV_ID = "walkerlab/Walker-v0"

if ENV_ID not in gymnasium.registry:
    gymnasium.register(id=ENV_ID, entry_point="walkerlab.gym.env:registered_env",
                       vector_entry_point="walkerlab.gym.vector:WalkerVectorEnv",
                       max_episode_steps=DEFAULT_EPISODE_STEPS)
