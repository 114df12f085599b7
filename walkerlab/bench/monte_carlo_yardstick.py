"""The plain-library yardstick of the Monte Carlo walks: a minimal numba loop over the
compass-gait walker on per-step random slopes (numpy, numba and scipy's DOP853 coefficients
only; no walkerlab import, so a benchmark can load this file beside any code tree).

Model (Goswami, Thuilot & Espiau 1996, INRIA RR-2996; the derivation written out in
``tests/independent/actuated_compass.py``): two legs of length ``L`` [m], each a point mass
``m`` [kg] at ``a`` [m] from its foot (``b = L - a`` from the hip), hip mass ``M_H`` [kg],
gravity ``g`` [m/s^2].  State ``[theta1, theta2, dtheta1, dtheta2]`` [rad, rad/s], swing
leg first, absolute angles from the vertical, counter-clockwise positive (walkerlab's
``swing_angle, stance_angle, swing_rate, stance_rate``).

One step: DOP853 (Hairer, Norsett & Wanner, "Solving ODEs I", sec. II.10; scipy's step-size
control, coefficients from ``scipy.integrate._ivp.dop853_coefficients``) from the post-impact
state; midstance when the legs cross (``theta1 - theta2`` through zero upwards) arms the heel
strike ``theta1 + theta2 + 2 gamma`` through zero downwards; a fall if the hip reaches the
ground (``|theta2| >= pi/2``), the swing leg falls back behind the stance leg after
midstance, or no heel strike within ``max_time`` [s].  Guard crossings are located on the
7th-order dense output (secant/bisection to 1e-14 s).  The impact is plastic: angular
momentum of the walker about the new stance foot and of the trailing leg about the hip are
conserved (a 2x2 solve), and the legs swap roles.

Accuracy: the error norm is the 2-norm over the walker's 4 components of the scaled error
estimate (``atol + rtol |y|``), as :class:`walkerlab.integrate.batch_step.BatchStepMap`
asks of each row of its stacked system (not scipy's RMS, which is 2x looser for 4
components).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.integrate._ivp import dop853_coefficients as _dc

A = np.ascontiguousarray(_dc.A)
B = np.ascontiguousarray(_dc.B)
C = np.ascontiguousarray(_dc.C)
E3 = np.ascontiguousarray(_dc.E3)
E5 = np.ascontiguousarray(_dc.E5)
D = np.ascontiguousarray(_dc.D)
NS = _dc.N_STAGES  # 12


@njit(cache=True)
def flow(y, p, out):  # pragma: no cover - compiled
    """dy/dt of the pinned compass gait (Lagrange; ``p = [m, M_H, L, a, g]``)."""
    m, MH, L, a, g = p[0], p[1], p[2], p[3], p[4]
    b = L - a
    mu = m * a + (m + MH) * L
    s = math.sin(y[0] - y[1])
    c = math.cos(y[0] - y[1])
    d11, d12, d22 = m * b * b, -m * L * b * c, m * a * a + (m + MH) * L * L
    r1 = -(-m * L * b * s * y[3] ** 2 + m * g * b * math.sin(y[0]))
    r2 = -(m * L * b * s * y[2] ** 2 - mu * g * math.sin(y[1]))
    det = d11 * d22 - d12 * d12
    out[0], out[1] = y[2], y[3]
    out[2] = (d22 * r1 - d12 * r2) / det
    out[3] = (d11 * r2 - d12 * r1) / det


@njit(cache=True)
def impact(x, p, out):  # pragma: no cover - compiled
    """Post-impact state (roles swapped) from the pre-impact state ``x``."""
    m, MH, L, a = p[0], p[1], p[2], p[3]
    b = L - a
    t1, t2, w1, w2 = x[0], x[1], x[2], x[3]
    s1, c1, s2, c2 = math.sin(t1), math.cos(t1), math.sin(t2), math.cos(t2)
    # positions from the old stance foot F = 0: hip H, swing mass P1, stance mass P2, foot S
    hx, hy = -L * s2, L * c2
    p1x, p1y = hx + b * s1, hy - b * c1
    p2x, p2y = -a * s2, a * c2
    sx, sy = hx + L * s1, hy - L * c1
    vhx, vhy = -L * c2 * w2, -L * s2 * w2
    v1x, v1y = vhx + b * c1 * w1, vhy + b * s1 * w1
    v2x, v2y = -a * c2 * w2, -a * s2 * w2
    # before: about S (all masses), about H (the trailing leg's mass P2)
    ls = (m * ((p1x - sx) * v1y - (p1y - sy) * v1x) + MH * ((hx - sx) * vhy - (hy - sy) * vhx)
          + m * ((p2x - sx) * v2y - (p2y - sy) * v2x))
    lh = m * ((p2x - hx) * v2y - (p2y - hy) * v2x)
    # after: new stance rate u2 (leg at angle t1 pinned at S), new swing rate u1 (angle t2)
    M = np.zeros((2, 2))
    for j in range(2):
        u1, u2 = (1.0, 0.0) if j == 0 else (0.0, 1.0)
        vhx, vhy = -L * c1 * u2, -L * s1 * u2
        v1x, v1y = -a * c1 * u2, -a * s1 * u2
        v2x, v2y = vhx + b * c2 * u1, vhy + b * s2 * u1
        M[0, j] = (m * ((p1x - sx) * v1y - (p1y - sy) * v1x)
                   + MH * ((hx - sx) * vhy - (hy - sy) * vhx)
                   + m * ((p2x - sx) * v2y - (p2y - sy) * v2x))
        M[1, j] = m * ((p2x - hx) * v2y - (p2y - hy) * v2x)
    det = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
    out[0], out[1] = t2, t1
    out[2] = (M[1, 1] * ls - M[0, 1] * lh) / det
    out[3] = (M[0, 0] * lh - M[1, 0] * ls) / det


@njit(cache=True)
def _dense(F, y_old, x, out):  # pragma: no cover - compiled
    """DOP853 dense output at the fraction ``x`` of the step (scipy's Dop853DenseOutput)."""
    for k in range(out.size):
        out[k] = 0.0
    for i in range(F.shape[0]):
        f = F[F.shape[0] - 1 - i]
        for k in range(out.size):
            out[k] += f[k]
            out[k] *= x if i % 2 == 0 else (1.0 - x)
    for k in range(out.size):
        out[k] += y_old[k]


@njit(cache=True)
def _guard(y, gamma, which):  # pragma: no cover - compiled
    if which == 0:
        return y[0] - y[1]  # midstance (legs cross)
    return y[0] + y[1] + 2.0 * gamma  # heel strike


@njit(cache=True)
def _locate(F, y_old, h, gamma, which, out):  # pragma: no cover - compiled
    """Time [s] in the step of the guard's crossing, state into ``out``."""
    lo, hi = 0.0, 1.0
    _dense(F, y_old, lo, out)
    glo = _guard(out, gamma, which)
    _dense(F, y_old, hi, out)
    ghi = _guard(out, gamma, which)
    for it in range(60):
        x = hi - ghi * (hi - lo) / (ghi - glo) if it % 3 != 2 else 0.5 * (lo + hi)
        if not lo < x < hi:
            x = 0.5 * (lo + hi)
        _dense(F, y_old, x, out)
        gx = _guard(out, gamma, which)
        if (gx > 0) == (glo > 0):
            lo, glo = x, gx
        else:
            hi, ghi = x, gx
        if (hi - lo) * h < 1e-14 or gx == 0.0:
            break
    _dense(F, y_old, x, out)
    return x * h


@njit(cache=True)
def _stage(y, h, K, s, p, out):  # pragma: no cover - compiled
    """Stage ``s`` of the step: its state ``out = y + h sum_j A[s, j] K[j]`` (j < s), its
    slope into ``K[s]``."""
    for k in range(y.size):
        acc = 0.0
        for j in range(s):
            acc += A[s, j] * K[j, k]
        out[k] = y[k] + h * acc
    flow(out, p, K[s])


@njit(cache=True)
def _dense_coeffs(y, ynew, h, K, F, ev, p):  # pragma: no cover - compiled
    """The 3 extra stages and the interpolant's coefficients ``F`` of the step."""
    n = y.size
    for s in range(NS + 1, 16):
        _stage(y, h, K, s, p, ev)
    for k in range(n):
        dy = ynew[k] - y[k]
        F[0, k] = dy
        F[1, k] = h * K[0, k] - dy
        F[2, k] = 2.0 * dy - h * (K[NS, k] + K[0, k])
        for r in range(4):
            acc = 0.0
            for j in range(16):
                acc += D[r, j] * K[j, k]
            F[3 + r, k] = h * acc


@njit(cache=True)
def step(x0, gamma, p, rtol, atol, max_time, out):  # pragma: no cover - compiled
    """One step from the post-impact state ``x0`` on slope ``gamma`` [rad]; the next
    post-impact state into ``out``.  Returns True for a heel strike, False for a fall."""
    n = 4
    K = np.empty((16, n))
    F = np.empty((7, n))
    y = x0.copy()
    ynew = np.empty(n)
    f = np.empty(n)
    ev = np.empty(n)
    flow(y, p, f)
    t, h, armed = 0.0, 0.02, False
    while t < max_time:
        rejected = False
        while True:
            K[0] = f
            for s in range(1, NS):
                _stage(y, h, K, s, p, ynew)
            for k in range(n):
                acc = 0.0
                for j in range(NS):
                    acc += B[j] * K[j, k]
                ynew[k] = y[k] + h * acc
            flow(ynew, p, K[NS])
            e5, e3 = 0.0, 0.0
            for k in range(n):
                sc = atol + rtol * max(abs(y[k]), abs(ynew[k]))
                a5, a3 = 0.0, 0.0
                for j in range(NS + 1):
                    a5 += E5[j] * K[j, k]
                    a3 += E3[j] * K[j, k]
                e5 += (a5 / sc) ** 2
                e3 += (a3 / sc) ** 2
            err = 0.0 if e5 == 0 and e3 == 0 else h * e5 / math.sqrt(e5 + 0.01 * e3)
            if err < 1.0:
                fac = 10.0 if err == 0 else min(10.0, 0.9 * err ** (-1.0 / 8.0))
                if rejected:
                    fac = min(1.0, fac)
                break
            h *= max(0.2, 0.9 * err ** (-1.0 / 8.0))
            rejected = True
        if abs(ynew[1]) >= 0.5 * math.pi:
            return False  # the hip reaches the ground
        if not armed and _guard(ynew, gamma, 0) > 0 >= _guard(y, gamma, 0):
            armed = True
        elif armed and _guard(ynew, gamma, 0) < 0:
            return False  # the swing leg falls back
        if armed and _guard(ynew, gamma, 1) <= 0 < _guard(y, gamma, 1):
            _dense_coeffs(y, ynew, h, K, F, ev, p)
            _locate(F, y, h, gamma, 1, ev)
            impact(ev, p, out)
            return True
        y[:] = ynew
        f[:] = K[NS]
        t += h
        h *= fac
    return False


@njit(cache=True)
def walks(x0, slopes, p, rtol, atol, max_time, steps_out, fell_out):  # pragma: no cover
    """Walk each row of ``slopes`` (W, max_steps) [rad] from ``x0`` until it falls or
    reaches the step cap: heel strikes into ``steps_out`` (W,), falls into ``fell_out``."""
    x = np.empty(4)
    nxt = np.empty(4)
    for w in range(slopes.shape[0]):
        x[:] = x0
        steps_out[w] = 0
        fell_out[w] = False
        for k in range(slopes.shape[1]):
            if not step(x, slopes[w, k], p, rtol, atol, max_time, nxt):
                fell_out[w] = True
                break
            steps_out[w] += 1
            x[:] = nxt


def params(walker_section) -> np.ndarray:
    """``[m, M_H, L, a, g]`` from a compass-gait scene's ``walker`` section (fields
    ``leg_mass_kg``, ``hip_mass_kg``, ``leg_length_m``, ``leg_mass_from_foot_m``,
    ``gravity_m_per_s2``)."""
    w = walker_section
    return np.array([w.leg_mass_kg, w.hip_mass_kg, w.leg_length_m, w.leg_mass_from_foot_m,
                     w.gravity_m_per_s2], dtype=float)
