"""The compiled right-hand side of a powered contact walker: the actuation as data.

Every actuated contact walker (straight or kneed legs; point, arc or flat feet; a torso; a
free-jointed biped) runs on one compiled right-hand side, ``powered_packed``, appended to its
generated contact module (:mod:`walkerlab.models.contact.generated`): the walker's own
straight-line dynamics with a generalised force added (``rhs_q``) and, in the same call, the
forces of its actuators computed from an *actuation block* of numbers in the data vector.
The block says everything a run's discrete state changes (which leg is in stance, when the
step began, whether a push-off pulse or an ankle push-off is on), so the event loop
(:mod:`walkerlab.integrate.contact_powered`) changes numbers between its events and never
calls Python inside a step.

The forces are those of :func:`walkerlab.models.contact.actuation.powered_rhs` (the
reference arithmetic; a test holds the two equal on every kind of walker):

- joint torques ``tau_k`` of the laws of :mod:`walkerlab.codegen.torque_law` (plain
  spring-dampers, phase and time tables, the replays' feed-forward laws; saturation), at
  the joint angles ``delta = B^T q`` (``B`` (nq, k) the stance's joint columns: ``+1`` on a
  joint's second link, ``-1`` on its first, ``1/2`` on each leg for a bisecting torso) and
  the phase variable ``s``: a coordinate (the stance leg's or stance thigh's angle), or the
  virtual stance leg's angle ``atan(-(hip - foot)_x / (hip - foot)_y)`` of a free-jointed
  biped (Westervelt, Grizzle & Koditschek 2003); ``Q += B tau``, power ``tau . d delta/dt``;
- a flat foot's ankle push-off ``tau_a = -K (a - a_0) - c`` on ``(foot, leg)`` while on;
- the push-off pulse: a force ``F e`` at the trailing foot's push point along the line to
  the hip, ``Q += J^T F e`` (on a flat foot with the ankle torque ``lam`` that holds the
  ankle: ``a M^-1 (J^T F e + a lam) = 0``);
- a generalised force held from outside (a Gymnasium action's torques, per stance leg),
  power ``E . dq``;
- the ledger's powers: ``W = [tau+, tau-, ankle+, ankle-, push, damper, contact, knee,
  action+, action-]``, of which the block's work map picks the run's work integrals in
  order.

The actuation block ``A`` (after the passive data ``[n1, n2, PC, p, c1, c2]``; then the call
counter):

=============  =============================================================================
``A[0]``       the block's length
``A[1]``       nq
``A[2]``       k, the number of joint torques
``A[3]``       phase mode: 0 a coordinate, 1 the virtual stance leg
``A[4]``       the phase's coordinate (mode 0) or the stance foot's contact point (mode 1)
               with leg1 in stance (``A[31]`` with leg2)
``A[5]``       the push-off pulse's contact point (-1: no pulse on)
``A[6]``       the pulse's force [N]
``A[7:9]``     the hip's position coordinates
``A[9]``       the ankle push-off is on (0/1)
``A[10:12]``   the stance ankle's foot and leg coordinates with leg1 in stance (``A[32:34]``
               with leg2)
``A[12:15]``   the ankle push-off's stiffness [N m/rad], rest angle [rad], constant [N m]
``A[15]``      the pulse holds a flat foot's ankle (0/1), ``A[16:18]`` its foot and leg
``A[18:20]``   the ankle dampers' and the leg springs' damping [N m s/rad]
``A[20:26]``   feet (2), ankle legs (2), legs (2) coordinates of the dampers' power
``A[26]``      the ledger has the dampers' term (0/1)
``A[27]``      m, the number of work integrals; ``A[34:34 + m]`` their indices in ``W``
``A[28]``      the stance leg (0: leg1, 1: leg2) before the switch time
``A[29]``      the switch time [s] (inf: none): from it the other leg is in stance, its step
               begun then, the ankle push-off off (a heel strike located in advance, so the
               solver meets it warm: :mod:`walkerlab.integrate.compiled_segments`)
``A[30]``      the time [s] the present step began (before the switch)
``A[34]``      a held generalised force is on (0/1)
``A[35]``      the ghost swing foot: its points at least ``A[35]`` [m] ahead of the stance
               foot's carry no contact force (< 0: none; :func:`rhs_q`'s ``G``), the swing
               leg's once the heel strike in the data has passed, or with none pending
then           ``B`` with leg1 in stance, then with leg2 (nq * k each, row-major), the held
               force ``E`` with leg1 in stance, then with leg2 (nq each), then the law block
               (its ``b[2]``, the time the step began, written by each call)
=============  =============================================================================

After the block, ``nq + 12`` numbers of scratch (the force, the powers and the ghost
swing foot of one call: the right-hand side allocates nothing), then the call counter.
"""

from __future__ import annotations

__all__ = ["A_HEAD", "CYRK_POWERED_SOURCE", "W_INDEX", "powered_source"]

#: Fixed fields of the actuation block before the work map (module docstring).
A_HEAD = 36
#: Index in the powers ``W`` of each work integral's name.
W_INDEX = {"hip_torque_positive": 0, "hip_torque_negative": 1, "ankle_torque_positive": 2,
           "ankle_torque_negative": 3, "push_off": 4, "damper": 5, "contact": 6,
           "knee_stop": 7, "action_positive": 8, "action_negative": 9}

_SOURCE = '''
# ---------------------------------------------------------------- powered walker
# (walkerlab.models.contact.powered_source: walker-independent; the actuation as data)
A_HEAD = 36


@njit(cache=True, error_model='numpy')
def _phase(x, A, p, st):
    """The phase variable [rad] and its rate [rad/s] with leg ``st`` in stance: a
    coordinate, or the virtual stance leg's angle, ``atan(-(hip - foot)_x / (hip - foot)_y)``."""
    n = NQ
    c = int(A[4]) if st == 0 else int(A[31])
    if A[3] < 0.5:
        return x[c], x[n + c]
    P = np.empty((NF, 2))
    V = np.empty((NF, 2))
    J = np.empty((NF, 2, n))
    feet(x, p, P, V, J)
    rx = x[int(A[7])] - P[c, 0]
    ry = x[int(A[8])] - P[c, 1]
    vx = x[n + int(A[7])] - V[c, 0]
    vy = x[n + int(A[8])] - V[c, 1]
    return np.arctan(-rx / ry), -(vx * ry - rx * vy) / (rx * rx + ry * ry)


@njit(cache=True, error_model='numpy')
def _pulse(x, A, p, S):
    """The push-off pulse's force into ``S[:NQ]`` and its power into ``S[NQ + 4]``."""
    n = NQ
    Qp, pp = push_force(x, p, int(A[5]), A[6], int(A[7]), int(A[8]))
    if A[15] > 0.5:  # a flat foot's ankle holds through the pulse
        a = np.zeros(n)
        a[int(A[16])] = 1.0
        a[int(A[17])] = -1.0
        xz = np.zeros(NX)
        xz[:n] = x[:n]
        M = np.empty((n, n))
        h = np.empty(n)
        dyn(xz, p, M, h)
        Ma = np.linalg.solve(M, a)
        lam = -np.dot(Ma, Qp) / np.dot(a, Ma)
        for i in range(n):
            Qp[i] += lam * a[i]
        pp += lam * (x[n + int(A[16])] - x[n + int(A[17])])
    for i in range(n):
        S[i] += Qp[i]
    S[NQ + 4] = pp


@njit(cache=True, error_model='numpy')
def actuate(t, x, A, p, S):
    """The actuators' generalised force into ``S[:NQ]`` and the powers ``W`` into
    ``S[NQ:NQ + 10]`` at the time ``t`` [s] and state ``x`` from the actuation block ``A``
    (module docstring)."""
    n = NQ
    k = int(A[2])
    st = int(A[28])
    switched = t >= A[29]
    if switched:  # the heel strike at A[29]: the other leg in stance
        st = 1 - st
    bo = A_HEAD + int(A[27]) + st * n * k
    eo = A_HEAD + int(A[27]) + 2 * n * k + st * n
    law = A[A_HEAD + int(A[27]) + 2 * n * (k + 1):]
    law[2] = A[29] if switched else A[30]
    if k > 0:
        s, ds = _phase(x, A, p, st)
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
        S[NQ + 0] = p_tau if p_tau > 0.0 else 0.0
        S[NQ + 1] = p_tau if p_tau < 0.0 else 0.0
    if A[9] > 0.5 and not switched:  # the ankle push-off
        f = int(A[10]) if st == 0 else int(A[32])
        lg = int(A[11]) if st == 0 else int(A[33])
        ta = -A[12] * (x[f] - x[lg] - A[13]) - A[14]
        S[f] += ta
        S[lg] -= ta
        pa = ta * (x[n + f] - x[n + lg])
        S[NQ + 2] = pa if pa > 0.0 else 0.0
        S[NQ + 3] = pa if pa < 0.0 else 0.0
    if A[5] >= 0.0:
        _pulse(x, A, p, S)
    if A[34] > 0.5:  # the held force
        pe = 0.0
        for i in range(n):
            S[i] += A[eo + i]
            pe += A[eo + i] * x[n + i]
        S[NQ + 8] = pe if pe > 0.0 else 0.0
        S[NQ + 9] = pe if pe < 0.0 else 0.0
    if A[26] > 0.5:  # the dampers' power
        r1 = x[n + int(A[20])] - x[n + int(A[22])]
        r2 = x[n + int(A[21])] - x[n + int(A[23])]
        hp = x[n + int(A[25])] - x[n + int(A[24])]
        S[NQ + 5] = -A[18] * (r1 * r1 + r2 * r2) - A[19] * hp * hp
'''

#: ``build_cyrk_powered()``: the address of a CyRK ``cyjit_sig`` cfunc of the module's
#: ``powered_packed`` (a generated contact module's, and the virtual constraints' right-hand
#: side's, :mod:`walkerlab.models.contact.virtual_constraints`)
CYRK_POWERED_SOURCE = '''def build_cyrk_powered():
    """Address of a CyRK ``cyjit_sig`` cfunc of powered_packed (numba disk cache)."""
    from CyRK.nb.numba_solver import cyjit_sig
    from numba import carray, cfunc

    @cfunc(cyjit_sig, cache=True)
    def rhs_c(dy, t, y, d):  # pragma: no cover - runs compiled
        dd = carray(d, (powered_size(d),))
        ny = powered_ny(dd)
        powered_packed(t, carray(y, (ny,)), dd, carray(dy, (ny,)))

    return rhs_c.address
'''

_PACKED = '''

@njit(cache=True, error_model='numpy')
def powered_packed(t, y, d, dy):
    """dy/dt of a powered walker's state and work integrals from the data vector ``d``
    (``[n1, n2, PC, p, c1, c2, A, scratch (NQ + 12), calls]``); counts the call in
    ``d[-1]``."""
    a1 = D_P + NP
    a2 = a1 + int(d[D_N1])
    a3 = a2 + int(d[D_N2])
    la = int(d[a3])
    A = d[a3:a3 + la]
    p = d[D_P:a1]
    # scratch in the data vector (no allocation per call): the force Q (NQ), the powers W
    # (10), the ghost swing foot G (2)
    S = d[a3 + la:a3 + la + NQ + 12]
    for i in range(NQ + 10):
        S[i] = 0.0
    actuate(t, y, A, p, S)
    # the ghost swing foot (A[35] >= 0: its ahead distance [m]): the swing leg's once the
    # heel strike in the data (A[29]) has passed, or with none pending
    st = int(A[28])
    switched = t >= A[29]
    if switched:
        st = 1 - st
    S[NQ + 10] = float(1 - st) if A[35] >= 0.0 and (switched or A[29] == np.inf) else -1.0
    S[NQ + 11] = A[35]
    rhs_q(y, d[D_PC:D_P], p, d[a1:a2], d[a2:a3], S, dy)
    m = int(A[27])
    for j in range(m):
        dy[NX + j] = S[NQ + int(A[A_HEAD + j])]
    d[d.size - 1] += 1.0


@njit(cache=True)
def powered_size(d):
    """Length of a powered data vector (``d`` may be a raw pointer in a cfunc)."""
    a3 = D_P + NP + int(d[D_N1]) + int(d[D_N2])
    return a3 + int(d[a3]) + NQ + 12 + 1


@njit(cache=True)
def powered_ny(d):
    """The state's length of a powered data vector: NX and the work integrals."""
    a3 = D_P + NP + int(d[D_N1]) + int(d[D_N2])
    return NX + int(d[a3 + 27])


''' + CYRK_POWERED_SOURCE


def powered_source() -> str:
    """The source appended to every generated contact module: the law kernels of
    :mod:`walkerlab.codegen.torque_law` (:func:`~walkerlab.codegen.torque_law.kernel_source`),
    ``actuate`` (the actuators' forces and powers from the actuation block),
    ``powered_packed`` (the powered right-hand side from the data vector) and
    ``build_cyrk_powered`` (its CyRK cfunc's address)."""
    from walkerlab.codegen.torque_law import kernel_source

    return "\n".join(kernel_source()) + _SOURCE + _PACKED
