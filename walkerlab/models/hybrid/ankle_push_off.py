"""Ankle push-off of a walker on flat feet in the rigid view (``walker.actuation.
ankle_push_off``): from heel off until heel strike a pre-loaded ankle spring is released
and/or a constant plantarflexion torque acts, as Mizani et al. (2018; the paper's ref. [32])
power the walker in ADAMS.

On the stance ankle angle ``a`` (the sole's angle from the stance leg's perpendicular,
positive toe up; :mod:`walkerlab.codegen.foot_modes`) the ankle spring gives ``-k (a - r)``;
the push-off adds ``-k_po (a - r_po) - tau_0``.  The sum is again a linear spring,
``-(k + k_po) (a - r_eff)`` with ``r_eff = (k r + k_po r_po - tau_0) / (k + k_po)``, so the
heel-off mode runs on the walker's own generated equations with the ankle numbers
``(k + k_po, r_eff)`` bound instead: exact, compiled with the rest, and its ground forces and
saltation at heel off follow.  Guards, resets and energies stay the walker's (the new stance
foot lands at its own rest angle).  The push-off's work over a step is
``W = -int (k_po (a - r_po) + tau_0) da`` over heel off (:func:`ankle_push_off_work`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from walkerlab.models.hybrid.base import HybridWalker

__all__ = ["AnklePushOffActuator", "actuate_flat", "ankle_push_off_work", "heel_off_data"]


@dataclass
class AnklePushOffActuator:
    """The ankle push-off bound to a walker (its ``actuators``).

    Attributes
    ----------
    spec : walkerlab.config.actuation.Actuation
    ankle : int
        Index of the stance ankle's angle in the state.
    """

    spec: object
    ankle: int

    limit = False

    def begin_step(self, t0: float) -> None:
        """No time-based law here (the integrator's per-step hook)."""

    def torque(self, a: float) -> float:
        """The push-off's torque on the ankle coordinate [N m] at ankle angle ``a`` [rad]."""
        po = self.spec.ankle_push_off
        return -po.stiffness_n_m_per_rad * (a - po.rest_angle_rad) - po.constant_n_m


def heel_off_data(data, spec):
    """The walker's data with the heel-off mode's ankle numbers ``(k + k_po, r_eff)``.

    Raises
    ------
    ValueError
        Legs that differ, or a total ankle stiffness of 0 with a constant torque (one line).
    """
    st = data.structure
    if st.asymmetric:
        raise ValueError("walker.actuation.ankle_push_off: legs that differ are not "
                         "supported yet")
    po = spec.ankle_push_off
    names = list(st.param_names)
    p = np.array(data.params, float)
    k, r = p[names.index("k_ankle")], p[names.index("r_ankle")]
    kt = k + po.stiffness_n_m_per_rad
    if kt <= 0.0:
        raise ValueError("walker.actuation.ankle_push_off: a constant torque needs an ankle "
                         "spring (leg.foot.ankle.stiffness_n_m_per_rad > 0)")
    p[names.index("k_ankle")] = kt
    p[names.index("r_ankle")] = (k * r + po.stiffness_n_m_per_rad * po.rest_angle_rad
                                 - po.constant_n_m) / kt
    return replace(data, params=tuple(float(v) for v in p))


def actuate_flat(walker: HybridWalker, data, spec) -> HybridWalker:
    """The flat-footed walker with its ankle push-off (module docstring), a push-off impulse
    at the trailing toe (:func:`walkerlab.models.hybrid.push_off.push_off_flat`), both, or
    with hip torques alone (:func:`walkerlab.models.hybrid.flat_hip_torque.actuate_flat_hips`).

    Raises
    ------
    ValueError
        Hip torques with a push-off (not written yet), legs that differ with an ankle
        push-off (one line).
    """
    from walkerlab.codegen.cache import functions
    from walkerlab.models.hybrid.push_off import push_off_flat
    from walkerlab.models.hybrid.rigid_foot_modes import make_flat_walker

    if spec.torques and spec.push_off is None and spec.ankle_push_off is None:
        from walkerlab.models.hybrid.flat_hip_torque import actuate_flat_hips

        return actuate_flat_hips(walker, data, spec)
    if spec.torques:
        raise ValueError("walker.actuation: flat feet take hip torques alone today (not with "
                         "push_off or ankle_push_off)")
    if spec.ankle_push_off is None:  # the push-off impulse at the trailing toe alone
        w = push_off_flat(walker, functions(data), spec)
        if walker.mirror is not None:  # legs that differ: the next step's walker too
            w = replace(w, mirror=push_off_flat(
                walker.mirror, functions(replace(data.mirror, mirror_params=None)), spec))
        return w
    w = make_flat_walker(data, walker.name, walker.variant, heel_off_data(data, spec))
    ankle = AnklePushOffActuator(spec, list(w.roles).index("stance_ankle"))
    if spec.push_off is not None:  # and the impulse at the toe before heel strike
        return push_off_flat(w, functions(data), spec, ankle)
    return replace(w, actuators=ankle)


def ankle_push_off_work(walker: HybridWalker, seg) -> float:
    """Work [J] of the ankle push-off over one step (``seg`` a
    :class:`~walkerlab.integrate.rigid.Segment`): ``int torque(a) da`` over its heel-off
    pieces (Gauss-Legendre on the dense output, 32 nodes a piece)."""
    acts = walker.actuators
    n2 = seg.x_start.size
    i, j = acts.ankle, acts.ankle + n2 // 2
    s, wq = np.polynomial.legendre.leggauss(32)
    work = 0.0
    for ph, sol, (ta, tb) in seg.pieces:
        if not ph.name.startswith("heel_off") or tb <= ta:
            continue
        t = 0.5 * (tb - ta) * s + 0.5 * (tb + ta)
        y = np.asarray(sol(t), float)[:n2]
        work += 0.5 * (tb - ta) * float(np.sum(wq * np.array(
            [acts.torque(a) for a in y[i]]) * y[j]))
    return work
