"""Push-off and heel strike: the step-to-step transition of a powered rigid walker (Kuo
2002's pre-emptive push-off impulse, then the plastic heel strike), through the generated
impact maps, for every foot kind.

The push-off is an impulse ``P`` [N s] at the trailing (stance) foot's material contact
point, directed from that point to the hip, the foot being free for it; then the plastic
heel strike pins the leading foot.  The contact point is

- a point foot: the foot;
- an arc foot: the arc's lowest point (the rolling contact, ``stance_contact``);
- a flat foot: the trailing toe (:class:`FlatPushOff`).

Point and arc feet share one form.  In the extended coordinates ``qe = (q, x_f, y_f)`` (the
stance foot free, :func:`walkerlab.codegen.symbolic.derive`'s ``De, E``: ``De`` the mass
matrix, ``E`` the leading foot's material contact point's Jacobian) the trailing contact's
material point moves at ``(dx_f, dy_f)`` (for an arc the rolling offset's rate cancels its
spin about its centre), so ``E_f = [0 | I]`` and::

    De (dqe_po - dqe-) = E_f^T P e,        e = (hip - contact) / |hip - contact|
    [De  -E^T] [dqe+]   [De dqe_po]
    [E     0 ] [ F  ] = [    0    ]

With ``P = 0`` this is the generated passive heel strike (tests show both to round-off).
A kneed walker holds its swing knee through both impulses (the constraint's gradient,
:meth:`PushOffTransition.hold_lock`); a free-jointed walker (the five-link biped) holds
nothing: its generated ``De, E`` (:func:`walkerlab.codegen.free_joints.derive_five_link`)
carry every link, the push-off along the virtual trailing leg (stance foot to hip).  A
walker with massless legs (only the hip carries mass) has a singular ``De``: its
transition is written for the hip mass directly (Kuo 2002, Eq. 2 and its appendix).
Flat feet: :class:`FlatPushOff`.

States stay the walker's own (role-ordered ``(2n,)``): nothing here knows their number.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from walkerlab.models.actuation import push_off_impulse
from walkerlab.numerics import complex_step_jacobian

__all__ = ["FlatPushOff", "PushOffTransition", "Transitions", "leg_rate_jacobian",
           "push_off_flat"]


class Transitions:
    """Memo of recent transitions (pre-impact state bytes -> result): the reset's result,
    asked again by the energy ledger and the step table."""

    def transition(self, x) -> dict:
        """Push-off and heel strike from the pre-impact state ``x`` (2n,).

        Returns
        -------
        dict
            ``x_plus`` (2n,) the post-impact state, roles swapped; ``impulse`` P [N s];
            ``ke_minus``, ``ke_push_off``, ``ke_plus`` kinetic energies [J] before the
            push-off, after it and after the heel strike.
        """
        x = np.asarray(x)
        key = None if np.iscomplexobj(x) else x.tobytes()
        if key is not None and key in self._memo:
            return self._memo[key]
        out = self._transition(x)
        if key is not None:
            if len(self._memo) >= 256:
                self._memo.pop(next(iter(self._memo)))
            self._memo[key] = out
        return out

    def reset(self, x) -> np.ndarray:
        """Post-impact state (2n,) after push-off and heel strike (roles swapped)."""
        return self.transition(x)["x_plus"]


def leg_rate_jacobian(leg_angles, n: int) -> tuple[tuple[str, str], np.ndarray]:
    """The legs the hip joins and their absolute angles' Jacobian ``A = d(psi_sw,
    psi_st)/dq``, exact: the generated leg angles' rates are linear in ``dq``, so ``A``'s
    columns are the rates at unit ``dq`` (and ``q = 0``).

    Parameters
    ----------
    leg_angles : callable
        The generated model's ``leg_angles(x)`` (2n,) -> dict of angles and rates.
    n : int
        Number of generalised coordinates.

    Returns
    -------
    legs : (str, str)
        ``("swing", "stance")``, or a kneed walker's ``("swing_thigh", "stance_thigh")``.
    A : ndarray (2, n)
        [-] (angle per generalised coordinate, every one an angle).
    """
    eye, z = np.eye(n), np.zeros(n)
    rows = [leg_angles(np.concatenate([z, eye[k]])) for k in range(n)]
    legs = ("swing_thigh", "stance_thigh") if "swing_thigh_rate" in rows[0] \
        else ("swing", "stance")
    return legs, np.array([[float(r[f"{legs[0]}_rate"]) for r in rows],
                           [float(r[f"{legs[1]}_rate"]) for r in rows]])

@dataclass
class PushOffTransition(Transitions):
    """Push-off and heel strike of a point- or arc-footed walker (module docstring).

    Attributes
    ----------
    spec : walkerlab.config.actuation.Actuation
        Its ``push_off`` law (None: ``P = 0``).
    fns : dict
        The generated model's functions (``impact_matrices``, ``points``,
        ``point_velocities``, ``leg_angles``, ``reset``).
    n : int
        Number of generalised coordinates.
    limit : bool
        The legs are massless (the walker's equations are the limit ``m_foot -> 0``).
    hip_mass_kg : float
    """

    spec: object
    fns: dict
    n: int
    limit: bool
    hip_mass_kg: float

    def __post_init__(self):
        # the role swap's rate map R = A^-1 S A (A: the absolute leg angles' Jacobian)
        _legs, A = leg_rate_jacobian(self.fns["leg_angles"], self.n)
        swap = np.array([[0.0, 1.0], [1.0, 0.0]])  # the legs' absolute angles trade places
        self.R = np.linalg.pinv(A) @ swap @ A
        self.lock = None  # the gradient (n,) of a constraint held through the transition
        self._memo: dict = {}

    def hold_lock(self, lock) -> None:
        """Hold the constraint whose gradient is ``lock(x)`` (n,) (a locked swing knee)
        through the push-off and the heel strike, as the passive heel strike does (McGeer
        1990); the role swap's rate map is then the swap of the generated reset's positions
        (affine in ``q``: central differences of unit step are exact), since a kneed leg's
        thigh and shank both take the straight leg's rate."""
        self.lock = lock
        self.swap_from_reset()

    def swap_from_reset(self) -> None:
        """Take the role swap's rate map ``R`` (n, n) from the generated reset's positions
        (affine in ``q``: central differences of unit step are exact): the swap of every
        coordinate, where the legs' absolute angles alone do not fix it (a locked knee's
        thigh and shank, a free-jointed walker's links, McGeer 1990; Westervelt et al.
        2003, Sec. III-B)."""
        n, z = self.n, np.zeros(self.n)
        pos = self.fns["reset"]
        self.R = np.stack([(np.real(pos(np.concatenate([e, z])))[:n]
                            - np.real(pos(np.concatenate([-e, z])))[:n]) / 2.0
                           for e in np.eye(n)], axis=1)
        self._memo.clear()

    def hip_velocity(self, x) -> np.ndarray:
        """Hip velocity (2,) [m/s] (world x forward, y up) of a state ``x`` (2n,), from the
        generated ``point_velocities`` (analytic in the whole state: complex-step safe)."""
        return np.asarray(self.fns["point_velocities"](x)["hip"])

    def point_jacobians(self, q, names) -> np.ndarray:
        """The named points' position Jacobians stacked (2 len(names), n) at ``q`` (n,),
        column ``k`` the points' velocities for ``dq = e_k`` (exact, and analytic in ``q``:
        complex-step safe)."""
        eye = np.eye(self.n)
        cols = []
        for k in range(self.n):
            v = self.fns["point_velocities"](np.concatenate([q, eye[k]]))
            cols.append(np.concatenate([np.asarray(v[name]) for name in names]))
        return np.array(cols).T

    def impulse(self, x) -> float:
        """Push-off impulse ``P`` [N s] for the pre-impact state ``x`` (>= 0)."""
        po = self.spec.push_off
        if po is None or po.speed_gain_n_s2_per_m == 0.0:
            return push_off_impulse(po, 0.0)
        v = self.hip_velocity(x)
        return push_off_impulse(po, np.sqrt(v @ v))

    def direction(self, x) -> np.ndarray:
        """The push-off's unit direction (2,): from the trailing foot's contact point (an
        arc's ``stance_contact``, else the stance foot at the origin) to the hip."""
        pts = self.fns["points"](x)
        r = np.asarray(pts["hip"])
        if "stance_contact" in pts:
            r = r - np.asarray(pts["stance_contact"])
        return r / np.sqrt(r @ r)

    def relabel(self, q):
        """New coordinates (n,) after the role swap and the rate map ``R`` (n, n)."""
        qn = np.real(self.fns["reset"](np.concatenate([np.real(q), np.zeros(self.n)]))[:self.n])
        return qn, self.R

    def _transition(self, x) -> dict:
        n = self.n
        q, dq = x[:n], x[n:]
        P = self.impulse(x)
        if self.limit:
            return self._transition_point_hip(x, P)
        De, E = self.fns["impact_matrices"](q)
        De, E = np.asarray(De), np.asarray(E)
        e = self.direction(x)
        dqe = np.concatenate([dq, np.zeros(2)])
        Ef = np.zeros((2, n + 2))
        Ef[:, n:] = np.eye(2)
        if self.lock is None:
            dqe_po = dqe + np.linalg.solve(De, Ef.T @ (P * e))
            K = np.zeros((n + 4, n + 4), dtype=np.result_type(De, E))
            K[:n + 2, :n + 2], K[:n + 2, n + 2:], K[n + 2:, :n + 2] = De, -E.T, E
            sol = np.linalg.solve(K, np.concatenate([De @ dqe_po, np.zeros(2)]))
        else:  # the swing knee locked through both impulses (as the passive heel strike)
            a = np.concatenate([np.asarray(self.lock(x)), np.zeros(2)])[None, :]
            A = np.zeros((n + 3, n + 3), dtype=np.result_type(De, a))
            A[:n + 2, :n + 2], A[:n + 2, n + 2:], A[n + 2:, :n + 2] = De, -a.T, a
            dqe_po = np.linalg.solve(A, np.concatenate([De @ dqe + Ef.T @ (P * e),
                                                        np.zeros(1)]))[:n + 2]
            C = np.vstack([E, a])
            K = np.zeros((n + 5, n + 5), dtype=np.result_type(De, C))
            K[:n + 2, :n + 2], K[:n + 2, n + 2:], K[n + 2:, :n + 2] = De, -C.T, C
            sol = np.linalg.solve(K, np.concatenate([De @ dqe_po, np.zeros(3)]))
        dq_plus = sol[:n]
        qn, R = self.relabel(np.real(q))
        qn = qn + R @ (q - np.real(q))  # the swap is affine: exact for a complex step too
        ke = (0.5 * dqe @ De @ dqe, 0.5 * dqe_po @ De @ dqe_po, 0.5 * sol[:n + 2] @ De
              @ sol[:n + 2])
        return {"x_plus": np.concatenate([qn, R @ dq_plus]),
                "impulse": P, "ke_minus": ke[0], "ke_push_off": ke[1], "ke_plus": ke[2]}

    def _transition_point_hip(self, x, P):
        """Push-off and heel strike of a point hip mass on massless legs (Kuo 2002, Eq. 2
        and its appendix); analytic in ``x`` (every point and Jacobian from the generated
        ``points``/``point_velocities``, the least-squares solve by its normal equations with
        a plain transpose), so the reset's Jacobian by the complex step is exact."""
        n, M = self.n, self.hip_mass_kg
        q = x[:n]
        pts = self.fns["points"](x)
        v = self.hip_velocity(x)
        hip, lead = np.asarray(pts["hip"]), np.asarray(pts["swing_foot"])
        et = hip / np.sqrt(hip @ hip)          # trailing leg: stance foot at the origin
        el = (hip - lead) / np.sqrt((hip - lead) @ (hip - lead))
        v_po = v + (P / M) * et
        v_plus = v_po - (v_po @ el) * el
        v_foot = (v_plus @ et) * et            # the trailing foot: no velocity across its leg
        qn, R = self.relabel(np.real(q))
        qn = qn + R @ (q - np.real(q))         # the swap is affine: exact for a complex step
        Jn = self.point_jacobians(qn, ("hip", "swing_foot"))   # (4, n), full column rank
        dq_plus = np.linalg.solve(Jn.T @ Jn, Jn.T @ np.concatenate([v_plus, v_foot]))
        ke = (0.5 * M * (v @ v), 0.5 * M * (v_po @ v_po), 0.5 * M * (v_plus @ v_plus))
        return {"x_plus": np.concatenate([qn, dq_plus]), "impulse": P, "ke_minus": ke[0],
                "ke_push_off": ke[1], "ke_plus": ke[2]}


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
