"""Independent reference for walkers built from parts: legs that differ, a torsional hip
spring-damper, an upper body on a bisecting hip mechanism (not walkerlab code).

Shares no code with ``walkerlab.models``.  Where the generator *eliminates* the coupling
(torso angle = mean of the leg angles, no torso coordinate), this reference keeps the torso
angle as a coordinate and *enforces* the coupling with a Lagrange multiplier (a KKT system for
the flow, an impulsive one for the impact); the impact is the extended-coordinate method (stance
foot free, impulse at the new stance foot, paper Eq. 6-7), not a momentum projection.

Conventions (the issue's): leg angles ``psi`` from the downward vertical, a point ``s`` along a
leg at ``hip + s (sin psi, -cos psi)``; the torso angle from the upward vertical, positive
leaning back, a point ``d`` up it at ``hip + d (-sin t, cos t)``, ``e`` ahead of its axis at
``+ e (cos t, sin t)``; x downhill, y up; the slope falls at ``gamma`` towards +x.  Legs are
physical (``A`` = leg1, ``B`` = leg2); a state is ``[psi_swing, psi_stance, rates]`` with the
stance leg named.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from independent._lagrange import lagrange, lam


@dataclass(frozen=True)
class Parts:
    """Numbers of a walker (SI).  ``legs``: ``{"A": (mass, from_hip[, off_axis]), "B": ...}``
    (a leg's point mass, ``off_axis`` ahead of the leg's axis)."""

    L: float = 1.0
    M_hip: float = 10.0
    legs: dict = field(default_factory=lambda: {"A": (5.0, 0.5), "B": (5.0, 0.5)})
    torso: tuple | None = None          # (mass, up the axis d, off the axis e, inertia)
    spring: tuple = (0.0, 0.0, 0.0)     # (k, rest, c): delta = psi_B - psi_A
    g: float = 9.81
    gamma: float = 0.0174


class PartsReference:
    """Flow, heel-strike map and a step of :class:`Parts` (see module docstring)."""

    def __init__(self, p: Parts):
        self.p = p
        sw, st, th, x, y = sp.symbols("sw st th x y", real=True)
        dsw, dst, dth, dx, dy = sp.symbols("dsw dst dth dx dy", real=True)
        self._fns = {}
        for stance in ("A", "B"):
            swing = "B" if stance == "A" else "A"
            foot = sp.Matrix([x, y])
            hip = foot + p.L * sp.Matrix([-sp.sin(st), sp.cos(st)])

            def on_leg(psi, s, e=0.0, hip=hip):
                return (hip + s * sp.Matrix([sp.sin(psi), -sp.cos(psi)])
                        + e * sp.Matrix([sp.cos(psi), sp.sin(psi)]))
            bodies = [(p.M_hip, 0, hip, 0),
                      (p.legs[stance][0], 0, on_leg(st, *p.legs[stance][1:]), st),
                      (p.legs[swing][0], 0, on_leg(sw, *p.legs[swing][1:]), sw)]
            if p.torso is not None:
                m, d, e, inertia = p.torso
                pos = hip + d * sp.Matrix([-sp.sin(th), sp.cos(th)]) \
                    + e * sp.Matrix([sp.cos(th), sp.sin(th)])
                bodies.append((m, inertia, pos, th))
            psi = {stance: st, swing: sw}
            k, rest, c = p.spring
            delta = psi["B"] - psi["A"]
            swing_foot = on_leg(sw, p.L)
            qe, dqe = [x, y, sw, st, th], [dx, dy, dsw, dst, dth]
            M, h, T, V = lagrange(qe, dqe, bodies, p.g)
            V = V + k * (delta - rest) ** 2 / 2
            ddelta = sum(sp.diff(delta, q) * dq for q, dq in zip(qe, dqe))
            h = h + sp.Matrix([k * (delta - rest) * sp.diff(delta, q)
                               + c * ddelta * sp.diff(delta, q) for q in qe])
            args = (sw, st, th, dsw, dst, dth)
            sub = {x: 0, y: 0, dx: 0, dy: 0}
            h_ext = lam((*args, dx, dy), h.subs({x: 0, y: 0}))
            # pinned stance foot: the angle block of the extended system
            Ma, ha = M[2:, 2:].subs(sub), h[2:, :].subs(sub)
            self._fns[stance] = {
                "M": lam(args, Ma), "h": lam(args, ha), "De": lam(args, M.subs(sub)),
                "E": lam(args, swing_foot.jacobian(sp.Matrix(qe)).subs(sub)),
                "T": lam(args, T.subs(sub)), "V": lam(args, V.subs(sub)),
                "swing_foot": lam(args, swing_foot.subs(sub)),
                "points": lam(args, sp.Matrix.hstack(*[b[2] for b in bodies]).subs(sub)),
                "masses": [b[0] for b in bodies], "angles": [b[3] for b in bodies],
                "h_ext": h_ext,
            }
        # the coupling th - (sw + st) / 2 = 0 (bisecting hip), as a constraint row
        self.a = np.array([-0.5, -0.5, 1.0])

    def floating(self, qf, dqf):
        """Mass matrix and bias ``M qdd + h = 0`` (no contact) in floating coordinates
        ``(hip_x, hip_y, psi_A, psi_B)`` [m, m, rad, rad], from the extended system (stance
        foot free at (x, y), leg B's foot there) through ``q_ext = (hip + L e(psi_B),
        psi_A, psi_B, (psi_A + psi_B) / 2)``."""
        f = self._fns["B"]
        hx, hy, pa, pb = qf
        L = self.p.L
        T = np.zeros((5, 4))
        T[0, 0] = T[1, 1] = T[2, 2] = T[3, 3] = 1.0
        T[0, 3], T[1, 3] = L * np.cos(pb), L * np.sin(pb)
        T[4, 2:] = 0.5 if self.p.torso is not None else 0.0
        Tdot_dq = np.array([-L * np.sin(pb), L * np.cos(pb), 0, 0, 0]) * dqf[3] ** 2
        v = T @ np.asarray(dqf, float)
        args = (pa, pb, 0.5 * (pa + pb), v[2], v[3], v[4], v[0], v[1])
        M = np.asarray(f["De"](*args[:6]), float)
        h = np.asarray(f["h_ext"](*args), float).ravel()
        if self.p.torso is None:
            M, h, T, Tdot_dq = M[:4, :4], h[:4], T[:4], Tdot_dq[:4]
        return T.T @ M @ T, T.T @ (M @ Tdot_dq + h)

    def _full(self, x):
        sw, st, dsw, dst = x
        th = 0.5 * (sw + st) if self.p.torso is not None else 0.0
        dth = 0.5 * (dsw + dst) if self.p.torso is not None else 0.0
        return sw, st, th, dsw, dst, dth

    def flow(self, x, stance):
        """``[rates, accelerations]`` (4,): the KKT system with the coupling enforced."""
        f = self._fns[stance]
        a = self._full(x)
        M, h = np.asarray(f["M"](*a), float), np.asarray(f["h"](*a), float).ravel()
        if self.p.torso is None:  # no torso: its (massless) coordinate is dropped
            acc = np.linalg.solve(M[:2, :2], -h[:2])
            return np.array([x[2], x[3], acc[0], acc[1]])
        K = np.zeros((4, 4))
        K[:3, :3], K[:3, 3], K[3, :3] = M, self.a, self.a
        sol = np.linalg.solve(K, np.concatenate([-h, [0.0]]))
        return np.array([x[2], x[3], sol[0], sol[1]])

    def energy(self, x, stance):
        f = self._fns[stance]
        a = self._full(x)
        return float(f["T"](*a)), float(f["V"](*a))

    def swing_foot(self, x, stance):
        return np.asarray(self._fns[stance]["swing_foot"](*self._full(x)), float).ravel()

    def guard(self, x, stance):
        """Swing foot's height above the slope through the stance foot [m]."""
        fx, fy = self.swing_foot(x, stance)
        g = self.p.gamma
        return fy * np.cos(g) + fx * np.sin(g)

    def angular_momentum(self, x, stance, about):
        """Angular momentum [kg m^2/s] of the walker about the point ``about`` (2,)."""
        f = self._fns[stance]
        a = self._full(x)
        P = np.asarray(f["points"](*a), float)
        dq = np.array(a[3:])
        out = 0.0
        for i, m in enumerate(f["masses"]):
            J = np.array([[complex_step(lambda z, i=i, r=r: np.asarray(
                f["points"](*z[:3], *a[3:]), complex)[r, i], np.array(a[:3]), k)
                for k in range(3)] for r in range(2)])
            v = J @ dq
            r = P[:, i] - about
            out += m * (r[0] * v[1] - r[1] * v[0])
        if self.p.torso is not None:  # the torso's own spin
            out += self.p.torso[3] * a[5]
        return out

    def reset(self, x, stance):
        """Plastic heel strike (impulse at the swing foot, the coupling enforced through it),
        then the role swap; returns the new state (the other leg in stance)."""
        f = self._fns[stance]
        a = self._full(x)
        De = np.asarray(f["De"](*a), float)
        E = np.asarray(f["E"](*a), float)
        rows = [E] + ([np.concatenate([[0.0, 0.0], self.a])[None, :]]
                      if self.p.torso is not None else [])
        A = np.vstack(rows)
        if self.p.torso is None:  # drop the torso coordinate
            De, A = De[:4, :4], A[:, :4]
        m = De.shape[0]
        dq = np.zeros(m)
        dq[2:4] = x[2:]
        if self.p.torso is not None:
            dq[4] = a[5]
        K = np.zeros((m + A.shape[0],) * 2)
        K[:m, :m], K[:m, m:], K[m:, :m] = De, -A.T, A
        sol = np.linalg.solve(K, np.concatenate([De @ dq, np.zeros(A.shape[0])]))
        dsw, dst = sol[2], sol[3]
        return np.array([x[1], x[0], dst, dsw])

    def step(self, x0, stance, rtol=1e-12, atol=1e-12):
        """One step from ``x0``: ``(t_heel, x_minus, x_plus)``."""
        from scipy.integrate import solve_ivp

        def ev(t, x):
            return self.guard(x, stance) if self.swing_foot(x, stance)[0] > 0 else 1.0
        ev.terminal, ev.direction = True, -1
        sol = solve_ivp(lambda t, x: self.flow(x, stance), (0, 5), x0, method="DOP853",
                        rtol=rtol, atol=atol, events=ev, dense_output=True)
        t = float(sol.t_events[0][0])
        xm = sol.y_events[0][0]
        return t, xm, self.reset(xm, stance), sol.sol


def complex_step(fun, z, k, h=1e-30):
    zc = np.asarray(z, complex).copy()
    zc[k] += 1j * h
    return float(np.imag(fun(zc)) / h)
