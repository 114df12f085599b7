"""Rigid-legged compass-gait walker as a hybrid system (paper Sec. 3.1-3.2, Appendix A).

State (paper Eq. 1), role-ordered: ``x = [theta1, theta2, dtheta1, dtheta2]`` with
``theta1`` the swing leg and ``theta2`` the stance leg, absolute angles from the vertical
[rad], positive when the foot is ahead of the hip... for the swing leg, i.e. the swing foot
is at ``hip + L (sin theta1, -cos theta1)`` and the hip at ``stance_foot + L (-sin theta2,
cos theta2)`` (A.1-A.3).  The walker walks in +x down a slope of angle ``phi``.

Three pure pieces (as in Drake's ``examples/compass_gait``):

- flow   :func:`flow`        ``M(q) qdd + C(q, dq) dq + G(q) = 0`` (Eq. 3-4)
- guard  generated with the flow (:func:`walkerlab.models.hybrid.rigid.make_rigid_walker`:
         ``heel_strike`` armed in late swing, after ``midstance``); :func:`swing_foot_height`
         is the geometry both factors of it come from
- reset  :func:`impact`       plastic impact and role swap (Eq. 6-8, A.41-A.57)

The ``derived`` equations are not written here: the compass gait is the generic biped of
:mod:`walkerlab.walker.description` (hip point mass, one point mass per leg) and its code is
generated and cached (:mod:`walkerlab.codegen.legged`, :mod:`walkerlab.codegen.source`).
This module keeps the paper's *printed* equations (Appendix A) for comparison.

Equation variants
-----------------
``derived``
    generic symbolic derivation - the default.
``appendix_a``
    the printed Appendix A flow (A.4-A.6, including the wrong sign of ``C[1, 0]`` in A.5)
    with the impact of A.57; reproduces the paper's Eq. 11.
``appendix_a_literal``
    as ``appendix_a`` but also with the printed y-component of the swing-foot position
    (A.55, ``cos(theta1) - cos(-theta2)``); its fixed point does *not* match Eq. 11, which
    shows the MATLAB code did not use that sign.
"""

from __future__ import annotations

from dataclasses import replace
from functools import cache, partial

import numpy as np

from walkerlab.codegen.cache import functions
from walkerlab.models.hybrid.base import HybridWalker
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.numerics import complex_step_jacobian
from walkerlab.walker.description import compass_gait_structure  # noqa: F401
from walkerlab.walker.plant import compass_gait_data

VARIANTS = ("derived", "appendix_a", "appendix_a_literal")


# ----------------------------------------------------------------- equations of motion
def matrices(q, dq, p, variant: str = "derived"):
    """Inertia ``M`` (2x2), Coriolis ``C`` (2x2) and gravity ``G`` (2,) of the swing phase.

    Parameters
    ----------
    q, dq : array_like, shape (2,)
        ``[theta1, theta2]`` [rad] and rates [rad/s] (complex allowed, for complex-step
        derivatives).
    p : tuple
        ``(m, M_H, L, a, g)`` in SI units.
    variant : str
        One of :data:`VARIANTS`.

    Returns
    -------
    M, C : ndarray, shape (2, 2)
    G : ndarray, shape (2,)
    """
    if variant == "derived":
        return _generated(tuple(p))["matrices"](np.concatenate([q, dq]))
    m, mh, L, a, g = p
    b = L - a
    t1, t2 = q
    w1, w2 = dq
    c, s = np.cos(t2 - t1), np.sin(t2 - t1)
    M = np.array([[m * b**2, -m * L * b * c],
                  [-m * L * b * c, mh * L**2 + m * (L**2 + a**2)]])  # A.4
    C = np.array([[0 * w2, m * L * b * w2 * s],
                  [m * L * b * w1 * s, 0 * w1]])  # A.5 as printed (C[1,0] sign is wrong)
    G = np.array([m * g * b * np.sin(t1), -(mh * L + m * (a + L)) * g * np.sin(t2)])  # A.6
    return M, C, G


def flow(t: float, x: np.ndarray, p: tuple, variant: str = "derived") -> np.ndarray:
    """Swing-phase vector field ``dx/dt = [dq, M^-1 (-C dq - G)]`` (paper Eq. 4, A.58).

    Parameters
    ----------
    t : float
        Time [s] (unused: the system is autonomous).
    x : ndarray, shape (4,)
        Role-ordered state ``[theta1, theta2, dtheta1, dtheta2]``.
    p : tuple
        ``(m, M_H, L, a, g)`` [kg, kg, m, m, m/s^2].

    Returns
    -------
    ndarray, shape (4,)
    """
    if variant == "derived":
        return _generated(tuple(p))["flow"](t, x)
    q, dq = x[:2], x[2:]
    M, C, G = matrices(q, dq, p, variant)
    qdd = np.linalg.solve(M, -C @ dq - G)
    return np.concatenate([dq, qdd])


# ----------------------------------------------------------------------------- guard
def swing_foot_height(x: np.ndarray, phi: float, L: float) -> np.ndarray:
    """Height of the swing foot above the slope, normal to it [m].

    ``h = L (cos(theta2 + phi) - cos(theta1 + phi)) = 2 L sin(sigma/2) sin((theta1-theta2)/2)``
    with ``sigma = theta1 + theta2 + 2 phi``.  It vanishes on two surfaces: heel strike
    (``sigma = 0``, the set S of Eq. 9-2 shifted by the slope) and mid-stance
    (``theta1 = theta2``, legs aligned: the swing foot scuffs through the ground).
    """
    return L * (np.cos(x[1] + phi) - np.cos(x[0] + phi))


# ----------------------------------------------------------------------------- reset
def impact_matrices(q, p, variant: str = "derived"):
    """Extended inertia ``De`` (4x4, coordinates ``[theta1, theta2, x_f, y_f]``, A.7-A.24)
    and swing-foot Jacobian ``E`` (2x4, A.56)."""
    De, E = _generated(tuple(p))["impact_matrices"](np.asarray(q))
    if variant == "appendix_a_literal":
        m, mh, L, a, g = p
        t1, t2 = q
        # A.55 as printed: y + L (cos(theta1) - cos(-theta2))
        E = E.copy()
        E[1] = [-L * np.sin(t1), L * np.sin(t2), 0.0, 1.0]
    return De, E


def impact(x_minus: np.ndarray, p: tuple, variant: str = "derived",
           return_impulse: bool = False):
    """Plastic heel-strike impact and leg-role swap (paper Eq. 6-8, A.41-A.57).

    Solves ``[[De, -E^T], [E, 0]] [dqe+, F] = [De dqe-, 0]`` with the stance foot at rest
    before impact (``dqe- = [dq-, 0, 0]``), so the new stance foot (old swing foot) has zero
    velocity afterwards, then swaps the roles: ``theta1+ = theta2-``, ``theta2+ = theta1-``.

    Parameters
    ----------
    x_minus : ndarray, shape (4,)
        State just before heel strike.
    return_impulse : bool
        Also return the impulse ``F`` [N s] (2,) at the new stance foot and the velocity
        [m/s] (2,) of the old stance foot just after impact (``y`` > 0: it lifts off).

    Returns
    -------
    x_plus : ndarray, shape (4,)
    """
    q, dq = x_minus[:2], x_minus[2:]
    De, E = impact_matrices(q, p, variant)
    dtype = np.result_type(De, x_minus)
    A = np.zeros((6, 6), dtype=dtype)
    A[:4, :4] = De
    A[:4, 4:] = -E.T
    A[4:, :4] = E
    rhs = np.zeros(6, dtype=dtype)
    rhs[:4] = De @ np.concatenate([dq, np.zeros(2, dtype=dq.dtype)])
    sol = np.linalg.solve(A, rhs)
    x_plus = np.array([q[1], q[0], sol[1], sol[0]])
    if return_impulse:
        return x_plus, sol[4:], sol[2:4]
    return x_plus


# ---------------------------------------------------------------------------- energy
def energies(x: np.ndarray, p: tuple) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy [J]; ``x`` of shape (4,) or (4, k).

    Potential energy is measured from the stance foot's height (world vertical).
    """
    return _generated(tuple(p))["energies"](np.asarray(x))


def points(x: np.ndarray, p: tuple) -> dict[str, np.ndarray]:
    """Positions [m] relative to the stance foot (A.1-A.3); each value (2,) or (2, k)."""
    return _generated(tuple(p))["points"](np.asarray(x))


# --------------------------------------------------------------------------- builder
@cache
def _generated(p: tuple) -> dict:
    """Generated functions for ``p = (m, M_H, L, a, g)`` (slope 0: flow, impact, energies)."""
    m, mh, L, a, g = p
    return functions(compass_gait_data(L, m, mh, g, a, 0.0))


def make_compass_gait(leg_length_m: float, leg_mass_kg: float, hip_mass_kg: float,
                      gravity_m_per_s2: float, leg_mass_from_foot_m: float, slope_rad: float,
                      variant: str = "derived") -> HybridWalker:
    """Build the compass-gait :class:`HybridWalker` (all arguments SI).

    ``derived`` is the generic biped (generated code); the ``appendix_a`` variants use the
    printed flow A.4-A.6 (generated too, see :class:`~walkerlab.walker.description.Structure`)
    and, for ``appendix_a_literal``, the impact with A.55 as printed (Jacobian by complex
    step).

    Raises
    ------
    ValueError
        Unknown ``variant``.
    """
    if variant not in VARIANTS:
        raise ValueError(f"ideal.variant: unknown variant {variant!r}; choose from {VARIANTS}")
    data = compass_gait_data(leg_length_m, leg_mass_kg, hip_mass_kg, gravity_m_per_s2,
                             leg_mass_from_foot_m, slope_rad)
    if variant == "derived":
        return make_rigid_walker(data, "compass_gait", variant)
    # printed flow (A.4-A.6): generated like any other, from the derived equations with the
    # printed sign of C[1, 0]; appendix_a_literal also uses the printed impact (A.55)
    data = replace(data, structure=replace(data.structure, variant="appendix_a"))
    kw = {}
    if variant == "appendix_a_literal":
        p = (leg_mass_kg, hip_mass_kg, leg_length_m, leg_mass_from_foot_m, gravity_m_per_s2)
        reset = partial(impact, p=p, variant=variant)
        kw = {"reset": reset, "reset_jacobian": lambda x: complex_step_jacobian(reset, x)}
    return make_rigid_walker(data, "compass_gait", variant, **kw)
