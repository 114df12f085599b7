"""The plain-library yardstick of ``walkerlab optimize`` designing the three-link walker's
virtual constraints (``optimize.design: virtual_constraints``): the same formulation written
directly in CasADi + IPOPT (numpy and casadi only; no walkerlab import, so a benchmark can
run this file as a process beside any code tree).

Walker (configs/threelink_hzd.yaml; J. W. Grizzle, G. Abba & F. Plestan (2001), IEEE TAC
46(1):51-64; Westervelt et al. 2007, *Feedback Control of Dynamic Bipedal Robot
Locomotion*, its three-link model): ``q = (q1, q2, q3)`` the stance leg, the swing leg (from
the downward vertical, positive with the foot ahead of the hip) and the torso (from the
upward vertical, positive leaning back); legs ``r`` with a point mass ``m`` at ``d`` from the
hip, hip mass ``MH``, torso mass ``MT`` at ``l`` above the hip; the closed forms of ``D, C,
G`` and ``B = [[1, 0], [0, 1], [-1, -1]]`` (u1, u2 at the stance and swing hips); the heel
strike at ``q1 + q2 = 0`` (level ground) by the extended model's impulse balance, then the
legs' relabelling.

Formulation (Hereid & Ames 2017, FROST; as walkerlab.optimal.transcription.
virtual_constraints): separated Hermite-Simpson on ``N`` uniform intervals, outputs ``y =
(q2, q3) - hd(s)``, ``s = (q1 - theta+) / (theta- - theta+)``, Bezier ``hd`` of degree 4 with
the coefficients as decision variables; ``y'' + kd y' + kp y = 0`` at every point, ``y = y' =
0`` after the heel strike, ``x_0 = Delta(x_N)``, the guard at the end moving down with the
swing foot ahead, the phase advancing, the stance foot pushing inside the friction cone,
``|u| <= u_max``, the target speed, and ``delta^2(q-, alpha) <= max_multiplier`` at the zero
dynamics' pre-impact configuration of ``alpha``; objective ``int |u|^2 dt / step length``.

    python walkerlab/bench/minimal_casadi_hzd.py GUESS.npz

reads the start (``t, x, u, alpha`` and the settings ``N, speed, max_multiplier, kp, kd,
u_max, mu``) and prints IPOPT's status, iterations, the build and solve times [s], the step
period [s], step length [m], objective [N^2 m s], delta^2 and the coefficients.
"""

from __future__ import annotations

import sys
import time
from math import comb

import casadi as ca
import numpy as np

#: configs/threelink_hzd.yaml: g, r, m, d, MH, MT, l
G_, R_, M_, D_, MH_, MT_, L_ = 9.8, 1.0, 5.0, 0.5, 15.0, 10.0, 0.5
B = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, -1.0]])
b = np.ones(3)  # b^T B = 0


def mass_matrix(q):
    q1, q2, q3 = q[0], q[1], q[2]
    d12 = -M_ * R_ * D_ * ca.cos(q1 - q2)
    d13 = MT_ * R_ * L_ * ca.cos(q1 - q3)
    return ca.vertcat(ca.horzcat((MH_ + MT_ + M_) * R_ ** 2 + M_ * (R_ - D_) ** 2, d12, d13),
                      ca.horzcat(d12, M_ * D_ ** 2, 0), ca.horzcat(d13, 0, MT_ * L_ ** 2))


def bias(q, dq):
    q1, q2, q3 = q[0], q[1], q[2]
    a = M_ * R_ * D_ * ca.sin(q1 - q2)
    c = MT_ * R_ * L_ * ca.sin(q1 - q3)
    C = ca.vertcat(ca.horzcat(0, -a * dq[1], c * dq[2]), ca.horzcat(a * dq[0], 0, 0),
                   ca.horzcat(-c * dq[0], 0, 0))
    G = ca.vertcat(-(MH_ * R_ + M_ * (R_ - D_) + M_ * R_ + MT_ * R_) * G_ * ca.sin(q1),
                   M_ * D_ * G_ * ca.sin(q2), -MT_ * L_ * G_ * ca.sin(q3))
    return ca.mtimes(C, dq) + G


def points(qe):
    """Positions of the hip, the three point masses and the swing foot, in ``(q, x_f,
    y_f)``."""
    q1, q2, q3, xf, yf = qe[0], qe[1], qe[2], qe[3], qe[4]
    hip = ca.vertcat(xf - R_ * ca.sin(q1), yf + R_ * ca.cos(q1))
    st = ca.vertcat(xf - (R_ - D_) * ca.sin(q1), yf + (R_ - D_) * ca.cos(q1))
    sw = hip + D_ * ca.vertcat(ca.sin(q2), -ca.cos(q2))
    to = hip + L_ * ca.vertcat(-ca.sin(q3), ca.cos(q3))
    foot = hip + R_ * ca.vertcat(ca.sin(q2), -ca.cos(q2))
    return [(MH_, hip), (M_, st), (M_, sw), (MT_, to)], foot


_QE = ca.SX.sym("qe", 5)
_BODIES, _FOOT = points(_QE)
#: the extended model's mass matrix De (5, 5) and the swing foot's Jacobian E (2, 5)
EXTENDED = ca.Function("extended", [_QE], [
    sum(m * ca.mtimes(ca.jacobian(p, _QE).T, ca.jacobian(p, _QE)) for m, p in _BODIES),
    ca.jacobian(_FOOT, _QE)])


def impact(x):
    De, E = EXTENDED(ca.vertcat(x[:3], 0, 0))
    A = ca.vertcat(ca.horzcat(De, -E.T), ca.horzcat(E, ca.DM.zeros(2, 2)))
    rhs = ca.vertcat(ca.mtimes(De, ca.vertcat(x[3:], 0, 0)), 0, 0)
    dq = ca.solve(A, rhs)[:3]
    return ca.vertcat(x[1], x[0], x[2], dq[1], dq[0], dq[2])


def bezier(alpha, s):
    M = alpha.shape[1] - 1
    hd = sum(alpha[:, j] * comb(M, j) * s ** j * (1 - s) ** (M - j) for j in range(M + 1))
    hd1 = sum(M * (alpha[:, j + 1] - alpha[:, j]) * comb(M - 1, j) * s ** j
              * (1 - s) ** (M - 1 - j) for j in range(M))
    return hd, hd1


def model_functions(columns: int, kp: float, kd: float) -> tuple:
    """The walker's CasADi functions for Bezier coefficients of ``columns`` columns and the
    outputs' feedback gains ``kp`` [1/s^2], ``kd`` [1/s]: ``flow(x, u)``, ``reset(x)``,
    ``out(x, u, a, theta+, theta-)`` (y, y', the closed loop's output equation),
    ``grf(x, u)`` (the stance foot's force [N]), ``ahead(x)`` (the swing foot's lead [m]) and
    ``delta2(q-, a)``."""
    x, u = ca.SX.sym("x", 6), ca.SX.sym("u", 2)
    a = ca.SX.sym("a", 2, columns)
    tp, tm = ca.SX.sym("tp"), ca.SX.sym("tm")
    qdd = ca.solve(mass_matrix(x[:3]), ca.mtimes(ca.DM(B), u) - bias(x[:3], x[3:]))
    f = ca.vertcat(x[3:], qdd)
    flow = ca.Function("flow", [x, u], [f])
    reset = ca.Function("reset", [x], [impact(x)])
    s = (x[0] - tp) / (tm - tp)
    hd, hd1 = bezier(a, s)
    y = x[1:3] - hd
    dy = x[4:6] - hd1 * x[3] / (tm - tp)
    ddy = ca.jtimes(dy, x, f)
    out = ca.Function("out", [x, u, a, tp, tm], [ca.vertcat(y, dy, ddy + kd * dy + kp * y)])
    bodies, foot = points(ca.vertcat(x[:3], 0, 0))
    mtot = sum(m for m, _ in bodies)
    com = sum(m * p for m, p in bodies) / mtot
    acc = ca.jtimes(ca.jtimes(com, x[:3], x[3:]), x, f)
    grf = ca.Function("grf", [x, u], [mtot * (acc + ca.vertcat(0, G_))])
    ahead = ca.Function("ahead", [x], [foot[0]])
    qm = ca.SX.sym("qm", 3)
    qd = ca.vertcat(1.0, (columns - 1) * (a[:, -1] - a[:, -2]) / (qm[0] - qm[1]))
    xp = impact(ca.vertcat(qm, qd))  # theta+ = q1+ = q2-
    sig = (ca.mtimes([b.reshape(1, -1), mass_matrix(xp[:3]), xp[3:]])
           / ca.mtimes([b.reshape(1, -1), mass_matrix(qm), qd]))
    delta2 = ca.Function("delta2", [qm, a], [sig ** 2])
    return flow, reset, out, grf, ahead, delta2


def problem(z, fns: tuple) -> tuple:
    """The collocation (module docstring) on the start ``z`` (the loaded GUESS.npz) with the
    functions ``fns`` of :func:`model_functions`: the IPOPT-ready ``Opti`` and its
    expressions ``T`` (period [s]), ``D`` (step length [m]), the objective, ``delta^2`` and
    ``A`` (the coefficients)."""
    flow, reset, out, grf, ahead, delta2 = fns
    N, speed, mmax = int(z["N"]), float(z["speed"]), float(z["max_multiplier"])
    umax, mu = float(z["u_max"]), float(z["mu"])
    K = 2 * N + 1
    opti = ca.Opti()
    X, U, T = opti.variable(6, K), opti.variable(2, K), opti.variable()
    A, Qm = opti.variable(*z["alpha"].shape), opti.variable(3)
    F = flow.map(K)(X, U)
    h = T / N
    xi, xm, xj = X[:, 0:K - 1:2], X[:, 1:K:2], X[:, 2:K:2]
    fi, fm, fj = F[:, 0:K - 1:2], F[:, 1:K:2], F[:, 2:K:2]
    opti.subject_to(ca.vec(xm - (xi + xj) / 2 - h / 8 * (fi - fj)) == 0)
    opti.subject_to(ca.vec(xj - xi - h / 6 * (fi + 4 * fm + fj)) == 0)
    th_p, th_m = X[0, 0], X[0, -1]
    Y = out.map(K)(X, U, A, th_p, th_m)
    opti.subject_to(ca.vec(Y[4:, :]) == 0)
    opti.subject_to(Y[:4, 0] == 0)
    opti.subject_to(X[:, 0] - reset(X[:, -1]) == 0)
    opti.subject_to(X[0, -1] + X[1, -1] == 0)
    opti.subject_to(X[3, -1] + X[4, -1] <= 0)
    D = ahead(X[:, -1])
    opti.subject_to(D >= 1e-3)
    opti.subject_to(ca.vec(X[3, :] * T / (th_m - th_p)) >= 0.2)
    Fg = grf.map(K)(X, U)
    opti.subject_to(Fg[1, :] >= 0)
    opti.subject_to(ca.vec(Fg[0, :] - mu * Fg[1, :]) <= 0)
    opti.subject_to(ca.vec(-Fg[0, :] - mu * Fg[1, :]) <= 0)
    opti.subject_to(opti.bounded(-umax, ca.vec(U), umax))
    opti.subject_to(opti.bounded(-np.pi / 2, X[:3, :], np.pi / 2))
    opti.subject_to(opti.bounded(0.1, T, 5.0))
    opti.subject_to(D == speed * T)
    opti.subject_to(Qm[1:] - A[:, -1] == 0)
    opti.subject_to(Qm[0] + Qm[1] == 0)
    d2 = delta2(Qm, A)
    opti.subject_to(d2 <= mmax)
    w = np.ones(K)
    w[1:K - 1:2], w[2:K - 1:2] = 4.0, 2.0
    objective = h / 3 * ca.mtimes(ca.sum1(U ** 2), ca.DM(w)) / D
    opti.minimize(objective)
    opti.set_initial(X, z["x"].T)
    opti.set_initial(U, z["u"].T)
    opti.set_initial(T, float(z["t"][-1]))
    opti.set_initial(A, z["alpha"])
    opti.set_initial(Qm, z["x"][-1, :3])
    opti.solver("ipopt", {"expand": True, "print_time": False},
                {"print_level": 0, "tol": 1e-10, "constr_viol_tol": 1e-11, "max_iter": 1000,
                 "sb": "yes"})
    return opti, T, D, objective, d2, A


def main(path: str) -> None:
    z = np.load(path)
    t0 = time.perf_counter()
    fns = model_functions(z["alpha"].shape[1], float(z["kp"]), float(z["kd"]))
    opti, T, D, objective, d2, A = problem(z, fns)
    build = time.perf_counter() - t0
    t1 = time.perf_counter()
    try:
        sol, status = opti.solve(), "Solve_Succeeded"
        get = sol.value
    except RuntimeError:
        status, get = str(opti.stats().get("return_status")), opti.debug.value
    solve = time.perf_counter() - t1
    print(status, "iterations", opti.stats().get("iter_count"), "build_s", f"{build:.6f}",
          "solve_s", f"{solve:.6f}", "period", f"{float(get(T)):.12g}", "length",
          f"{float(get(D)):.12g}", "objective", f"{float(get(objective)):.12g}", "delta2",
          f"{float(get(d2)):.12g}", "alpha",
          " ".join(f"{v:.12g}" for v in np.asarray(get(A)).ravel()))


if __name__ == "__main__":
    main(sys.argv[1])
