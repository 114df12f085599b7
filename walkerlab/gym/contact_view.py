"""The contact view of the Gymnasium environment: the scene's floating walker with compliant
feet (:class:`walkerlab.models.contact.model.ContactWalker`, its IMPACT contact law and
terrain) advanced one control period at a time.

The walker, its terrain's patches and its start are those of ``walkerlab contact-sim``
(:func:`walkerlab.analysis.contact.sim.scene_start`: the stance foot at its static
penetration, the rigid gait's rates times ``contact_sim.initial_rate_scale``; with
``contact_sim.start: periodic_gait`` the contact model's own periodic gait at its mid-stance
section, on patches spaced by its step length, found once per scene and process), the
patches laid out for the episode's longest walk.  Each control period is the contact view's one
powered run (:class:`walkerlab.integrate.contact_powered.ActuationHook`, advanced to the
period's end: :meth:`~walkerlab.integrate.contact_powered.ActuationHook.run_until`) on its
compiled segments (:class:`walkerlab.integrate.compiled_segments.CompiledSegments`, CyRK's
BDF at the scene's ``contact_solver`` tolerances, whatever its method): the action's
torques are a generalised force held in the compiled right-hand side's data, beside the
scene's own actuation (its torque laws, its push-off pulse, a flat foot's ankle push-off),
exactly as ``walkerlab contact-sim`` runs them.  Its events are that run's: the swing foot's
touchdown on ground at least ``min_step_m`` ahead of the stance foot (the heel strike: the
stance leg switches there) and the hip's fall below ``contact_sim.fall_hip_height_m``.  The
action's torques act ``+tau`` on the second link of their joint and ``-tau`` on the first,
on the floating coordinates (absolute link angles, the same convention as the rigid
view's); their positive and negative work, the scene's torques' and the push-off's are the
run's work integrals.

Footholds (``terrain.kind: footholds`` on checkerboard lanes): the patches are laid at the
rigid gait's footfalls (of several heights: the period-n gait's, as ``contact-sim`` lays
them, :func:`walkerlab.analysis.contact.footfalls.rigid_step_lengths`) and, once the episode
has made a period of steps and one more, at its own footfalls as it goes (each heel strike:
:func:`walkerlab.analysis.contact.footfalls.own_footfall_lanes` of the heel strikes so far,
the footfalls ahead advancing by the last step of their step of the cycle), as
``contact-sim`` lays them again where its walker's footfalls drift off the rigid ones.

Seeded terrain: with ``terrain_roughness_m > 0`` each patch is raised or lowered by a height
drawn uniformly from ``[-r, r]`` by the episode's terrain seed (rough ground as geometry,
:attr:`~walkerlab.models.contact.model.ContactWalker.heights1`), all but the starting stance
foot's patch (the walker starts on the scene's own ground, not inside a raised patch).  The
patches are laid out for :data:`LAYOUT_STEPS` steps at a time and laid out again for twice
as many as the walk nears their end (memory and each contact evaluation's patch search stay
proportional to the walk so far, not to ``max_episode_steps``); a patch's height depends on
the seed and its place only, so the ground a walker meets does not depend on when it was laid.

The fall event also ends the episode as ``launch``: the hip more than
:data:`LAUNCH_HIP_FACTOR` leg lengths above the ground line (plus the highest ground laid
out).  No walker with a foot on the ground gets there; a foot that meets a raised patch's
side below its top does (the contact law measures the penetration below the patch's top, so
the foot is pushed out at once as from that depth: the walker is thrown into the air).

A control period whose compiled solver stops (a force jump it cannot step over, where a foot
meets a patch's side below its top) ends the episode as ``solver_failure`` (or ``trip``,
when the foot is found at a patch's side), with the reason in :attr:`ContactView.failure`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["CONTACT_LEDGER_TERMS", "ContactView"]

#: the contact view's ledger terms [J] (the episode's sums)
CONTACT_LEDGER_TERMS = ("action_work_positive", "action_work_negative", "scene_torque_work",
                        "push_off_work")
#: a touchdown is a heel strike only this far [m] ahead of the stance foot (as the contact
#: view's powered run, ``ContactActuators.min_step_m``)
MIN_STEP_M = 0.05
#: the hip this many leg lengths above the ground line (plus the highest ground laid out)
#: ends the episode as ``launch`` (a walking hip is at most one leg length above its foot)
LAUNCH_HIP_FACTOR = 1.5
#: steps the patches are laid out for at a time (the layout doubles as the walk nears its end)
LAYOUT_STEPS = 32
#: the run's works [J] that make each ledger term (the terms' names: the ledger's)
_LEDGER = {"action_work_positive": ("action_positive",),
           "action_work_negative": ("action_negative",),
           "scene_torque_work": ("hip_torque_positive", "hip_torque_negative",
                                 "ankle_torque_positive", "ankle_torque_negative"),
           "push_off_work": ("push_off",)}


#: the contact model's own periodic gait of each scene with ``contact_sim.start:
#: periodic_gait``, found once per process (key: the scene's JSON)
_PERIODIC: dict = {}


def _periodic_gait(setup, probe, x_gait):
    """The contact walker's own periodic gait (:func:`walkerlab.analysis.contact.periodic.
    find_contact_periodic_gait` from the rigid gait ``x_gait``, within ``contact_sim.
    periodic_max_step_maps``), as ``contact-sim`` starts from it
    (:func:`walkerlab.analysis.contact.periodic.simulate_from_periodic_gait`): the run
    starts at its mid-stance section, on patches spaced by its step length.

    Raises
    ------
    walkerlab.analysis.contact.periodic.PeriodicGaitError
        No periodic gait found (one line).
    """
    from walkerlab.analysis.contact.periodic import (
        converged_gait,
        find_contact_periodic_gait,
        search_bounds,
    )

    key = setup.scene.model_dump_json() if setup.scene is not None else None
    if key is None or key not in _PERIODIC:
        gait = converged_gait(find_contact_periodic_gait(
            probe, x_gait, **search_bounds(setup.sim)))
        if key is None:
            return gait
        _PERIODIC[key] = gait
    return _PERIODIC[key]


def _link_coordinate(link: str, leg: dict, names: tuple) -> int:
    """Index of a rigid role link (``stance``, ``swing_thigh``, ``torso``, a 3D walker's
    ``stance_roll``, ``pelvis_roll``, ...) among the floating coordinates ``names`` with
    ``leg`` = ``{"stance": legX, "swing": legY}``: the link's ``<name>_angle``, else (a 3D
    walker's rolls: ``legX_roll``, ``pelvis_roll``) ``<name>``."""
    role, _, part = link.partition("_")
    if role in leg:
        name = f"{leg[role]}_{part}" if part else leg[role]
    else:
        name = link
    for n in (f"{name}_angle", name):
        if n in names:
            return names.index(n)
    raise ValueError(f"walkerlab.gym: the contact view has no coordinate {name}_angle for "
                     f"the action's link {link} (its coordinates: {', '.join(names)})")


class ContactView:
    """The scene's contact walker stepped by control periods.

    Parameters
    ----------
    setup : walkerlab.models.contact.scene.ContactSetup
    links : list of (str, str)
        The action's joints as their (first, second) rigid links
        (:attr:`walkerlab.gym.action.ActionTorques.links`).
    x_gait : ndarray (2n,)
        The rigid gait's post-impact state (the start).
    n_steps : int
        Steps the episode may take (the patches are first laid out for at most
        :data:`LAYOUT_STEPS` of them, then for more as the walk goes).

    Raises
    ------
    ValueError
        A scene actuation the view does not carry (an ankle push-off), or an action link
        with no floating coordinate (a torso that bisects the legs), one line.
    """

    def __init__(self, setup, links, x_gait, n_steps: int, horizon_s: float = 60.0):
        self._setup, self._x_gait = setup, np.asarray(x_gait, float)
        self._first_layout = max(1, min(int(n_steps), LAYOUT_STEPS))
        self._roughness, self._seed = 0.0, 0
        self._track = None  # footholds: the episode's footfalls (:class:`_Footfalls`)
        self._layouts = {}  # steps laid out for -> the scene's walker, start, limits, step
        self._built = None  # (walker, its run's walker, its compiled segments): _start's
        self.x_start, self.limits, self.step_length = self._lay_out(self._first_layout)
        names = tuple(self.walker.coordinate_names())
        self.nq = len(names)
        self.index = []  # per stance leg (0: leg1, 1: leg2): (first, second) coordinates
        for stance in (0, 1):
            leg = {"stance": f"leg{stance + 1}", "swing": f"leg{2 - stance}"}
            self.index.append([(_link_coordinate(a, leg, names),
                                _link_coordinate(b, leg, names)) for a, b in links])
        self._last_held = (None, None)  # the last torques (k,) and their held force
        # the coordinate hip_x's index (None: the hip read from the walker's points)
        self._hip_x = names.index("hip_x") if "hip_x" in names else None
        s = setup.solver
        #: the run's integrator: the compiled one at the scene's tolerances
        self.solver = s.model_copy(update={"method": "cyrk_bdf"})
        self.grid = np.arange(0.0, float(horizon_s), 1.0 / self.limits.sample_rate_hz)
        self.state_names = list(self.walker.state_names())
        self.hook = None
    def _lay_out(self, n_steps: int):
        """Patches for ``n_steps`` steps (:func:`walkerlab.analysis.contact.sim.scene_start`),
        the episode's roughness on them; returns the scene's start, limits, step length."""
        from walkerlab.analysis.contact.sim import scene_start  # light

        if n_steps not in self._layouts:  # the scene's patches for n_steps: the same each
            walker, x0, limits, step_length = scene_start(  # episode, laid out once
                self._setup, self._x_gait, n_steps // 2 + 1)
            if self._setup.sim.start == "periodic_gait":  # contact-sim's start: the contact
                gait = _periodic_gait(self._setup, walker, self._x_gait)  # model's own
                walker, step_length = self._setup.build(  # gait, its patches at its steps
                    self._x_gait, 2 * (n_steps // 2 + 1), step_length_m=gait.step_length_m)
                x0 = np.asarray(gait.full_state, float)
            self._layouts[n_steps] = walker, x0, limits, step_length
        walker, x0, limits, step_length = self._layouts[n_steps]
        self._laid = n_steps
        self._at_rigid = walker  # the patches at the rigid gait's footfalls
        self._use(self._own_footfalls(walker))
        return x0, limits, step_length

    def _own_footfalls(self, walker):
        """Footholds: ``walker`` with its patches at the episode's own footfalls so far, as
        ``contact-sim`` lays them (:func:`walkerlab.analysis.contact.footfalls.
        own_footfall_lanes`; ``walker`` itself until enough heel strikes are known)."""
        from walkerlab.analysis.contact.footfalls import own_footfall_lanes

        if self._track is None:
            return walker
        moved = own_footfall_lanes(walker, self._track, self._track.period)
        return walker if moved is None else moved

    def _use(self, walker) -> None:
        """Lay the episode's ground on ``walker``'s patches (its roughness added)."""
        self._lanes = (walker.lane1.copy(), walker.lane2.copy())
        # the scene's own patch heights (stairs, footholds; None on the slope): roughness adds
        self._heights = (walker.heights1, walker.heights2)
        self._scene_walker = walker
        self._roughen()
        w = self.walker
        ground = [0.0] + [float(np.max(h)) for h in (w.heights1, w.heights2)
                          if h is not None and np.size(h)]
        if w.ground_line is not None:
            ground.append(float(np.max(w.ground_line[:, 0] * np.sin(w.phi)
                                       + w.ground_line[:, 1] * np.cos(w.phi))))
        self._launch_height = LAUNCH_HIP_FACTOR * float(w.L) + max(ground)

    def _roughen(self) -> None:
        w, base, r = self._scene_walker, self._heights, self._roughness
        if r <= 0.0:
            self.walker = w
            return
        h = []
        for k, (lane, b) in enumerate(zip(self._lanes, base)):
            d = np.random.default_rng([self._seed, k]).uniform(-r, r, lane.size)
            if k == 1:
                d[0] = 0.0  # leg2's first patch: the starting stance foot's ground
            h.append(d if b is None else np.asarray(b, float) + d)
        self.walker = dataclasses.replace(w, heights1=h[0], heights2=h[1])

    def set_terrain(self, roughness_m: float, seed: int) -> None:
        """The scene's patch heights (its stairs' or footholds'; none on the slope) plus
        heights drawn from ``[-roughness_m, roughness_m]`` [m] by ``seed`` (0: the scene's
        ground as it is), the starting stance foot's patch (leg2's first) left as the scene
        has it; the patches laid out afresh for :data:`LAYOUT_STEPS` steps."""
        self._roughness, self._seed = float(roughness_m), int(seed)
        self._track = None
        self._lay_out(self._first_layout)

    def reset(self, x0: np.ndarray | None = None) -> None:
        """Start at the contact state ``x0`` (N,) (default: the scene's start), leg2 in
        stance, at t = 0."""
        self.ended = ""
        self.failure = ""
        self.ledger = dict.fromkeys(CONTACT_LEDGER_TERMS, 0.0)
        self.steps = 0
        if self._track is not None:  # the last episode's footfalls: the rigid gait's again
            self._track = None
            self._use(self._at_rigid)
        self._start(np.array(self.x_start if x0 is None else x0, dtype=float), 0.0)
        if self._setup.patches_follow_feet:
            self._track = _Footfalls(self._setup, self.walker, self.x)

    def _start(self, x, t: float, keep=None) -> None:
        """The run's hook on the present walker from ``(t, x)``; ``keep``: the stance leg,
        step start, ankle push-off and work integrals carried over (a new layout)."""
        from walkerlab.integrate.contact_powered import ActuationHook  # light

        if self._built is not None and self._built[0] is self.walker:  # the walker of
            _, w, segments = self._built  # the last run (a new episode on the same
        else:  # ground): its run's walker and compiled segments again
            w, segments = self.walker, None
            if w.actuators is None:  # the action alone: actuators with no law of the scene's
                w = dataclasses.replace(w, actuators=self._setup.held_actuators())
        self.hook = ActuationHook(w, self.solver, self.limits, np.inf, self.grid,
                                  held_force=True, launch_height_m=self._launch_height)
        self.hook.start(x, t, segments)
        self._built = (self.walker, w, self.hook.segments)
        if keep is not None:
            h = self.hook
            h.stance, h.t_origin, h.ankle_on, h.step_s = keep[:4]
            h.y[2 * self.nq:] = keep[4]
        works = list(self.hook.work_names)
        #: each ledger term's work integrals (their indices after the walker's state)
        self._ledger_index = [(term, [works.index(k) for k in names if k in works])
                              for term, names in _LEDGER.items()]

    @property
    def x(self) -> np.ndarray:
        """The walker's state (N,)."""
        return self.hook.y[:2 * self.nq].copy()

    @property
    def t(self) -> float:
        """The time [s]."""
        return float(self.hook.t)

    @property
    def t_step(self) -> float:
        """When the present step began (the last heel strike, or 0) [s]."""
        return float(self.hook.t_origin)

    @property
    def stance(self) -> int:
        """The stance leg (0: leg1, 1: leg2)."""
        return int(self.hook.stance)

    def hip_x(self) -> float:
        """World position of the hip along x (horizontal, downhill) [m]: the floating
        coordinate ``hip_x`` (the generated ``points``' hip is that coordinate plus 0; all
        of them were evaluated for it each period)."""
        if self._hip_x is not None:
            return float(self.hook.y[self._hip_x]) + 0.0
        return float(self.walker.points(self.x)["hip"][0, 0])

    def points(self) -> dict:
        """World positions (2,) [m] of the walker's named points."""
        return {k: np.asarray(v, float)[:, 0] for k, v in self.walker.points(self.x).items()}

    # ------------------------------------------------------------------ stepping
    def _held(self, u) -> tuple[np.ndarray, np.ndarray]:
        """The action's generalised force (nq,) with leg1, then leg2 in stance (the torques
        ``u`` (k,) summed in floats, joint by joint)."""
        u = [float(tau) for tau in u]
        if self._last_held[0] == u:  # the same torques as the last period's (a zero action)
            return self._last_held[1]
        out = []
        for stance in (0, 1):
            Q = [0.0] * self.nq
            for tau, (a, b) in zip(u, self.index[stance]):
                Q[b] += tau
                Q[a] -= tau
            out.append(np.array(Q))
        self._last_held = (u, tuple(out))
        return self._last_held[1]

    def advance(self, u: np.ndarray, t_end: float) -> list[float]:
        """Integrate to ``t_end`` [s] with the action torques ``u`` (k,) [N m] held.

        Returns
        -------
        list of float
            The heel-strike (touchdown) times inside the period [s]; :attr:`ended` is set
            when the episode ended inside it (``fall``, ``launch``, ``trip``,
            ``solver_failure``).
        """
        from walkerlab.integrate.ends import RunEnd

        h, n = self.hook, 2 * self.nq
        h.segments.pdata.held = self._held(np.asarray(u, float))
        before = h.y[n:].tolist()
        strikes = h.run_until(t_end)
        gained = [b - a for a, b in zip(before, h.y[n:].tolist())]
        for term, index in self._ledger_index:
            self.ledger[term] += float(sum(gained[k] for k in index))
        self.steps += len(strikes)
        if h.t < t_end - 1e-12 or h.term is not RunEnd.T_FINAL:
            self._ended(h)
        follow = bool(strikes) and self._track is not None and self._track.add(
            self.walker, h, strikes)
        h.forget()
        more = self.steps + 4 >= self._laid
        if not self.ended and (more or follow):  # lay out more patches, or move them
            keep = (h.stance, h.t_origin, h.ankle_on, h.step_s, h.y[n:].copy())
            x, t = self.x, self.t
            if more:
                self._lay_out(2 * self._laid)
            else:
                self._use(self._own_footfalls(self._at_rigid))
            self._start(x, t, keep)
        return strikes

    def _ended(self, h) -> None:
        """The episode's end from the run's (a fall event above the ground: ``launch``)."""
        from walkerlab.integrate.ends import RunEnd

        if h.term is RunEnd.FALL:
            high = float(self.walker.hip_height(self.x)[0]) > 0.5 * self._launch_height
            self.ended = "launch" if high else "fall"
        elif h.term is RunEnd.TRIP:
            self.ended, self.failure = "trip", str(h.msg)
        else:
            self.ended, self.failure = "solver_failure", str(h.msg)


class _Footfalls:
    """The episode's heel strikes on footholds and the feet's along-slope places at them
    [s, m], read as :func:`walkerlab.analysis.contact.footfalls.own_footfall_lanes` reads a
    ``contact-sim`` run (its samples' ``t``, ``feet[leg].s``, heel-strike times and legs):
    each place interpolated between the run's samples at the heel strike, as there."""

    def __init__(self, setup, walker, x0: np.ndarray, t0: float = 0.0):
        from walkerlab.models.contact.terrain import ground_drops

        self.period = len(ground_drops(setup.terrain))
        q = walker.foot_quantities(np.asarray(x0, float)[None])
        self._t = [float(t0)]
        self._s = {leg: [float(q[leg]["s"][0])] for leg in ("leg1", "leg2")}
        self.heel_strike_times: list[float] = []
        self.heel_strike_legs: list[str] = []

    @property
    def t(self) -> np.ndarray:
        return np.asarray(self._t)

    @property
    def feet(self) -> dict:
        return {leg: _Trace(np.asarray(s)) for leg, s in self._s.items()}

    def add(self, walker, hook, strikes) -> bool:
        """Record ``strikes`` [s] from the run's kept samples (``hook.ts``, ``hook.Ys``);
        True when the patches are to follow the feet (enough heel strikes known)."""
        T = np.concatenate(hook.ts)
        q = walker.foot_quantities(np.vstack(hook.Ys)[:, :2 * walker.nq])
        for th in strikes:
            self._t.append(float(th))
            for leg in self._s:
                self._s[leg].append(float(np.interp(th, T, q[leg]["s"])))
            # the legs alternate, leg2 in stance first
            self.heel_strike_legs.append("leg1" if len(self.heel_strike_legs) % 2 == 0
                                         else "leg2")
            self.heel_strike_times.append(float(th))
        return len(self.heel_strike_legs) >= self.period + 1


@dataclasses.dataclass
class _Trace:
    s: np.ndarray
