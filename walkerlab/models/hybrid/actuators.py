"""Actuators on a rigid hybrid walker: ``B(q) u`` in the flow (paper Eq. 3 with u != 0) and a
push-off impulse in the reset (Kuo 2002's two-impulse step-to-step transition).

Flow
----
``M(q) qdd + C(q, dq) dq + G(q) = B(q) tau``: each actuator's torque acts between the two
links of its joint (:data:`walkerlab.config.actuation.JOINTS`: ``+tau`` on the second link,
``-tau`` on the first), so its generalised force is ``tau d(delta)/dq`` with ``delta =
psi_second - psi_first`` the joint's angle (virtual work).  The absolute link angles are the
generated ``leg_angles`` of the walker (:func:`link_angles`: legs, thighs, shanks, torso; a
bisecting torso's angle is the legs' mean, so a torso-to-leg torque reaches both legs; a flat
foot's angle is its leg's plus the ankle's); their rates are linear in ``dq``, so the rows of
``B^T = d(delta)/dq`` are read exactly from unit rates (and are constant: every link angle is
affine in ``q``, checked).  A torque on a locked joint (a kneed walker's stance knee, a swing
flat foot) has a zero row: the lock takes it.  The generated passive flow is kept and the
actuation added: ``qdd = qdd_passive + M^-1 B tau`` (in a phase holding a constraint:
through it).  On a walker whose legs are massless (the limit
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
from walkerlab.models.hybrid.push_off import PushOffTransition, leg_rate_jacobian
from walkerlab.numerics import complex_step_jacobian
from walkerlab.walker.joints import (  # noqa: F401 (joint_links: importable from here)
    joint_angles,
    joint_columns,
    joint_links,
    link_angles,
)

__all__ = ["Actuators", "joint_links", "link_angles", "torque_chain_jacobian"]


@dataclass
class Actuators:
    """The actuators of one walker, bound to its generated model.

    Attributes
    ----------
    spec : walkerlab.config.actuation.Actuation
    fns : dict
        The generated model's functions (``matrices``, ``impact_matrices``, ``points``,
        ``leg_angles``, ``reset``, ``energies``).
    n, limit, hip_mass_kg
        As :class:`~walkerlab.models.hybrid.push_off.PushOffTransition`'s: the number of
        generalised coordinates, whether the legs are massless, the hip's mass [kg].
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

    #: with a bisecting torso on flat feet: the torso's angle, the legs' mean (the flat-foot
    #: model's ``leg_angles`` output does not name it)
    torso_mean: bool = False

    #: legs with some massless bodies: the generated equations' rows are link-angle rows
    #: (:mod:`walkerlab.codegen.legged`'s massless limit), the force mapped into them
    #: (:meth:`link_rows`)
    some_massless: bool = False

    def __post_init__(self):
        z = np.zeros(self.n)
        # d(delta)/dq from the absolute leg angles' Jacobian A = d(psi_sw, psi_st)/dq
        self.legs, self.A = leg_rate_jacobian(self.fns["leg_angles"], self.n)
        self.ddelta_dq = self.A[0] - self.A[1]
        self.laws = TorqueLaws(self.spec.torques)
        # each actuator's (first, second) link and its row of B^T = d(delta)/dq (exact)
        names = self.link_angles(np.concatenate([z, z]))
        self.links = [joint_links(names, t.joint, f"walker.actuation.torques.{i}.joint")
                      for i, t in enumerate(self.spec.torques)]
        self.B = joint_columns(self.link_angles, self.n, self.links)
        q1 = np.linspace(0.1, 0.3, self.n)  # a second configuration (link_rows' point)
        #: every actuator at the one hip between the legs (the straight-legged walkers'
        #: actuation: B tau = ddelta_dq sum(tau), as before)
        self.hip_only = all(t.joint == "hip" for t in self.spec.torques) and not (
            "stance_angle" in names and "stance_thigh" in names)
        #: (n, n) the map of a generalised force in ``q``'s rows into the generated
        #: equations' rows (legs with some massless bodies), or None: the same rows
        self.rows = self.link_rows(q1) if self.some_massless and not self.limit else None
        self.t_origin = 0.0  # the time [s] the present step began (time_reference laws)
        # (t, x) -> (k, 2n) the torques' derivative by the state, when known in closed form
        # (a torque of time alone: zeros); None: the complex step differentiates the torques
        self.torque_jacobian = None

    def link_rows(self, q) -> np.ndarray:
        """The map ``L`` (n, n) of a generalised force ``F`` in ``q``'s rows into the
        generated equations' rows on legs with some massless bodies, ``M_gen qdd + ... =
        L F``.  The generated rows are link-angle rows, each at its massless limit
        (:mod:`walkerlab.codegen.legged`, Garcia et al. 1998): a link that moves massive
        bodies keeps its row's value at ``m = 0``, ``(A^-T F)_k`` (``A = dpsi/dq``); a link
        that moves only massless bodies has its row divided by the vanishing mass, where a
        finite torque would give an infinite angular acceleration.  With ``M_q`` the
        Hessian of the generated kinetic energy in the rates (massless bodies carry none;
        its null space: the motions of massless links alone), ``L = M_gen M_q^+`` on the
        massive links' rows (exact: ``M_gen_r = (A^-T)_r M_q`` there and ``F`` lies in
        ``M_q``'s range) and 0 on the others.  Constant (every link angle is affine in
        ``q``), read at the angles ``q`` (n,).

        Raises
        ------
        ValueError
            A torque across a link that carries no mass (its virtual work on a motion of
            massless links alone is not 0), naming ``walker.actuation.torques.<i>.joint``.
        """
        n = self.n
        eye = np.eye(n)

        def T(dq):
            return float(np.real(self.fns["energies"](np.concatenate([q, dq]))[0]))
        d = [T(eye[i]) for i in range(n)]
        Mq = np.array([[2.0 * d[i] if i == j else T(eye[i] + eye[j]) - d[i] - d[j]
                        for j in range(n)] for i in range(n)])
        w, V = np.linalg.eigh(Mq)
        null = V[:, w <= 1e-10 * max(float(np.max(np.abs(w))), 1e-300)]
        for i, t in enumerate(self.spec.torques):
            col = self.B[:, i]
            if null.size and np.max(np.abs(null.T @ col)) > 1e-10 * max(np.max(np.abs(col)),
                                                                        1e-300):
                raise ValueError(f"walker.actuation.torques.{i}.joint: {t.joint} acts on a "
                                 "link whose bodies are all massless (no inertia: a finite "
                                 "torque there has an infinite angular acceleration); give "
                                 "that link a body with mass")
        Mg = np.real(np.asarray(self.fns["matrices"](np.concatenate([q, np.zeros(n)]))[0]))
        L = Mg @ np.linalg.pinv(Mq)
        if null.size:  # the massless links' rows (the limit's): no force reaches them
            L[np.max(np.abs(Mg @ null), axis=1) > 1e-10 * np.max(np.abs(Mg))] = 0.0
        return L

    def affine_joint_map(self, joint_state) -> tuple | None:
        """``(Bt (k, n), c (k,))``: the actuators' joint angles ``delta = Bt q + c`` and rates
        ``ddelta = Bt dq``, affine in the coordinates (``B``'s rows, checked constant by
        :func:`walkerlab.walker.joints.joint_columns`; for hip actuators every row the hip's
        ``ddelta_dq``), or None where ``joint_state`` (``x -> (delta, ddelta)``, the
        generated ``leg_angles``' reading) disagrees with it at a probe state beyond
        round-off (1e-12)."""
        n, k = self.n, len(self.spec.torques)
        Bt = (np.tile(np.real(self.ddelta_dq), (k, 1)) if self.hip_only
              else np.real(np.asarray(self.B, float)).T)
        c = np.asarray(joint_state(np.zeros(2 * n))[0], float)
        probe = np.concatenate([np.linspace(0.1, 0.3, n), np.linspace(-0.5, 0.5, n)])
        d, dd = joint_state(probe)
        q, dq = np.split(probe, 2)
        if (np.allclose(Bt @ q + c, d, rtol=0.0, atol=1e-12)
                and np.allclose(Bt @ dq, dd, rtol=0.0, atol=1e-12)):
            return np.ascontiguousarray(Bt), c
        return None

    @staticmethod
    def affine_joint_state(x, affine) -> tuple[np.ndarray, np.ndarray]:
        """``(delta, ddelta)`` (k,) [rad, rad/s] at the state ``x`` (2n,) by the map
        ``affine`` (:meth:`affine_joint_map`)."""
        Bt, c = affine
        n = len(x) // 2  # (slices: np.split's views, without its Python)
        return Bt @ x[:n] + c, Bt @ x[n:]

    @staticmethod
    def affine_joint_rates(X, affine) -> np.ndarray:
        """The joint rates ``ddelta`` (k, m) [rad/s] at the states ``X`` (2n, m), one per
        column, by the map ``affine`` (:meth:`affine_joint_map`)."""
        return affine[0] @ X[len(X) // 2:]

    def link_angles(self, x) -> dict:
        """``{link: (angle [rad], rate [rad/s])}`` at the state ``x`` (2n,)
        (:func:`link_angles`; a bisecting torso on flat feet: the legs' mean)."""
        out = link_angles(self.fns["leg_angles"](x))
        if self.torso_mean and "torso" not in out:
            (a, da), (b, db) = out["stance"], out["swing"]
            out["torso"] = ((a + b) / 2, (da + db) / 2)
        return out

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

    def joint_angles(self, x):
        """``(deltas, ddeltas, s, ds)``: each actuator's joint angle [rad] and rate [rad/s]
        (lists, length k), the phase variable (the stance leg's absolute angle; a kneed
        walker's stance thigh's, a five-link biped's virtual stance leg's) [rad] and its
        rate [rad/s]."""
        d = self.link_angles(x)
        return joint_angles(d, self.links, "stance" if "stance" in d else self.legs[1])

    def torques(self, t, x) -> np.ndarray:
        """Torque of each actuator (k,) [N m; N m/kg when ``scaled_by: foot_mass``] at the
        state ``x`` (2n,) (complex-safe: the complex step differentiates through it)."""
        if self.hip_only:
            return self.laws(*self.hip_angles(x), t - self.t_origin)
        return self.laws.each(*self.joint_angles(x), t - self.t_origin)

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
        elif self.hip_only:
            col = self.ddelta_dq
        else:
            return self.B @ tau if self.rows is None else self.rows @ (self.B @ tau)
        return col * np.sum(tau) if self.rows is None else self.rows @ (col * np.sum(tau))

    def power(self, t, x) -> float:
        """Mechanical power of the joint torques [W]: ``sum_k tau_k ddelta_k`` (0 for
        torques scaled by a massless foot's mass: they do no work in the limit)."""
        if self.limit or not self.spec.torques:
            return 0.0
        if self.hip_only:
            return float(np.real(np.sum(self.torques(t, x)) * self.hip_angles(x)[1]))
        ddeltas = self.joint_angles(x)[1]
        return float(np.real(np.sum(self.torques(t, x) * np.asarray(ddeltas))))

    def added_acceleration(self, t, x, constraint=None, M=None):
        """``M^-1 B tau`` (n,) [rad/s^2]; in a phase holding a constraint with gradient
        ``a = constraint(x)`` (n,) (a locked knee), the constrained system's
        ``M^-1 (B tau + a lam)`` with ``a . qdd = 0`` (the lock's share: ``lam = -a M^-1
        B tau / (a M^-1 a)``; the same as ``[S^T M; a] qdd = [S^T B tau; 0]``, ``S`` a
        basis of the constraint's null space, :mod:`walkerlab.codegen.legged`).  ``M``
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
        if self.torque_jacobian is None or constraint is not None or self.rows is not None:
            return complex_step_jacobian(
                lambda z: self.added_acceleration(t, z, constraint), x)
        dtau = np.asarray(self.torque_jacobian(t, x), float)
        if not self.limit and not self.hip_only:
            return torque_chain_jacobian(self.fns["matrices"], x,
                                         self.generalised_force(t, x), self.B @ dtau)
        B = self.ddelta_dq
        if self.limit:  # rows of the absolute leg angles, swing row first, / m_foot
            B = np.zeros(self.n)
            B[0] = 1.0
        dtau = np.sum(dtau, axis=0)
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
