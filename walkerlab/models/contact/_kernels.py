"""Numba-compiled scalar contact laws of the compliant-contact walker (ADAMS STEP, IMPACT,
Coulomb friction with stiction, patch height).

Internal module.  Everything is SI.  These are the scalar twins of the vectorised laws in
:mod:`walkerlab.models.contact.laws` (``tests/contact/test_laws_config.py`` checks both agree); the
walker's mechanics (mass matrix, bias, contact points and Jacobians) is generated from the
walker description (:mod:`walkerlab.codegen.floating`) and assembled with these laws in
:mod:`walkerlab.models.contact.generated`.  The hand-written floating compass gait that lived here
retired after the generated one was shown equal to it (rhs 5e-16, Jacobian 1.8e-14 relative,
measured); the independent numpy check is ``tests/independent/contact_reference.py``.
"""

from __future__ import annotations

from walkerlab.usercache import use_for_numba

use_for_numba()  # cache=True below: numba's cache in the user cache, not in the package

import numpy as np  # noqa: E402
from numba import njit  # noqa: E402


@njit(cache=True)
def step(x, x0, h0, x1, h1):
    """Scalar ADAMS STEP and its derivative d/dx (see laws.adams_step)."""
    if x <= x0:
        return h0, 0.0
    if x >= x1:
        return h1, 0.0
    w = x1 - x0
    s = (x - x0) / w
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s), 6.0 * (h1 - h0) * s * (1.0 - s) / w


@njit(cache=True)
def normal_force(delta, ddot, k, e, cmax, dmax):
    """IMPACT force and its partials (F [N], dF/ddelta [N/m], dF/dddot [N s/m])."""
    if delta <= 0.0:
        return 0.0, 0.0, 0.0
    c, dc = step(delta, 0.0, 0.0, dmax, cmax)
    ke = k * delta ** e
    f = ke + c * ddot
    if f <= 0.0:
        return 0.0, 0.0, 0.0
    return f, e * ke / delta + dc * ddot, c


@njit(cache=True)
def friction_mu(v, mus, mud, vs, vd):
    """Signed ADAMS Coulomb coefficient and d(mu)/dv [s/m] (see laws)."""
    av = abs(v)
    if av < vs:
        return step(v, -vs, mus, vs, -mus)
    sg = 1.0 if v > 0.0 else -1.0
    mu, dmu = step(av, vs, mus, vd, mud)
    return -sg * mu, -dmu  # d/dv(-sg*h(|v|)) = -sg*h'*sg = -h'


@njit(cache=True)
def patch_height(s, lane, hw, continuous):
    """Height [m] (along the slope's outward normal, > 0 raised) of the ground of the lane
    at along-slope coordinate ``s`` [m]; NaN in a gap.

    ``lane`` (2 n + 1,): the centres [m] of the lane's n patches, their heights [m], and
    their largest height [m] (the kernel lane of
    :meth:`walkerlab.models.contact.model.ContactWalker.kernel_lanes`).  Continuous ground: 0."""
    if continuous:
        return 0.0
    n = (lane.shape[0] - 1) // 2
    for j in range(n):
        if abs(s - lane[j]) <= hw:
            return lane[n + j]
    return np.nan
