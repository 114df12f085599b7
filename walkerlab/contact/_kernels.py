"""Numba-compiled kernels of the floating compass walker with compliant feet.

Internal module.  Everything is SI.  The packed parameter vector ``P`` (float64, (NPAR,)) is
read only through the named index constants below (``P[I_PHI]``, never a bare number):

======  ======================  =====
name    meaning                 unit
======  ======================  =====
I_L     L leg length            m
I_M     m leg mass              kg
I_MH    MH hip mass             kg
I_B     b hip-to-leg-mass       m
I_G     g gravity               m/s^2
I_PHI   phi slope               rad
I_K     k stiffness             N/m^e
I_E     e exponent              -
I_CMAX  cmax max damping        N s/m
I_DMAX  dmax                    m
I_MUS   mu_s                    -
I_MUD   mu_d                    -
I_VS    v_s                     m/s
I_VD    v_d                     m/s
I_HW    patch half width        m
I_CONT  continuous ground (1/0) -
======  ======================  =====

``c1``/``c2`` are the along-slope patch centres [m] of the lanes of leg1/leg2.
State ``x = [hip_x, hip_y, theta1, theta2, vhip_x, vhip_y, dtheta1, dtheta2]``.
The pure-numpy reference of the same equations is :mod:`walkerlab.contact.reference`.
"""

from __future__ import annotations

import numpy as np

from walkerlab.usercache import use_for_numba

use_for_numba()  # cache=True below: numba's cache in the user cache, not in the package

from numba import njit  # noqa: E402

# Named indices into ``P`` (module-level ints are compile-time constants under numba).
I_L, I_M, I_MH, I_B, I_G, I_PHI = 0, 1, 2, 3, 4, 5
I_K, I_E, I_CMAX, I_DMAX = 6, 7, 8, 9
I_MUS, I_MUD, I_VS, I_VD = 10, 11, 12, 13
I_HW, I_CONT = 14, 15
NPAR = 16

# Named indices into the state x (8,) of the floating walker.
X_HIP_X, X_HIP_Y, X_TH1, X_TH2, X_VHIP_X, X_VHIP_Y, X_W1, X_W2 = range(8)
X_TH = (X_TH1, X_TH2)


@njit(cache=True)
def step(x, x0, h0, x1, h1):
    """Scalar ADAMS STEP and its derivative d/dx (see laws.adams_step)."""
    if x <= x0:
        return h0, 0.0
    if x >= x1:
        return h1, 0.0
    w = x1 - x0
    s = (x - x0) / w
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s), 6.0 * (h1 - h0) * s * (1.0 - s) / w


@njit(cache=True)
def normal_force(delta, ddot, k, e, cmax, dmax):
    """IMPACT force and its partials (F [N], dF/ddelta [N/m], dF/dddot [N s/m])."""
    if delta <= 0.0:
        return 0.0, 0.0, 0.0
    c, dc = step(delta, 0.0, 0.0, dmax, cmax)
    ke = k * delta ** e
    f = ke + c * ddot
    if f <= 0.0:
        return 0.0, 0.0, 0.0
    return f, e * ke / delta + dc * ddot, c


@njit(cache=True)
def friction_mu(v, mus, mud, vs, vd):
    """Signed ADAMS Coulomb coefficient and d(mu)/dv [s/m] (see laws)."""
    av = abs(v)
    if av < vs:
        return step(v, -vs, mus, vs, -mus)
    sg = 1.0 if v > 0.0 else -1.0
    mu, dmu = step(av, vs, mus, vd, mud)
    return -sg * mu, -dmu  # d/dv(-sg*h(|v|)) = -sg*h'*sg = -h'


@njit(cache=True)
def in_patch(s, centres, hw, continuous):
    """True when along-slope coordinate ``s`` [m] lies on ground of the lane."""
    if continuous:
        return True
    for j in range(centres.shape[0]):
        if abs(s - centres[j]) <= hw:
            return True
    return False


@njit(cache=True)
def foot_state(x, i, P):
    """Foot i (0/1) position and velocity: (px, py, vx, vy)."""
    L = P[I_L]
    th = x[X_TH1 + i]
    w = x[X_W1 + i]
    st, ct = np.sin(th), np.cos(th)
    return (x[X_HIP_X] + L * st, x[X_HIP_Y] - L * ct, x[X_VHIP_X] + L * ct * w,
            x[X_VHIP_Y] + L * st * w)


@njit(cache=True)
def foot_contact(x, i, P, centres):
    """Contact of foot i: (delta, ddot, v_t, s, Fn, Ff, dFn_dd, dFn_dddot, mu, dmu).

    delta [m] penetration (may be negative = height), ddot [m/s] penetration rate,
    v_t [m/s] down-slope slip velocity, s [m] along-slope position, Fn [N] normal force,
    Ff [N] friction force along t = (cos phi, -sin phi).
    """
    sp, cp = np.sin(P[I_PHI]), np.cos(P[I_PHI])
    px, py, vx, vy = foot_state(x, i, P)
    delta = -(px * sp + py * cp)
    ddot = -(vx * sp + vy * cp)
    vt = vx * cp - vy * sp
    s = px * cp - py * sp
    fn, dfd, dfdd, mu, dmu = 0.0, 0.0, 0.0, 0.0, 0.0
    if delta > 0.0 and in_patch(s, centres, P[I_HW], P[I_CONT] > 0.5):
        fn, dfd, dfdd = normal_force(delta, ddot, P[I_K], P[I_E], P[I_CMAX], P[I_DMAX])
        if fn > 0.0:
            mu, dmu = friction_mu(vt, P[I_MUS], P[I_MUD], P[I_VS], P[I_VD])
    return delta, ddot, vt, s, fn, mu * fn, dfd, dfdd, mu, dmu


@njit(cache=True)
def mass_blocks(th1, th2, P):
    """The one mass matrix of the floating walker, by blocks.

    ``M(q) = [[A I, B], [B^T, D I]]`` with ``A = MH + 2 m`` [kg], ``D = m b^2`` [kg m^2] and
    ``B = m b [[cos th1, cos th2], [sin th1, sin th2]]`` [kg m].  Returns (A, D, B00, B01,
    B10, B11).  :func:`mass_matrix` and :func:`msolve` are both built from it.
    """
    m, MH, b = P[I_M], P[I_MH], P[I_B]
    return (MH + 2.0 * m, m * b * b, m * b * np.cos(th1), m * b * np.cos(th2),
            m * b * np.sin(th1), m * b * np.sin(th2))


@njit(cache=True)
def msolve(th1, th2, P, r):
    """Solve M(q) a = r for the 4x4 mass matrix (:func:`mass_blocks`) by its block structure.

    ``r`` is (4,) or (4, n).  Schur complement ``S = A I - B B^T / D``.
    """
    A, D, B00, B01, B10, B11 = mass_blocks(th1, th2, P)
    S00 = A - (B00 * B00 + B01 * B01) / D
    S01 = -(B00 * B10 + B01 * B11) / D
    S11 = A - (B10 * B10 + B11 * B11) / D
    det = S00 * S11 - S01 * S01
    out = np.empty_like(r)
    r0 = r[0] - (B00 * r[2] + B01 * r[3]) / D
    r1 = r[1] - (B10 * r[2] + B11 * r[3]) / D
    a0 = (S11 * r0 - S01 * r1) / det
    a1 = (S00 * r1 - S01 * r0) / det
    out[0] = a0
    out[1] = a1
    out[2] = (r[2] - B00 * a0 - B10 * a1) / D
    out[3] = (r[3] - B01 * a0 - B11 * a1) / D
    return out


@njit(cache=True)
def gen_force(x, P, c1, c2, use1, use2):
    """Generalized force Q - c (4,): gravity, centripetal terms, contact of feet used."""
    L, m, MH, b, g, phi = P[I_L], P[I_M], P[I_MH], P[I_B], P[I_G], P[I_PHI]
    sp, cp = np.sin(phi), np.cos(phi)
    Q = np.zeros(4)
    Q[1] = -(MH + 2.0 * m) * g
    for i in range(2):
        th = x[X_TH1 + i]
        w = x[X_W1 + i]
        st, ct = np.sin(th), np.cos(th)
        Q[2 + i] = -m * g * b * st
        # minus centripetal term c(q, qd)
        Q[0] += m * b * st * w * w
        Q[1] -= m * b * ct * w * w
        if (i == 0 and use1) or (i == 1 and use2):
            cen = c1 if i == 0 else c2
            res = foot_contact(x, i, P, cen)
            fn, ff = res[4], res[5]
            if fn > 0.0:
                Fx = fn * sp + ff * cp
                Fy = fn * cp - ff * sp
                Q[0] += Fx
                Q[1] += Fy
                Q[2 + i] += L * (ct * Fx + st * Fy)
    return Q


@njit(cache=True)
def rhs(x, P, c1, c2):
    """Free-floating walker: dx/dt (8,)."""
    Q = gen_force(x, P, c1, c2, True, True)
    qdd = msolve(x[X_TH1], x[X_TH2], P, Q)
    out = np.empty(8)
    out[:4] = x[4:]
    out[4:] = qdd
    return out


#: Data vector handed to the compiled integrators (``_cyrk``, ``_lsoda``) through a C
#: pointer: ``[n1, n2, P (NPAR), c1 (n1), c2 (n2), nfev]``; these are the offsets of the
#: lane sizes and of P.
D_N1, D_N2, D_P = 0, 1, 2


def pack(P: np.ndarray, c1: np.ndarray, c2: np.ndarray) -> np.ndarray:
    """Data vector ``[n1, n2, P, c1, c2, nfev=0]`` (float64) for :func:`rhs_packed`."""
    return np.concatenate([[len(c1), len(c2)], P, c1, c2, [0.0]]).astype(np.float64)


@njit(cache=True)
def packed_size(p):
    """Length of the data vector (see :func:`pack`) whose lane sizes are ``p[D_N1]``,
    ``p[D_N2]`` (``p`` may be a raw pointer in a cfunc)."""
    return D_P + NPAR + int(p[D_N1]) + int(p[D_N2]) + 1


@njit(cache=True)
def rhs_packed(y, d, dy):
    """:func:`rhs` of the state ``y`` (8,) with the lanes and parameters unpacked from the
    data vector ``d`` (see :func:`pack`), written into ``dy`` (8,); counts the call in
    ``d[-1]``."""
    a1 = D_P + NPAR  # start of c1
    a2 = a1 + int(d[D_N1])  # start of c2
    r = rhs(y, d[D_P:a1], d[a1:a2], d[a2:d.size - 1])
    for i in range(8):
        dy[i] = r[i]
    d[d.size - 1] += 1.0


@njit(cache=True)
def jac(x, P, c1, c2):
    """Analytic Jacobian d(rhs)/dx (8, 8) of the free-floating walker.

    Patch membership is treated as locally constant (the patch edge is a discontinuity).
    """
    return jac_flag(x, P, c1, c2, True)


@njit(cache=True)
def rhs_flag(x, P, c1, c2, use_contact):
    """:func:`rhs` with the contact forces switched on/off."""
    Q = gen_force(x, P, c1, c2, use_contact, use_contact)
    out = np.empty(8)
    out[:4] = x[4:]
    out[4:] = msolve(x[X_TH1], x[X_TH2], P, Q)
    return out


@njit(cache=True)
def jac_flag(x, P, c1, c2, use_contact):
    """:func:`jac` with the contact forces switched on/off."""
    L, m, b, g, phi = P[I_L], P[I_M], P[I_B], P[I_G], P[I_PHI]
    sp, cp = np.sin(phi), np.cos(phi)
    Q = gen_force(x, P, c1, c2, use_contact, use_contact)
    qdd = msolve(x[X_TH1], x[X_TH2], P, Q)
    dQq = np.zeros((4, 4))
    dQv = np.zeros((4, 4))
    for i in range(2):
        j = 2 + i
        th = x[j]
        w = x[X_W1 + i]
        st, ct = np.sin(th), np.cos(th)
        # gravity
        dQq[j, j] += -m * g * b * ct
        # -c(q, qd): Q0 += m b st w^2, Q1 -= m b ct w^2
        dQq[0, j] += m * b * ct * w * w
        dQq[1, j] += m * b * st * w * w
        dQv[0, j] += 2.0 * m * b * st * w
        dQv[1, j] += -2.0 * m * b * ct * w
        # - dM/dth_j * qdd  (dM/dth_j: (0,j),(j,0) = -m b st ; (1,j),(j,1) = m b ct)
        dQq[0, j] -= -m * b * st * qdd[j]
        dQq[1, j] -= m * b * ct * qdd[j]
        dQq[j, j] -= -m * b * st * qdd[0] + m * b * ct * qdd[1]
        # contact
        if not use_contact:
            continue
        cen = c1 if i == 0 else c2
        delta, ddot, vt, s, fn, ff, dfd, dfdd, mu, dmu = foot_contact(x, i, P, cen)
        if fn <= 0.0:
            continue
        # foot Jacobian columns: d p/d(hx,hy,th) = (1,0,L ct), (0,1,L st)
        # dv/dth = (-L st w, L ct w); dv/dqd same as dp/dq
        # derivatives of delta, ddot, vt w.r.t. (q, qd) -- only hx, hy, th_j, vx, vy, w_j
        # n = (sp, cp), t = (cp, -sp)
        Jx = np.zeros(4)
        Jy = np.zeros(4)
        Jx[0] = 1.0
        Jy[1] = 1.0
        Jx[j] = L * ct
        Jy[j] = L * st
        Vx = np.zeros(4)
        Vy = np.zeros(4)
        Vx[j] = -L * st * w
        Vy[j] = L * ct * w
        d_delta_q = -(sp * Jx + cp * Jy)
        d_ddot_q = -(sp * Vx + cp * Vy)
        d_ddot_v = d_delta_q
        d_vt_q = cp * Vx - sp * Vy
        d_vt_v = cp * Jx - sp * Jy
        dfn_q = dfd * d_delta_q + dfdd * d_ddot_q
        dfn_v = dfdd * d_ddot_v
        dff_q = mu * dfn_q + fn * dmu * d_vt_q
        dff_v = mu * dfn_v + fn * dmu * d_vt_v
        dFx_q = sp * dfn_q + cp * dff_q
        dFy_q = cp * dfn_q - sp * dff_q
        dFx_v = sp * dfn_v + cp * dff_v
        dFy_v = cp * dfn_v - sp * dff_v
        Fx = fn * sp + ff * cp
        Fy = fn * cp - ff * sp
        for k in range(4):
            dQq[0, k] += dFx_q[k]
            dQq[1, k] += dFy_q[k]
            dQq[j, k] += L * (ct * dFx_q[k] + st * dFy_q[k])
            dQv[0, k] += dFx_v[k]
            dQv[1, k] += dFy_v[k]
            dQv[j, k] += L * (ct * dFx_v[k] + st * dFy_v[k])
        dQq[j, j] += L * (-st * Fx + ct * Fy)
    out = np.zeros((8, 8))
    for k in range(4):
        out[k, 4 + k] = 1.0
    out[4:, :4] = msolve(x[X_TH1], x[X_TH2], P, dQq)
    out[4:, 4:] = msolve(x[X_TH1], x[X_TH2], P, dQv)
    return out


@njit(cache=True)
def rhs_pinned(z, P, c1, c2, pfx, pfy):
    """Reduced dynamics with foot 2 pinned at (pfx, pfy): z = [th1, th2, w1, w2] -> dz/dt."""
    L = P[I_L]
    th1, th2, w1, w2 = z[0], z[1], z[2], z[3]
    s2, c2_ = np.sin(th2), np.cos(th2)
    x = np.empty(8)
    x[0] = pfx - L * s2
    x[1] = pfy + L * c2_
    x[2] = th1
    x[3] = th2
    x[4] = -L * c2_ * w2
    x[5] = -L * s2 * w2
    x[6] = w1
    x[7] = w2
    Q = gen_force(x, P, c1, c2, True, False)
    # q = Phi(th), qd = Jp thd, qdd = Jp thdd + gam, gam = (L s2 w2^2, -L c2 w2^2, 0, 0)
    gam = np.zeros(4)
    gam[0] = L * s2 * w2 * w2
    gam[1] = -L * c2_ * w2 * w2
    Jp = np.zeros((4, 2))
    Jp[0, 1] = -L * c2_
    Jp[1, 1] = -L * s2
    Jp[2, 0] = 1.0
    Jp[3, 1] = 1.0
    M = mass_matrix(x[X_TH1], x[X_TH2], P)
    r = Jp.T @ (Q - M @ gam)
    Mr = Jp.T @ M @ Jp
    det = Mr[0, 0] * Mr[1, 1] - Mr[0, 1] * Mr[1, 0]
    out = np.empty(4)
    out[0] = w1
    out[1] = w2
    out[2] = (Mr[1, 1] * r[0] - Mr[0, 1] * r[1]) / det
    out[3] = (Mr[0, 0] * r[1] - Mr[1, 0] * r[0]) / det
    return out


@njit(cache=True)
def mass_matrix(th1, th2, P):
    """4x4 mass matrix M(q) [kg, kg m, kg m^2] from :func:`mass_blocks`."""
    A, D, B00, B01, B10, B11 = mass_blocks(th1, th2, P)
    M = np.zeros((4, 4))
    M[0, 0] = A
    M[1, 1] = A
    M[2, 2] = D
    M[3, 3] = D
    M[0, 2] = M[2, 0] = B00
    M[0, 3] = M[3, 0] = B01
    M[1, 2] = M[2, 1] = B10
    M[1, 3] = M[3, 1] = B11
    return M


@njit(cache=True)
def contact_table(X, P, c1, c2):
    """Per-sample contact quantities of both feet.

    X: (n, 8) states.  Returns (n, 2, 8): [delta, ddot, vt, s, Fn, Ff, power, on_ground] per
    foot; power = F . v_foot [W]; on_ground = 1 where the lane has ground under the foot.
    """
    n = X.shape[0]
    out = np.zeros((n, 2, 8))
    sp, cp = np.sin(P[I_PHI]), np.cos(P[I_PHI])
    for r in range(n):
        x = X[r]
        for i in range(2):
            cen = c1 if i == 0 else c2
            res = foot_contact(x, i, P, cen)
            px, py, vx, vy = foot_state(x, i, P)
            fn, ff = res[4], res[5]
            Fx = fn * sp + ff * cp
            Fy = fn * cp - ff * sp
            for k in range(6):
                out[r, i, k] = res[k]
            out[r, i, 6] = Fx * vx + Fy * vy
            out[r, i, 7] = 1.0 if in_patch(res[3], cen, P[I_HW], P[I_CONT] > 0.5) else 0.0
    return out


@njit(cache=True)
def hip_height(x, P):
    """Hip height above the ground line, hip . n [m]: the one fall test compares it with a
    threshold (:meth:`walkerlab.contact.model.ContactWalker.fall_margin`)."""
    return x[X_HIP_X] * np.sin(P[I_PHI]) + x[X_HIP_Y] * np.cos(P[I_PHI])


@njit(cache=True)
def hip_heights(X, P):
    """:func:`hip_height` of each row of X (n, 8) -> (n,)."""
    out = np.empty(X.shape[0])
    for r in range(X.shape[0]):
        out[r] = hip_height(X[r], P)
    return out
