"""Hip torques on a walker with flat feet in the rigid view: each stance-foot mode's
generated flow (:mod:`walkerlab.codegen.foot_modes`) gains the torque's acceleration
``M_mode^-1 B tau`` (``B = d(swing - stance)/dq``: ``+tau`` on the swing leg, ``-tau`` on the
stance leg, none on the ankle coordinate, which is the sole's angle from the stance leg), in
foot flat through the locked foot (``a . qdd = 0``, ``a = d phi / dq``:
:meth:`walkerlab.models.hybrid.actuated.Actuators.added_acceleration`).  ``M_mode`` is the
Hessian in the rates of the mode's generated kinetic energy (heel- or toe-pinned
kinematics), read exactly by polarisation (the energy is quadratic in the rates).  The
guards read the ground forces through the actuated flow (a hip torque is internal: the
ground reaction's formula from the accelerations holds); resets stay the walker's.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from walkerlab.models.hybrid.base import HybridWalker
from walkerlab.numerics import fd_jacobian

__all__ = ["actuate_flat_hips", "mode_mass_matrix"]

#: the stance foot's pinned point in each mode
PIN = {"heel_contact": "heel", "foot_flat": "heel", "heel_off": "toe"}


def mode_mass_matrix(kinetic, x) -> np.ndarray:
    """The mass matrix (n, n) of a kinetic energy ``kinetic(x) -> {"kinetic": T}`` at the
    angles of ``x`` (2n,): ``M_ii = 2 T(q, e_i)``, ``M_ij = T(q, e_i + e_j) - T(q, e_i) -
    T(q, e_j)`` (exact for ``T = dq^T M(q) dq / 2``)."""
    x = np.real(np.asarray(x))
    n = x.size // 2
    eye = np.eye(n)

    def T(dq):
        return float(kinetic(np.concatenate([x[:n], dq]))["kinetic"])
    d = [T(eye[i]) for i in range(n)]
    M = np.diag(2.0 * np.array(d))
    for i in range(n):
        for j in range(i + 1, n):
            M[i, j] = M[j, i] = T(eye[i] + eye[j]) - d[i] - d[j]
    return M


def actuate_flat_hips(walker: HybridWalker, data, spec) -> HybridWalker:
    """The flat-footed walker with its hip torques (module docstring).

    Raises
    ------
    ValueError
        A torque on another joint or per foot mass, legs that differ (one line).
    """
    from walkerlab.codegen.cache import functions
    from walkerlab.models.hybrid.actuators import Actuators
    from walkerlab.models.hybrid.rigid_foot_modes import make_flat_walker

    for i, t in enumerate(spec.torques):
        if t.joint != "hip" or t.scaled_by != "none":
            raise ValueError(f"walker.actuation.torques.{i}: flat feet take hip torques "
                             "(joint: hip, scaled_by: none)")
    if data.structure.asymmetric:
        raise ValueError("walker.actuation.torques: legs that differ are not supported on "
                         "flat feet yet")
    f = functions(data)
    n = len(walker.roles)
    acts = Actuators(spec, f, n, False, float(walker.total_mass_kg))

    def flow_of(mode, flow, jac):
        kinetic = f[f"energies_{PIN[mode]}"]
        lock = (lambda x: np.asarray(f["grad_foot_angle"](np.real(x)))[:n]) \
            if mode == "foot_flat" else None

        def acc(t, x):
            return acts.added_acceleration(t, x, lock, mode_mass_matrix(kinetic, x))

        def fl(t, x):
            out = np.array(flow(t, x), float)
            out[n:] += acc(t, x)
            return out

        def J(t, x):
            out = np.array(jac(t, x), float)
            out[n:] += fd_jacobian(lambda z: acc(t, z), np.asarray(x, float), 1e-7)
            return out
        return fl, J

    w = make_flat_walker(data, walker.name, walker.variant, flow_of=flow_of)
    return replace(w, actuators=acts)
