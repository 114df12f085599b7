"""A walker in memory, both views: the rigid walker's Poincaré map, exact Jacobian, Floquet
multipliers, fixed point and simulation (:class:`Walker`), and the compliant-contact
walker's walks and own periodic gait (:class:`ContactWalker`), with no artifact written or
read (only the generated-code cache is used).

The artifact functions of :mod:`walkerlab.api` stay the front door for stored results; this
is the object for loops and notebooks, as MuJoCo's ``MjModel``/``MjData`` or Pinocchio's
``Model``/``Data``::

    import walkerlab as wl
    w = wl.Walker.from_scene("configs/paper.yaml")
    gait = w.fixed_point()              # the very numbers of `walkerlab fixedpoint`
    gait.state["stance_angle"], gait.step_period, gait.multipliers
    heavier = w.with_changes({"walker.hip_mass_kg": 12.0})
    cw = w.contact()                    # the contact view (wl.ContactWalker)
    walk = cw.simulate(strides=2)       # the very numbers of `walkerlab contact-sim`
    walk.step_periods, walk.normal_force["leg2"], cw.periodic_gait().multipliers

Each object builds its model and integrator once, from the scene; :meth:`Walker.
with_changes` makes a new walker.

The walker is the scene's: its ground (a slope, per-step slopes, stairs, footholds of one
or several heights, a height profile, a rough ground drawn from ``simulate.terrain_seed``),
its actuation and its gait search's start (``fixedpoint.initial_guess``, or a known gait
carried here from ``fixedpoint.from``) are those of the commands, through the same library
functions, so every number equals ``walkerlab fixedpoint``/``simulate``/``contact-sim``'s
for the same scene (``tests/test_api_scenes.py`` walks every shipped scene both ways).  A
scene feature a view cannot carry is refused in one line naming the key, as by the command
(a profile walked by an actuated walker: ``terrain.kind: profile: ...``).

States are role-ordered arrays of :meth:`Walker.state_names` (angles [rad], rates [rad/s];
in a ``units: nondimensional`` scene every quantity is in the walker's own units, time in
√(l/g)).  Nothing here knows how many states a walker has.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Any

from walkerlab.api.checks import (
    STEP_EVALUATIONS,
    bounded_steps,
    check_target,
    short,
    simulate_options,
)
from walkerlab.api.scenes import as_scene, scene_plant, with_changes
from walkerlab.api.walks import ContactWalk, Gait, Step, Walk, recorded_contact_walk, sampled_walk
from walkerlab.integrate.solver import Solver
from walkerlab.rigid_walker import SceneWalker

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from walkerlab.config import Scene

__all__ = ["STEP_EVALUATIONS", "ContactWalk", "ContactWalker", "Step", "Walk", "Walker",
           "check_target"]


class Walker(SceneWalker):
    """The rigid hybrid walker of a scene, in memory.

    Build it with :meth:`from_scene`; it holds the validated scene, the generated model
    (:func:`walkerlab.models.registry.build_walker`) and the scene's integrator, built once:
    every method uses them (a changed scene is a new walker, :meth:`with_changes`).
    :meth:`contact` is the same walker's contact view.

    Parameters
    ----------
    scene : walkerlab.config.Scene
        A validated scene (its ``walker``, ``slope``, ``ideal``, ``terrain``, ``solver``,
        ``fixedpoint`` and ``simulate`` sections are used, as the ``fixedpoint`` and
        ``simulate`` stages use them).
    step_evaluations : int
        Right-hand-side evaluations each walking step of :meth:`step`, :meth:`jacobian`,
        :meth:`floquet` and :meth:`simulate` may take [-] (work, not time: the same step
        ends the same way on any machine, busy or not); past it the map stops with one line
        (:class:`~walkerlab.analysis.gait.poincare.StepFailed`, ``work_limit``).  The
        simulated time of a step is bounded apart, by ``fixedpoint.max_step_time_s``.
    plant : walkerlab.walker.plant.Plant, optional
        A plant the caller holds (:func:`~walkerlab.api.scenes.scene_plant`).

    Attributes
    ----------
    scene : walkerlab.config.Scene
    model : walkerlab.models.hybrid.HybridWalker
        The generated rigid hybrid model.
    solver : walkerlab.integrate.solver.Solver
        The integrator of the scene's ``solver`` section.
    max_step_time : float
        Longest simulated time of one step of the map [s] (``fixedpoint.max_step_time_s``).
    walk_step_time : float
        Longest simulated time of one step of :meth:`simulate` [s]
        (``simulate.max_step_time_s``, as the ``simulate`` stage; a scene without a
        ``simulate`` section: :attr:`max_step_time`).

    Raises
    ------
    walkerlab.config.SceneError
        ``step_evaluations`` not a positive number.
    ValueError
        A walker or ground the rigid model does not carry (one line naming the key, as
        :func:`walkerlab.models.registry.build_walker`: footholds of several heights for
        an actuated walker, printed equations on stairs, ...).
    """

    def __init__(self, scene: Scene, step_evaluations: int = STEP_EVALUATIONS, plant=None):
        super().__init__(scene_plant(scene, plant), step_evaluations)  # the front describes

    @classmethod
    def from_scene(cls, scene: Scene | str | Path | dict[str, Any],
                   step_evaluations: int = STEP_EVALUATIONS) -> Walker:
        """The walker of a scene: a YAML path, a mapping with the scene's sections, or a
        loaded scene (``step_evaluations`` as in :class:`Walker`).

        Raises
        ------
        walkerlab.config.SceneError
            The file is missing or the scene does not validate (one line per field), or a
            bad ``step_evaluations``.
        """
        return cls(as_scene(scene), step_evaluations)

    def with_changes(self, changes: dict[str, Any]) -> Walker:
        """A new walker with scene fields set by dotted path
        (``{"walker.hip_mass_kg": 12, "slope.angle_deg": 2}``); this one is unchanged.

        Raises
        ------
        walkerlab.config.SceneError
            An unknown field (with the closest name) or a value the field does not accept.
        """
        return Walker(with_changes(self.scene, changes), self.step_evaluations, self.plant)

    def contact(self) -> ContactWalker:
        """The contact (compliant-foot) view of this walker: a :class:`ContactWalker` on the
        same scene, whose runs start from this walker's gait.

        Raises
        ------
        walkerlab.models.contact.scene.ContactSceneError
            No ``contact`` section, or a walker the contact view does not carry (one line).
        """
        return ContactWalker(self.scene, self)

    def _map(self, x, jacobian: bool = False, steps: list | None = None):
        from walkerlab.analysis.gait.poincare import poincare_map  # light

        x = self.check_state(x)
        with bounded_steps(self.step_evaluations, self.max_step_time):
            return poincare_map(self.model, x, self.solver, self.max_step_time,
                                jacobian=jacobian, steps=steps)

    def step(self, x) -> Step:
        """One Poincaré map step ``x -> P(x)`` (paper Eq. 10; a stride when legs differ).

        Parameters
        ----------
        x : array_like, shape (2n,)
            State just after heel strike (role order of :meth:`state_names`) [rad, rad/s].

        Returns
        -------
        Step
            ``x_next`` (2n,) the state just after the next heel strike, ``period`` [s] the
            map's duration, ``events`` the phases ``(phase, t_start, t_end, guard)``.

        Raises
        ------
        walkerlab.config.SceneError
            ``x`` not a finite state of the walker's size, or no walking state
            (:meth:`check_state`; one line).
        walkerlab.analysis.gait.poincare.StepFailed
            The step fell, the solver failed, the step ran past ``max_step_time_s`` or the
            step past ``step_evaluations`` right-hand-side evaluations (one line: how and when).
        """
        segs: list = []
        x_next, period, _ = self._map(x, steps=segs)
        events = [entry for seg in segs for entry in seg.phase_log]
        return Step(x_next, float(period), events)

    def jacobian(self, x) -> np.ndarray:
        """Exact Jacobian ``DP`` (2n, 2n) of the Poincaré map at ``x``: variational equations
        with the saltation matrix at every guard (Aizerman & Gantmacher 1958).

        Raises
        ------
        walkerlab.config.SceneError, walkerlab.analysis.gait.poincare.StepFailed
            As :meth:`step`.
        """
        return self._map(x, jacobian=True)[2]

    def floquet(self, x) -> np.ndarray:
        """Floquet multipliers (2n,) at ``x`` (eigenvalues of :meth:`jacobian`), by
        decreasing modulus; meaningful at a fixed point.

        Raises
        ------
        walkerlab.config.SceneError, walkerlab.analysis.gait.poincare.StepFailed
            As :meth:`step`.
        """
        import numpy as np

        from walkerlab.numerics import sort_multipliers  # light

        return sort_multipliers(np.linalg.eigvals(self.jacobian(x)))

    def find_gait_for(self, vary: str, **target: float) -> tuple[Walker, Gait]:
        """The walker whose period-1 gait meets a target, one field freed (Kuo's
        ``findgait(target=speed, varying=P)``): ``w.find_gait_for(
        "walker.actuation.push_off.impulse_n_s", speed_m_per_s=0.45)``.

        Parameters
        ----------
        vary : str
            The dotted numeric scene field to solve for (started from its own value).
        **target : float
            Exactly one of ``speed_m_per_s``, ``step_length_m``, ``step_period_s``.

        Returns
        -------
        walker : Walker
            This walker with ``vary`` set to the value found.
        gait : Gait
            Its gait (as :meth:`fixed_point` finds it, from the solution).

        Raises
        ------
        walkerlab.config.SceneError
            Not exactly one known target, a target that is not a positive finite number
            (``0``, ``nan``, ``inf``, ``-1``), or ``vary`` a field that takes whole numbers,
            is no number, or is outside the ``walker`` and ``slope`` sections (the gait does
            not depend on it): refused before any map (:func:`check_target`).
        walkerlab.studies.params.SweepError
            ``vary`` names no field of the scene.
        walkerlab.analysis.continuation.target.TargetNotReached
            No gait meets the target near the start (one line).
        """
        from walkerlab.analysis.continuation.target import MEASURES, solve_target  # light
        from walkerlab.studies.continuation import scene_family, scene_value  # light

        name, value = check_target(self.scene, vary, target)
        fam = scene_family(self.scene, vary, plant=self.plant)
        res = solve_target(fam, scene_value(self.scene, vary), self.fixed_point().x,
                           MEASURES[name][0], value)
        found = self.with_changes({vary: res.p})
        fp = self.scene.fixedpoint
        if fp is not None and fp.initial_guess is not None:  # start from the solution,
            # its gait the one reported (under ``stable`` an unstable solution would send
            # the search to another gait, which does not meet the target, or to the seeds)
            found = found.with_changes({
                f"fixedpoint.initial_guess.{n}_{'rad' if n.endswith('_angle') else 'rad_per_s'}":
                float(v) for n, v in zip(found.state_names(), res.x)} |
                {"fixedpoint.gait": "nearest_guess"})
        return found, found.fixed_point()

    def simulate(self, x0, strides: int, sample_rate_hz: float = 500.0, *,
                 terrain_seed: int | None = None) -> Walk:
        """Walk ``strides`` strides (2 * strides heel strikes) from ``x0`` on the scene's
        ground, as the ``simulate`` stage walks it
        (:func:`walkerlab.analysis.gait.rigid_run.walk_scene`): a slope, per-step slopes,
        stairs and footholds through the walker's heel-strike guard, a height profile
        segment by segment, a rough ground drawn from ``terrain_seed``; each step bounded
        to :attr:`walk_step_time` of simulated time.  From the stage's start (the gait of
        :meth:`fixed_point`, or ``simulate.initial_state``) with the scene's strides, the
        heel strikes, the step table and the energy ledger are those of
        ``walkerlab simulate``, bit for bit (the samples are the same walk, taken on each
        step's own time grid).

        Parameters
        ----------
        x0 : array_like, shape (2n,)
            State just after heel strike; ``leg1`` swings first (:meth:`check_state`).
        strides : int
            Strides, a whole number from 1 to
            :data:`~walkerlab.config.MAX_SIMULATE_STRIDES` (as ``simulate.strides``).
        sample_rate_hz : float
            Samples per second of the returned arrays [Hz] (as ``simulate.sample_rate_hz``);
            the walk holds at most :data:`~walkerlab.config.MAX_SIMULATE_SAMPLES` samples,
            as the ``simulate`` stage.
        terrain_seed : int, optional
            Walk the per-step ground of ``terrain.per_step`` drawn from this seed (as
            ``walkerlab simulate --terrain-seed``;
            :func:`walkerlab.analysis.gait.rigid_run.rough_ground_steps`: the walk ends
            after its ``2 * strides`` steps); default the scene's
            ``simulate.terrain_seed`` (none: the scene's own ground).

        Returns
        -------
        Walk
            Samples, heel strikes, phases, the step table and energy ledger per step.

        Raises
        ------
        walkerlab.config.SceneError
            ``strides`` not a whole number in range (``1.5``, ``True``, ``"2"``, ``10**9``),
            ``sample_rate_hz`` not a positive number, more samples than the cap (said before
            any is taken), ``x0`` no state of the walker, a ``terrain_seed`` out of range
            or without ``terrain.per_step``, or a ground the walk does not read (a profile
            only in ``terrain.profile_csv``, a profile walked by an actuated walker or
            printed equations: ``terrain.kind: profile: ...``) (one line each, naming the
            key).
        walkerlab.analysis.gait.poincare.StepFailed
            A step used up its ``step_evaluations`` (a fall is recorded in
            ``termination``, not raised).
        """
        from walkerlab.analysis.gait.rigid_run import rough_ground_walker, walk_scene  # light
        from walkerlab.config import SceneError  # light
        from walkerlab.config.options import with_terrain_seed  # light

        strides, rate = simulate_options(strides, sample_rate_hz)
        x0 = self.check_state(x0, "x0")
        try:
            scene = with_terrain_seed(self.scene, terrain_seed)
        except SceneError as exc:
            raise SceneError(f"simulate: terrain_seed={short(terrain_seed)}: "
                             f"{str(exc).split(': ', 1)[-1]}") from None
        walker = self.model
        try:
            if scene.simulate is not None and scene.simulate.terrain_seed is not None:
                walker = rough_ground_walker(scene, 2 * strides, self.plant)
            with bounded_steps(self.step_evaluations, self.max_step_time):
                traj = walk_scene(scene, walker, x0, 2 * strides, self.solver,
                                  self.walk_step_time, self.plant)
        except SceneError:
            raise
        except ValueError as exc:  # a ground this walk does not read (one line, its key)
            raise SceneError(str(exc)) from None
        return sampled_walk(traj, rate)

    def __repr__(self) -> str:
        return (f"Walker({self.scene.name!r}, states={self.state_names()}, "
                f"slope={self.model.params.get('slope_rad', 'n/a')})")


class ContactWalker:
    """The contact (compliant-foot, floating-base) view of a scene's walker, in memory.

    Build it with :meth:`from_scene` or :meth:`walkerlab.api.walker.Walker.contact`.  It
    holds the scene's contact model once (:attr:`setup`: the walker's structure and
    parameters, the contact law in SI, the knee stop, the actuators as forces, the run
    options; :func:`walkerlab.models.contact.scene.contact_setup`), the model itself
    (:attr:`model`, on no terrain), the integrator (:attr:`solver`, ``contact_solver``) and
    the rigid view (:attr:`rigid`) whose gait starts a run.  Each run lays the terrain's
    patches for its own start (they are spaced by its step length), as the stage does.

    Parameters
    ----------
    scene : walkerlab.config.Scene
        A validated scene (its ``walker``, ``slope``, ``contact``, ``terrain``,
        ``contact_sim``, ``contact_solver`` and, for the rigid gait, ``solver`` and
        ``fixedpoint`` sections are used; a ``contact`` section left out is its defaults,
        the paper's contact law, and :attr:`scene` has it written out).
    rigid : Walker, optional
        The scene's rigid walker (default: built here).
    step_evaluations : int
        As :class:`~walkerlab.api.walker.Walker` (the rigid view's steps).

    Attributes
    ----------
    scene : walkerlab.config.Scene
    setup : walkerlab.models.contact.scene.ContactSetup
    model : walkerlab.models.contact.model.ContactWalker
    solver : walkerlab.integrate.solver.Solver
    rigid : Walker

    Raises
    ------
    walkerlab.models.contact.scene.ContactSceneError
        A walker the contact view does not carry (one line:
        :func:`~walkerlab.models.contact.scene.contact_setup`).
    walkerlab.config.SceneError
        A bad ``step_evaluations``.
    """

    def __init__(self, scene: Scene, rigid: Walker | None = None,
                 step_evaluations: int = STEP_EVALUATIONS):
        from walkerlab.config.sections import with_default_section  # light
        from walkerlab.models.contact.scene import contact_setup  # light

        self.scene = with_default_section(scene, "contact")  # left out: its defaults
        self.setup = contact_setup(self.scene, plant=scene_plant(scene, rigid and rigid.plant))
        self.rigid = rigid or Walker(scene, step_evaluations, self.setup.plant)  # described once
        self.model = self.setup.model()  # as the stage's (a wheel's hub inertia too)
        self.solver = Solver.from_settings(self.setup.solver)
        self._gait = None  # the rigid gait, found on first use
        self._periodic_checked = False

    @classmethod
    def from_scene(cls, scene: Scene | str | Path | dict[str, Any],
                   step_evaluations: int = STEP_EVALUATIONS) -> ContactWalker:
        """The contact walker of a scene: a YAML path, a mapping with the scene's sections,
        or a loaded scene.

        Raises
        ------
        walkerlab.config.SceneError
            The file is missing or the scene does not validate (one line per field).
        walkerlab.models.contact.scene.ContactSceneError
            As :class:`ContactWalker`.
        """
        return cls(as_scene(scene), step_evaluations=step_evaluations)

    def with_changes(self, changes: dict[str, Any]) -> ContactWalker:
        """A new contact walker (and rigid walker) with scene fields set by dotted path
        (``{"contact.mu_static": 0.6, "contact_sim.start": "periodic_gait"}``); this one is
        unchanged.

        Raises
        ------
        walkerlab.config.SceneError
            An unknown field (with the closest name) or a value the field does not accept.
        walkerlab.models.contact.scene.ContactSceneError
            The changed scene's walker is one the contact view does not carry.
        """
        return ContactWalker((rigid := self.rigid.with_changes(changes)).scene, rigid)

    def state_names(self) -> list[str]:
        """Names of the floating walker's state (N,): the hip position, the link angles,
        then their rates (``hip_x``, ``hip_y``, ``theta1``, ... , ``dhip_x``, ...)."""
        return list(self.model.state_names())

    def state_units(self) -> list[str]:
        """Units of the state's entries (``m``, ``rad``, ``m/s``, ``rad/s``)."""
        return list(self.model.state_units())

    def contact_names(self) -> list[str]:
        """Names of the contact points (``leg1``, ``leg2``; flat feet ``leg1_heel``, ...)."""
        return list(self.model.contact_names())

    def rigid_gait(self):
        """The rigid view's period-1 gait (:meth:`Walker.fixed_point`, found once and kept):
        the start of :meth:`simulate` and :meth:`periodic_gait`, as ``fixedpoint.h5`` is
        the ``contact-sim`` stage's.

        Raises
        ------
        walkerlab.analysis.gait.search.GaitNotFound
            As :meth:`Walker.fixed_point`.
        """
        if self._gait is None:
            self._gait = self.rigid.fixed_point()
        return self._gait

    def _start(self, x0, period_s) -> tuple[np.ndarray, float]:
        """The rigid start ``x0`` (default the rigid gait) and its step period [s]."""
        import numbers

        from walkerlab.analysis.gait.poincare import StepFailed  # light
        from walkerlab.config import SceneError  # light

        if x0 is None:
            if period_s is not None:
                raise SceneError("simulate: period_s goes with x0 (without x0 the run starts "
                                 "from the rigid gait with its own step period)")
            gait = self.rigid_gait()
            return gait.x, gait.step_period
        x = self.rigid.check_state(x0, "x0")
        if period_s is not None:
            if (isinstance(period_s, bool) or not isinstance(period_s, numbers.Real)
                    or not 0 < period_s < float("inf")):
                raise SceneError(f"simulate: period_s={period_s!r}: give the rigid step "
                                 "period from x0 as a positive number of seconds")
            return x, float(period_s)
        try:
            step = self.rigid.step(x)
        except StepFailed as exc:
            raise SceneError(f"simulate: x0 sizes the run by its rigid step, which failed "
                             f"({exc}); give period_s=...") from None
        return x, step.period / self.rigid.model.steps_per_map

    def _with_strides(self, strides):
        """:attr:`setup` with ``contact_sim.n_strides`` set to ``strides`` (checked as the
        field is)."""
        import numbers

        from walkerlab.config import MAX_CONTACT_STRIDES, SceneError  # light

        if strides is None:
            return self.setup
        if (isinstance(strides, bool) or not isinstance(strides, numbers.Integral)
                or not 1 <= strides <= MAX_CONTACT_STRIDES):
            raise SceneError(f"simulate: strides={strides!r}: give a whole number of strides "
                             f"from 1 to {MAX_CONTACT_STRIDES} (as contact_sim.n_strides)")
        sim = self.setup.sim.model_copy(update={"n_strides": int(strides)})
        return dataclasses.replace(self.setup, sim=sim)

    def simulate(self, x0=None, strides: int | None = None, *,
                 period_s: float | None = None) -> ContactWalk:
        """Walk the contact walker, started as the ``contact-sim`` stage starts it
        (:func:`walkerlab.analysis.contact.record.contact_walk`): from the rigid state
        ``x0`` with the stance foot at its static penetration and the rates times
        ``contact_sim.initial_rate_scale`` (``start: ideal``), from the rates the
        adjustment searches (``start: adjusted``), or from the contact model's own periodic
        gait found from ``x0`` (``start: periodic_gait``); change the start with
        :meth:`with_changes`.  With ``x0`` left out, the numbers are those of
        ``walkerlab contact-sim`` for the same scene, bit for bit.

        Parameters
        ----------
        x0 : array_like, shape (2n,), optional
            A rigid post-impact state (:meth:`Walker.state_names` of :attr:`rigid`, leg1
            swing, leg2 stance) [rad, rad/s]; default the rigid gait (:meth:`rigid_gait`).
        strides : int, optional
            Strides (two heel strikes each), 1 to
            :data:`~walkerlab.config.MAX_CONTACT_STRIDES`; default ``contact_sim.n_strides``.
        period_s : float, optional
            The rigid step period from ``x0`` [s], which sizes the run's end time (default:
            one rigid step from ``x0``; the rigid gait's own period without ``x0``).

        Returns
        -------
        ContactWalk
            Samples, heel strikes, the step table, contact forces by point, outcome.

        Raises
        ------
        walkerlab.config.SceneError
            ``x0`` not a finite rigid state of the walker's size (the message names the
            states), ``strides`` not a whole number in range, a bad ``period_s``, or a rigid
            step from ``x0`` that failed (one line each).
        walkerlab.analysis.contact.step_map.PeriodicGaitError
            ``start: periodic_gait`` and the periodic gait was not found (one line).
        walkerlab.analysis.gait.search.GaitNotFound
            No rigid gait to start from (``x0`` left out).
        """
        from walkerlab.analysis.contact.record import contact_walk  # light

        setup = self._with_strides(strides)
        x_ideal, period = self._start(x0, period_s)
        walker, res, x_start, step_length, scale, gait, _ = contact_walk(
            setup, x_ideal, period, solver=self.solver)
        return recorded_contact_walk(walker, res, x_start, x_ideal, step_length,
                                     scale if scale is not None
                                     else setup.sim.initial_rate_scale, gait)

    def periodic_gait(self, x0=None):
        """The contact model's own periodic gait (fixed point of its mid-stance step map)
        and its Floquet multipliers, as ``walkerlab contact-sim`` with
        ``contact_sim.periodic_gait: true`` finds it
        (:func:`walkerlab.analysis.contact.periodic.find_contact_periodic_gait`, from the
        rigid state ``x0``, within ``contact_sim.periodic_max_step_maps``).

        Parameters
        ----------
        x0 : array_like, shape (2n,), optional
            The rigid state the search starts from [rad, rad/s]; default the rigid gait.

        Returns
        -------
        walkerlab.analysis.contact.periodic.ContactPeriodicGait
            ``fixed_point`` (the section state by name), ``period_s`` [s],
            ``step_length_m`` [m], ``multipliers`` (n,) by decreasing modulus, ``jacobian``
            (n, n), ``residual`` (below the search's tolerance: ``converged`` is True),
            ``stable``, ``full_state`` (N,).

        Raises
        ------
        walkerlab.config.SceneError
            ``x0`` no rigid state of the walker (one line naming the states).
        walkerlab.models.contact.scene.ContactSceneError
            A walker whose contact periodic gait is not found yet (as ``contact_sim:
            periodic_gait: true`` is refused for it; one line).
        walkerlab.analysis.contact.step_map.PeriodicGaitError
            The gait was not found (a step fell, found no mid-stance, the solver failed,
            the time limit ran out, or the search did not converge: ``kind``
            ``not_converged``, :func:`~walkerlab.analysis.contact.periodic.converged_gait`;
            one line), as the stage reports it.
        """
        from walkerlab.analysis.contact.periodic import (  # light
            converged_gait,
            find_contact_periodic_gait,
            search_bounds,
        )
        from walkerlab.analysis.contact.sim import scene_start  # light

        self._check_periodic()
        x = self.rigid_gait().x if x0 is None else self.rigid.check_state(x0, "x0")
        walker = scene_start(self.setup, x, self.setup.sim.n_strides)[0]  # the stage's ground
        return converged_gait(find_contact_periodic_gait(
            walker, x, **search_bounds(self.setup.sim)))

    def _check_periodic(self) -> None:
        """Refuse a walker whose periodic gait the contact view does not find (the scene's
        checks of ``contact_sim.periodic_gait: true``, run once on a copy of the scene)."""
        cs = self.setup.sim
        if cs.periodic_gait or cs.start == "periodic_gait" or self._periodic_checked:
            return
        from walkerlab.models.contact.scene import contact_setup  # light

        contact_setup(self.scene, periodic=True, plant=self.rigid.plant)
        self._periodic_checked = True

    def __repr__(self) -> str:
        return (f"ContactWalker({self.scene.name!r}, states={self.state_names()}, "
                f"contacts={self.contact_names()})")

