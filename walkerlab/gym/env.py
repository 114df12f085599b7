"""``walkerlab/Walker-v0``: a scene's walker as a Gymnasium environment
(:class:`WalkerEnv`).

Spaces
------
Planar and 3D walkers alike: the spaces are read from the walker's own named state and
joints (a 3D walker's hip-roll joints among them), never from its dimension.  Action: one
torque per joint of :attr:`WalkerEnv.joints` (:mod:`walkerlab.gym.action`), added to the
scene's own actuation and held over the control period: ``Box(-1, 1, (k,), float32)``, the
torque as a fraction of its bound ``tau = a * tau_max`` (:attr:`WalkerEnv.tau_max` [N m];
as Walker2d's by its motors' gears), or with ``normalize_action=False`` ``Box(-tau_max,
tau_max)`` in N m.  An all-zero action is the scene as written (passive, or its laws).

A scene whose actuation is a feedback controller (``walker.actuation.virtual_constraints``)
is stepped without it: the action drives the controller's joints (bounded by its
``max_torque_n_m``, else ``M g l``) and :meth:`WalkerEnv.scene_policy` is the controller as a
policy (``obs -> action``, sampled at each control period's start and held);
``policy="scene"`` adds that held torque to every action (a zero action: the closed loop).

Observation: ``Box((2n + 3,), float64)`` (entries within +-:data:`OBS_BOUND`), by name
:attr:`WalkerEnv.observation_names`:
the walker's state (:attr:`WalkerEnv.state_names`: the rigid walker's role-ordered angles
and rates [rad, rad/s]; in the contact view the floating state ``hip_x, hip_y``, link
angles, then rates [m, rad, m/s, rad/s]), then the phase: ``stance_is_leg1`` (1.0 while
``leg1`` is the stance leg, else 0.0), ``phase_index`` (the rigid step's continuous phase,
:attr:`walkerlab.models.hybrid.HybridWalker.phases`; 0 in the contact view) and
``time_since_heel_strike_s`` [s].

Reward (Walker2d-v5's convention, every weight a keyword)::

    reward = forward_reward_weight * (x_hip(t + dt) - x_hip(t)) / dt + healthy_reward
             - ctrl_cost_weight * sum((u / tau_max)^2)
             - work_cost_weight * (positive action work over the period [J]) / dt

``x_hip`` the hip's world position along x (horizontal, downhill) [m]; defaults 1.0, 1.0,
1e-3 (on the action normalised to [-1, 1], as Walker2d's actions are), 0.0; or a callable
``reward_fn(env, info) -> float`` in its place.

Episode: from the scene's gait (its fixed point, found once per scene and process and
cached; :meth:`walkerlab.rigid_walker.SceneWalker.fixed_point`), leg1 swinging, unless
``reset(options={"state": x})`` gives the state (the rigid walker's post-impact state (2n,),
or in the contact view its floating state (N,)); ``start_noise`` (at most 1) multiplies the
start's rates by ``1 + U(-s, s)`` drawn by the reset's seed, before the start is checked.
Terminated on a fall (a fall guard of the rigid model - a 3D walker's sideways fall too, its
hip at half its leg length; in the contact view the hip below ``contact_sim.fall_hip_height_m``), a
stall (no heel strike within
``fixedpoint.max_step_time_s``), a launch (contact view: the hip thrown above
:data:`walkerlab.gym.contact_view.LAUNCH_HIP_FACTOR` leg lengths, a foot having met a raised
patch's side), a trip (contact view: a foot found at a patch's side where the solver stopped),
the ground's end (rigid view: a finite foothold list walked, a landing past a profile's
last point, as ``walkerlab simulate`` ends there) or a solver failure; truncated after
``max_episode_steps`` control periods.

Ground: the scene's, as the commands step it.  The rigid view steps each step's walker of
a ground whose steps differ as ``walkerlab simulate`` does (footholds of several heights or
slopes: :func:`walkerlab.integrate.rigid.walker_of_step`; a height profile: the walker
landing on the segment under its foot, :class:`walkerlab.analysis.gait.profile_walk.
ProfileGround`, a step landing off the segment it was walked on walked again from its
start on the other with its periods' actions); the contact view lays the patches as
``walkerlab contact-sim`` does (:mod:`walkerlab.gym.contact_view`).
A profile is taken in both views where the capability table's gym cell of the walker's
kind takes it (:data:`walkerlab.walker.kinds.CAPABILITIES`), refused in its one line
elsewhere.
``step`` and ``render`` before the first ``reset`` raise gymnasium's ``ResetNeeded`` (as
``gym.make``'s order enforcing does); an action that is not ``k`` finite real numbers of shape
``(k,)`` (None, NaN, inf, complex, another shape) raises :class:`InvalidAction` (a
``ValueError``), one line naming the action space.

Info (the dict ``reset`` and ``step`` return, the same keys in both; :data:`INFO_KEYS`):

- ``time_s`` (float) [s]: the episode's time (0 at the reset);
- ``heel_strike`` (bool): a heel strike happened inside the control period just held;
- ``heel_strike_time_s`` (float or None) [s]: the exact event time of the period's last heel
  strike (the rigid model's guard, the contact view's touchdown), None without one;
- ``heel_strike_times_s`` (list of float) [s]: every heel strike inside the period;
- ``steps`` (int): heel strikes since the reset;
- ``stance_leg`` (str): the stance leg after the period, ``"leg1"`` or ``"leg2"``;
- ``hip_x_m`` (float) [m]: the hip's world position along x (horizontal, downhill), the
  reward's forward term's;
- ``termination`` (str): ``""`` while the episode goes on, else why it was terminated:
  ``fall``, ``stall``, ``launch``, ``trip``, ``ground_end``, ``solver_failure`` (see
  Episode);
- ``solver_message`` (str): the solver's words on a ``trip`` or ``solver_failure`` in the
  contact view, else ``""``;
- ``terrain_seed`` (int): the seed of this episode's terrain, drawn by the reset's seed;
- ``ledger_<term>`` (float) [J]: the energy ledger's terms summed since the reset, one key
  each: the rigid view's :data:`walkerlab.gym.rigid_view.LEDGER_TERMS`
  (``action_work_positive``, ``action_work_negative``, ``scene_torque_work``,
  ``push_off_work``, ``heel_strike_loss``), the contact view's
  :data:`walkerlab.gym.contact_view.CONTACT_LEDGER_TERMS` (the same without
  ``heel_strike_loss``: its collisions are the contact forces' work, not a ledger term).

``reset(seed=...)`` draws the terrain seed and the start's noise from the seed: the same
seed, the same episode bit for bit.  ``copy.deepcopy`` or a pickle round trip of a
mid-episode environment continues its episode bit for bit (:mod:`walkerlab.gym.
episode_state`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from walkerlab.rigid_walker import SceneWalker, scene_of
from walkerlab.walker.plant import Plant

from .arguments import (
    InvalidAction,
    check_arguments,
    checked_action,
    plant_scene,
    rigid_ground,
)
from .episode_state import capture, restore

__all__ = ["INFO_KEYS", "InvalidAction", "WalkerEnv"]

#: bound of the observation's state entries [m, rad, m/s, rad/s] and time [s]: far beyond a
#: walking state (an observation past it is clipped to it)
OBS_BOUND = 1e6

#: the keys of the ``info`` dict of :meth:`WalkerEnv.reset` and :meth:`WalkerEnv.step`
#: besides the ledger's ``ledger_<term>`` (module docstring, Info: type [unit] and meaning)
INFO_KEYS = ("time_s", "heel_strike", "heel_strike_time_s", "heel_strike_times_s", "steps",
             "stance_leg", "hip_x_m", "termination", "solver_message", "terrain_seed")

#: the fixed point of each scene, found once per process (key: the scene's JSON)
_GAITS: dict[str, Any] = {}


#: ``term -> "ledger_<term>"`` (:meth:`WalkerEnv._info`'s keys, made once)
_LEDGER_KEYS: dict[str, str] = {}


def _ledger_key(term: str) -> str:
    key = _LEDGER_KEYS[term] = f"ledger_{term}"
    return key


def _gait(walker):
    key = walker.scene.model_dump_json()
    if key not in _GAITS:
        _GAITS[key] = walker.fixed_point()
    return _GAITS[key]



#: the episode's length in control periods when none is given (``WalkerEnv``'s default; the
#: registered id's ``gym.make`` limit)
DEFAULT_EPISODE_STEPS = 1000


def _rebuild_env(cls, kwargs):
    """Unpickle a :class:`WalkerEnv`: built again from its arguments."""
    return cls(**kwargs)


def registered_env(**kwargs) -> WalkerEnv:
    """The entry point of ``gym.make("walkerlab/Walker-v0", ...)``: a :class:`WalkerEnv`
    without a limit of its own, so that ``gym.make``'s ``max_episode_steps`` (its
    ``TimeLimit`` wrapper; the id's default :data:`DEFAULT_EPISODE_STEPS`) governs the
    episode's length (before: the env's own 1000 truncated ``max_episode_steps=2500``)."""
    return WalkerEnv(**{"max_episode_steps": None, **kwargs})


class WalkerEnv(gym.Env):
    """A walkerlab scene's walker as a Gymnasium environment (module docstring: spaces,
    reward, episode, info).

    ``reset`` returns ``(observation, info)``, ``step`` ``(observation, reward, terminated,
    truncated, info)``; ``info`` is a dict with the keys :data:`INFO_KEYS` and one
    ``ledger_<term>`` per energy-ledger term (module docstring, Info): ``time_s`` [s],
    ``heel_strike`` (bool), ``heel_strike_time_s`` [s] (None without a heel strike in the
    period), ``heel_strike_times_s`` [s], ``steps``, ``stance_leg`` (``"leg1"`` or
    ``"leg2"``), ``hip_x_m`` [m], ``termination`` (``""`` or why the episode ended),
    ``solver_message``, ``terrain_seed``, ``ledger_<term>`` [J].

    Parameters
    ----------
    scene : Scene, str, Path or dict
        A scene (YAML path, mapping, or loaded :class:`walkerlab.config.Scene`).
    view : {"rigid", "contact"}
        The rigid hybrid model (default) or the compliant-contact model.
    control_period_s : float
        Time the action is held [s] (0.01: 100 Hz).
    max_episode_steps : int or None
        Control periods before the env truncates (default 1000); None: no limit of its
        own (``gym.make(..., max_episode_steps=N)`` builds it so: its TimeLimit wrapper
        truncates at N, by default 1000).
    max_torque_n_m : float or sequence of float, optional
        The action's bounds [N m] (default: the actuators' ``max_torque_n_m``, else
        :data:`walkerlab.gym.action.DEFAULT_TORQUE_FRACTION` ``M g l``).
    forward_reward_weight, healthy_reward, ctrl_cost_weight, work_cost_weight : float
        The reward's weights (module docstring).
    reward_fn : callable, optional
        ``(env, info) -> float`` in place of the default reward.
    start_noise : float
        Relative uniform noise on the start's rates [-], in ``[0, 1]`` (0: the gait itself).
    terrain_roughness_m : float
        Contact view: patch heights uniform in ``[-r, r]`` [m], drawn by the terrain seed.
    normalize_action : bool
        Actions in [-1, 1] (fractions of :attr:`tau_max`; default) or in N m.
    render_mode : {None, "rgb_array"}
    policy : {None, "scene"}
        ``"scene"``: the scene's feedback controller (virtual constraints) acts with every
        action, its torque sampled at the control period's start and held
        (:meth:`scene_policy`); None: the action alone drives the controller's joints.
    compiled_step : bool
        Rigid view: each control period on the compiled control step (default: the flow
        with the action's torques compiled by numba, integrated by DOP853 in compiled code
        at the scene solver's tolerances, as the native vector environment integrates one
        walker: :class:`walkerlab.gym.rigid_view.RigidView`; heel
        strikes within 1e-9 s of the scene's solver on the shipped scenes, 5-20x the
        steps per second), where the step's walker has one (no torque laws of its own, no
        flat feet); False: the scene's ``solver`` with Python flows everywhere.

    Attributes
    ----------
    tau_max : ndarray (k,)
        The bound of each action torque [N m].
    joints : list of str
        The action's joints.
    state_names, observation_names : list of str
        The walker's state's names; the observation's (the state's, then the phase's).
    gait : walkerlab.rigid_walker.Gait
        The scene's gait (the episodes' start).

    Raises
    ------
    walkerlab.config.SceneError
        A scene that does not load or validate (one line).
    ValueError
        A bad view, control period, episode length, bound or policy (``"scene"`` without
        virtual constraints), or a walker the action cannot drive (massless legs, a
        joint-less rimless wheel), one line each.
    walkerlab.analysis.gait.search.GaitNotFound
        The scene has no gait to start from.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 100}

    def __reduce__(self):
        """Pickled (and copied by ``copy.deepcopy``) as the arguments it was built from and
        its episode (:func:`walkerlab.gym.episode_state.capture`): the copy is built again
        from the arguments and continues the episode bit for bit."""
        return (_rebuild_env, (type(self), self._init_args), capture(self))

    def __setstate__(self, state: dict) -> None:
        """The episode of a pickled or copied environment
        (:func:`walkerlab.gym.episode_state.restore`)."""
        restore(self, state)

    def __init__(self, scene, view: str = "rigid", control_period_s: float = 0.01,
                 max_episode_steps: int | None = 1000, max_torque_n_m=None,
                 forward_reward_weight: float = 1.0, healthy_reward: float = 1.0,
                 ctrl_cost_weight: float = 1e-3, work_cost_weight: float = 0.0,
                 reward_fn=None, start_noise: float = 0.0, terrain_roughness_m: float = 0.0,
                 normalize_action: bool = True, render_mode: str | None = None,
                 policy: str | None = None, compiled_step: bool = True):
        #: the arguments it was built from (pickling rebuilds it from them: __reduce__)
        self._init_args = {k: v for k, v in locals().items() if k not in ("self", "__class__")}
        from .action import action_joints, action_limits, action_torques, walker_links
        from .rigid_view import RigidView

        check_arguments(view, control_period_s, max_episode_steps, render_mode, start_noise,
                        terrain_roughness_m)
        if policy not in (None, "scene"):
            raise ValueError(f"policy={policy!r}: give None or 'scene' (the scene's feedback "
                             "controller acting with the action)")
        self.rigid = SceneWalker(Plant.from_scene(scene_of(str(scene) if isinstance(
            scene, Path) else scene)))  # the gym's front door: the walker described once
        sc = self.rigid.scene
        data = self.rigid.plant.data  # the scene's walker, described once (SceneWalker)
        data.structure.kind.require("walk", "gym", "walkerlab.gym")  # the table's refusals
        if sc.terrain is not None and sc.terrain.kind == "profile":  # its gym cell, in both
            # views (the contact view laid any profile contact-sim walks before)
            data.structure.kind.require("profile", "gym",
                                        "walkerlab.gym: terrain.kind: profile")
        vc = sc.walker.actuation.virtual_constraints if sc.walker.actuation else None
        if vc is not None:
            data.structure.kind.require("virtual_constraints", "gym",
                                        "walker.actuation.virtual_constraints")
        elif policy == "scene":
            raise ValueError("policy='scene': the scene has no feedback controller "
                             "(walker.actuation.virtual_constraints) to act as the policy; "
                             "its torque laws act in the walker with policy=None")
        self.policy = policy
        ground = rigid_ground(sc, self.rigid.plant) if view == "rigid" else None
        if view == "contact":  # the contact view's refusals (the table's contact cells for
            # the scene's features, its ground): from the scene alone, before the gait search
            from walkerlab.models.contact.scene import contact_setup

            setup = contact_setup(sc, plant=self.rigid.plant)
        self.scene, self.view = sc, view
        self.dt = float(control_period_s)
        self.max_episode_steps = max_episode_steps
        self.render_mode = render_mode
        self.metadata = dict(self.metadata, render_fps=max(1, round(1.0 / self.dt)))
        self.weights = (float(forward_reward_weight), float(healthy_reward),
                        float(ctrl_cost_weight), float(work_cost_weight))
        self.reward_fn = reward_fn
        self.start_noise = float(start_noise)
        self.terrain_roughness_m = float(terrain_roughness_m)
        self.gait = _gait(self.rigid)
        #: the scene's feedback controller (virtual constraints; None: the scene has none):
        #: out of the walker's flow, the policy (:meth:`scene_policy`)
        self.controller = self.rigid.model.actuators.controller if vc is not None else None
        plant = self.rigid if vc is None else SceneWalker(self.rigid.plant.with_(plant_scene(sc)))
        model = plant.model
        self.joints = action_joints(sc, self.controller, () if vc is not None else
                                    walker_links(data, model.n_coordinates))
        if view == "rigid":
            self.sim = RigidView(model, plant.solver, data, self.joints,
                                 plant.max_step_time, ground, plant.scene.walker.actuation,
                                 compiled=bool(compiled_step))
        self._contact_controller = None
        if view == "contact":
            import dataclasses

            from .contact_view import ContactView

            links = action_torques(data, model.n_coordinates, self.joints).links
            n_steps = int(math.ceil((max_episode_steps or DEFAULT_EPISODE_STEPS) * self.dt
                                    / self.gait.step_period)) + 4
            if vc is not None:  # the controller at the contact walker's role state, held
                self._contact_controller = setup.actuators  # by the action (the plant's
                setup = dataclasses.replace(setup, actuators=None)  # run stays compiled)
            self.sim = ContactView(setup, links, self.gait.x, n_steps)
        p = model.params
        self.tau_max = action_limits(sc, self.joints, float(model.total_mass_kg),
                                     float(p["gravity_m_per_s2"]), float(p["leg_length_m"]),
                                     max_torque_n_m)
        self.state_names = list(self.sim.state_names)
        self.observation_names = self.state_names + ["stance_is_leg1", "phase_index",
                                                     "time_since_heel_strike_s"]
        self.normalize_action = bool(normalize_action)
        bound = (np.ones_like(self.tau_max) if self.normalize_action else self.tau_max)
        self.action_space = spaces.Box(-bound.astype(np.float32), bound.astype(np.float32),
                                       dtype=np.float32)
        nphase = len(model.phases) if view == "rigid" else 1
        m = len(self.state_names)
        self.observation_space = spaces.Box(
            np.concatenate([np.full(m, -OBS_BOUND), [0.0, 0.0, 0.0]]),
            np.concatenate([np.full(m, OBS_BOUND), [1.0, max(nphase - 1.0, 1.0), OBS_BOUND]]),
            dtype=np.float64)
        self._checked_start = None  # the last start that passed the rigid walker's check
        self.terrain_seed = 0
        self._elapsed = 0
        self._has_reset = False

    # ------------------------------------------------------------------ scene policy
    def _controller_torques(self, x, stance_is_leg1: bool) -> np.ndarray:
        """The scene's feedback controller's torques (k,) [N m] at the view's state ``x``
        (the rigid role state, or the contact view's floating state with leg1 in stance or
        not), saturated at its ``max_torque_n_m``."""
        x = np.asarray(x, dtype=float)
        if self.view == "rigid":
            return np.real(np.asarray(self.controller.torques(x), dtype=float))
        return np.asarray(self._contact_controller.torques(x, 0 if stance_is_leg1 else 1),
                          dtype=float)

    def scene_policy(self):
        """The scene's feedback controller as a policy: a callable ``observation ->
        action``.

        The controller is the computed torque of the scene's virtual constraints
        (:class:`walkerlab.models.virtual_constraints.VirtualConstraintController`:
        ``u = (L_g L_f h)^-1 (-L_f^2 h - kp y - kd y')``, Westervelt, Grizzle & Koditschek
        2003, Sec. IV), at the observed state: the rigid view's role state, or the contact
        view's floating state read at its stance leg (``stance_is_leg1``) as the rigid
        walker's role state (:class:`walkerlab.models.contact.virtual_constraints.
        VirtualConstraintJointTorques`).  The environment holds an action over its control
        period, so the policy's torque is sampled at the period's start and held (a
        zero-order hold); ``policy="scene"`` adds the same held torque to every action
        inside the environment.

        Returns
        -------
        callable
            ``obs (2n + 3,) or (N + 3,) -> action (k,)`` float32, in the action space
            (fractions of :attr:`tau_max`, or N m with ``normalize_action=False``), clipped
            to its bounds.

        Raises
        ------
        ValueError
            The scene has no feedback controller (no ``walker.actuation.
            virtual_constraints``), one line.
        """
        if self.controller is None:
            raise ValueError("scene_policy: the scene has no feedback controller "
                             "(walker.actuation.virtual_constraints); its torque laws act "
                             "in the walker under any action")
        m = len(self.state_names)

        def policy(obs):
            obs = np.asarray(obs, dtype=float)
            u = np.clip(self._controller_torques(obs[:m], obs[m] > 0.5), -self.tau_max,
                        self.tau_max)
            return (u / self.tau_max if self.normalize_action else u).astype(np.float32)
        return policy

    # ------------------------------------------------------------------ gymnasium API
    def _obs(self) -> np.ndarray:
        s = self.sim
        if self.view == "rigid":
            leg1, k = float(s.leg == "leg1"), float(s.k)
        else:
            leg1, k = float(s.stance == 0), 0.0
        x = s.x
        m = x.size
        obs = np.empty(m + 3)
        obs[:m] = x
        obs[m:] = (leg1, k, s.t - s.t_step)
        low, high = self.observation_space.low, self.observation_space.high
        for v, a, b in zip(obs.tolist(), low.tolist(), high.tolist()):
            if not a <= v <= b:  # (NaN too) clipped to the bounds
                return np.clip(obs, low, high)
        return obs

    def _info(self, strikes: list[float]) -> dict:
        s = self.sim
        self._hip_x = s.hip_x()  # the next period's start (its reward's origin)
        stance = (s.leg if self.view == "rigid" else f"leg{s.stance + 1}")
        info = {"time_s": float(s.t), "heel_strike": bool(strikes),
                "heel_strike_time_s": float(strikes[-1]) if strikes else None,
                "heel_strike_times_s": list(map(float, strikes)), "steps": int(s.steps),
                "stance_leg": stance, "hip_x_m": self._hip_x, "termination": s.ended,
                "solver_message": str(getattr(s, "failure", "")),
                "terrain_seed": int(self.terrain_seed)}
        for k, v in s.ledger.items():
            info[_LEDGER_KEYS.get(k) or _ledger_key(k)] = float(v)
        return info

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Start an episode (module docstring); returns ``(observation, info)``.

        Raises
        ------
        walkerlab.config.SceneError
            ``options["state"]`` no state of the walker (one line naming the states).
        ValueError
            ``options`` not a dict, or an unknown option (one line).
        """
        if options is not None and not isinstance(options, Mapping):
            raise ValueError(f"reset: options must be a dict such as {{'state': x}} or None, "
                             f"got a {type(options).__name__}")
        super().reset(seed=seed)
        options = dict(options or {})
        state = options.pop("state", None)
        if options:
            raise ValueError(f"reset: unknown options {sorted(options)}; give 'state'")
        self.terrain_seed = int(self.np_random.integers(2**31 - 1))
        noise = (self.np_random.uniform(-self.start_noise, self.start_noise)
                 if self.start_noise > 0 else None)
        if self.view == "contact":
            self.sim.set_terrain(self.terrain_roughness_m, self.terrain_seed)
        start = self.gait.x if self.view == "rigid" else self.sim.x_start
        if state is not None and any(isinstance(v, str | bytes) for v in
                                     np.ravel(np.asarray(state, dtype=object))):
            from walkerlab.config import SceneError

            raise SceneError(f"options['state']: give {len(self.state_names)} numbers "
                             f"({', '.join(self.state_names)}), not text")
        try:
            x0 = np.array(start if state is None else state, float)
        except (TypeError, ValueError):  # not numbers: the checks below say so
            x0 = state
        if noise is not None and isinstance(x0, np.ndarray) and x0.ndim == 1:
            h = x0.size // 2  # before the check: the noisy start is checked
            x0[h:] *= 1.0 + self.np_random.uniform(-self.start_noise, self.start_noise, h)
        if self.view == "rigid":
            seen = self._checked_start
            if not (seen is not None and isinstance(x0, np.ndarray) and x0.dtype == seen.dtype
                    and x0.shape == seen.shape and x0.tobytes() == seen.tobytes()):
                x0 = self.rigid.check_state(x0, "options['state']" if state is not None
                                            else "the start with start_noise")
                self._checked_start = x0  # (the same numbers pass again: not checked twice)
        elif not (isinstance(x0, np.ndarray) and x0.shape == self.sim.x_start.shape
                  and np.all(np.isfinite(x0))):
            from walkerlab.config import SceneError

            raise SceneError(f"options['state']: give {len(self.state_names)} finite "
                             f"numbers ({', '.join(self.state_names)})")
        self.sim.reset(x0)
        self._elapsed = 0
        self._has_reset = True
        return self._obs(), self._info([])

    def _action(self, action) -> np.ndarray:
        """``action`` as finite float64 torques (k,) (not yet scaled or clipped).

        Raises
        ------
        InvalidAction
            None, not real numbers (complex, text, objects), not of shape (k,), or NaN/inf
            entries (one line naming the action space).
        """
        k = self.tau_max.size
        if (type(action) is np.ndarray and action.shape == (k,) and action.dtype.kind == "f"
                and (all(map(math.isfinite, action.tolist())) if action.dtype.char in "fd"
                     else np.isfinite(action).all())):
            return action.astype(np.float64)  # the common case: no message built
        return checked_action(action, k, self.joints, self.action_space)

    def step(self, action):
        """Hold ``action`` (k,) (fractions of :attr:`tau_max`, or N m), clipped to the
        bounds, for one control period; returns ``(observation, reward, terminated,
        truncated, info)``.

        Raises
        ------
        gymnasium.error.ResetNeeded
            Before the first :meth:`reset`.
        InvalidAction
            Not ``k`` finite real numbers of shape ``(k,)`` (one line).
        """
        u, before = self.begin_period(action)
        return self.end_period(u, self.sim.advance(u, self._elapsed * self.dt), before)

    def begin_period(self, action) -> tuple[np.ndarray, tuple]:
        """:meth:`step`'s first half: the held torques ``u`` (k,) [N m] of ``action`` (and
        the scene policy's), the period counted, and what the reward needs of the period's
        start; the walker is then advanced to ``period_end_s`` (by :meth:`step`, or with
        others by the native vector environment) and :meth:`end_period` finishes.

        Raises
        ------
        gymnasium.error.ResetNeeded
            Before the first :meth:`reset`.
        InvalidAction
            Not ``k`` finite real numbers of shape ``(k,)`` (one line).
        """
        if not self._has_reset:
            raise gym.error.ResetNeeded("Cannot call env.step() before calling env.reset()")
        a = self._action(action)
        if self.normalize_action:
            a = a * self.tau_max
        s = self.sim
        if self.policy == "scene":  # the controller's torque at the period's start, held
            leg1 = (s.leg == "leg1") if self.view == "rigid" else (s.stance == 0)
            a = a + self._controller_torques(s.x, leg1)
        for v, t in zip(a.tolist(), self.tau_max.tolist()):
            if not -t <= v <= t:  # (NaN too) clipped to the bounds
                a = np.clip(a, -self.tau_max, self.tau_max)
                break
        u = a  # (a new array: the action is copied above)
        # the hip at the period's start (the last info's) and the positive work so far
        before = (self._hip_x, s.ledger["action_work_positive"])
        self._elapsed += 1
        return u, before

    @property
    def period_end_s(self) -> float:
        """The end of the present control period [s] (after :meth:`begin_period`)."""
        return self._elapsed * self.dt

    def end_period(self, u: np.ndarray, strikes: list[float], before: tuple):
        """:meth:`step`'s second half, once the walker is advanced with ``u`` held and met
        the heel strikes ``strikes`` [s]: ``(observation, reward, terminated, truncated,
        info)``."""
        s = self.sim
        x_before, w_before = before
        info = self._info(strikes)
        terminated = bool(s.ended)
        truncated = (not terminated and self.max_episode_steps is not None
                     and self._elapsed >= self.max_episode_steps)
        if self.reward_fn is not None:
            reward = float(self.reward_fn(self, info))
        else:
            fw, healthy, cw, ww = self.weights
            reward = (fw * (info["hip_x_m"] - x_before) / self.dt
                      + (0.0 if terminated else healthy)
                      - cw * float(np.add.reduce((u / self.tau_max) ** 2))
                      - ww * (s.ledger["action_work_positive"] - w_before) / self.dt)
        return self._obs(), float(reward), terminated, truncated, info

    def render(self):
        """The walker drawn (matplotlib, Agg) as an RGB array (H, W, 3) uint8, with
        ``render_mode="rgb_array"``; None otherwise.

        Raises
        ------
        gymnasium.error.ResetNeeded
            Before the first :meth:`reset`.
        """
        if not self._has_reset:
            raise gym.error.ResetNeeded("Cannot call env.render() before calling env.reset()")
        if self.render_mode != "rgb_array":
            return None
        from .render import draw

        return draw(self.sim.points(), float(self.scene.slope.phi_rad),
                    float(self.rigid.model.params["leg_length_m"]), self.sim.t)
