"""Independent reference of the floating (contact) view of a flat-footed walker: kinetic and
potential energy and the heel/toe positions and velocities, written by hand in numpy from the
geometry (no sympy, no code shared with :mod:`walkerlab.codegen.floating`).

Walker: hip point mass ``MH``, one point mass ``m`` per leg at ``d`` from the hip, legs of
length ``L`` (hip to ankle), a foot per leg with mass ``mf`` at the ankle and inertia ``If``
about it, ankle spring ``k`` with rest angle ``r`` on ``delta = psi - theta`` (foot angle minus
leg angle, toe up > 0), heel ``h`` behind and toe ``tt`` ahead of the ankle along the sole.
``q = [x, y, th1, th2, psi1, psi2]`` (hip position [m], absolute leg and foot angles [rad];
a point at distance ``s`` along a link at angle ``a`` lies at ``(s sin a, -s cos a)`` from its
joint; the sole's direction is ``(cos psi, sin psi)``).
"""

from __future__ import annotations

import numpy as np


def _unit(a):
    return np.array([np.sin(a), -np.cos(a)])


def _perp(a):
    return np.array([np.cos(a), np.sin(a)])


def kinetic(q, dq, p: dict) -> float:
    """Kinetic energy [J]: sum of 1/2 m |v|^2 over the point masses + 1/2 If dpsi^2."""
    x, y, th1, th2, ps1, ps2 = q
    vx, vy, w1, w2, wp1, wp2 = dq
    vh = np.array([vx, vy])
    T = 0.5 * p["MH"] * vh @ vh
    for th, w in ((th1, w1), (th2, w2)):
        vm = vh + p["d"] * w * _perp(th)
        va = vh + p["L"] * w * _perp(th)
        T += 0.5 * p["m"] * vm @ vm + 0.5 * p["mf"] * va @ va
    return float(T + 0.5 * p["If"] * (wp1 ** 2 + wp2 ** 2))


def potential(q, p: dict) -> float:
    """Gravity (height y, g down) plus the two ankle springs [J]."""
    x, y, th1, th2, ps1, ps2 = q
    V = p["MH"] * p["g"] * y
    for th, ps in ((th1, ps1), (th2, ps2)):
        V += p["m"] * p["g"] * (y - p["d"] * np.cos(th))
        V += p["mf"] * p["g"] * (y - p["L"] * np.cos(th))
        V += 0.5 * p["k"] * (ps - th - p["r"]) ** 2
    return float(V)


def mass_matrix(q, p: dict) -> np.ndarray:
    """M(q) (6, 6) by polarisation of the quadratic form ``T = 1/2 dq^T M dq``."""
    n = 6
    E = np.eye(n)
    M = np.empty((n, n))
    for i in range(n):
        M[i, i] = 2.0 * kinetic(q, E[i], p)
        for j in range(i):
            M[i, j] = M[j, i] = (kinetic(q, E[i] + E[j], p) - kinetic(q, E[i], p)
                                 - kinetic(q, E[j], p))
    return M


def heel_toe(q, dq, p: dict) -> dict:
    """Positions and velocities [m, m/s] of ``leg{i}_heel`` and ``leg{i}_toe``."""
    x, y, th1, th2, ps1, ps2 = q
    vx, vy, w1, w2, wp1, wp2 = dq
    out = {}
    for i, (th, ps, w, wp) in enumerate(((th1, ps1, w1, wp1), (th2, ps2, w2, wp2)), 1):
        ankle = np.array([x, y]) + p["L"] * _unit(th)
        v_ankle = np.array([vx, vy]) + p["L"] * w * _perp(th)
        for end, s in (("heel", -p["h"]), ("toe", p["tt"])):
            pos = ankle + s * _perp(ps)
            vel = v_ankle + s * wp * np.array([-np.sin(ps), np.cos(ps)])
            out[f"leg{i}_{end}"] = (pos, vel)
    return out
