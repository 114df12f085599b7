"""The plain-library yardstick of a warm ``walkerlab contact-sim``: a bare numpy + scipy script
that finds the paper walker's passive fixed point (no walkerlab import, so a benchmark can run
this file as a whole process beside any code tree).

    python walkerlab/bench/bare_fixedpoint.py

Model: the compass-gait walker of the paper's Table 1 (Goswami, Thuilot & Espiau 1996, INRIA
RR-2996; the same equations as :mod:`walkerlab.bench.monte_carlo_yardstick`): legs of 1 m, 5 kg at
0.5 m from the foot, hip 10 kg, g = 9.81 m/s^2, slope 0.0174 rad.  State ``[theta1, theta2,
dtheta1, dtheta2]`` (swing leg first, absolute angles from the vertical) just after heel strike.
One step is ``scipy.integrate.solve_ivp`` (DOP853, rtol = atol = 1e-12, the scene's solver) to
the heel strike ``theta1 + theta2 + 2 gamma = 0`` after midstance, then the plastic impact
(angular momentum about the new stance foot and of the trailing leg about the hip).  The fixed
point is ``scipy.optimize.root`` (hybr) of ``P(x) - x`` from the paper's Eq. (11), the initial
guess ``configs/paper.yaml`` gives.  Prints the fixed point and the step period.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import root

M, MH, L, A, G = 5.0, 10.0, 1.0, 0.5, 9.81
B = L - A
GAMMA = 0.0174
GUESS = np.array([-0.2022, 0.1674, -0.60, -0.84])  # the paper's Eq. (11)


def flow(t, y):
    """dy/dt (4,) [rad/s, rad/s, rad/s^2, rad/s^2] of the pinned compass gait at the state
    ``y`` (4,) [rad, rad, rad/s, rad/s] (Lagrange; Goswami, Thuilot & Espiau 1996, the
    equations of :func:`walkerlab.bench.monte_carlo_yardstick.flow`); ``t`` [s] unused."""
    mu = M * A + (M + MH) * L
    s, c = math.sin(y[0] - y[1]), math.cos(y[0] - y[1])
    d11, d12, d22 = M * B * B, -M * L * B * c, M * A * A + (M + MH) * L * L
    r1 = M * L * B * s * y[3] ** 2 - M * G * B * math.sin(y[0])
    r2 = -M * L * B * s * y[2] ** 2 + mu * G * math.sin(y[1])
    det = d11 * d22 - d12 * d12
    return [y[2], y[3], (d22 * r1 - d12 * r2) / det, (d11 * r2 - d12 * r1) / det]


def heel_strike(t, y):
    """Heel-strike event of ``solve_ivp`` at the state ``y`` (4,) [rad, rad, rad/s, rad/s]:
    ``theta1 + theta2 + 2 gamma`` [rad] once the legs have crossed (midstance), 1 before
    (no heel strike while the swing foot is behind the stance foot)."""
    return y[0] + y[1] + 2.0 * GAMMA if y[0] - y[1] > 0 else 1.0


heel_strike.terminal, heel_strike.direction = True, -1


def impact(x):
    """Post-impact state (4,) [rad, rad, rad/s, rad/s], the legs' roles swapped, from the
    pre-impact state ``x`` (4,): plastic impact, angular momentum of the walker about the
    new stance foot and of the trailing leg about the hip conserved (Goswami, Thuilot &
    Espiau 1996)."""
    t1, t2, w1, w2 = x
    s1, c1, s2, c2 = math.sin(t1), math.cos(t1), math.sin(t2), math.cos(t2)
    h = np.array([-L * s2, L * c2])
    p1, p2, foot = h + B * np.array([s1, -c1]), A * np.array([-s2, c2]), h + L * np.array([s1, -c1])

    def cross(r, v):  # z component of r x v
        return r[0] * v[1] - r[1] * v[0]

    vh = -L * w2 * np.array([c2, s2])
    v1, v2 = vh + B * w1 * np.array([c1, s1]), -A * w2 * np.array([c2, s2])
    before = [M * cross(p1 - foot, v1) + MH * cross(h - foot, vh) + M * cross(p2 - foot, v2),
              M * cross(p2 - h, v2)]
    cols = []
    for u1, u2 in ((1.0, 0.0), (0.0, 1.0)):  # new swing rate, new stance rate
        vh = -L * u2 * np.array([c1, s1])
        v1, v2 = -A * u2 * np.array([c1, s1]), vh + B * u1 * np.array([c2, s2])
        cols.append([M * cross(p1 - foot, v1) + MH * cross(h - foot, vh)
                     + M * cross(p2 - foot, v2), M * cross(p2 - h, v2)])
    rates = np.linalg.solve(np.array(cols).T, before)
    return np.array([t2, t1, rates[0], rates[1]])


def step(x):
    """The Poincare map from the post-impact state ``x`` (4,) [rad, rad, rad/s, rad/s]:
    (the next post-impact state (4,), the step period [s])."""
    sol = solve_ivp(flow, (0.0, 5.0), x, method="DOP853", rtol=1e-12, atol=1e-12,
                    events=heel_strike)
    return impact(sol.y_events[0][0]), sol.t_events[0][0]


def main() -> None:
    """Find and print the fixed point (4,) [rad, rad, rad/s, rad/s] and its period [s]."""
    sol = root(lambda x: step(x)[0] - x, GUESS, method="hybr", tol=1e-12)
    x = sol.x
    print("fixed point", " ".join(f"{v:.10f}" for v in x), f"period {step(x)[1]:.10f} s",
          f"residual {np.max(np.abs(step(x)[0] - x)):.2e}")


if __name__ == "__main__":
    main()
