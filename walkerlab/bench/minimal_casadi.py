"""The plain-library yardstick of ``walkerlab optimize configs/compass_optimal.yaml``: the
same collocation written directly in CasADi + IPOPT (numpy, scipy and casadi only; no
walkerlab import, so a benchmark can run this file as a process beside any code tree).

Walker (configs/compass_optimal.yaml: the paper's Table 1 walker on a 0.0525 rad slope):
two legs of length ``L`` [m], each a point mass ``m`` [kg] at ``a`` [m] from its foot, hip
mass ``M_H`` [kg], gravity ``g`` [m/s^2] (Goswami, Thuilot & Espiau 1996, INRIA RR-2996;
the derivation as in :mod:`walkerlab.bench.monte_carlo_yardstick`).  State
``[theta1, theta2, dtheta1, dtheta2]`` [rad, rad/s], swing leg first, absolute angles from
the vertical (walkerlab's ``swing_angle, stance_angle, swing_rate, stance_rate``); the hip
torque ``u`` [N m] acts ``+u`` on the swing leg and ``-u`` on the stance leg.

Transcription (Kelly 2017, SIAM Review 59(4):849-904, Sec. 4, separated Hermite-Simpson,
``N`` = 40 uniform intervals): states and torque at ``2N + 1`` points, the step period
``T`` free in ``[0.05, 5] T_guess``; the end a heel strike (``theta1 + theta2 + 2 gamma = 0``
with its rate at most ``-0.05`` rad/s, the swing foot ahead; the swing foot may dip
through the ground mid-swing, as walkerlab's straight legs); the start the plastic impact
of the end (angular momentum about the new stance foot and of the trailing leg about the
hip conserved, the legs' roles swapped);
objective ``int u^2 dt`` by Simpson's rule; IPOPT at ``tol`` 1e-12 (walkerlab's options).
The starting guess: one passive step (scipy's DOP853 at 1e-12 on the same flow) from the
scene's fixed point written to 8 digits, sampled at the points.

    python -m walkerlab.bench.minimal_casadi     (or: python walkerlab/bench/minimal_casadi.py)

prints IPOPT's status, iterations, the step period [s], the objective [N^2 m^2 s] and the
step's start (the post-impact state) [rad, rad/s].
"""

from __future__ import annotations

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp

#: configs/compass_optimal.yaml: m, M_H, L, a, g, slope gamma [rad]
M, MH, L, A, G, GAMMA = 5.0, 10.0, 1.0, 0.5, 9.81, 0.0525
N = 40
#: the scene's passive fixed point (post-impact state), 8 digits
X_FIXED = [-0.32377462, 0.21877462, -0.37613459, -1.09286681]


def flow_expr(x, u):
    """dx/dt of the pinned compass gait with the hip torque ``u`` (CasADi expressions)."""
    b = L - A
    mu = M * A + (M + MH) * L
    s, c = ca.sin(x[0] - x[1]), ca.cos(x[0] - x[1])
    d11, d12, d22 = M * b * b, -M * L * b * c, M * A * A + (M + MH) * L * L
    r1 = M * L * b * s * x[3] ** 2 - M * G * b * ca.sin(x[0]) + u
    r2 = -M * L * b * s * x[2] ** 2 + mu * G * ca.sin(x[1]) - u
    det = d11 * d22 - d12 * d12
    return ca.vertcat(x[2], x[3], (d22 * r1 - d12 * r2) / det, (d11 * r2 - d12 * r1) / det)


def impact_expr(x):
    """Post-impact state (roles swapped) from the pre-impact state ``x`` (CasADi)."""
    b = L - A
    t1, t2, w1, w2 = x[0], x[1], x[2], x[3]
    s1, c1, s2, c2 = ca.sin(t1), ca.cos(t1), ca.sin(t2), ca.cos(t2)
    hx, hy = -L * s2, L * c2
    p1x, p1y = hx + b * s1, hy - b * c1
    p2x, p2y = -A * s2, A * c2
    sx, sy = hx + L * s1, hy - L * c1

    def cross(px, py, ox, oy, vx, vy):
        return (px - ox) * vy - (py - oy) * vx

    vhx, vhy = -L * c2 * w2, -L * s2 * w2
    v1x, v1y = vhx + b * c1 * w1, vhy + b * s1 * w1
    v2x, v2y = -A * c2 * w2, -A * s2 * w2
    ls = (M * cross(p1x, p1y, sx, sy, v1x, v1y) + MH * cross(hx, hy, sx, sy, vhx, vhy)
          + M * cross(p2x, p2y, sx, sy, v2x, v2y))
    lh = M * cross(p2x, p2y, hx, hy, v2x, v2y)
    cols = []
    for u1, u2 in ((1.0, 0.0), (0.0, 1.0)):
        vhx, vhy = -L * c1 * u2, -L * s1 * u2
        v1x, v1y = -A * c1 * u2, -A * s1 * u2
        v2x, v2y = vhx + b * c2 * u1, vhy + b * s2 * u1
        cols.append((M * cross(p1x, p1y, sx, sy, v1x, v1y)
                     + MH * cross(hx, hy, sx, sy, vhx, vhy)
                     + M * cross(p2x, p2y, sx, sy, v2x, v2y),
                     M * cross(p2x, p2y, hx, hy, v2x, v2y)))
    (m00, m10), (m01, m11) = cols
    det = m00 * m11 - m01 * m10
    return ca.vertcat(t2, t1, (m11 * ls - m01 * lh) / det, (m00 * lh - m10 * ls) / det)


def main() -> None:
    xs, us = ca.SX.sym("x", 4), ca.SX.sym("u")
    f = ca.Function("f", [xs, us], [flow_expr(xs, us)])
    reset = ca.Function("reset", [xs], [impact_expr(xs)])

    def guard(x):
        return x[0] + x[1] + 2 * GAMMA

    # the starting guess: one passive step from the fixed point
    def strike(t, y):
        return guard(y) if y[0] > y[1] else 1.0  # armed after midstance
    strike.terminal, strike.direction = True, -1
    sol = solve_ivp(lambda t, y: np.asarray(f(y, 0.0)).ravel(), (0, 5), X_FIXED,
                    "DOP853", rtol=1e-12, atol=1e-12, events=strike, dense_output=True)
    Tg = float(sol.t_events[0][0])
    x_guess = sol.sol(np.linspace(0.0, Tg, 2 * N + 1))

    opti = ca.Opti()
    X, U, T = opti.variable(4, 2 * N + 1), opti.variable(1, 2 * N + 1), opti.variable()
    h = T / N
    F = [f(X[:, k], U[k]) for k in range(2 * N + 1)]
    for i in range(0, 2 * N, 2):
        m, j = i + 1, i + 2
        opti.subject_to(X[:, m] == 0.5 * (X[:, i] + X[:, j]) + h / 8 * (F[i] - F[j]))
        opti.subject_to(X[:, j] == X[:, i] + h / 6 * (F[i] + 4 * F[m] + F[j]))
    opti.subject_to(guard(X[:, -1]) == 0)
    opti.subject_to(-(X[2, -1] + X[3, -1]) >= 0.05)  # the guard's rate, downwards
    opti.subject_to(X[0, -1] - X[1, -1] >= 1e-3)  # the swing foot ahead
    opti.subject_to(X[:, 0] == reset(X[:, -1]))
    opti.subject_to(opti.bounded(0.05 * Tg, T, 5.0 * Tg))
    w = np.tile([4.0, 2.0], N + 1)[: 2 * N + 1]
    w[0] = w[-1] = 1.0
    opti.minimize(h / 6 * ca.sum2(ca.DM(w).T * U ** 2))
    opti.set_initial(X, x_guess)
    opti.set_initial(U, 0.0)
    opti.set_initial(T, Tg)
    opti.solver("ipopt", {"print_time": False},
                {"print_level": 0, "tol": 1e-12, "acceptable_tol": 1e-10, "max_iter": 500,
                 "sb": "yes"})
    s = opti.solve()
    x0 = " ".join(f"{v:.10f}" for v in s.value(X[:, 0]))
    print(f"{s.stats()['return_status']} after {s.stats()['iter_count']} iterations; step "
          f"period {s.value(T):.10f} s, objective {s.value(opti.f):.3e} N^2 m^2 s, "
          f"start {x0}")


if __name__ == "__main__":
    main()
