"""Independent reference: the three-link walker (two straight legs, a torso hinged at the hip,
point feet, point masses), written by hand in numpy from the closed-form model of
J. W. Grizzle, G. Abba & F. Plestan (2001), "Asymptotically stable walking for biped robots:
analysis via systems with impulse effects", IEEE TAC 46(1):51-64, and E. R. Westervelt,
J. W. Grizzle, C. Chevallereau, J. H. Choi & B. Morris (2007), *Feedback Control of Dynamic
Bipedal Robot Locomotion*, CRC Press (its three-link model).  No walkerlab import, no sympy,
no code shared with walkerlab's generator.

Coordinates ``q = (q1, q2, q3)`` [rad]: stance leg, swing leg (from the downward vertical,
positive with the foot ahead of the hip) and torso (from the upward vertical, positive
leaning back); world x forward, y up, gravity ``(0, -g)``; the stance foot at ``(x_f, y_f)``.
Legs of length ``r`` with a point mass ``m`` at ``d`` from the hip (the book: ``d = r / 2``),
hip mass ``MH``, torso mass ``MT`` at ``l`` above the hip::

    hip    = p_f + r (-sin q1, cos q1)
    stance mass = p_f + (r - d) (-sin q1, cos q1)
    swing mass  = hip + d (sin q2, -cos q2);  swing foot = hip + r (sin q2, -cos q2)
    torso mass  = hip + l (-sin q3, cos q3)

Flow ``D(q) q'' + C(q, q') q' + G(q) = B u`` with (the book's form; ``d = r / 2`` gives its
``D11 = (5/4 m + MH + MT) r^2``, ``D12 = -m r^2 cos(q1 - q2) / 2``, ``D22 = m r^2 / 4``)::

    D11 = (MH + MT + m) r^2 + m (r - d)^2    D12 = -m r d cos(q1 - q2)
    D13 = MT r l cos(q1 - q3)                D22 = m d^2,  D33 = MT l^2,  D23 = 0
    C   = [[0, -m r d sin(q1 - q2) q2', MT r l sin(q1 - q3) q3'],
           [m r d sin(q1 - q2) q1', 0, 0],
           [-MT r l sin(q1 - q3) q1', 0, 0]]
    G   = [-(MH r + m (r - d) + m r + MT r) g sin q1,  m d g sin q2,  -MT l g sin q3]

``u = (u1, u2)`` the torques at the stance and swing hips, each ``+u`` on its leg and ``-u``
on the torso (the joint angle leg minus torso): ``B = [[1, 0], [0, 1], [-1, -1]]`` (texts
differ in the sign of ``u``).

Heel strike (rigid, plastic, no slip; the trailing foot leaves without impulse): extended
coordinates ``(q, x_f, y_f)``, ``De = sum m J^T J`` of the point masses, ``E`` the Jacobian
of the swing foot::

    [[De, -E^T], [E, 0]] [qe'+, F] = [De qe'-, 0]

then relabelling: ``q+ = (q2, q1, q3)``, ``q'+`` likewise.  The heel strike happens with the
legs symmetric about the slope's normal, ``q1 + q2 + 2 gamma = 0`` (swing foot ahead; the
straight swing foot's pass through the ground at mid-stance is ignored, as in the compass
gait and the book).
"""

from __future__ import annotations

import numpy as np

#: parameter names (SI): gravity, leg length, leg mass and its distance from the hip, hip
#: mass, torso mass and its distance above the hip
PARAMS = ("g", "r", "m", "d", "MH", "MT", "l")


def mass_matrix(q, p) -> np.ndarray:
    """``D(q)`` (3, 3) [kg m^2]."""
    q1, q2, q3 = q
    r, m, d, MH, MT, lt = (p[k] for k in ("r", "m", "d", "MH", "MT", "l"))
    D12 = -m * r * d * np.cos(q1 - q2)
    D13 = MT * r * lt * np.cos(q1 - q3)
    return np.array([[(MH + MT + m) * r ** 2 + m * (r - d) ** 2, D12, D13],
                     [D12, m * d ** 2, 0.0],
                     [D13, 0.0, MT * lt ** 2]])


def coriolis(q, dq, p) -> np.ndarray:
    """``C(q, q')`` (3, 3) [kg m^2 / s]."""
    q1, q2, q3 = q
    d1, d2, d3 = dq
    a = p["m"] * p["r"] * p["d"] * np.sin(q1 - q2)
    b = p["MT"] * p["r"] * p["l"] * np.sin(q1 - q3)
    return np.array([[0.0, -a * d2, b * d3], [a * d1, 0.0, 0.0], [-b * d1, 0.0, 0.0]])


def gravity(q, p) -> np.ndarray:
    """``G(q)`` (3,) [N m]."""
    q1, q2, q3 = q
    g, r, m, d, MH, MT, lt = (p[k] for k in PARAMS)
    return np.array([-(MH * r + m * (r - d) + m * r + MT * r) * g * np.sin(q1),
                     m * d * g * np.sin(q2), -MT * lt * g * np.sin(q3)])


#: the torques' generalised forces (3, 2): u1 at the stance hip, u2 at the swing hip
B = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, -1.0]])


def bias(q, dq, p) -> np.ndarray:
    """``h = C q' + G`` (3,) [N m]."""
    return coriolis(q, dq, p) @ np.asarray(dq, float) + gravity(q, p)


def acceleration(q, dq, u, p) -> np.ndarray:
    """``q''`` (3,) [rad/s^2] under hip torques ``u`` (2,) [N m]."""
    return np.linalg.solve(mass_matrix(q, p), B @ np.asarray(u, float) - bias(q, dq, p))


def _jacobians(q, p) -> tuple[list, np.ndarray]:
    """``[(mass, J (2, 5))]`` of the point masses in ``(q1, q2, q3, x_f, y_f)`` and the swing
    foot's Jacobian ``E`` (2, 5)."""
    q1, q2, q3 = q
    r, m, d, MH, MT, lt = (p[k] for k in ("r", "m", "d", "MH", "MT", "l"))
    c1, s1, c2, s2, c3, s3 = np.cos(q1), np.sin(q1), np.cos(q2), np.sin(q2), np.cos(q3), \
        np.sin(q3)
    hip = np.array([[-r * c1, 0, 0, 1, 0], [-r * s1, 0, 0, 0, 1]], float)
    stance = np.array([[-(r - d) * c1, 0, 0, 1, 0], [-(r - d) * s1, 0, 0, 0, 1]], float)
    swing = hip + np.array([[0, d * c2, 0, 0, 0], [0, d * s2, 0, 0, 0]])
    torso = hip + np.array([[0, 0, -lt * c3, 0, 0], [0, 0, -lt * s3, 0, 0]])
    E = hip + np.array([[0, r * c2, 0, 0, 0], [0, r * s2, 0, 0, 0]])
    return [(MH, hip), (m, stance), (m, swing), (MT, torso)], E


def extended_mass_matrix(q, p) -> np.ndarray:
    """``De`` (5, 5) in ``(q, x_f, y_f)``."""
    bodies, _ = _jacobians(q, p)
    return sum(mass * J.T @ J for mass, J in bodies)


def impact(x, p) -> np.ndarray:
    """The heel strike and relabelling: post-impact state (6,) of the pre-impact ``x``."""
    q, dq = np.asarray(x[:3], float), np.asarray(x[3:], float)
    De = extended_mass_matrix(q, p)
    _, E = _jacobians(q, p)
    A = np.block([[De, -E.T], [E, np.zeros((2, 2))]])
    rhs = np.concatenate([De @ np.concatenate([dq, [0.0, 0.0]]), [0.0, 0.0]])
    dqe = np.linalg.solve(A, rhs)[:3]
    swap = [1, 0, 2]
    return np.concatenate([q[swap], dqe[swap]])


def energy(x, p) -> float:
    """Kinetic plus potential energy [J] (the stance foot at height 0)."""
    q, dq = np.asarray(x[:3], float), np.asarray(x[3:], float)
    q1, q2, q3 = q
    g, r, m, d, MH, MT, lt = (p[k] for k in PARAMS)
    V = g * (MH * r * np.cos(q1) + m * (r - d) * np.cos(q1)
             + m * (r * np.cos(q1) - d * np.cos(q2)) + MT * (r * np.cos(q1) + lt * np.cos(q3)))
    return 0.5 * dq @ mass_matrix(q, p) @ dq + V


def pd_phase_law(tables, gains):
    """A PD law on the hip angles (leg minus torso) tracking references of the phase
    variable ``s = q1``, read by not-a-knot cubic splines of the tables and held at their
    end values outside: ``u_i = -K_i (delta_i - h_i(s)) - D_i (delta_i' - h_i'(s) s')``.

    Parameters
    ----------
    tables : list of (phases, angles)
        Per hip (stance, swing).
    gains : list of (K, D)

    Returns
    -------
    callable
        ``x (6,) -> u (2,)``.
    """
    from scipy.interpolate import CubicSpline

    splines = [(CubicSpline(s, y, bc_type="not-a-knot"), s[0], s[-1]) for s, y in tables]

    def law(x):
        q, dq = x[:3], x[3:]
        s, ds = q[0], dq[0]
        u = []
        for i, ((sp, lo, hi), (K, D)) in enumerate(zip(splines, gains)):
            sc = min(max(s, lo), hi)
            h, dh = float(sp(sc)), (float(sp(sc, 1)) if lo < s < hi else 0.0)
            delta, ddelta = q[i] - q[2], dq[i] - dq[2]
            u.append(-K * (delta - h) - D * (ddelta - dh * ds))
        return np.array(u)

    return law


def step(x0, law, p, gamma=0.0, rtol=1e-12, atol=1e-12, t_max=5.0) -> tuple[np.ndarray, float]:
    """One step of the closed loop from the post-impact ``x0``: the flow until the heel
    strike (``q1 + q2 + 2 gamma`` decreasing through zero with the swing foot ahead), the
    impact and relabelling (scipy's DOP853).  Returns ``(x+, duration [s])``."""
    from scipy.integrate import solve_ivp

    def f(t, x):
        return np.concatenate([x[3:], acceleration(x[:3], x[3:], law(x), p)])

    def strike(t, x):
        return x[0] + x[1] + 2 * gamma if x[1] > x[0] else 1.0  # the swing foot ahead
    strike.terminal, strike.direction = True, -1
    sol = solve_ivp(f, (0.0, t_max), np.asarray(x0, float), method="DOP853", rtol=rtol,
                    atol=atol, events=strike)
    if not sol.t_events[0].size:
        raise RuntimeError("no heel strike")
    return impact(sol.y_events[0][0], p), float(sol.t_events[0][0])
