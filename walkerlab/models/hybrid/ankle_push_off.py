"""Ankle push-off of a walker on flat feet in the rigid view
(``walker.actuation.ankle_push_off``): from heel off until heel strike a pre-loaded ankle
spring is released and/or a constant plantarflexion torque acts, as Mizani et al. (2018;
the paper's ref. [32]) power the walker in ADAMS.

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

from walkerlab.codegen.cache import functions
from walkerlab.models.hybrid.base import HybridWalker
from walkerlab.models.hybrid.mode_torques import actuate_flat_hips
from walkerlab.models.hybrid.rigid_foot_modes import make_flat_walker
from walkerlab.models.hybrid.toe_push_off import FlatPushOff, push_off_flat

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

    Legs that differ: ``data`` is one step's (its stance leg's ankle numbers ``k_st_ankle``,
    ``r_st_ankle``), the next step's walker takes its own.

    Raises
    ------
    ValueError
        A total ankle stiffness of 0 with a constant torque (one line): the released
        spring's rest angle ``r_eff`` would be infinite (a constant torque on a massless
        foot with no spring to balance it has no heel-off flow).
    """
    st = data.structure
    tag = "st_" if st.asymmetric else ""  # the stance leg's own numbers when legs differ
    po = spec.ankle_push_off
    names = list(st.param_names)
    p = np.array(data.params, float)
    ik, ir = names.index(f"k_{tag}ankle"), names.index(f"r_{tag}ankle")
    k, r = p[ik], p[ir]
    kt = k + po.stiffness_n_m_per_rad
    if kt <= 0.0:
        raise ValueError("walker.actuation.ankle_push_off: a constant torque needs an ankle "
                         "spring (leg.foot.ankle.stiffness_n_m_per_rad > 0)")
    p[ik] = kt
    p[ir] = (k * r + po.stiffness_n_m_per_rad * po.rest_angle_rad - po.constant_n_m) / kt
    return replace(data, params=tuple(float(v) for v in p), mirror_params=None)


def actuate_flat(walker: HybridWalker, data, spec) -> HybridWalker:
    """The flat-footed walker with its actuators, any of them together: joint torques
    (:func:`walkerlab.models.hybrid.mode_torques.actuate_flat_hips`), the ankle push-off
    in heel off (module docstring) and the push-off impulse at the trailing toe before heel
    strike (:func:`walkerlab.models.hybrid.toe_push_off.push_off_flat`).  Legs that differ:
    each step's walker on its own numbers (``mirror``).

    Returns
    -------
    HybridWalker
        Its ``actuators``: the torques' :class:`walkerlab.models.hybrid.actuators.Actuators`
        (torques alone), an :class:`AnklePushOffActuator` (the ankle push-off alone) or a
        :class:`walkerlab.models.hybrid.toe_push_off.FlatPushOff` carrying every one given.

    Raises
    ------
    ValueError
        A joint the walker does not have, a torque per foot mass, an ankle push-off's
        constant torque without an ankle spring (one line, naming the field).
    """
    if spec.torques and spec.push_off is None and spec.ankle_push_off is None:
        return actuate_flat_hips(walker, data, spec)
    if data.mirror is None:
        return _actuate_flat_step(walker, data, spec)
    w = _actuate_flat_step(walker, replace(data, mirror_params=None), spec)
    # legs that differ: the next step's walker (leg2 swinging) on its own numbers
    return replace(w, mirror=_actuate_flat_step(
        walker.mirror, replace(data.mirror, mirror_params=None), spec))


def _actuate_flat_step(walker: HybridWalker, data, spec) -> HybridWalker:
    """One step's flat-footed walker (``data`` without ``mirror_params``, or legs alike)
    with the push-off impulse and/or the ankle push-off, and joint torques if any."""

    walker = replace(walker, mirror=None)  # one step's (legs that differ: set by the caller)
    off = None if spec.ankle_push_off is None else heel_off_data(data, spec)
    torques = None
    if spec.torques:
        w = actuate_flat_hips(walker, replace(data, mirror_params=None), spec, off)
        torques = w.actuators
    elif off is not None:
        w = make_flat_walker(data, walker.name, walker.variant, off,
                             double_support=walker.step_entry is not None,
                             landing_m=walker.params.get("landing_drop_m", 0.0))
    else:
        w = walker
    ankle = None if off is None else AnklePushOffActuator(
        spec, list(w.roles).index("stance_ankle"))
    if spec.push_off is not None:  # the impulse at the toe before heel strike
        return push_off_flat(w, functions(data), spec, ankle, torques)
    if torques is None:
        return replace(w, actuators=ankle)
    return replace(w, actuators=FlatPushOff(spec, functions(data), ankle, torques=torques))


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
