"""An independent reference for the 3D straight-legged walker on feet curved in both
directions (``walker.leg.foot.kind: toroidal``; Coleman & Ruina 1998, PRL 80(16); Collins,
Wisse & Ruina 2001, IJRR 20(7)), written from Newton-Euler's laws with numpy alone (no
sympy, no walkerlab): each leg a rigid body (its point mass and a slender rod's inertia),
the pelvis a point mass; velocities and accelerations propagated from the stance foot's
torus centre, whose velocity is the no-slip condition ``v_c = omega_st x (c - p)`` (``p``
the foot's lowest point, ``c - p = (R - R_l) e2 + R_l n``, ``e2`` the rolled normal): the
rolling written as a velocity constraint (non-holonomic as it is), not as the generator's
reduction; Kane's equations (partial velocities) for the flow; the plastic impact with the
impulse at the new foot's material contact point as an unknown (the old stance torus'
centre free).  ``R_l = 0`` is tests/test_round_feet_3d.py's disc foot.

Also :func:`travel_rate`: the stance contact's speed along the fall line (its integral is
the step's true advance).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from tests.independent.mirror_stride import to_heel_strike

__all__ = ["TorusReference"]


class TorusReference:
    """Newton-Euler's walker (module docstring); state ``[lean, swing, stance, rates]`` as
    walkerlab's, ``w`` the swing hip's offset along the hip axis (its sign: the side)."""

    def __init__(self, g, L, gamma, M, m, a, I_leg, R, R_l=0.0, arms=None):
        self.g, self.L, self.gamma, self.M, self.m, self.a, self.I, self.R = (
            g, L, gamma, M, m, a, I_leg, R)
        self.R_l = R_l
        #: arms coupled to the opposite legs: dict(h, r, m, d, I) (shoulders h above the
        #: hips, r hip widths apart; each arm's mass m at d down it, I normal to it)
        self.arms = arms
        self.s = np.array([math.cos(gamma), -math.sin(gamma), 0.0])   # the fall line
        self.n = np.array([math.sin(gamma), math.cos(gamma), 0.0])    # the slope's normal
        self.z = np.array([0.0, 0.0, 1.0])

    def _frames(self, q):
        """The roll (about the fall line) and each leg's axis (foot to hip, unit)."""
        roll = Rotation.from_rotvec(q[0] * self.s).as_matrix()

        def up(th):
            return roll @ Rotation.from_rotvec(th * self.z).as_matrix() @ [0.0, 1.0, 0.0]
        return roll, up(q[1]), up(q[2])

    def kinematics(self, w, q, dq, ddq, v_centre=None):
        """Positions (from the stance contact point), velocities and accelerations of the
        points, each leg's angular velocity and acceleration.  ``v_centre``: the stance
        disc centre's velocity given (the impact's free old foot), else rolling."""
        L, R, a = self.L, self.R, self.a
        roll, u_sw, u_st = self._frames(q)
        e2, e3 = roll @ self.n, roll @ self.z         # the rolled normal and hip axis
        w_p, al_p = dq[0] * self.s, ddq[0] * self.s
        w_st = w_p + dq[2] * e3
        w_sw = w_p + dq[1] * e3
        de3 = np.cross(w_p, e3)
        al_st = al_p + ddq[2] * e3 + dq[2] * de3
        al_sw = al_p + ddq[1] * e3 + dq[1] * de3
        pos, vel, acc = {}, {}, {}
        rho, R_l = R - self.R_l, self.R_l
        arm = rho * e2 + R_l * self.n             # the torus' centre from its lowest point
        pos["centre"] = arm
        if v_centre is None:   # no slip: the contact's material point at rest
            vel["centre"] = np.cross(w_st, arm)
            acc["centre"] = (np.cross(al_st, arm)
                             + np.cross(w_st, rho * np.cross(w_p, e2)))
        else:
            vel["centre"], acc["centre"] = np.asarray(v_centre), np.zeros(3)

        def rigid(name, base, r, omega, alpha):
            pos[name] = pos[base] + r
            vel[name] = vel[base] + np.cross(omega, r)
            acc[name] = acc[base] + np.cross(alpha, r) + np.cross(omega, np.cross(omega, r))

        rigid("hip", "centre", (L - R) * u_st, w_st, al_st)
        rigid("stance_mass", "centre", (a - R) * u_st, w_st, al_st)
        rigid("pelvis", "hip", w / 2 * e3, w_p, al_p)
        rigid("swing_hip", "hip", w * e3, w_p, al_p)
        rigid("swing_mass", "swing_hip", -(L - a) * u_sw, w_sw, al_sw)
        rigid("swing_centre", "swing_hip", -(L - R) * u_sw, w_sw, al_sw)
        rigid("swing_contact", "swing_centre", -rho * e2 - R_l * self.n, w_sw,
              al_sw)   # its material point
        legs = [(w_st, al_st, u_st, self.I), (w_sw, al_sw, u_sw, self.I)]
        if self.arms:   # each arm parallel to the opposite leg, on the pelvis' shoulder
            A = self.arms
            for side, k, w_arm, al_arm, u in (("stance", -1, w_sw, al_sw, u_sw),
                                              ("swing", 1, w_st, al_st, u_st)):
                rigid(f"{side}_shoulder", "hip", A["h"] * e2 + w * (1 + k * A["r"]) / 2 * e3,
                      w_p, al_p)
                rigid(f"{side}_arm", f"{side}_shoulder", -A["d"] * u, w_arm, al_arm)
                legs.append((w_arm, al_arm, u, A["I"]))
        return pos, vel, acc, legs

    def bodies(self):
        arms = [(f"{s}_arm", self.arms["m"]) for s in ("stance", "swing")] if self.arms else []
        return [("pelvis", self.M), ("stance_mass", self.m), ("swing_mass", self.m)] + arms

    def _partials(self, w, q, v_centre=False):
        """Partial velocities (3, k) of the points and angular velocities of the legs, with
        ``v_centre`` the stance centre's velocity three more rates (k = 6), else k = 3."""
        k = 6 if v_centre else 3
        cols = []
        for j in range(k):
            e = np.zeros(k)
            e[j] = 1.0
            cols.append(self.kinematics(w, q, e[:3], np.zeros(3),
                                        e[3:] if v_centre else None))
        vel = {p: np.column_stack([c[1][p] for c in cols]) for p in cols[0][1]}
        om = [np.column_stack([c[3][i][0] for c in cols]) for i in range(len(cols[0][3]))]
        return vel, om

    def _inertia(self, u, inertia):
        return inertia * (np.eye(3) - np.outer(u, u))

    def rhs(self, w):
        grav = np.array([0.0, -self.g, 0.0])

        def f(t, x):
            q, dq = x[:3], x[3:]
            vel, om = self._partials(w, q)
            _, _, acc, legs = self.kinematics(w, q, dq, np.zeros(3))   # the bias
            Mq, rhs = np.zeros((3, 3)), np.zeros(3)
            for p, m in self.bodies():
                Mq += m * vel[p].T @ vel[p]
                rhs += vel[p].T @ (m * (grav - acc[p]))
            for W, (omega, alpha, u, inertia) in zip(om, legs):
                Ib = self._inertia(u, inertia)
                Mq += W.T @ Ib @ W
                rhs -= W.T @ (Ib @ alpha + np.cross(omega, Ib @ omega))
            return np.concatenate([dq, np.linalg.solve(Mq, rhs)])
        return f

    def energy(self, w, x):
        """Kinetic plus potential energy (the stance contact at height 0)."""
        pos, vel, _, legs = self.kinematics(w, x[:3], x[3:], np.zeros(3))
        e = 0.0
        for p, m in self.bodies():
            e += 0.5 * m * vel[p] @ vel[p] + m * self.g * pos[p][1]
        for omega, _, u, inertia in legs:
            e += 0.5 * omega @ self._inertia(u, inertia) @ omega
        return e

    def foot_height(self, w, x):
        return float(self.n @ self.kinematics(w, x[:3], x[3:], np.zeros(3))[0]["swing_contact"])

    def impact_rates(self, w, y):
        """The plastic impact: extended rates ``[dq, v_centre]`` (the old stance disc's
        centre free), ``M_e (v+ - v-) = E^T F`` and ``E v+ = 0`` (the new foot's material
        contact point at rest); returns ``dq+`` (before the roles swap) and ``v_centre+``."""
        q, dq = y[:3], y[3:]
        vel, om = self._partials(w, q, v_centre=True)
        _, _, _, legs = self.kinematics(w, q, dq, np.zeros(3))
        Me = np.zeros((6, 6))
        for p, m in self.bodies():
            Me += m * vel[p].T @ vel[p]
        for W, (_, _, u, inertia) in zip(om, legs):
            Me += W.T @ self._inertia(u, inertia) @ W
        E = vel["swing_contact"]
        v_minus = np.concatenate([dq, self.kinematics(w, q, dq, np.zeros(3))[1]["centre"]])
        K = np.block([[Me, -E.T], [E, np.zeros((3, 3))]])
        sol = np.linalg.solve(K, np.concatenate([Me @ v_minus, np.zeros(3)]))
        return sol[:3], sol[3:6]

    def impact(self, w, y):
        dqp = self.impact_rates(w, y)[0]
        q = y[:3]
        return np.array([q[0], q[2], q[1], dqp[0], dqp[2], dqp[1]])

    def momentum_about(self, w, q, dq, point, v_centre=None):
        """Angular momentum (3,) about ``point`` (from the stance contact)."""
        pos, vel, _, legs = self.kinematics(w, q, dq, np.zeros(3), v_centre)
        h = np.zeros(3)
        for p, m in self.bodies():
            h += m * np.cross(pos[p] - point, vel[p])
        for omega, _, u, inertia in legs:
            h += self._inertia(u, inertia) @ omega
        return h

    def step(self, w, x):
        """One step from just after a heel strike: ``(x just after the next one, period)``."""
        y, t2 = to_heel_strike(self.rhs(w), x, 1, 2, lambda y: self.foot_height(w, y), 10.0)
        return self.impact(w, y), t2

    def on_surface(self, w, z):
        """The state just after a heel strike from ``z = [lean, stance, rates]``: the swing
        foot on the slope behind (Brent's method)."""
        def h(th_sw):
            return self.foot_height(w, np.array([z[0], th_sw, z[1], 0, 0, 0]))
        th_sw = brentq(h, -z[1] - 2 * self.gamma - 0.3, -z[1] - 2 * self.gamma + 0.05)
        return np.array([z[0], th_sw, z[1], *z[2:]])

    def contact_velocity(self, w, x):
        """The stance contact point's velocity (3,) along the slope (the torus centre's less
        the lowest point's turning: ``p' = c' - rho (omega_p x e2)``)."""
        _, vel, _, _ = self.kinematics(w, x[:3], x[3:], np.zeros(3))
        roll = Rotation.from_rotvec(x[0] * self.s).as_matrix()
        return vel["centre"] - (self.R - self.R_l) * np.cross(x[3] * self.s, roll @ self.n)
