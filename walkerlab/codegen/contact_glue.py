"""The per-structure glue of a compliant-contact walker's generated module: the structure's
generated functions (``dyn``, ``dyn_jac``, ``feet``, ``feet_jac`` of
:mod:`walkerlab.codegen.floating`) evaluated and handed to the walker-independent kernels of
:mod:`walkerlab.models.contact.assembly`.

The glue holds no arithmetic of its own: each function allocates the arrays the generated
functions fill, calls them, and passes the arrays to a kernel (the Cholesky solve, the
contact forces, the Jacobian's assembly, the pinned dynamics, the tables).  It must be
generated per structure only because numba's on-disk cache cannot hold a kernel that takes
a compiled function as an argument; the kernels themselves are an ordinary module.

Generated functions (``x = [q, dq]`` (NX,)):

=======================================  =================================================
``_force(x, PC, p, c1, c2, use1, use2,   ``Q - h`` (NQ,), filling ``M`` and the points'
M, P, V, J, info, knees)``               arrays (``assembly.contact_q``)
``jac(x, PC, p, c1, c2)``                d rhs / dx (NX, NX) (``assembly.jac_assemble``)
``pinned_to_full(z, p, foot2)``          full state (NX,) of a pinned state
``rhs_pinned(z, PC, p, c1, c2, foot2)``  leg2's point PIN held: dz/dt
``contact_table(X, PC, p, c1, c2)``      (n, NF, 8) per point (``assembly.contact_row``)
``knee_table(X, PC, p, c1, c2)``         (n, 2, 4) per knee (``assembly.knee_row``)
``push_force(x, p, leg, F, hx, hy)``     a push-off force's generalised force and power
``powered_rhs(x, PC, p, c1, c2, ...)``   a powered walker's rhs and ledger powers
``packed_size(d)``, ``rhs_packed``       rhs from the packed data vector, counts calls
``build_cyrk()``, ``build_lsoda(sig)``   addresses of cfuncs of ``rhs_packed``
=======================================  =================================================
"""

from __future__ import annotations

__all__ = ["contact_glue_source"]

_HEAD = '''
# ---------------------------------------------------------------- contact assembly
# (walkerlab.codegen.contact_glue: this structure's functions handed to the kernels of
# walkerlab.models.contact.assembly)
from math import sin as _sin, cos as _cos
from walkerlab.models.contact.assembly import (  # noqa: F401
    I_PHI, I_K, I_E, I_CMAX, I_DMAX, I_MUS, I_MUD, I_VS, I_VD, I_HW, I_CONT, I_KK, I_KE,
    I_KC, I_KD, I_KL, I_KF, I_KA, NPC, D_N1, D_N2, D_PC, D_P, point as _point,
    knee_torque as _knee_torque, chol as _chol, chol_solve as _chol_solve,
    buffers as _buffers, contact_q as _contact_q, world_forces as _world_forces,
    jac_assemble as _jac_assemble, link_state as _link_state, place_pin as _place_pin,
    pinned_accelerations as _pinned_accelerations, contact_row as _contact_row,
    knee_row as _knee_row, push_q as _push_q, powered_q as _powered_q,
    powered_out as _powered_out)

NX = 2 * NQ
'''

_FORCE = '''
@njit(cache=True)
def _force(x, PC, p, c1, c2, use1, use2, M, P, V, J, info, knees):
    """Q - h (NQ,) with the contact forces of the legs' points used and the knee stops."""
    h = np.empty(NQ)
    dyn(x, p, M, h)
    feet(x, p, P, V, J)
    return _contact_q(x, PC, c1, c2, use1, use2, h, P, V, J, info, knees, POINT_LEG, KNEE)


@njit(cache=True)
def jac(x, PC, p, c1, c2):
    """Analytic d rhs / dx (NX, NX); patch membership locally constant."""
    M, P, V, J, info, knees = _buffers(NQ, NF)
    Q = _force(x, PC, p, c1, c2, True, True, M, P, V, J, info, knees)
    L = _chol(M)
    a = _chol_solve(L, Q.reshape((NQ, 1)))[:, 0]
    Dq = np.empty((NQ, NQ))
    Dv = np.empty((NQ, NQ))
    dyn_jac(x, a, p, Dq, Dv)
    F = _world_forces(info)
    dV = np.empty((NF, 2, NQ))
    dJtF = np.empty((NQ, NQ))
    feet_jac(x, F, p, dV, dJtF)
    return _jac_assemble(L, J, dV, dJtF, Dq, Dv, info, knees, KNEE)
'''

_PINNED = '''
@njit(cache=True)
def pinned_to_full(z, p, foot2):
    """Full state (NX,) with leg2's (first) contact point PIN at ``foot2`` (2,), at rest."""
    x = _link_state(z, NQ)
    P = np.empty((NF, 2))
    V = np.empty((NF, 2))
    J = np.empty((NF, 2, NQ))
    feet(x, p, P, V, J)  # hip at the origin, at rest: foot offset and velocity
    return _place_pin(x, P, V, foot2, PIN)


@njit(cache=True)
def rhs_pinned(z, PC, p, c1, c2, foot2):
    """Reduced dynamics with leg2's foot pinned (leg1 keeps its contact): dz/dt."""
    x = pinned_to_full(z, p, foot2)
    M, P, V, J, info, knees = _buffers(NQ, NF)
    Q = _force(x, PC, p, c1, c2, True, False, M, P, V, J, info, knees)
    dV = np.empty((NF, 2, NQ))
    dJtF = np.empty((NQ, NQ))
    feet_jac(x, np.zeros((NF, 2)), p, dV, dJtF)
    return _pinned_accelerations(z, x, Q, M, J, dV, PIN)
'''

_TABLES = '''
@njit(cache=True)
def contact_table(X, PC, p, c1, c2):
    """(n, NF, 8) per contact point (walkerlab.models.contact.assembly.contact_row)."""
    n = X.shape[0]
    out = np.zeros((n, NF, 8))
    sp, cp = _sin(PC[I_PHI]), _cos(PC[I_PHI])
    P = np.empty((NF, 2))
    V = np.empty((NF, 2))
    J = np.empty((NF, 2, NQ))
    for r in range(n):
        feet(X[r], p, P, V, J)
        _contact_row(out[r], P, V, sp, cp, PC, c1, c2, POINT_LEG)
    return out


@njit(cache=True)
def knee_table(X, PC, p, c1, c2):
    """(n, 2, 4) per knee (walkerlab.models.contact.assembly.knee_row)."""
    n = X.shape[0]
    out = np.zeros((n, 2, 4))
    P = np.empty((NF, 2))
    V = np.empty((NF, 2))
    J = np.empty((NF, 2, NQ))
    sp, cp = _sin(PC[I_PHI]), _cos(PC[I_PHI])
    if KNEE:
        for r in range(n):
            feet(X[r], p, P, V, J)
            _knee_row(out[r], X[r], P, V, sp, cp, PC, c1, c2)
    return out
'''

_POWERED = '''
@njit(cache=True, error_model='numpy')
def push_force(x, p, push_leg, force, hx, hy):
    """The generalised force (NQ,) and power [W] of a push-off force at point push_leg."""
    P = np.empty((NF, 2))
    V = np.empty((NF, 2))
    J = np.empty((NF, 2, NQ))
    feet(x, p, P, V, J)
    return _push_q(x, P, V, J, push_leg, force, hx, hy)


@njit(cache=True, error_model='numpy')
def powered_rhs(x, PC, p, c1, c2, has_tau, sw, st, tau, push_leg, force, hx, hy, out):
    """A powered walker's rhs and ledger powers into ``out`` (NX + 4,)."""
    r = rhs(x, PC, p, c1, c2)
    tab = contact_table(x.reshape((1, NX)), PC, p, c1, c2)
    Qp = np.zeros(NQ)
    p_po = 0.0
    if push_leg >= 0:
        Qp, p_po = push_force(x, p, push_leg, force, hx, hy)
    Q, p_tau, moved = _powered_q(x, NQ, has_tau, sw, st, tau, push_leg >= 0, Qp)
    M = np.empty((NQ, NQ))
    if moved:
        xz = np.zeros(NX)
        xz[:NQ] = x[:NQ]
        h = np.empty(NQ)
        dyn(xz, p, M, h)
    _powered_out(r, tab, Q, p_tau, moved, p_po, M, out)
'''

_PACKED = '''
@njit(cache=True)
def packed_size(d):
    """Length of the data vector (``d`` may be a raw pointer in a cfunc)."""
    return D_P + NP + int(d[D_N1]) + int(d[D_N2]) + 1


@njit(cache=True)
def rhs_packed(y, d, dy):
    """rhs of ``y`` (NX,) unpacked from the data vector ``d`` into ``dy``; counts the call."""
    a1 = D_P + NP
    a2 = a1 + int(d[D_N1])
    r = rhs(y, d[D_PC:D_P], d[D_P:a1], d[a1:a2], d[a2:d.size - 1])
    for i in range(NX):
        dy[i] = r[i]
    d[d.size - 1] += 1.0


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


def contact_glue_source() -> str:
    """The glue's source (module docstring), appended to a structure's generated floating
    module and its constants (``NQ``, ``NP``, ``NF``, ``KNEE``, ``POINT_LEG``, ``PIN``) by
    :func:`walkerlab.models.contact.generated.contact_source`."""
    return "\n".join((_HEAD, _FORCE, _PINNED, _TABLES, _POWERED, _PACKED))
