"""Compliant-contact force laws of MSC ADAMS (STEP, IMPACT, Coulomb friction).

All functions are pure and vectorized (numpy broadcasting).  They are unit-agnostic: the
caller must pass every argument in one consistent unit system (``walkerlab.contact`` uses SI
internally, see :meth:`walkerlab.config.contact.ContactSettings.to_si`).

Sources
-------
* MSC Adams/Solver function reference, ``STEP`` (cubic step) and ``IMPACT`` (one-sided
  spring-damper contact force); Adams/View contact dialog, Coulomb friction with stiction
  and friction transition velocities.
* /work/shared/NOTES.md, section "The MSC ADAMS model", which restates these laws.

Scalar, numba-compiled twins of these functions live in :mod:`walkerlab.contact._kernels`;
``tests/contact/test_laws.py`` checks that both agree.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "adams_step",
    "adams_step_derivative",
    "coulomb_friction_coefficient",
    "impact_normal_force",
]


def _unit_interval(x, x0, x1):
    return np.clip((np.asarray(x, dtype=float) - x0) / (x1 - x0), 0.0, 1.0)


def adams_step(x, x0, h0, x1, h1):
    """ADAMS ``STEP(x, x0, h0, x1, h1)``: cubic, C1 transition from ``h0`` to ``h1``.

    ``h0`` for ``x <= x0``, ``h1`` for ``x >= x1`` and
    ``h0 + (h1 - h0) * s**2 * (3 - 2*s)``, ``s = (x - x0) / (x1 - x0)``, in between
    (MSC Adams/Solver function reference, STEP; NOTES.md).

    Parameters
    ----------
    x : array_like
        Independent variable, any shape, any unit ``[u]``.
    x0, x1 : float
        Start and end of the transition, ``[u]``, ``x1 > x0``.
    h0, h1 : float
        Values before and after the transition, any unit ``[w]``.

    Returns
    -------
    ndarray
        Same shape as ``x``, unit ``[w]``.
    """
    s = _unit_interval(x, x0, x1)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


def adams_step_derivative(x, x0, h0, x1, h1):
    """Derivative of :func:`adams_step` with respect to ``x``.

    ``6 (h1 - h0) s (1 - s) / (x1 - x0)`` inside the transition, zero outside (the step is C1,
    so the derivative is continuous).  Needed for analytic Jacobians.

    Parameters
    ----------
    x : array_like
        Any shape, ``[u]``.
    x0, h0, x1, h1 : float
        As in :func:`adams_step`.

    Returns
    -------
    ndarray
        Same shape as ``x``, unit ``[w]/[u]``.
    """
    s = _unit_interval(x, x0, x1)
    return 6.0 * (h1 - h0) * s * (1.0 - s) / (x1 - x0)


def impact_normal_force(delta, delta_dot, k, e, cmax, dmax):
    """ADAMS ``IMPACT`` normal contact force (never pulls).

    ``Fn = max(0, k * delta**e + STEP(delta, 0, 0, dmax, cmax) * delta_dot)`` for
    ``delta > 0`` and ``Fn = 0`` otherwise (MSC Adams/Solver function reference, IMPACT;
    NOTES.md).  The damping ramps in over the first ``dmax`` of penetration, so the force is
    continuous at touchdown.

    Parameters
    ----------
    delta : array_like
        Penetration depth ``[len]`` (``>= 0`` means in contact).
    delta_dot : array_like
        Penetration rate ``[len/s]``, positive when penetrating deeper.
    k : float
        Contact stiffness ``[N/len**e]``.
    e : float
        Force exponent ``[-]`` (``>= 1``; ADAMS default 2.2).
    cmax : float
        Maximum damping coefficient ``[N s/len]``.
    dmax : float
        Penetration at which full damping is reached ``[len]``.

    Returns
    -------
    ndarray
        Normal force ``[N]``, broadcast shape of ``delta`` and ``delta_dot``.
    """
    delta = np.asarray(delta, dtype=float)
    dpos = np.maximum(delta, 0.0)
    f = k * dpos**e + adams_step(dpos, 0.0, 0.0, dmax, cmax) * np.asarray(delta_dot, float)
    return np.where(delta > 0.0, np.maximum(f, 0.0), 0.0)


def coulomb_friction_coefficient(v, mu_s, mu_d, v_s, v_d):
    """ADAMS-style regularized Coulomb friction coefficient (signed, opposes ``v``).

    * ``|v| < v_s``: ``mu = STEP(v, -v_s, mu_s, v_s, -mu_s)`` (so ``mu(0) = 0``);
    * ``v_s <= |v| <= v_d``: ``mu = -sign(v) * STEP(|v|, v_s, mu_s, v_d, mu_d)``;
    * ``|v| > v_d``: ``mu = -sign(v) * mu_d``.

    (Adams/View contact, Coulomb friction; NOTES.md.)  The friction force is
    ``mu * Fn`` along the direction in which ``v`` is measured.

    Parameters
    ----------
    v : array_like
        Slip velocity ``[len/s]``.
    mu_s, mu_d : float
        Static and dynamic friction coefficients ``[-]``.
    v_s, v_d : float
        Stiction and friction transition velocities ``[len/s]``, ``0 < v_s < v_d``.

    Returns
    -------
    ndarray
        Signed coefficient ``[-]``, same shape as ``v``.
    """
    v = np.asarray(v, dtype=float)
    av = np.abs(v)
    inner = adams_step(v, -v_s, mu_s, v_s, -mu_s)
    outer = -np.sign(v) * adams_step(av, v_s, mu_s, v_d, mu_d)
    return np.where(av < v_s, inner, outer)
