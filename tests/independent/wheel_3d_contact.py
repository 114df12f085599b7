"""The rimless (spoked) wheel in three dimensions set free on compliant contact, from the
Newton-Euler equations of one rigid body: an independent reference of walkerlab's 3D wheel
contact model (``ContactWalker`` of ``model: rimless_wheel`` with ``space: 3d``).

Not walkerlab code and sharing none with it (numpy; the contact law's functions are
``tests/independent/floating_3d_contact.py``'s, written from the Adams formulas).  The
wheel (Coleman, Chatterjee & Ruina 1997): a hub of mass ``M`` at its centre, inertia
``diag(I_diam, I_diam, I_hub)`` about it in the wheel's frame (``z`` its axle), and ``n``
massless spokes of length ``L`` in the wheel's plane, ``2 pi / n`` apart.  World axes ``x``
downhill, ``y`` up, ``z`` lateral; the slope plane ``y = -x tan(gamma)``, its outward normal
``n = (sin gamma, cos gamma, 0)``, its fall line ``s = (cos gamma, -sin gamma, 0)``.

Coordinates ``q = [p_x, p_y, p_z, heading, lean, theta]``: spoke 0's tip at ``p``, the
wheel's orientation ``R = Rot(n, heading) Rot(s, lean) Rot(z, theta)`` (the wheel's frame
the world's when all three are 0: spoke 0 pointing straight down from the hub), so the hub
is at ``p + R (0, L, 0)`` and spoke ``k``'s tip at ``hub + R (L sin(2 pi k / n), -L cos(2 pi
k / n), 0)`` (spoke ``k`` is ``k`` spokes ahead of spoke 0 rolling downhill).

The flow from Newton's and Euler's laws of the body (not Lagrange's):

* ``M a_hub = M g + sum_k F_k``;
* ``I omega_b' + omega_b x I omega_b = sum_k (R^T (r_k - hub)) x (R^T F_k) + R^T n M_k``
  (the body's angular velocity ``omega_b = vee(R^T R')`` in its own frame),

with ``a_hub = J_h qdd + J_h' dq`` and ``omega_b' = W qdd + W' dq`` (``J_h`` the hub's
Jacobian, ``W`` the body rate's, each column ``vee(R^T dR/dq_k)``), all by the complex step
(exact to rounding) and the velocity-product terms as a central difference (step ``EPS``)
of the complex-step first derivative along ``dq``; the six equations solved for ``qdd``.
Each spoke tip ``k``'s contact: penetration ``delta = -(r_k . n)``, its rate from the tip's
material velocity, the IMPACT normal force, Coulomb friction against the slip velocity in
the tangent plane and the torsional friction moment ``M_k`` about ``n`` against the body's
spin ``omega . n`` (``floating_3d_contact.Floating3DContact.foot_contact``'s law).
Continuous ground (every tip below the slope plane is in contact).
"""

from __future__ import annotations

import numpy as np

from tests.independent.floating_3d_contact import EPS, H_CS, _rot, coulomb_mu, impact

COORDINATES = ("spoke0_x", "spoke0_y", "spoke0_z", "heading", "lean", "theta")


def _vee(W):
    """The vector of a skew matrix (3, 3) -> (3,)."""
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


class Wheel3DContact:
    """The wheel of the module docstring: gravity ``g`` [m/s^2], spoke length ``L`` [m],
    slope ``gamma`` [rad], mass ``M`` [kg], inertias ``I_hub`` (axle), ``I_diam`` (a
    diameter) [kg m^2], ``spokes`` spokes; ``law`` the contact law in SI (``k``, ``e``,
    ``cmax``, ``dmax``, ``mus``, ``mud``, ``vs``, ``vd``, ``tau``: as
    ``floating_3d_contact.Floating3DContact``'s)."""

    def __init__(self, g, L, gamma, M, I_hub, I_diam, spokes, law):
        self.g, self.L, self.gamma, self.M = g, L, gamma, M
        self.inertia = np.diag([I_diam, I_diam, I_hub])
        self.spokes = int(spokes)
        self.law = dict(law)
        self.n = np.array([np.sin(gamma), np.cos(gamma), 0.0])
        self.s = np.array([np.cos(gamma), -np.sin(gamma), 0.0])
        self.z = np.array([0.0, 0.0, 1.0])

    # -- kinematics ----------------------------------------------------------------
    def rotation(self, q):
        """The wheel's frame to the world's (3, 3)."""
        return _rot(self.n, q[3]) @ _rot(self.s, q[4]) @ _rot(self.z, q[5])

    def hub(self, q):
        """The hub (3,) [m]."""
        return np.asarray(q[:3]) + self.rotation(q) @ np.array([0.0, self.L, 0.0])

    def tip(self, q, k):
        """Spoke ``k``'s tip (3,) [m]."""
        a = 2.0 * np.pi * k / self.spokes
        return self.hub(q) + self.rotation(q) @ np.array([self.L * np.sin(a),
                                                          -self.L * np.cos(a), 0.0])

    def _d_along(self, f, q, dq):
        """``d/dt f(q + t dq)`` at 0 by the complex step."""
        return np.imag(f(np.asarray(q, complex) + 1j * H_CS * np.asarray(dq))) / H_CS

    def jacobian(self, f, q):
        """(3, 6) Jacobian of the point map ``f``."""
        return np.column_stack([self._d_along(f, q, e) for e in np.eye(6)])

    def jdot_dq(self, f, q, dq):
        """(3,) ``J' dq`` of the point map ``f`` (central difference, step EPS)."""
        q, dq = np.asarray(q, float), np.asarray(dq, float)
        return (self._d_along(f, q + EPS * dq, dq) - self._d_along(f, q - EPS * dq, dq)) / (
            2 * EPS)

    def body_rate_jacobian(self, q):
        """(3, 6) ``W``: the body's angular velocity in its own frame is ``W dq``."""
        R = self.rotation(q)
        return np.column_stack([_vee(R.T @ self._d_along(self.rotation, q, e))
                                for e in np.eye(6)])

    def body_rate_dot(self, q, dq):
        """(3,) ``W' dq`` (central difference of ``W(q + t dq) dq``, step EPS)."""
        q, dq = np.asarray(q, float), np.asarray(dq, float)
        return (self.body_rate_jacobian(q + EPS * dq) @ dq
                - self.body_rate_jacobian(q - EPS * dq) @ dq) / (2 * EPS)

    # -- contact -------------------------------------------------------------------
    def tip_contact(self, q, dq, k):
        """Spoke ``k``'s contact: its position ``r`` (3,), the force ``F`` (3,) [N] on the
        tip and the torsional moment ``moment`` [N m] about ``n``, with ``delta``,
        ``fn``, ``slip``, ``spin``."""
        r = self.tip(q, k)
        v = self.jacobian(lambda qq: self.tip(qq, k), q) @ dq
        delta, ddelta = -(r @ self.n), -(v @ self.n)
        vt = v - (v @ self.n) * self.n
        spin = (self.rotation(q) @ (self.body_rate_jacobian(q) @ dq)) @ self.n
        fn = impact(delta, ddelta, self.law)
        F = fn * self.n
        slip = np.linalg.norm(vt)
        if fn > 0.0 and slip > 0.0:
            F = F - coulomb_mu(slip, self.law) * fn * vt / slip
        moment, tau = 0.0, self.law["tau"]
        if fn > 0.0 and tau > 0.0 and spin != 0.0:
            rho = tau / self.law["mus"]
            moment = -coulomb_mu(rho * abs(spin), self.law) * fn * rho * np.sign(spin)
        return {"r": r, "F": F, "moment": moment, "delta": delta, "fn": fn, "slip": slip,
                "spin": spin}

    # -- dynamics ------------------------------------------------------------------
    def accelerations(self, x):
        """``qdd`` (6,) at ``x = [q, dq]`` (12,) from Newton's and Euler's laws."""
        q, dq = np.asarray(x[:6], float), np.asarray(x[6:], float)
        R = self.rotation(q)
        hub = self.hub(q)
        W = self.body_rate_jacobian(q)
        w = W @ dq
        force = np.array([0.0, -self.M * self.g, 0.0])
        torque = -np.cross(w, self.inertia @ w)
        for k in range(self.spokes):
            c = self.tip_contact(q, dq, k)
            force = force + c["F"]
            torque = torque + np.cross(R.T @ (c["r"] - hub), R.T @ c["F"]) \
                + R.T @ self.n * c["moment"]
        Jh = self.jacobian(self.hub, q)
        A = np.vstack([self.M * Jh, self.inertia @ W])
        b = np.concatenate([force - self.M * self.jdot_dq(self.hub, q, dq),
                            torque - self.inertia @ self.body_rate_dot(q, dq)])
        return np.linalg.solve(A, b)

    def rhs(self, t, x):
        """dx/dt (12,)."""
        return np.concatenate([np.asarray(x[6:], float), self.accelerations(x)])
