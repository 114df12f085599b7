"""Points of a walker as sums of link vectors: a point is ``sum(length * e(angle))`` over
``{angle: length}`` (an angle a coordinate or a linear expression of them), so that velocities
and the mass matrix come out in ``cos(a - b)`` form without a trigonometric simplifier (shared
by the derivations of :mod:`walkerlab.codegen.symbolic`, :mod:`walkerlab.codegen.foot_modes`
and :mod:`walkerlab.codegen.free_joints`).
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
