"""Independent toe push-off of the flat-footed reference walker (``flat_feet_reference.py``),
written with Newton-Euler impulse balances instead of extended coordinates (no walkerlab
code).

Push-off: an impulse ``P e`` at the stance toe, ``e`` from the toe to the hip, the ankle held
through it (the foot and the stance leg one rigid body with the hip mass), the swing leg
pinned at the hip (no impulsive torque there), the toe free.  Unknowns: the hip's velocity
change and both legs' spin changes (4); equations: the whole walker's linear momentum
(``sum m dv = P e``, 2), its angular momentum about the toe (unchanged: the impulse acts
there, 1) and the swing leg's about the hip (unchanged, 1).  Then the reference's own heel
strike (momentum projection on the new heel-pinned coordinates, the trailing foot free) of
those velocities.
"""

from __future__ import annotations

import numpy as np


def _cross(a, b) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _perp(r):
    """``k x r`` (the velocity of a point at ``r`` turning at 1 rad/s)."""
    return np.array([-r[1], r[0]])


def toe(ref, mode: str, q) -> np.ndarray:
    """The stance toe's position [m] in ``mode``'s frame: ankle + t along the sole."""
    pos = ref.positions(mode, q)
    st, an = q[1], q[2]
    ankle = pos["hip"] + ref.p["L"] * np.array([np.sin(st), -np.cos(st)])
    return ankle + ref.p["t"] * np.array([np.cos(st + an), np.sin(st + an)])


def push_off(ref, mode: str, x, P: float) -> dict:
    """Velocities (dict of (2,), the massive bodies) after the push-off ``P`` [N s], and
    the unit direction ``e`` and toe position."""
    q = x[:3]
    pos, v = ref.positions(mode, q), ref.velocities(mode, x)
    M, m = ref.p["M"], ref.p["m"]
    tp = toe(ref, mode, q)
    e = (pos["hip"] - tp) / np.linalg.norm(pos["hip"] - tp)
    r_st, r_sw = pos["stance_mass"] - pos["hip"], pos["swing_mass"] - pos["hip"]

    def dv(u):  # velocity changes of the bodies for u = (dvh_x, dvh_y, dw_st, dw_sw)
        h = u[:2]
        return {"hip": h, "stance_mass": h + u[2] * _perp(r_st),
                "swing_mass": h + u[3] * _perp(r_sw)}

    mass = {"hip": M, "stance_mass": m, "swing_mass": m}

    def residual(u):
        d = dv(u)
        lin = sum(mass[k] * d[k] for k in d)
        ang_toe = sum(mass[k] * _cross(pos[k] - tp, d[k]) for k in d)
        ang_sw = m * _cross(r_sw, d["swing_mass"])
        return np.array([lin[0], lin[1], ang_toe, ang_sw])

    A = np.stack([residual(ei) for ei in np.eye(4)], axis=1)  # linear, no constant part
    u = np.linalg.solve(A, np.array([*(P * e), 0.0, 0.0]))
    d = dv(u)
    return {"v": {k: v[k] + d[k] for k in v}, "e": e, "toe": tp, "mass": mass}


def pushed_heel_strike(ref, mode: str, x, P: float) -> dict:
    """Push-off then the reference's heel strike: ``x_plus`` (new labelling, heel contact),
    the kinetic energies before, after the push-off and after the heel strike [J]."""
    po = push_off(ref, mode, x, P)
    v, mass = po["v"], po["mass"]
    qn = np.array([x[1], x[0], ref.p["r"]])
    heel = ref.modes["heel"]
    pair = {"hip": "hip", "stance_mass": "swing_mass", "swing_mass": "stance_mass"}
    rhs = sum(heel["masses"][k] * heel["J"][k](*qn).T @ v[pair[k]] for k in pair)
    x_plus = np.concatenate([qn, np.linalg.solve(heel["M"](*qn), rhs)])
    v0 = ref.velocities(mode, x)
    ke = [0.5 * sum(mass[k] * vk @ vk for k, vk in vel.items())
          for vel in (v0, v, ref.velocities("heel", x_plus))]
    return {"x_plus": x_plus, "ke": ke, **po}
