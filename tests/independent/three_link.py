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


def _u(a):
    """Unit vector of a leg at ``a`` from the downward vertical, and its derivative."""
    return np.array([np.sin(a), -np.cos(a)]), np.array([np.cos(a), np.sin(a)])


def _jacobians(q, p, gamma=0.0, R=0.0) -> tuple[list, np.ndarray]:
    """``[(mass, J (2, 5), height)]`` of the point masses in ``(q1, q2, q3, x_f, y_f)`` and
    the Jacobian ``E`` (2, 5) of the swing foot's material contact point.  Arc feet of
    radius ``R`` (McGeer 1990; centre on the leg at ``r - R`` from the hip): the stance arc
    rolls, its contact point ``-R (q1 + gamma)`` along the slope (tangent ``t = (cos gamma,
    -sin gamma)``, normal ``n = (sin gamma, cos gamma)``) from the step's reference point,
    its centre at ``R n`` above that; the swing arc's material contact point moves at its
    centre's velocity plus ``R q2' t``.  Complex-safe (the complex step below)."""
    q1, q2, q3 = q
    r, m, d, MH, MT, lt = (p[k] for k in ("r", "m", "d", "MH", "MT", "l"))
    t = np.array([np.cos(gamma), -np.sin(gamma)])
    n = np.array([np.sin(gamma), np.cos(gamma)])
    (u1, du1), (u2, du2), (u3, du3) = _u(q1), _u(q2), _u(q3)
    base, dbase = -R * (q1 + gamma) * t + R * n, -R * t  # the stance arc's centre

    def jac(d1=0.0, d2=0.0, d3=0.0):
        return np.column_stack([d1 * np.ones(2) if np.isscalar(d1) else d1,
                                d2 * np.ones(2) if np.isscalar(d2) else d2,
                                d3 * np.ones(2) if np.isscalar(d3) else d3, np.eye(2)])
    hip, dhip = base - (r - R) * u1, dbase - (r - R) * du1
    bodies = [(MH, jac(dhip), hip[1]),
              (m, jac(dbase - (r - R - d) * du1), (base - (r - R - d) * u1)[1]),
              (m, jac(dhip, d * du2), (hip + d * u2)[1]),
              (MT, jac(dhip, 0.0, -lt * du3), (hip - lt * u3)[1])]
    E = jac(dhip, (r - R) * du2 + R * t)
    return bodies, E


def extended_mass_matrix(q, p, gamma=0.0, R=0.0) -> np.ndarray:
    """``De`` (5, 5) in ``(q, x_f, y_f)``."""
    bodies, _ = _jacobians(q, p, gamma, R)
    return sum(mass * J.T @ J for mass, J, _ in bodies)


def rolling_dynamics(q, dq, p, gamma=0.0, R=0.0) -> tuple[np.ndarray, np.ndarray]:
    """``(M, h)`` of any foot radius (arc feet; ``R = 0`` the point feet of the closed
    forms): ``M`` the pinned block of :func:`extended_mass_matrix`, ``h = C q' + G`` with
    ``h_i = sum_jk (dM_ij/dq_k - dM_jk/dq_i / 2) q'_j q'_k + dV/dq_i``, the derivatives by
    the complex step (exact to round-off)."""
    q = np.asarray(q, float)
    dq = np.asarray(dq, float)
    step = 1e-30

    def M_of(z):
        return extended_mass_matrix(z, p, gamma, R)[:3, :3]

    def V_of(z):
        return sum(mass * p["g"] * y for mass, _, y in _jacobians(z, p, gamma, R)[0])
    dM = [np.imag(M_of(q + 1j * step * e)) / step for e in np.eye(3)]
    G = np.array([np.imag(V_of(q + 1j * step * e)) / step for e in np.eye(3)])
    h = np.array([sum((dM[k][i, j] - 0.5 * dM[i][j, k]) * dq[j] * dq[k]
                      for j in range(3) for k in range(3)) for i in range(3)])
    return np.real(M_of(q)), h + G


def impact(x, p, gamma=0.0, R=0.0) -> np.ndarray:
    """The heel strike and relabelling: post-impact state (6,) of the pre-impact ``x``."""
    q, dq = np.asarray(x[:3], float), np.asarray(x[3:], float)
    De = extended_mass_matrix(q, p, gamma, R)
    _, E = _jacobians(q, p, gamma, R)
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
