"""Push-off and heel strike of a flat-footed rigid walker (:class:`FlatPushOff`,
:func:`push_off_flat`): the push-off impulse at the trailing toe, directed from it to the hip,
then the plastic heel strike that pins the leading heel, through the generated impact maps
of the foot modes (heel contact, foot flat, heel off: :data:`FLAT_PIN`, the point each mode
pins).  The point and arc feet's transition, and the shared :class:`~walkerlab.models.hybrid.
push_off.Transitions` protocol, are :mod:`walkerlab.models.hybrid.push_off`'s.

States stay the walker's own (role-ordered ``(2n,)``): nothing here knows their number.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from walkerlab.models.actuation import push_off_impulse
from walkerlab.models.hybrid.push_off import Transitions
from walkerlab.numerics import complex_step_jacobian

#: The stance foot's pinned point in each flat-foot mode (the toe in heel off).
FLAT_PIN = {"heel_contact": "heel", "foot_flat": "heel", "heel_off": "toe"}


@dataclass
class FlatPushOff(Transitions):
    """Push-off at the trailing toe of a flat foot, then the heel strike
    (:func:`walkerlab.codegen.foot_modes.derive_flat`'s ``push_off_<pin>`` systems).

    In the extended coordinates ``qe = (q, x_f, y_f)`` of the mode's pinned point (heel or
    toe), the impulse ``P`` at the stance toe along ``e`` (toe -> hip), the ankle's rate held
    through it (a massless foot passes an impulse off its ankle's line only with an
    impulsive ankle torque; the spring gives none, the joint holds)::

        [De  -a^T] [dqe' - dqe-]   [Jt^T P e]
        [a     0 ] [    lam    ] = [   0    ],      a = d(ankle)/dqe

    then the heel strike with the trailing foot free, ``Mi dq+ = Be dqe'`` (the swing heel
    pinned, the new stance ankle at its rest angle), and the role swap.  ``P = 0``: the
    generated passive heel strike (``Be [dq; 0] = B dq``).

    Attributes
    ----------
    spec : walkerlab.config.actuation.Actuation
    fns : dict
        The flat-footed walker's generated functions.
    ankle_push : object or None
        An ankle push-off acting with it
        (:class:`walkerlab.models.hybrid.ankle_push_off.AnklePushOffActuator`).
    pin : str or None
        ``heel`` or ``toe``: the pinned point of the mode the heel strike ends (None: read
        from the foot's angle, as the generated ``points``).
    torques : Actuators or None
        Joint torques acting with it (:class:`walkerlab.models.hybrid.actuators.Actuators`
        on the flat-foot modes, :mod:`walkerlab.models.hybrid.mode_torques`): their
        ``links``, ``power`` and per-step hook are read through this object.  Finite
        torques add no impulse: the transition is the same.
    """

    spec: object
    fns: dict
    ankle_push: object = None
    pin: str | None = None
    torques: object = None

    limit = False

    def __post_init__(self):
        self._memo: dict = {}
        self.ankle = None if self.ankle_push is None else self.ankle_push.ankle

    @property
    def links(self) -> list:
        """The joint torques' ``(first, second)`` links (empty without torques)."""
        return [] if self.torques is None else self.torques.links

    def power(self, t, x) -> float:
        """Mechanical power of the joint torques [W] (0 without torques; the ankle
        push-off's is ``torque(a) da/dt`` in heel off, apart)."""
        return 0.0 if self.torques is None else self.torques.power(t, x)

    def begin_step(self, t0: float) -> None:
        """The integrator's per-step hook (the joint torques' time origin, if any)."""
        if self.torques is not None:
            self.torques.begin_step(t0)

    def torque(self, a: float) -> float:
        """The ankle push-off's torque [N m] at ankle angle ``a`` [rad] (0 without one)."""
        return 0.0 if self.ankle_push is None else self.ankle_push.torque(a)

    def at(self, pin: str) -> FlatPushOff:
        """The transition of the mode pinned at ``pin`` (``heel`` or ``toe``)."""
        return FlatPushOff(self.spec, self.fns, self.ankle_push, pin, self.torques)

    def _pin(self, x) -> str:
        """The pinned point: this transition's, else the toe once the foot's angle from the
        slope ``phi`` is below -1e-12 rad (heel up), as the generated ``points`` read it."""
        if self.pin is not None:
            return self.pin
        return "toe" if float(self.fns["guard_foot_angle"](0.0, np.real(x))) < -1e-12 \
            else "heel"

    def impulse(self, x) -> float:
        """Push-off impulse ``P`` [N s] for the pre-impact state ``x`` (6,) (>= 0)."""
        po = self.spec.push_off
        if po is None or po.speed_gain_n_s2_per_m == 0.0:
            return push_off_impulse(po, 0.0)
        d = self.fns[f"push_off_{self._pin(x)}"](x[:3])
        v = np.asarray(d["Jh"]) @ x[3:]
        return push_off_impulse(po, np.sqrt(v @ v))

    def _transition(self, x) -> dict:
        q, dq = x[:3], x[3:]
        d = self.fns[f"push_off_{self._pin(x)}"](q)
        De, Jt, Mi, Be = (np.asarray(d[k]) for k in ("De", "Jt", "Mi", "Be"))
        r = np.asarray(d["push"])
        e = r / np.sqrt(r @ r)
        P = self.impulse(x)
        a = np.zeros(5)
        a[2] = 1.0  # the stance ankle's angle
        K = np.zeros((6, 6), dtype=np.result_type(De, x))
        K[:5, :5], K[:5, 5], K[5, :5] = De, -a, a
        dqe = np.concatenate([dq, np.zeros(2, dtype=dq.dtype)])
        dqe_po = dqe + np.linalg.solve(K, np.concatenate([Jt.T @ (P * e), [0.0]]))[:5]
        dq_plus = np.linalg.solve(Mi, Be @ dqe_po)
        qn = np.asarray(d["relabel_q"]).reshape(-1)
        ke = (0.5 * dqe @ De @ dqe, 0.5 * dqe_po @ De @ dqe_po, 0.5 * dq_plus @ Mi @ dq_plus)
        return {"x_plus": np.concatenate([qn, np.asarray(d["relabel_rate"]) @ dq_plus]),
                "impulse": P, "ke_minus": ke[0], "ke_push_off": ke[1], "ke_plus": ke[2]}


def push_off_flat(walker, fns: dict, spec, ankle_push=None, torques=None):
    """The flat-footed ``walker`` with the push-off at its trailing toe before every heel
    strike (:class:`FlatPushOff`: each phase's heel-strike guard gets its mode's transition,
    its Jacobian by the complex step).

    Parameters
    ----------
    walker : HybridWalker
        A flat-footed walker (:func:`walkerlab.models.hybrid.rigid_foot_modes.make_flat_walker`).
    fns : dict
        Its generated functions (the walker's own numbers: the heel strike's).
    spec : walkerlab.config.actuation.Actuation
    ankle_push : AnklePushOffActuator, optional
        An ankle push-off acting in heel off as well.
    torques : Actuators, optional
        Joint torques acting as well (already in ``walker``'s flows).

    Returns
    -------
    HybridWalker
        With ``actuators`` the :class:`FlatPushOff` (its pin read from the state).
    """
    acts = FlatPushOff(spec, fns, ankle_push, torques=torques)
    by_pin = {pin: acts.at(pin) for pin in ("heel", "toe")}

    def jac(tr):
        return lambda x: complex_step_jacobian(tr.reset, x)

    phases = []
    for ph in walker.phases:
        mode = ph.name.split(":", 1)[0]
        if not any(g.outcome == "heel_strike" for g in ph.guards) or mode not in FLAT_PIN:
            phases.append(ph)  # no heel strike from here (double support ends at toe off)
            continue
        tr = by_pin[FLAT_PIN[mode]]
        guards = tuple(replace(g, reset=tr.reset, reset_jacobian=jac(tr))
                       if g.outcome == "heel_strike" else g for g in ph.guards)
        phases.append(replace(ph, guards=guards))
    heel = by_pin["heel"]
    return replace(walker, phases=tuple(phases), reset=heel.reset, reset_jacobian=jac(heel),
                   actuators=acts)
