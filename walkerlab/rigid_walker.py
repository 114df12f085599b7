"""The rigid walker of a scene, below both front doors that hold one: its generated model,
its integrator, the check of a state and the period-1 gait the ``fixedpoint`` stage finds
(:class:`SceneWalker`, with the record of that gait, :class:`Gait`).

:class:`walkerlab.api.walker.Walker` (the in-memory walker of notebooks and loops) adds its
map, simulation and targets to it; :class:`walkerlab.gym.env.WalkerEnv` starts its episodes
from its gait.  Imports nothing heavy at module level (``import walkerlab.api`` stays light).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from walkerlab.integrate.solver import Solver

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from walkerlab.config import Scene

__all__ = ["STEP_EVALUATIONS", "Gait", "SceneWalker", "positive", "scene_of", "short"]

#: right-hand-side evaluations one walking step of the in-memory walker may take (a map is
#: one step, or a stride of two; :func:`walkerlab.integrate.work_limit.step_work_limit`), as
#: the gait search's budget
#: (:data:`walkerlab.analysis.gait.budget.ROOT_BUDGET_EVALUATIONS`): work, not time, so that
#: a step ends the same way on any machine
STEP_EVALUATIONS = 2_000_000


def short(value) -> str:
    """``repr(value)``, cut to 40 characters."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def scene_of(scene) -> Scene:
    """``scene`` itself (a :class:`walkerlab.config.Scene`), the scene of a mapping with the
    scene's sections (named ``"scene"`` unless it says), or of a YAML file.

    Raises
    ------
    walkerlab.config.SceneError
        File missing, malformed YAML, or fields that do not validate (one line each).
    """
    from walkerlab.config import Scene, load_scene, scene_from_dict  # light

    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, dict):
        data = dict(scene)
        data.setdefault("name", "scene")
        return scene_from_dict(data)
    return load_scene(scene)


def positive(value, name: str, unit: str = "right-hand-side evaluations") -> float:
    """``value`` as a positive finite float, else one line naming ``name`` (and ``unit``,
    what the number counts)."""
    import math
    import numbers

    from walkerlab.config import SceneError  # light

    if (isinstance(value, bool) or not isinstance(value, numbers.Real)
            or not math.isfinite(value) or value <= 0):
        raise SceneError(f"{name}={short(value)}: give a positive number of {unit}")
    return float(value)


@dataclass(frozen=True)
class Gait:
    """A period-1 gait (fixed point of the Poincaré map), as ``walkerlab fixedpoint`` finds it.

    Attributes
    ----------
    x : ndarray, shape (2n,)
        State just after heel strike (role order of ``names``) [rad, rad/s].
    names : tuple of str
        State names (:meth:`~walkerlab.api.walker.Walker.state_names`).
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
        max ``|P(x) - x|`` [state units].
    label : str
        Which gait of the search (``long_period``, ``short_period``, ...).
    step_length : float
        Mean step length [m]: stance foot to swing foot at heel strike
        (:func:`walkerlab.analysis.gait.metrics.step_length`).
    speed : float
        Distance along the ground over the map's period [m/s]: the step length (along the
        slope) over the step period.  Not :attr:`walkerlab.api.walks.Walk.speed` (the
        ``simulate`` stage's ``hip_speed``), the hip's *horizontal* displacement over the
        step's period: on a slope of angle phi that is ``cos(phi)`` times this, at the
        fixed point exactly (the paper's scene, phi = 0.0174 rad: 0.527902 against 0.527822
        m/s, 1.5e-4 lower; the same gait, two definitions).
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
    neutral : tuple of str
        The walker's neutral coordinates (:attr:`HybridWalker.neutral`, the 3D wheel's
        heading: its gaits form a family along it); their multipliers (1 on the family,
        the ``len(neutral)`` nearest 1) are set aside by :attr:`stable` and
        :attr:`max_abs_multiplier`.
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
    neutral: tuple = ()

    @property
    def state(self) -> dict[str, float]:
        """The fixed point by state name."""
        return {n: float(v) for n, v in zip(self.names, self.x)}

    @property
    def max_abs_multiplier(self) -> float:
        """Largest ``|Floquet multiplier|`` [-], the neutral ones (:attr:`neutral`) set
        aside."""
        import numpy as np

        from walkerlab.numerics import without_neutral  # light: numpy only

        return float(np.max(np.abs(without_neutral(self.multipliers, len(self.neutral)))))

    @property
    def stable(self) -> bool:
        """All ``|Floquet multipliers|`` < 1, the neutral ones (:attr:`neutral`) set aside."""
        return self.max_abs_multiplier < 1.0


def rebuilt(cls, plant, step_evaluations: int):
    """A :class:`SceneWalker` of class ``cls`` (or a subclass whose constructor only hands
    its plant up, :class:`walkerlab.api.walker.Walker`) built again from its plant and step
    work limit: what unpickling a walker calls.

    Returns
    -------
    SceneWalker
    """
    walker = cls.__new__(cls)
    SceneWalker.__init__(walker, plant, step_evaluations)
    return walker


class SceneWalker:
    """The rigid hybrid walker of a scene: the validated scene, its walker described
    (:attr:`plant`, a :class:`~walkerlab.walker.plant.Plant`), the generated model
    (:func:`walkerlab.models.registry.build_walker`) and the scene's integrator, built once
    (the attributes and errors of :class:`walkerlab.api.walker.Walker`, which extends it and
    builds the plant from its scene).

    Parameters
    ----------
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once, by the front that builds this walker (the API's
        :class:`walkerlab.api.walker.Walker`, the gym's environment): its ``scene`` is the
        walker's (:attr:`scene`).
    step_evaluations : int
        Right-hand-side evaluations each walking step may take [-]
        (:data:`STEP_EVALUATIONS`; work, not time: the same on any machine).

    Raises
    ------
    walkerlab.config.SceneError
        ``step_evaluations`` not a positive number.
    ValueError
        A walker or ground the rigid model does not carry (one line naming the key).
    """

    def __reduce__(self):
        """Pickled as its plant and step work limit (the model is built again: a compiled
        flow does not pickle; a process pool or a vector env's subprocess gets the same
        walker, of the same class: :func:`rebuilt`)."""
        return (rebuilt, (type(self), self.plant, self.step_evaluations))

    def __init__(self, plant, step_evaluations: int = STEP_EVALUATIONS):
        from walkerlab.models.registry import build_walker  # light

        self.step_evaluations = positive(step_evaluations, "step_evaluations")
        self.plant = plant  # described once by the front, handed to every analysis
        self.scene = scene = plant.scene
        self.model = build_walker(plant)
        self.solver = Solver.from_settings(scene.solver)
        fp = scene.fixedpoint
        self.max_step_time = 5.0 if fp is None else fp.max_step_time_s
        sim = scene.simulate
        self.walk_step_time = self.max_step_time if sim is None else sim.max_step_time_s

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

        from walkerlab.analysis.gait.scene import MAX_GUESS_RATE  # light
        from walkerlab.config import SceneError  # light

        names = self.state_names()
        want = (f"give the state as {len(names)} numbers ({', '.join(names)}) "
                "[rad, rad/s], e.g. gait.x")
        if x is None or isinstance(x, (str, bytes, dict)):
            raise SceneError(f"{what}={short(x)}: {want}")
        try:
            arr = np.asarray(x)
            if arr.dtype.kind not in "biuf" or arr.dtype.kind == "b":
                raise TypeError
            arr = arr.astype(float)
        except (TypeError, ValueError):
            raise SceneError(f"{what}={short(x)}: not numbers; {want}") from None
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

    def fixed_point(self) -> Gait:
        """The period-1 gait the ``fixedpoint`` stage finds, bit for bit (the same search:
        :func:`walkerlab.analysis.gait.scene.solve_scene`, on this walker's own model
        :attr:`model` and integrator :attr:`solver`: nothing is rebuilt from the scene; with
        the stage's check of each gait's ground contact, which the choice among several
        gaits prefers, and the stage's start: ``fixedpoint.initial_guess``, or the gait of
        the scene ``fixedpoint.from`` names carried here by homotopy,
        :func:`walkerlab.studies.continuation.homotopy_start`), without writing anything.

        Returns
        -------
        Gait
            The selected gait: ``x`` (2n,) [rad, rad/s], step and map periods [s], Floquet
            multipliers (2n,), the map's Jacobian (2n, 2n), step length [m], speed [m/s],
            cost of transport [-] and the energy ledger of the map's steps.

        Raises
        ------
        walkerlab.analysis.gait.search.GaitNotFound
            No gait (one line: what was tried, what to try next).
        walkerlab.config.SceneError
            ``fixedpoint.from`` names a scene that does not load (one line).
        ValueError
            A malformed initial guess or gait choice, or a ``fixedpoint.from`` gait that
            does not reach this walker (one line naming the field).
        """
        import numpy as np

        from walkerlab.analysis.gait.energy import gait_ledger  # light
        from walkerlab.analysis.gait.scene import solve_scene  # light

        _, search = solve_scene(self.scene, guess=self._known_start(), walker=self.model,
                                solver=self.solver, ground=True, plant=self.plant)
        chosen = search.gaits[search.selected]
        r = chosen.result
        m, ledger = gait_ledger(self.model, r.x, self.model.steps_per_map, self.solver,
                                self.max_step_time)
        return Gait(np.asarray(r.x, float), tuple(self.state_names()),
                    float(r.period_s) / self.model.steps_per_map, float(r.period_s),
                    np.asarray(r.multipliers_variational),
                    np.asarray(r.jacobian_variational), float(r.residual), chosen.label,
                    m["step_length"], m["speed"], m["cost_of_transport"], ledger,
                    tuple(getattr(r, "neutral", ())))

    def _known_start(self):
        """The start of the gait search carried from ``fixedpoint.from`` (as the
        ``fixedpoint`` stage: :func:`walkerlab.studies.continuation.known_scene`,
        :func:`~walkerlab.studies.continuation.homotopy_start`), None without one."""
        fp = self.scene.fixedpoint
        if fp is None or fp.from_ is None:
            return None
        from walkerlab.config import SceneError  # light
        from walkerlab.studies.continuation import homotopy_start, known_scene  # light

        try:
            src = known_scene(self.scene)
        except SceneError as exc:
            raise SceneError(f"fixedpoint.from: {exc}") from None
        return homotopy_start(self.scene, src, plant=self.plant)[0]
