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


@njit(cache=True)
def ground_line(px, py, line):
    """Contact frame of a point at (px, py) [m] on a polyline ground (treads, risers,
    profile segments): the signed penetration [m] (> 0 inside the ground) into the nearest
    segment and that segment's outward unit normal (nx, ny).

    ``line`` (2 m,): the polyline's vertices ``x0, y0, x1, y1, ...`` [m] in the world frame
    (the ground lies to the right of each segment's direction: a segment running in +x has
    the normal +y; a riser going down in +x faces +x).  The nearest segment is the one whose
    closest point (clamped to the segment) is nearest; the sign is the side of that segment's
    line.  Past a segment's end (a corner) the normal is the direction from that end to the
    point, so penetration and normal are continuous around corners; the penetration is the
    distance to the ground's surface (a signed distance function of the polyline).  A point
    nearest to a vertex that ends two segments is inside only when it is inside both
    segments' lines: beyond a convex corner (the top of a riser up) it lies inside one line
    and outside the other, and is outside the ground."""
    m = line.shape[0] // 2
    best = np.inf
    delta, nx, ny = -np.inf, 0.0, 1.0
    for j in range(m - 1):
        ax, ay = line[2 * j], line[2 * j + 1]
        ex, ey = line[2 * j + 2] - ax, line[2 * j + 3] - ay
        l2 = ex * ex + ey * ey
        if l2 <= 0.0:
            continue
        u = ((px - ax) * ex + (py - ay) * ey) / l2
        clamped = u < 0.0 or u > 1.0
        if u <= 0.0:    # past an end: the vertex itself (a tie between the two segments
            dx, dy = px - ax, py - ay   # that share it is exact)
        elif u >= 1.0:
            dx, dy = px - line[2 * j + 2], py - line[2 * j + 3]
        else:
            dx, dy = px - (ax + u * ex), py - (ay + u * ey)
        r2 = dx * dx + dy * dy
        if r2 > best:
            continue
        ln = np.sqrt(l2)
        sx, sy = -ey / ln, ex / ln  # the segment's outward normal
        side = -((px - ax) * sx + (py - ay) * sy)  # > 0: inside the ground
        if r2 == best and not (clamped and delta > 0.0 and side <= 0.0):
            continue  # a tie at a vertex two segments share: inside only inside both
        best = r2
        r = np.sqrt(r2)
        if clamped and r > 0.0:
            sg = 1.0 if side > 0.0 else -1.0
            delta, nx, ny = sg * r, -sg * dx / r, -sg * dy / r
        else:
            delta, nx, ny = side, sx, sy
    return delta, nx, ny
