"""Joint torques on a walker with flat feet in the rigid view: each stance-foot mode's
generated flow (:mod:`walkerlab.codegen.foot_modes`) gains the torques' acceleration
``M_mode^-1 B tau`` (:class:`walkerlab.models.hybrid.actuators.Actuators`: ``B^T =
d(delta)/dq`` of each joint's angle, the hip between the legs, a torso's hips, the ankles
(``stance_ankle``: the ankle coordinate itself; the swing foot is held at its rest angle,
so its ankle's torque has a zero row)), in foot flat through the locked foot (``a @ qdd =
0``, ``a = d phi / dq``:
:meth:`walkerlab.models.hybrid.actuators.Actuators.added_acceleration`).  ``M_mode`` is the
Hessian in the rates of the mode's generated kinetic energy (heel- or toe-pinned
kinematics), read exactly by polarisation (the energy is quadratic in the rates;
complex-safe in the angles, so the added acceleration's Jacobian is the complex step's).
The guards read the ground forces through the actuated flow (a joint torque is internal:
the ground reaction's formula from the accelerations holds); resets stay the walker's.
The double support after heel strike (the trailing toe pinned,
:func:`walkerlab.models.hybrid.rigid_foot_modes.double_support_phases`) is kept: its closed
chain gains the torques' generalised force, ``[M -J^T; J 0] [qdd; lam] = [-h + B tau; -dJ
dq]``, so its flow, the toe-off guard's and the falls' contact forces and the step entry's
check of the trailing toe's force all carry the torque (the swing foot's ankle has no row
there either: the trailing foot's ankle angle is no coordinate of ``q``).
Legs that differ: the next step's walker (``mirror``) gets its own actuators on its own
numbers.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.models.hybrid.actuators import Actuators
from walkerlab.models.hybrid.base import HybridWalker
from walkerlab.models.hybrid.rigid_foot_modes import make_flat_walker
from walkerlab.numerics import complex_step_jacobian

__all__ = ["actuate_flat_hips", "mode_mass_matrix"]

#: the stance foot's pinned point in each mode
PIN = {"heel_contact": "heel", "foot_flat": "heel", "heel_off": "toe"}


def mode_mass_matrix(kinetic, x) -> np.ndarray:
    """The mass matrix (n, n) of a kinetic energy ``kinetic(x) -> {"kinetic": T}`` at the
    angles of ``x`` (2n,): ``M_ii = 2 T(q, e_i)``, ``M_ij = T(q, e_i + e_j) - T(q, e_i) -
    T(q, e_j)`` (exact for ``T = dq^T M(q) dq / 2``; complex angles give the complex
    step's derivative, the rates being real)."""
    x = np.asarray(x)
    n = x.size // 2
    eye = np.eye(n)
    q = x[:n]

    def T(dq):
        return kinetic(np.concatenate([q, dq]))["kinetic"]
    d = [T(eye[i]) for i in range(n)]
    M = np.zeros((n, n), dtype=np.result_type(x, float))
    for i in range(n):
        M[i, i] = 2.0 * d[i]
        for j in range(i + 1, n):
            M[i, j] = M[j, i] = T(eye[i] + eye[j]) - d[i] - d[j]
    return M


def actuate_flat_hips(walker: HybridWalker, data, spec, heel_off=None,
                      actuators=None) -> HybridWalker:
    """The flat-footed walker with its joint torques (module docstring).

    The double support is kept when ``walker`` has it (its ``step_entry``; a walker made
    with ``double_support=False`` stays without).

    ``heel_off``: the walker's data with the heel-off mode's ankle numbers of an ankle
    push-off acting as well (:func:`walkerlab.models.hybrid.ankle_push_off.heel_off_data`;
    then ``data`` is one step's, without ``mirror_params``), or None.

    ``actuators``: the :class:`~walkerlab.models.hybrid.actuators.Actuators` of ``spec``
    to act (a subclass whose torques are set from outside: the Gymnasium environment's
    action, :class:`walkerlab.gym.action.ActionTorques`), or None: built from ``spec``.
    Given, it acts on this step's walker only (``walker.mirror`` is dropped).

    Raises
    ------
    ValueError
        A joint the walker does not have (naming the joints it has), a torque per foot
        mass (flat feet carry massive legs) (one line).
    """

    for i, t in enumerate(spec.torques):
        if t.scaled_by != "none":
            raise ValueError(f"walker.actuation.torques.{i}.scaled_by: foot_mass is for "
                             "walkers whose legs are massless (flat feet need massive legs)")
    f = functions(data)
    n = len(walker.roles)
    acts = actuators if actuators is not None else Actuators(
        spec, f, n, False, float(walker.total_mass_kg), torso_mean=bool(data.structure.torso))

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
            out[n:] += complex_step_jacobian(lambda z: acc(t, z), np.asarray(x, float))
            return out
        return fl, J

    w = make_flat_walker(replace(data, mirror_params=None), walker.name, walker.variant,
                         heel_off, flow_of=flow_of, force=acts.generalised_force,
                         step_clock=lambda: acts.t_origin,
                         double_support=walker.step_entry is not None,
                         landing_m=walker.params.get("landing_drop_m", 0.0))
    mirror = walker.mirror if actuators is None else None
    if mirror is not None:  # legs that differ: the next step's walker, its own numbers
        mirror = actuate_flat_hips(mirror, data.mirror, spec)
    return replace(w, actuators=acts, mirror=mirror)
