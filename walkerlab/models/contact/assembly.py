"""The compliant-contact walker's assembly: contact geometry (points, their velocities and
Jacobians, the mass matrix and bias) in, forces and accelerations out; numba, on arrays.

Internal module.  Everything is SI.  These kernels do the walker-independent work of a
compliant-contact walker's compiled model with the laws of
:mod:`walkerlab.models.contact._kernels` (IMPACT normal force, ADAMS Coulomb friction, patch
membership): the contact of each point from its position and material velocity
(:func:`point`), the generalised forces ``Q = J^T F - h`` with the knee stops and latch
(:func:`contact_forces`, :func:`knee`), the solve of ``M qdd = Q - h`` (:func:`chol`,
:func:`chol_solve`), the analytic Jacobian's assembly (:func:`jac_assembly`), the pinned
stance foot's reduced dynamics (:func:`pinned_dynamics`) and the per-point and per-knee
tables.  They take arrays only (no compiled function is an argument: numba's disk cache
keys a function on its arguments' types); the generated module of each walker structure
(:func:`walkerlab.models.contact.generated.contact_source`) calls its generated kinematics
(``dyn``, ``feet``, ``feet_jac``) and hands their arrays to these kernels
(:mod:`walkerlab.codegen.contact_glue`).

Shapes: ``nq`` generalised coordinates, ``nf`` contact points, ``d`` the world's dimension
(2: a planar walker, world axes ``x`` downhill, ``y`` up; 3: a walker in 3D, ``z``
lateral); ``P``, ``V`` (nf, d) the points' positions [m] and material velocities [m/s],
``J`` (nf, d, nq) their Jacobians, ``point_leg`` (nf,) each point's leg (0: leg1, on lane
``c1``; 1: leg2, on ``c2``), ``info`` (nf, :data:`NINFO`) each point's :func:`point`
result, ``knees`` (2, 5) each knee's :func:`knee` result.  The kernels read ``d`` from the
arrays' shapes and take a planar point as a 3D one in its plane (``z = 0``, no lateral slip):
one path for either dimension.
The contact parameter vector ``PC`` is read through the named indices ``I_*``
(:mod:`walkerlab.models.contact.generated`'s table).
"""

from __future__ import annotations

from math import cos as _cos
from math import sin as _sin

import numpy as np
from numba import njit

from walkerlab.models.contact._kernels import (
    friction_mu,
    ground_line,
    normal_force,
    patch_height,
    step,
)

I_PHI, I_K, I_E, I_CMAX, I_DMAX = 0, 1, 2, 3, 4
I_MUS, I_MUD, I_VS, I_VD, I_HW, I_CONT = 5, 6, 7, 8, 9, 10
I_KK, I_KE, I_KC, I_KD, I_KL, I_KF, I_KA = 11, 12, 13, 14, 15, 16, 17
I_TOR, I_WEPS = 18, 19
#: Number of contact parameters.
NPC = 20
#: Columns of a contact point's ``info`` row: :func:`point`'s 15.
NINFO = 15
#: The packed data vector's head: ``[n1, n2, PC (NPC), p, ...]``.
D_N1, D_N2, D_PC = 0, 1, 2
D_P = D_PC + NPC


@njit(cache=True)
def chol(M):
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
def chol_solve(L, B):
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
def slope(PC):
    """The slope's (sin phi, cos phi)."""
    return _sin(PC[I_PHI]), _cos(PC[I_PHI])


@njit(cache=True)
def pressed(px, py, vx, vy, sp, cp, PC, cen):
    """How a point at (px, py) [m] with material velocity (vx, vy) [m/s] (in 3D: their
    sagittal parts; the slope does not change across it) presses the slope's lane ``cen``:
    (delta, ddot, vt, s, Fn, dFn/ddelta, dFn/dddot), the penetration [m] below the top of
    the patch under it (a gap: none), its rate [m/s], the slip along the fall line [m/s],
    the along-slope position [m] and the IMPACT normal force [N] with its partials; the
    slope's (sin, cos) = (sp, cp).  :func:`point`'s normal part."""
    delta = -(px * sp + py * cp)
    ddot = -(vx * sp + vy * cp)
    vt = vx * cp - vy * sp
    s = px * cp - py * sp
    fn, dfd, dfdd = 0.0, 0.0, 0.0
    # a patch at height hp: penetration below its top (cen[-1], the lane's highest patch,
    # skips the lookup for a foot above every patch; all heights 0: the flat ground)
    hp = patch_height(s, cen, PC[I_HW], PC[I_CONT] > 0.5) if delta + cen[-1] > 0.0 else np.nan
    if hp == hp:
        delta += hp
    if delta > 0.0 and hp == hp:
        fn, dfd, dfdd = normal_force(delta, ddot, PC[I_K], PC[I_E], PC[I_CMAX], PC[I_DMAX])
    return delta, ddot, vt, s, fn, dfd, dfdd


@njit(cache=True)
def point(px, py, pz, vx, vy, vz, sp, cp, PC, cen):
    """Contact of a point at (px, py, pz) [m] whose material velocity is (vx, vy, vz) [m/s]
    (a planar walker's: ``pz = vz = 0``) with the slope (the plane ``y = -x tan phi``,
    outward normal ``n = (sin phi, cos phi, 0)``, its lines of greatest slope along ``t =
    (cos phi, -sin phi, 0)``, level across them along ``z``), on the lane ``cen``: the
    penetration, its rate, ``s`` and the patches are :func:`pressed`'s (the ground does not
    change across the slope); the friction acts against the slip velocity ``v_t = (vt, vz)`` in the
    tangent plane with the ADAMS Coulomb coefficient of the slip speed ``|v_t|``
    (stiction and transition velocities on ``|v_t|``, MSC Adams/Solver's CONTACT
    friction): ``F_t = mu(|v_t|) Fn v_t / |v_t|`` (``mu`` signed, < 0: against the slip;
    ``mu(w) / w`` -> ``dmu(0)`` as ``w`` -> 0, so the force is smooth through rest).

    Returns the 15 entries (delta, ddot, vt, s, Fn, Ft, dFn/ddelta, dFn/dddot, g, dmu/dw,
    nx, ny, vz, Fz, w): ``Ft`` the friction along ``t`` [N], ``g = mu(w) / w`` [s/m] (the
    friction per unit slip and normal force) and ``dmu/dw`` at the slip speed ``w = |v_t|``
    [m/s], then the lateral slip ``vz`` [m/s], the lateral friction ``Fz`` [N] and ``w``.
    On a polyline ground (``PC[I_CONT] == 2``: ``cen`` its vertices in the ``x, y`` plane,
    :func:`ground_line`; stairs' treads and risers, level across the fall line along ``z``)
    the penetration, the normal ``(nx, ny, 0)`` and the slip along ``(ny, -nx, 0)`` are the
    nearest segment's, the lateral slip ``vz`` the same.  The one contact kernel of the
    right-hand side, the Jacobian, the pinned dynamics and the tables (one compile)."""
    if PC[I_CONT] > 1.5:
        delta, nx, ny = ground_line(px, py, cen)
        ddot = -(vx * nx + vy * ny)
        vt = vx * ny - vy * nx
        s = px * cp - py * sp
        fn, dfd, dfdd = 0.0, 0.0, 0.0
        if delta > 0.0:
            fn, dfd, dfdd = normal_force(delta, ddot, PC[I_K], PC[I_E], PC[I_CMAX],
                                         PC[I_DMAX])
        return _slip3(delta, ddot, vt, s, fn, dfd, dfdd, nx, ny, vz, PC)
    delta, ddot, vt, s, fn, dfd, dfdd = pressed(px, py, vx, vy, sp, cp, PC, cen)
    return _slip3(delta, ddot, vt, s, fn, dfd, dfdd, sp, cp, vz, PC)


@njit(cache=True)
def _slip3(delta, ddot, vt, s, fn, dfd, dfdd, nx, ny, vz, PC):
    """:func:`point`'s 15 entries from the normal contact of a point on the ground of
    outward normal ``(nx, ny, 0)``: the Coulomb friction on the slip ``(vt, vz)``."""
    w = np.sqrt(vt * vt + vz * vz)
    g, dmu = 0.0, 0.0
    if fn > 0.0:
        mu, dmu = friction_mu(w, PC[I_MUS], PC[I_MUD], PC[I_VS], PC[I_VD])
        g = mu / w if w > 0.0 else dmu
    return (delta, ddot, vt, s, fn, g * fn * vt, dfd, dfdd, g, dmu, nx, ny, vz, g * fn * vz, w)


@njit(cache=True)
def latch_ground(s, cen, PC):
    """Height [m] (along the slope's outward normal) of the ground a foot at along-slope
    coordinate ``s`` [m] is measured from for its knee latch: the top of the nearest patch
    of its lane ``cen`` (stairs and footholds: over a gap too, so a swing foot below the
    slope line is not taken for one on the ground); 0.0 on continuous ground and on the
    plain slope (all heights 0: the latch's penetration bit for bit the slope's)."""
    n = (cen.shape[0] - 1) // 2
    if PC[I_CONT] > 0.5 or n == 0:
        return 0.0
    best, h = np.inf, 0.0
    for j in range(n):
        d = abs(s - cen[j])
        if d < best:
            best, h = d, cen[n + j]
    return h


@njit(cache=True)
def latch_weight(delta, ext, PC):
    """Latch engagement in [0, 1] of a knee at extension ext [rad] (< 0 flexed) whose foot
    has the penetration delta [m] (< 0: above the ground)."""
    if PC[I_KL] < 0.5:
        return 0.0
    return (step(delta, -PC[I_KF], 0.0, 0.0, 1.0)[0]
            * step(ext, -PC[I_KA], 0.0, -0.5 * PC[I_KA], 1.0)[0])


@njit(cache=True)
def knee(x, t, s, PC, delta, nq):
    """Knee stop (and latch, its foot at penetration delta [m]) of the knee between the
    thigh angle ``x[t]`` and the shank angle ``x[s]`` of the state ``x`` (``nq``
    coordinates, then their rates): (extension, rate, torque, dT/dext, dT/drate)."""
    ext = x[s] - x[t]
    rate = x[nq + s] - x[nq + t]
    if ext < 0.0:
        w = latch_weight(delta, ext, PC)
        if w <= 0.0:
            return ext, rate, 0.0, 0.0, 0.0
        T, dd, dr = normal_force(-ext, -rate, PC[I_KK], PC[I_KE], PC[I_KC], PC[I_KD])
        return ext, rate, -w * T, w * dd, w * dr
    if ext == 0.0:
        return ext, rate, 0.0, 0.0, 0.0
    T, dd, dr = normal_force(ext, rate, PC[I_KK], PC[I_KE], PC[I_KC], PC[I_KD])
    return ext, rate, T, dd, dr


@njit(cache=True)
def knee_torque(ext, rate, PC, delta):
    """Knee-stop torque [N m] (>= 0 past straight) at hyperextension ``ext`` [rad], rate
    [rad/s]; with the latch on and the leg's foot at penetration delta [m] (near or on the
    ground), also < 0 in flexion."""
    if ext < 0.0:
        w = latch_weight(delta, ext, PC)
        if w <= 0.0:
            return 0.0
        return -w * normal_force(-ext, -rate, PC[I_KK], PC[I_KE], PC[I_KC], PC[I_KD])[0]
    if ext == 0.0:
        return 0.0
    return normal_force(ext, rate, PC[I_KK], PC[I_KE], PC[I_KC], PC[I_KD])[0]


@njit(cache=True)
def contact_forces(x, h, PC, c1, c2, use1, use2, P, V, J, info, knees, point_leg,
                   has_knees, knee_idx):
    """Q - h (nq,) from the bias ``h`` (nq,) with the contact forces of the points of the
    legs used (``use1``, ``use2``) and, ``has_knees``, the knee stops (knee k's foot: point
    k; its thigh's and shank's coordinates ``knee_idx[k]``, (2, 2)); fills ``info`` and
    ``knees``.  Points in ``d = P.shape[1]`` dimensions
    (:func:`point`; a planar point in its plane)."""
    nq, d = h.shape[0], P.shape[1]
    if info.shape[0] < P.shape[0] or info.shape[1] < NINFO or knees.shape[1] < 5:
        raise ValueError("contact_forces: info must be (nf, NINFO) and knees (2, 5)")
    Q = -h
    sp, cp = _sin(PC[I_PHI]), _cos(PC[I_PHI])
    for i in range(P.shape[0]):
        leg = point_leg[i]
        if not ((leg == 0 and use1) or (leg == 1 and use2)):
            continue
        cen = c1 if leg == 0 else c2
        r = point(P[i, 0], P[i, 1], P[i, 2] if d == 3 else 0.0, V[i, 0], V[i, 1],
                  V[i, 2] if d == 3 else 0.0, sp, cp, PC, cen)
        for k in range(NINFO):
            info[i, k] = r[k]
        if r[4] > 0.0:
            F = world_force(info[i])
            for k in range(nq):   # a planar point's third term 0.0: its sum as the plane's
                Q[k] += J[i, 0, k] * F[0] + J[i, 1, k] * F[1] + (
                    J[i, 2, k] * F[2] if d == 3 else 0.0)
    if has_knees:
        for k in range(2):
            used = (k == 0 and use1) or (k == 1 and use2)
            t, s = knee_idx[k, 0], knee_idx[k, 1]
            res = knee(x, t, s, PC, info[k, 0] if used else np.inf, nq)  # pinned: on ground
            for j in range(5):
                knees[k, j] = res[j]
            T = res[2]
            Q[t] += T
            Q[s] -= T
    return Q


@njit(cache=True)
def twist(spin, fn, PC):
    """The torsional friction moment [N m] about the ground's normal on a contact point
    whose body spins at ``spin`` [rad/s] about it under the normal force ``fn`` [N]: the
    contact patch's, ``M = mu(rho spin) fn rho`` with ``rho = tau / mu_s`` (``tau`` =
    ``PC[I_TOR]`` [m], the largest moment per newton of normal force: MuJoCo's
    torsional coefficient; an evenly pressed disc of radius ``r`` has ``tau = 2 mu_s r /
    3``) and ``mu`` the ADAMS Coulomb coefficient of the patch's slip speed ``rho spin``
    (:func:`walkerlab.models.contact._kernels.friction_mu`, signed: against the spin).
    0 without a torsional coefficient, without friction (``mu_s`` 0: no moment, and no
    ``rho``) or off the ground."""
    tau = PC[I_TOR]
    if fn <= 0.0 or tau <= 0.0 or PC[I_MUS] <= 0.0:
        return 0.0
    rho = tau / PC[I_MUS]
    return friction_mu(rho * spin, PC[I_MUS], PC[I_MUD], PC[I_VS], PC[I_VD])[0] * fn * rho


@njit(cache=True)
def add_twists(Q, info, S, Jn, PC):
    """Add each 3D contact point's torsional friction ``Jn_i^T M_i`` (:func:`twist` of its
    spin ``S`` (nf,) [rad/s] and its ``info`` row's normal force) to ``Q`` (nq,)."""
    for i in range(S.shape[0]):
        m = twist(S[i], info[i, 4], PC)
        if m != 0.0:
            for k in range(Q.shape[0]):
                Q[k] += Jn[i, k] * m


@njit(cache=True)
def world_force(row):
    """A point's contact force (3,) [N] in the world from its ``info`` row
    (:func:`point`): ``Fn n + Ft t + Fz e_z`` (a planar point's ``Fz`` 0)."""
    fn, ft, nx, ny = row[4], row[5], row[10], row[11]
    return np.array((fn * nx + ft * ny, fn * ny - ft * nx, row[13]))


@njit(cache=True)
def buffers(nq, nf, d):
    """The arrays :func:`contact_forces` and the kinematics fill: M (nq, nq), the points'
    P, V (nf, d), J (nf, d, nq), their info (nf, NINFO) and the knees' (2, 5)."""
    return (np.empty((nq, nq)), np.empty((nf, d)), np.empty((nf, d)), np.empty((nf, d, nq)),
            np.zeros((nf, NINFO)), np.zeros((2, 5)))


@njit(cache=True)
def point_buffers(nq, nf, d):
    """The points' P, V (nf, d) and J (nf, d, nq), to be filled by the kinematics."""
    return np.empty((nf, d)), np.empty((nf, d)), np.empty((nf, d, nq))


@njit(cache=True)
def world_forces(info, d):
    """(nf, d) each point's contact force [N] in the world from its ``info`` row."""
    F = np.zeros((info.shape[0], d))
    for i in range(info.shape[0]):
        if info[i, 4] > 0.0:
            F[i] = world_force(info[i])[:d]
    return F


@njit(cache=True)
def jac_assembly(L, Dq, Dv, dJtF, J, dV, info, knees, has_knees, knee_idx):
    """d rhs / dx (2 nq, 2 nq) from the Cholesky factor ``L`` of M, the partials ``Dq``,
    ``Dv`` (nq, nq) of ``M a + h`` at the acceleration ``a``, ``dJtF`` (nq, nq) of ``J^T F``
    at the forces held, the points' Jacobians ``J`` and their rates' partials ``dV``
    (nf, d, nq); patch membership and each point's normal locally constant
    (:func:`point_partials`)."""
    nq = L.shape[0]
    B = np.empty((nq, 2 * nq))
    for r in range(nq):
        for k in range(nq):
            B[r, k] = dJtF[r, k] - Dq[r, k]
            B[r, nq + k] = -Dv[r, k]
    for i in range(info.shape[0]):
        fn = info[i, 4]
        if fn <= 0.0:
            continue
        point_partials(B, J, dV, info[i], i)
    if has_knees:
        for kk in range(2):
            t, s = knee_idx[kk, 0], knee_idx[kk, 1]
            dd, dr = knees[kk, 3], knees[kk, 4]
            # Q[t] += T, Q[s] -= T with T(ext = q_s - q_t, rate = dq_s - dq_t)
            for off, d in ((0, dd), (nq, dr)):
                B[t, off + s] += d
                B[t, off + t] -= d
                B[s, off + s] -= d
                B[s, off + t] += d
    X = chol_solve(L, B)
    nx = 2 * nq
    out = np.zeros((nx, nx))
    for k in range(nq):
        out[k, nq + k] = 1.0
        for c in range(nx):
            out[nq + k, c] = X[k, c]
    return out


@njit(cache=True)
def point_partials(B, J, dV, row, i):
    """Add ``J_i^T dF_i/dx`` (nq, 2 nq) of the point ``i`` (its :func:`point` ``row``; a
    planar point's ``J``, ``dV`` of two rows, its lateral slip 0) to ``B``: ``F = Fn n + g
    Fn (vt t + vz e_z)`` with ``g = mu(w) / w`` and ``dg/dw = (dmu/dw - g) / w`` (0 at rest,
    where ``g`` is even in ``w``)."""
    nq, d = J.shape[2], J.shape[1]
    fn, vt, dfd, dfdd, g, dmu = row[4], row[2], row[6], row[7], row[8], row[9]
    sp, cp, vz, w = row[10], row[11], row[12], row[14]
    dgdw = (dmu - g) / w if w > 0.0 else 0.0
    dF = np.zeros((3, 2 * nq))
    for k in range(2 * nq):
        if k < nq:  # a coordinate: the point moves, its material velocity changes
            dn, dndot = -(sp * J[i, 0, k] + cp * J[i, 1, k]), -(sp * dV[i, 0, k] + cp * dV[i, 1, k])
            dvt, dvz = cp * dV[i, 0, k] - sp * dV[i, 1, k], dV[i, 2, k] if d == 3 else 0.0
        else:  # a rate: only the velocity changes
            c = k - nq
            dn, dndot = 0.0, -(sp * J[i, 0, c] + cp * J[i, 1, c])
            dvt, dvz = cp * J[i, 0, c] - sp * J[i, 1, c], J[i, 2, c] if d == 3 else 0.0
        dfn = dfd * dn + dfdd * dndot
        dg = dgdw * (vt * dvt + vz * dvz) / w if w > 0.0 else 0.0
        dft = (dg * fn + g * dfn) * vt + g * fn * dvt
        dF[0, k] = sp * dfn + cp * dft
        dF[1, k] = cp * dfn - sp * dft
        dF[2, k] = (dg * fn + g * dfn) * vz + g * fn * dvz
    for r in range(nq):
        for k in range(2 * nq):
            B[r, k] += J[i, 0, r] * dF[0, k] + J[i, 1, r] * dF[1, k] + (
                J[i, 2, r] * dF[2, k] if d == 3 else 0.0)


@njit(cache=True)
def pinned_angles(z, nq, d):
    """The state (2 nq,) with the coordinates after the ``d`` slides of the floating base
    and their rates ``z`` (2 (nq - d),), the base at the origin and at rest."""
    x = np.zeros(2 * nq)
    for k in range(nq - d):
        x[d + k] = z[k]
        x[nq + d + k] = z[nq - d + k]
    return x


@njit(cache=True)
def pin_at(x, P, V, pin, foot2):
    """Move the state ``x`` of :func:`pinned_angles` (its points at ``P``, ``V``) so that
    its point ``pin`` is at ``foot2`` (d,) and at rest (the base's slides: the first ``d``
    coordinates, translations along the world's axes)."""
    nq = x.shape[0] // 2
    for r in range(P.shape[1]):
        x[r] = foot2[r] - P[pin, r]
        x[nq + r] = -V[pin, r]


@njit(cache=True)
def pinned_dynamics(z, x, Q, M, J, dV, pin):
    """dz/dt of the reduced dynamics with point ``pin`` held: ``q = Phi(z)``,
    ``dq = Jp dz``, ``qdd = Jp zdd + gam``; ``Jp^T M Jp zdd = Jp^T (Q - h - M gam)``, from
    the full state ``x``, its ``Q - h``, ``M`` and the points' ``J``, ``dV`` (the base's
    ``d = J.shape[1]`` slides eliminated)."""
    nq = M.shape[0]
    d = J.shape[1]
    m = nq - d
    Jp = np.zeros((nq, m))
    for k in range(m):
        for r in range(d):
            Jp[r, k] = -J[pin, r, d + k]
        Jp[d + k, k] = 1.0
    gam = np.zeros(nq)
    for r in range(d):
        s = 0.0
        for k in range(nq):
            s += dV[pin, r, k] * x[nq + k]
        gam[r] = -s
    rhs_q = Q.copy()
    for i in range(nq):
        for k in range(nq):
            rhs_q[i] -= M[i, k] * gam[k]
    MJ = np.zeros((nq, m))
    for i in range(nq):
        for c in range(m):
            for k in range(nq):
                MJ[i, c] += M[i, k] * Jp[k, c]
    r = np.zeros(m)
    Mr = np.zeros((m, m))
    for a in range(m):
        for i in range(nq):
            r[a] += Jp[i, a] * rhs_q[i]
            for c in range(m):
                Mr[a, c] += Jp[i, a] * MJ[i, c]
    zdd = chol_solve(chol(Mr), r.reshape((m, 1)))[:, 0]
    out = np.empty(2 * m)
    for k in range(m):
        out[k] = z[m + k]
        out[m + k] = zdd[k]
    return out


@njit(cache=True)
def contact_row(P, V, sp, cp, PC, c1, c2, point_leg, out, r, S):
    """Row ``r`` of the contact table ``out`` (n, nf, 8) (3D: (n, nf, 12)): per point
    penetration [m], its rate [m/s], slip velocity along the slope's fall line [m/s], s
    [m], Fn [N], Ff [N] (the friction along the fall line), power F . v (+ M spin) [W],
    on_ground; in 3D then the lateral slip velocity [m/s] and friction [N], the spin
    about the normal ``S`` (nf,) [rad/s] and the torsional friction moment [N m]."""
    for i in range(P.shape[0]):
        cen = c1 if point_leg[i] == 0 else c2
        d = P.shape[1]
        res = point(P[i, 0], P[i, 1], P[i, 2] if d == 3 else 0.0, V[i, 0], V[i, 1],
                    V[i, 2] if d == 3 else 0.0, sp, cp, PC, cen)
        for k in range(6):
            out[r, i, k] = res[k]
        F = world_force(np.array(res))
        power = 0.0
        for c in range(d):
            power += F[c] * V[i, c]
        if d == 3:   # the lateral slip and friction, the spin and its torsional moment
            m = twist(S[i], res[4], PC)
            power += m * S[i]
            out[r, i, 8] = res[12]
            out[r, i, 9] = res[13]
            out[r, i, 10] = S[i]
            out[r, i, 11] = m
        out[r, i, 6] = power
        s = res[3]
        hq = patch_height(s, cen, PC[I_HW], PC[I_CONT] > 0.5)  # NaN in a gap
        out[r, i, 7] = 1.0 if hq == hq else 0.0


@njit(cache=True)
def knee_row(x, nq, P, V, sp, cp, PC, c1, c2, out, r, knee_idx):
    """Row ``r`` of the knee table ``out`` (n, 2, 4): per knee extension [rad], its rate
    [rad/s], stop torque [N m] and the stop's power [W] (knee k's foot: point k; its
    thigh's and shank's coordinates ``knee_idx[k]``) of the state ``x`` (``nq``
    coordinates, then their rates)."""
    for k in range(2):
        cen = c1 if k == 0 else c2
        d = P.shape[1]
        delta = point(P[k, 0], P[k, 1], P[k, 2] if d == 3 else 0.0, V[k, 0], V[k, 1],
                      V[k, 2] if d == 3 else 0.0, sp, cp, PC, cen)[0]
        ext, rate, T, _, _ = knee(x, knee_idx[k, 0], knee_idx[k, 1], PC, delta, nq)
        out[r, k, 0] = ext
        out[r, k, 1] = rate
        out[r, k, 2] = T
        out[r, k, 3] = -T * rate
