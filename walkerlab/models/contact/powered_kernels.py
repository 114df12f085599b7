"""The powered contact walker's actuation kernels: the actuators' forces and powers from the
actuation block, numba, on arrays.

Internal module.  Everything is SI.  The forces of
:mod:`walkerlab.models.contact.powered_source` (the actuation block's layout ``A``, the
scratch ``S`` of one call: the generalised force ``S[:nq]``, the powers
``W = S[nq:nq + 10]``, the ghost swing foot ``S[nq + 10:nq + 12]``, the joint law's
positive and negative power ``S[nq + 12:nq + 14]``), taking arrays only; the
generated contact module of each walker structure calls its generated kinematics (``feet``,
``dyn``) and hands their arrays to these kernels, in the order of the actuators' sum
(joint torques, the ankle push-off, the push-off pulse, the held force:
:mod:`walkerlab.codegen.contact_glue`).  The joint torques' laws are those of
:mod:`walkerlab.codegen.torque_law` (:func:`~walkerlab.codegen.torque_law.law_torque`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

import walkerlab.models.contact._kernels  # noqa: F401  (numba's cache in the user cache)
from walkerlab.codegen.torque_law import HEAD, PLAIN, law_torque

#: Fixed fields of the actuation block before the work map.
A_HEAD = 36


@njit(cache=True, error_model='numpy')
def push_along_leg(P, V, J, push_leg, force, hip):
    """The generalised force (nq,) of a force ``force`` [N] at contact point ``push_leg``
    (its position ``P``, velocity ``V``, Jacobian ``J``) along the line from it to its
    leg's hip ``hip`` (d,) [m] (the hip point of a planar walker, the leg's own end of the
    hip axis of one with hip width), and its power [W]."""
    rr = hip - P[push_leg]
    e = rr / np.sqrt(np.dot(rr, rr))
    F = force * e
    Jt = np.ascontiguousarray(J[push_leg].T)
    return np.dot(Jt, F), np.dot(F, V[push_leg].copy())


@njit(cache=True, error_model='numpy')
def hip_torque_ledger(x, r, tab, has_tau, sw, st, tau, out):
    """:func:`walkerlab.models.contact.actuation.powered_rhs`'s hip torque: ``out[:nx]`` the
    passive rates ``r`` (nx,), ``out[nx:nx + 2]`` the torque's positive and negative power,
    ``out[nx + 3]`` the contact forces' (``tab`` the state's contact table (1, nf, 8)); the
    hip torque's generalised force (nq,) (+tau on ``sw``, -tau on ``st``)."""
    nx = r.shape[0]
    n = nx // 2
    for i in range(nx):
        out[i] = r[i]
    rest = 0.0  # numpy's sum of the column: the first entry, then the others from 0.0
    for i in range(1, tab.shape[1]):
        rest += tab[0, i, 6]
    p_contact = tab[0, 0, 6] + rest
    Q = np.zeros(n)
    p_tau = 0.0
    if has_tau:
        Q[sw] = Q[sw] + tau
        Q[st] = Q[st] - tau
        p_tau = tau * (x[n + sw] - x[n + st])
    out[nx] = 0.0 if 0.0 > p_tau else p_tau  # Python's max(p_tau, 0.0), min(p_tau, 0.0)
    out[nx + 1] = 0.0 if 0.0 < p_tau else p_tau
    out[nx + 3] = p_contact
    return Q


@njit(cache=True)
def moves(Q):
    """Whether the generalised force ``Q`` has a nonzero entry."""
    moved = False
    for i in range(Q.shape[0]):
        if Q[i] != 0.0:
            moved = True
    return moved


@njit(cache=True)
def at_rest(x, nq):
    """The state (2 nq,) with the coordinates of ``x`` and zero rates."""
    xz = np.zeros(2 * nq)
    xz[:nq] = x[:nq]
    return xz


@njit(cache=True, error_model='numpy')
def add_accelerations(M, Q, out):
    """``out[nq:2 nq] += M^-1 Q``."""
    n = Q.shape[0]
    a = np.linalg.solve(M, Q)
    for i in range(n):
        out[n + i] = out[n + i] + a[i]


@njit(cache=True, error_model='numpy')
def stance(t, A, nq):
    """The leg in stance (0: leg1, 1: leg2) at time ``t`` [s] and whether the heel strike
    of the block (``A[29]``) has passed; writes the law block's step start time."""
    k = int(A[2])
    st = int(A[28])
    switched = t >= A[29]
    if switched:  # the heel strike at A[29]: the other leg in stance
        st = 1 - st
    law = A[A_HEAD + int(A[27]) + 2 * nq * (k + 1):]
    law[2] = A[29] if switched else A[30]
    return st, switched


@njit(cache=True, error_model='numpy')
def virtual_leg_phase(x, A, P, V, c, nq):
    """The virtual stance leg's angle ``atan(-(hip - foot)_x / (hip - foot)_y)`` [rad] and
    its rate [rad/s], the stance foot contact point ``c`` (at ``P``, ``V``)."""
    rx = x[int(A[7])] - P[c, 0]
    ry = x[int(A[8])] - P[c, 1]
    vx = x[nq + int(A[7])] - V[c, 0]
    vy = x[nq + int(A[8])] - V[c, 1]
    return np.arctan(-rx / ry), -(vx * ry - rx * vy) / (rx * rx + ry * ry)


@njit(cache=True, error_model='numpy')
def joint_torques(t, x, A, S, st, s, ds, nq):
    """The joint torques' generalised force into ``S[:nq]`` and their positive and
    negative power into ``S[nq]``, ``S[nq + 1]``, leg ``st`` in stance, the phase ``s``
    [rad] and its rate ``ds`` [rad/s]."""
    n = nq
    k = int(A[2])
    bo = A_HEAD + int(A[27]) + st * n * k
    law = A[A_HEAD + int(A[27]) + 2 * n * (k + 1):]
    p_tau = 0.0
    for j in range(k):
        d = 0.0
        dd = 0.0
        for i in range(n):
            b = A[bo + i * k + j]
            if b != 0.0:
                d += b * x[i]
                dd += b * x[n + i]
        h = 3 + HEAD * j
        if law[h] == PLAIN:  # a spring-damper (the law kernel's formula, inline)
            tau = law[h + 1] - law[h + 2] * (d - law[h + 4]) - law[h + 3] * dd
            if tau > law[h + 5]:
                tau = law[h + 5]
            elif tau < -law[h + 5]:
                tau = -law[h + 5]
        else:
            tau = law_torque(law, j, d, dd, s, ds, t)[0]
        for i in range(n):
            S[i] += A[bo + i * k + j] * tau
        p_tau += tau * dd
    S[nq + 0] = p_tau if p_tau > 0.0 else 0.0
    S[nq + 1] = p_tau if p_tau < 0.0 else 0.0


@njit(cache=True, error_model='numpy')
def ankle_push_off(x, A, S, st, nq):
    """A flat foot's ankle push-off ``-K (a - a_0) - c`` on the stance ankle into ``S``
    and its positive and negative power into ``S[nq + 2]``, ``S[nq + 3]``."""
    n = nq
    f = int(A[10]) if st == 0 else int(A[32])
    lg = int(A[11]) if st == 0 else int(A[33])
    ta = -A[12] * (x[f] - x[lg] - A[13]) - A[14]
    S[f] += ta
    S[lg] -= ta
    pa = ta * (x[n + f] - x[n + lg])
    S[nq + 2] = pa if pa > 0.0 else 0.0
    S[nq + 3] = pa if pa < 0.0 else 0.0


@njit(cache=True, error_model='numpy')
def hold_ankle(x, A, M, Qp, pp):
    """The push-off pulse's force ``Qp`` (nq,) with the ankle torque that holds a flat
    foot's ankle (``A[16:18]``) through it, ``a M^-1 (Qp + a lam) = 0``, added in place;
    returns the pulse's power with the torque's."""
    n = Qp.shape[0]
    a = np.zeros(n)
    a[int(A[16])] = 1.0
    a[int(A[17])] = -1.0
    Ma = np.linalg.solve(M, a)
    lam = -np.dot(Ma, Qp) / np.dot(a, Ma)
    for i in range(n):
        Qp[i] += lam * a[i]
    return pp + lam * (x[n + int(A[16])] - x[n + int(A[17])])


@njit(cache=True, error_model='numpy')
def hold_row(M, Qp, pp, a, rate):
    """The push-off pulse's force ``Qp`` (nq,) with the generalised force ``lam a`` that
    holds the rate ``a @ dq`` (its value ``rate``) through it, ``a M^-1 (Qp + a lam) = 0``,
    added in place (a 3D walker's trailing foot holding its spin about the ground's
    normal: ``a`` the spin's Jacobian); returns the pulse's power with ``lam rate``."""
    n = Qp.shape[0]
    Ma = np.linalg.solve(M, a)
    lam = -np.dot(Ma, Qp) / np.dot(a, Ma)
    for i in range(n):
        Qp[i] += lam * a[i]
    return pp + lam * rate


@njit(cache=True, error_model='numpy')
def add_pulse(S, Qp, pp):
    """The push-off pulse's force into ``S[:nq]`` and its power into ``S[nq + 4]``."""
    n = Qp.shape[0]
    for i in range(n):
        S[i] += Qp[i]
    S[n + 4] = pp


@njit(cache=True, error_model='numpy')
def held_force_and_dampers(x, A, S, st, nq):
    """The generalised force held from outside (``A[34]``) into ``S`` with its positive and
    negative power, and the dampers' power (``A[26]``)."""
    n = nq
    if A[34] > 0.5:  # the held force
        k = int(A[2])
        eo = A_HEAD + int(A[27]) + 2 * n * k + st * n
        pe = 0.0
        for i in range(n):
            S[i] += A[eo + i]
            pe += A[eo + i] * x[n + i]
        S[nq + 8] = pe if pe > 0.0 else 0.0
        S[nq + 9] = pe if pe < 0.0 else 0.0
    if A[26] > 0.5:  # the dampers' power
        r1 = x[n + int(A[20])] - x[n + int(A[22])]
        r2 = x[n + int(A[21])] - x[n + int(A[23])]
        hp = x[n + int(A[25])] - x[n + int(A[24])]
        S[nq + 5] = -A[18] * (r1 * r1 + r2 * r2) - A[19] * hp * hp


@njit(cache=True, error_model='numpy')
def ghost_foot(t, A, S, nq):
    """The ghost swing foot into ``S[nq + 10:nq + 12]`` (``A[35] >= 0``: its ahead distance
    [m]): the swing leg's once the heel strike in the data (``A[29]``) has passed, or with
    none pending."""
    st = int(A[28])
    switched = t >= A[29]
    if switched:
        st = 1 - st
    S[nq + 10] = float(1 - st) if A[35] >= 0.0 and (switched or A[29] == np.inf) else -1.0
    S[nq + 11] = A[35]


@njit(cache=True, error_model='numpy')
def split_law_power(S, nq):
    """The joint laws' power of the flow (``S[nq + 7]``: a 3D walker's hip-roll law) split
    into its positive and negative parts, ``S[nq + 12]``, ``S[nq + 13]`` (the ledger's
    ``hip_roll_positive``, ``hip_roll_negative``: the rigid ledger's split)."""
    p = S[nq + 7]
    S[nq + 12] = p if p > 0.0 else 0.0
    S[nq + 13] = p if p < 0.0 else 0.0


@njit(cache=True, error_model='numpy')
def work_rates(A, S, dy, nq):
    """The work integrals' rates ``dy[2 nq:]``: the powers ``W`` the block's work map
    picks."""
    m = int(A[27])
    for j in range(m):
        dy[2 * nq + j] = S[nq + int(A[A_HEAD + j])]
