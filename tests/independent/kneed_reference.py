"""Independent prototype of the kneed passive walker (Hsu Chen 2007 point-mass model).

Written from scratch (sympy Lagrange + ``scipy.integrate.solve_ivp`` events +
``scipy.optimize.root``) to check walkerlab's generic walker framework; it shares no code
with ``walkerlab.models``.

Model (V. F. Hsu Chen, "Passive dynamic walking with knees: a point foot model", MIT
M.Eng. thesis, 2007; parameters as in R. Tedrake's ``kneedCompassGait.m`` that simulates
it): straight stance leg; swing leg = thigh + shank joined by a knee with a stop; five point
masses (hip, one per thigh, one per shank).  Coordinates ``q = [q1, q2, q3]`` = stance leg,
swing thigh, swing shank, absolute angles from the world vertical [rad], walkerlab's sign
convention (hip at ``stance_foot + l (-sin q1, cos q1)``, knee at ``hip + lt (sin q2,
-cos q2)``); the slope falls towards +x at angle ``gamma``.

Step: three-link swing (knee free) until the knee straightens (``q3 = q2``): plastic knee
strike that locks the knee; two-link swing until heel strike (``q1 + q2 = -2 gamma``, swing
foot ahead); plastic heel strike with the knee still locked, legs swap, the new swing knee
unlocks.

Parts beyond Hsu Chen's walker (issue 22), all optional (``p`` keys, default off): the swing
leg's masses ``mt_sw``, ``ms_sw`` differing from the stance leg's ``mt``, ``ms`` (legs that
differ: the step with the other leg swinging swaps them); a torsional hip spring-damper
between the stance leg and the swing thigh, ``k_hip``, ``rest_hip``, ``c_hip`` on
``delta = q1 - q2`` (stance minus swing thigh angle: potential ``k (delta - rest)^2 / 2``,
generalised force ``-(k (delta - rest) + c d(delta)/dt) d(delta)/dq``); a torsional spring-
damper at the swing knee, ``k_knee``, ``rest_knee``, ``c_knee`` on the knee angle
``q3 - q2`` (the stance knee is straight: its spring holds a constant energy, left out).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache, cached_property

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp
from scipy.optimize import root

from ._lagrange import lagrange, lam

#: Tedrake's kneedCompassGait.m parameter set (the Hsu Chen 2007 walker), SI units.
HSU_CHEN = {
    "g": 9.8,
    "lt": 0.5,          # thigh length [m]
    "ls": 0.5,          # shank length [m]
    "mh": 0.5,          # hip mass = 2 * 0.5 * mt [kg]
    "mt": 0.5,          # thigh mass [kg]
    "ms": 0.05,         # shank mass = mt / 10 [kg]
    "a1": 0.35,         # shank mass above the foot = 0.7 ls [m]
    "b1": 0.15,         # shank mass below the knee [m]
    "a2": 0.2,          # thigh mass above the knee = 0.4 lt [m]
    "b2": 0.3,          # thigh mass below the hip [m]
    "gamma": float(np.arcsin(7.25 / 144.0)),   # slope [rad]
}

#: Tedrake's printed initial condition (just after heel strike, knee straight, unlocked);
#: produced with an explicit Euler integration, so a guess, not a fixed point.
TEDRAKE_X0 = np.array([0.187700106303669, -0.288437140111164, -0.288437140111164,
                       -1.101439041094875, -0.039885255927632, -0.039885255927632])


@cache
def _symbolic(torso=False):
    q = sp.symbols("q1 q2 q3" + (" q4" if torso else ""), real=True)
    dq = sp.symbols("dq1 dq2 dq3" + (" dq4" if torso else ""), real=True)
    g, lt, ls, mh, mt, ms, a1, b1, a2, b2 = sp.symbols("g lt ls mh mt ms a1 b1 a2 b2",
                                                       positive=True)
    mt_sw, ms_sw = sp.symbols("mt_sw ms_sw", positive=True)
    springs = sp.symbols("k_hip rest_hip c_hip k_knee rest_knee c_knee", real=True)
    q1, q2, q3 = q[:3]
    up = lambda th: sp.Matrix([-sp.sin(th), sp.cos(th)])  # noqa: E731
    hip = (ls + lt) * up(q1)
    knee = hip - lt * up(q2)
    pts = {
        "stance_shank": a1 * up(q1),
        "stance_thigh": (ls + a2) * up(q1),
        "hip": hip,
        "swing_thigh": hip - b2 * up(q2),
        "swing_knee": knee,
        "swing_shank": knee - b1 * up(q3),
        "swing_foot": knee - ls * up(q3),
        "stance_knee": ls * up(q1),
    }
    bodies = [(ms, 0, pts["stance_shank"], q1), (mt, 0, pts["stance_thigh"], q1),
              (mh, 0, hip, q1), (mt_sw, 0, pts["swing_thigh"], q2),
              (ms_sw, 0, pts["swing_shank"], q3)]
    extra = ()
    if torso:  # a point mass d up the torso (angle q4 from the upward vertical)
        m_tor, d_tor = sp.symbols("m_tor d_tor", positive=True)
        pts["torso"] = hip + d_tor * up(q[3])
        bodies.append((m_tor, 0, pts["torso"], q[3]))
        extra = (m_tor, d_tor)
    M, h, T, V = lagrange(q, dq, bodies, g)
    k_hip, rest_hip, c_hip, k_knee, rest_knee, c_knee = springs
    for k, rest, c, delta in ((k_hip, rest_hip, c_hip, q1 - q2),
                              (k_knee, rest_knee, c_knee, q3 - q2)):
        grad = sp.Matrix([sp.diff(delta, qi) for qi in q])
        rate = sum(gi * dqi for gi, dqi in zip(grad, dq))
        V = V + k * (delta - rest) ** 2 / 2
        h = h + (k * (delta - rest) + c * rate) * grad
    # extended coordinates for heel strike: the stance foot free at (xf, yf)
    xf, yf, dxf, dyf = sp.symbols("xf yf dxf dyf", real=True)
    qe, dqe = (*q, xf, yf), (*dq, dxf, dyf)
    off = sp.Matrix([xf, yf])
    Me, _, _, _ = lagrange(qe, dqe, [(m, 0, p + off, a) for m, _, p, a in bodies], g,
                           mass_matrix_only=True)
    E = (pts["swing_foot"] + off).jacobian(sp.Matrix(qe))
    par = (g, lt, ls, mh, mt, ms, a1, b1, a2, b2, mt_sw, ms_sw, *springs, *extra)
    masses = {"stance_shank": ms, "stance_thigh": mt, "hip": mh, "swing_thigh": mt_sw,
              "swing_shank": ms_sw}
    return q, dq, par, M, h, T, V, Me, E, pts, masses


@cache
def _lambdified(torso=False):
    q, dq, par, M, h, T, V, Me, E, pts, masses = _symbolic(torso)
    a = (q, dq, par)
    return {"M": lam((q, par), M), "h": lam(a, h), "T": lam(a, T), "V": lam((q, par), V),
            "Me": lam((q, par), Me), "E": lam((q, par), E),
            "pts": {k: lam((q, par), v) for k, v in pts.items()}}


@dataclass
class KneedReference:
    """The kneed walker: flows, guards, impacts, Poincaré map (independent prototype)."""

    p: dict = field(default_factory=lambda: dict(HSU_CHEN))
    rtol: float = 1e-12
    atol: float = 1e-12

    @cached_property
    def _f(self):
        q, dq, par, M, h, T, V, Me, E, pts, masses = _symbolic()
        f = dict(_lambdified())
        f["mass_of"] = {k: float(v.subs({s: self._par()[i] for i, s in enumerate(par)}))
                        for k, v in masses.items()}
        return f

    def _par(self):
        p = self.p
        return (p["g"], p["lt"], p["ls"], p["mh"], p["mt"], p["ms"], p["a1"], p["b1"],
                p["a2"], p["b2"], p.get("mt_sw", p["mt"]), p.get("ms_sw", p["ms"]),
                *(p.get(k, 0.0) for k in ("k_hip", "rest_hip", "c_hip", "k_knee",
                                          "rest_knee", "c_knee")))

    # ------------------------------------------------------------------ flows
    J_KNEE = np.array([0.0, -1.0, 1.0])   # knee constraint q3 - q2 = 0 (row)

    def flow_unlocked(self, t, x):
        q, dq = x[:3], x[3:]
        M = self._f["M"](q, self._par())
        h = self._f["h"](q, dq, self._par()).ravel()
        return np.concatenate([dq, np.linalg.solve(M, -h)])

    def locked_accel(self, x):
        """Accelerations and knee-stop torque with the knee locked (q3 = q2).

        Returns ``(qdd (3,), lam)``; ``lam`` is the generalized constraint force along
        ``[0, -1, 1]`` [N m]: negative = the stop pushes the shank backwards (a knee stop can
        do this), positive = the knee must be held against flexing (needs a latch).
        """
        q, dq = x[:3], x[3:]
        M = self._f["M"](q, self._par())
        h = self._f["h"](q, dq, self._par()).ravel()
        J = self.J_KNEE
        A = np.zeros((4, 4))
        A[:3, :3] = M
        A[:3, 3] = -J
        A[3, :3] = J
        sol = np.linalg.solve(A, np.concatenate([-h, [0.0]]))
        return sol[:3], sol[3]

    def flow_locked(self, t, x):
        return np.concatenate([x[3:], self.locked_accel(x)[0]])

    # ----------------------------------------------------------------- guards
    def point(self, name, x):
        return self._f["pts"][name](x[:3], self._par()).ravel()

    def height_above_slope(self, xy):
        """Distance of a point [m] above the slope line through the stance foot."""
        gm = self.p["gamma"]
        return xy[0] * np.sin(gm) + xy[1] * np.cos(gm)

    def swing_foot_clearance(self, x):
        return self.height_above_slope(self.point("swing_foot", x))

    def heel_strike_guard(self, x):
        return x[0] + x[1] + 2 * self.p["gamma"]

    # ---------------------------------------------------------------- impacts
    def knee_strike(self, x):
        """Plastic knee strike: ``M (dq+ - dq-) = J^T lam``, ``J dq+ = 0``."""
        q, dq = x[:3], x[3:]
        M = self._f["M"](q, self._par())
        J = self.J_KNEE
        A = np.zeros((4, 4))
        A[:3, :3] = M
        A[:3, 3] = -J
        A[3, :3] = J
        sol = np.linalg.solve(A, np.concatenate([M @ dq, [0.0]]))
        q_new = q.copy()
        q_new[2] = q[1]           # the event is at q3 = q2 (to round-off)
        return np.concatenate([q_new, sol[:3]])

    def heel_strike(self, x, return_extra=False):
        """Plastic heel strike (knee locked), then swap: new q = [q2, q1, q1]."""
        q, dq = x[:3], x[3:]
        Me = self._f["Me"](q, self._par())
        E = self._f["E"](q, self._par())
        Jk = np.array([[0.0, -1.0, 1.0, 0.0, 0.0]])
        C = np.vstack([E, Jk])                      # 3 x 5 constraints after impact
        A = np.zeros((8, 8))
        A[:5, :5] = Me
        A[:5, 5:] = -C.T
        A[5:, :5] = C
        rhs = np.concatenate([Me @ np.concatenate([dq, [0.0, 0.0]]), np.zeros(3)])
        sol = np.linalg.solve(A, rhs)
        dqp = sol[:5]
        x_plus = np.array([q[1], q[0], q[0], dqp[1], dqp[0], dqp[0]])
        if return_extra:
            # velocity of the old stance foot just after impact (must lift off)
            return x_plus, {"impulse": sol[5:7], "old_stance_foot_velocity": dqp[3:5]}
        return x_plus

    # --------------------------------------------------------------- energies
    def energies(self, x):
        q, dq = x[:3], x[3:]
        return (float(self._f["T"](q, dq, self._par())), float(self._f["V"](q, self._par())))

    def positions_velocities(self, x):
        """World positions and velocities of the five masses (finite-free: by Jacobian)."""
        out = {}
        for k, m in self._f["mass_of"].items():
            p = self.point(k, x)
            # complex-step derivative along dq
            qc = x[:3].astype(complex) + 1e-30j * x[3:]
            v = np.imag(self._f["pts"][k](qc, self._par()).ravel()) / 1e-30
            out[k] = (m, p, v)
        return out

    # ------------------------------------------------------------------ a step
    def step(self, x0, dense=False):
        """One step from just after heel strike.  Returns a dict (raises on failure)."""
        tol = dict(rtol=self.rtol, atol=self.atol, method="DOP853")

        def knee(t, x):
            return x[2] - x[1]
        knee.terminal, knee.direction = True, 1

        def foot_down(t, x):
            return self.swing_foot_clearance(x) if t > 1e-3 else 1.0
        foot_down.terminal, foot_down.direction = True, -1

        def fall(t, x):
            return self.height_above_slope(self.point("hip", x))
        fall.terminal, fall.direction = True, -1

        s1 = solve_ivp(self.flow_unlocked, (0, 5), x0, events=[knee, foot_down, fall],
                       dense_output=True, **tol)
        if not len(s1.t_events[0]):
            raise RuntimeError(f"no knee strike (status {s1.status}, events "
                               f"{[len(e) for e in s1.t_events]})")
        tk, xk_minus = s1.t_events[0][0], s1.y_events[0][0]
        xk_plus = self.knee_strike(xk_minus)

        def heel(t, x):
            return self.heel_strike_guard(x) if x[1] > x[0] else 1.0
        heel.terminal, heel.direction = True, -1
        s2 = solve_ivp(self.flow_locked, (tk, tk + 5), xk_plus, events=[heel, fall],
                       dense_output=True, **tol)
        if not len(s2.t_events[0]):
            raise RuntimeError("no heel strike after knee strike")
        th, xh_minus = s2.t_events[0][0], s2.y_events[0][0]
        x_next = self.heel_strike(xh_minus)
        out = {"t_knee": tk, "x_knee_minus": xk_minus, "x_knee_plus": xk_plus,
               "t_heel": th, "x_heel_minus": xh_minus, "x_next": x_next}
        if dense:
            out["sol_unlocked"], out["sol_locked"] = s1.sol, s2.sol
        return out

    # ---------------------------------------------------------- Poincaré map
    def from_section(self, z):
        q1, dq1, dq2 = z
        q2 = -2 * self.p["gamma"] - q1
        return np.array([q1, q2, q2, dq1, dq2, dq2])

    @staticmethod
    def section(x):
        return np.array([x[0], x[3], x[4]])

    def poincare(self, z):
        return self.section(self.step(self.from_section(z))["x_next"])

    def fixed_point(self, x_guess=TEDRAKE_X0, xtol=1e-13):
        sol = root(lambda z: self.poincare(z) - z, self.section(np.asarray(x_guess)),
                   method="hybr", options={"xtol": xtol})
        if not sol.success:
            raise RuntimeError(sol.message)
        return self.from_section(sol.x)

    def multipliers(self, x_star, h=1e-6):
        """Eigenvalues of the Jacobian of the reduced (3-D) Poincaré map, central differences."""
        z = self.section(x_star)
        J = np.empty((3, 3))
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            J[:, k] = (self.poincare(z + e) - self.poincare(z - e)) / (2 * h)
        ev = np.linalg.eigvals(J)
        return ev[np.argsort(-np.abs(ev))]


if __name__ == "__main__":  # pragma: no cover - prints the reference numbers
    w = KneedReference()
    r = w.step(TEDRAKE_X0)
    print("one step from Tedrake's x0: t_knee", r["t_knee"], "t_heel", r["t_heel"])
    print("x_next", r["x_next"])
    xs = w.fixed_point()
    np.set_printoptions(precision=15)
    print("fixed point", xs)
    s = w.step(xs)
    print("period", s["t_heel"], "knee strike at", s["t_knee"])
    print("multipliers", w.multipliers(xs), np.abs(w.multipliers(xs)))


@dataclass
class KneedTorsoReference(KneedReference):
    """The kneed walker with an upper body on a bisecting hip mechanism (Wisse, Hobbelen &
    Schwab 2007): a point mass ``m_tor`` at ``d_tor`` up a torso whose angle ``q4`` from the
    upward vertical (positive leaning back) is a fourth coordinate, held at ``(q1 + q2) / 2``
    (the mean of the stance leg's and the swing thigh's angles) by a Lagrange multiplier in
    every flow and impact - not eliminated as in walkerlab.  States stay ``[q1, q2, q3,
    rates]``; ``q4`` and its rate follow from the coupling."""

    #: the coupling row q4 - (q1 + q2) / 2 = 0
    A_TORSO = np.array([-0.5, -0.5, 0.0, 1.0])
    J_KNEE4 = np.array([0.0, -1.0, 1.0, 0.0])

    @cached_property
    def _f(self):
        return dict(_lambdified(True))

    def _par(self):
        return (*super()._par(), self.p["m_tor"], self.p["d_tor"])

    @staticmethod
    def _full(x):
        q, dq = np.asarray(x[:3]), np.asarray(x[3:])
        return (np.append(q, 0.5 * (q[0] + q[1])), np.append(dq, 0.5 * (dq[0] + dq[1])))

    def _solve(self, M, rhs, rows):
        """``M a - C^T lam = rhs``, ``C a = 0``: (a, lam)."""
        C = np.atleast_2d(rows)
        n, k = M.shape[0], C.shape[0]
        A = np.zeros((n + k, n + k))
        A[:n, :n], A[:n, n:], A[n:, :n] = M, -C.T, C
        sol = np.linalg.solve(A, np.concatenate([rhs, np.zeros(k)]))
        return sol[:n], sol[n:]

    def flow_unlocked(self, t, x):
        q, dq = self._full(x)
        M = self._f["M"](q, self._par())
        h = self._f["h"](q, dq, self._par()).ravel()
        a, _ = self._solve(M, -h, self.A_TORSO)
        return np.concatenate([x[3:], a[:3]])

    def locked_accel(self, x):
        q, dq = self._full(x)
        M = self._f["M"](q, self._par())
        h = self._f["h"](q, dq, self._par()).ravel()
        a, lam_ = self._solve(M, -h, np.vstack([self.J_KNEE4, self.A_TORSO]))
        return a[:3], lam_[0]

    def knee_strike(self, x):
        q, dq = self._full(x)
        M = self._f["M"](q, self._par())
        v, _ = self._solve(M, M @ dq, np.vstack([self.J_KNEE4, self.A_TORSO]))
        q_new = np.asarray(x[:3], float).copy()
        q_new[2] = q_new[1]
        return np.concatenate([q_new, v[:3]])

    def heel_strike(self, x, return_extra=False):
        q, dq = self._full(x)
        Me = self._f["Me"](q, self._par())
        E = self._f["E"](q, self._par())
        rows = np.vstack([E, np.append(self.J_KNEE4, [0.0, 0.0]),
                          np.append(self.A_TORSO, [0.0, 0.0])])
        v, _ = self._solve(Me, Me @ np.concatenate([dq, [0.0, 0.0]]), rows)
        return np.array([q[1], q[0], q[0], v[1], v[0], v[0]])

    def energies(self, x):
        q, dq = self._full(x)
        return (float(self._f["T"](q, dq, self._par())), float(self._f["V"](q, self._par())))

    def point(self, name, x):
        return self._f["pts"][name](self._full(x)[0], self._par()).ravel()
