"""``walkerlab/Walker-v0`` vectorised (:mod:`walkerlab.gym.vector`): ``gymnasium.make_vec``
in its three modes (``sync``, ``async``, ``vector_entry_point``: the native
:class:`~walkerlab.gym.vector.WalkerVectorEnv`), the id's time limit in each, gymnasium's
autoreset convention, per-sub-env seeds, one-line refusals.

The native form steps the same :class:`~walkerlab.gym.env.WalkerEnv` code as ``sync`` in
the same order of floating-point operations, so the two are compared exactly
(``assert_array_equal``, no tolerance); ``async`` steps it in subprocesses, and a process
boundary does not change a float64 either, so it too is compared exactly.
"""

from dataclasses import replace
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
    from walkerlab.bench.gym_vector import ACTIONS, FORMS, bench_vector, lines

    res = bench_vector("configs/paper.yaml", num_envs=2, steps=3, repeats=1, warmup=1)
    assert all(res[f"{f}_steps_per_s"] > 0 and res[f"random_{f}_steps_per_s"] > 0
               for f in FORMS)
    text = lines(res)
    assert len(text) == 1 + len(ACTIONS) * len(FORMS)
    assert all(f in "\n".join(text) for f in FORMS + ACTIONS)
    with pytest.raises(ValueError) as e:
        bench_vector(num_envs=0)
    _one_line(e, "num_envs")
    with pytest.raises(ValueError) as e:
        bench_vector(warmup=-1)
    _one_line(e, "warmup")


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


def _walker_by_walker(env, monkeypatch):
    """``env``'s batched step with each walker beginning and ending its own period
    (``WalkerEnv.begin_period``/``end_period``: the physics the same batched call) and the
    infos batched by gymnasium's own ``VectorEnv._add_info``, one sub-env at a time."""
    import walkerlab.gym.vector as vector

    monkeypatch.setattr(vector, "batch_parameters", lambda envs: None)

    def add_info(stepped, resets):
        out: dict = {}
        for i, info in enumerate(env._info_dicts(stepped, resets)):
            out = env._add_info(out, info, i)
        return out
    monkeypatch.setattr(env, "_batched_infos", add_info)


def _arrays_and_one_by_one(monkeypatch, scene, mode, steps, scale=0.1, n=3, **kw):
    """Both forms of ``_native(n, scene, ...)`` through ``steps`` random actions (times
    ``scale``; the last sub-env pushed over: it falls), every output compared bit for
    bit."""
    arrays = _native(n, scene, autoreset_mode=mode, **kw)
    one = _native(n, scene, autoreset_mode=mode, **kw)
    actions = _random_actions(arrays, steps) * scale
    actions[:, -1] = 0.6 + 0.4 * np.abs(actions[:, -1])
    a = _run(arrays, actions, 3, mode)
    with monkeypatch.context() as mp:
        _walker_by_walker(one, mp)
        b = _run(one, actions, 3, mode)
    for k, (x, y) in enumerate(zip(a, b, strict=True)):
        for j, (u, v) in enumerate(zip(x, y, strict=True)):
            _same(u, v, f"output {k}, item {j}")
            if isinstance(u, dict):
                assert list(u) == list(v), f"output {k}: the keys' order"
    arrays.close()
    one.close()
    return a


@pytest.mark.parametrize("mode", ["NextStep", "SameStep", "Disabled"])
def test_array_step_equals_each_walker_ending_its_period_bit_for_bit(monkeypatch, mode):
    """The batched step's walkers begun and ended as arrays over the walkers (held torques,
    observations, rewards, flags, infos batched from columns) give the numbers of each
    walker's own ``begin_period``/``end_period`` on the same batched physics, and infos
    equal to gymnasium's ``_add_info`` batching of each walker's dict, bit for bit: falls,
    heel strikes, the time limit (66) and their autoresets included."""
    out = _arrays_and_one_by_one(monkeypatch, "threelink_hzd", mode, 70, n=2,
                                 max_episode_steps=66, start_noise=0.1)
    steps = [o for o in out if len(o) == 5]
    assert np.array([o[2] for o in steps]).any() and np.array([o[3] for o in steps]).any()
    assert any(o[4]["heel_strike"].any() for o in steps)


@pytest.mark.slow
def test_batched_infos_equal_gymnasiums_add_info_batching_over_300_steps_with_autoresets(
        monkeypatch):
    """300 periods of three walkers under random actions (one pushed over: falls and
    autoresets on the next step), the time limit 100: every output of the array step equals
    the walker-by-walker step's with gymnasium's ``_add_info`` batching, bit for bit, both
    forms of ``heel_strike_time_s`` (None first: objects; a number first: NaN) met."""
    out = _arrays_and_one_by_one(monkeypatch, "threelink_hzd", "NextStep", 300,
                                 max_episode_steps=100, start_noise=0.1)
    kinds = {o[4]["heel_strike_time_s"].dtype.kind for o in out[1:]}
    assert kinds == {"O", "f"}


@pytest.mark.parametrize("kw", [{"policy": "scene"}, {"normalize_action": False},
                                {"ctrl_cost_weight": 0.3, "work_cost_weight": 0.05}])
def test_array_step_takes_the_scene_policy_raw_torques_and_reward_weights(monkeypatch, kw):
    """The scene's controller added to each action, actions in N m, and other reward
    weights: the array step equals each walker's own ending of its period bit for bit."""
    _arrays_and_one_by_one(monkeypatch, "threelink_hzd", "NextStep", 15, scale=1.0,
                           max_episode_steps=10, **kw)


def test_a_reward_fn_steps_the_batch_walker_by_walker():
    """A ``reward_fn`` (given each walker's info dict) leaves the array step: the batched
    physics with each walker ending its own period, equal to sync's to round-off."""
    def reward_fn(env, info):
        return info["hip_x_m"] + 10.0 * info["heel_strike"]

    sync = _vec("sync", 2, "threelink_hzd", reward_fn=reward_fn, max_episode_steps=10)
    native = _native(2, "threelink_hzd", reward_fn=reward_fn, max_episode_steps=10)
    assert native._batch_parameters() is None
    actions = _random_actions(sync, 12)
    a, b = _run(sync, actions, 1), _run(native, actions, 1)
    for k, (x, y) in enumerate(zip(a, b, strict=True)):
        for j, (u, v) in enumerate(zip(x, y, strict=True)):
            _same(u, v, f"output {k}, item {j}", 1e-9)
    sync.close()
    native.close()


def test_set_attr_is_read_by_the_next_array_step():
    """Weights changed by ``set_attr`` between steps: the array step reads them again
    (each walker's own reward, walker by walker, the same numbers)."""
    env = _native(2, "threelink_hzd")
    env.reset(seed=0)
    zero = np.zeros(env.action_space.shape, np.float32)
    env.step(zero)
    env.set_attr("weights", [(0.0, 5.0, 0.0, 0.0), (0.0, 7.0, 0.0, 0.0)])
    _, r, term, _, _ = env.step(zero)
    assert not term.any() and r.tolist() == [5.0, 7.0]
    env.close()


def test_hip_xs_are_each_views_hip_x_bit_for_bit():
    """The hips of many rigid walkers from one call of the step walker's ``points`` on the
    states as columns equal each walker's own, bit for bit; a ``points`` of one state only
    is called state by state."""
    from walkerlab.gym.batch import _hips, hip_xs

    env = _native(4, "threelink_hzd", start_noise=0.3)
    env.reset(seed=2)
    for _ in range(30):
        env.step(_random_actions(env, 1)[0] * 0.2)
    views = [e.sim for e in env.envs]
    np.testing.assert_array_equal(hip_xs(views), [v.hip_x() for v in views])
    np.testing.assert_array_equal(hip_xs(views[1:3]), [v.hip_x() for v in views[1:3]])
    walker = views[0].walker
    assert walker.hip_x is not None  # the generated hip's x alone

    def one_state(x):
        if np.ndim(x) != 1:
            raise ValueError("one state")
        return walker.points(x)
    one = replace(walker, points=one_state, hip_x=None)
    assert _hips(one, np.array([v.x for v in views])) is None
    env.close()


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["rabbit_hzd", "paper"])
def test_batched_native_form_walks_rabbit_and_a_passive_walker_as_sync(scene):
    """RABBIT (five links, its controller out: it falls) and the passive compass walker:
    the batched array step's outputs equal sync's to round-off over 40 periods of random
    actions and autoresets (the same falls, resets and heel strikes)."""
    n, steps = 3, 40
    kw = dict(max_episode_steps=15, start_noise=0.05)
    sync = _vec("sync", n, scene, **kw)
    native = _native(n, scene, **kw)
    actions = _random_actions(sync, steps) * 0.3
    a, b = _run(sync, actions, 2), _run(native, actions, 2)
    for k, (x, y) in enumerate(zip(a, b, strict=True)):
        for j, (u, v) in enumerate(zip(x, y, strict=True)):
            _same(u, v, f"output {k}, item {j}", 1e-9)
    assert np.array([o[3] for o in a[1:]]).any()
    sync.close()
    native.close()


def test_a_steps_infos_are_batched_when_first_read_and_equal_the_batching():
    """The native step's infos (:class:`walkerlab.gym.infos.LazyInfos`) are batched by the
    first read, not before, and are then the entries the batching gives, whatever reads
    them first (a key, ``in``, ``len``, iteration, a copy, a pickle: plain dicts of the
    same entries)."""
    import copy
    import pickle

    from walkerlab.gym.infos import LazyInfos

    calls = []

    def make():
        calls.append(1)
        return {"time_s": np.array([0.1, 0.2]), "_time_s": np.ones(2, np.bool_),
                "stance_leg": np.array(["leg1", "leg2"], dtype=object)}

    want = make()
    calls.clear()
    readers = [lambda d: d["time_s"], lambda d: "time_s" in d, len, list, dict,
               copy.deepcopy, lambda d: pickle.loads(pickle.dumps(d)), lambda d: d == {},
               lambda d: {**d}, repr, lambda d: d.get("x")]
    for read in readers:
        infos = LazyInfos(make)
        assert calls == [] and isinstance(infos, dict)
        read(infos)
        assert calls == [1]
        calls.clear()
        _same(want, dict(infos))
        assert calls == []  # made once
    assert type(copy.deepcopy(LazyInfos(make))) is dict
    env = _native(2, "threelink_hzd")
    env.reset(seed=0)
    infos = env.step(np.zeros(env.action_space.shape))[4]
    assert isinstance(infos, LazyInfos) and infos._make is not None
    assert infos["_time_s"].all() and infos._make is None
    env.close()


def test_batched_ledger_equals_each_walkers_own_where_the_actions_power_changes_sign(
        monkeypatch):
    """The batched rows' held-torque ledger (:func:`walkerlab.gym.rigid_rows._held_rows`:
    the exact work where the action's power keeps its sign over a period, else the power at
    the period's Gauss-Legendre nodes read from the kernel's dense output) equals each
    walker's own ledger of its own integration (sync, each walker's pieces on CyRK's
    DOP853, :meth:`RigidView._run`: its dense output at the same nodes, the joint maps
    applied state by state) within 1e-9 J, over 60 periods of full-range random actions
    on the three-link walker, periods of both kinds met (the sync walkers' node ledger
    counted)."""
    from walkerlab.gym import rigid_view

    nodes = []
    own = rigid_view.RigidView._work

    def counted(self, *a, **k):
        nodes.append(1)
        return own(self, *a, **k)

    def by_itself(self, u, t_end):  # the walker's own integration, piece by piece
        self.open_period(u, t_end)
        return self._run(u, t_end)

    monkeypatch.setattr(rigid_view.RigidView, "_work", counted)
    monkeypatch.setattr(rigid_view.RigidView, "advance", by_itself)
    n, steps = 4, 60
    kw = dict(max_episode_steps=30, start_noise=0.05)
    sync = _vec("sync", n, "threelink_hzd", **kw)
    native = _native(n, "threelink_hzd", **kw)
    actions = _random_actions(sync, steps, seed=4)
    a = _run(sync, actions, 5)
    assert nodes  # sync met periods whose power changed sign
    b = _run(native, actions, 5)
    keys = ("ledger_action_work_positive", "ledger_action_work_negative")
    for x, y in zip(a[1:], b[1:], strict=True):
        np.testing.assert_allclose(y[0], x[0], rtol=0, atol=1e-9)  # the same walks
        for k in keys:
            np.testing.assert_allclose(y[4][k], x[4][k], rtol=0, atol=1e-9)
    work = np.array([[o[4][k] for k in keys] for o in a[1:]])
    assert (work[:, 0] > 0).any() and (work[:, 1] < 0).any()
    sync.close()
    native.close()


def test_a_crossing_rows_dense_output_run_again_by_the_kernel_is_cyrks(monkeypatch):
    """A batched row ended by a guard crossing (a heel strike, a fall) with the action on
    reads its ledger's Gauss-Legendre nodes from the same kernel run again with the nodes
    as samples (:class:`walkerlab.gym.rigid_rows._RowRedo`): the states equal those of
    the single walker's integrator over the same piece (CyRK's DOP853, its own dense
    output) within 1e-9, over 60 periods of random actions on RABBIT (such rows met)."""
    from walkerlab.gym import rigid_rows

    seen = []
    own = rigid_rows._RowRedo.__call__

    def compared(self, t):
        got = own(self, t)
        ref = np.atleast_2d(self.args[3](t))[:got.shape[0]]
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9)
        seen.append(got.shape)
        return got

    monkeypatch.setattr(rigid_rows._RowRedo, "__call__", compared)
    native = _native(4, "rabbit_hzd", max_episode_steps=30, start_noise=0.05)
    _run(native, _random_actions(native, 60, seed=4), 5)
    assert seen and all(s[1] == 4 for s in seen)  # the 4 nodes of each such piece
    native.close()


def test_small_array_tests_answer_as_numpys_reductions():
    """:mod:`walkerlab.gym.small_arrays` answers as ``ndarray.any()`` and
    ``np.isfinite(a).all()`` do: small and large arrays, NaN and infinities anywhere,
    huge finite entries (float64 1e200, float32 1e20: finite, though their squares are
    not), integer and empty arrays; no floating-point warning (the suite raises them)."""
    from walkerlab.gym.small_arrays import SMALL, all_finite, any_true

    rng = np.random.default_rng(0)
    for n in (0, 1, 8, SMALL, SMALL + 1, 500):
        for p in (0.0, 0.05, 1.0):
            b = rng.random(n) < p
            assert any_true(b) == bool(b.any())
            assert any_true(b.reshape(-1, 1)) == bool(b.any())
    cases = [np.zeros((8, 2)), np.full((3, 4), 1e200), np.full(5, 1e20, np.float32),
             np.arange(6), np.zeros(0), rng.normal(size=(200, 3))]
    for a in list(cases):
        for bad in (np.nan, np.inf, -np.inf):
            if a.size and a.dtype.kind == "f":
                b = a.copy()
                b.flat[int(rng.integers(b.size))] = bad
                cases.append(b)
    for a in cases:
        assert all_finite(a) == bool(np.isfinite(a).all()), a


def test_rows_data_vectors_written_at_once_are_each_flows_own(monkeypatch):
    """``ActuatedFlow.data_rows`` (the native rows' data vectors, the shared constants
    written once) gives each row the numbers of the flow's own ``data_into``, after
    random actions have written the walkers' law blocks, and so does its row-by-row path
    (flows whose constants are equal numbers in different arrays)."""
    env = _native(4, "threelink_hzd", start_noise=0.05)
    env.reset(seed=1)
    for a in _random_actions(env, 3, seed=2):
        env.step(a)
    flows = [e.sim._lane[6][0].compiled for e in env.envs]
    ref = np.empty((4, flows[0].data_size()))
    for f, row in zip(flows, ref):
        f.data_into(row)
    assert len({f.laws.tobytes() for f in flows}) > 1  # the walkers' own torques
    D = np.full_like(ref, np.nan)
    flows[0].data_rows(flows, D)
    np.testing.assert_array_equal(D, ref)
    monkeypatch.setitem(flows[2]._memo, "consts", flows[2].constants().copy())
    D = np.full_like(ref, np.nan)
    flows[0].data_rows(flows, D)
    np.testing.assert_array_equal(D, ref)
    env.close()


def test_one_stacked_reduction_gives_the_separate_row_sums():
    """The batched ledger's three sums of each row (:func:`walkerlab.gym.rigid_rows.
    _held_rows`: one reduction over a stacked (3, r, n) array) equal numpy's separate
    ``(r, n).sum(axis=1)`` bit for bit, as the walkers' own ledgers sum them: rows of 1
    to 23 terms (numpy's pairwise summation begins at 8), 4,000 random cases."""
    rng = np.random.default_rng(5)
    for _ in range(4000):
        r, n = int(rng.integers(1, 17)), int(rng.integers(1, 24))
        A = rng.normal(size=(3, r, n)) * 10.0 ** rng.uniform(-6, 6, size=(3, r, 1))
        S = A.sum(axis=2)
        for k in range(3):
            np.testing.assert_array_equal(S[k], A[k].sum(axis=1))


def test_the_vector_benchmarks_speedup_pairs_each_round_with_its_own_single_env(
        monkeypatch):
    """A speedup is the median of each round's form rate over the same round's single
    environment (a shared machine's load drifts between rounds): single 1, 10, 2 and
    native 3, 20, 10 steps/s give 3 (the pairs 3, 2, 5), not the medians' ratio 5."""
    from walkerlab.bench import gym_vector

    rates = {"single": iter([1.0, 10.0, 2.0]), "native": iter([3.0, 20.0, 10.0])}
    monkeypatch.setattr(gym, "make", lambda env_id, **kw: "single")
    monkeypatch.setattr(gym, "make_vec", lambda env_id, n, mode, **kw: {
        "vector_entry_point": "native"}.get(mode, mode))

    def timed(make, steps, vector=False, action="zero", warmup=0):
        form = make()
        if steps == 5 and action == "zero" and form in rates:  # (not the first, untimed call)
            return next(rates[form])
        return 1.0

    monkeypatch.setattr(gym_vector, "_time", timed)
    res = gym_vector.bench_vector(num_envs=2, steps=5, repeats=3, warmup=0)
    assert res["single_steps_per_s"] == 2.0 and res["native_steps_per_s"] == 10.0
    assert res["speedup_native"] == 3.0


def test_the_native_vector_envs_first_batched_step_says_in_one_line_when_it_compiles(
        monkeypatch, capfd):
    """Its first batched step compiles its kernels (about 13 s on an idle machine, once):
    a first step still running after ``COMPILE_NOTICE_S`` says so in one line on stderr; a
    quick first step and every later step say nothing."""
    import time

    from walkerlab.gym import rigid_rows, vector

    envs = _native(2)
    envs.reset(seed=0)
    real = vector._advance_rows()

    def slow(*args, **kwargs):  # a first call as long as a compile, scaled down
        time.sleep(0.5)
        return real(*args, **kwargs)

    monkeypatch.setattr(vector, "_ADVANCE_ROWS", slow)
    monkeypatch.setattr(rigid_rows, "COMPILE_NOTICE_S", 0.05)
    a = np.zeros((2, *envs.single_action_space.shape), np.float32)
    capfd.readouterr()
    envs.step(a)
    envs.step(a)
    err = capfd.readouterr().err
    assert err.splitlines() == [rigid_rows.COMPILE_NOTICE]
    quick = _native(2)  # a first step shorter than the wait: nothing said
    quick.reset(seed=0)
    monkeypatch.setattr(vector, "_ADVANCE_ROWS", real)
    monkeypatch.setattr(rigid_rows, "COMPILE_NOTICE_S", 60.0)
    quick.step(a)
    assert capfd.readouterr().err == ""


@pytest.mark.parametrize("scene", ["threelink_hzd", "rabbit_hzd"])
def test_one_environment_is_the_vector_environment_with_one_walker_bit_for_bit(scene):
    """Issue 80 item 4, one integrator per view: ``gym.make``'s environment advances its
    rigid walker as the native vector environment advances each of its walkers
    (:func:`walkerlab.gym.rigid_rows.advance_rows`, the compiled pieces on
    :func:`walkerlab.integrate.rows_dop853.period_rows`, here a batch of one), so its
    observations, rewards, flags and infos are the one-walker vector environment's bit for
    bit: the scene's controller with random actions through heel strikes to the episode's
    end (before: CyRK's DOP853 against the kernel's, within 1e-9 after 50 periods)."""
    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

    kw = dict(start_noise=0.05, max_episode_steps=120, policy="scene")
    single = gym.make(ID, scene=_scene(scene), **kw)
    native = _native(1, scene, **kw)
    actions = 0.3 * _random_actions(native, 120, seed=7)
    obs, info = single.reset(seed=3)
    vobs, vinfo = native.reset(seed=3)
    np.testing.assert_array_equal(vobs[0], obs)
    strikes = 0
    for a in actions:
        obs, r, term, trunc, info = single.step(a[0])
        vobs, vr, vterm, vtrunc, vinfo = native.step(a)
        assert obs.tobytes() == vobs[0].tobytes() and r == vr[0]
        assert (term, trunc) == (vterm[0], vtrunc[0])
        for k, v in info.items():
            w = vinfo[k][0]
            assert (w is None or np.isnan(w)) if v is None else v == w, k
        strikes += info["heel_strike"]
        if term or trunc:
            break
    assert strikes > 1 and (term or trunc)
    single.close()
    native.close()


@pytest.mark.parametrize("policy, action_scale", [("scene", 0.3), (None, 1.0)])
def test_native_vector_env_of_8_walkers_is_8_single_envs_bit_for_bit(policy, action_scale):
    """The native vector env's batched step (the common period's batch arrays,
    :func:`walkerlab.gym.rows_common.step_common`, and the array step around it) against
    8 ``gym.make`` environments seeded ``s + i`` and stepped with the same actions, each
    reset on the step after its episode's end (gymnasium's NEXT_STEP): over 200 periods
    (the scene's controller walking through heel strikes, or random pushes without it: falls;
    the time limit and resets on the way) the observations and rewards are equal with
    ``==``, and the flags and heel strikes exactly."""
    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

    n, steps = 8, 200
    kw = dict(start_noise=0.05, max_episode_steps=60, policy=policy)
    native = _native(n, "threelink_hzd", **kw)
    singles = [gym.make(ID, scene=_scene("threelink_hzd"), **kw) for _ in range(n)]
    actions = action_scale * _random_actions(native, steps, seed=5)
    vobs, _ = native.reset(seed=11)
    for i, env in enumerate(singles):
        obs, _ = env.reset(seed=11 + i)
        assert (obs == vobs[i]).all()
    ended = [False] * n
    strikes = ends = 0
    for a in actions:
        vobs, vr, vterm, vtrunc, vinfo = native.step(a)
        for i, env in enumerate(singles):
            if ended[i]:
                obs, r, term, trunc, hs = (*env.reset()[:1], 0.0, False, False, False)
            else:
                obs, r, term, trunc, info = env.step(a[i])
                hs = info["heel_strike"]
            assert (obs == vobs[i]).all() and r == vr[i], i
            assert (term, trunc, hs) == (vterm[i], vtrunc[i], vinfo["heel_strike"][i]), i
            ended[i] = term or trunc
            strikes += hs
            ends += term or trunc
    assert ends > 8 and strikes > (8 if policy else 0)  # episode ends, heel strikes
    native.close()
    for env in singles:
        env.close()


@pytest.mark.parametrize("batched", [True, False], ids=["batched", "per_walker"])
def test_a_callers_change_to_a_steps_arrays_does_not_come_back_from_a_partial_reset(batched):
    """The step's arrays are the caller's (copies): changed in place (an observation
    normalised in place, say), the walker a reset of the others leaves keeps its row as the
    environment has it."""
    env = _native(2, autoreset_mode="Disabled", batched=batched)
    env.reset(seed=0)
    zero = np.zeros(env.action_space.shape, np.float32)
    obs, reward, term, trunc, _ = env.step(zero)
    kept = obs[1].copy()
    obs += 1000.0
    reward += 1000.0
    again, _ = env.reset(options={"reset_mask": np.array([True, False])})
    np.testing.assert_array_equal(again[1], kept)
    assert not np.shares_memory(again, obs)
    obs2, reward2, *_ = env.step(zero)
    assert np.all(np.abs(obs2) < 1000.0) and np.all(np.abs(reward2) < 1000.0)
    env.close()
