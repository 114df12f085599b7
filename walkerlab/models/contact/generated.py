"""The compliant-contact walker's compiled kernels, generated per walker structure.

The generated module is the floating view of the walker (:mod:`walkerlab.codegen.floating`:
``dyn``, ``dyn_jac``, ``feet``, ``feet_jac``, numba) followed by :data:`ASSEMBLY`, the
walker-independent code that turns contact geometry into forces with the laws of
:mod:`walkerlab.models.contact._kernels` (IMPACT normal force, ADAMS Coulomb friction, patch
membership) and solves ``M qdd = Q - h`` (no mechanics is written by hand here: every
position, velocity, Jacobian, mass matrix and bias comes from the generator).  It is cached
on disk next to the rigid models' code (:func:`walkerlab.codegen.cache.cache_dir`), keyed on
the structure, the generators and this file.

Contact parameter vector ``PC`` (float64, (NPC,)), read through named indices:

========  ========================================  ==============
name      meaning                                   unit
========  ========================================  ==============
I_PHI     slope phi                                 rad
I_K       IMPACT stiffness k                        N/m^e
I_E       IMPACT exponent e                         -
I_CMAX    IMPACT max damping                        N s/m
I_DMAX    penetration at max damping                m
I_MUS     static friction coefficient               -
I_MUD     dynamic friction coefficient              -
I_VS      stiction transition velocity              m/s
I_VD      friction transition velocity              m/s
I_HW      patch half width                          m
I_CONT    continuous ground (1/0)                   -
I_KK      knee-stop stiffness                       N m/rad^e
I_KE      knee-stop exponent                        -
I_KC      knee-stop max damping                     N m s/rad
I_KD      knee-stop penetration at max damping      rad
I_KL      knee latch on (1/0)                       -
I_KF      latch release height of the foot          m
I_KA      latch capture angle                       rad
========  ========================================  ==============

Knee latch (``contact.knee_stop.latch``): while a leg's foot is on (or within the release
height I_KF of) the ground, its knee stop acts in both directions (flexion too, with the
same IMPACT law mirrored), weighted by ``STEP(delta, -I_KF, 0, 0, 1)`` of that foot's
penetration delta (so it holds through the heel strike of the other leg, as the rigid
model's locked knee does, and releases as the foot rises) and by
``STEP(ext, -I_KA, 0, -I_KA / 2, 1)`` of the knee's extension (a latch captures a knee only
near straight: a bent knee whose foot touches down is not snapped straight).  A pinned
stance foot (``rhs_pinned``) counts as on the ground.  The analytic Jacobian holds the
weight constant (left out: its dependence on the foot's height; Newton directions only).

Packed data vector of the compiled integrators (``_cyrk``, ``numbalsoda_backend``):
``[n1, n2, PC (NPC), p (NP), c1 (n1), c2 (n2), nfev]`` (``p`` the floating view's parameter
vector, :func:`walkerlab.codegen.floating.param_names`; ``c1``/``c2`` the kernel lanes of
leg1's / leg2's patches: their centres [m], their heights [m] along the outward normal and the
largest height [m], ``n = 2 patches + 1``;
:meth:`walkerlab.models.contact.model.ContactWalker.kernel_lanes`).  A foot's penetration is
measured below the top of the patch under it (all heights 0: the flat ground, bit for bit).

Contact points: ``NF`` of them, named ``CONTACTS`` (``('leg1', 'leg2')`` for point and arc
feet, ``('leg1_heel', 'leg1_toe', 'leg2_heel', 'leg2_toe')`` for flat feet), each with the
IMPACT and Coulomb laws on its leg's lane (``POINT_LEG``); ``PIN`` is leg2's first point
(the point a pinned stance foot holds).

Generated functions (``x = [q, dq]`` (NX,), see :mod:`walkerlab.codegen.floating` for ``q``):

=======================================  =================================================
``rhs(x, PC, p, c1, c2)``                dx/dt (NX,)
``jac(x, PC, p, c1, c2)``                d rhs / dx (NX, NX), patch membership locally constant
``rhs_pinned(z, PC, p, c1, c2, foot2)``  leg2's point PIN held at ``foot2``:
                                         ``z = [link angles, their rates]`` -> dz/dt
``pinned_to_full(z, p, foot2)``          full state (NX,) of a pinned state
``contact_table(X, PC, p, c1, c2)``      (n, NF, 8) per point: penetration, its rate, slip
                                         velocity, s, Fn, Ff, power, on_ground
``knee_table(X, PC, p)``                 (n, 2, 4) per knee: extension, its rate, stop torque,
                                         power
``rhs_packed(y, d, dy)``                 rhs from the packed data vector, counts calls
``powered_rhs(x, PC, p, c1, c2, ...)``   a powered walker's rhs and ledger powers (hip
                                         torque, push-off force; compiled actuation hook)
``build_cyrk()``, ``build_lsoda(sig)``   addresses of cfuncs of ``rhs_packed``
=======================================  =================================================
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.models.contact.rhs_lines import rhs_source
from walkerlab.walker.description import Structure

__all__ = ["ASSEMBLY", "NPC", "contact_module", "contact_source", "rhs_source"]

#: The files whose text the generated module's source is made of (its cache key).
_SOURCES = (Path(__file__), Path(__file__).with_name("powered_source.py"),
            Path(__file__).with_name("rhs_lines.py"),
            Path(__file__).parents[2] / "codegen" / "torque_law.py")

#: Number of contact parameters (see the table above).
NPC = 18

ASSEMBLY = '''
# ---------------------------------------------------------------- contact assembly
# (walkerlab.models.contact.generated.ASSEMBLY: walker-independent; laws from contact._kernels)
from math import sin as _sin, cos as _cos
from walkerlab.models.contact._kernels import (normal_force, friction_mu, patch_height,
                                               step, ground_line)

I_PHI, I_K, I_E, I_CMAX, I_DMAX = 0, 1, 2, 3, 4
I_MUS, I_MUD, I_VS, I_VD, I_HW, I_CONT = 5, 6, 7, 8, 9, 10
I_KK, I_KE, I_KC, I_KD, I_KL, I_KF, I_KA = 11, 12, 13, 14, 15, 16, 17
NPC = 18
NX = 2 * NQ
D_N1, D_N2, D_PC = 0, 1, 2
D_P = D_PC + NPC
# contact points: NF of them (generated feet order), POINT_LEG[i] = leg of point i (its
# lane: c1 for leg1, c2 for leg2), PIN = leg2's first point (the pinned stance foot)


@njit(cache=True)
def _chol(M):
    """Lower Cholesky factor of the SPD matrix M (NQ, NQ)."""
    n = M.shape[0]
    L = np.zeros((n, n))
    for j in range(n):
        s = M[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        d = np.sqrt(s)
        L[j, j] = d
        for i in range(j + 1, n):
            s = M[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / d
    return L


@njit(cache=True)
def _chol_solve(L, B):
    """Solve (L L^T) X = B, B (n, m), in place of a copy."""
    n, m = B.shape
    X = B.copy()
    for c in range(m):
        for i in range(n):
            s = X[i, c]
            for k in range(i):
                s -= L[i, k] * X[k, c]
            X[i, c] = s / L[i, i]
        for i in range(n - 1, -1, -1):
            s = X[i, c]
            for k in range(i + 1, n):
                s -= L[k, i] * X[k, c]
            X[i, c] = s / L[i, i]
    return X


@njit(cache=True)
def _point(px, py, vx, vy, sp, cp, PC, cen):
    """Contact of a point at (px, py) [m] whose material velocity is (vx, vy) [m/s] on the
    lane ``cen``, the slope's (sin, cos) = (sp, cp): (delta, ddot, vt, s, Fn, Ff, dFn/ddelta,
    dFn/dddot, mu, dmu/dvt, nx, ny), (nx, ny) the ground's outward normal there (the
    friction acts along (ny, -nx)).  The one contact kernel of the right-hand side, the
    Jacobian, the pinned dynamics and the tables (one compile).  On a polyline ground
    (``PC[I_CONT] == 2``: ``cen`` its vertices, :func:`ground_line`) the penetration and
    normal are the nearest segment's."""
    if PC[I_CONT] > 1.5:
        return _on_line(px, py, vx, vy, sp, cp, PC, cen)
    delta = -(px * sp + py * cp)
    ddot = -(vx * sp + vy * cp)
    vt = vx * cp - vy * sp
    s = px * cp - py * sp
    fn, dfd, dfdd, mu, dmu = 0.0, 0.0, 0.0, 0.0, 0.0
    # a patch at height hp: penetration below its top (cen[-1], the lane's highest patch,
    # skips the lookup for a foot above every patch; all heights 0: the flat ground)
    hp = patch_height(s, cen, PC[I_HW], PC[I_CONT] > 0.5) if delta + cen[-1] > 0.0 else np.nan
    if hp == hp:
        delta += hp
    if delta > 0.0 and hp == hp:
        fn, dfd, dfdd = normal_force(delta, ddot, PC[I_K], PC[I_E], PC[I_CMAX], PC[I_DMAX])
        if fn > 0.0:
            mu, dmu = friction_mu(vt, PC[I_MUS], PC[I_MUD], PC[I_VS], PC[I_VD])
    return delta, ddot, vt, s, fn, mu * fn, dfd, dfdd, mu, dmu, sp, cp


@njit(cache=True)
def _on_line(px, py, vx, vy, sp, cp, PC, line):
    """:func:`_point` on the polyline ground ``line`` (stairs' treads and risers): the
    IMPACT and Coulomb laws on the penetration into the nearest segment, along its normal."""
    delta, nx, ny = ground_line(px, py, line)
    ddot = -(vx * nx + vy * ny)
    vt = vx * ny - vy * nx
    s = px * cp - py * sp
    fn, dfd, dfdd, mu, dmu = 0.0, 0.0, 0.0, 0.0, 0.0
    if delta > 0.0:
        fn, dfd, dfdd = normal_force(delta, ddot, PC[I_K], PC[I_E], PC[I_CMAX], PC[I_DMAX])
        if fn > 0.0:
            mu, dmu = friction_mu(vt, PC[I_MUS], PC[I_MUD], PC[I_VS], PC[I_VD])
    return delta, ddot, vt, s, fn, mu * fn, dfd, dfdd, mu, dmu, nx, ny


@njit(cache=True)
def _latch_weight(delta, ext, PC):
    """Latch engagement in [0, 1] of a knee at extension ext [rad] (< 0 flexed) whose foot
    has the penetration delta [m] (< 0: above the ground)."""
    if PC[I_KL] < 0.5:
        return 0.0
    return (step(delta, -PC[I_KF], 0.0, 0.0, 1.0)[0]
            * step(ext, -PC[I_KA], 0.0, -0.5 * PC[I_KA], 1.0)[0])


@njit(cache=True)
def _knee(x, k, PC, delta):
    """Knee stop (and latch, its foot at penetration delta [m]) of knee k: (extension,
    rate, torque, dT/dext, dT/drate)."""
    t, s = 2 + 2 * k, 3 + 2 * k
    ext = x[s] - x[t]
    rate = x[NQ + s] - x[NQ + t]
    if ext < 0.0:
        w = _latch_weight(delta, ext, PC)
        if w <= 0.0:
            return ext, rate, 0.0, 0.0, 0.0
        T, dd, dr = normal_force(-ext, -rate, PC[I_KK], PC[I_KE], PC[I_KC], PC[I_KD])
        return ext, rate, -w * T, w * dd, w * dr
    if ext == 0.0:
        return ext, rate, 0.0, 0.0, 0.0
    T, dd, dr = normal_force(ext, rate, PC[I_KK], PC[I_KE], PC[I_KC], PC[I_KD])
    return ext, rate, T, dd, dr


@njit(cache=True)
def _force(x, PC, p, c1, c2, use1, use2, M, P, V, J, info, knees):
    """Q - h (NQ,) with the contact forces of the legs' points used and the knee stops;
    fills M, the points' P, V, J, per-point ``info`` (NF, 12) (see _point) and ``knees``
    (2, 5) (knees only with one contact point per leg: point k is leg k's)."""
    h = np.empty(NQ)
    dyn(x, p, M, h)
    feet(x, p, P, V, J)
    Q = -h
    sp, cp = _sin(PC[I_PHI]), _cos(PC[I_PHI])
    for i in range(NF):
        leg = POINT_LEG[i]
        if not ((leg == 0 and use1) or (leg == 1 and use2)):
            continue
        res = _point(P[i, 0], P[i, 1], V[i, 0], V[i, 1], sp, cp, PC, c1 if leg == 0 else c2)
        for k in range(12):
            info[i, k] = res[k]
        fn, ff = res[4], res[5]
        if fn > 0.0:
            nx, ny = res[10], res[11]  # the ground's normal (the slope's: sp, cp)
            Fx = fn * nx + ff * ny
            Fy = fn * ny - ff * nx
            for k in range(NQ):
                Q[k] += J[i, 0, k] * Fx + J[i, 1, k] * Fy
    if KNEE:
        for k in range(2):
            used = (k == 0 and use1) or (k == 1 and use2)
            res = _knee(x, k, PC, info[k, 0] if used else np.inf)  # pinned: on the ground
            for j in range(5):
                knees[k, j] = res[j]
            T = res[2]
            Q[2 + 2 * k] += T
            Q[3 + 2 * k] -= T
    return Q


@njit(cache=True)
def _knee_torque(ext, rate, PC, delta):
    """Knee-stop torque [N m] (>= 0 past straight) at hyperextension ``ext`` [rad], rate
    [rad/s]; with the latch on and the leg's foot at penetration delta [m] (near or on the
    ground), also < 0 in flexion."""
    if ext < 0.0:
        w = _latch_weight(delta, ext, PC)
        if w <= 0.0:
            return 0.0
        return -w * normal_force(-ext, -rate, PC[I_KK], PC[I_KE], PC[I_KC], PC[I_KD])[0]
    if ext == 0.0:
        return 0.0
    return normal_force(ext, rate, PC[I_KK], PC[I_KE], PC[I_KC], PC[I_KD])[0]


@njit(cache=True)
def _buffers():
    """The arrays :func:`_force` fills: M (NQ, NQ), the points' P, V (NF, 2), J (NF, 2, NQ),
    their info (NF, 12) and the knees' (2, 5)."""
    return (np.empty((NQ, NQ)), np.empty((NF, 2)), np.empty((NF, 2)), np.empty((NF, 2, NQ)),
            np.zeros((NF, 12)), np.zeros((2, 5)))


@njit(cache=True)
def jac(x, PC, p, c1, c2):
    """Analytic d rhs / dx (NX, NX); patch membership locally constant."""
    M, P, V, J, info, knees = _buffers()
    Q = _force(x, PC, p, c1, c2, True, True, M, P, V, J, info, knees)
    L = _chol(M)
    a = _chol_solve(L, Q.reshape((NQ, 1)))[:, 0]
    Dq = np.empty((NQ, NQ))
    Dv = np.empty((NQ, NQ))
    dyn_jac(x, a, p, Dq, Dv)
    F = np.zeros((NF, 2))
    for i in range(NF):
        fn, ff = info[i, 4], info[i, 5]
        if fn > 0.0:
            sp, cp = info[i, 10], info[i, 11]  # the ground's normal at the point
            F[i, 0] = fn * sp + ff * cp
            F[i, 1] = fn * cp - ff * sp
    dV = np.empty((NF, 2, NQ))
    dJtF = np.empty((NQ, NQ))
    feet_jac(x, F, p, dV, dJtF)
    B = np.empty((NQ, 2 * NQ))
    for r in range(NQ):
        for k in range(NQ):
            B[r, k] = dJtF[r, k] - Dq[r, k]
            B[r, NQ + k] = -Dv[r, k]
    for i in range(NF):
        fn = info[i, 4]
        if fn <= 0.0:
            continue
        dfd, dfdd, mu, dmu = info[i, 6], info[i, 7], info[i, 8], info[i, 9]
        sp, cp = info[i, 10], info[i, 11]  # the normal, locally constant
        dFx = np.empty(2 * NQ)
        dFy = np.empty(2 * NQ)
        for k in range(NQ):
            d_delta = -(sp * J[i, 0, k] + cp * J[i, 1, k])  # = d ddot / d dq_k
            d_ddot = -(sp * dV[i, 0, k] + cp * dV[i, 1, k])
            d_vt_q = cp * dV[i, 0, k] - sp * dV[i, 1, k]
            d_vt_v = cp * J[i, 0, k] - sp * J[i, 1, k]
            dfn_q = dfd * d_delta + dfdd * d_ddot
            dfn_v = dfdd * d_delta
            dff_q = mu * dfn_q + fn * dmu * d_vt_q
            dff_v = mu * dfn_v + fn * dmu * d_vt_v
            dFx[k] = sp * dfn_q + cp * dff_q
            dFy[k] = cp * dfn_q - sp * dff_q
            dFx[NQ + k] = sp * dfn_v + cp * dff_v
            dFy[NQ + k] = cp * dfn_v - sp * dff_v
        for r in range(NQ):
            for k in range(2 * NQ):
                B[r, k] += J[i, 0, r] * dFx[k] + J[i, 1, r] * dFy[k]
    if KNEE:
        for kk in range(2):
            t, s = 2 + 2 * kk, 3 + 2 * kk
            dd, dr = knees[kk, 3], knees[kk, 4]
            # Q[t] += T, Q[s] -= T with T(ext = q_s - q_t, rate = dq_s - dq_t)
            for off, d in ((0, dd), (NQ, dr)):
                B[t, off + s] += d
                B[t, off + t] -= d
                B[s, off + s] -= d
                B[s, off + t] += d
    X = _chol_solve(L, B)
    out = np.zeros((NX, NX))
    for k in range(NQ):
        out[k, NQ + k] = 1.0
        for c in range(NX):
            out[NQ + k, c] = X[k, c]
    return out


@njit(cache=True)
def pinned_to_full(z, p, foot2):
    """Full state (NX,) with leg2's (first) contact point PIN at ``foot2`` (2,) and at
    rest; ``z = [link angles (NQ - 2), their rates]``."""
    x = np.zeros(NX)
    for k in range(NQ - 2):
        x[2 + k] = z[k]
        x[NQ + 2 + k] = z[NQ - 2 + k]
    P = np.empty((NF, 2))
    V = np.empty((NF, 2))
    J = np.empty((NF, 2, NQ))
    feet(x, p, P, V, J)  # hip at the origin, at rest: foot offset and velocity
    x[0] = foot2[0] - P[PIN, 0]
    x[1] = foot2[1] - P[PIN, 1]
    x[NQ] = -V[PIN, 0]
    x[NQ + 1] = -V[PIN, 1]
    return x


@njit(cache=True)
def rhs_pinned(z, PC, p, c1, c2, foot2):
    """Reduced dynamics with leg2's foot pinned: ``q = Phi(z)``, ``dq = Jp dz``,
    ``qdd = Jp zdd + gam``; ``Jp^T M Jp zdd = Jp^T (Q - h - M gam)`` (leg1 keeps its contact)."""
    x = pinned_to_full(z, p, foot2)
    M, P, V, J, info, knees = _buffers()
    Q = _force(x, PC, p, c1, c2, True, False, M, P, V, J, info, knees)
    dV = np.empty((NF, 2, NQ))
    dJtF = np.empty((NQ, NQ))
    feet_jac(x, np.zeros((NF, 2)), p, dV, dJtF)
    m = NQ - 2
    Jp = np.zeros((NQ, m))
    for k in range(m):
        Jp[0, k] = -J[PIN, 0, 2 + k]
        Jp[1, k] = -J[PIN, 1, 2 + k]
        Jp[2 + k, k] = 1.0
    gam = np.zeros(NQ)
    for r in range(2):
        s = 0.0
        for k in range(NQ):
            s += dV[PIN, r, k] * x[NQ + k]
        gam[r] = -s
    rhs_q = Q.copy()
    for i in range(NQ):
        for k in range(NQ):
            rhs_q[i] -= M[i, k] * gam[k]
    MJ = np.zeros((NQ, m))
    for i in range(NQ):
        for c in range(m):
            for k in range(NQ):
                MJ[i, c] += M[i, k] * Jp[k, c]
    r = np.zeros(m)
    Mr = np.zeros((m, m))
    for a in range(m):
        for i in range(NQ):
            r[a] += Jp[i, a] * rhs_q[i]
            for c in range(m):
                Mr[a, c] += Jp[i, a] * MJ[i, c]
    zdd = _chol_solve(_chol(Mr), r.reshape((m, 1)))[:, 0]
    out = np.empty(2 * m)
    for k in range(m):
        out[k] = z[m + k]
        out[m + k] = zdd[k]
    return out


@njit(cache=True)
def contact_table(X, PC, p, c1, c2):
    """(n, NF, 8): per contact point penetration [m], its rate [m/s], slip velocity [m/s],
    s [m], Fn [N], Ff [N], power F . v [W], on_ground (1/0)."""
    n = X.shape[0]
    out = np.zeros((n, NF, 8))
    sp, cp = _sin(PC[I_PHI]), _cos(PC[I_PHI])
    P = np.empty((NF, 2))
    V = np.empty((NF, 2))
    J = np.empty((NF, 2, NQ))
    for r in range(n):
        feet(X[r], p, P, V, J)
        for i in range(NF):
            cen = c1 if POINT_LEG[i] == 0 else c2
            res = _point(P[i, 0], P[i, 1], V[i, 0], V[i, 1], sp, cp, PC, cen)
            fn, ff = res[4], res[5]
            Fx = fn * res[10] + ff * res[11]
            Fy = fn * res[11] - ff * res[10]
            for k in range(6):
                out[r, i, k] = res[k]
            out[r, i, 6] = Fx * V[i, 0] + Fy * V[i, 1]
            hq = patch_height(res[3], cen, PC[I_HW], PC[I_CONT] > 0.5)  # NaN in a gap
            out[r, i, 7] = 1.0 if hq == hq else 0.0
    return out


@njit(cache=True)
def knee_table(X, PC, p, c1, c2):
    """(n, 2, 4): per knee extension [rad] (> 0 hyperextended), its rate [rad/s], stop
    torque [N m] (> 0 pushing the knee straight from hyperextension; < 0 the latch holding
    a loaded leg's knee against flexion) and the stop's power [W] (<= 0 while it
    dissipates)."""
    n = X.shape[0]
    out = np.zeros((n, 2, 4))
    P = np.empty((NF, 2))
    V = np.empty((NF, 2))
    J = np.empty((NF, 2, NQ))
    sp, cp = _sin(PC[I_PHI]), _cos(PC[I_PHI])
    if KNEE:
        for r in range(n):
            feet(X[r], p, P, V, J)
            for k in range(2):
                delta = _point(P[k, 0], P[k, 1], V[k, 0], V[k, 1], sp, cp, PC,
                               c1 if k == 0 else c2)[0]
                ext, rate, T, _, _ = _knee(X[r], k, PC, delta)
                out[r, k, 0] = ext
                out[r, k, 1] = rate
                out[r, k, 2] = T
                out[r, k, 3] = -T * rate
    return out


@njit(cache=True)
def packed_size(d):
    """Length of the data vector (``d`` may be a raw pointer in a cfunc)."""
    return D_P + NP + int(d[D_N1]) + int(d[D_N2]) + 1


@njit(cache=True)
def rhs_packed(y, d, dy):
    """rhs of ``y`` (NX,) with everything unpacked from the data vector ``d``, into ``dy``;
    counts the call in ``d[-1]``."""
    a1 = D_P + NP
    a2 = a1 + int(d[D_N1])
    r = rhs(y, d[D_PC:D_P], d[D_P:a1], d[a1:a2], d[a2:d.size - 1])
    for i in range(NX):
        dy[i] = r[i]
    d[d.size - 1] += 1.0


@njit(cache=True, error_model='numpy')
def powered_rhs(x, PC, p, c1, c2, has_tau, sw, st, tau, push_leg, force, hx, hy, out):
    """A powered walker's right-hand side with its ledger's powers, into ``out``
    (NX + 4,): ``[dx, hip torque's positive and negative power, push-off's, contact
    forces']``, the arithmetic of :func:`walkerlab.models.contact.actuation.powered_rhs`
    in the same order (the same numbers).  ``has_tau``: the walker has hip-torque laws,
    whose torque ``tau`` [N m] acts +tau on coordinate ``sw``, -tau on ``st``; a push-off
    force ``force`` [N] at point ``push_leg`` (-1: none) along the line from it to the hip
    (coordinates ``hx``, ``hy``)."""
    n = NQ
    r = rhs(x, PC, p, c1, c2)
    for i in range(NX):
        out[i] = r[i]
    tab = contact_table(x.reshape((1, NX)), PC, p, c1, c2)
    rest = 0.0  # numpy's sum of the column: the first entry, then the others from 0.0
    for i in range(1, NF):
        rest += tab[0, i, 6]
    p_contact = tab[0, 0, 6] + rest
    Q = np.zeros(n)
    p_tau = 0.0
    if has_tau:
        Q[sw] = Q[sw] + tau
        Q[st] = Q[st] - tau
        p_tau = tau * (x[n + sw] - x[n + st])
    p_po = 0.0
    if push_leg >= 0:
        Qp, p_po = push_force(x, p, push_leg, force, hx, hy)
        Q = Q + Qp
    moved = False
    for i in range(n):
        if Q[i] != 0.0:
            moved = True
    if moved:
        xz = np.zeros(NX)
        xz[:n] = x[:n]
        M = np.empty((n, n))
        h = np.empty(n)
        dyn(xz, p, M, h)
        a = np.linalg.solve(M, Q)
        for i in range(n):
            out[n + i] = out[n + i] + a[i]
    out[NX] = 0.0 if 0.0 > p_tau else p_tau  # Python's max(p_tau, 0.0), min(p_tau, 0.0)
    out[NX + 1] = 0.0 if 0.0 < p_tau else p_tau
    out[NX + 2] = p_po
    out[NX + 3] = p_contact


@njit(cache=True, error_model='numpy')
def push_force(x, p, push_leg, force, hx, hy):
    """The generalised force (NQ,) of a force ``force`` [N] at contact point ``push_leg``
    along the line from it to the hip (coordinates ``hx``, ``hy``), and its power [W]."""
    P = np.empty((NF, 2))
    V = np.empty((NF, 2))
    J = np.empty((NF, 2, NQ))
    feet(x, p, P, V, J)
    rr = np.empty(2)
    rr[0] = x[hx] - P[push_leg, 0]
    rr[1] = x[hy] - P[push_leg, 1]
    e = rr / np.sqrt(np.dot(rr, rr))
    F = force * e
    Jt = np.ascontiguousarray(J[push_leg].T)
    return np.dot(Jt, F), np.dot(F, V[push_leg].copy())


def build_cyrk():
    """Address of a CyRK ``cyjit_sig`` cfunc of rhs_packed (numba disk cache)."""
    from CyRK.nb.numba_solver import cyjit_sig
    from numba import carray, cfunc

    @cfunc(cyjit_sig, cache=True)
    def rhs_c(dy, t, y, d):  # pragma: no cover - runs compiled
        rhs_packed(carray(y, (NX,)), carray(d, (packed_size(d),)), carray(dy, (NX,)))

    return rhs_c.address


def build_lsoda(sig):
    """Address of a numbalsoda ``lsoda_sig`` cfunc of rhs_packed."""
    from numba import carray, cfunc

    @cfunc(sig, cache=True)
    def rhs_c(t, u, du, d):  # pragma: no cover - runs compiled
        rhs_packed(carray(u, (NX,)), carray(d, (packed_size(d),)), carray(du, (NX,)))

    return rhs_c.address
'''


def contact_source(structure: Structure, key: str) -> str:
    """Source of the generated contact module of ``structure`` (its floating view, the
    constants ``NP``, ``KNEE`` (knee stops: kneed legs whose knees are not free), ``NF``,
    ``POINT_LEG``, ``PIN``, ``CONTACTS``, then :data:`ASSEMBLY` and the straight-line
    ``rhs``).

    Raises
    ------
    ValueError
        A kneed walker with more than one contact point per leg (flat feet).
    """
    from walkerlab.codegen import floating

    from .powered_source import powered_source

    eq = floating.derive_floating(structure)
    if structure.knee and len(eq.feet) != 2:
        raise ValueError("a kneed walker's contact model needs one contact point per leg")
    fl = floating.floating_source(structure, key)
    legs = tuple(eq.point_legs)
    return (fl + f"\nNP = {len(eq.params)}\nKNEE = {bool(eq.knees)}\n"
            f"NF = {len(eq.feet)}\nPOINT_LEG = {legs!r}\nPIN = {legs.index(1)}\n"
            f"CONTACTS = {tuple(eq.contacts)!r}\n" + ASSEMBLY + "\n\n" + rhs_source(eq)
            + "\n\n" + rhs_source(eq, forced=True) + "\n\n" + powered_source())


def contact_module(structure: Structure):
    """The imported generated contact module of ``structure`` (compiled lazily by numba,
    cached on disk).

    Raises
    ------
    ValueError
        Massless bodies (a floating model needs positive leg masses).
    """
    from walkerlab.codegen import floating

    floating.check_masses(structure)
    return floating.load_generated(structure, "contact",
                                   lambda key: contact_source(structure, key),
                                   sources=_SOURCES)


def contact_module_state(structure: Structure) -> tuple[str, bool | None]:
    """The module name :func:`contact_module` gives ``structure``'s generated contact module
    (``ContactWalker.kernels.__name__``) and whether its source is in the user cache already
    (:func:`walkerlab.codegen.floating.generated_state`: False on the first contact run of
    this walker structure with this cache and generator; None without a user cache
    folder), without generating or importing it."""
    from walkerlab.codegen import floating

    return floating.generated_state(structure, "contact", sources=_SOURCES)
