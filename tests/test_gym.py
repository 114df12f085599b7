"""The walker as a Gymnasium environment (:mod:`walkerlab.gym`): the checker's contract, the
scene's own walk under a zero action in both views, seeded episodes bit for bit, a vector
of environments, one-line refusals."""

import warnings
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: the paper walker's step period [s] (walkerlab fixedpoint configs/paper.yaml)
PAPER_PERIOD_S = 0.70359688


def _env(name, **kw):
    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

    steps = kw.pop("max_episode_steps", 1000)
    env = gym.make("walkerlab/Walker-v0", scene=str(ROOT / "configs" / f"{name}.yaml"),
                   **kw).unwrapped
    env.max_episode_steps = steps  # the unwrapped env truncates by itself
    return env


def _check(name, view="rigid"):
    env = _env(name, view=view, max_episode_steps=50, render_mode="rgb_array")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the checker's warnings are failures here
        check_env(env)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert frame.std() > 0  # something is drawn


@pytest.mark.parametrize("name", ["paper", "powered_compass"])
def test_check_env_passes_for_a_passive_and_a_pushed_walker(name):
    _check(name)


@pytest.mark.slow
@pytest.mark.parametrize("name,view", [("rabbit", "rigid"), ("paper", "contact"),
                                       ("powered_compass", "contact")])
def test_check_env_passes_for_a_five_link_biped_and_the_contact_view(name, view):
    _check(name, view)


def _walk(env, periods, seed=None, action=None):
    obs, info = env.reset(seed=seed)
    strikes, out = [], [np.concatenate([obs, [0.0, 0.0, 0.0]])]
    for _ in range(periods):
        a = np.zeros(env.action_space.shape) if action is None else action(env)
        obs, r, term, trunc, info = env.step(a)
        out.append(np.concatenate([obs, [r, term, trunc]]))
        if info["heel_strike"]:
            strikes.append(info["heel_strike_time_s"])
            assert info["heel_strike_times_s"][-1] == info["heel_strike_time_s"]
        if term or trunc:
            break
    return np.array(strikes), np.array(out), info


def test_a_zero_action_walks_the_paper_gait_with_heel_strikes_at_its_step_period():
    """The rigid view with no torque is the scene's passive walk: each heel strike at the
    event's own time inside its control period, k T (T the gait's step period; to 1e-6, the
    integrator's restarts at each period bound being all that differs), the heel strike's
    loss the only ledger term."""
    env = _env("paper", max_episode_steps=300)
    strikes, obs, info = _walk(env, 300)
    assert len(strikes) == 4 and not info["termination"]
    np.testing.assert_allclose(strikes, PAPER_PERIOD_S * np.arange(1, 5), atol=1e-6)
    assert np.all(np.abs(strikes / 0.01 - np.round(strikes / 0.01)) > 1e-6)  # off the grid
    assert info["ledger_action_work_positive"] == info["ledger_action_work_negative"] == 0.0
    assert info["ledger_heel_strike_loss"] < 0.0


@pytest.mark.slow
def test_a_zero_action_walks_the_paper_contact_walker_near_the_rigid_step_period():
    """The contact view's heel strikes (touchdowns ahead of the stance foot) come at the
    rigid step period within 3 % (mean of the steps after the first, which starts from the
    rigid state placed on compliant ground)."""
    env = _env("paper", view="contact", max_episode_steps=400)
    strikes, _, info = _walk(env, 400)
    assert len(strikes) >= 4, info
    mean = np.mean(np.diff(strikes))
    assert abs(mean / PAPER_PERIOD_S - 1.0) < 0.03, (strikes, mean)


def test_the_same_seed_gives_the_same_episode_bit_for_bit():
    """Start noise and random actions drawn from the seed: two environments, one seed, the
    same observations, rewards and ends to the last bit; another seed, another episode."""
    def run(seed):
        env = _env("paper", max_episode_steps=40, start_noise=0.02)
        env.action_space.seed(seed)
        return _walk(env, 40, seed=seed, action=lambda e: e.action_space.sample())[1:]

    (a, ia), (b, ib), (c, _) = run(7), run(7), run(8)
    assert np.array_equal(a, b) and ia == ib
    assert ia["terrain_seed"] == ib["terrain_seed"]
    assert a.shape != c.shape or not np.array_equal(a, c)


def test_a_torque_moves_the_walker_and_is_charged_in_the_ledger():
    """A constant hip torque (swing leg forward) changes the walk and its work is booked:
    positive and negative parts, and the control cost in the reward."""
    env = _env("paper", max_episode_steps=60)
    _, free, _ = _walk(env, 60)
    _, pushed, info = _walk(env, 60, action=lambda e: np.full(e.action_space.shape, 0.5))
    assert not np.allclose(free[-1][:4], pushed[-1][:4])
    work = info["ledger_action_work_positive"] + info["ledger_action_work_negative"]
    assert info["ledger_action_work_positive"] > 0.0 and np.isfinite(work)


def test_a_vector_of_eight_environments_steps_together():
    env = gym.vector.SyncVectorEnv([lambda: _env("paper", max_episode_steps=20)
                                    for _ in range(8)])
    obs, _ = env.reset(seed=list(range(8)))
    assert obs.shape == (8, 7)
    for _ in range(3):
        obs, r, term, trunc, info = env.step(np.zeros((8, 1), np.float32))
    assert obs.shape == (8, 7) and r.shape == (8,) and not term.any()
    np.testing.assert_array_equal(obs[0], obs[7])  # no noise: every walker alike
    env.close()


def test_reset_from_a_given_state_and_bad_inputs_say_one_line():
    from walkerlab.config import SceneError

    env = _env("paper", max_episode_steps=5)
    x = np.array(env.gait.x) * 1.01
    obs, _ = env.reset(options={"state": x})
    np.testing.assert_array_equal(obs[:4], x)
    with pytest.raises(SceneError, match="options\\['state'\\]"):
        env.reset(options={"state": [1.0, 2.0]})
    with pytest.raises(ValueError, match="unknown options"):
        env.reset(options={"x": 1})
    from walkerlab.gym import WalkerEnv

    scene = str(ROOT / "configs" / "paper.yaml")
    for kw, msg in [({"view": "soft"}, "view='soft'"), ({"control_period_s": 0}, "control_"),
                    ({"max_episode_steps": 0}, "max_episode_steps"),
                    ({"max_torque_n_m": [1, 2]}, "max_torque_n_m")]:
        with pytest.raises(ValueError, match=msg) as exc:
            WalkerEnv(scene, **kw)
        assert "\n" not in str(exc.value)
    with pytest.raises(ValueError, match="flat feet") as exc:
        WalkerEnv(str(ROOT / "configs" / "flat_feet.yaml"))
    with pytest.raises(ValueError, match="rimless wheel"):
        WalkerEnv(str(ROOT / "configs" / "rimless_wheel.yaml"))


def _zero_walk(env, seed=0):
    env.reset(seed=seed)
    strikes, info = [], {}
    for _ in range(env.max_episode_steps):
        _, _, term, trunc, info = env.step(np.zeros(env.action_space.shape, np.float32))
        strikes += info["heel_strike_times_s"]
        if term or trunc:
            break
    return np.asarray(strikes), info


def test_the_contact_view_keeps_the_scenes_stairs():
    """configs/stairs.yaml in the contact view (patches a riser lower each step): a zero
    action walks down them at the rigid stair gait's step period (0.70998 s) within 3 %, as
    `contact-sim` does (before: the episode's reset laid every patch flat, and the walker
    fell at 2.07 s after one heel strike); a roughness adds to the stairs' heights."""
    env = _env("stairs", view="contact", max_episode_steps=600)
    strikes, info = _zero_walk(env)
    assert info["termination"] == "" and len(strikes) >= 8
    assert np.mean(np.diff(strikes)[2:]) == pytest.approx(0.70998, rel=0.03)
    base = env.sim._heights
    rough = _env("stairs", view="contact", max_episode_steps=5, terrain_roughness_m=0.002)
    rough.reset(seed=3)
    for got, b in zip((rough.sim.walker.heights1, rough.sim.walker.heights2), base):
        d = np.asarray(got) - np.asarray(b)
        assert np.all(np.abs(d) <= 0.002) and np.any(d != 0)


def test_the_rigid_view_refuses_a_ground_whose_steps_differ():
    """A profile (or per-step ground): the rigid view steps one walker, so it says so in one
    line (before: it walked the scene's slope under a profile); the contact view, which has
    the profile as geometry, takes it."""
    with pytest.raises(ValueError, match=r"^walkerlab\.gym: terrain\.kind: profile: .*"
                       r"use view='contact'$"):
        _env("profile")
    env = _env("profile", view="contact", max_episode_steps=70)
    strikes, info = _zero_walk(env)
    assert info["termination"] == "" and len(strikes) >= 1
