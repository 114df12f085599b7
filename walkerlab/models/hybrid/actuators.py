"""Actuators on a rigid hybrid walker: ``B(q) u`` in the flow (paper Eq. 3 with u != 0) and a
push-off impulse in the reset (Kuo 2002's two-impulse step-to-step transition).

Flow
----
``M(q) qdd + C(q, dq) dq + G(q) = B(q) tau``: each hip actuator's torque acts on the swing leg
(``+tau``) and on the stance leg (``-tau``), so its generalised force is ``tau d(delta)/dq``
with ``delta = psi_swing - psi_stance`` (the absolute leg angles; exact, from the generated
leg angles' rates).  The generated passive flow is kept and the actuation added:
``qdd = qdd_passive + M^-1 B tau``.  On a walker whose legs are massless (the limit
``m_foot -> 0`` of the simplest walker, whose equations are the rows of the absolute leg
angles divided by the foot mass), a torque ``scaled_by: foot_mass`` gives ``tau / m_foot``
and acts on the swing row only (Kuo 2002: it stays finite there and does no work).

Reset
-----
Push-off, then heel strike, then the roles swap.  The push-off is an impulse ``P`` at the
trailing (stance) foot along the trailing leg, from the foot towards the hip, the foot being
free for it; then the plastic heel strike pins the leading foot.  In the extended
coordinates ``qe = (q, x_f, y_f)`` (stance foot free, :func:`impact_matrices` of the
generated model: ``De`` its mass matrix, ``E`` the leading foot's Jacobian)::

    De (dqe_po - dqe-) = E_f^T P e,        E_f = d(x_f, y_f)/dqe,  e = (hip - foot)/|.|
    [De  -E^T] [dqe+]   [De dqe_po]
    [E     0 ] [ F  ] = [    0    ]

With ``P = 0`` this is the generated impact (tests show both to round-off).  A walker with
massless legs (only the hip carries mass) has a singular ``De``: its transition is written
for the hip mass directly: ``v_po = v- + (P / M) e``, the heel strike removes the velocity
along the new stance leg, the trailing foot keeps no velocity across its leg (Kuo 2002,
Eq. 2 and its appendix; ``tests/independent/actuated_compass.py`` derives both).

States stay the walker's own (role-ordered ``(2n,)``): nothing here knows their number.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.models.actuation import TorqueLaws
from walkerlab.models.hybrid.push_off import PushOffTransition
from walkerlab.numerics import complex_step_jacobian

__all__ = ["Actuators", "torque_chain_jacobian"]


@dataclass
class Actuators:
    """The actuators of one walker, bound to its generated model.

    Attributes
    ----------
    spec : walkerlab.config.actuation.Actuation
    fns : dict
        The generated model's functions (``matrices``, ``impact_matrices``, ``points``,
        ``leg_angles``, ``reset``, ``energies``).
    n : int
        Number of generalised coordinates.
    limit : bool
        The legs are massless (the walker's equations are the limit ``m_foot -> 0``).
    hip_mass_kg : float
    torque_jacobian : callable or None
        ``(t, x) -> (k, 2n)``: the torques' derivative by the state when it is known in
        closed form (a torque of time alone: zeros), set after construction; the flow's
        Jacobian is then :func:`torque_chain_jacobian`'s.  None (default): the complex step
        through :meth:`added_acceleration`.
    """

    spec: object
    fns: dict
    n: int
    limit: bool
    hip_mass_kg: float

    def __post_init__(self):
        eye = np.eye(self.n)
        la = self.fns["leg_angles"]
        z = np.zeros(self.n)
        # d(delta)/dq and the absolute leg angles' Jacobian A = d(psi_sw, psi_st)/dq, exact:
        # the generated leg angles' rates are linear in dq
        rows = [la(np.concatenate([z, eye[k]])) for k in range(self.n)]
        # the hip joins the thighs: a kneed walker's legs name them
        self.legs = ("swing_thigh", "stance_thigh") if "swing_thigh_rate" in rows[0] \
            else ("swing", "stance")
        self.A = np.array([[float(r[f"{self.legs[0]}_rate"]) for r in rows],
                           [float(r[f"{self.legs[1]}_rate"]) for r in rows]])
        self.ddelta_dq = self.A[0] - self.A[1]
        swap = np.array([[0.0, 1.0], [1.0, 0.0]])  # the legs' absolute angles trade places
        self.R = np.linalg.pinv(self.A) @ swap @ self.A
        self.laws = TorqueLaws(self.spec.torques)
        self.t_origin = 0.0  # the time [s] the present step began (time_reference laws)
        # (t, x) -> (k, 2n) the torques' derivative by the state, when known in closed form
        # (a torque of time alone: zeros); None: the complex step differentiates the torques
        self.torque_jacobian = None
        self._memo: dict = {}  # recent transitions (pre-impact state bytes -> result)
        self.lock = None  # the gradient (n,) of a constraint held through the transition

    @property
    def push(self):
        """The push-off and heel strike (:class:`walkerlab.models.hybrid.push_off.
        PushOffTransition`), made on first use."""
        if "_push" not in self.__dict__:
            self._push = PushOffTransition(self.spec, self.fns, self.n, self.limit,
                                           self.hip_mass_kg)
        return self._push

    def hold_lock(self, lock) -> None:
        """Hold the constraint ``lock(x)`` (n,) (a locked swing knee) through the push-off
        and the heel strike (:meth:`PushOffTransition.hold_lock`)."""
        self.push.hold_lock(lock)

    # ---------------------------------------------------------------- joint torques
    def hip_angles(self, x):
        """``(delta, ddelta, s, ds)``: hip angle (swing minus stance) [rad], its rate
        [rad/s], the phase variable (stance angle) [rad] and its rate [rad/s]."""
        d = self.fns["leg_angles"](x)
        sw, st = self.legs
        return (d[f"{sw}_angle"] - d[f"{st}_angle"], d[f"{sw}_rate"] - d[f"{st}_rate"],
                d[f"{st}_angle"], d[f"{st}_rate"])

    def torques(self, t, x) -> np.ndarray:
        """Torque of each actuator (k,) [N m; N m/kg when ``scaled_by: foot_mass``] at the
        state ``x`` (2n,) (complex-safe: the complex step differentiates through it)."""
        return self.laws(*self.hip_angles(x), t - self.t_origin)

    def begin_step(self, t0: float) -> None:
        """A step begins at ``t0`` [s]: the origin of the time a ``time_reference`` law
        reads (the integrator calls it at every step's start)."""
        self.t_origin = float(t0)

    def generalised_force(self, t, x):
        """``B(q) tau`` (n,) in the rows of the generated ``M`` [N m]."""
        tau = self.torques(t, x)
        if self.limit:  # rows of the absolute leg angles, swing row first, / m_foot
            col = np.zeros(self.n)
            col[0] = 1.0
        else:
            col = self.ddelta_dq
        return col * np.sum(tau)

    def power(self, t, x) -> float:
        """Mechanical power of the joint torques [W]: ``tau * ddelta`` (0 for torques scaled
        by a massless foot's mass: they do no work in the limit)."""
        if self.limit or not self.spec.torques:
            return 0.0
        return float(np.real(np.sum(self.torques(t, x)) * self.hip_angles(x)[1]))

    def added_acceleration(self, t, x, constraint=None, M=None):
        """``M^-1 B tau`` (n,) [rad/s^2]; in a phase holding a constraint with gradient
        ``a = constraint(x)`` (n,) (a locked knee), the constrained system's
        ``M^-1 (B tau + a lam)`` with ``a . qdd = 0`` (the lock's share: ``lam = -a M^-1
        B tau / (a M^-1 a)``; the same as ``[S^T M; a] qdd = [S^T B tau; 0]``, ``S`` a
        basis of the constraint's null space, :mod:`walkerlab.codegen.symbolic`).  ``M``
        (n, n): the mass matrix of the phase (default: the generated ``matrices``')."""
        M = self.fns["matrices"](x)[0] if M is None else M
        acc = np.linalg.solve(M, self.generalised_force(t, x))
        if constraint is None:
            return acc
        a = np.asarray(constraint(x))
        Ma = np.linalg.solve(M, a)
        return acc - Ma * (a @ acc) / (a @ Ma)

    def acceleration_jacobian(self, t, x, constraint=None) -> np.ndarray:
        """``d(M^-1 B tau)/dx`` (n, 2n) at the state ``x`` (2n,) (rows: ``qdd`` [rad/s^2];
        columns: the state's entries).

        With :attr:`torque_jacobian` set and no constraint: :func:`torque_chain_jacobian`
        (``B`` is constant: the leg angles are linear in ``q``).  Otherwise the complex step
        of :meth:`added_acceleration` (``2n`` calls through the torque laws)."""
        x = np.asarray(x, float)
        if self.torque_jacobian is None or constraint is not None:
            return complex_step_jacobian(
                lambda z: self.added_acceleration(t, z, constraint), x)
        B = self.ddelta_dq
        if self.limit:  # rows of the absolute leg angles, swing row first, / m_foot
            B = np.zeros(self.n)
            B[0] = 1.0
        dtau = np.sum(np.asarray(self.torque_jacobian(t, x), float), axis=0)
        return torque_chain_jacobian(self.fns["matrices"], x, self.generalised_force(t, x),
                                     np.outer(B, dtau))

    # ---------------------------------------------------------------- push-off
    def hip_velocity(self, x) -> np.ndarray:
        """Hip velocity (2,) [m/s] of a state ``x`` (2n,) (:mod:`push_off`)."""
        return self.push.hip_velocity(x)

    def impulse(self, x) -> float:
        """Push-off impulse ``P`` [N s] for the pre-impact state ``x`` (>= 0)."""
        return self.push.impulse(x)

    def transition(self, x) -> dict:
        """Push-off and heel strike from the pre-impact state ``x`` (2n,)
        (:meth:`walkerlab.models.hybrid.push_off.Transitions.transition`)."""
        return self.push.transition(x)

    def reset(self, x) -> np.ndarray:
        """Post-impact state (2n,) after push-off and heel strike (roles swapped)."""
        return self.push.reset(x)


def torque_chain_jacobian(matrices, x, force, force_jacobian) -> np.ndarray:
    """``d(M(q)^-1 F)/dx`` (n, 2n) of a generalised force ``F`` (n,) [N m] whose derivative
    ``dF/dx`` (n, 2n) is known: ``M^-1 (dF/dx - [dM/dq_k acc]_k)``, ``acc = M^-1 F``
    (``d(M^-1) = -M^-1 dM M^-1``; ``M`` depends on ``q`` only).  ``dM/dq_k`` by the complex
    step of the generated ``matrices`` alone (``n`` calls, exact to round-off; Squire &
    Trapp 1998).

    Parameters
    ----------
    matrices : callable
        The generated model's ``x (2n,) -> (M (n, n), C, G)`` (complex-safe).
    x : ndarray (2n,)
        The state (``q`` [rad], ``dq`` [rad/s]).
    force : ndarray (n,)
        ``F = B tau`` [N m].
    force_jacobian : ndarray (n, 2n)
        ``dF/dx`` (``B dtau/dx`` with a constant ``B``).

    Returns
    -------
    ndarray (n, 2n)
        ``d qdd / dx`` of the added acceleration [rad/s^2 per unit of each state entry].
    """
    x = np.asarray(x, float)
    n, h = len(force), 1e-30
    M = matrices(x)[0]
    acc = np.linalg.solve(M, force)
    rhs = np.array(force_jacobian, float)
    for k in range(n):
        xc = x.astype(complex)
        xc[k] += 1j * h
        rhs[:, k] -= (np.imag(matrices(xc)[0]) / h) @ acc
    return np.linalg.solve(M, rhs)
