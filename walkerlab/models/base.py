"""The data structure every rigid hybrid walker model fills in.

A step of a hybrid walker is a sequence of continuous *phases* (compass gait: early swing
until the swing leg passes the stance leg, then late swing until heel strike; a kneed
walker would add a knee-locked phase).  Each phase has a flow ``f(t, x)`` and named guards;
a guard either moves to the next phase, ends the step with the reset map (heel strike), or
ends the run (fall).  The analysis layer (:mod:`walkerlab.analysis.hybrid`) integrates any
model described this way.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

Flow = Callable[[float, np.ndarray], np.ndarray]
GuardOutcome = Literal["next_phase", "heel_strike", "fall"]


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
    """

    name: str
    function: Callable[[float, np.ndarray], float]
    direction: int
    outcome: GuardOutcome


@dataclass(frozen=True)
class Phase:
    """A continuous phase of a step: its flow and the guards active during it."""

    name: str
    flow: Flow
    guards: tuple[Guard, ...]
    jacobian: Callable[[float, np.ndarray], np.ndarray] | None = None


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
        Inverse of ``section`` on the guard surface.
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

    @property
    def n_coordinates(self) -> int:
        return len(self.roles)

    def state_names(self) -> list[str]:
        """Role-ordered state names, e.g. ``['swing_angle', 'stance_angle', 'swing_rate', ...]``."""
        return [f"{r}_angle" for r in self.roles] + [f"{r}_rate" for r in self.roles]

    def state_units(self) -> list[str]:
        """Units of :meth:`state_names` (angles [rad], then rates [rad/s])."""
        n = self.n_coordinates
        return ["rad"] * n + ["rad/s"] * n

    def _physical_name(self, role: str, stance_leg: str) -> str:
        for prefix, leg in self.role_to_leg(stance_leg).items():
            if role == prefix or role.startswith(prefix + "_"):
                return leg + role[len(prefix):]
        return role

    def leg_coordinates(self, X: np.ndarray, stance_leg: str) -> dict[str, np.ndarray]:
        """Physical named series of a role-ordered state while ``stance_leg`` is in stance.

        Parameters
        ----------
        X : ndarray, shape (2n,) or (2n, k)
        stance_leg : str
            One of :attr:`legs`.

        Returns
        -------
        dict
            ``<leg>[_<part>]_angle`` [rad] and ``..._rate`` [rad/s] (compass gait:
            ``leg1_angle``, ``leg2_angle``, ``leg1_rate``, ``leg2_rate``); the keys do not
            depend on ``stance_leg``; coordinates not on a leg keep their role name.
        """
        X = np.asarray(X)
        n = self.n_coordinates
        out = {}
        for i, role in enumerate(self.roles):
            out[self._physical_name(role, stance_leg) + "_angle"] = X[i]
        for i, role in enumerate(self.roles):
            out[self._physical_name(role, stance_leg) + "_rate"] = X[n + i]
        return out

    @property
    def coordinate_units(self) -> dict[str, str]:
        """Unit of each key of :meth:`leg_coordinates`."""
        names = self.leg_coordinates(np.zeros(2 * self.n_coordinates), self.legs[-1])
        return {k: ("rad" if k.endswith("_angle") else "rad/s") for k in names}
