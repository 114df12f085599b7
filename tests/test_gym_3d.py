"""The Gymnasium environment's rigid view of 3D walkers (:mod:`walkerlab.gym`, the same env
as the planar walkers'): the scene's own walk under a zero action (the fixed point's period),
the checker's contract, an action from the walker's joints (the hip's pitch torque, and its
hip-roll joints where it has them), the sideways fall as a termination, seeded episodes and
the native vector env bit for bit, and the contact view's walk near the rigid period."""

import warnings
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from tests.test_gym import _env, _walk  # noqa: E402
from tests.test_gym_vector import _native, _run, _same, _vec  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: configs/hip_width_stabilised.yaml's step period [s] (walkerlab fixedpoint: its rigid
#: gait, 0.703241865 s, a stride of two steps landing on either side)
STABILISED_PERIOD_S = 0.7032418654


def test_a_zero_action_walks_the_stabilised_3d_gait_at_the_fixed_points_step_period():
    """configs/hip_width_stabilised.yaml (Kuo 1999's lateral foot placement) under a zero
    action is the scene's own rigid walk: over 3 strides (6 heel strikes, each at the
    event's own time inside its control period, off the 10 ms grid) every step period is
    the fixed point's (the project's gait search, :meth:`SceneWalker.fixed_point`) to 1e-6
    relative (the integrator's restarts at each period bound at rtol 1e-12 are all that
    differs: measured 5e-13), and the walker stays upright (no termination)."""
    env = _env("hip_width_stabilised", max_episode_steps=430)
    strikes, _, info = _walk(env, 430)
    period = env.gait.step_period
    assert abs(period / STABILISED_PERIOD_S - 1.0) < 1e-9
    assert len(strikes) == 6 and not info["termination"]
    np.testing.assert_allclose(np.diff(strikes, prepend=0.0), period, rtol=1e-6, atol=0)
    assert np.all(np.abs(strikes / 0.01 - np.round(strikes / 0.01)) > 1e-6)  # off the grid
    assert info["ledger_action_work_positive"] == info["ledger_action_work_negative"] == 0.0
    assert info["stance_leg"] == "leg2" and info["steps"] == 6  # leg1 swings first


def test_the_3d_action_is_the_hip_pitch_torque_and_the_hip_roll_joints_where_the_walker_has_them():
    """The action's joints are read from the walker's links: the passive 3D walker without
    hip-roll joints (configs/hip_width.yaml) takes the planar passive walker's action (one
    hip torque, ``Box(-1, 1, (1,))``, 0.1 M g l = 19.62 N m); the walker with them
    (configs/hip_width_stabilised.yaml) the hip's and each roll joint's, whose columns of
    ``B`` are the roll joints' angle gradients of the hip-roll law (leg roll minus pelvis
    roll: ``(lean, swing, stance, pelvis_roll, swing_roll)`` rows (1, 0, 0, -1, 0) and
    (0, 0, 0, -1, 1), exactly); the observation is the walker's named state and phase."""
    passive = _env("hip_width", max_episode_steps=5)
    planar = _env("paper", max_episode_steps=5)
    assert passive.joints == planar.joints == ["hip"]
    assert passive.action_space == planar.action_space
    np.testing.assert_allclose(passive.tau_max, [0.1 * 20.0 * 9.81 * 1.0], rtol=1e-12)
    env = _env("hip_width_stabilised", max_episode_steps=5)
    assert env.joints == ["hip", "stance_hip_roll", "swing_hip_roll"]
    assert env.action_space.shape == (3,)
    assert env.state_names == passive.state_names[:3] + ["pelvis_roll_angle",
                                                         "swing_roll_angle"] + [
        n.replace("angle", "rate") for n in passive.state_names[:3]] + [
        "pelvis_roll_rate", "swing_roll_rate"]
    assert env.observation_names == env.state_names + [
        "stance_is_leg1", "phase_index", "time_since_heel_strike_s"]
    B = env.sim.acts["leg1"].B
    np.testing.assert_array_equal(B[:, 1], [1.0, 0.0, 0.0, -1.0, 0.0])
    np.testing.assert_array_equal(B[:, 2], [0.0, 0.0, 0.0, -1.0, 1.0])
    np.testing.assert_array_equal(B[:, 0], [0.0, 1.0, -1.0, 0.0, 0.0])  # swing - stance


@pytest.mark.slow
def test_a_swing_roll_torque_rolls_the_swing_leg_out_and_its_work_is_booked():
    """A held swing-hip-roll torque (+0.2 of its bound: 3.9 N m, +tau on the swing leg about
    its roll joint) against the zero action over one step's first 0.2 s: the swing leg's
    roll relative to the pelvis grows (the torque's sign), the pitch coordinates are moved
    far less, and the torque's positive work is booked in the ledger."""
    env = _env("hip_width_stabilised", max_episode_steps=20)
    _, free, _ = _walk(env, 20)
    _, rolled, info = _walk(env, 20, action=lambda e: np.array([0.0, 0.0, 0.2], np.float32))
    names = env.observation_names
    d = {k: rolled[-1][names.index(k)] - free[-1][names.index(k)] for k in names[:5]}
    assert d["swing_roll_angle"] - d["pelvis_roll_angle"] > 1e-3
    assert abs(d["swing_angle"]) < abs(d["swing_roll_angle"] - d["pelvis_roll_angle"])
    assert info["ledger_action_work_positive"] > 0.0


@pytest.mark.slow
def test_a_3d_walker_pushed_sideways_falls_as_the_episode_s_termination():
    """The passive 3D walker (configs/hip_width.yaml, Kuo 1999: its lateral mode unstable,
    a multiplier of about 100 a stride) started from its gait with the lean rate 5 %
    larger leans over to the side: the episode ends as a ``fall`` (the rigid model's own
    fall guard: a 3D walker's hip at half its leg length), its last observation leaning far
    over (|lean| past 0.5 rad) - the sideways fall, not the sagittal one."""
    env = _env("hip_width", max_episode_steps=1500)
    x = np.array(env.gait.x, float)
    lean_rate = env.state_names.index("lean_rate")
    x[lean_rate] *= 1.05
    obs, _ = env.reset(options={"state": x})
    for _ in range(1500):
        obs, _, term, trunc, info = env.step(np.zeros(1, np.float32))
        if term or trunc:
            break
    assert term and info["termination"] == "fall", info["termination"]
    assert abs(obs[env.observation_names.index("lean_angle")]) > 0.5


@pytest.mark.slow
def test_check_env_passes_for_a_3d_walker_with_hip_roll_joints():
    """gymnasium's ``check_env`` (its warnings failures) on configs/hip_width_stabilised.yaml,
    and its frame (the sagittal view of the 3D points) drawn."""
    env = _env("hip_width_stabilised", max_episode_steps=50, render_mode="rgb_array")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.std() > 0


@pytest.mark.slow
def test_the_same_seed_gives_the_same_3d_episode_and_the_native_vector_env_is_sync_s():
    """Start noise and random actions drawn from the seed on configs/hip_width_stabilised.yaml
    (three action joints): one seed, the same episode to the last bit, another seed another;
    and the native vector env of 3 walkers gives ``make_vec(..., "sync")``'s observations,
    rewards, flags and infos exactly (the same kernel, the same order of operations)."""
    def run(seed):
        env = _env("hip_width_stabilised", max_episode_steps=30, start_noise=0.02)
        env.action_space.seed(seed)
        return _walk(env, 30, seed=seed, action=lambda e: e.action_space.sample())[1:]

    (a, ia), (b, ib), (c, _) = run(7), run(7), run(8)
    assert np.array_equal(a, b) and ia == ib
    assert a.shape != c.shape or not np.array_equal(a, c)
    n, steps = 3, 40
    kw = dict(start_noise=0.05, max_episode_steps=25)
    sync = _vec("sync", n, "hip_width_stabilised", **kw)
    native = _native(n, "hip_width_stabilised", **kw)
    actions = 0.3 * np.random.default_rng(3).uniform(-1, 1, (steps, n, 3)).astype(np.float32)
    got, want = _run(native, actions, 5), _run(sync, actions, 5)
    for k, (x, y) in enumerate(zip(want, got, strict=True)):
        for j, (u, v) in enumerate(zip(x, y, strict=True)):
            _same(u, v, f"output {k}, item {j}")
    assert any(o[3].any() for o in got[1:])  # the time limit met (resets on the way)
    sync.close()
    native.close()


@pytest.mark.slow
def test_the_contact_view_walks_the_stabilised_3d_walker_near_the_rigid_step_period():
    """The contact view of configs/hip_width_stabilised.yaml (its floating walker from the
    contact model's own periodic gait; the action's torques on the floating legs' pitch and
    roll coordinates) under a zero action: its heel strikes come at the rigid step period
    within 3 % (the planar contact view's tolerance: the compliant feet; measured 0.3 %),
    mean of the steps after the first, and it does not fall."""
    env = _env("hip_width_stabilised", view="contact", max_episode_steps=400)
    assert env.joints == ["hip", "stance_hip_roll", "swing_hip_roll"]
    strikes, _, info = _walk(env, 400)
    assert len(strikes) >= 4 and not info["termination"], info
    mean = np.mean(np.diff(strikes))
    assert abs(mean / STABILISED_PERIOD_S - 1.0) < 0.03, (strikes, mean)
