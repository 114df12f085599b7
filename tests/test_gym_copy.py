"""A copy of a mid-episode ``walkerlab/Walker-v0`` (``copy.deepcopy``, a pickle round trip)
continues the episode bit for bit (:mod:`walkerlab.gym.episode_state`), as MuJoCo's
environments' copies do: a tree search or a rollout from a saved state needs it."""

import copy
import pickle
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

ROOT = Path(__file__).resolve().parents[1]


def _scene(name: str) -> str:
    return str(ROOT / "configs" / f"{name}.yaml")


def _same(a, b) -> bool:
    """Two ``step`` returns equal bit for bit (observation, reward, flags, info)."""
    obs_a, *rest_a = a
    obs_b, *rest_b = b
    return obs_a.tobytes() == obs_b.tobytes() and rest_a == rest_b


def _continues(env, before: int, after: int, amplitude: float, copies) -> None:
    """Step ``env`` ``before`` control periods with small seeded random actions, copy it
    each way of ``copies``, then step the original and every copy with the same actions:
    every return the same bit for bit, a heel strike among them (the copy continues across
    the reset map, not only inside a step)."""
    rng = np.random.default_rng(3)
    actions = rng.uniform(-amplitude, amplitude, (before + after, *env.action_space.shape))
    env.reset(seed=5)
    for a in actions[:before]:
        env.step(a)
    assert env.sim.steps >= 1  # copied after a heel strike, mid-step
    clones = [make(env) for make in copies]
    strikes = 0
    for a in actions[before:]:
        ref = env.step(a)
        assert not ref[2], ref[4]["termination"]
        strikes += ref[4]["heel_strike"]
        for c in clones:
            assert _same(c.step(a), ref)
    assert strikes >= 1


COPIES = [copy.deepcopy, lambda e: pickle.loads(pickle.dumps(e))]


@pytest.mark.parametrize("view", ["rigid", "contact"])
def test_a_deep_copied_env_continues_the_episode_bit_for_bit(view):
    """Before: the copy was built again from its arguments without the episode, its first
    ``step`` raising ``ResetNeeded``.  The paper walker copied 0.9 s into its walk (a heel
    strike made, one period 0.70 s) continues for 0.9 s more (a heel strike among them)
    under the same actions, its deep copy and its pickle round trip alike."""
    from walkerlab.gym.env import WalkerEnv

    _continues(WalkerEnv(_scene("paper"), view=view), 90, 90, 0.02, COPIES)


@pytest.mark.slow
@pytest.mark.parametrize("name,view", [("profile", "rigid"), ("flat_feet", "rigid"),
                                       ("powered_compass", "contact"),
                                       ("footholds", "contact")])
def test_a_copied_env_continues_on_a_profile_flat_feet_a_push_off_and_footholds(name, view):
    """The parts of an episode a copy carries beyond the state: a height profile's step
    (its dense output made again from the step's start), a flat foot's modes, the contact
    view's push-off pulse and the footholds laid at the episode's own footfalls."""
    from walkerlab.gym.env import WalkerEnv

    _continues(WalkerEnv(_scene(name), view=view), 240, 150, 0.02, COPIES)


def test_a_copied_env_before_its_first_reset_still_asks_for_one():
    from walkerlab.gym.env import WalkerEnv

    env = copy.deepcopy(WalkerEnv(_scene("paper")))
    with pytest.raises(gym.error.ResetNeeded):
        env.step(np.zeros(env.action_space.shape))


def test_a_copied_env_draws_the_next_reset_as_the_original_does():
    """The reset's random generator is carried: the next unseeded reset (its terrain seed,
    its start's noise) is the original's."""
    from walkerlab.gym.env import WalkerEnv

    env = WalkerEnv(_scene("paper"), start_noise=0.05)
    env.reset(seed=2)
    c = copy.deepcopy(env)
    (o1, i1), (o2, i2) = env.reset(), c.reset()
    assert o1.tobytes() == o2.tobytes() and i1 == i2


def test_a_deep_copied_vector_env_continues_its_walkers_bit_for_bit():
    """The native vector env copies as its walkers do (before: its copy's first step failed
    on an attribute of the episode not carried)."""
    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

    envs = gym.make_vec("walkerlab/Walker-v0", num_envs=2, scene=_scene("paper"),
                        vectorization_mode="vector_entry_point")
    a = np.full((2, *envs.single_action_space.shape), 0.01, np.float32)
    envs.reset(seed=0)
    for _ in range(90):
        envs.step(a)
    clone = copy.deepcopy(envs)
    for _ in range(60):
        ref, got = envs.step(a), clone.step(a)
        for x, y in zip(ref[:4], got[:4]):
            assert np.asarray(x).tobytes() == np.asarray(y).tobytes()
        assert ref[4]["heel_strike"].tolist() == got[4]["heel_strike"].tolist()
