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

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from walkerlab.config import Scene

__all__ = ["Gait", "Step", "Walk", "Walker"]


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
    """

    x: np.ndarray
    names: tuple
    step_period: float
    map_period: float
    multipliers: np.ndarray
    jacobian: np.ndarray
    residual: float
    label: str

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
    """

    t: np.ndarray
    x: np.ndarray
    stance_leg: np.ndarray
    heel_strikes: np.ndarray
    events: list
    termination: str


class Walker:
    """The rigid hybrid walker of a scene, in memory.

    Build it with :meth:`from_scene`; it holds the validated scene, the generated model
    (:func:`walkerlab.models.registry.build_walker`) and the scene's solver settings.

    Parameters
    ----------
    scene : walkerlab.config.Scene
        A validated scene (its ``walker``, ``slope``, ``ideal``, ``solver`` and
        ``fixedpoint`` sections are used).
    """

    def __init__(self, scene: Scene):
        from walkerlab.integrate.solver import Solver
        from walkerlab.models.registry import build_walker

        self.scene = scene
        self.model = build_walker(scene)
        self.solver = Solver.from_settings(scene.solver)
        fp = scene.fixedpoint
        self.max_step_time = 5.0 if fp is None else fp.max_step_time_s

    @classmethod
    def from_scene(cls, scene: Scene | str | Path | dict[str, Any]) -> Walker:
        """The walker of a scene: a YAML path, a mapping with the scene's sections, or a
        loaded scene.

        Raises
        ------
        walkerlab.config.SceneError
            The file is missing or the scene does not validate (one line per field).
        """
        from walkerlab.api.scenes import as_scene

        return cls(as_scene(scene))

    def with_changes(self, changes: dict[str, Any]) -> Walker:
        """A new walker with scene fields set by dotted path
        (``{"walker.hip_mass_kg": 12, "slope.angle_deg": 2}``); this one is unchanged.

        Raises
        ------
        walkerlab.config.SceneError
            An unknown field (with the closest name) or a value the field does not accept.
        """
        from walkerlab.api.scenes import with_changes

        return Walker(with_changes(self.scene, changes))

    def state_names(self) -> list[str]:
        """Names of the role-ordered state (2n,), coordinates then rates."""
        return list(self.model.state_names())

    def state_units(self) -> list[str]:
        """Units of the state's entries (``rad``, ``rad/s``)."""
        return list(self.model.state_units())

    def _map(self, x, jacobian: bool = False, steps: list | None = None):
        import numpy as np

        from walkerlab.analysis.gait.poincare import poincare_map

        return poincare_map(self.model, np.asarray(x, dtype=float), self.solver,
                            self.max_step_time, jacobian=jacobian, steps=steps)

    def step(self, x) -> Step:
        """One Poincaré map step ``x -> P(x)`` (paper Eq. 10; a stride when legs differ).

        Parameters
        ----------
        x : array_like, shape (2n,)
            State just after heel strike.

        Raises
        ------
        walkerlab.analysis.gait.poincare.StepFailed
            The step fell, the solver failed or the step ran past ``max_step_time_s``.
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
        walkerlab.analysis.gait.poincare.StepFailed
            As :meth:`step`.
        """
        return self._map(x, jacobian=True)[2]

    def floquet(self, x) -> np.ndarray:
        """Floquet multipliers (2n,) at ``x`` (eigenvalues of :meth:`jacobian`), by
        decreasing modulus; meaningful at a fixed point."""
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

        from walkerlab.analysis.gait.scene import solve_scene

        _, search = solve_scene(self.scene)
        chosen = search.gaits[search.selected]
        r = chosen.result
        return Gait(np.asarray(r.x, float), tuple(self.state_names()),
                    float(r.period_s) / self.model.steps_per_map, float(r.period_s),
                    np.asarray(r.multipliers_variational),
                    np.asarray(r.jacobian_variational), float(r.residual), chosen.label)

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
        ValueError
            Not exactly one known target.
        walkerlab.studies.params.SweepError
            ``vary`` names no numeric field.
        walkerlab.analysis.continuation.target.TargetNotReached
            No gait meets the target near the start (one line).
        """
        from walkerlab.analysis.continuation.target import MEASURES, solve_target
        from walkerlab.studies.continuation import scene_family, scene_value

        if len(target) != 1 or next(iter(target)) not in MEASURES:
            raise ValueError(f"give exactly one target of {', '.join(MEASURES)}")
        (name, value), = target.items()
        fam = scene_family(self.scene, vary)
        res = solve_target(fam, scene_value(self.scene, vary), self.fixed_point().x,
                           MEASURES[name][0], float(value))
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
            State just after heel strike; ``leg1`` swings first.
        strides : int
            Strides (>= 1).
        sample_rate_hz : float
            Samples per second of the returned arrays [Hz].

        Raises
        ------
        ValueError
            ``strides`` < 1 or ``sample_rate_hz`` <= 0.
        """
        import numpy as np

        from walkerlab.integrate.rigid import simulate_steps

        if strides < 1 or not sample_rate_hz > 0:
            raise ValueError("simulate: give strides >= 1 and sample_rate_hz > 0")
        traj = simulate_steps(self.model, np.asarray(x0, float), 2 * int(strides),
                              self.solver, max_step_time=self.max_step_time)
        ts, xs, legs, events = [], [], [], []
        for seg in traj.segments:
            n = max(2, int(np.ceil((seg.t_end - seg.t_start) * sample_rate_hz)) + 1)
            t = np.linspace(seg.t_start, seg.t_end, n)
            ts.append(t)
            xs.append(seg.sample(t).T)
            legs.append(np.full(n, seg.stance_leg))
            events += [(seg.index, seg.stance_leg, *entry) for entry in seg.phase_log]
        hs = np.array([s.t_end for s in traj.segments if s.termination == "heel_strike"])
        return Walk(np.concatenate(ts), np.concatenate(xs), np.concatenate(legs), hs, events,
                    traj.termination)

    def __repr__(self) -> str:
        return (f"Walker({self.scene.name!r}, states={self.state_names()}, "
                f"slope={self.model.params.get('slope_rad', 'n/a')})")
