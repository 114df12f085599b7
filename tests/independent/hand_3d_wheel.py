"""The 3D spoked wheel (Coleman, Chatterjee & Ruina 1997, "Motions of a rimless spoked wheel:
a simple three-dimensional system with impacts", Dynamics and Stability of Systems 12(3))
derived by hand from its kinetic energy, as walkerlab derived it before the body tree (kept
as an independent reference for the tree's derivation,
``walkerlab.codegen.derive_3d.derive_spoked``; not walkerlab code: its own rotations, its own
Christoffel symbols, the impact as the angular momentum about the new foot conserved).

The wheel: a hub of mass ``M``, inertia ``I_hub`` about its axle and ``I_diam`` about any
diameter, ``n`` massless spokes of length ``L``, ``2 alpha`` apart; orientation
``R = Rot(n, psi) Rot(s, phi) Rot(z, theta)`` (heading, lean, spin from the downward
vertical); ``T = [(M L^2 + I_diam) |omega|^2 - M (omega . r_hub)^2 + (I_hub - I_diam)
(omega . a)^2] / 2`` about the fixed foot (König), ``V = M g y_hub``.
"""

from __future__ import annotations

from types import SimpleNamespace

import sympy as sp

from tests.independent.hand_3d_compass import christoffel, rotation


def _cross(a: sp.Matrix, b: sp.Matrix) -> sp.Matrix:
    return sp.Matrix(a).cross(sp.Matrix(b))


def _dot(a: sp.Matrix, b: sp.Matrix):
    return (sp.Matrix(a).T * sp.Matrix(b))[0]


def _spoke(theta_offset, L) -> sp.Matrix:
    """A spoke from the hub in the wheel's frame at ``theta_offset`` from the stance spoke:
    ``Rot(z, theta_offset) (0, -L, 0)``."""
    return sp.Matrix([L * sp.sin(theta_offset), -L * sp.cos(theta_offset), 0])


def _spoked_impact(W, hub, spin, par):
    """The spoked wheel's impact (:func:`derive_spoked`): ``Mi dq+ = B dq-``, the angular
    momentum about the new foot conserved (``Mi``: rotating about it, ``B``: the motion
    about the old foot), in the frame ``A`` of heading and lean (``omega_A = W dq``; ``hub``
    the hub in it, ``spin`` the wheel's rotation by its angle; ``par`` the parameters).

    Returns
    -------
    Mi, B : sympy.Matrix (3, 3)
    """
    _g, L, _gamma, m, I_axle, alpha, I_diam = par
    ez = sp.Matrix([0, 0, 1])
    d = -spin * _spoke(2 * alpha, L)                       # new foot -> hub (A's frame)

    def inertia_cm(w):  # I_cm w, the axisymmetric hub
        return I_diam * w + (I_axle - I_diam) * w[2] * ez

    def h_after(w):  # angular momentum about the new foot, rotating about it at w
        return inertia_cm(w) + m * _cross(d, _cross(w, d))

    def h_before(w):  # ... of the motion about the old foot at w (hub velocity w x hub)
        return inertia_cm(w) + m * _cross(d, _cross(w, hub))

    cols = [W[:, j] for j in range(3)]
    Mi = (W.T * sp.Matrix.hstack(*[h_after(c) for c in cols])).applyfunc(sp.trigsimp)
    B = (W.T * sp.Matrix.hstack(*[h_before(c) for c in cols])).applyfunc(sp.trigsimp)
    return Mi, B


def derive_spoked(structure) -> SimpleNamespace:
    """The 3D spoked wheel's flow, impact, guards, energies and points (module docstring),
    the fields of ``walkerlab.codegen.equations.Equations``, for a structure with ``spokes``
    and ``in_3d``."""
    if not (structure.spokes and structure.in_3d):
        raise ValueError("derive_3d.derive_spoked: the structure is not a 3D spoked wheel")
    psi, phi, th = sp.symbols("q_heading q_lean q_stance", real=True)
    dpsi, dphi, dth = sp.symbols("dq_heading dq_lean dq_stance", real=True)
    q, dq = (psi, phi, th), (dpsi, dphi, dth)
    par = sp.symbols(structure.param_names, real=True)
    g, L, gamma, m, I_axle, alpha, I_diam = par
    nrm = sp.Matrix([sp.sin(gamma), sp.cos(gamma), 0])
    fall = sp.Matrix([sp.cos(gamma), -sp.sin(gamma), 0])
    ez = sp.Matrix([0, 0, 1])
    A = rotation(nrm, psi) * rotation(fall, phi)          # heading, then lean
    # vectors in A's frame (the wheel's plane spun by theta): the energies and the impact
    # are invariant under the rotation A, and read shortest there
    spin = rotation(ez, th)
    W = sp.Matrix.hstack(rotation(fall, -phi) * nrm, fall, ez)   # omega_A = W dq
    omega = W * sp.Matrix(dq)
    hub = spin * sp.Matrix([0, L, 0])
    kinetic = sp.Rational(1, 2) * ((m * L ** 2 + I_diam) * _dot(omega, omega)
                                   - m * _dot(omega, hub) ** 2
                                   + (I_axle - I_diam) * _dot(omega, ez) ** 2)
    Mq = sp.Matrix(3, 3, lambda i, j: sp.trigsimp(sp.expand(sp.diff(kinetic, dq[i], dq[j]))))
    hub_w = A * hub                                         # world axes
    potential = m * g * hub_w[1]
    G = sp.Matrix([sp.diff(potential, qi) for qi in q])
    C = christoffel(Mq, q, dq)

    def foot(k):  # the foot of the spoke k spokes ahead of the stance spoke (world)
        return A * (hub + spin * _spoke(2 * k * alpha, L))

    nxt = foot(1)
    Mi, B = _spoked_impact(W, hub, spin, par)
    # world axes from here (walkerlab's derivation before the tree rebound ``hub`` here, so
    # that foot(k) below, its closure, turned the hub's world position once more: its
    # trailing_foot and spoke<k>_foot points were off by (A - I) hub, wrong once the wheel
    # leaned or turned)
    hub_world, axle = hub_w, A * ez
    # the section: the spoke behind's foot on the slope, a cos(theta) + b sin(theta) = 0
    u = W[:, 0]                                             # the normal in A's frame
    v = sp.Matrix([0, L, 0]) + _spoke(-2 * alpha, L)       # hub -> trailing foot, wheel frame
    a = u[0] * v[0] + u[1] * v[1]
    b = u[1] * v[0] - u[0] * v[1]
    theta_on = sp.atan2(a, -b)                              # = alpha - gamma upright
    points = {"hip": hub_world, "stance_foot": sp.zeros(3, 1), "swing_foot": nxt,
              "trailing_foot": foot(-1),
              **{f"spoke{k}_foot": foot(k) for k in range(2, structure.spokes - 1)},
              "axle_tip": hub_world + L * axle / 4}
    n = 3
    return SimpleNamespace(
        q=q, dq=dq, params=tuple(par), M=Mq, C=C, G=G, Mi=Mi, B=B,
        relabel_q=sp.Matrix([psi, phi, th + 2 * alpha]), relabel_rate=sp.eye(n),
        kinetic=kinetic, potential=potential,
        guards={"heel_strike": _dot(nxt, nrm), "rolls_back": dth,
                "hip_height": _dot(hub_world, nrm), "swing_clearance": _dot(nxt, nrm)},
        points=points,
        leg_angles={"stance": th, "swing": th + 2 * alpha, "heading": psi, "lean": phi},
        section_drop=2, drop_solution=theta_on,
        De=sp.zeros(n + 2, n + 2), E=sp.zeros(2, n + 2), limit=False, section_tied=None,
    )
