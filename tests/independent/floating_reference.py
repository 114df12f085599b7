"""Independent numpy floating walker: mass matrix and bias from the bodies of a WalkerData.

Written directly from Newton's laws for planar point masses and rods, sharing no code with
``walkerlab.models`` (neither the symbolic generator nor the multibody export): every body
(the hip point mass, every point mass and rod of both legs, every body of an upper body) is
kept separate, with its own position Jacobian, so the link combination by the parallel-axis
theorem in the export is checked too.

Floating coordinates ``q = (hip_x, hip_y, psi...)`` [m, m, rad]: the hip position (y up) and
the absolute angle from the vertical of every link, leg1 first (straight leg: ``leg1_angle``;
kneed: ``leg1_thigh_angle, leg1_shank_angle``), then leg2.  A point at distance ``s`` along
a link of angle ``psi`` and ``e`` ahead of its axis lies at ``joint + s u(psi) + e
u(psi + pi/2)``, ``u(psi) = (sin psi, -cos psi)``.  With legs that differ, leg1 carries the
first step's swing numbers (``m_sw_<body>``), leg2 the stance numbers.  The upper body of
the bisecting hip mechanism (Wisse et al. 2007) has the angle ``a = (psi_leg1 + psi_leg2)/2``
from the upward vertical: a body ``d`` up its axis and ``e`` ahead lies at
``hip - d u(a) + e u(a + pi/2)``.

Every body position is ``hip + sum_k l_k u(w_k . q + o_k)`` (``w_k`` a weight row over the
coordinates, ``o_k`` a constant).  For a body of mass ``m``: ``v = J qd`` with columns
``l_k (cos a_k, sin a_k) w_k``, ``Jdot qd = sum_k l_k (-sin a_k, cos a_k) (w_k . qd)^2``.  Then
``M = sum m J^T J + sum I w w^T`` (``w`` the body's link-angle weights) and
``bias = sum m J^T (Jdot qd) + sum m J^T (0, g)`` so that ``M qdd + bias = Q`` (generalised
external forces; gravity along -y).

Springs (``walker.springs``, first step: swing = leg1, stance = leg2): ``delta = angle(second)
- angle(first)``, potential ``k (delta - r)^2 / 2``, generalised force
``-(k (delta - r) + c d(delta)/dt) d(delta)/dq``; a knee spring (``knee.spring``) the same on
each knee's angle ``delta = shank - thigh``.
"""

from __future__ import annotations

import numpy as np


def coordinate_names(data) -> tuple[str, ...]:
    """Floating coordinate names of the walker of ``data`` (a WalkerData)."""
    segs = ("thigh", "shank") if data.structure.knee else (None,)
    return ("hip_x", "hip_y") + tuple(f"{leg}_{s}_angle" if s else f"{leg}_angle"
                                      for leg in ("leg1", "leg2") for s in segs)


def _leg_angle_rows(data) -> dict[str, np.ndarray]:
    """Weight rows of the link angles a spring or the torso sees: ``swing`` = leg1's (upper)
    link, ``stance`` = leg2's, ``torso`` = their mean."""
    names = coordinate_names(data)
    n = len(names)
    up = [names.index("leg1_thigh_angle" if data.structure.knee else "leg1_angle"),
          names.index("leg2_thigh_angle" if data.structure.knee else "leg2_angle")]
    rows = {}
    for role, k in zip(("swing", "stance"), up):
        rows[role] = np.zeros(n)
        rows[role][k] = 1.0
    rows["torso"] = (rows["swing"] + rows["stance"]) / 2
    return rows


def _bodies(data):
    """(mass, inertia, link-angle weights, [(weights, length, offset)]) per body."""
    s = data.structure
    p = dict(zip(s.param_names, data.params))
    names = coordinate_names(data)
    n = len(names)

    def unit(k):
        w = np.zeros(n)
        w[k] = 1.0
        return w

    out = [(p["M_hip"], 0.0, np.zeros(n), [])] if s.hip_mass else []
    tags = ("sw_", "st_") if s.asymmetric else ("", "")
    for leg, tag in zip(("leg1", "leg2"), tags):
        for b in s.bodies:
            if b.massless:
                continue
            m, d = p[f"m_{tag}{b.name}"], p[f"d_{tag}{b.name}"]
            inertia = p.get(f"I_{tag}{b.name}", 0.0)
            e = p.get(f"e_{tag}{b.name}", 0.0)
            if b.link == "leg":
                link = unit(names.index(f"{leg}_angle"))
                chain = [(link, d, 0.0)]
            elif b.link == "thigh":
                link = unit(names.index(f"{leg}_thigh_angle"))
                chain = [(link, d, 0.0)]
            else:  # shank: hip -> knee along the thigh, then along the shank
                lt = p["L_thigh"]
                link = unit(names.index(f"{leg}_shank_angle"))
                chain = [(unit(names.index(f"{leg}_thigh_angle")), lt, 0.0), (link, d - lt, 0.0)]
            if e:
                chain.append((link, e, np.pi / 2))
            out.append((m, inertia, link, chain))
    torso = _leg_angle_rows(data)["torso"]
    for b in s.torso:
        d, e = p[f"d_torso_{b.name}"], p.get(f"e_torso_{b.name}", 0.0)
        chain = [(torso, -d, 0.0)] + ([(torso, e, np.pi / 2)] if e else [])
        out.append((p[f"m_torso_{b.name}"], p.get(f"I_torso_{b.name}", 0.0), torso, chain))
    return out


def mass_matrix_and_bias(data, q, dq):
    """``M(q)`` (n, n) [kg, kg m, kg m^2] and ``bias(q, dq) = C dq + G`` (n,) [N, N m]
    (gravity and inertia only: the springs are :func:`spring_force`)."""
    q, dq = np.asarray(q, float), np.asarray(dq, float)
    n = q.size
    g = dict(zip(data.structure.param_names, data.params))["g"]
    M = np.zeros((n, n))
    bias = np.zeros(n)
    for m, inertia, link, chain in _bodies(data):
        J = np.zeros((2, n))
        J[0, 0] = J[1, 1] = 1.0
        acc = np.zeros(2)  # Jdot dq
        for w, length, off in chain:
            a = w @ q + off
            J += length * np.outer([np.cos(a), np.sin(a)], w)
            acc += length * np.array([-np.sin(a), np.cos(a)]) * (w @ dq) ** 2
        M += m * J.T @ J
        bias += m * J.T @ (acc + np.array([0.0, g]))
        M += inertia * np.outer(link, link)
    return M, bias


def potential(data, q) -> float:
    """Gravitational potential ``sum m g y`` plus the springs' ``k (delta - r)^2 / 2`` [J]."""
    q = np.asarray(q, float)
    g = dict(zip(data.structure.param_names, data.params))["g"]
    V = 0.0
    for m, _, _, chain in _bodies(data):
        y = q[1] + sum(-length * np.cos(w @ q + off) for w, length, off in chain)
        V += m * g * y
    for k, r, _, row in _springs(data):
        V += k * (row @ q - r) ** 2 / 2
    return V


def _springs(data):
    """(k, r, c, row of delta over q) per spring."""
    s = data.structure
    p = dict(zip(s.param_names, data.params))
    rows = _leg_angle_rows(data)
    out = [(p[f"k_s{i}"], p[f"r_s{i}"], p[f"c_s{i}"], rows[second] - rows[first])
           for i, (first, second) in enumerate(s.springs)]
    if "k_knee" in p:  # a spring-damper at each knee on its angle shank - thigh
        names = coordinate_names(data)
        for leg in ("leg1", "leg2"):
            row = np.zeros(len(names))
            row[names.index(f"{leg}_shank_angle")] = 1.0
            row[names.index(f"{leg}_thigh_angle")] = -1.0
            out.append((p["k_knee"], p["r_knee"], p["c_knee"], row))
    return out


def spring_force(data, q, dq):
    """Generalised force of the springs and dampers (n,) [N, N m]: ``M qdd + bias = Q``."""
    q, dq = np.asarray(q, float), np.asarray(dq, float)
    Q = np.zeros(q.size)
    for k, r, c, row in _springs(data):
        Q -= (k * (row @ q - r) + c * (row @ dq)) * row
    return Q
