"""Independent numpy floating walker: mass matrix and bias from the bodies of a WalkerData.

Written directly from Newton's laws for planar point masses and rods, sharing no code with
``walkerlab.models`` (neither the symbolic generator nor the multibody export): every body
(the hip point mass, every point mass and rod of both legs) is kept separate, with its own
position Jacobian, so the link combination by the parallel-axis theorem in the export is
checked too.

Floating coordinates ``q = (hip_x, hip_y, psi...)`` [m, m, rad]: the hip position (y up) and
the absolute angle from the vertical of every link, leg1 first (straight leg: ``leg1_angle``;
kneed: ``leg1_thigh_angle, leg1_shank_angle``), then leg2.  A point at distance ``s`` along
a link of angle ``psi`` lies at ``joint + s e(psi)``, ``e(psi) = (sin psi, -cos psi)``.

For a body of mass ``m`` at ``p(q)``: ``v = J qd``, ``a = J qdd + sum_k l_k e'(psi_k)' psid_k^2``
with ``e'(psi) = (cos psi, sin psi)`` and ``d/dt e'(psi) = -e(psi) psid``.  Then
``M = sum m J^T J + sum I a_k a_k^T`` and ``bias = sum m J^T (Jdot qd) + sum m J^T (0, g)``
so that ``M qdd + bias = Q`` (generalised external forces; gravity along -y).
"""

from __future__ import annotations

import numpy as np


def coordinate_names(data) -> tuple[str, ...]:
    """Floating coordinate names of the walker of ``data`` (a WalkerData)."""
    segs = ("thigh", "shank") if data.structure.knee else (None,)
    return ("hip_x", "hip_y") + tuple(f"{leg}_{s}_angle" if s else f"{leg}_angle"
                                      for leg in ("leg1", "leg2") for s in segs)


def _bodies(data):
    """(mass, inertia, [(coordinate index, length along that link)]) per body."""
    s = data.structure
    p = dict(zip(s.param_names, data.params))
    names = coordinate_names(data)
    out = [(p["M_hip"], 0.0, [])] if s.hip_mass else []
    for leg in ("leg1", "leg2"):
        for b in s.bodies:
            if b.massless:
                continue
            m, d = p[f"m_{b.name}"], p[f"d_{b.name}"]
            inertia = p.get(f"I_{b.name}", 0.0)
            if b.link == "leg":
                chain = [(names.index(f"{leg}_angle"), d)]
            elif b.link == "thigh":
                chain = [(names.index(f"{leg}_thigh_angle"), d)]
            else:  # shank: hip -> knee along the thigh, then along the shank
                lt = p["L_thigh"]
                chain = [(names.index(f"{leg}_thigh_angle"), lt),
                         (names.index(f"{leg}_shank_angle"), d - lt)]
            out.append((m, inertia, chain))
    return out


def mass_matrix_and_bias(data, q, dq):
    """``M(q)`` (n, n) [kg, kg m, kg m^2] and ``bias(q, dq) = C dq + G`` (n,) [N, N m]."""
    q, dq = np.asarray(q, float), np.asarray(dq, float)
    n = q.size
    g = dict(zip(data.structure.param_names, data.params))["g"]
    M = np.zeros((n, n))
    bias = np.zeros(n)
    for m, inertia, chain in _bodies(data):
        J = np.zeros((2, n))
        J[0, 0] = J[1, 1] = 1.0
        acc = np.zeros(2)  # Jdot dq
        for k, length in chain:
            psi = q[k]
            J[:, k] += length * np.array([np.cos(psi), np.sin(psi)])
            acc += length * np.array([-np.sin(psi), np.cos(psi)]) * dq[k] ** 2
        M += m * J.T @ J
        bias += m * J.T @ (acc + np.array([0.0, g]))
        if inertia and chain:
            k = chain[-1][0]
            M[k, k] += inertia
    return M, bias
