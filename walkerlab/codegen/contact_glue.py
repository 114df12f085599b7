"""The per-structure glue of a compliant-contact walker's generated module: short numba
functions that call the structure's generated kinematics (``dyn``, ``dyn_jac``, ``feet``,
``feet_jac`` of :mod:`walkerlab.codegen.floating`, and the straight-line ``rhs``,
``rhs_q``) and hand their arrays to the walker-independent kernels of
:mod:`walkerlab.models.contact.assembly` (contact forces, knee stops, solves, tables) and
:mod:`walkerlab.models.contact.powered_kernels` (the actuators' forces and powers).

The glue is text because numba needs the generated functions as globals of the functions
that call them (a compiled function passed as an argument defeats numba's disk cache); it
holds no arithmetic of its own beyond indexing.  :func:`contact_glue` is appended to the
floating module by :func:`walkerlab.models.contact.generated.contact_source`, which also
defines the constants it reads (``NQ``, ``NP``, ``NF``, ``KNEE``, ``KNEES``, ``POINT_LEG``,
``PIN``).
"""

from __future__ import annotations

__all__ = ["CYRK_POWERED_SOURCE", "contact_glue", "powered_glue"]

_HEAD = '''
# ---------------------------------------------------------------- contact assembly
# (walker-independent kernels: walkerlab.models.contact.assembly and .powered_kernels;
# this glue hands them the generated kinematics: walkerlab.codegen.contact_glue)
from math import sin as _sin, cos as _cos
from walkerlab.models.contact import assembly as _asm
from walkerlab.models.contact import powered_kernels as _pk
from walkerlab.models.contact._kernels import (normal_force, friction_mu, patch_height,
                                               step, ground_line)
from walkerlab.models.contact.assembly import (I_PHI, I_K, I_E, I_CMAX, I_DMAX, I_MUS,
                                               I_MUD, I_VS, I_VD, I_HW, I_CONT, I_KK, I_KE,
                                               I_KC, I_KD, I_KL, I_KF, I_KA, I_TOR, I_WEPS, NPC,
                                               D_N1, D_N2, D_PC, D_P)
from walkerlab.models.contact.assembly import chol as _chol, chol_solve as _chol_solve
from walkerlab.models.contact.assembly import point as _point, knee_torque as _knee_torque
from walkerlab.models.contact.assembly import twist as _twist
from walkerlab.models.contact.powered_kernels import A_HEAD
from walkerlab.codegen.torque_law import HEAD

NX = 2 * NQ
'''

_FORCE = '''

@njit(cache=True)
def _force(x, PC, p, c1, c2, use1, use2, M, P, V, J, info, knees):
    """Q - h (NQ,) with the contact forces of the legs' points used and the knee stops;
    fills M, the points' P, V, J, per-point ``info`` (NF, NINFO) and ``knees`` (2, 5)."""
    h = np.empty(NQ)
    dyn(x, p, M, h)
    feet(x, p, P, V, J)
    Q = _asm.contact_forces(x, h, PC, c1, c2, use1, use2, P, V, J, info, knees,
                            POINT_LEG, KNEE, KNEES)
    if DIM == 3:  # the contact patches' torsional friction (the analytic Jacobian holds
        # it constant)
        S, Jn = np.empty(NF), np.empty((NF, NQ))
        spins(x, p, S, Jn)
        _asm.add_twists(Q, info, S, Jn, PC)
    return Q


@njit(cache=True)
def jac(x, PC, p, c1, c2):
    """Analytic d rhs / dx (NX, NX); patch membership locally constant."""
    M, P, V, J, info, knees = _asm.buffers(NQ, NF, DIM)
    Q = _force(x, PC, p, c1, c2, True, True, M, P, V, J, info, knees)
    L = _chol(M)
    a = _chol_solve(L, Q.reshape((NQ, 1)))[:, 0]
    Dq = np.empty((NQ, NQ))
    Dv = np.empty((NQ, NQ))
    dyn_jac(x, a, p, Dq, Dv)
    dV = np.empty((NF, DIM, NQ))
    dJtF = np.empty((NQ, NQ))
    feet_jac(x, _asm.world_forces(info, DIM), p, dV, dJtF)
    return _asm.jac_assembly(L, Dq, Dv, dJtF, J, dV, info, knees, KNEE, KNEES)
'''

_PINNED = '''

@njit(cache=True)
def pinned_to_full(z, p, foot2):
    """Full state (NX,) with leg2's (first) contact point PIN at ``foot2`` (DIM,) and at
    rest; ``z = [the coordinates after the base's DIM slides, their rates]``."""
    x = _asm.pinned_angles(z, NQ, DIM)
    P, V, J = _asm.point_buffers(NQ, NF, DIM)
    feet(x, p, P, V, J)  # hip at the origin, at rest: foot offset and velocity
    _asm.pin_at(x, P, V, PIN, foot2)
    return x


@njit(cache=True)
def rhs_pinned(z, PC, p, c1, c2, foot2):
    """Reduced dynamics with leg2's foot pinned (leg1 keeps its contact)."""
    x = pinned_to_full(z, p, foot2)
    M, P, V, J, info, knees = _asm.buffers(NQ, NF, DIM)
    Q = _force(x, PC, p, c1, c2, True, False, M, P, V, J, info, knees)
    dV = np.empty((NF, DIM, NQ))
    dJtF = np.empty((NQ, NQ))
    feet_jac(x, np.zeros((NF, DIM)), p, dV, dJtF)
    return _asm.pinned_dynamics(z, x, Q, M, J, dV, PIN)
'''

_TABLES = '''

@njit(cache=True)
def contact_table(X, PC, p, c1, c2):
    """(n, NF, 8) (3D: (n, NF, 12)): per contact point penetration [m], its rate [m/s],
    slip velocity [m/s], s [m], Fn [N], Ff [N], power F . v [W], on_ground (1/0); in 3D
    then the lateral slip velocity [m/s] and friction [N], the spin about the normal
    [rad/s] and the torsional friction moment [N m] (``assembly.contact_row``)."""
    out = np.zeros((X.shape[0], NF, 8 if DIM == 2 else 12))
    sp, cp = _asm.slope(PC)
    P, V, J = _asm.point_buffers(NQ, NF, DIM)
    S, Jn = np.zeros(NF), np.empty((NF, NQ))
    for r in range(X.shape[0]):
        feet(X[r], p, P, V, J)
        if DIM == 3:
            spins(X[r], p, S, Jn)
        _asm.contact_row(P, V, sp, cp, PC, c1, c2, POINT_LEG, out, r, S)
    return out


@njit(cache=True)
def knee_table(X, PC, p, c1, c2):
    """(n, 2, 4): per knee extension [rad], its rate [rad/s], stop torque [N m] and the
    stop's power [W] (zeros without knee stops)."""
    out = np.zeros((X.shape[0], 2, 4))
    if KNEE:
        sp, cp = _asm.slope(PC)
        P, V, J = _asm.point_buffers(NQ, NF, DIM)
        for r in range(X.shape[0]):
            feet(X[r], p, P, V, J)
            _asm.knee_row(X[r], NQ, P, V, sp, cp, PC, c1, c2, out, r, KNEES)
    return out
'''

_PACKED = '''

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
'''

_POWERED_RHS = '''

@njit(cache=True, error_model='numpy')
def push_force(x, p, push_leg, force):
    """The generalised force (NQ,) of a force ``force`` [N] at contact point ``push_leg``
    along the line from it to its leg's hip (``hips``), and its power [W]."""
    P, V, J = _asm.point_buffers(NQ, NF, DIM)
    feet(x, p, P, V, J)
    H = np.empty((3, DIM))
    HV = np.empty((3, DIM))
    hips(x, p, H, HV)
    return _pk.push_along_leg(P, V, J, push_leg, force, H[1 + POINT_LEG[push_leg]])


@njit(cache=True, error_model='numpy')
def powered_rhs(x, PC, p, c1, c2, has_tau, sw, st, tau, push_leg, force, out):
    """A powered walker's right-hand side with its ledger's powers, into ``out``
    (NX + 4,): ``[dx, hip torque's positive and negative power, push-off's, contact
    forces']`` (:func:`walkerlab.models.contact.actuation.powered_rhs`'s arithmetic)."""
    r = rhs(x, PC, p, c1, c2)
    tab = contact_table(x.reshape((1, NX)), PC, p, c1, c2)
    Q = _pk.hip_torque_ledger(x, r, tab, has_tau, sw, st, tau, out)
    p_po = 0.0
    if push_leg >= 0:
        Qp, p_po = push_force(x, p, push_leg, force)
        Q = Q + Qp
    out[NX + 2] = p_po
    if _pk.moves(Q):
        M = np.empty((NQ, NQ))
        h = np.empty(NQ)
        dyn(_pk.at_rest(x, NQ), p, M, h)
        _pk.add_accelerations(M, Q, out)
'''

_CFUNCS = '''

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

_ACTUATE = '''

@njit(cache=True, error_model='numpy')
def _phase(x, A, p, st):
    """The phase variable [rad] and its rate [rad/s] with leg ``st`` in stance: a
    coordinate, or the virtual stance leg's angle."""
    c = int(A[4]) if st == 0 else int(A[31])
    if A[3] < 0.5:
        return x[c], x[NQ + c]
    P, V, J = _asm.point_buffers(NQ, NF, DIM)
    feet(x, p, P, V, J)
    return _pk.virtual_leg_phase(x, A, P, V, c, NQ)


@njit(cache=True, error_model='numpy')
def _pulse(x, A, p, S):
    """The push-off pulse's force into ``S[:NQ]`` and its power into ``S[NQ + 4]``."""
    Qp, pp = push_force(x, p, int(A[5]), A[6])
    if A[15] > 1.5:  # a 3D walker's trailing foot holds its spin through the pulse
        M = np.empty((NQ, NQ))
        h = np.empty(NQ)
        dyn(_pk.at_rest(x, NQ), p, M, h)
        Sn = np.empty(NF)
        Jn = np.empty((NF, NQ))
        spins(x, p, Sn, Jn)
        k = int(A[5])
        pp = _pk.hold_row(M, Qp, pp, Jn[k].copy(), Sn[k])
    elif A[15] > 0.5:  # a flat foot's ankle holds through the pulse
        M = np.empty((NQ, NQ))
        h = np.empty(NQ)
        dyn(_pk.at_rest(x, NQ), p, M, h)
        pp = _pk.hold_ankle(x, A, M, Qp, pp)
    _pk.add_pulse(S, Qp, pp)


@njit(cache=True, error_model='numpy')
def actuate(t, x, A, p, S):
    """The actuators' generalised force into ``S[:NQ]`` and the powers ``W`` into
    ``S[NQ:NQ + 10]`` at the time ``t`` [s] and state ``x`` from the actuation block ``A``
    (:mod:`walkerlab.models.contact.powered_source`)."""
    st, switched = _pk.stance(t, A, NQ)
    if int(A[2]) > 0:
        s, ds = _phase(x, A, p, st)
        _pk.joint_torques(t, x, A, S, st, s, ds, NQ)
    if A[9] > 0.5 and not switched:  # the ankle push-off
        _pk.ankle_push_off(x, A, S, st, NQ)
    if A[5] >= 0.0:
        _pulse(x, A, p, S)
    _pk.held_force_and_dampers(x, A, S, st, NQ)
'''

_POWERED_PACKED = '''

@njit(cache=True, error_model='numpy')
def powered_packed(t, y, d, dy):
    """dy/dt of a powered walker's state and work integrals from the data vector ``d``
    (``[n1, n2, PC, p, c1, c2, A, scratch (NQ + 14), calls]``); counts the call in
    ``d[-1]``."""
    a1 = D_P + NP
    a2 = a1 + int(d[D_N1])
    a3 = a2 + int(d[D_N2])
    la = int(d[a3])
    A = d[a3:a3 + la]
    p = d[D_P:a1]
    # scratch in the data vector (no allocation per call): the force Q (NQ), the powers W
    # (10), the ghost swing foot G (2), the joint law's positive and negative power (2)
    S = d[a3 + la:a3 + la + NQ + 14]
    for i in range(NQ + 10):
        S[i] = 0.0
    actuate(t, y, A, p, S)
    _pk.ghost_foot(t, A, S, NQ)
    rhs_q(y, d[D_PC:D_P], p, d[a1:a2], d[a2:a3], S, dy)
    _pk.split_law_power(S, NQ)
    _pk.work_rates(A, S, dy, NQ)
    d[d.size - 1] += 1.0


@njit(cache=True)
def powered_size(d):
    """Length of a powered data vector (``d`` may be a raw pointer in a cfunc)."""
    a3 = D_P + NP + int(d[D_N1]) + int(d[D_N2])
    return a3 + int(d[a3]) + NQ + 14 + 1


@njit(cache=True)
def powered_ny(d):
    """The state's length of a powered data vector: NX and the work integrals."""
    a3 = D_P + NP + int(d[D_N1]) + int(d[D_N2])
    return NX + int(d[a3 + 27])

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


def contact_glue() -> str:
    """The glue of the passive model: imports of the kernels and the contact parameters'
    indices, ``_force``, ``jac``, ``pinned_to_full``, ``rhs_pinned``, ``contact_table``,
    ``knee_table``, ``packed_size``, ``rhs_packed``, ``push_force``, ``powered_rhs``,
    ``build_cyrk`` and ``build_lsoda`` (their contracts:
    :mod:`walkerlab.models.contact.generated`)."""
    return _HEAD + _FORCE + _PINNED + _TABLES + _PACKED + _POWERED_RHS + _CFUNCS


def powered_glue() -> str:
    """The glue of the powered model: ``actuate`` (the actuators' forces and powers from
    the actuation block), ``powered_packed`` (the powered right-hand side from the data
    vector), ``powered_size``, ``powered_ny`` and ``build_cyrk_powered`` (its CyRK cfunc's
    address); :mod:`walkerlab.models.contact.powered_source`."""
    return _ACTUATE + _POWERED_PACKED + CYRK_POWERED_SOURCE
