"""The state layout of a walker view: what the state vector's rows are, by name.

Every view of a walker (the rigid hybrid model, the floating contact model) has a state
``x = [q, qd]`` of ``2 n`` rows: ``n`` generalised coordinates, then their rates in the same
order.  :class:`StateLayout` is the one place that knows this; code outside the model layer
(analysis, sweeps, stages, plots, report, io) asks a walker for its layout
(``walker.layout()``) and addresses states by name, never by row number or by a count of its
own (the rule in the project's STYLE: "state by name, sized by the walker").

=========================  =================================================================
view                       coordinates (``n``), state names, units
=========================  =================================================================
rigid (``HybridWalker``)   roles, e.g. ``swing, stance`` or ``swing_thigh, swing_shank,
                           stance``; states ``<role>_angle`` [rad], ``<role>_rate`` [rad/s]
floating (``ContactWalker``) ``hip_x, hip_y, leg1_angle, leg2_angle`` (or ``leg{i}_thigh_angle``,
                           ``leg{i}_shank_angle``); states ``hip_x`` [m] ... ``theta1`` [rad],
                           rates ``vhip_x`` [m/s] ... ``dtheta1`` [rad/s]
=========================  =================================================================

Legs and coordinates: a coordinate belongs to leg (or role) ``L`` when its name is ``L`` or
starts with ``L_`` (``swing_thigh`` to ``swing``, ``leg1_shank_angle`` to ``leg1``); the
floating base (``hip_x``, ``hip_y``) and a torso belong to no leg.

The rigid -> floating map (:func:`floating_links_from_rigid`): the rigid model's step starts
with ``leg1`` swinging (paper Eq. 11), so floating link ``leg1_<link>_angle`` takes the rigid
``swing_<link>`` angle, or the straight swing leg's ``swing`` angle when the rigid leg has no
such link (a knee the rigid model holds straight); ``leg2`` likewise from ``stance``; a
hinged torso's ``torso_angle`` takes the rigid ``torso`` angle (no leg: no role swap, its rate
not scaled).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

#: The rigid model's role of each floating leg on the first step (paper Eq. 11).
ROLE_OF_LEG = {"leg1": "swing", "leg2": "stance"}


@dataclass(frozen=True)
class StateLayout:
    """Names, units and slices of a walker view's state ``x = [q, qd]`` (2n,).

    Attributes
    ----------
    coordinates : tuple of str, shape (n,)
        Generalised coordinate names, in state order.
    names : tuple of str, shape (2n,)
        State names: the coordinates' states, then their rates (same order).
    units : tuple of str, shape (2n,)
        Unit of each state (``rad``, ``rad/s``, ``m``, ``m/s``).

    Raises
    ------
    ValueError
        ``names`` or ``units`` are not twice as long as ``coordinates``, or names repeat.
    """

    coordinates: tuple[str, ...]
    names: tuple[str, ...]
    units: tuple[str, ...]

    def __post_init__(self):
        n = len(self.coordinates)
        if len(self.names) != 2 * n or len(self.units) != 2 * n:
            raise ValueError(f"a state layout of {n} coordinates needs {2 * n} names and "
                             f"units (got {len(self.names)}, {len(self.units)})")
        if len(set(self.names)) != len(self.names):
            raise ValueError(f"state names repeat: {self.names}")

    # ------------------------------------------------------------------ construction
    @classmethod
    def rigid(cls, roles) -> StateLayout:
        """Layout of a rigid hybrid walker with coordinate ``roles`` (``HybridWalker.roles``):
        states ``<role>_angle`` [rad] then ``<role>_rate`` [rad/s]."""
        roles = tuple(roles)
        return cls(roles, tuple(f"{r}_angle" for r in roles)
                   + tuple(f"{r}_rate" for r in roles),
                   ("rad",) * len(roles) + ("rad/s",) * len(roles))

    @classmethod
    def floating(cls, coordinates, names, units) -> StateLayout:
        """Layout of a floating (contact) view: ``coordinates`` as
        :func:`walkerlab.codegen.floating.coordinate_names`, ``names`` and ``units`` (2n,) as
        the contact walker's ``state_names()`` / ``state_units()``."""
        return cls(tuple(coordinates), tuple(names), tuple(units))

    # ------------------------------------------------------------------ sizes and slices
    @property
    def n_coordinates(self) -> int:
        """Number of generalised coordinates ``n``."""
        return len(self.coordinates)

    @property
    def size(self) -> int:
        """Number of states ``2 n``."""
        return len(self.names)

    @property
    def q_slice(self) -> slice:
        """Rows of the coordinates in a state (first axis)."""
        return slice(0, self.n_coordinates)

    @property
    def qd_slice(self) -> slice:
        """Rows of the rates in a state (first axis)."""
        return slice(self.n_coordinates, self.size)

    def zeros(self) -> np.ndarray:
        """A zero state (2n,)."""
        return np.zeros(self.size)

    def q(self, X) -> np.ndarray:
        """Coordinates of ``X`` (2n,) or (2n, k) -> (n,) or (n, k)."""
        return np.asarray(X)[self.q_slice]

    def qd(self, X) -> np.ndarray:
        """Rates of ``X`` (2n,) or (2n, k) -> (n,) or (n, k)."""
        return np.asarray(X)[self.qd_slice]

    def join(self, q, qd) -> np.ndarray:
        """The state (2n,) from coordinates ``q`` (n,) and rates ``qd`` (n,).

        Raises
        ------
        ValueError
            ``q`` or ``qd`` does not have n entries.
        """
        q, qd = np.asarray(q, float).ravel(), np.asarray(qd, float).ravel()
        if q.size != self.n_coordinates or qd.size != self.n_coordinates:
            raise ValueError(f"a state of this walker has {self.n_coordinates} coordinates "
                             f"and {self.n_coordinates} rates (got {q.size}, {qd.size})")
        return np.concatenate([q, qd])

    def state_rows(self, Y) -> np.ndarray:
        """The state rows (2n, ...) of an augmented array ``Y`` whose first rows are the state
        (e.g. a dense output of the state and its variational equations)."""
        return np.asarray(Y)[:self.size]

    # ------------------------------------------------------------------ names
    def index(self, name: str) -> int:
        """Row of state ``name``.

        Raises
        ------
        KeyError
            No state of that name (the message lists the names).
        """
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"no state {name!r}; states: {', '.join(self.names)}") from None

    def rate_of(self, name: str) -> str:
        """Name of the rate state of coordinate state ``name`` (``theta1`` -> ``dtheta1``).

        Raises
        ------
        KeyError
            ``name`` is not a coordinate's state.
        """
        i = self.index(name)
        if i >= self.n_coordinates:
            raise KeyError(f"{name!r} is a rate, not a coordinate's state")
        return self.names[i + self.n_coordinates]

    def named(self, X) -> dict[str, np.ndarray]:
        """``{state name: X[row]}`` for ``X`` (2n,) or (2n, k)."""
        X = np.asarray(X)
        return {nm: X[i] for i, nm in enumerate(self.names)}

    def coordinate_values(self, X) -> tuple[dict, dict]:
        """``({coordinate: value}, {coordinate: rate})`` of ``X`` (2n,) or (2n, k)."""
        X = np.asarray(X)
        n = self.n_coordinates
        return ({c: X[i] for i, c in enumerate(self.coordinates)},
                {c: X[n + i] for i, c in enumerate(self.coordinates)})

    # ------------------------------------------------------------------ legs
    def coordinates_of(self, leg: str) -> tuple[str, ...]:
        """Coordinates of ``leg`` (a role ``swing``/``stance`` or a leg ``leg1``/``leg2``),
        proximal first, in state order."""
        return tuple(c for c in self.coordinates if c == leg or c.startswith(leg + "_"))

    def leg_of(self, coordinate: str) -> str | None:
        """The leg or role (``swing``, ``stance``, ``leg1``, ``leg2``) of ``coordinate``, or
        None (the floating base, a torso, the slope-relative ``hip`` angle)."""
        head = coordinate.split("_", 1)[0]
        return head if head in ("swing", "stance", "leg1", "leg2") else None

    def scale_rates(self, x, scale: Mapping[str, float]) -> np.ndarray:
        """A copy of state ``x`` (2n,) with each leg's rates multiplied by ``scale[leg]``
        (e.g. ``{"swing": 1.02, "stance": 1.0}``, the contact model's initial rate scale).

        Raises
        ------
        ValueError
            A coordinate belongs to no leg of ``scale`` (its rate could not be scaled
            consistently, e.g. the slope-relative ``hip`` angle).
        """
        out = np.array(x, dtype=float)
        n = self.n_coordinates
        for i, c in enumerate(self.coordinates):
            leg = self.leg_of(c)
            if leg not in scale:
                raise ValueError(f"coordinate {c!r} belongs to no leg of {sorted(scale)}: "
                                 "its rate cannot be scaled by leg")
            out[n + i] *= float(scale[leg])
        return out


def floating_links_from_rigid(values: Mapping[str, float], floating: StateLayout,
                              rate_scale=(1.0, 1.0)) -> np.ndarray:
    """The floating view's link state ``z = [link angles, their rates]`` (the coordinates that
    belong to a leg, and a hinged torso's, in state order) from the rigid model's named
    values.

    Parameters
    ----------
    values : mapping
        Rigid values by name, ``<role>_angle`` [rad] and ``<role>_rate`` [rad/s] for the roles
        ``swing``/``stance`` (straight legs, e.g. a rigid walker's ``leg_angles``) or their
        links (``swing_thigh``, ``swing_shank``); ``leg1`` is the swing leg (module docstring).
    floating : StateLayout
        The floating view's layout.
    rate_scale : (float, float)
        Multipliers on leg1's and leg2's rates.

    Returns
    -------
    ndarray (2 m,)
        ``m`` = number of link coordinates of ``floating``.

    Raises
    ------
    KeyError
        ``values`` lack a link's angle or rate (neither ``<role>_<link>`` nor ``<role>``).
    """
    scale = dict(zip(ROLE_OF_LEG, (float(rate_scale[0]), float(rate_scale[1]))))
    angles, rates = [], []
    for c in floating.coordinates:
        leg = floating.leg_of(c)
        if c == "torso_angle":  # a hinged torso: the rigid view's own torso coordinate
            angles.append(values["torso_angle"])
            rates.append(values["torso_rate"])
            continue
        if leg not in ROLE_OF_LEG:
            continue
        role = ROLE_OF_LEG[leg]
        link = c[len(leg) + 1:-len("angle")]  # "" or "thigh_"
        own = f"{role}_{link}"
        src = own if f"{own}angle" in values else f"{role}_"
        angles.append(values[f"{src}angle"])
        rates.append(scale[leg] * values[f"{src}rate"])
    return np.array(angles + rates, dtype=float)


class StateIndex:
    """Columns of a walker's state by name, never by number: a view of the walker's
    :class:`~walkerlab.walker.layout.StateLayout` (``walker.layout()``).

    ``idx["hip_x"]`` is a column; :meth:`rate_of` the column of a coordinate's rate;
    :attr:`coordinates` the columns of the coordinates q, :attr:`rates` of their rates.
    """

    def __init__(self, walker):
        self.layout = walker.layout()
        self.names = self.layout.names
        self._col = {n: i for i, n in enumerate(self.names)}
        self.n = self.layout.size

    def __getitem__(self, name: str) -> int:
        return self._col[name]

    @property
    def coordinates(self) -> slice:
        """Columns of the generalised coordinates q."""
        return self.layout.q_slice

    @property
    def rates(self) -> slice:
        """Columns of the rates."""
        return self.layout.qd_slice

    def rate_of(self, name: str) -> int:
        """Column of the rate of coordinate state ``name``."""
        return self._col[self.layout.rate_of(name)]

