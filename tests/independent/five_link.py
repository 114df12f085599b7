"""Independent reference: a planar five-link biped (torso, two thighs, two shanks, point
feet, a hip point mass), Lagrange by sympy in RELATIVE joint coordinates, with the heel strike
solved in extended coordinates (no walkerlab import, no code shared with its generator).

Source of the model: E. R. Westervelt, J. W. Grizzle & D. E. Koditschek (2003), "Hybrid
zero dynamics of planar biped walkers", IEEE TAC 48(1):42-56, Sec. II-III (RABBIT: torso,
femurs, tibias; centres of mass measured from the link's upper joint: the femur's from
the hip, the tibia's from the knee, the torso's from the hip).

Coordinates ``r = (th, h1, h2, k1, k2)`` [rad]:

- ``th`` the torso's angle from the upward vertical, counter-clockwise (leaning back);
- ``h1, h2`` the stance / swing hip angles, thigh relative to the torso, counter-clockwise
  (both zero with the torso upright and the thigh hanging straight down);
- ``k1, k2`` the stance / swing knee angles, shank relative to its thigh (0 straight).

A link's absolute direction angle ``a`` (counter-clockwise from the downward vertical for a
leg link) gives its unit vector ``u(a) = (sin a, -cos a)``; the thighs are ``th + h``, the
shanks ``th + h + k``; the torso points along ``-u(th)``.  Stance foot at the origin, world
x forward, y up, gravity (0, -g)::

    knee1 = -ls u(th+h1+k1);   hip = knee1 - lt u(th+h1)
    knee2 = hip + lt u(th+h2);  foot2 = knee2 + ls u(th+h2+k2)

Flow: ``T = sum 1/2 m |dp/dt|^2 + 1/2 I w^2``, ``V = sum m g y``, Euler-Lagrange with
``D = d^2 T / dr' dr'`` and ``h = (d^2 L / dr' dr) r' - dL/dr`` (sympy differentiates the
Lagrangian; nothing is assembled by hand): ``D r'' + h = Q``, ``Q`` the joint torques (in
relative coordinates each joint torque is its own coordinate's generalised force).

Heel strike (Westervelt et al. 2003, Sec. III-B; Hurmuzlu & Marghitu 1994): extended
coordinates ``(r, x_f, y_f)`` (stance foot free), ``De`` the Hessian of the extended kinetic
energy, ``E`` the Jacobian of the swing foot's position; plastic, no slip, the stance foot
leaving without impulse::

    [[De, -E^T], [E, 0]] [re'+, F] = [De re'-, 0]

then relabelling: the legs swap (``h1 <-> h2``, ``k1 <-> k2``, the torso stays).
"""

from __future__ import annotations

from functools import cache

import numpy as np
import sympy as sp

#: parameter names of :func:`reference` (SI): gravity, thigh and shank lengths, masses,
#: centre-of-mass distances (thigh from the hip, shank from the KNEE, torso up from the hip),
#: inertias about the centres of mass, hip point mass
PARAMS = ("g", "lt", "ls", "mt", "ms", "mT", "ct", "cs", "cT", "It", "Is", "IT", "mH")


@cache
def _model():
    r = sp.symbols("th h1 h2 k1 k2", real=True)
    dr = sp.symbols("dth dh1 dh2 dk1 dk2", real=True)
    xf, yf, dxf, dyf = sp.symbols("xf yf dxf dyf", real=True)
    g, lt, ls, mt, ms, mT, ct, cs, cT, It, Is, IT, mH = sp.symbols(PARAMS, real=True)
    th, h1, h2, k1, k2 = r

    def u(a):
        return sp.Matrix([sp.sin(a), -sp.cos(a)])

    base = sp.Matrix([xf, yf])
    knee1 = base - ls * u(th + h1 + k1)
    hip = knee1 - lt * u(th + h1)
    knee2 = hip + lt * u(th + h2)
    foot2 = knee2 + ls * u(th + h2 + k2)
    bodies = [  # (mass, inertia, centre, absolute angle)
        (mH, 0, hip, th),
        (mT, IT, hip - cT * u(th), th),
        (mt, It, hip + ct * u(th + h1), th + h1),
        (mt, It, hip + ct * u(th + h2), th + h2),
        (ms, Is, knee1 + cs * u(th + h1 + k1), th + h1 + k1),
        (ms, Is, knee2 + cs * u(th + h2 + k2), th + h2 + k2),
    ]
    qe, dqe = sp.Matrix([*r, xf, yf]), sp.Matrix([*dr, dxf, dyf])
    Te, V = sp.Integer(0), sp.Integer(0)
    for m, inertia, p, a in bodies:
        v = p.jacobian(qe) * dqe
        w = sp.diff(a, th) * dr[0] + sum(sp.diff(a, x) * dx for x, dx in zip(r[1:], dr[1:]))
        Te += sp.Rational(1, 2) * (m * (v.T * v)[0] + inertia * w ** 2)
        V += m * g * p[1]
    pinned = {xf: 0, yf: 0, dxf: 0, dyf: 0}
    Lag = (Te - V).subs(pinned)
    rv, drv = sp.Matrix(r), sp.Matrix(dr)
    D = sp.hessian(Lag, drv)
    dLdr = sp.Matrix([sp.diff(Lag, x) for x in r])
    h = sp.Matrix([sp.diff(Lag, dx) for dx in dr]).jacobian(rv) * drv - dLdr
    De = sp.hessian(Te, dqe).subs(pinned)
    E = foot2.jacobian(qe).subs(pinned)
    pars = sp.symbols(PARAMS, real=True)
    args = (list(r), list(dr), list(pars))
    return (sp.lambdify(args, D, "numpy"), sp.lambdify(args, h, "numpy"),
            sp.lambdify(args, De, "numpy"), sp.lambdify(args, E, "numpy"),
            sp.lambdify(args, (Te - V).subs(pinned), "numpy"),
            sp.lambdify(args, (foot2.subs(pinned), hip.subs(pinned)), "numpy"))


def acceleration(r, dr, p: dict, Q=None) -> np.ndarray:
    """``r''`` (5,) [rad/s^2] at ``(r, r')``; ``p`` by :data:`PARAMS`.  ``Q`` (5,): the
    generalised forces [N m] of the relative coordinates - joint torques ARE those: a
    torque ``tau`` at the stance hip (on the thigh, its reaction on the torso) does the
    virtual work ``tau dh1``, so ``Q = (0, tau_stance_hip, tau_swing_hip, tau_stance_knee,
    tau_swing_knee)``; None: passive."""
    D, h = _model()[:2]
    args = (list(r), list(dr), [p[k] for k in PARAMS])
    rhs = -np.asarray(h(*args), float).ravel() + (0.0 if Q is None else np.asarray(Q, float))
    return np.linalg.solve(np.asarray(D(*args), float), rhs)


def heel_strike(r, dr, p: dict) -> tuple[np.ndarray, np.ndarray]:
    """Post-impact ``(r, r')`` after the plastic heel strike and the legs' swap."""
    De, E = (np.asarray(f(list(r), list(dr), [p[k] for k in PARAMS]), float)
             for f in _model()[2:4])
    n = De.shape[0]
    K = np.zeros((n + 2, n + 2))
    K[:n, :n], K[:n, n:], K[n:, :n] = De, -E.T, E
    rhs = np.concatenate([De @ np.concatenate([dr, [0.0, 0.0]]), [0.0, 0.0]])
    dq = np.linalg.solve(K, rhs)[:5]
    swap = [0, 2, 1, 4, 3]
    return np.asarray(r)[swap], dq[swap]


def push_off_heel_strike(r, dr, p: dict, impulse: float) -> tuple[np.ndarray, np.ndarray]:
    """Kuo's (2002) pre-emptive push-off, then the plastic heel strike and the legs' swap:
    an impulse ``impulse`` [N s] at the stance foot, free for it, along the line from that
    foot to the hip (``De (dqe' - dqe-) = [0 | I]^T impulse e``, the extended coordinates'
    last two being the foot's position), then :func:`heel_strike`'s system from ``dqe'``
    (the new rates; the trailing foot's own rate is dropped as it leaves the ground)."""
    args = (list(r), list(dr), [p[k] for k in PARAMS])
    De, E = (np.asarray(f(*args), float) for f in _model()[2:4])
    hip = np.asarray(_model()[5](*args)[1], float).ravel()
    e = hip / np.linalg.norm(hip)
    n = De.shape[0]
    dqe = np.concatenate([dr, [0.0, 0.0]])
    dqe_po = dqe + np.linalg.solve(De, np.concatenate([np.zeros(n - 2), impulse * e]))
    K = np.zeros((n + 2, n + 2))
    K[:n, :n], K[:n, n:], K[n:, :n] = De, -E.T, E
    sol = np.linalg.solve(K, np.concatenate([De @ dqe_po, [0.0, 0.0]]))
    swap = [0, 2, 1, 4, 3]
    return np.asarray(r)[swap], sol[:5][swap]


def energy(r, dr, p: dict) -> float:
    """``T + V`` [J] (potential from the stance foot's height)."""
    f = _model()[4]
    return -float(f(list(r), list(dr), [p[k] for k in PARAMS])) + 2 * float(
        _kinetic(r, dr, p))


def _kinetic(r, dr, p):
    D = _model()[0]
    M = np.asarray(D(list(r), list(dr), [p[k] for k in PARAMS]), float)
    return 0.5 * np.asarray(dr) @ M @ np.asarray(dr)


def swing_foot(r, p: dict) -> np.ndarray:
    """Swing foot position (2,) [m] relative to the stance foot."""
    f = _model()[5]
    return np.asarray(f(list(r), [0.0] * 5, [p[k] for k in PARAMS])[0], float).ravel()
