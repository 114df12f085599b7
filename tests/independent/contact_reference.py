"""Pure-numpy reference implementation of the contact walker's equations of motion.

Slow (~tens of µs per call) but written directly from the Lagrangian, independently of the
generated kernels (:mod:`walkerlab.models.contact.generated`); tests check the two agree.  Test-only
(it moved here from ``walkerlab/models/contact/reference.py`` when the hand-written numba kernel
retired, issue 17).

Lagrangian of the floating walker, q = [hip_x, hip_y, theta1, theta2] (SI):
``T = 1/2 MH |v_hip|^2 + sum_i 1/2 m |v_hip + b (cos th_i, sin th_i) w_i|^2``,
``V = g (MH y_hip + sum_i m (y_hip - b cos th_i))``.
Contact forces F_i (world frame, [N]) act at foot_i = hip + L (sin th_i, -cos th_i) and enter
as generalized forces J_i^T F_i.
"""

from __future__ import annotations

import numpy as np

from walkerlab.models.contact.laws import coulomb_friction_coefficient, impact_normal_force

__all__ = ["contact_forces_ref", "mass_matrix_ref", "rhs_ref"]


def mass_matrix_ref(q, L, m, MH, a):
    """Mass matrix M(q) (4, 4) [kg, kg m, kg m^2]."""
    b = L - a
    _, _, t1, t2 = q
    M = np.diag([MH + 2 * m, MH + 2 * m, m * b * b, m * b * b]).astype(float)
    for j, th in ((2, t1), (3, t2)):
        M[0, j] = M[j, 0] = m * b * np.cos(th)
        M[1, j] = M[j, 1] = m * b * np.sin(th)
    return M


def contact_forces_ref(x, L, phi, params, lanes, half_width, continuous):
    """World-frame contact force on each foot, (2, 2) [N] (row i = foot i+1).

    ``params`` is a :class:`~walkerlab.models.contact.laws.ContactParamsSI`; ``lanes`` = (c1, c2)
    patch-centre arrays [m].
    """
    n = np.array([np.sin(phi), np.cos(phi)])
    t = np.array([np.cos(phi), -np.sin(phi)])
    F = np.zeros((2, 2))
    for i in range(2):
        th, w = x[2 + i], x[6 + i]
        p = x[:2] + L * np.array([np.sin(th), -np.cos(th)])
        v = x[4:6] + L * w * np.array([np.cos(th), np.sin(th)])
        delta = -p @ n
        s = p @ t
        on_ground = continuous or np.any(np.abs(s - np.asarray(lanes[i])) <= half_width)
        if delta <= 0 or not on_ground:
            continue
        fn = float(impact_normal_force(delta, -v @ n, params.k, params.e, params.cmax, params.dmax))
        mu = float(coulomb_friction_coefficient(v @ t, params.mu_s, params.mu_d, params.v_s,
                                                params.v_d))
        F[i] = fn * n + mu * fn * t
    return F


def rhs_ref(x, L, m, MH, a, g, phi, params, lanes, half_width, continuous):
    """dx/dt (8,) of the floating walker; x = [q, qdot] (SI)."""
    b = L - a
    q, qd = x[:4], x[4:]
    M = mass_matrix_ref(q, L, m, MH, a)
    Q = np.array([0.0, -(MH + 2 * m) * g, -m * g * b * np.sin(q[2]), -m * g * b * np.sin(q[3])])
    # centripetal terms: d/dt(M) qd - dT/dq
    for th, w in ((q[2], qd[2]), (q[3], qd[3])):
        Q[0] += m * b * np.sin(th) * w * w
        Q[1] -= m * b * np.cos(th) * w * w
    F = contact_forces_ref(x, L, phi, params, lanes, half_width, continuous)
    for i in range(2):
        th = q[2 + i]
        J = np.zeros((2, 4))
        J[0, 0] = J[1, 1] = 1.0
        J[0, 2 + i] = L * np.cos(th)
        J[1, 2 + i] = L * np.sin(th)
        Q += J.T @ F[i]
    return np.concatenate([qd, np.linalg.solve(M, Q)])
