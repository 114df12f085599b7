"""Independent reference: Kuo's (2002) powered simplest walker, its step map and Floquet
multipliers.

Pure numpy/scipy, no walkerlab import.  Sources: Garcia M., Chatterjee A., Ruina A., Coleman M.
(1998) "The simplest walking model: stability, complexity, and scaling", J Biomech Eng
120:281-288 (Eq. 1-3); Kuo A.D. (2002) "Energetics of actively powered locomotion using the
simplest walking model", J Biomech Eng 124:113-120 (the push-off impulse P before heel strike
and the swing-hip spring of stiffness k).

Nondimensional (hip mass M = 1, leg length l = 1, g = 1), massless legs, infinitesimal feet.
theta: stance-leg angle from the slope normal, phi: inter-leg angle, gamma: slope:

    theta'' = sin(theta - gamma)
    phi''   = sin(theta - gamma) + sin(phi) (theta'^2 - cos(theta - gamma)) - k phi

Heel strike when phi - 2 theta crosses zero with theta < 0 (the swing foot ahead, after
mid-stance).  Push-off along the trailing leg, then the plastic heel strike (Kuo 2002, Eq. 2):

    theta+ = -theta-,  theta'+ = cos(2 theta-) theta'- + sin(2 theta-) P,
    phi+ = -2 theta-,  phi'+ = (1 - cos(2 theta-)) theta'+

(theta'+ is written with the sign convention theta'- < 0: the push-off adds to the forward
rotation.)  The state is (theta, phi, theta', phi'), walkerlab's order for this walker
(stance angle, hip angle, stance rate, hip rate).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import root

RTOL = ATOL = 1e-12


def flow(t, x, k, gamma):
    """Garcia et al. (1998) Eq. 1-2 with Kuo's swing-hip spring ``-k phi`` (4,)."""
    th, ph, dth, dph = x
    thdd = np.sin(th - gamma)
    return np.array([dth, dph, thdd,
                     thdd + np.sin(ph) * (dth ** 2 - np.cos(th - gamma)) - k * ph])


def transition(x, P):
    """Push-off ``P`` then heel strike (Kuo 2002, Eq. 2) of the pre-impact state (4,)."""
    th, _, dth, _ = x
    c, s = np.cos(2 * th), np.sin(2 * th)
    dth_p = c * dth + s * P
    return np.array([-th, -2 * th, dth_p, (1 - c) * dth_p])


def step(x, k, P, gamma=0.0, t_max=20.0):
    """Post-impact state (4,) to the next post-impact state and the step period."""
    def strike(t, z, *_):
        return z[1] - 2 * z[0]
    strike.terminal, strike.direction = True, 1

    def late(t, z, *_):  # arm the guard after mid-stance only (theta < 0)
        return z[0]
    late.terminal, late.direction = True, -1

    s1 = solve_ivp(flow, (0.0, t_max), x, args=(k, gamma), method="DOP853", rtol=RTOL,
                   atol=ATOL, events=[late])
    t0, z = s1.t[-1], s1.y[:, -1]
    s2 = solve_ivp(flow, (t0, t_max), z, args=(k, gamma), method="DOP853", rtol=RTOL,
                   atol=ATOL, events=[strike])
    if len(s2.t_events[0]) == 0:
        raise RuntimeError("no heel strike")
    return transition(s2.y[:, -1], P), float(s2.t[-1])


def fixed_point(k, P, gamma=0.0, guess=(0.2, 0.4, -0.21, -0.017), h=1e-6):
    """The period-1 gait ``(x* (4,), step period, multipliers (4,) by decreasing modulus)``:
    the root of ``(theta, theta', phi') -> P(x) - x`` on the section ``phi = 2 theta``, the
    multipliers from central differences (step ``h``) of the full map."""
    def full(z):
        return np.array([z[0], 2 * z[0], z[1], z[2]])

    def res(z):
        xn, _ = step(full(z), k, P, gamma)
        return xn[[0, 2, 3]] - z

    g = np.asarray(guess, float)
    sol = root(res, g[[0, 2, 3]], method="hybr", options={"xtol": 1e-13})
    x = full(sol.x)
    if np.max(np.abs(res(sol.x))) > 1e-10:
        raise RuntimeError(f"no fixed point: {sol.message}")
    J = np.zeros((4, 4))
    for j in range(4):
        e = np.zeros(4)
        e[j] = h
        J[:, j] = (step(x + e, k, P, gamma)[0] - step(x - e, k, P, gamma)[0]) / (2 * h)
    mult = np.linalg.eigvals(J)
    return x, step(x, k, P, gamma)[1], mult[np.argsort(-np.abs(mult))]
