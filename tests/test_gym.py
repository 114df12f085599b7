"""The walker as a Gymnasium environment (:mod:`walkerlab.gym`): the checker's contract, the
scene's own walk under a zero action in both views, seeded episodes bit for bit, a vector
of environments, one-line refusals."""

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from walkerlab.walker.plant import Plant  # noqa: E402

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
                                       ("powered_compass", "contact"), ("flat_feet", "rigid"),
                                       ("flat_feet", "contact"), ("threelink_hzd", "rigid")])
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


def _documented_info_keys(page: str) -> set[str]:
    """The keys of the docs' gym ``info`` table (its first column's backquoted names)."""
    head = page.index("| key | type [unit] | meaning |")
    rows = page[head:].split("\n\n", 1)[0].splitlines()[2:]
    return {k for r in rows for k in re.findall(r"`([a-z_]+)`", r.split("|")[1])}


def test_the_info_keys_are_the_documented_ones_with_their_types():
    """Issue 64: ``info`` was documented in a sentence that left out half its keys.  The
    keys ``reset`` and ``step`` return are :data:`walkerlab.gym.env.INFO_KEYS` plus one
    ``ledger_<term>`` per ledger term, each named in the env's docstring and in the docs'
    gym table (which lists the contact view's ledger terms too), with the types said there;
    the time advances by the control period."""
    import walkerlab.gym.env as genv
    from walkerlab.gym.contact_view import CONTACT_LEDGER_TERMS
    from walkerlab.gym.rigid_view import LEDGER_TERMS

    env = _env("paper", max_episode_steps=5)
    _, first = env.reset(seed=0)
    *_, info = env.step(np.zeros(env.action_space.shape, np.float32))
    keys = set(genv.INFO_KEYS) | {f"ledger_{t}" for t in LEDGER_TERMS}
    assert set(first) == set(info) == keys
    assert set(CONTACT_LEDGER_TERMS) <= set(LEDGER_TERMS)
    assert first["time_s"] == 0.0 and info["time_s"] == pytest.approx(0.01, abs=1e-12)
    assert first["heel_strike"] is False and first["heel_strike_time_s"] is None
    assert info["heel_strike_times_s"] == [] and info["steps"] == 0
    assert info["stance_leg"] in ("leg1", "leg2") and info["termination"] == ""
    assert isinstance(info["hip_x_m"], float) and isinstance(info["terrain_seed"], int)
    assert info["solver_message"] == ""
    assert all(isinstance(info[f"ledger_{t}"], float) for t in LEDGER_TERMS)
    for doc in (genv.__doc__, genv.WalkerEnv.__doc__):
        missing = [k for k in genv.INFO_KEYS if f"``{k}``" not in doc]
        assert not missing and "``ledger_<term>``" in doc, missing
    assert all(f"``{t}``" in genv.__doc__ for t in LEDGER_TERMS)
    page = (ROOT / "docs" / "user_guide" / "python_api.md").read_text()
    assert _documented_info_keys(page) == keys | {f"ledger_{t}" for t in CONTACT_LEDGER_TERMS}


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


def test_the_contact_views_heel_strikes_are_located_on_the_first_runs_interpolant(
        monkeypatch):
    """A control period's compiled segment keeps no dense output; where an event (the heel
    strike) is to be located it runs the segment again with one
    (:mod:`walkerlab.integrate.compiled_segments`).  Against the same periods with every
    segment's dense output kept from its first run and that one used: the same heel-strike
    times, observations and rewards bit for bit (the scene's controller as the policy, 120
    periods of the three-link walker: two heel strikes)."""
    import gymnasium as gym

    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0
    from walkerlab.integrate import _cyrk

    def walk():
        env = gym.make("walkerlab/Walker-v0", scene=str(ROOT / "configs" / "threelink_hzd.yaml"),
                       view="contact", policy="scene")
        obs, _ = env.reset(seed=0)
        zero = np.zeros(env.action_space.shape, env.action_space.dtype)
        rows, strikes = [obs], []
        for _ in range(120):
            obs, reward, term, trunc, info = env.step(zero)
            rows.append(np.append(obs, reward))
            strikes += list(info["heel_strike_times_s"])
            assert not (term or trunc), info
        env.close()
        return np.concatenate(rows), strikes

    replayed = walk()
    call, kept = _cyrk.ChunkSolver.__call__, {}  # a solver's last run, with its dense output

    def first_runs_dense(self, x0, t_eval, data, dense=False):
        if dense:  # an event's interpolant: the segment's first run's, whatever is asked
            return kept.pop(id(self))  # (no segment stops early here)
        if id(self) in kept:
            kept.pop(id(self))[4].free()
        out = kept[id(self)] = call(self, x0, t_eval, data, True)
        return out[:4]

    monkeypatch.setattr(_cyrk.ChunkSolver, "__call__", first_runs_dense)
    kept_first = walk()
    assert len(replayed[1]) >= 2
    assert replayed[1] == kept_first[1]
    np.testing.assert_array_equal(replayed[0], kept_first[0])


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
    # flat feet walk both views now (test_flat_feet_walk_the_rigid_view_as_simulate_does)
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


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
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


def _stage_heel_strikes(stage, name, tmp_path):
    """The heel-strike times [s] of ``walkerlab simulate`` / ``contact-sim`` of a shipped
    scene (its artifact: the step table's ends, the contact run's events)."""
    import h5py

    from walkerlab.config import load_scene
    from walkerlab.stages import pipeline

    path = pipeline.run(stage, load_scene(ROOT / "configs" / f"{name}.yaml"), tmp_path).path
    with h5py.File(path, "r") as f:
        if stage == "simulate":
            ok = f["steps/termination"][:].astype(str) == "heel_strike"
            return f["steps/t_end"][:][ok]
        return f["events/heel_strike_times"][:]


@pytest.mark.parametrize("name,periods,differ", [("footholds_two", 740, 0.0398),
                                                 ("profile", 560, 0.0)])
def test_the_rigid_view_walks_footholds_and_a_profile_as_simulate_does(name, periods,
                                                                        differ, tmp_path):
    """configs/footholds_two.yaml (two heights in turn: a period-2 gait, steps of 0.6918 and
    0.7317 s) and configs/profile.yaml (an undulating ramp: step periods 0.530-0.558 s) in
    the rigid view under a zero action: each of `walkerlab simulate`'s 10 heel strikes at
    the same time to 1e-9 s (the same integrator; the gym restarts it at each control
    period's bound, measured 1.8e-12 s); on the profile a step is walked again on the
    segment its foot lands on (before: both scenes refused in one line)."""
    ref = _stage_heel_strikes("simulate", name, tmp_path)
    assert ref.size == 10
    env = _env(name, max_episode_steps=periods)
    strikes, info = _zero_walk(env)
    assert info["termination"] == "" and strikes.size == ref.size, (strikes, info)
    np.testing.assert_allclose(strikes, ref, rtol=0.0, atol=1e-9)
    T = np.diff(strikes, prepend=0.0)
    if differ:  # the period-2 gait: its two steps' periods in turn (the scene's comment)
        np.testing.assert_allclose(T[0::2], 0.6918, atol=1e-4)
        np.testing.assert_allclose(T[1::2], 0.7317, atol=1e-4)
    else:  # the undulation moves the periods by up to 3.5 % (on the ramp alone: constant)
        assert np.ptp(T) > 0.01  # [s]: 0.0189 measured


def test_a_finite_foothold_list_ends_the_rigid_episode_where_simulate_ends():
    """configs/footholds_two.yaml with ``periodic: false``: simulate walks the list's 2 steps
    and stops; the episode ends there too, terminated as ``ground_end`` (not a fall)."""
    import yaml

    from walkerlab.gym.env import WalkerEnv

    d = yaml.safe_load((ROOT / "configs" / "footholds_two.yaml").read_text())
    d["terrain"]["periodic"] = False
    env = WalkerEnv(d, max_episode_steps=400)
    strikes, info = _zero_walk(env)
    assert info["termination"] == "ground_end" and strikes.size == info["steps"] == 2
    np.testing.assert_allclose(np.diff(strikes, prepend=0.0), [0.6918, 0.7317], atol=1e-4)


def test_the_rigid_view_refuses_a_ground_drawn_per_step_and_an_actuated_profile():
    """A per-step random ground is simulate's draw (--terrain-seed): the rigid view says so
    in one line; a profile with an actuated walker, as simulate, in one line."""
    import yaml

    from walkerlab.gym.env import WalkerEnv

    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    d["terrain"] = {"kind": "slope", "per_step": {"slope_sd_rad": 0.001}}
    with pytest.raises(ValueError, match=r"^walkerlab\.gym: terrain\.per_step: [^\n]*$"):
        WalkerEnv(d)
    d = yaml.safe_load((ROOT / "configs" / "profile.yaml").read_text())
    d["walker"]["actuation"] = {"push_off": {"impulse_n_s": 0.05}}
    with pytest.raises(ValueError, match=r"^walkerlab\.gym: terrain\.kind: profile: "
                       r"walked by the passive walker"):
        WalkerEnv(d)


@pytest.mark.slow
def test_the_rigid_view_trips_on_a_wall_where_simulate_does():
    """The paper's walker on its slope written as a profile with a 1 m wall half-way
    between footfalls 1 and 2 (before: the rigid view walked through it): under a zero
    action the episode ends as a ``trip`` after 1 heel strike, as ``simulate``'s walk does
    (:func:`walkerlab.analysis.gait.rigid_run.profile_walk`), the foot meeting the wall at
    the same time and place (to 1e-8 s and m: the integrator restarted at each control
    period against one step's integration)."""
    import yaml

    from walkerlab.analysis.gait.rigid_run import profile_walk
    from walkerlab.gym.env import WalkerEnv

    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    t = np.tan(d["slope"]["angle_rad"])
    x0 = 0.58  # half-way between footfalls 1 and 2 (0.3867 m steps from x = 0)
    pts = [(0.0, 0.0), (x0, 0.0), (x0 + 1e-3, 1.0), (x0 + 0.05, 1.0),
           (x0 + 0.051, 0.0), (20.0, 0.0)]
    d["terrain"] = {"kind": "profile", "profile_m": [[x, -x * t + h] for x, h in pts]}
    env = WalkerEnv(d, max_episode_steps=400)  # its gait: the scene's slope's (the profile)
    ref = profile_walk(env.rigid.scene, env.gait.x, 6, plant=Plant.from_scene(env.rigid.scene))
    assert ref.termination == "trip" and len(ref.segments) == 2
    strikes, info = _zero_walk(env)
    assert info["termination"] == "trip" and strikes.size == 1
    assert np.allclose(env.sim.trip, ref.profile_trip, atol=1e-8, rtol=0)


@pytest.mark.parametrize("kind", ["flat_feet", "hinged_torso"])
def test_both_views_refuse_a_profile_as_the_tables_gym_cell_does(kind):
    """The capability table refuses a profile in the gym for flat feet and the three-link
    walker (the rigid walk of a profile takes neither); before, the contact view took their
    profile reference cases anyway.  Now both views refuse it in the table's one line."""
    from walkerlab.gym.env import WalkerEnv
    from walkerlab.walker.kinds import KINDS
    from walkerlab.walker.reference_cases import reference_scene

    why = KINDS[kind].cell("profile", "gym")
    assert why is not None
    d = reference_scene(kind, "profile", "gym")[1]
    for view in ("rigid", "contact"):
        with pytest.raises(ValueError) as exc:
            WalkerEnv(d, view=view)
        assert str(exc.value) == f"walkerlab.gym: terrain.kind: profile: {why}"


@pytest.mark.slow
@pytest.mark.parametrize("name,periods", [("footholds_two", 880), ("profile", 560)])
def test_the_contact_view_walks_footholds_and_a_profile_as_contact_sim_does(name, periods,
                                                                           tmp_path):
    """configs/footholds_two.yaml (patches at the rigid period-2 gait's footfalls, then at
    the walker's own: before, the episode tripped at a patch's side after 6 heel strikes)
    and configs/profile.yaml (the profile as the contact model's polyline ground) in the
    contact view under a zero action: every step period of `walkerlab contact-sim`'s heel
    strikes (12 and 10) within 2 % (measured: 6e-5 s and 2.3e-4 s apart)."""
    ref = _stage_heel_strikes("contact-sim", name, tmp_path)
    assert ref.size >= 10
    env = _env(name, view="contact", max_episode_steps=periods)
    strikes, info = _zero_walk(env)
    assert info["termination"] == "" and strikes.size >= ref.size, (strikes, info)
    got, want = np.diff(strikes[:ref.size], prepend=0.0), np.diff(ref, prepend=0.0)
    np.testing.assert_allclose(got, want, rtol=0.02)


def _one_line_error(exc_info, *words):
    text = str(exc_info.value)
    assert "\n" not in text and all(w in text for w in words), text


@pytest.mark.parametrize("view", ["rigid", "contact"])
def test_a_nan_none_complex_or_ill_shaped_action_is_refused_in_one_line(view):
    """Before: the rigid view took ``[nan]`` and ``None`` (NaN observation and reward,
    'solver_failure'); the contact view returned a NaN observation, did not terminate, and
    its next step raised scipy's "y0 must be finite"; a complex action was cast with a
    warning and ``[[0.1]]`` reshaped.  Now each is gymnasium's ``InvalidAction`` (a
    ValueError) naming the action space, and the episode goes on untouched."""
    from walkerlab.gym.env import InvalidAction

    env = _env("paper", view=view, max_episode_steps=5)
    env.reset(seed=0)
    for bad in ([np.nan], None, [np.inf], [1 + 1j], np.array([0.1], complex), [[0.1]],
                [0.1, 0.2], "x", [[0.1], [0.2, 0.3]]):
        with pytest.raises(InvalidAction) as exc:
            env.step(bad)
        assert isinstance(exc.value, ValueError)
        assert isinstance(exc.value, gym.error.InvalidAction)
        _one_line_error(exc, "action", "Box(")
    obs, r, term, _, info = env.step(np.zeros(1, np.float32))
    assert np.all(np.isfinite(obs)) and np.isfinite(r) and not term, info
    assert info["time_s"] == pytest.approx(0.01)  # the refused actions did not advance it


def test_step_or_render_before_reset_asks_for_a_reset():
    """Outside ``gym.make`` (no order-enforcing wrapper) ``step``/``render`` before
    ``reset`` raised AttributeError; now gymnasium's ResetNeeded."""
    from walkerlab.gym import WalkerEnv

    env = WalkerEnv(str(ROOT / "configs" / "paper.yaml"), render_mode="rgb_array")
    with pytest.raises(gym.error.ResetNeeded, match="step"):
        env.step(np.zeros(1))
    with pytest.raises(gym.error.ResetNeeded, match="render"):
        env.render()
    env.reset(seed=0)
    env.step(np.zeros(1))
    assert env.render().ndim == 3


def test_start_noise_is_bounded_and_options_must_be_a_dict():
    """``start_noise=1e300`` was taken and overflowed (OverflowError) after the start's
    check; ``reset(options=[1, 2])`` raised a bare TypeError.  Now start_noise is refused
    above 1 (rates times 1 + U(-s, s)) and a noisy given state is checked after the noise."""
    from walkerlab.config import SceneError
    from walkerlab.gym import WalkerEnv

    scene = str(ROOT / "configs" / "paper.yaml")
    for noise in (1e300, 1.5, True, float("nan"), -0.1):
        with pytest.raises(ValueError, match="^start_noise=") as exc:
            WalkerEnv(scene, start_noise=noise)
        _one_line_error(exc)
    env = WalkerEnv(scene, start_noise=1.0)
    obs, _ = env.reset(seed=0)
    assert np.all(np.isfinite(obs)) and not np.array_equal(obs[:4], env.gait.x)
    with pytest.raises(ValueError, match="options must be a dict") as exc:
        env.reset(options=[1, 2])
    _one_line_error(exc, "list")
    # the bound on rates (20 sqrt(g/l) = 62.6 rad/s) holds 40 rad/s; the noise (up to x2)
    # may take it past: the check comes after the noise, and names the state
    x = np.array(env.gait.x, float)
    x[2:] = 40.0
    seeds = [s for s in range(20) if _raises(env, x, s)]
    assert seeds and len(seeds) < 20, seeds
    with pytest.raises(SceneError, match=r"options\['state'\]"):
        env.reset(seed=seeds[0], options={"state": x})


def _raises(env, x, seed):
    from walkerlab.config import SceneError

    try:
        env.reset(seed=seed, options={"state": x})
    except SceneError:
        return True
    return False


def test_a_huge_max_episode_steps_lays_out_the_contact_ground_as_the_walk_goes():
    """``max_episode_steps=10**12`` in the contact view asked for 52.9 GiB of patches
    (MemoryError); the patches are now laid out for 32 steps at a time and again as the
    walk nears their end, and a walk whose ground is laid out afresh after its first heel
    strike is the walk on ground laid out once, bit for bit."""
    from walkerlab.gym import WalkerEnv
    from walkerlab.gym.contact_view import LAYOUT_STEPS

    scene = str(ROOT / "configs" / "paper.yaml")
    huge = WalkerEnv(scene, view="contact", max_episode_steps=10**12)
    assert huge.sim.walker.lane1.size <= LAYOUT_STEPS
    short = WalkerEnv(scene, view="contact", max_episode_steps=10)  # 5 steps laid out
    runs = []
    for env in (huge, short):
        env.reset(seed=0)
        out, laid = [], []
        for _ in range(80):
            obs, _, term, _, info = env.step(np.zeros(1))
            out.append(obs)
            laid.append(env.sim.walker.lane1.size)
            assert not term, info
        assert info["steps"] >= 1
        runs.append((np.array(out), laid))
    assert runs[1][1][-1] > runs[1][1][0]  # the short layout grew at the heel strike
    np.testing.assert_array_equal(runs[0][0], runs[1][0])


def test_rough_contact_ground_ends_episodes_cleanly_for_seeds_0_to_5():
    """``terrain_roughness_m=0.05``: before, seed 0 raised scipy's "f(a) and f(b) must have
    different signs" at step 51 and seeds 1 and 5 threw the hip to 6.4 and 373 m (the
    starting stance foot's patch raised under it; a swing foot meeting a raised patch's side
    is pushed out as from below its top).  Now the starting patch is the scene's, and each
    episode runs its 60 periods or ends as ``launch`` (hip above 1.5 leg lengths plus the
    highest patch), ``trip`` (the compiled solver stopped with a foot at a patch's side) or
    ``solver_failure`` (with the solver's words) - no exception, finite observations."""
    from walkerlab.gym.contact_view import LAUNCH_HIP_FACTOR

    env = _env("paper", view="contact", terrain_roughness_m=0.05)
    ends = {}
    for seed in range(6):
        env.reset(seed=seed)
        assert env.sim.walker.heights2[0] == 0.0  # the starting stance foot's patch
        assert np.ptp(env.sim.walker.heights1) > 0.02  # the rest is rough
        top = LAUNCH_HIP_FACTOR * 1.0 + 0.05  # leg length 1 m, patches within 5 cm
        for _ in range(60):
            obs, r, term, _, info = env.step(np.zeros(1, np.float32))
            assert np.all(np.isfinite(obs)) and np.isfinite(r)
            hip = env.sim.walker.hip_height(env.sim.x)[0]
            assert hip <= top + 0.01, (seed, hip)  # event located to the solver's tolerance
            if term:
                break
        ends[seed] = info["termination"]
        assert ends[seed] in ("", "launch", "trip", "solver_failure"), info
        assert (ends[seed] in ("trip", "solver_failure")) == bool(info["solver_message"])
    assert "" in ends.values(), ends


def _policy_walk(env, periods, policy):
    obs, info = env.reset()
    strikes = []
    for _ in range(periods):
        obs, _r, term, trunc, info = env.step(policy(obs))
        strikes += info["heel_strike_times_s"]
        if term or trunc:
            break
    return np.array(strikes), info


@pytest.mark.slow
def test_the_scene_policy_walks_the_three_link_closed_loop_as_simulate_does(tmp_path):
    """configs/threelink_hzd.yaml (Bezier virtual constraints on the three-link walker): the
    environment steps the walker without its controller, and ``scene_policy()`` is the
    controller, sampled at each control period's start and held (a zero-order hold).  Each
    of `walkerlab simulate`'s 10 heel strikes' step periods (0.45054 s) is met within one
    control period: the hold delays the computed torque by dt / 2 on average, a first-order
    error in dt (measured: periods 2.3-3.1 ms short at dt = 10 ms, 0.27-0.37 ms at 1 ms);
    so at a fifth of the period the error falls at least threefold (first order: fivefold).
    ``policy="scene"`` adds the same held torque inside the environment: a zero action then
    walks the policy's walk (to the float32 rounding of the policy's action)."""
    from walkerlab.gym.env import WalkerEnv

    ref = np.diff(_stage_heel_strikes("simulate", "threelink_hzd", tmp_path), prepend=0.0)
    assert ref.size == 10
    err = {}
    for dt in (0.01, 0.002):
        env = WalkerEnv(str(ROOT / "configs" / "threelink_hzd.yaml"), control_period_s=dt,
                        max_episode_steps=int(round(4.6 / dt)))
        assert env.joints == ["stance_hip", "swing_hip"]
        strikes, info = _policy_walk(env, env.max_episode_steps, env.scene_policy())
        assert info["termination"] == "" and strikes.size >= ref.size, (strikes, info)
        d = np.diff(strikes, prepend=0.0)[:ref.size] - ref
        assert np.max(np.abs(d)) < dt, (dt, d)
        err[dt] = np.max(np.abs(d))
        if dt == 0.01:
            inside = WalkerEnv(str(ROOT / "configs" / "threelink_hzd.yaml"),
                               control_period_s=dt, max_episode_steps=460, policy="scene")
            same, _ = _policy_walk(inside, 460, lambda o: np.zeros(2))
            np.testing.assert_allclose(same, strikes, rtol=0.0, atol=1e-6)
            unforced, info = _policy_walk(env, 460, lambda o: np.zeros(2))
            assert info["termination"] == "fall"  # the plant without its controller
    assert err[0.002] < err[0.01] / 3, err


def test_the_scene_policy_is_refused_in_one_line_where_the_scene_has_none():
    from walkerlab.gym.env import WalkerEnv

    env = _env("paper", max_episode_steps=5)
    with pytest.raises(ValueError) as e:
        env.scene_policy()
    _one_line_error(e, "scene_policy", "walker.actuation.virtual_constraints")
    with pytest.raises(ValueError) as e:
        WalkerEnv(str(ROOT / "configs" / "paper.yaml"), policy="scene")
    _one_line_error(e, "policy='scene'", "walker.actuation.virtual_constraints")
    with pytest.raises(ValueError) as e:
        WalkerEnv(str(ROOT / "configs" / "paper.yaml"), policy="pd")
    _one_line_error(e, "policy='pd'")


@pytest.mark.slow
def test_rabbit_walks_twenty_contact_steps_under_its_scene_policy_near_the_rigid_speed():
    """configs/rabbit_hzd.yaml in the contact view, its controller as the environment's
    policy (``policy="scene"``: the computed torque at the contact walker's role state,
    held over each 2 ms control period): at least 20 heel strikes, the mean speed from the
    second heel strike on within 3 % of the rigid closed loop's (0.70445 m/s)."""
    env = _env("rabbit_hzd", view="contact", control_period_s=0.002, policy="scene",
               max_episode_steps=6500)
    obs, info = env.reset()
    strikes, x_at = [], []
    for _ in range(env.max_episode_steps):
        obs, _r, term, trunc, info = env.step(np.zeros(env.action_space.shape))
        if info["heel_strike"]:
            strikes.append(info["time_s"])
            x_at.append(info["hip_x_m"])
        if term or trunc or len(strikes) >= 22:
            break
    assert len(strikes) >= 21, (strikes, info)
    rigid = env.gait.speed
    speed = (x_at[-1] - x_at[1]) / (strikes[-1] - strikes[1])
    assert abs(speed / rigid - 1.0) < 0.03, (speed, rigid)


@pytest.mark.slow
@pytest.mark.parametrize("name,periods", [("flat_feet", 900), ("flat_feet_push_off", 900),
                                          ("flat_feet_foot_mass", 1100)])
def test_flat_feet_walk_the_contact_view_as_contact_sim_does(name, periods, tmp_path):
    """Flat feet on ankle springs (configs/flat_feet.yaml, passive on a slope;
    configs/flat_feet_push_off.yaml, an ankle push-off on level ground;
    configs/flat_feet_foot_mass.yaml, 0.1 kg feet, started as contact-sim starts it on the
    contact model's own periodic gait, ``contact_sim.start: periodic_gait``: a search of
    ~40 s CPU, twice here) in the contact view under a zero action: every step period of
    `walkerlab contact-sim`'s heel strikes (11 each; the first scene's run from the rigid
    gait's mid-stance, contact_sim.start: mid_stance) within 0.5 % (the environment's
    run is the compiled BDF with a held force, the command's its own integrator at the same
    tolerances: measured 1.6e-3 s, 1.4e-4 s and 2.2e-4 s apart at most, 0.2 %, 0.02 % and
    0.03 %; before the periodic start, the last scene's episode tripped at a patch's edge
    after 6 heel strikes)."""
    ref = _stage_heel_strikes("contact-sim", name, tmp_path)
    assert ref.size >= 6
    env = _env(name, view="contact", max_episode_steps=periods)
    strikes, info = _zero_walk(env)
    assert info["termination"] == "" and strikes.size >= ref.size, (strikes, info)
    got, want = np.diff(strikes[:ref.size], prepend=0.0), np.diff(ref, prepend=0.0)
    np.testing.assert_allclose(got, want, rtol=0.005)


@pytest.mark.parametrize("name,periods", [("flat_feet", 820), ("flat_feet_push_off", 780)])
def test_flat_feet_walk_the_rigid_view_as_simulate_does(name, periods, tmp_path):
    """Flat feet in the rigid view (the stance foot's heel, flat and toe modes, the double
    support) under a zero action: `walkerlab simulate`'s 10 heel strikes at the same times
    to 1e-9 s (the same integrator and phases; measured 1.5e-12 s).  A vanishing action
    (1e-12 of the bound) walks through the action's twin walker (each mode's own mass
    matrix, Python flows instead of the compiled ones): the first two heel strikes the
    same to 1e-9 s (measured 2.5e-12 s), so the twin's modes, guards and resets are the
    scene's (before: flat feet refused in the environment)."""
    ref = _stage_heel_strikes("simulate", name, tmp_path)
    assert ref.size == 10
    env = _env(name, max_episode_steps=periods)
    strikes, info = _zero_walk(env)
    assert info["termination"] == "" and strikes.size == ref.size, (strikes, info)
    np.testing.assert_allclose(strikes, ref, rtol=0.0, atol=1e-9)
    env.max_episode_steps = int(ref[1] / env.dt) + 2
    tiny, info = _walk(env, env.max_episode_steps,
                       action=lambda e: np.full(e.action_space.shape, 1e-12))[::2]
    assert tiny.size == 2 and not info["termination"], (tiny, info)
    np.testing.assert_allclose(tiny, ref[:2], rtol=0.0, atol=1e-9)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_a_held_hip_torque_slows_the_flat_feet_step_alike_in_the_rigid_and_contact_views():
    """configs/flat_feet.yaml with a held hip torque (0.02 of the bound: 0.39 N m): the
    first step's period grows by the same amount in the rigid view (the twin's mode mass
    matrices, M_mode^-1 B u) and in the contact view (the torque a generalised force on the
    floating model's legs; no code shared with the rigid modes): measured +9.98 ms and
    +9.86 ms (the zero-action periods differ by 4.5 ms, the foot's compliance); within 10 %."""
    change = {}
    for view in ("rigid", "contact"):
        env = _env("flat_feet", view=view, max_episode_steps=120)
        first = []
        for a in (0.0, 0.02):
            strikes, _, info = _walk(env, 120, action=lambda e, a=a: np.full(
                e.action_space.shape, a))
            assert strikes.size >= 1, info
            first.append(strikes[0])
        change[view] = first[1] - first[0]
    assert change["rigid"] > 0.005, change
    assert abs(change["contact"] / change["rigid"] - 1.0) < 0.1, change


def test_gym_make_max_episode_steps_governs_the_episode_not_the_envs_own_1000():
    """Before: ``gym.make(..., max_episode_steps=2500)`` still truncated at 1000 control
    periods (the env's own limit under the TimeLimit wrapper)."""
    import gymnasium as gym

    import walkerlab.gym  # noqa: F401 - registers the id

    env = gym.make("walkerlab/Walker-v0", scene=str(ROOT / "configs" / "paper.yaml"),
                   max_episode_steps=2500)
    assert env.unwrapped.max_episode_steps is None and env.spec.max_episode_steps == 2500
    env.reset(seed=0)
    env.unwrapped._elapsed = 1000  # past the env's old limit, short of the wrapper's
    _, _, term, trunc, _ = env.step(np.zeros(env.action_space.shape, np.float32))
    assert not trunc or term
    assert gym.make("walkerlab/Walker-v0", scene=str(ROOT / "configs" / "paper.yaml")
                    ).spec.max_episode_steps == 1000


def test_the_env_and_the_walker_pickle_and_a_subprocess_vector_env_steps():
    """Before: ``WalkerEnv`` and ``wl.Walker`` did not pickle (a compiled flow), so
    ``AsyncVectorEnv`` could not take them; now each pickles as what it was built from."""
    import pickle

    import gymnasium as gym

    from walkerlab.api.walker import Walker
    from walkerlab.gym.env import WalkerEnv

    paper = str(ROOT / "configs" / "paper.yaml")
    w = pickle.loads(pickle.dumps(Walker.from_scene(paper)))
    assert w.state_names() == Walker.from_scene(paper).state_names()
    env = pickle.loads(pickle.dumps(WalkerEnv(paper, max_episode_steps=7)))
    assert env.max_episode_steps == 7
    obs, _ = env.reset(seed=1)
    ref, _ = WalkerEnv(paper).reset(seed=1)
    np.testing.assert_array_equal(obs, ref)
    vec = gym.vector.AsyncVectorEnv([lambda: WalkerEnv(paper)] * 2)
    try:
        obs, _ = vec.reset(seed=0)
        obs, *_ = vec.step(np.zeros((2, *env.action_space.shape), np.float32))
        assert obs.shape[0] == 2 and np.all(np.isfinite(obs))
    finally:
        vec.close()


@pytest.mark.parametrize("view", ["rigid", "contact"])
def test_a_reset_state_given_as_text_is_refused_in_one_line(view):
    from walkerlab.config import SceneError

    env = _env("paper", view=view, max_episode_steps=5)
    x = [str(v) for v in env.reset(seed=0)[1].get("state", env.gait.x)] \
        if view == "rigid" else [str(v) for v in env.sim.x_start]
    with pytest.raises(SceneError) as e:
        env.reset(options={"state": x})
    _one_line_error(e, "options['state']", "not text")
