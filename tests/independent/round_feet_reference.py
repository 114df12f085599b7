"""Independent prototype of the compass gait with circular (round) feet, rolling without slip.

Written from scratch (sympy Lagrange + ``scipy.integrate.solve_ivp`` + ``scipy.optimize.root``)
as a check of walkerlab's generic walker framework; it shares no code with
``walkerlab.models``.

Model (round feet: T. McGeer, "Passive dynamic walking", Int. J. Robotics Research 9(2),
1990; the rigid-leg version with a hip mass, leg mass ``m`` at distance ``c`` from the hip and
leg inertia ``I`` is the one of P. A. Bhounsule's ``passivewalker.m``, Cornell 2009,
pab47/pab47.github.io): each leg of length ``L`` (hip to sole) ends in a circular arc of radius
``R`` centred on the leg axis at ``L - R`` from the hip.  The stance foot rolls without slip
on the slope; heel strike when the swing arc touches the slope (swing foot ahead); the impact is
plastic about the new contact point.

State ``x = [th_sw, th_st, w_sw, w_st]``: absolute leg angles from the world vertical [rad]
(walkerlab's sign convention) and rates [rad/s].  The slope falls towards +x at angle
``gamma``; ``psi = th + gamma`` is a leg's angle from the slope normal.  Positions are
relative to the stance foot's *reference point*: the point of the slope the stance arc
touches when ``psi_st = 0``; the contact point is then ``-R psi_st`` along the slope.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp
from scipy.optimize import root

from ._lagrange import lagrange, lam

#: Bhounsule's passivewalker.m round-foot set (nondimensional: g = 1, hip-to-arc-centre 1).
BHOUNSULE = {"g": 1.0, "L": 1.2, "R": 0.2, "M": 1.0, "m": 0.5, "c": 0.5, "I": 0.02,
             "gamma": 0.01}
#: Its printed stable root, converted to our state: ``[q1, u1, q2, u2]`` =
#: [0.189472782205104, -0.239124222551699, 0.378945564410209, -0.053691703909393] with
#: ``q1`` = psi_st, ``q1 - q2`` = psi_sw, ``u1`` = w_st, ``u1 - u2`` = w_sw.
_Z = (0.189472782205104, -0.239124222551699, 0.378945564410209, -0.053691703909393)
BHOUNSULE_FIXED_POINT = np.array([_Z[0] - _Z[2] - 0.01, _Z[0] - 0.01, _Z[1] - _Z[3], _Z[1]])


@cache
def _symbolic():
    q = sp.symbols("th_sw th_st", real=True)
    dq = sp.symbols("w_sw w_st", real=True)
    g, L, R, M, m, c, Ileg, gm = sp.symbols("g L R M m c I gamma", real=True)
    th_sw, th_st = q
    n = sp.Matrix([sp.sin(gm), sp.cos(gm)])       # slope normal (up)
    tt = sp.Matrix([sp.cos(gm), -sp.sin(gm)])     # slope tangent (downhill)
    up = lambda th: sp.Matrix([-sp.sin(th), sp.cos(th)])  # noqa: E731
    contact = -R * (th_st + gm) * tt
    centre_st = contact + R * n
    hip = centre_st + (L - R) * up(th_st)
    centre_sw = hip - (L - R) * up(th_sw)
    pts = {
        "stance_contact": contact,
        "stance_centre": centre_st,
        "hip": hip,
        "stance_mass": hip - c * up(th_st),
        "swing_mass": hip - c * up(th_sw),
        "swing_centre": centre_sw,
        "swing_contact": centre_sw - R * n,
        "next_reference": centre_sw - R * n + R * (th_sw + gm) * tt,
    }
    bodies = [(M, 0, hip, th_st), (m, Ileg, pts["stance_mass"], th_st),
              (m, Ileg, pts["swing_mass"], th_sw)]
    Mm, h, T, V = lagrange(q, dq, bodies, g)
    # heel strike: extended coordinates (the whole walker translated by (xf, yf))
    xf, yf, dxf, dyf = sp.symbols("xf yf dxf dyf", real=True)
    qe, dqe = (*q, xf, yf), (*dq, dxf, dyf)
    off = sp.Matrix([xf, yf])
    Me, _, _, _ = lagrange(qe, dqe, [(mm, ii, p + off, a) for mm, ii, p, a in bodies], g,
                           mass_matrix_only=True)
    # velocity of the swing foot's material point at the contact: v_centre + w x (-R n)
    qev = sp.Matrix(qe)
    v_centre_J = (centre_sw + off).jacobian(qev)
    w_J = sp.Matrix([th_sw]).jacobian(qev)
    r = -R * n
    E = v_centre_J + sp.Matrix([[-r[1]], [r[0]]]) * w_J
    par = (g, L, R, M, m, c, Ileg, gm)
    return q, dq, par, Mm, h, T, V, Me, E, pts


@cache
def _lambdified():
    q, dq, par, Mm, h, T, V, Me, E, pts = _symbolic()
    a = (q, dq, par)
    return {"M": lam((q, par), Mm), "h": lam(a, h), "T": lam(a, T), "V": lam((q, par), V),
            "Me": lam((q, par), Me), "E": lam((q, par), E),
            "pts": {k: lam((q, par), v) for k, v in pts.items()}}


@dataclass
class RoundFeetReference:
    """Round-foot compass gait (independent prototype)."""

    p: dict = field(default_factory=lambda: dict(BHOUNSULE))
    rtol: float = 1e-12
    atol: float = 1e-12

    @property
    def _f(self):
        return _lambdified()

    def _par(self):
        p = self.p
        return (p["g"], p["L"], p["R"], p["M"], p["m"], p["c"], p["I"], p["gamma"])

    def flow(self, t, x):
        q, dq = x[:2], x[2:]
        M = self._f["M"](q, self._par())
        h = self._f["h"](q, dq, self._par()).ravel()
        return np.concatenate([dq, np.linalg.solve(M, -h)])

    def point(self, name, x):
        return self._f["pts"][name](x[:2], self._par()).ravel()

    def energies(self, x):
        return (float(self._f["T"](x[:2], x[2:], self._par())),
                float(self._f["V"](x[:2], self._par())))

    def heel_strike_guard(self, x):
        return x[0] + x[1] + 2 * self.p["gamma"]

    def impact(self, x, return_extra=False):
        q, dq = x[:2], x[2:]
        Me = self._f["Me"](q, self._par())
        E = self._f["E"](q, self._par())
        A = np.zeros((6, 6))
        A[:4, :4] = Me
        A[:4, 4:] = -E.T
        A[4:, :4] = E
        rhs = np.concatenate([Me @ np.concatenate([dq, [0.0, 0.0]]), [0.0, 0.0]])
        sol = np.linalg.solve(A, rhs)
        x_plus = np.array([q[1], q[0], sol[1], sol[0]])
        if return_extra:
            return x_plus, {"impulse": sol[4:]}
        return x_plus

    def step(self, x0, dense=False):
        tol = dict(rtol=self.rtol, atol=self.atol, method="DOP853")

        def heel(t, x):
            return self.heel_strike_guard(x) if x[0] > x[1] else 1.0
        heel.terminal, heel.direction = True, -1
        s = solve_ivp(self.flow, (0, 20), x0, events=[heel], dense_output=True, **tol)
        if not len(s.t_events[0]):
            raise RuntimeError("no heel strike")
        out = {"t_heel": s.t_events[0][0], "x_heel_minus": s.y_events[0][0],
               "x_next": self.impact(s.y_events[0][0])}
        if dense:
            out["sol"] = s.sol
        return out

    def from_section(self, z):
        return np.array([-2 * self.p["gamma"] - z[0], z[0], z[1], z[2]])

    @staticmethod
    def section(x):
        return np.asarray(x)[1:]

    def poincare(self, z):
        return self.section(self.step(self.from_section(z))["x_next"])

    def fixed_point(self, x_guess, xtol=1e-13):
        sol = root(lambda z: self.poincare(z) - z, self.section(x_guess), method="hybr",
                   options={"xtol": xtol})
        if not sol.success:
            raise RuntimeError(sol.message)
        return self.from_section(sol.x)

    def multipliers(self, x_star, h=1e-6):
        z = self.section(x_star)
        J = np.empty((3, 3))
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            J[:, k] = (self.poincare(z + e) - self.poincare(z - e)) / (2 * h)
        ev = np.linalg.eigvals(J)
        return ev[np.argsort(-np.abs(ev))]


if __name__ == "__main__":  # pragma: no cover
    np.set_printoptions(precision=15)
    w = RoundFeetReference()
    xs = w.fixed_point(BHOUNSULE_FIXED_POINT)
    print("fixed point", xs, "published", BHOUNSULE_FIXED_POINT, "diff",
          np.abs(xs - BHOUNSULE_FIXED_POINT).max())
    print("period", w.step(xs)["t_heel"])
    mu = w.multipliers(xs)
    print("multipliers", mu, np.abs(mu))
