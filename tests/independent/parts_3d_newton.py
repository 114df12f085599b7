"""A 3D straight-legged walker of point masses from Newton's law, for the walkers written from
parts (``model: biped`` with ``space: 3d``): a pelvis mass midway between the hips, point
masses on each leg at given distances from the hip, and point masses on an upper body held
on the bisector of the legs (Wisse, Hobbelen & Schwab 2007): its pitch from the upward
vertical is the mean of the legs' pitches, its roll the pelvis'.

Not walkerlab code and sharing none with it: the rotation matrices by scipy, their
derivatives by hand (``d/dt R(phi) T(psi) c = S R T c phi' + R Z T c psi'``, ``S`` and ``Z``
the cross-product matrices of the fall line and of ``z``; ``R`` and ``S`` commute), the flow
by d'Alembert's principle projected on the coordinates, the impact with the impulse at the
new foot as an unknown (a Lagrange multiplier) in extended coordinates.

State ``[lean, swing, stance, rates]`` as walkerlab's (world axes, ``x`` downhill, ``y`` up;
the lean a roll about the fall line, the legs' pitches from the vertical, positive with the
foot ahead).  A point is a list of terms ``(weights, c)``: ``R(lean) T(sum_i w_i q_i) c``,
or ``R(lean) c`` for ``weights`` None.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from tests.independent.mirror_stride import to_heel_strike

SWING, STANCE = 1, 2


class PartsReference:
    """The walker (module docstring): ``legs`` and ``torso`` are ``[(mass [kg], distance
    from the hip [m])]`` (down each leg, up the upper body)."""

    def __init__(self, g, L, gamma, M_hip, legs, torso=()):
        self.g, self.L, self.gamma, self.M = g, L, gamma, M_hip
        self.legs, self.torso = list(legs), list(torso)
        self.s = np.array([math.cos(gamma), -math.sin(gamma), 0.0])
        self.n = np.array([math.sin(gamma), math.cos(gamma), 0.0])
        self.z = np.array([0.0, 0.0, 1.0])
        self.S, self.Z = self._skew(self.s), self._skew(self.z)

    @staticmethod
    def _skew(v):
        return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

    def points(self, w):
        """The masses ``[(m, terms)]`` and the swing foot's terms; ``w`` the swing hip's
        offset along the hip axis."""
        L, mean = self.L, {SWING: 0.5, STANCE: 0.5}
        hip_st = [({STANCE: 1.0}, np.array([0.0, L, 0.0]))]
        pelvis = hip_st + [(None, w / 2 * self.z)]
        hip_sw = hip_st + [(None, w * self.z)]
        out = [(self.M, pelvis)]
        for m, d in self.legs:
            out.append((m, hip_st + [({STANCE: 1.0}, np.array([0.0, -d, 0.0]))]))
            out.append((m, hip_sw + [({SWING: 1.0}, np.array([0.0, -d, 0.0]))]))
        for m, d in self.torso:
            out.append((m, pelvis + [(mean, np.array([0.0, d, 0.0]))]))
        return out, hip_sw + [({SWING: 1.0}, np.array([0.0, -L, 0.0]))]

    def kin(self, terms, q, dq):
        """Position (3,), Jacobian (3, 3) and the velocity-product term ``Jdot dq`` (3,)."""
        R = Rotation.from_rotvec(q[0] * self.s).as_matrix()
        r, J, h = np.zeros(3), np.zeros((3, 3)), np.zeros(3)
        for weights, c in terms:
            psi = 0.0 if weights is None else sum(wi * q[i] for i, wi in weights.items())
            rate = 0.0 if weights is None else sum(wi * dq[i] for i, wi in weights.items())
            T = Rotation.from_rotvec(psi * self.z).as_matrix()
            p = R @ T @ c
            r += p
            J[:, 0] += self.S @ p
            h += self.S @ self.S @ p * dq[0] ** 2
            if weights is not None:
                d_psi = R @ self.Z @ T @ c
                for i, wi in weights.items():
                    J[:, i] += wi * d_psi
                h += 2 * self.S @ d_psi * dq[0] * rate + R @ self.Z @ self.Z @ T @ c * rate ** 2
        return r, J, h

    def rhs(self, w):
        masses, _ = self.points(w)
        grav = np.array([0.0, -self.g, 0.0])

        def f(t, x):
            q, dq = x[:3], x[3:]
            Mq, rhs = np.zeros((3, 3)), np.zeros(3)
            for m, terms in masses:
                _, J, h = self.kin(terms, q, dq)
                Mq += m * J.T @ J
                rhs += m * J.T @ (grav - h)
            return np.concatenate([dq, np.linalg.solve(Mq, rhs)])
        return f

    def foot_height(self, w, x):
        return float(self.n @ self.kin(self.points(w)[1], x[:3], x[3:])[0])

    def step(self, w, x):
        """One step from just after a heel strike: ``(x just after the next one, period)``."""
        y, t2 = to_heel_strike(self.rhs(w), x, SWING, STANCE,
                               lambda y: self.foot_height(w, y), 5.0)
        return self.impact(w, y), t2

    def impact(self, w, y):
        """The plastic impact, the impulse at the new foot an unknown: ``M_e (dq+ - dq-) =
        E^T F``, ``E dq+ = 0``; then the legs' roles swap."""
        q, dqp = y[:3], self._impact_solution(w, y)[:3]
        return np.array([q[0], q[2], q[1], dqp[0], dqp[2], dqp[1]])

    def _impact_solution(self, w, y):
        """``[dq+ (3), the old foot's velocity after (3), the impulse F (3)]`` of the
        impact from ``y`` (:meth:`impact`)."""
        masses, foot = self.points(w)
        q, dq = y[:3], y[3:]
        Me = np.zeros((6, 6))
        for m, terms in masses:
            Je = np.hstack([self.kin(terms, q, dq)[1], np.eye(3)])
            Me += m * Je.T @ Je
        E = np.hstack([self.kin(foot, q, dq)[1], np.eye(3)])
        K = np.block([[Me, -E.T], [E, np.zeros((3, 3))]])
        return np.linalg.solve(K, np.concatenate([Me @ np.concatenate([dq, np.zeros(3)]),
                                                   np.zeros(3)]))

    def ground_wrench(self, w, x):
        """The ground's force (3,) [N] and its moment about the stance foot (3,) [N m] at the
        state ``x`` of a step, world axes: Newton's and Euler's laws on the point masses,
        ``sum m (a - g)`` and ``sum r x m (a - g)``, with ``a = J qdd + Jdot dq`` and this
        model's own ``qdd`` (the rigid stance foot: no slip, no turn)."""
        masses, _ = self.points(w)
        q, dq = x[:3], x[3:]
        qdd = self.rhs(w)(0.0, x)[3:]
        grav = np.array([0.0, -self.g, 0.0])
        force, moment = np.zeros(3), np.zeros(3)
        for m, terms in masses:
            r, J, h = self.kin(terms, q, dq)
            f = m * (J @ qdd + h - grav)
            force += f
            moment += np.cross(r, f)
        return force, moment

    def impact_impulse(self, w, y):
        """The ground's impulse (3,) [N s] at the new stance foot in the heel strike from the
        pre-impact state ``y`` (the Lagrange multiplier of :meth:`impact`; the old foot
        leaves with none), world axes."""
        return self._impact_solution(w, y)[6:]

    def on_surface(self, w, z):
        """The state just after a heel strike of section coordinates ``z = [lean, stance,
        rates]``: the swing foot on the slope behind, by Brent's method."""
        def h(th_sw):
            return self.foot_height(w, np.array([z[0], th_sw, z[1], 0, 0, 0]))
        th_sw = brentq(h, -z[1] - 2 * self.gamma - 0.3, -z[1] - 2 * self.gamma + 0.05)
        return np.array([z[0], th_sw, z[1], *z[2:]])
