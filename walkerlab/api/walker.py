"""A walker in memory: its Poincaré map, exact Jacobian, Floquet multipliers, fixed point
and simulation, with no artifact written or read (only the generated-code cache is used).

The artifact functions of :mod:`walkerlab.api` stay the front door for stored results; this
is the object for loops and notebooks, as MuJoCo's ``MjModel``/``MjData`` or Pinocchio's
``Model``/``Data``::

    import walkerlab as wl
    w = wl.Walker.from_scene("configs/paper.yaml")
    gait = w.fixed_point()              # the very numbers of `walkerlab fixedpoint`
    gait.state["stance_angle"], gait.step_period, gait.multipliers
    heavier = w.with_changes({"walker.hip_mass_kg": 12.0})

States are role-ordered arrays of :meth:`Walker.state_names` (angles [rad], rates [rad/s];
in a ``units: nondimensional`` scene every quantity is in the walker's own units, time in
√(l/g)).  Nothing here knows how many states a walker has.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from walkerlab.config import Scene

__all__ = ["STEP_TIME_LIMIT_S", "Gait", "Step", "Target", "Walk", "Walker", "check_target",
           "target"]

#: CPU time one walking step of the in-memory walker may take [s] (a map is one step, or a
#: stride of two; :func:`walkerlab.integrate.time_limit.integration_time_limit`), as the gait
#: search's budget (:data:`walkerlab.analysis.gait.poincare.ROOT_BUDGET_S`)
STEP_TIME_LIMIT_S = 60.0


@dataclass(frozen=True)
class Gait:
    """A period-1 gait (fixed point of the Poincaré map), as ``walkerlab fixedpoint`` finds it.

    Attributes
    ----------
    x : ndarray, shape (2n,)
        State just after heel strike (role order of ``names``) [rad, rad/s].
    names : tuple of str
        State names (:meth:`Walker.state_names`).
    step_period : float
        Step period [s, or √(l/g) in a nondimensional scene]; for a walker whose legs
        differ (a stride map), the mean of its two steps.
    map_period : float
        Period of the Poincaré map [s]: the step period, or the stride period.
    multipliers : ndarray, shape (2n,), complex
        Floquet multipliers (variational equations with saltation), by decreasing modulus.
    jacobian : ndarray, shape (2n, 2n)
        Jacobian of the Poincaré map at ``x``.
    residual : float
        max |P(x) - x| [state units].
    label : str
        Which gait of the search (``long_period``, ``short_period``, ...).
    step_length : float
        Mean step length [m]: stance foot to swing foot at heel strike
        (:func:`walkerlab.analysis.gait.metrics.step_length`).
    speed : float
        Distance along the ground over the map's period [m/s].
    cost_of_transport : float
        Mean over the map's steps of (positive actuator work + push-off work + slope
        energy if > 0) / (M g d) [-] (Kuo 2002; Collins et al. 2005); a passive gait's is
        sin(slope).  NaN without a ledger (flat feet on legs that differ).
    ledger : dict[str, ndarray (steps,)]
        The energy ledger of each step of the map, as ``simulate.h5``'s ``ledger/``
        (:func:`walkerlab.analysis.gait.energy.gait_ledger`): ``actuator_work_positive``,
        ``actuator_work_negative``, ``push_off_work``, ``heel_strike_loss``,
        ``internal_collision_loss``, ``damper_work``, ``potential_work``, ``energy_change``,
        ``closure``, ``slope_energy`` [J], ``push_off_impulse`` [N s],
        ``cost_of_transport`` [-].
    """

    x: np.ndarray
    names: tuple
    step_period: float
    map_period: float
    multipliers: np.ndarray
    jacobian: np.ndarray
    residual: float
    label: str
    step_length: float = float("nan")
    speed: float = float("nan")
    cost_of_transport: float = float("nan")
    ledger: dict = field(default_factory=dict)

    @property
    def state(self) -> dict[str, float]:
        """The fixed point by state name."""
        return {n: float(v) for n, v in zip(self.names, self.x)}

    @property
    def stable(self) -> bool:
        """All |Floquet multipliers| < 1."""
        import numpy as np

        return bool(np.max(np.abs(self.multipliers)) < 1.0)


@dataclass(frozen=True)
class Step:
    """One application of the Poincaré map (a step, or a stride when the legs differ).

    Attributes
    ----------
    x_next : ndarray, shape (2n,)
        State just after the last heel strike.
    period : float
        Duration [s].
    events : list of (str, float, float, str)
        Each phase of each step: ``(phase, t_start [s], t_end [s], guard that ended it)``.
    """

    x_next: np.ndarray
    period: float
    events: list


@dataclass(frozen=True)
class Walk:
    """A simulated walk.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Sample times [s].
    x : ndarray, shape (m, 2n)
        Role-ordered states at ``t`` (roles swap at every heel strike).
    stance_leg : ndarray, shape (m,), str
        Physical leg in stance at each sample.
    heel_strikes : ndarray, shape (k,)
        Times of the heel strikes [s].
    events : list of (int, str, str, float, float, str)
        ``(step, stance leg, phase, t_start, t_end, guard)`` of every phase.
    termination : str
        How the walk ended (``heel_strike`` after the last step, ``fall``, ...).
    steps : dict[str, ndarray (k,)]
        The step table of the ``simulate`` stage
        (:func:`walkerlab.analysis.gait.metrics.step_table`): ``period`` [s],
        ``step_length`` [m], ``hip_speed`` [m/s], ``impact_energy_loss`` [J],
        ``termination``, ``stance_leg`` ... of each step (the last one may have fallen).
    ledger : dict[str, ndarray (k,)]
        The energy ledger of each step, as :attr:`Gait.ledger` (NaN for a step that did
        not end by a heel strike; empty for flat feet on legs that differ).
    """

    t: np.ndarray
    x: np.ndarray
    stance_leg: np.ndarray
    heel_strikes: np.ndarray
    events: list
    termination: str
    steps: dict = field(default_factory=dict)
    ledger: dict = field(default_factory=dict)

    @property
    def step_length(self) -> np.ndarray:
        """Length of each step [m] (``steps["step_length"]``)."""
        return self.steps["step_length"]

    @property
    def speed(self) -> np.ndarray:
        """Hip speed of each step [m/s] (``steps["hip_speed"]``)."""
        return self.steps["hip_speed"]

    @property
    def cost_of_transport(self) -> np.ndarray:
        """Cost of transport of each step [-] (``ledger["cost_of_transport"]``)."""
        return self.ledger["cost_of_transport"]


class Walker:
    """The rigid hybrid walker of a scene, in memory.

    Build it with :meth:`from_scene`; it holds the validated scene, the generated model
    (:func:`walkerlab.models.registry.build_walker`) and the scene's solver settings.

    Parameters
    ----------
    scene : walkerlab.config.Scene
        A validated scene (its ``walker``, ``slope``, ``ideal``, ``solver`` and
        ``fixedpoint`` sections are used).
    step_time_limit_s : float
        CPU time each walking step of :meth:`step`, :meth:`jacobian`, :meth:`floquet` and
        :meth:`simulate` may take [s] (this thread's CPU time, so a busy machine does not
        trip it); past it the map stops with one line
        (:class:`~walkerlab.analysis.gait.poincare.StepFailed`, ``time_limit``).  The
        simulated time of a step is bounded apart, by ``fixedpoint.max_step_time_s``.

    Raises
    ------
    walkerlab.config.SceneError
        ``step_time_limit_s`` not a positive number.
    """

    def __init__(self, scene: Scene, step_time_limit_s: float = STEP_TIME_LIMIT_S):
        from walkerlab.integrate.solver import Solver
        from walkerlab.models.registry import build_walker

        self.step_time_limit_s = _positive(step_time_limit_s, "step_time_limit_s")
        self.scene = scene
        self.model = build_walker(scene)
        self.solver = Solver.from_settings(scene.solver)
        fp = scene.fixedpoint
        self.max_step_time = 5.0 if fp is None else fp.max_step_time_s

    @classmethod
    def from_scene(cls, scene: Scene | str | Path | dict[str, Any],
                   step_time_limit_s: float = STEP_TIME_LIMIT_S) -> Walker:
        """The walker of a scene: a YAML path, a mapping with the scene's sections, or a
        loaded scene (``step_time_limit_s`` as in :class:`Walker`).

        Raises
        ------
        walkerlab.config.SceneError
            The file is missing or the scene does not validate (one line per field), or a
            bad ``step_time_limit_s``.
        """
        from walkerlab.api.scenes import as_scene

        return cls(as_scene(scene), step_time_limit_s)

    def with_changes(self, changes: dict[str, Any]) -> Walker:
        """A new walker with scene fields set by dotted path
        (``{"walker.hip_mass_kg": 12, "slope.angle_deg": 2}``); this one is unchanged.

        Raises
        ------
        walkerlab.config.SceneError
            An unknown field (with the closest name) or a value the field does not accept.
        """
        from walkerlab.api.scenes import with_changes

        return Walker(with_changes(self.scene, changes), self.step_time_limit_s)

    def state_names(self) -> list[str]:
        """Names of the role-ordered state (2n,), coordinates then rates."""
        return list(self.model.state_names())

    def state_units(self) -> list[str]:
        """Units of the state's entries (``rad``, ``rad/s``)."""
        return list(self.model.state_units())

    def check_state(self, x, what: str = "x") -> np.ndarray:
        """``x`` as the walker's state: a float array (2n,) of finite numbers, rates within
        :data:`~walkerlab.analysis.gait.scene.MAX_GUESS_RATE` sqrt(g/l) and angles within
        [-pi, pi] (beyond them no walking gait is near: a leg that fast would leave the
        ground, and the integrator crawls; the bounds of ``fixedpoint.initial_guess``).

        Parameters
        ----------
        x : array_like, shape (2n,)
            A role-ordered state (:meth:`state_names`) [rad, rad/s].
        what : str
            The argument's name in the message.

        Returns
        -------
        ndarray, shape (2n,)

        Raises
        ------
        walkerlab.config.SceneError
            One line naming the shape, the entry or the value.
        """
        import math

        import numpy as np

        from walkerlab.analysis.gait.scene import MAX_GUESS_RATE
        from walkerlab.config import SceneError

        names = self.state_names()
        want = (f"give the state as {len(names)} numbers ({', '.join(names)}) "
                "[rad, rad/s], e.g. gait.x")
        if x is None or isinstance(x, (str, bytes, dict)):
            raise SceneError(f"{what}={_short(x)}: {want}")
        try:
            arr = np.asarray(x)
            if arr.dtype.kind not in "biuf" or arr.dtype.kind == "b":
                raise TypeError
            arr = arr.astype(float)
        except (TypeError, ValueError):
            raise SceneError(f"{what}={_short(x)}: not numbers; {want}") from None
        if arr.shape != (len(names),):
            raise SceneError(f"{what} has shape {arr.shape}; the walker's state is "
                             f"({len(names)},): {want}")
        p = self.model.params
        max_rate = MAX_GUESS_RATE * math.sqrt(float(p["gravity_m_per_s2"])
                                              / float(p["leg_length_m"]))
        for i, (name, v) in enumerate(zip(names, arr)):
            if not math.isfinite(v):
                raise SceneError(f"{what}[{i}] ({name}) = {v}: give finite numbers")
            if name.endswith("_rate") and abs(v) > max_rate:
                raise SceneError(f"{what}[{i}] ({name}) = {v:g} rad/s is not a walking state: "
                                 f"at most {max_rate:.3g} ({MAX_GUESS_RATE:g} sqrt(g/l); a "
                                 "leg this fast would leave the ground)")
            if name.endswith("_angle") and abs(v) > math.pi:
                raise SceneError(f"{what}[{i}] ({name}) = {v:g} rad is more than half a "
                                 "turn: give an angle within [-pi, pi]")
        return arr

    def _map(self, x, jacobian: bool = False, steps: list | None = None):
        from walkerlab.analysis.gait.poincare import poincare_map

        x = self.check_state(x)
        with self._bounded():
            return poincare_map(self.model, x, self.solver, self.max_step_time,
                                jacobian=jacobian, steps=steps)

    @contextmanager
    def _bounded(self):
        """Each walking step inside bounded to ``step_time_limit_s`` of CPU time; a failed
        step said in one line (how and when it ended, what to do)."""
        from walkerlab.analysis.gait.poincare import StepFailed
        from walkerlab.integrate.time_limit import IntegrationTimeLimit, integration_time_limit

        try:
            with integration_time_limit(self.step_time_limit_s):
                yield
        except IntegrationTimeLimit:
            out = StepFailed("time_limit", float("nan"), None)
            out.args = (f"step: a walking step used up its {self.step_time_limit_s:g} s of "
                        "CPU time (Walker(..., step_time_limit_s=...)): a state far from any "
                        "gait, or a very stiff spring, makes the integrator crawl",)
            raise out from None
        except StepFailed as exc:
            raise _clear(exc, self.max_step_time) from None

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
            step past ``step_time_limit_s`` of CPU time (one line: how and when).
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

        from walkerlab.numerics import sort_multipliers

        return sort_multipliers(np.linalg.eigvals(self.jacobian(x)))

    def fixed_point(self) -> Gait:
        """The period-1 gait the ``fixedpoint`` stage finds, bit for bit (the same search:
        :func:`walkerlab.analysis.gait.scene.solve_scene`), without writing anything.

        Raises
        ------
        walkerlab.analysis.gait.search.GaitNotFound
            No gait (one line: what was tried, what to try next).
        ValueError
            A malformed initial guess or gait choice (one line naming the field).
        """
        import numpy as np

        from walkerlab.analysis.gait.energy import gait_ledger
        from walkerlab.analysis.gait.scene import solve_scene

        _, search = solve_scene(self.scene)
        chosen = search.gaits[search.selected]
        r = chosen.result
        m, ledger = gait_ledger(self.model, r.x, self.model.steps_per_map, self.solver,
                                self.max_step_time)
        return Gait(np.asarray(r.x, float), tuple(self.state_names()),
                    float(r.period_s) / self.model.steps_per_map, float(r.period_s),
                    np.asarray(r.multipliers_variational),
                    np.asarray(r.jacobian_variational), float(r.residual), chosen.label,
                    m["step_length"], m["speed"], m["cost_of_transport"], ledger)

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
        from walkerlab.analysis.continuation.target import MEASURES, solve_target
        from walkerlab.studies.continuation import scene_family, scene_value

        name, value = check_target(self.scene, vary, target)
        fam = scene_family(self.scene, vary)
        res = solve_target(fam, scene_value(self.scene, vary), self.fixed_point().x,
                           MEASURES[name][0], value)
        found = self.with_changes({vary: res.p})
        fp = self.scene.fixedpoint
        if fp is not None and fp.initial_guess is not None:  # start from the solution
            found = found.with_changes({
                f"fixedpoint.initial_guess.{n}_{'rad' if n.endswith('_angle') else 'rad_per_s'}":
                float(v) for n, v in zip(found.state_names(), res.x)})
        return found, found.fixed_point()

    def simulate(self, x0, strides: int, sample_rate_hz: float = 500.0) -> Walk:
        """Walk ``strides`` strides (2 * strides heel strikes) from ``x0``.

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

        Returns
        -------
        Walk
            Samples, heel strikes, phases, the step table and energy ledger per step.

        Raises
        ------
        walkerlab.config.SceneError
            ``strides`` not a whole number in range (``1.5``, ``True``, ``"2"``, ``10**9``),
            ``sample_rate_hz`` not a positive number, more samples than the cap (said before
            any is taken), or ``x0`` no state of the walker (one line each).
        walkerlab.analysis.gait.poincare.StepFailed
            A step used up ``step_time_limit_s`` of CPU time (a fall is recorded in
            ``termination``, not raised).
        """
        import numpy as np

        from walkerlab.analysis.gait.energy import trajectory_ledger
        from walkerlab.analysis.gait.metrics import step_table
        from walkerlab.config import MAX_SIMULATE_SAMPLES, SceneError
        from walkerlab.integrate.rigid import simulate_steps

        strides, rate = _simulate_options(strides, sample_rate_hz)
        x0 = self.check_state(x0, "x0")
        with self._bounded():
            traj = simulate_steps(self.model, x0, 2 * strides, self.solver,
                                  max_step_time=self.max_step_time)
        counts = [max(2, int(np.ceil((seg.t_end - seg.t_start) * rate)) + 1)
                  for seg in traj.segments]
        if sum(counts) > MAX_SIMULATE_SAMPLES:
            span = traj.segments[-1].t_end - traj.segments[0].t_start
            raise SceneError(f"simulate: sample_rate_hz={rate:g} Hz over {span:.3g} s gives "
                             f"{sum(counts):,} samples; at most {MAX_SIMULATE_SAMPLES:,} are "
                             "kept (lower sample_rate_hz or strides)")
        ts, xs, legs, events = [], [], [], []
        for seg, n in zip(traj.segments, counts):
            t = np.linspace(seg.t_start, seg.t_end, n)
            ts.append(t)
            xs.append(seg.sample(t).T)
            legs.append(np.full(n, seg.stance_leg))
            events += [(seg.index, seg.stance_leg, *entry) for entry in seg.phase_log]
        hs = np.array([s.t_end for s in traj.segments if s.termination == "heel_strike"])
        return Walk(np.concatenate(ts), np.concatenate(xs), np.concatenate(legs), hs, events,
                    traj.termination, step_table(traj), trajectory_ledger(traj))

    def __repr__(self) -> str:
        return (f"Walker({self.scene.name!r}, states={self.state_names()}, "
                f"slope={self.model.params.get('slope_rad', 'n/a')})")


def _short(value) -> str:
    """``repr(value)``, cut to 40 characters."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _positive(value, name: str) -> float:
    """``value`` as a positive finite float, else one line naming ``name``."""
    import math
    import numbers

    from walkerlab.config import SceneError

    if (isinstance(value, bool) or not isinstance(value, numbers.Real)
            or not math.isfinite(value) or value <= 0):
        raise SceneError(f"{name}={_short(value)}: give a positive number of seconds")
    return float(value)


def _simulate_options(strides, sample_rate_hz) -> tuple[int, float]:
    """``(strides, sample_rate_hz)`` checked by the ``simulate`` section's own fields
    (whole strides from 1 to the cap, a positive rate up to its cap); one line each."""
    import numbers

    from pydantic import ValidationError

    from walkerlab.config import SceneError
    from walkerlab.config.studies import SimulateSettings

    if isinstance(strides, bool) or not isinstance(strides, numbers.Integral):
        raise SceneError(f"simulate: strides={_short(strides)}: give a whole number of "
                         "strides (an int, e.g. strides=10)")
    if isinstance(sample_rate_hz, bool) or not isinstance(sample_rate_hz, numbers.Real):
        raise SceneError(f"simulate: sample_rate_hz={_short(sample_rate_hz)}: give a "
                         "number of samples per second, e.g. 500")
    try:
        sim = SimulateSettings.model_validate({"strides": int(strides),
                                               "sample_rate_hz": float(sample_rate_hz)})
    except ValidationError as err:
        e = err.errors()[0]
        field = e["loc"][0]
        value = strides if field == "strides" else sample_rate_hz
        raise SceneError(f"simulate: {field}={_short(value)}: {e['msg'].lower()} "
                         f"(as simulate.{field})") from None
    return sim.strides, sim.sample_rate_hz


def _clear(exc, max_step_time: float):
    """A :class:`StepFailed` of the map said in the walker's terms (one line: how the step
    ended, when, and what to do), not in the integrator's."""
    from walkerlab.analysis.gait.poincare import StepFailed

    t = f"t = {exc.t:.4g} s"
    why = {
        "fall": f"the walker fell at {t}, before its heel strike (a fall guard fired): the "
                "state is not on a walking gait; start from a gait (w.fixed_point().x) or "
                "nearer to it",
        "t_final": f"no heel strike within max_step_time_s = {max_step_time:g} s "
                   "(fixedpoint.max_step_time_s): the walker stalled",
        "solver_failure": f"the integrator stopped at {t}: "
                          f"{' '.join(str(exc).split(' s ', 1)[-1].split())}",
    }.get(exc.termination)
    if why is None:
        return exc
    out = StepFailed(exc.termination, exc.t, exc.x)
    out.args = (f"step: {why}",)
    return out


def check_target(scene: Scene, vary, target: dict) -> tuple[str, float]:
    """The field and target of :meth:`Walker.find_gait_for` (and ``walkerlab target``)
    checked before any map.

    Parameters
    ----------
    scene : walkerlab.config.Scene
    vary : str
        Dotted scene field to solve for.
    target : dict
        ``{measure: value}``, one of
        :data:`walkerlab.analysis.continuation.target.MEASURES`.

    Returns
    -------
    name : str
        The measure (``speed_m_per_s``, ``step_length_m`` or ``step_period_s``).
    value : float
        The target [m/s, m or s].

    Raises
    ------
    walkerlab.config.SceneError
        Not exactly one known measure; a value that is not a positive finite number (a
        speed, a step length and a step period are all > 0); ``vary`` not a string, a field
        outside the ``walker`` and ``slope`` sections, a whole-number field or one whose
        value is no number (one line each).
    walkerlab.studies.params.SweepError
        ``vary`` names no field of the scene (with the closest name).
    """
    import math
    import numbers

    from walkerlab.analysis.continuation.target import MEASURES
    from walkerlab.config import SceneError
    from walkerlab.studies.continuation import scene_family, scene_value
    from walkerlab.studies.params import ParamAxis, takes_whole_numbers

    if len(target) != 1 or next(iter(target)) not in MEASURES:
        raise SceneError(f"target: give exactly one of {', '.join(MEASURES)} (got "
                         f"{', '.join(target) or 'none'})")
    (name, value), = target.items()
    unit = MEASURES[name][1]
    if (isinstance(value, bool) or not isinstance(value, numbers.Real)
            or not math.isfinite(value) or value <= 0):
        raise SceneError(f"target {name} (--{name.replace('_', '-')}) = {_short(value)}: "
                         f"give a positive finite number [{unit}]")
    if not isinstance(vary, str) or not vary.startswith(("walker.", "slope.")):
        raise SceneError(f"target --vary {_short(vary)}: vary a numeric field of the walker "
                         "or the slope (e.g. walker.actuation.push_off.impulse_n_s); the "
                         "gait depends on no other section")
    from walkerlab.studies.params import SweepError

    try:
        scene_family(scene, vary)  # an unknown field: SweepError with the closest name
    except SweepError as exc:
        raise SweepError(str(exc).replace("--param ", "target --vary ", 1)) from None
    if takes_whole_numbers(scene, ParamAxis(vary, (), vary)):
        raise SceneError(f"target --vary {vary}: the field takes whole numbers; a target is "
                         "solved over a real-valued field")
    scene_value(scene, vary)  # unset or not a number: one line
    return name, float(value)


@dataclass(frozen=True)
class Target:
    """The value of one field whose period-1 gait meets a target (:func:`target`).

    Attributes
    ----------
    field : str
        The dotted scene field solved for.
    value : float
        Its value [the field's unit, ``unit``].
    unit : str
        The field's unit (``-`` when it has none).
    walker : Walker
        The walker with ``field`` set to ``value``.
    gait : Gait
        Its period-1 gait (step length, speed, cost of transport, multipliers ...).
    """

    field: str
    value: float
    unit: str
    walker: Walker
    gait: Gait


def target(scene: Scene | str | Path | dict[str, Any], vary: str, *,
           speed_m_per_s: float | None = None, step_length_m: float | None = None,
           step_period_s: float | None = None) -> Target:
    """The value of ``vary`` whose period-1 gait has a target speed, step length or step
    period, solved with the fixed point (``walkerlab target``; Kuo's DynLoco
    ``findgait(target=speed, varying=P)``), in memory: nothing is written.

    Parameters
    ----------
    scene : Scene, str, Path or dict
        A scene (:func:`walkerlab.api.load_scene`); its gait at its own value of ``vary``
        starts the solve.
    vary : str
        A real-valued field of the ``walker`` or ``slope`` section
        (``"walker.actuation.push_off.impulse_n_s"``).
    speed_m_per_s, step_length_m, step_period_s : float
        Exactly one target, a positive finite number [m/s, m, s].

    Returns
    -------
    Target

    Raises
    ------
    walkerlab.config.SceneError
        The checks of ``walkerlab target`` (:func:`check_target`), before any map.
    walkerlab.studies.params.SweepError
        ``vary`` names no field of the scene.
    walkerlab.analysis.continuation.target.TargetNotReached
        No gait meets the target near the scene's own (one line).
    walkerlab.analysis.gait.search.GaitNotFound
        No gait at the scene's own value to start from.

    Examples
    --------
    >>> t = wl.target("configs/powered_compass.yaml",
    ...               "walker.actuation.push_off.impulse_n_s", speed_m_per_s=0.45)  # doctest: +SKIP
    >>> t.value, t.gait.step_period, t.gait.cost_of_transport                      # doctest: +SKIP
    """
    from walkerlab.studies.continuation import scene_value
    from walkerlab.units import field_unit

    given = {k: v for k, v in (("speed_m_per_s", speed_m_per_s),
                               ("step_length_m", step_length_m),
                               ("step_period_s", step_period_s)) if v is not None}
    walker, gait = Walker.from_scene(scene).find_gait_for(vary, **given)
    return Target(vary, scene_value(walker.scene, vary), field_unit(vary) or "-", walker, gait)
