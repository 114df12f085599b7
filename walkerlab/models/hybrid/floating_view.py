"""A rigid walker's floating view (:mod:`walkerlab.codegen.floating`: the same walker with no
foot pinned, coordinates ``[hip_x, hip_y, link angles]`` in the plane, a 3D body tree set
free at its stance foot) as plain Python: its mass matrix and bias ``M(q)``, ``h(q, dq)``,
its feet's contact points, material velocities and Jacobians, and their velocity
gradients (:class:`FloatingView`), which the ground reaction of
:mod:`walkerlab.models.hybrid.ground_reaction` reads.
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
        A massless body beside massive ones (no floating view).
    """

    def __init__(self, data):
        mod = floating_plain(data.structure)  # raises for a massless body
        self.params = np.asarray(floating_params(data), float)
        self.nq, self.dim = int(mod["NQ"]), int(mod["DIM"])
        self.names = contact_names(data.structure)
        self.coordinates = coordinate_names(data.structure)
        self._dyn, self._feet, self._feet_jac = mod["dyn"], mod["feet"], mod["feet_jac"]

    def _x(self, q, dq=None) -> np.ndarray:
        return np.concatenate([q, np.zeros(self.nq) if dq is None else dq])

    def dynamics(self, q, dq) -> tuple[np.ndarray, np.ndarray]:
        """``M(q)`` (nq, nq) and ``h(q, dq)`` (nq,)."""
        M, h = np.empty((self.nq, self.nq)), np.empty(self.nq)
        self._dyn(self._x(q, dq), self.params, M, h)
        return M, h

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
