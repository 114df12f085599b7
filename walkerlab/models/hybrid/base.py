"""The data structure every rigid hybrid walker model fills in - the contract downstream code
relies on.

A step of a hybrid walker is a sequence of continuous *phases* (compass gait: early swing
until the swing leg passes the stance leg, then late swing until heel strike; a kneed
walker adds a knee-locked phase; flat feet cross the stance foot's modes with early / late
swing, a guard naming the phase it leads to).  Each phase has a flow ``f(t, x)`` and named guards;
a guard either moves to the next phase (optionally through its own reset map, e.g. a knee
strike), ends the step with the reset map (heel strike), or ends the run (fall).  The analysis
layer (:mod:`walkerlab.integrate.rigid`) integrates any model described this way.

Contract of :class:`HybridWalker` (nothing outside the model layer may assume more)
-------------------------------------------------------------------------------------
``roles``
    Role-ordered generalised coordinates, prefixed ``swing``/``stance`` where they belong to
    a leg: ``("swing", "stance")`` for the compass gait, ``("stance", "hip")`` for the
    simplest walker (``hip`` = angle between the legs), e.g. ``("stance", "swing_thigh",
    "swing_shank")`` for a kneed walker, ``("swing", "stance", "stance_ankle")`` for flat
    feet on ankle springs.  ``n = len(roles)``; the state is ``x = [n angles,
    n rates]`` and its dimension is the same in every phase of a step (a locked knee is a
    constraint on the same coordinates, not fewer states).
``state_names()``, ``state_units()``
    2n names (``<role>_angle``, ``<role>_rate``) and units (``rad``, ``rad/s``).
``legs``, ``role_to_leg(stance_leg)``
    Physical legs ``("leg1", "leg2")`` (``leg1`` starts as the swing leg, paper Eq. 11) and
    the map ``{"stance": leg, "swing": other leg}`` for a step with ``stance_leg`` in stance.
``leg_coordinates(X, stance_leg)`` and ``coordinate_units``
    Physical, step-independent named series with the SAME keys on every step:
    ``leg1_angle, leg2_angle, leg1_rate, leg2_rate`` (absolute leg angles from the vertical,
    positive when the foot is ahead of the hip, and their rates) for every biped here, whatever
    its state coordinates.  ``X`` is (2n,) or (2n, k); values are () or (k,).
``points(X)``
    Positions [m] relative to the step's stance reference point (the stance foot for point
    feet), world axes (x horizontal downhill, y up; a 3D walker's also z, to the right of a
    walker facing downhill: (3,) or (3, k)); keys include ``hip``, ``stance_foot``,
    ``swing_foot``; role-prefixed names (``swing_mass``, ...) are mapped to legs by prefix.
    ``points(x_end)["swing_foot"]`` is the world offset of the next step's reference point.
``energies(X)``
    ``(kinetic, potential)`` [J]; potential relative to the reference point's height.
``params``
    Includes ``gravity_m_per_s2``, ``leg_length_m``, ``total_mass_kg``, ``slope_rad``.
``section``, ``from_section``, ``reset``, ``reset_jacobian``, ``variational``, ``heel_strike_guard``
    Poincaré-section coordinates (state minus the coordinate fixed by the heel-strike
    surface) and its inverse; heel-strike map incl. the role swap and its Jacobian (2n, 2n);
    flow Jacobian ``(t, x) -> (2n, 2n)``; the heel-strike guard function.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from walkerlab.walker.description import state_names, state_units
from walkerlab.walker.layout import StateLayout

Flow = Callable[[float, np.ndarray], np.ndarray]
GuardOutcome = Literal["next_phase", "heel_strike", "fall"]


#: Physical legs; ``leg1`` swings first (paper Eq. 11).
LEGS = ("leg1", "leg2")


class OffSection(RuntimeError):
    """``from_section(z)`` found no state on the post-impact surface with the section
    coordinates ``z`` (a landing the legs cannot reach from there: e.g. a stair riser higher
    than the stance leg's posture allows).  A root finder's iterate there is a failed map,
    as a fall is."""


class SectionInverse:
    """A walker's ``from_section`` whose domain errors are :class:`OffSection`: the generated
    inverse solves the guard for an angle (``acos``, ``sqrt``), and section coordinates no
    state on the surface has raise ``ValueError("math domain error")`` there - for a root
    finder that is a point off the surface, as an unreachable landing is.

    Parameters
    ----------
    inverse : callable ``z -> x``
        The generated inverse of ``section``.
    """

    def __init__(self, inverse: Callable[[np.ndarray], np.ndarray]):
        self.inverse = inverse

    def __call__(self, z: np.ndarray) -> np.ndarray:
        try:
            return self.inverse(z)
        except ValueError as exc:
            if "math domain error" not in str(exc):
                raise
            raise OffSection(f"no state on the heel-strike surface at section coordinates "
                             f"{np.asarray(z).tolist()} ({exc})") from None


def role_to_leg(stance_leg: str) -> dict[str, str]:
    """``{"stance": stance_leg, "swing": other leg}``.

    Raises
    ------
    KeyError
        ``stance_leg`` is not ``leg1`` or ``leg2``.
    """
    other = {"leg1": "leg2", "leg2": "leg1"}[stance_leg]
    return {"stance": stance_leg, "swing": other}


@dataclass(frozen=True)
class Guard:
    """A scalar guard function whose zero crossing (in ``direction``) triggers ``outcome``.

    Attributes
    ----------
    name : str
        Used as the event/termination label (``"heel_strike"``, ``"fall"``, ...).
    function : callable ``(t, x) -> float``
        Smooth guard function of the state ``x`` (shape ``(2n,)``).
    direction : {-1, 1, 0}
        Crossing direction as in ``scipy.integrate.solve_ivp`` events.
    outcome : {"next_phase", "heel_strike", "fall"}
        What happens when the guard fires.
    gradient : callable ``x -> (2n,)``, optional
        Gradient of ``function`` (saltation matrices); complex step on ``function`` if None.
    reset, reset_jacobian : callable, optional
        For ``next_phase`` guards: a map applied to the state when the guard fires (an
        intra-step impact such as a knee strike, state dimension unchanged) and its Jacobian.
        For a ``heel_strike`` guard: the heel-strike map of this phase (role swap included)
        in place of the walker's :attr:`HybridWalker.reset` (a flat foot's depends on the
        stance foot's mode).
    next_phase : str, optional
        For ``next_phase`` guards: the name of the phase that follows (the phases of a step
        then form a graph, e.g. a flat foot's modes crossed with early / late swing); None:
        the next phase in :attr:`HybridWalker.phases`.
    at_entry : bool
        Also fire when the phase begins on the guard's firing side (``function < 0`` for
        ``direction = -1``, ``> 0`` for ``+1``), which no zero crossing would report: a
        contact force that is already pulling when its contact mode begins (a flat foot's
        unilateral contacts).  False: crossings only.
    """

    name: str
    function: Callable[[float, np.ndarray], float]
    direction: int
    outcome: GuardOutcome
    gradient: Callable[[np.ndarray], np.ndarray] | None = None
    reset: Callable[[np.ndarray], np.ndarray] | None = None
    reset_jacobian: Callable[[np.ndarray], np.ndarray] | None = None
    next_phase: str | None = None
    at_entry: bool = False


@dataclass(frozen=True)
class Phase:
    """A continuous phase of a step: its flow and the guards active during it.

    ``jacobian`` is ``(t, x) -> d flow / dx`` (2n, 2n); ``variational``, if given, is the
    right-hand side of the variational equations in one call,
    ``(t, [x, Phi.ravel()]) -> [flow(t, x), (jacobian(t, x) @ Phi).ravel()]`` (2n + 4n^2,).

    ``compiled`` (optional) is a handle on the same flow compiled for CyRK's C++ integrators
    (:class:`walkerlab.models.compiled_flows.CompiledFlow`: ``address(variational)``, ``data()``),
    used by the ``cyrk_compiled`` solver backend.

    ``constraint`` (optional) is ``x -> (n,)``, the gradient in ``q`` of a holonomic
    constraint the flow holds (a locked knee: ``d(shank - thigh)/dq``); a joint torque added
    to such a phase acts through the constrained system (its share along the constraint is
    taken by the lock).  None: the flow is unconstrained.

    ``held_energy`` (optional) is ``x -> (energy [J], power [W])`` of a spring-damper the
    flow holds beyond the walker's ``energies`` (a flat foot's trailing ankle in double
    support: its spring's energy and its damper's power, <= 0), for the energy ledger.

    ``jacobian_rtol`` (optional) is the relative accuracy [-] of a numerical ``jacobian``
    (central differences: round-off ``eps / h``); the variational equations' rows
    ``Phi`` are integrated to no tighter a tolerance than it (tighter, the step-size
    control chases the differences' noise: DOP853 at ``rtol = 1e-12`` took 63,000
    right-hand sides for one double support of 0.09 s, 1,300 at this floor).  None: the
    Jacobian is exact (generated), and ``Phi`` gets the solver's tolerances.
    """

    name: str
    flow: Flow
    guards: tuple[Guard, ...]
    jacobian: Callable[[float, np.ndarray], np.ndarray] | None = None
    variational: Callable[[float, np.ndarray], np.ndarray] | None = None
    compiled: object | None = None
    constraint: Callable[[np.ndarray], np.ndarray] | None = None
    held_energy: Callable[[np.ndarray], tuple] | None = None
    jacobian_rtol: float | None = None


@dataclass(frozen=True)
class HybridWalker:
    """A rigid hybrid walker, described as data.

    Attributes
    ----------
    name : str
        Model name (``"compass_gait"``), stored in artifacts.
    variant : str
        Equation variant (``"derived"`` or ``"appendix_a"``).
    roles : tuple of str, shape (n,)
        Role of each generalized coordinate in the state, e.g. ``("swing", "stance")``.
    legs : tuple of str
        Physical leg names, e.g. ``("leg1", "leg2")``; ``leg1`` starts as the swing leg.
    phases : tuple of Phase
        Continuous phases of one step, in order.
    reset : callable ``x_minus (2n,) -> x_plus (2n,)``
        Impact map including the swap of leg roles (paper Eq. 8).
    energies : callable ``x (2n,) or (2n, k) -> (kinetic, potential)`` [J]
        Potential energy relative to the stance foot's height.
    points : callable ``x -> dict[str, ndarray (2,) or (2, k)]``
        Positions [m] of named points (``hip``, ``swing_foot``, masses) relative to the
        stance foot, world axes (x forward/downhill, y up).
    section : callable ``x -> ndarray``
        Coordinates that parametrise the Poincaré section (state minus the guard constraint).
    from_section : callable ``z -> x``
        Inverse of ``section`` on the guard surface; raises :class:`OffSection` where the
        surface has no state with those section coordinates.
    role_to_leg : callable ``(stance_leg: str) -> dict[role, leg]``
        Which physical leg plays each role when ``stance_leg`` is in stance.
    total_mass_kg : float
    slope_rad : float
    params : dict
        Numeric parameters (SI) for the record.
    variational : callable or None
        ``(t, x) -> (2n, 2n)`` Jacobian of the flow, for the variational equations.
    reset_jacobian : callable or None
        ``x_minus -> (2n, 2n)`` Jacobian of the reset map.
    heel_strike_guard : callable or None
        ``(t, x) -> float``, zero on the heel-strike surface.
    leg_angles : callable or None
        ``X -> {"stance_angle", "swing_angle", "stance_rate", "swing_rate"}`` absolute leg
        angles from the vertical [rad] and rates [rad/s], by role (used by
        :meth:`leg_coordinates`); None: the coordinates are already absolute leg angles.
    mirror : HybridWalker or None
        The walker of the steps with ``legs[0]`` in stance when they differ from this one's
        (legs that differ: same roles and state, other numbers); None when the legs are
        mirror images.  This walker takes the steps with ``legs[1]`` in stance (``legs[0]``
        swings first, paper Eq. 11); with a mirror the Poincaré map is a stride (two steps).
    mirror_reflection : tuple of str or None
        With a :attr:`mirror`: the state names (:meth:`state_names`) the reflection across
        the sagittal plane negates when it carries this walker's step onto the mirror's,
        ``P_mirror(x) = S P(S x)`` (:meth:`reflect`; a 3D walker with hip width, whose steps
        alternate sides: :attr:`walkerlab.walker.description.Structure.mirror_odd_roles`);
        None: the mirror is not a reflection (planar legs that differ) or there is none.
    actuators : walkerlab.models.hybrid.actuated.Actuators or None
        The walker's actuators (joint torques, push-off) bound to its model; None: passive.
    matrices : callable or None
        ``x (2n,) -> (M (n, n), C (n, n), G (n,))`` of the generated flow (the energy
        ledger's damper power); None for hand-written models.
    step_entry : callable or None
        ``x (2n,) -> (x (2n,), phase name or None)``, applied as each step begins (after
        the heel-strike map): the rest of the heel strike's impact where a second contact
        stays closed (a flat foot's trailing toe, kept on the ground when its impulse is
        compressive) and the phase the step begins in (None: ``phases[0]``).  None: the
        step begins in ``phases[0]`` from the reset's state.
    cycle : tuple of HybridWalker or None
        The walkers of the steps of one Poincaré map in order, when the ground differs from
        step to step (footholds of several heights or slopes,
        :func:`walkerlab.models.hybrid.ground.on_footholds`): step ``k`` of a walk is taken
        by ``cycle[k % len(cycle)]`` (:meth:`for_step`); None: :attr:`mirror` decides.
    neutral : tuple of str
        State names (:meth:`state_names`) of coordinates along which the walker's gaits
        form a family - one Floquet multiplier 1 each, named and set aside by the stability
        verdict, and held at the start by the fixed-point search (the 3D rimless wheel's
        ``heading_angle``: it rolls steadily at every heading, Coleman, Chatterjee & Ruina
        1997).  Empty for every planar walker.
    ground_steps : int or None
        Steps of a finite ground (``terrain.periodic: false``: a foothold list that does not
        repeat, of one height or several; a drawn rough ground): a walk stops after them.
        None: the ground goes on (:attr:`cycle`, if any, repeats).
    hip_x : callable or None
        ``x (2n,) or (2n, k) -> float or (k,)``: the hip's x [m] relative to the stance
        foot alone, ``points(x)["hip"][0]`` bit for bit (generated beside ``points``:
        :func:`walkerlab.codegen.printers.numpy_fn`'s slices); None: read it from
        ``points``.
    section_words : str
        What the Poincaré section's state is, in words for the outputs that print it
        (``fixedpoint``): "state just after heel strike"; flat feet with a double support:
        after the heel strike's impulse, before the trailing toe is pinned.
    closed_form_gait : callable or None
        ``() -> ndarray (2n,) or None``: the walker's period-1 gait in closed form, where
        one is known (the planar rimless wheel's, McGeer 1990), None when it has none at
        these numbers (it cannot roll over its stance foot); the attribute None: no closed
        form.
    creep_rate : callable or None
        ``x (2n,) -> float`` [m/s]: how fast the stance contact runs along the fall line
        ahead of the reference travel :attr:`points` and :attr:`energies` are measured at
        (feet curved in both directions, whose rolling is not holonomic:
        :func:`walkerlab.walker.foot_trees.creep_rate`); None: the points are the true ones.
    """

    name: str
    variant: str
    roles: tuple[str, ...]
    legs: tuple[str, ...]
    phases: tuple[Phase, ...]
    reset: Callable[[np.ndarray], np.ndarray]
    energies: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
    points: Callable[[np.ndarray], dict[str, np.ndarray]]
    section: Callable[[np.ndarray], np.ndarray]
    from_section: Callable[[np.ndarray], np.ndarray]
    role_to_leg: Callable[[str], dict[str, str]]
    total_mass_kg: float
    slope_rad: float
    params: dict = field(default_factory=dict)
    variational: Callable[[float, np.ndarray], np.ndarray] | None = None
    reset_jacobian: Callable[[np.ndarray], np.ndarray] | None = None
    heel_strike_guard: Callable[[float, np.ndarray], float] | None = None
    leg_angles: Callable[[np.ndarray], dict[str, np.ndarray]] | None = None
    mirror: HybridWalker | None = None
    mirror_reflection: tuple[str, ...] | None = None
    actuators: object | None = None
    matrices: Callable[[np.ndarray], tuple] | None = None
    step_entry: Callable[[np.ndarray], tuple] | None = None
    cycle: tuple | None = None
    ground_steps: int | None = None
    neutral: tuple[str, ...] = ()
    hip_x: Callable[[np.ndarray], float] | None = None
    section_words: str = "state just after heel strike"
    closed_form_gait: Callable[[], np.ndarray | None] | None = None
    creep_rate: Callable[[np.ndarray], float] | None = None

    def __post_init__(self):
        # the inverse of the section raises OffSection off the surface (SectionInverse)
        if not isinstance(self.from_section, SectionInverse):
            object.__setattr__(self, "from_section", SectionInverse(self.from_section))

    def for_step(self, k: int) -> HybridWalker:
        """The walker of step ``k`` (0-based from the map's start, ``legs[1]`` in stance
        first): ``cycle[k % len(cycle)]``, else this one or :attr:`mirror` by stance leg."""
        if self.cycle is not None:
            return self.cycle[k % len(self.cycle)]
        return self.for_stance(self.legs[1] if k % 2 == 0 else self.legs[0])

    def for_stance(self, stance_leg: str) -> HybridWalker:
        """The walker of a step with ``stance_leg`` in stance (this one or :attr:`mirror`)."""
        if self.mirror is not None and stance_leg == self.legs[0]:
            return self.mirror
        return self

    def reflect(self, X: np.ndarray) -> np.ndarray:
        """``S X``: the states ``X`` (2n,) or (N, 2n) with the :attr:`mirror_reflection`
        coordinates negated (a copy).

        Raises
        ------
        ValueError
            A walker whose mirror is not a reflection (``mirror_reflection`` None).
        """
        if self.mirror_reflection is None:
            raise ValueError(f"{self.name}: the next step is not a reflection of this one")
        names = self.state_names()
        S = np.array([-1.0 if n in self.mirror_reflection else 1.0 for n in names])
        return np.asarray(X, dtype=float) * S

    @property
    def steps_per_map(self) -> int:
        """Steps in one Poincaré map: 1 (mirror-image legs), 2 (a stride) or the period of
        :attr:`cycle` (a ground that differs from step to step)."""
        if self.cycle is not None:
            return len(self.cycle)
        return 1 if self.mirror is None else 2

    def with_steps_per_map(self, steps: int) -> HybridWalker:
        """This walker with a Poincaré map of ``steps`` steps: its own map composed
        ``steps / steps_per_map`` times (:attr:`cycle` the walkers of those steps, in order,
        :meth:`for_step`), so that a study whose members differ (a 3D walker's hip width
        from zero, a step map, to any other, a stride) compares one map at every point.
        The fixed points are the same; the Floquet multipliers are the ``steps /
        steps_per_map``-th powers of the walker's own (per stride: the squares of per step).

        Parameters
        ----------
        steps : int
            Steps of the map wanted (>= 1).

        Returns
        -------
        HybridWalker
            This walker itself when its map already has ``steps`` steps.

        Raises
        ------
        ValueError
            ``steps`` is not a multiple of :attr:`steps_per_map` (one line).
        """
        own = self.steps_per_map
        if steps == own:
            return self
        if steps < 1 or steps % own:
            raise ValueError(f"a map of {steps} steps is not made of this walker's maps of "
                             f"{own} step{'s' if own > 1 else ''}")
        return replace(self, cycle=tuple(self.for_step(k) for k in range(steps)))

    @property
    def n_coordinates(self) -> int:
        return len(self.roles)

    def layout(self):
        """The state layout (:class:`walkerlab.walker.layout.StateLayout`): names, units,
        q / qd slices and legs of the role-ordered state (2n,)."""
        return StateLayout.rigid(self.roles)

    def section_names(self) -> list[str]:
        """The state names of :attr:`section`'s coordinates, in its order (the state without
        the coordinates the heel-strike surface fixes)."""
        names = self.state_names()
        kept = self.section(np.arange(len(names), dtype=float))
        return [names[int(round(v))] for v in kept]

    def neutral_in_section(self) -> list[int]:
        """Positions of the :attr:`neutral` coordinates among :attr:`section`'s (empty for a
        walker without any)."""
        if not self.neutral:
            return []
        names = self.section_names()
        return [names.index(c) for c in self.neutral]

    def state_names(self) -> list[str]:
        """Role-ordered state names, e.g. ``['swing_angle', 'stance_angle', 'swing_rate', ...]``."""
        return state_names(self.roles)

    def state_units(self) -> list[str]:
        """Units of :meth:`state_names` (every coordinate is an angle)."""
        return state_units(self.roles)

    @property
    def coordinate_units(self) -> dict[str, str]:
        """Units of the :meth:`leg_coordinates` series, by name (in their order)."""
        X = np.zeros(2 * self.n_coordinates)
        return {k: ("rad/s" if k.endswith("_rate") else "rad")
                for k in self.leg_coordinates(X, self.legs[-1])}

    def leg_coordinates(self, X: np.ndarray, stance_leg: str) -> dict[str, np.ndarray]:
        """Absolute angle [rad] and rate [rad/s] of each physical leg, keyed ``<leg>_angle``,
        ``<leg>_rate`` (the same keys on every step).

        Parameters
        ----------
        X : ndarray, shape (2n,) or (2n, k)
            Role-ordered states of a step with ``stance_leg`` in stance.
        stance_leg : str
            One of :attr:`legs`.

        Returns
        -------
        dict[str, ndarray]
            Values of shape () or (k,).
        """
        X = np.asarray(X)
        n = self.n_coordinates
        if self.leg_angles is not None:
            by_role = self.leg_angles(X)
        else:
            by_role = {}
            for i, r in enumerate(self.roles):
                by_role[f"{r}_angle"], by_role[f"{r}_rate"] = X[i], X[n + i]
        r2l = self.role_to_leg(stance_leg)
        out = {}
        for key, val in by_role.items():
            role = next((r for r in sorted(r2l, key=len, reverse=True)
                         if key.startswith(r + "_")), None)
            # a coordinate on no leg (a torso) keeps its own name
            out[key if role is None else r2l[role] + key[len(role):]] = np.asarray(val)
        return out
