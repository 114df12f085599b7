"""Points of a walker as sums of link vectors: a point is ``sum(length * e(angle))`` over
``{angle: length}`` (an angle a coordinate or a linear expression of them), so that velocities
and the mass matrix come out in ``cos(a - b)`` form without a trigonometric simplifier (shared
by the derivations of :mod:`walkerlab.codegen.legged`, :mod:`walkerlab.codegen.foot_modes`
and :mod:`walkerlab.codegen.legged`), and the heel strike's impact in extended
coordinates of those bodies (:func:`extended_impact`, written once for the planar
derivations).
"""

from __future__ import annotations

import sympy as sp


def e(psi):
    """Unit vector from the hip towards the foot of a leg at angle ``psi`` from the vertical."""
    return sp.Matrix([sp.sin(psi), -sp.cos(psi)])


def position_of(lin: dict) -> sp.Matrix:
    """Position ``sum(length * e(angle))`` of a ``{angle: length}`` leg-vector sum."""
    out = sp.zeros(2, 1)
    for psi, length in lin.items():
        out += length * e(psi)
    return out


def velocity_terms(lin: dict, psv) -> list[list[tuple]]:
    """For each ``psi_k``: the ``(angle, coefficient)`` terms of ``d position / d psi_k =
    sum coefficient * e'(angle)`` of a ``{angle: length}`` leg-vector sum."""
    out = []
    for s in psv:
        terms = []
        for a, length in lin.items():
            da = sp.diff(a, s)
            if length != 0 and da != 0:
                terms.append((a, length * da))
        out.append(terms)
    return out


def dot_terms(u: list, v: list):
    """``(sum cu e'(a)) . (sum cv e'(b)) = sum cu cv cos(a - b)``."""
    return sum((cu * cv * sp.cos(a - b) for a, cu in u for b, cv in v), sp.Integer(0))


def add_length(lin: dict, psi, length) -> dict:
    """Copy of the leg-vector sum ``lin`` with ``length`` more along the angle ``psi``."""
    out = dict(lin)
    out[psi] = out.get(psi, 0) + length
    return out


def add_mass_terms(M, Mi, B, mass, lin: dict, foot_lin: dict, qs, n: int) -> None:
    """Add, in place, a point mass ``mass`` at the leg-vector sum ``lin`` to the mass matrix
    ``M`` (``sum m e'(a) . e'(b)`` of its velocity) and to the impact matrices ``Mi`` (its
    velocity with the point at ``foot_lin`` at rest, the new stance foot) and ``B`` (the
    momentum of the pre-impact velocity on those directions), all (n, n) in ``qs``."""
    rel = {k: lin.get(k, 0) - foot_lin.get(k, 0) for k in {**lin, **foot_lin}}
    dl, dn = velocity_terms(lin, qs), velocity_terms(rel, qs)
    for i in range(n):
        for j in range(n):
            M[i, j] += mass * dot_terms(dl[i], dl[j])
            Mi[i, j] += mass * dot_terms(dn[i], dn[j])
            B[i, j] += mass * dot_terms(dn[i], dl[j])


def extended_impact(q, dq, bodies, foot: sp.Matrix, *, massless=None, arc=None):
    """The heel strike's impact in extended coordinates (paper Eq. 6-7, A.7-A.24; Hurmuzlu &
    Marghitu 1994): the stance foot set free at ``(x_f, y_f)`` (the whole walker translated
    by it), ``De`` the Hessian of the kinetic energy in the rates of ``[q, x_f, y_f]`` and
    ``E`` the Jacobian of the swing foot's material contact point, so that the plastic
    impact is ``De (dqe+ - dqe-) = E^T F``, ``E dqe+ = 0``.

    ``T = sum_b [m_b |v_b|^2 + I_b w_b^2] / 2`` over the bodies, each at its position
    moved with the free foot, turning at the rate of its link angle.

    Parameters
    ----------
    q, dq : sequence of Symbol (n,)
        The walker's coordinates [rad] and rates [rad/s].
    bodies : iterable of (mass, position, inertia, angle)
        Each body's mass [kg], centre of mass (2, 1) from the stance foot in ``q`` [m],
        inertia about it [kg m^2] and link angle (an expression of ``q``) [rad].
    foot : sympy Matrix (2, 1)
        The swing foot's contact point in ``q`` [m] (an arc foot's centre, with ``arc``).
    massless : Symbol or None
        The massless limit's symbolic mass: ``T`` is taken at 0 of it (massless bodies
        carry no kinetic energy; Garcia et al. 1998).
    arc : (Expr, Matrix (2, 1), Expr) or None
        An arc foot's radius ``R`` [m], the slope's fall line ``t`` and the swing arc's
        angle: its material contact point moves at ``v_centre + R w t`` (the arc's spin
        ``w``; McGeer 1990).

    Returns
    -------
    De : sympy Matrix (n + 2, n + 2)
        [kg m^2, kg m, kg by coordinate].
    E : sympy Matrix (2, n + 2)
        [m, dimensionless].
    """
    xf, yf, dxf, dyf = sp.symbols("x_f y_f dx_f dy_f", real=True)
    qe, dqe = sp.Matrix([*q, xf, yf]), sp.Matrix([*dq, dxf, dyf])
    Te = sp.Integer(0)
    for mass, pos, inertia, psi in bodies:
        ve = (pos + sp.Matrix([xf, yf])).jacobian(qe) * dqe
        a = sp.Matrix([[sp.diff(psi, qi) for qi in qe]])
        Te += (sp.Rational(1, 2) * mass * (ve.T * ve)[0]
               + sp.Rational(1, 2) * inertia * (a * dqe)[0] ** 2)
    if massless is not None:
        Te = Te.subs(massless, 0)
    E = (foot + sp.Matrix([xf, yf])).jacobian(qe)
    if arc is not None:  # the arc's material point: w x (-R n) = R w t
        R, tangent, spin = arc
        E += R * tangent * sp.Matrix([[sp.diff(spin, qi) for qi in qe]])
    return sp.hessian(Te, dqe), E
