"""Push-off and heel strike: the step-to-step transition of a powered rigid walker (Kuo
2002's pre-emptive push-off impulse, then the plastic heel strike), through the generated
impact maps, for every foot kind.

The push-off is an impulse ``P`` [N s] at the trailing (stance) foot's material contact
point, directed from that point to the hip, the foot being free for it; then the plastic
heel strike pins the leading foot.  The contact point is

- a point foot: the foot;
- an arc foot: the arc's lowest point (the rolling contact, ``stance_contact``);
- a flat foot: the trailing toe
  (:class:`walkerlab.models.hybrid.toe_push_off.FlatPushOff`).

Point and arc feet share one form.  In the extended coordinates ``qe = (q, x_f, y_f)`` (the
stance foot free, :func:`walkerlab.codegen.legged.derive_legged`'s ``De, E``: ``De`` the mass
matrix, ``E`` the leading foot's material contact point's Jacobian) the trailing contact's
material point moves at ``(dx_f, dy_f)`` (for an arc the rolling offset's rate cancels its
spin about its centre), so ``E_f = [0 | I]`` and::

    De (dqe_po - dqe-) = E_f^T P e,        e = (hip - contact) / |hip - contact|
    [De  -E^T] [dqe+]   [De dqe_po]
    [E     0 ] [ F  ] = [    0    ]

With ``P = 0`` this is the generated passive heel strike (tests show both to round-off).
A kneed walker holds its swing knee through both impulses (the constraint's gradient,
:meth:`PushOffTransition.hold_lock`); a free-jointed walker (the five-link biped) holds
nothing: its generated ``De, E`` (:func:`walkerlab.codegen.legged.derive_legged`)
carry every link, the push-off along the virtual trailing leg (stance foot to hip).  A
walker with massless legs (only the hip carries mass) has a singular ``De``: its
transition is written for the hip mass directly (Kuo 2002, Eq. 2 and its appendix).
Flat feet: :mod:`walkerlab.models.hybrid.toe_push_off`.

States stay the walker's own (role-ordered ``(2n,)``): nothing here knows their number.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.models.actuation import push_off_impulse

__all__ = ["PushOffTransition", "Transitions", "leg_rate_jacobian"]


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

        def swap(q0, h):
            return np.stack([(np.real(pos(np.concatenate([q0 + h * e, z])))[:n]
                              - np.real(pos(np.concatenate([q0 - h * e, z])))[:n]) / (2 * h)
                             for e in np.eye(n)], axis=1)

        try:
            R = swap(z, 1.0)
        except ZeroDivisionError:  # the reset's impact singular at a unit step from q = 0
            R = None  # (both legs vertical under an upper body on the bisecting hip)
        if R is None or not np.all(np.isfinite(R)):
            # the positions are affine in q: a generic nearby point gives the same map
            R = swap(0.05 * (1.0 + np.arange(n)) / n, 0.1)
        self.R = R
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
        # the trailing leg's hip: a walker in 3D with hip width names its own (its
        # ``stance_hip``, w/2 from the pelvis' ``hip``); a planar walker's legs share one
        r = np.asarray(pts["stance_hip"] if "stance_hip" in pts else pts["hip"])
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
        k = len(De) - n  # the foot's translations: 2 (planar), 3 (a walker in 3D)
        dqe = np.concatenate([dq, np.zeros(k)])
        Ef = np.zeros((k, n + k))
        Ef[:, n:] = np.eye(k)
        if self.lock is None:
            dqe_po = dqe + np.linalg.solve(De, Ef.T @ (P * e))
            K = np.zeros((n + 2 * k, n + 2 * k), dtype=np.result_type(De, E))
            K[:n + k, :n + k], K[:n + k, n + k:], K[n + k:, :n + k] = De, -E.T, E
            sol = np.linalg.solve(K, np.concatenate([De @ dqe_po, np.zeros(k)]))
        else:  # the swing knee locked through both impulses (as the passive heel strike)
            a = np.concatenate([np.asarray(self.lock(x)), np.zeros(k)])[None, :]
            A = np.zeros((n + k + 1, n + k + 1), dtype=np.result_type(De, a))
            A[:n + k, :n + k], A[:n + k, n + k:], A[n + k:, :n + k] = De, -a.T, a
            dqe_po = np.linalg.solve(A, np.concatenate([De @ dqe + Ef.T @ (P * e),
                                                        np.zeros(1)]))[:n + k]
            C = np.vstack([E, a])
            K = np.zeros((n + 2 * k + 1, n + 2 * k + 1), dtype=np.result_type(De, C))
            K[:n + k, :n + k], K[:n + k, n + k:], K[n + k:, :n + k] = De, -C.T, C
            sol = np.linalg.solve(K, np.concatenate([De @ dqe_po, np.zeros(k + 1)]))
        dq_plus = sol[:n]
        qn, R = self.relabel(np.real(q))
        qn = qn + R @ (q - np.real(q))  # the swap is affine: exact for a complex step too
        ke = (0.5 * dqe @ De @ dqe, 0.5 * dqe_po @ De @ dqe_po, 0.5 * sol[:n + k] @ De
              @ sol[:n + k])
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
