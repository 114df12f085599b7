"""A walker's floating view (:mod:`walkerlab.codegen.floating`: the same walker with no
foot pinned, coordinates ``[hip_x, hip_y, link angles]`` in the plane, a 3D body tree set
free at its stance foot) as plain Python: its mass matrix and bias ``M(q)``, ``h(q, dq)``,
its feet's contact points, material velocities and Jacobians, their velocity gradients,
its energies and named points (:class:`FloatingView`), which the ground reaction of
:mod:`walkerlab.models.hybrid.ground_reaction` reads and the checks against other libraries
(Pinocchio, MuJoCo, Drake) compare.
"""

from __future__ import annotations

import numpy as np

from walkerlab.codegen.floating import (
    contact_names,
    coordinate_names,
    floating_params,
    floating_plain,
)

__all__ = ["FloatingView"]


class FloatingView:
    """The generated floating module's kernels (:mod:`walkerlab.codegen.floating`: ``dyn``,
    ``feet``, ``feet_jac``) run as the plain Python they are generated from
    (:func:`~walkerlab.codegen.floating.floating_plain`): a check of a few hundred states
    loads no numba and compiles nothing.

    Parameters
    ----------
    data : walkerlab.walker.description.WalkerData
        The walker's structure and numbers.
    foot_mass_kg, foot_inertia_kg_m2 : float, optional
        A flat foot's mass [kg] (at the ankle) and inertia about the ankle [kg m^2], for
        a walker whose feet carry none (:func:`~walkerlab.codegen.floating.floating_params`).

    Attributes
    ----------
    params : ndarray
        The floating view's parameters (:func:`~walkerlab.codegen.floating.floating_params`).
    nq, dim : int
        Its coordinates' count and the contact points' dimension (2 in the plane, 3 in 3D).
    names, coordinates : tuple of str
        Its contact points' and coordinates' names.

    Raises
    ------
    ValueError
        A massless body (:data:`walkerlab.codegen.floating.MASSLESS_MESSAGE`); flat feet of
        no mass without ``foot_mass_kg`` and ``foot_inertia_kg_m2``.
    """

    def __init__(self, data, foot_mass_kg: float | None = None,
                 foot_inertia_kg_m2: float | None = None):
        mod = floating_plain(data.structure)  # raises for a massless body
        self.params = np.asarray(floating_params(data, foot_mass_kg, foot_inertia_kg_m2),
                                 float)
        self.nq, self.dim = int(mod["NQ"]), int(mod["DIM"])
        self.names = contact_names(data.structure)
        self.coordinates = coordinate_names(data.structure)
        self._dyn, self._feet, self._feet_jac = mod["dyn"], mod["feet"], mod["feet_jac"]
        self._energies, self._points = mod["energies"], mod["points"]

    def coordinate_names(self) -> tuple[str, ...]:
        """The generalised coordinates, in order (:attr:`coordinates`)."""
        return self.coordinates

    def contact_names(self) -> tuple[str, ...]:
        """The contact points, in order (:attr:`names`)."""
        return self.names

    def _x(self, q, dq=None) -> np.ndarray:
        return np.concatenate([q, np.zeros(self.nq) if dq is None else dq])

    def dynamics(self, q, dq) -> tuple[np.ndarray, np.ndarray]:
        """``M(q)`` (nq, nq) and ``h(q, dq)`` (nq,)."""
        M, h = np.empty((self.nq, self.nq)), np.empty(self.nq)
        self._dyn(self._x(q, dq), self.params, M, h)
        return M, h

    def mass_matrix(self, q) -> np.ndarray:
        """``M(q)`` (nq, nq) [kg, kg m, kg m^2]."""
        return self.dynamics(q, None)[0]

    def bias(self, q, dq) -> np.ndarray:
        """``h(q, dq) = C(q, dq) dq + G(q)`` (nq,) [N, N m]: ``M qdd + h = sum J^T F``."""
        return self.dynamics(q, dq)[1]

    def gravity(self, q) -> np.ndarray:
        """``G(q) = h(q, 0)`` (nq,) [N, N m]."""
        return self.dynamics(q, None)[1]

    def energies(self, X) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic and potential energy [J] of states ``X`` (2 nq,) or (2 nq, k)."""
        return self._energies(X, self.params)

    def points(self, X) -> dict:
        """Named points (hip, bodies, feet, knees) (d,) or (d, k) [m], named as the rigid
        model's, of states ``X`` (2 nq,) or (2 nq, k)."""
        return self._points(X, self.params)

    def contact_points(self, q, dq=None):
        """Contact points (nf, d) [m], material velocities (nf, d) [m/s], Jacobians
        (nf, d, nq) (``d`` 2 in the plane, 3 in 3D: world axes)."""
        nf, d = len(self.names), self.dim
        P, V, J = np.empty((nf, d)), np.empty((nf, d)), np.empty((nf, d, self.nq))
        self._feet(self._x(q, dq), self.params, P, V, J)
        return P, V, J

    def velocity_gradient(self, q, dq) -> np.ndarray:
        """``d V_i / dq`` (nf, d, nq) at fixed rates: ``(dV/dq) dq = Jdot dq``."""
        nf, d = len(self.names), self.dim
        dV, dJtF = np.empty((nf, d, self.nq)), np.empty((self.nq, self.nq))
        self._feet_jac(self._x(q, dq), np.zeros((nf, d)), self.params, dV, dJtF)
        return dV
