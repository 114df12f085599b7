"""An independent compass-gait walker going down stairs (no walkerlab code): level treads, the
heel strike when the swing foot reaches the next tread ``H`` below the stance foot.

Its own conventions and equations (derived by hand from the Lagrangian, written out below):
absolute leg angles from the vertical, positive when the foot is ahead of the hip, state
``(phi_sw, phi_st, w_sw, w_st)``; stance foot at the origin, x forward, y up; each leg's
mass ``m`` at ``a`` from its foot (``b = L - a`` from the hip), hip mass ``mh``.

    T = 1/2 (mh L^2 + m a^2 + m L^2) w_st^2 + 1/2 m b^2 w_sw^2 - m L b cos(phi_st - phi_sw)
        w_st w_sw
    V = g ((mh L + m a + m L) cos phi_st - m b cos phi_sw)

Lagrange's equations (s, c of ``phi_st - phi_sw``):

    m b^2 w_sw' - m L b c w_st' + m L b s w_st^2 + m g b sin phi_sw = 0
    I w_st' - m L b c w_sw' - m L b s w_sw^2 - g (mh L + m a + m L) sin phi_st = 0

Heel strike (plastic, the trailing foot leaves the ground): the angular momentum of the
whole walker about the landing foot and of the trailing leg about the hip are conserved
(computed from the point masses' positions and velocities, not from the equations above);
the legs swap roles.  Poincaré section: just after heel strike, where the new swing foot is
``H`` above the new stance foot; parametrised by ``(phi_st, w_sw, w_st)``.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve


class StairsCompass:
    """The walker and its step-to-step map down stairs of riser ``H`` [m]."""

    def __init__(self, H, L=1.0, m=5.0, mh=10.0, a=0.5, g=9.81, rtol=1e-13, atol=1e-13):
        self.H, self.L, self.m, self.mh, self.a, self.g = H, L, m, mh, a, g
        self.b = L - a
        self.rtol, self.atol = rtol, atol

    # -- flow ---------------------------------------------------------------------------
    def rhs(self, t, x):
        p_sw, p_st, w_sw, w_st = x
        L, m, mh, a, b, g = self.L, self.m, self.mh, self.a, self.b, self.g
        c, s = np.cos(p_st - p_sw), np.sin(p_st - p_sw)
        inertia = mh * L**2 + m * a**2 + m * L**2
        M = np.array([[m * b**2, -m * L * b * c], [-m * L * b * c, inertia]])
        rhs = -np.array([m * L * b * s * w_st**2 + m * g * b * np.sin(p_sw),
                         -m * L * b * s * w_sw**2 - g * (mh * L + m * a + m * L) * np.sin(p_st)])
        acc = np.linalg.solve(M, rhs)
        return [w_sw, w_st, acc[0], acc[1]]

    def foot_height(self, x):
        """Swing foot's height above the stance foot [m]."""
        return self.L * (np.cos(x[1]) - np.cos(x[0]))

    # -- impact -------------------------------------------------------------------------
    def _masses(self, q, w):
        """(mass, position, velocity) of each point mass; q = (phi_sw, phi_st)."""
        p_sw, p_st = q
        w_sw, w_st = w
        L, a, b = self.L, self.a, self.b
        hip = np.array([-L * np.sin(p_st), L * np.cos(p_st)])
        v_hip = L * w_st * np.array([-np.cos(p_st), -np.sin(p_st)])
        st = np.array([-a * np.sin(p_st), a * np.cos(p_st)])
        v_st = a * w_st * np.array([-np.cos(p_st), -np.sin(p_st)])
        sw = hip + b * np.array([np.sin(p_sw), -np.cos(p_sw)])
        v_sw = v_hip + b * w_sw * np.array([np.cos(p_sw), np.sin(p_sw)])
        foot = hip + L * np.array([np.sin(p_sw), -np.cos(p_sw)])
        return [(self.mh, hip, v_hip), (self.m, st, v_st), (self.m, sw, v_sw)], hip, foot

    @staticmethod
    def _h(m, r, v, p):
        d = r - p
        return m * (d[0] * v[1] - d[1] * v[0])

    def reset(self, x):
        """Heel-strike map (roles swapped)."""
        q, w = x[:2], x[2:]
        bodies, hip, foot = self._masses(q, w)
        h_all = sum(self._h(m_, r, v, foot) for m_, r, v in bodies)
        h_leg = self._h(*bodies[1], hip)  # the trailing (old stance) leg about the hip
        qn = np.array([q[1], q[0]])  # new swing = old stance, new stance = old swing

        def moments(wn):  # the same two momenta after impact, new stance foot at rest
            bn, hipn, _ = self._masses(qn, wn)
            # new frame: stance foot at the origin; the old swing foot is the new stance foot
            return np.array([sum(self._h(m_, r, v, np.zeros(2)) for m_, r, v in bn),
                             self._h(*bn[2], hipn)])
        A = np.column_stack([moments(np.array([1.0, 0.0])), moments(np.array([0.0, 1.0]))])
        wn = np.linalg.solve(A, np.array([h_all, h_leg]))
        return np.array([qn[0], qn[1], wn[0], wn[1]])

    # -- map ----------------------------------------------------------------------------
    def step(self, x):
        """(pre-impact state, step time) of the step from the post-impact state ``x``."""
        def ev(t, y):
            return self.foot_height(y) + self.H
        ev.terminal, ev.direction = True, -1
        sol = solve_ivp(self.rhs, (0, 5.0), x, method="DOP853", rtol=self.rtol,
                        atol=self.atol, events=ev)
        assert sol.t_events[0].size, "no heel strike"
        return sol.y_events[0][0], float(sol.t_events[0][0])

    def map(self, x):
        y, _ = self.step(x)
        return self.reset(y)

    def from_z(self, z):
        p_st, w_sw, w_st = z
        p_sw = -np.arccos(np.cos(p_st) - self.H / self.L)  # trailing foot H above
        return np.array([p_sw, p_st, w_sw, w_st])

    def fixed_point(self, x0):
        z0 = np.array([x0[1], x0[2], x0[3]])
        with warnings.catch_warnings():  # "no further improvement": at round-off
            warnings.simplefilter("ignore", RuntimeWarning)
            z = fsolve(lambda z: self.map(self.from_z(z))[1:] - z, z0, xtol=1e-14)
        return self.from_z(z)

    def multipliers(self, x, h=1e-4):
        """Eigenvalues of the section map's Jacobian (3 x 3, five-point differences), with
        the zero multiplier of the full-state map appended; sorted by modulus."""
        z = x[1:]
        J = np.empty((3, 3))
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            f = [self.map(self.from_z(z + c * e))[1:] for c in (-2, -1, 1, 2)]
            J[:, k] = (f[0] - 8 * f[1] + 8 * f[2] - f[3]) / (12 * h)
        mu = np.concatenate([np.linalg.eigvals(J), [0.0]])
        return mu[np.argsort(-np.abs(mu), kind="stable")]


class FootholdsCompass(StairsCompass):
    """The same walker on footholds of several heights: step ``k`` of a walk lands
    ``drops[k % p]`` [m] below its stance foot (no walkerlab code).  Its Poincaré map walks
    the ``p`` steps of the list; the section is the state just after the list's last heel
    strike, where the new swing foot is ``drops[-1]`` above the new stance foot."""

    def __init__(self, drops, **kw):
        super().__init__(float(drops[-1]), **kw)
        self.drops = [float(d) for d in drops]

    def step_on(self, x, H):
        """(pre-impact state, step time) of a step landing ``H`` [m] below."""
        self.H, keep = H, self.H
        try:
            return self.step(x)
        finally:
            self.H = keep

    def map(self, x):
        for H in self.drops:
            y, _ = self.step_on(x, H)
            x = self.reset(y)
        return x

    def period(self, x):
        """Duration of one map (all the list's steps) [s] from ``x``."""
        t = 0.0
        for H in self.drops:
            y, dt = self.step_on(x, H)
            x, t = self.reset(y), t + dt
        return t
