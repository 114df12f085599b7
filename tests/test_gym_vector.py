"""``walkerlab/Walker-v0`` vectorised (:mod:`walkerlab.gym.vector`): ``gymnasium.make_vec``
in its three modes (``sync``, ``async``, ``vector_entry_point``: the native
:class:`~walkerlab.gym.vector.WalkerVectorEnv`), the id's time limit in each, gymnasium's
autoreset convention, per-sub-env seeds, one-line refusals.

The native form steps the same :class:`~walkerlab.gym.env.WalkerEnv` code as ``sync`` in
the same order of floating-point operations, so the two are compared exactly
(``assert_array_equal``, no tolerance); ``async`` steps it in subprocesses, and a process
boundary does not change a float64 either, so it too is compared exactly.
"""

from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from gymnasium.vector import AutoresetMode  # noqa: E402
from gymnasium.vector.utils import batch_space  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ID = "walkerlab/Walker-v0"


def _scene(name):
    return str(ROOT / "configs" / f"{name}.yaml")


def _vec(mode, n, name="paper", vector_kwargs=None, **kw):
    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

    return gym.make_vec(ID, num_envs=n, vectorization_mode=mode, scene=_scene(name),
                        vector_kwargs=vector_kwargs, **kw)


def _native(n, name="paper", **kw):
    return _vec("vector_entry_point", n, name, **kw)


def _same(a, b, where="", atol=0.0):
    """``a`` and ``b`` equal bit for bit (``atol`` 0) or their floats within ``atol``:
    arrays of the same dtype and shape and values (NaN where NaN), dicts key by key, None
    where None; flags, counts and text exactly."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), where
        for k in a:
            _same(a[k], b[k], f"{where}[{k!r}]", atol)
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape, where
        if a.dtype == object:
            for i, (x, y) in enumerate(zip(a.ravel(), b.ravel(), strict=True)):
                _same(x, y, f"{where}[{i}]", atol)
        elif atol and a.dtype.kind == "f":
            np.testing.assert_allclose(b, a, rtol=0, atol=atol, err_msg=where)
        else:
            np.testing.assert_array_equal(a, b, err_msg=where)
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{where}[{i}]", atol)
    elif isinstance(a, float) and np.isnan(a):
        assert isinstance(b, float) and np.isnan(b), where
    elif atol and isinstance(a, float):
        assert type(a) is type(b) and abs(a - b) <= atol, (where, a, b)
    else:
        assert type(a) is type(b) and a == b, (where, a, b)


def _run(env, actions, seed, mode="NextStep"):
    """Reset ``env`` with ``seed`` and step it through ``actions`` (T, N, k); with
    ``mode="Disabled"`` reset the ended sub-envs by ``reset_mask`` after each step.
    Returns the reset's and every step's outputs."""
    out = [env.reset(seed=seed)]
    for a in actions:
        out.append(env.step(a))
        ended = out[-1][2] | out[-1][3]
        if mode == "Disabled" and ended.any():
            out.append(env.reset(options={"reset_mask": ended}))
    return out


def _random_actions(env, steps, seed=1):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.0, 1.0, (steps, *env.action_space.shape)).astype(np.float32)


def test_make_vec_sync_equals_a_loop_of_single_envs():
    """``make_vec(..., "sync")`` is N ``gym.make`` envs: sub-env i seeded s + i, each
    truncated by the id's time limit given to make_vec (20), reset on the step after."""
    import walkerlab.gym  # noqa: F401

    n, steps = 2, 25
    vec = _vec("sync", n, max_episode_steps=20, start_noise=0.2)
    actions = _random_actions(vec, steps)
    got = _run(vec, actions, seed=7)
    singles = [gym.make(ID, scene=_scene("paper"), max_episode_steps=20, start_noise=0.2)
               for _ in range(n)]
    for i, env in enumerate(singles):
        obs, _ = env.reset(seed=7 + i)
        np.testing.assert_array_equal(got[0][0][i], obs)
        ended = False
        for t in range(steps):
            if ended:  # NEXT_STEP: the step after the end is the reset
                obs, r, term, trunc = (*env.reset()[:1], 0.0, False, False)
            else:
                obs, r, term, trunc, _ = env.step(actions[t][i])
            ended = term or trunc
            o, rv, tv, trv, _ = got[t + 1]
            np.testing.assert_array_equal(o[i], obs)
            assert (rv[i], tv[i], trv[i]) == (r, term, trunc)
        assert got[20][3][i] and not got[21][3][i]  # truncated at 20, reset at 21
    vec.close()


@pytest.mark.parametrize("batched", [False, True])
@pytest.mark.parametrize("mode", ["NextStep", "SameStep", "Disabled"])
def test_native_vector_env_equals_make_vec_sync(mode, batched):
    """The three-link walker without its controller under random actions (sub-env 0's
    pushed forward): falls and the time limit (20) end episodes, each autoreset;
    observations, rewards, flags and infos (final_obs and final_info too) of the native
    form are sync's exactly with the walkers stepped one by one (``batched=False``); with
    their compiled pieces integrated together (``batched``: the same DOP853 in another
    compiled loop, its states after a period within 1e-15 of CyRK's) the same falls,
    resets, flags and heel strikes, every number within 1e-9 (round-off carried through
    50 periods and their heel strikes; measured 7e-10 on RABBIT's rates over 300)."""
    n, steps = 3, 50
    kw = dict(max_episode_steps=20, start_noise=0.1)
    sync = _vec("sync", n, "threelink_hzd", vector_kwargs={"autoreset_mode": mode}, **kw)
    native = _native(n, "threelink_hzd", autoreset_mode=mode, batched=batched, **kw)
    assert native.metadata["autoreset_mode"] == AutoresetMode(mode)
    actions = _random_actions(sync, steps)
    actions[:, 0] = 0.6 + 0.4 * np.abs(actions[:, 0])  # sub-env 0 pushed over: it falls
    a, b = _run(sync, actions, 3, mode), _run(native, actions, 3, mode)
    assert len(a) == len(b)
    for k, (x, y) in enumerate(zip(a, b, strict=True)):
        assert len(x) == len(y)
        for j, (u, v) in enumerate(zip(x, y, strict=True)):
            _same(u, v, f"output {k}, item {j}", 1e-9 if batched else 0.0)
    terms = np.array([o[2] for o in a if len(o) == 5])
    truncs = np.array([o[3] for o in a if len(o) == 5])
    assert terms.any() and truncs.any()  # both ends were met (and reset from)
    assert not np.array_equal(a[0][0][0], a[0][0][1])  # seeds s + i: the starts differ
    sync.close()
    native.close()


def test_native_vector_env_autoresets_on_the_next_step_as_gymnasium_says():
    """NEXT_STEP (gymnasium 1.x's default): the step that ends an episode returns its last
    observation; the next step ignores the action and returns the reset's observation with
    reward 0 and both flags False; the time limit's count restarts there."""
    env = _native(2, max_episode_steps=20)
    assert type(env).metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert env.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    start, _ = env.reset(seed=0)
    zero = np.zeros(env.action_space.shape, np.float32)
    for t in range(1, 20):
        obs, r, term, trunc, _ = env.step(zero)
        assert not (term.any() or trunc.any()), t
    obs, r, term, trunc, _ = env.step(zero)
    assert trunc.all() and not term.any() and not np.array_equal(obs, start)
    obs, r, term, trunc, info = env.step(np.ones(env.action_space.shape, np.float32))
    np.testing.assert_array_equal(obs, start)  # no start noise: the reset is the start
    assert np.all(r == 0.0) and not (term.any() or trunc.any())
    np.testing.assert_array_equal(info["time_s"], 0.0)
    for _ in range(19):
        *_, trunc, _ = env.step(zero)
        assert not trunc.any()
    assert env.step(zero)[3].all()  # 20 periods after the reset, again
    env.close()


def test_native_reset_seed_s_gives_sub_env_i_the_seed_s_plus_i():
    import walkerlab.gym  # noqa: F401

    env = _native(3, start_noise=0.3)
    obs, info = env.reset(seed=11)
    for i in range(3):
        one, one_info = gym.make(ID, scene=_scene("paper"), start_noise=0.3).reset(seed=11 + i)
        np.testing.assert_array_equal(obs[i], one)
        assert info["terrain_seed"][i] == one_info["terrain_seed"]
    again, _ = env.reset(seed=[11, 12, 13])
    np.testing.assert_array_equal(again, obs)
    env.close()


def test_the_ids_max_episode_steps_governs_each_sub_envs_truncation():
    """Without ``max_episode_steps`` both forms take the id's 1000; given, each sub-env is
    truncated after that many periods (as gymnasium's TimeLimit: counted from each
    sub-env's own reset)."""
    import walkerlab.gym  # noqa: F401

    default = gym.spec(ID).max_episode_steps
    assert default == 1000
    sync, native = _vec("sync", 2), _native(2)
    assert [e.spec.max_episode_steps for e in sync.envs] == [default] * 2
    assert native.max_episode_steps == default
    assert all(e.max_episode_steps is None for e in native.envs)  # the vector truncates
    for env in (_vec("sync", 2, max_episode_steps=3), _native(2, max_episode_steps=3)):
        env.reset(seed=0)
        zero = np.zeros(env.action_space.shape, np.float32)
        flags = [env.step(zero)[3].tolist() for _ in range(7)]
        assert flags == [[False] * 2] * 2 + [[True] * 2] + [[False] * 2] * 3 + [[True] * 2]
        env.close()
    for env in (sync, native):
        env.close()


def test_native_vector_env_spaces_are_the_single_spaces_batched():
    from walkerlab.gym import WalkerVectorEnv

    env = _vec(None, 4, "threelink_hzd")  # no mode given: the id's vector entry point
    assert isinstance(env, WalkerVectorEnv) and len(env.envs) == 4
    one = env.envs[0]
    assert env.single_observation_space == one.observation_space
    assert env.single_action_space == one.action_space
    assert env.observation_space == batch_space(one.observation_space, 4)
    assert env.action_space == batch_space(one.action_space, 4)
    obs, info = env.reset(seed=0)
    assert obs.shape == env.observation_space.shape and obs.dtype == np.float64
    assert env.observation_space.contains(obs)
    obs, r, term, trunc, info = env.step(env.action_space.sample())
    assert r.shape == term.shape == trunc.shape == (4,) and r.dtype == np.float64
    assert term.dtype == trunc.dtype == np.bool_ and info["hip_x_m"].shape == (4,)
    env.close()


def test_async_make_vec_steps_two_sub_envs_in_subprocesses():
    """``make_vec(..., "async")``: each sub-env rebuilt in its own process (WalkerEnv
    pickles as its arguments) and stepped there; its outputs are sync's exactly, the
    time limit (5) included (under a second: the parent's walker and gait, built first,
    are forked with it)."""
    n, steps = 2, 8
    kw = dict(max_episode_steps=5, start_noise=0.1)
    sync, asyn = _vec("sync", n, **kw), _vec("async", n, **kw)
    try:
        assert type(asyn).__name__ == "AsyncVectorEnv"
        actions = _random_actions(sync, steps)
        a, b = _run(sync, actions, 4), _run(asyn, actions, 4)
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            for j in range(len(x) - 1):  # the infos: gymnasium batches them alike
                _same(x[j], y[j], f"output {k}, item {j}")
        assert np.array([o[3] for o in a[1:]]).any()
    finally:
        sync.close()
        asyn.close()


def _one_line(exc_info, *words):
    text = str(exc_info.value)
    assert "\n" not in text and all(w in text for w in words), text


def test_native_vector_env_refuses_bad_input_in_one_line():
    from walkerlab.gym import InvalidAction, WalkerVectorEnv

    scene = _scene("paper")
    for bad in (0, -1, 1.5, True, "2"):
        with pytest.raises(ValueError) as e:
            WalkerVectorEnv(bad, scene=scene)
        _one_line(e, "num_envs", ">= 1")
    with pytest.raises(ValueError) as e:
        _native(0)  # through make_vec too
    _one_line(e, "num_envs")
    with pytest.raises(ValueError) as e:
        WalkerVectorEnv(2, scene=scene, max_episode_steps=0)
    _one_line(e, "max_episode_steps")
    with pytest.raises(ValueError) as e:
        WalkerVectorEnv(2, scene=scene, autoreset_mode="later")
    _one_line(e, "autoreset_mode", "NextStep")
    env = WalkerVectorEnv(2, scene=scene)
    with pytest.raises(gym.error.ResetNeeded):
        env.step(np.zeros((2, 1), np.float32))
    env.reset(seed=0)
    for bad, words in ((np.zeros((3, 1)), ("shape (3, 1)", "2 rows")),
                       (np.zeros(2), ("shape (2,)",)), (None, ("None",)),
                       (np.array([[0.0], [np.nan]]), ("actions[1, 0] is nan",)),
                       (np.zeros((2, 1), complex), ("complex",))):
        with pytest.raises(InvalidAction) as e:
            env.step(bad)
        _one_line(e, *words)
    with pytest.raises(ValueError) as e:
        env.reset(seed=[1, 2, 3])
    _one_line(e, "3 entries", "num_envs=2")
    with pytest.raises(ValueError) as e:
        env.reset(options={"reset_mask": np.zeros(2, bool)})
    _one_line(e, "reset_mask", "at least one True")
    env.close()


def test_disabled_autoreset_refuses_to_step_an_ended_sub_env_until_it_is_reset():
    env = _native(2, max_episode_steps=2, autoreset_mode="Disabled")
    env.reset(seed=0)
    zero = np.zeros(env.action_space.shape, np.float32)
    env.step(zero)
    assert env.step(zero)[3].all()
    with pytest.raises(RuntimeError) as e:
        env.step(zero)
    _one_line(e, "[0, 1]", "reset_mask")
    obs, info = env.reset(options={"reset_mask": np.array([True, False])})
    assert info["_time_s"].tolist() == [True, False]
    with pytest.raises(RuntimeError):
        env.step(zero)  # sub-env 1 still ended
    env.reset(options={"reset_mask": np.array([False, True])})
    assert not env.step(zero)[3].any()
    env.close()


def test_the_vector_benchmark_reports_a_rate_for_each_form():
    """Not a timing: the benchmark runs and prints one line per form."""
    from walkerlab.bench.gym_vector import FORMS, bench_vector, lines

    res = bench_vector("configs/paper.yaml", num_envs=2, steps=3, repeats=1)
    assert all(res[f"{f}_steps_per_s"] > 0 for f in FORMS)
    text = lines(res)
    assert len(text) == 1 + len(FORMS) and all(f in "\n".join(text) for f in FORMS)
    with pytest.raises(ValueError) as e:
        bench_vector(num_envs=0)
    _one_line(e, "num_envs")


@pytest.mark.slow
def test_batched_native_form_steps_flat_feet_one_by_one_as_sync():
    """Flat feet's modes have no compiled control step: the batched native form integrates
    their pieces as each walker does, so it is sync's bit for bit (two walkers, a small
    random action, 6 periods)."""
    n = 2
    sync = _vec("sync", n, "flat_feet")
    native = _native(n, "flat_feet", batched=True)
    actions = _random_actions(sync, 6) * 0.1
    a, b = _run(sync, actions, 5), _run(native, actions, 5)
    for k, (x, y) in enumerate(zip(a, b, strict=True)):
        for j, (u, v) in enumerate(zip(x, y, strict=True)):
            _same(u, v, f"output {k}, item {j}")
    sync.close()
    native.close()
