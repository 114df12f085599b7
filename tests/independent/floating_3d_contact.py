"""The 3D straight-legged compass walker (Kuo 1999) set free on compliant contact, from
Newton's law on its point masses: an independent reference of walkerlab's 3D contact
model (``ContactWalker`` of a ``space: 3d`` compass gait).

Not walkerlab code and sharing none with it (numpy only).  The walker: a hip mass ``M_hip``
midway between the hips, which lie ``w`` apart on the hip axis; on each straight leg of
length ``L`` a point mass ``m`` at ``a`` from its foot.  World axes ``x`` downhill, ``y``
up, ``z`` lateral; the slope plane ``y = -x tan(gamma)``, its outward normal ``n = (sin
gamma, cos gamma, 0)``, its fall line ``s = (cos gamma, -sin gamma, 0)``.

Coordinates ``q = [p_x, p_y, p_z, heading, lean, pitch1, pitch2]``: leg2's foot at ``p``
(three slides along the world's axes), then a turn ``heading`` about ``n``, a roll
``lean`` about the fall line and each leg's pitch about the lateral axis ``z`` (from the
upward vertical, positive with the foot ahead), as ``tests/independent/parts_3d_newton.py``
writes the rigid walker:

* leg ``k``'s orientation ``R_k = Rot(n, heading) Rot(s, lean) Rot(z, pitch_k)``,
  the pelvis' ``R_p = Rot(n, heading) Rot(s, lean)``;
* leg2's hip ``p + R_2 (0, L, 0)``, the hip mass ``hip2 + R_p (0, 0, w / 2)``, leg1's hip
  ``hip2 + R_p (0, 0, w)``, leg1's foot ``hip1 + R_1 (0, -L, 0)``, the leg masses
  ``p + R_2 (0, a, 0)`` and ``hip1 + R_1 (0, a - L, 0)``.

The flow by d'Alembert's principle projected on the coordinates, ``M qdd = sum_feet J^T F
+ sum_feet Jw^T M_n - sum_masses m J^T (Jdot dq) + sum_masses m J^T g``, with

* ``M = sum m J^T J``, each position's Jacobian ``J`` by the complex step (exact to
  rounding: ``J e_k = Im r(q + i h e_k) / h``, ``h = 1e-30``) and the velocity-product
  term ``Jdot dq`` (the second derivative of ``r(q + t dq)`` in ``t``) as a central
  difference (step ``EPS`` = 1e-6 s) of that complex-step first derivative: truncation
  ``EPS^2 |d^3 r / dt^3| / 6`` (~ 2e-13 m |dq|^3), rounding ~ ``1e-16 |dr/dt| / EPS``;
* each leg's angular velocity from ``Rdot R^T`` (``Rdot`` by the complex step), its spin
  about ``n`` and that spin's Jacobian ``Jw`` (the spin is linear in the rates);
* the contact law written from MSC Adams/Solver's IMPACT and STEP functions and its
  CONTACT's Coulomb friction (:func:`adams_step`, :func:`impact`, :func:`coulomb_mu`):
  penetration ``delta = -(p . n)`` of the foot point, its rate from the foot's
  material velocity ``v = J dq``; ``F_n = k delta^e + STEP(delta, 0, 0, dmax, cmax)
  ddelta`` (``delta > 0``), at least 0; friction against the slip velocity ``v_t = v -
  (v . n) n``, ``F_t = -mu(|v_t|) F_n v_t / |v_t|``; a torsional friction moment about
  ``n`` on the foot's leg ``M_n = -mu(rho |w_n|) F_n rho sign(w_n)``, ``rho = tau /
  mu_s`` (``tau`` the torsional coefficient [m], ``w_n`` the leg's spin about ``n``).
  Continuous ground (every foot below the slope plane is in contact).
"""

from __future__ import annotations

import numpy as np

#: Step of the complex-step derivatives (exact to rounding for any small h).
H_CS = 1e-30
#: Step of the central difference that takes the second derivative along ``dq`` [s]
#: (the flow's error against walkerlab's falls as EPS^2 down to 1e-6, then rises: rounding).
EPS = 1e-6

COORDINATES = ("foot2_x", "foot2_y", "foot2_z", "heading", "lean", "pitch1", "pitch2")


def adams_step(x, x0, h0, x1, h1):
    """MSC Adams STEP: ``h0`` for ``x <= x0``, ``h1`` for ``x >= x1``, between them
    ``h0 + (h1 - h0) u^2 (3 - 2 u)``, ``u = (x - x0) / (x1 - x0)``."""
    if x <= x0:
        return h0
    if x >= x1:
        return h1
    u = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * u * u * (3.0 - 2.0 * u)


def impact(delta, ddelta, law):
    """Adams IMPACT normal force [N] at penetration ``delta`` [m] and its rate ``ddelta``
    [m/s] (> 0 penetrating): ``k delta^e + STEP(delta, 0, 0, dmax, cmax) ddelta``, never
    pulling (clamped at 0); 0 above the ground."""
    if delta <= 0.0:
        return 0.0
    f = law["k"] * delta ** law["e"] + adams_step(delta, 0.0, 0.0, law["dmax"],
                                                   law["cmax"]) * ddelta
    return max(f, 0.0)


def coulomb_mu(v, law):
    """Adams CONTACT Coulomb friction coefficient (>= 0) at slip speed ``v >= 0`` [m/s]:
    ``STEP(v, -vs, -mus, vs, mus)`` below the stiction velocity ``vs`` (0 at rest), then
    ``STEP(v, vs, mus, vd, mud)`` up to the friction velocity ``vd``, ``mud`` beyond."""
    if v < law["vs"]:
        return adams_step(v, -law["vs"], -law["mus"], law["vs"], law["mus"])
    return adams_step(v, law["vs"], law["mus"], law["vd"], law["mud"])


def _rot(axis, angle):
    """Rotation (3, 3) by ``angle`` about the unit ``axis`` (Rodrigues; complex angles
    allowed, for the complex step)."""
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]],
                  [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


class Floating3DContact:
    """The walker of the module docstring: gravity ``g`` [m/s^2], leg length ``L`` [m],
    slope ``gamma`` [rad], hip mass ``M_hip`` [kg], leg masses ``m`` [kg] at ``a`` [m] from
    the foot, hip width ``w`` [m]; ``law`` a dict of the contact law in SI: ``k`` [N/m^e],
    ``e``, ``cmax`` [N s/m], ``dmax`` [m], ``mus``, ``mud``, ``vs``, ``vd`` [m/s], ``tau``
    [m]."""

    def __init__(self, g, L, gamma, M_hip, m, a, w, law):
        self.g, self.L, self.gamma = g, L, gamma
        self.M_hip, self.m, self.a, self.w = M_hip, m, a, w
        self.law = dict(law)
        self.n = np.array([np.sin(gamma), np.cos(gamma), 0.0])
        self.s = np.array([np.cos(gamma), -np.sin(gamma), 0.0])
        self.z = np.array([0.0, 0.0, 1.0])

    # -- kinematics ------------------------------------------------------------------
    def orientations(self, q):
        """``(R_pelvis, R_leg1, R_leg2)`` (3, 3) each."""
        Rp = _rot(self.n, q[3]) @ _rot(self.s, q[4])
        return Rp, Rp @ _rot(self.z, q[5]), Rp @ _rot(self.z, q[6])

    def positions(self, q):
        """Named points (3,) [m]: each leg's hip ``leg1_hip``, ``leg2_hip`` (the ends of the
        hip axis), ``hip_mass``, ``leg1_mass``, ``leg2_mass``, ``leg1_foot``,
        ``leg2_foot``."""
        L, a, w = self.L, self.a, self.w
        Rp, R1, R2 = self.orientations(q)
        p = np.asarray(q[:3])
        hip2 = p + R2 @ np.array([0.0, L, 0.0])
        hip1 = hip2 + Rp @ np.array([0.0, 0.0, w])
        return {"leg1_hip": hip1, "leg2_hip": hip2,
                "hip_mass": hip2 + Rp @ np.array([0.0, 0.0, w / 2]),
                "leg1_mass": hip1 + R1 @ np.array([0.0, a - L, 0.0]),
                "leg2_mass": p + R2 @ np.array([0.0, a, 0.0]),
                "leg1_foot": hip1 + R1 @ np.array([0.0, -L, 0.0]),
                "leg2_foot": p}

    def _d_along(self, f, q, dq):
        """``d/dt f(q + t dq)`` at ``t = 0`` by the complex step (``f`` any analytic map of
        ``q``)."""
        return np.imag(f(np.asarray(q, complex) + 1j * H_CS * np.asarray(dq))) / H_CS

    def jacobian(self, name, q):
        """(3, 7) Jacobian of point ``name``."""
        def f(qq):
            return self.positions(qq)[name]
        return np.column_stack([self._d_along(f, q, e) for e in np.eye(7)])

    def jdot_dq(self, name, q, dq):
        """(3,) ``Jdot dq`` of point ``name``: ``d^2/dt^2 r(q + t dq)`` at 0, the central
        difference (step :data:`EPS`) of the complex-step first derivative."""
        def f(qq):
            return self.positions(qq)[name]
        q, dq = np.asarray(q, float), np.asarray(dq, float)
        return (self._d_along(f, q + EPS * dq, dq) - self._d_along(f, q - EPS * dq, dq)) / (
            2 * EPS)

    def spin_jacobian(self, leg, q):
        """(7,) the Jacobian of leg ``leg``'s (1 or 2) angular velocity's component about
        the slope's normal: ``n . vee(dR/dq_k R^T)``."""
        R = self.orientations(q)[leg]
        out = np.empty(7)
        for k, e in enumerate(np.eye(7)):
            W = self._d_along(lambda qq: self.orientations(qq)[leg], q, e) @ R.T
            out[k] = self.n @ np.array([W[2, 1], W[0, 2], W[1, 0]])
        return out

    def angular_velocity_jacobian(self, body, q):
        """(3, 7) the Jacobian of body ``body``'s (0 the pelvis, 1 leg1, 2 leg2) angular
        velocity in world axes: column ``k`` is ``vee(dR/dq_k R^T)``."""
        R = self.orientations(q)[body]
        out = np.empty((3, 7))
        for k, e in enumerate(np.eye(7)):
            W = self._d_along(lambda qq: self.orientations(qq)[body], q, e) @ R.T
            out[:, k] = (W[2, 1], W[0, 2], W[1, 0])
        return out

    def hip_torque_force(self, q, tau, stance):
        """The generalised force (7,) of a hip motor pair: a torque ``+tau`` about the
        hip axis (the pelvis' lateral axis ``R_p z``) on the swing leg and ``-tau`` on the
        stance leg ``stance`` (1 or 2), each against the pelvis: the virtual power
        ``tau (w_swing - w_stance) . (R_p z)``."""
        axis = self.orientations(q)[0] @ self.z
        swing = 3 - stance
        Jw = self.angular_velocity_jacobian(swing, q) - self.angular_velocity_jacobian(stance, q)
        return tau * (axis @ Jw)

    def push_force(self, q, force, leg):
        """The generalised force (7,) of a force ``force`` [N] at leg ``leg``'s foot (1 or
        2) along the line from it to that leg's own hip."""
        r = self.positions(q)
        e = r[f"leg{leg}_hip"] - r[f"leg{leg}_foot"]
        return self.jacobian(f"leg{leg}_foot", q).T @ (force * e / np.linalg.norm(e))

    # -- contact -----------------------------------------------------------------------
    def foot_contact(self, q, dq, leg):
        """Contact of leg ``leg``'s foot (1 or 2): a dict with the penetration ``delta``
        [m], its rate ``ddelta`` [m/s], the slip velocity ``v_t`` (3,) [m/s], the spin
        ``spin`` [rad/s], the normal force ``fn`` [N], the force ``F`` (3,) [N] on the foot
        and the torsional moment ``moment`` [N m] about ``n`` on the leg, and the Jacobians
        ``J`` (3, 7), ``Jw`` (7,)."""
        name = f"leg{leg}_foot"
        r = self.positions(q)[name]
        J = self.jacobian(name, q)
        v = J @ dq
        delta, ddelta = -(r @ self.n), -(v @ self.n)
        vt = v - (v @ self.n) * self.n
        Jw = self.spin_jacobian(leg, q)
        spin = Jw @ dq
        fn = impact(delta, ddelta, self.law)
        F = fn * self.n
        slip = np.linalg.norm(vt)
        if fn > 0.0 and slip > 0.0:
            F = F - coulomb_mu(slip, self.law) * fn * vt / slip
        moment = 0.0
        tau = self.law["tau"]
        if fn > 0.0 and tau > 0.0 and spin != 0.0:
            rho = tau / self.law["mus"]
            moment = -coulomb_mu(rho * abs(spin), self.law) * fn * rho * np.sign(spin)
        return {"delta": delta, "ddelta": ddelta, "v_t": vt, "slip": slip, "spin": spin,
                "fn": fn, "F": F, "moment": moment, "J": J, "Jw": Jw}

    # -- dynamics ----------------------------------------------------------------------
    def masses(self):
        """``(point name, mass [kg])`` of the three masses."""
        return (("hip_mass", self.M_hip), ("leg1_mass", self.m), ("leg2_mass", self.m))

    def mass_matrix(self, q):
        """(7, 7) ``sum m J^T J``."""
        M = np.zeros((7, 7))
        for name, mass in self.masses():
            J = self.jacobian(name, q)
            M += mass * J.T @ J
        return M

    def accelerations(self, x, held=()):
        """``qdd`` (7,) at the state ``x = [q, dq]`` (14,); with coordinates ``held`` (indices,
        at rest in ``x``) those rows and columns removed, the accelerations of the others
        (the held coordinates' constraint forces are their rows' multipliers)."""
        q, dq = np.asarray(x[:7], float), np.asarray(x[7:], float)
        grav = np.array([0.0, -self.g, 0.0])
        M, Q = np.zeros((7, 7)), np.zeros(7)
        for name, mass in self.masses():
            J = self.jacobian(name, q)
            M += mass * J.T @ J
            Q += mass * J.T @ (grav - self.jdot_dq(name, q, dq))
        for leg in (1, 2):
            c = self.foot_contact(q, dq, leg)
            Q += c["J"].T @ c["F"] + c["Jw"] * c["moment"]
        keep = [k for k in range(7) if k not in held]
        return np.linalg.solve(M[np.ix_(keep, keep)], Q[keep])

    def rhs(self, t, x):
        """dx/dt (14,)."""
        return np.concatenate([np.asarray(x[7:], float), self.accelerations(x)])
