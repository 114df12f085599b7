"""Independent reference of a walker on flat feet with ankle springs (rigid view), sharing no
code with walkerlab's generator (:mod:`walkerlab.codegen.foot_modes`).

Written from scratch for the point-mass walker of ``configs/flat_feet.yaml`` (hip mass ``M``,
one point mass ``m`` per leg at ``b`` from the hip, leg ``L`` hip to ankle; massless flat
feet, heel ``h`` behind and toe ``t`` ahead of the ankle on the sole line; ankle spring ``k``,
rest angle ``r``, damper ``c``; slope ``gamma``), with its OWN coordinates per mode:

- ``heel``  (heel contact): ``(swing, stance, ankle)``, the heel pinned at the origin;
- ``toe``   (heel off): ``(swing, stance, ankle)``, the toe pinned at ``(h + t)`` down the slope;
- ``flat``  (foot flat): only ``(swing, stance)``, the ankle fixed at ``h`` down the slope
  (the locked foot angle eliminated, not enforced by a multiplier as the generator does).

Each mode's equations come from its own Lagrangian (``T - V``, ``V`` gravity plus
``k (ankle - r)^2 / 2``) through the small sympy helper of this folder, plus the damper's
generalised force ``-c (d ankle/dt) d ankle/dq``.  Impacts are momentum
projections written here: foot slap ``M_flat dq+ = sum J_flat^T m v-`` (both heel and toe
pinned after the slap), heel strike ``M_heel(new) dq+ = sum J_heel(new)^T m v-`` in the new
labelling (new heel at the origin, new ankle at the rest angle).  The ground reaction in foot
flat: ``N = sum m (a + g y) . n`` and the toe's share from the moment about the heel.
"""

from __future__ import annotations

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from tests.independent._lagrange import lagrange, lam


class FlatFeetReference:
    """The reference walker; ``p``: ``M, m, b, L, h, t, k, r, c, gamma, g`` (SI)."""

    def __init__(self, p: dict):
        self.p = dict(p)
        M, m, b, L, h, t = (p[k] for k in ("M", "m", "b", "L", "h", "t"))
        k, r, c, gamma, g = (p[k] for k in ("k", "r", "c", "gamma", "g"))
        sw, st, an = sp.symbols("sw st an", real=True)
        dsw, dst, dan = sp.symbols("dsw dst dan", real=True)
        slope = sp.Matrix([sp.cos(gamma), -sp.sin(gamma)])
        self.normal = np.array([np.sin(gamma), np.cos(gamma)])

        def legs(ankle, stance, swing):
            hip = ankle + L * sp.Matrix([-sp.sin(stance), sp.cos(stance)])
            m_st = hip + b * sp.Matrix([sp.sin(stance), -sp.cos(stance)])
            m_sw = hip + b * sp.Matrix([sp.sin(swing), -sp.cos(swing)])
            sw_ankle = hip + L * sp.Matrix([sp.sin(swing), -sp.cos(swing)])
            sw_heel = sw_ankle - h * sp.Matrix([sp.cos(swing + r), sp.sin(swing + r)])
            return {"hip": (M, hip), "stance_mass": (m, m_st), "swing_mass": (m, m_sw),
                    "swing_ankle": (0, sw_ankle), "swing_heel": (0, sw_heel)}

        foot = sp.Matrix([sp.cos(st + an), sp.sin(st + an)])
        ankles = {"heel": h * foot, "toe": (h + t) * slope - t * foot, "flat": h * slope}
        self.modes = {}
        for mode, ankle in ankles.items():
            q = [sw, st] if mode == "flat" else [sw, st, an]
            dq = [dsw, dst] if mode == "flat" else [dsw, dst, dan]
            pts = legs(ankle.subs(an, -gamma - st) if mode == "flat" else ankle, st, sw)
            bodies = [(mass, 0, pos, 0) for name, (mass, pos) in pts.items() if mass != 0]
            Mm, hvec, T, V = lagrange(q, dq, bodies, g)
            a_spring = (-gamma - st) if mode == "flat" else an
            Vs = k * (a_spring - r) ** 2 / 2
            da = sum(sp.diff(a_spring, qi) * dqi for qi, dqi in zip(q, dq))
            hvec = hvec + sp.Matrix([sp.diff(Vs, qi) + c * da * sp.diff(a_spring, qi)
                                     for qi in q])
            qdd = sp.symbols(f"qdd0:{len(q)}", real=True)
            qv, dqv, ddv = sp.Matrix(q), sp.Matrix(dq), sp.Matrix(qdd)
            ground = sp.zeros(2, 1)
            moment = sp.Integer(0)
            for mass, _i, pos, _a in bodies:
                vel = pos.jacobian(qv) * dqv
                acc = vel.jacobian(qv) * dqv + vel.jacobian(dqv) * ddv
                f = mass * (acc + sp.Matrix([0, g]))
                ground += f
                moment += pos[0] * f[1] - pos[1] * f[0]
            args = (*q, *dq)
            self.modes[mode] = {
                "n": len(q),
                "M": lam(q, Mm), "h": lam(args, hvec),
                "T": lam(args, T), "V": lam(q, V + Vs),
                "points": {n: lam(q, pos) for n, (_m, pos) in pts.items()},
                "J": {n: lam(q, pos.jacobian(qv)) for n, (_m, pos) in pts.items()},
                "masses": {n: mass for n, (mass, _p) in pts.items() if mass != 0},
                "ground": lam((*args, *qdd), [ground[0], ground[1], moment]),
            }

    # ------------------------------------------------------------------ flow and energy
    def qdd(self, mode: str, x: np.ndarray) -> np.ndarray:
        """Accelerations of ``mode`` at ``x = [q, dq]`` (its own coordinates)."""
        md = self.modes[mode]
        n = md["n"]
        return np.linalg.solve(md["M"](*x[:n]), -md["h"](*x).ravel())

    def rhs(self, mode: str):
        def f(_t, x):
            return np.concatenate([x[self.modes[mode]["n"]:], self.qdd(mode, x)])
        return f

    def energy(self, mode: str, x: np.ndarray) -> float:
        """Kinetic + gravity + ankle spring [J] (gravity from the origin's height)."""
        md = self.modes[mode]
        return float(md["T"](*x) + md["V"](*x[:md["n"]]))

    def ground(self, mode: str, x: np.ndarray) -> tuple[float, float]:
        """``(N, N_toe)``: total normal ground force and, in foot flat, the toe's [N]."""
        fx, fy, mom = self.modes[mode]["ground"](*x, *self.qdd(mode, x))
        n = float(fx * self.normal[0] + fy * self.normal[1])
        return n, float(mom) / (self.p["h"] + self.p["t"])

    def velocities(self, mode: str, x: np.ndarray) -> dict:
        """World velocity of each massive body [m/s]."""
        md = self.modes[mode]
        n = md["n"]
        return {k: md["J"][k](*x[:n]) @ x[n:] for k in md["masses"]}

    def positions(self, mode: str, q: np.ndarray) -> dict:
        md = self.modes[mode]
        return {k: np.ravel(f(*q)) for k, f in md["points"].items()}

    # ------------------------------------------------------------------ impacts
    def foot_slap(self, x: np.ndarray) -> np.ndarray:
        """Heel contact state (3 coordinates) at the toe's touchdown -> foot flat state
        ``[swing, stance, d swing, d stance]`` (both contacts pinned after the slap)."""
        v = self.velocities("heel", x)
        flat = self.modes["flat"]
        q = x[:2]
        rhs = sum(flat["masses"][k] * flat["J"][k](*q).T @ v[k] for k in v)
        return np.concatenate([q, np.linalg.solve(flat["M"](*q), rhs)])

    def heel_strike(self, mode: str, x: np.ndarray) -> np.ndarray:
        """Pre-impact state of ``mode`` -> post-impact heel-contact state in the new
        labelling (new swing = old stance leg, new stance = old swing leg, ankle = r)."""
        md = self.modes[mode]
        v = self.velocities(mode, x)
        qn = np.array([x[1], x[0], self.p["r"]])
        heel = self.modes["heel"]
        pair = {"hip": "hip", "stance_mass": "swing_mass", "swing_mass": "stance_mass"}
        rhs = sum(heel["masses"][k] * heel["J"][k](*qn).T @ v[pair[k]] for k in pair)
        del md
        return np.concatenate([qn, np.linalg.solve(heel["M"](*qn), rhs)])

    # ------------------------------------------------------------------ one step
    def step(self, x0: np.ndarray, rtol: float = 1e-12) -> dict:
        """One step from a post-impact heel-contact state: heel contact until the foot lies
        flat, foot slap, foot flat until the heel's force reaches 0, heel off until the
        swing heel reaches the slope after mid-stance, heel strike.

        Returns ``{"modes": [...], "times": [...], "x_minus": pre-impact state of the last
        mode, "x_plus": post-impact state, "t": step period}``.
        """
        gamma = self.p["gamma"]
        kw = dict(rtol=rtol, atol=rtol, dense_output=False)
        out = {"modes": [], "times": []}

        def ev(fun, direction):
            fun.terminal, fun.direction = True, direction
            return fun

        # heel contact: the foot turns about the heel until it lies flat (phi = 0)
        s = solve_ivp(self.rhs("heel"), (0, 5), x0, events=[ev(
            lambda t, x: x[1] + x[2] + gamma, -1)], **kw)
        t1, x1 = s.t_events[0][0], s.y_events[0][0]
        out["modes"].append("heel_contact")
        out["times"].append(t1)
        z = self.foot_slap(x1)

        def heel_force(t, x):
            n, n_toe = self.ground("flat", x)
            return n - n_toe
        s = solve_ivp(self.rhs("flat"), (t1, t1 + 5), z, events=[ev(heel_force, -1)], **kw)
        t2, z2 = s.t_events[0][0], s.y_events[0][0]
        out["modes"].append("foot_flat")
        out["times"].append(t2)
        x2 = np.array([z2[0], z2[1], -gamma - z2[1], z2[2], z2[3], -z2[3]])
        heel_pt = self.modes["toe"]["points"]["swing_heel"]
        if not x2[0] > x2[1]:
            raise ValueError("the reference step expects heel off after mid-stance")

        def swing_heel(t, x):
            return float(np.ravel(heel_pt(*x[:3])) @ self.normal)
        s = solve_ivp(self.rhs("toe"), (t2, t2 + 5), x2, events=[ev(swing_heel, -1)], **kw)
        t3, x3 = s.t_events[0][0], s.y_events[0][0]
        out["modes"].append("heel_off")
        out["times"].append(t3)
        out.update(x_minus=x3, x_plus=self.heel_strike("toe", x3), t=t3)
        return out
