"""Joint-torque laws in compiled code: the laws of :mod:`walkerlab.models.actuation` (one
formula: ``tau = constant - K (delta - ref) - D (ddelta - dref)``, saturated) evaluated inside
a numba ``cfunc`` right-hand side (:mod:`walkerlab.codegen.actuated`), with the partial
derivatives the variational equations need.

The laws travel as one float64 vector, the *law block* (appended to the compiled flow's data
vector, so a law's numbers are data, not code: one compiled module serves any gains and
tables):

=====================  ====================================================================
``b[0]``               ``L``, the block's length
``b[1]``               number of actuators ``k``
``b[2]``               the time the present step began [s] (``time_reference`` laws)
``b[3 + HEAD i + j]``  actuator ``i``'s header, ``j`` = :data:`FIELDS` (kind: 0 a plain
                       spring-damper, 1 a reference of the phase variable, 2 of the time
                       since the step began; ``limit`` inf when unsaturated; the table's
                       knot count and offset in ``b``)
table                  the knots ``s`` (``n``), then per interval ``j`` the coefficients
                       ``c0..c3`` of ``c0 u^3 + c1 u^2 + c2 u + c3``, ``u = r - s_j``
                       (:class:`scipy.interpolate.PPoly`'s ``c[:, j]``; a piecewise-linear
                       table has ``c0 = c1 = 0``)
=====================  ====================================================================

Outside its knots a table is held at its end values (slope and curvature 0), as
:func:`walkerlab.models.actuation.phase_reference`.

Kind 3, a *phase-variable feed-forward* law (an optimised step replayed as virtual
constraints, :class:`walkerlab.optimal.replay.phase.PhaseLaw`): ``tau = U(T(s)) - K (delta -
h(s)) - D (ddelta - h'(s) ds)``, every spline extrapolated with its end interval's cubic
(:class:`scipy.interpolate.PPoly`'s ``extrapolate=True``).  Its table: the knots ``s``
(``n``), ``h``'s coefficients as above, then ``T``'s (the time the optimised step passes
``s``) on the same knots, then ``m`` (the count of ``U``'s knots, the times), those knots and
``U``'s coefficients per interval (``U`` the feed-forward of time; a quadratic padded with
``c0 = 0``).

Kind 5, a *feed-forward of time* (an optimised step's torque replayed from each heel strike,
:class:`walkerlab.models.actuation.TorqueOfTime`): ``tau = U(t - t_step)``, its table as a
kind-1 table's (held at its end values outside its knots), the gains not read.

Kind 4, a *piecewise* phase-variable law (one kind-3 law per phase of a step, the one in
force chosen by ``s``: :class:`walkerlab.optimal.replay.hip_phase.PiecewisePhaseLaw`): the
header's ``knots`` field holds the count of pieces ``P``; the table holds ``sign`` (the
phase variable's direction over the step), the ``P - 1`` breaks (``s`` where each piece
after the first begins), each piece's offset from the table's start, then each piece as
``n`` and a kind-3 table.  The piece in force is the number of breaks with
``sign (s - break) >= 0``.
"""

from __future__ import annotations

import numpy as np
from numba.extending import register_jitable

__all__ = ["FIELDS", "HEAD", "cubic_at", "feedforward_terms", "interval", "kernel_source",
           "law_torque", "pack_laws", "table_value"]

#: An actuator's header fields in the law block, in order.
FIELDS = ("kind", "constant_n_m", "stiffness_n_m_per_rad", "damping_n_m_s_per_rad",
          "rest_angle_rad", "limit_n_m", "knots", "table_offset")
HEAD = len(FIELDS)
#: Law kinds.
PLAIN, PHASE, TIME, FEEDFORWARD, PIECEWISE, TIME_FEEDFORWARD = 0, 1, 2, 3, 4, 5


def pack_laws(laws) -> np.ndarray:
    """The law block (module docstring) of ``laws``, with the step's start time 0.

    Parameters
    ----------
    laws : sequence of tuple
        Per actuator ``(kind, constant, stiffness, damping, rest, limit, knots, coefs[,
        tail])``: ``kind`` one of :data:`PLAIN`, :data:`PHASE`, :data:`TIME`,
        :data:`FEEDFORWARD`, :data:`PIECEWISE`, :data:`TIME_FEEDFORWARD`; ``limit`` [N m]
        or None; ``knots`` (n,) increasing and ``coefs`` (4, n - 1) (PPoly order, highest
        degree first), both None for a plain law; ``tail`` (1-D) appended after the table
        (a :data:`FEEDFORWARD` law's ``T`` and ``U``, module docstring).  A
        :data:`PIECEWISE` law gives its piece count as ``knots`` (an int), ``coefs`` None
        and its whole table as ``tail``.

    Returns
    -------
    ndarray (L,)
    """
    head = np.zeros((len(laws), HEAD))
    tables = []
    offset = 3 + HEAD * len(laws)
    for i, (kind, c, k, d, rest, limit, knots, coefs, *tail) in enumerate(laws):
        n = 0 if knots is None else (int(knots) if np.ndim(knots) == 0 else len(knots))
        head[i] = (kind, c, k, d, rest, np.inf if limit is None else limit, n, offset)
        if n:
            block = np.concatenate(
                ([] if np.ndim(knots) == 0 else [np.asarray(knots, float),
                                                 np.asarray(coefs, float).T.ravel()])
                + [np.asarray(a, float).ravel() for a in tail])
            tables.append(block)
            offset += block.size
    body = np.concatenate([head.ravel(), *tables]) if tables else head.ravel()
    return np.concatenate([[3.0 + body.size, float(len(laws)), 0.0], body])


@register_jitable
def table_value(b, off, n, u):
    """``(h, h', h'')`` of the table at ``b[off:]`` (``n`` knots) at ``u``, held outside."""
    s0, s1 = b[off], b[off + n - 1]
    inside = s0 < u < s1
    r = min(max(u, s0), s1)
    j = 0
    while j < n - 2 and b[off + j + 1] <= r:
        j += 1
    c = off + n + 4 * j
    x = r - b[off + j]
    h = ((b[c] * x + b[c + 1]) * x + b[c + 2]) * x + b[c + 3]
    if not inside:
        return h, 0.0, 0.0
    return h, (3.0 * b[c] * x + 2.0 * b[c + 1]) * x + b[c + 2], 6.0 * b[c] * x + 2.0 * b[c + 1]


@register_jitable
def interval(b, off, n, u):
    """Index ``j`` of the interval of the knots ``b[off:off + n]`` that holds ``u``
    (``knots[j] <= u < knots[j + 1]``; the end intervals outside, as
    :class:`scipy.interpolate.PPoly`), by bisection."""
    lo, hi = 0, n - 2
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if b[off + mid] <= u:
            lo = mid
        else:
            hi = mid - 1
    return lo


@register_jitable
def cubic_at(b, off, n, u):
    """``(p, p', p'')`` at ``u`` of the piecewise cubic with knots ``b[off:off + n]`` and
    coefficients after them, extrapolated with its end intervals."""
    j = interval(b, off, n, u)
    c = off + n + 4 * j
    x = u - b[off + j]
    return (((b[c] * x + b[c + 1]) * x + b[c + 2]) * x + b[c + 3],
            (3.0 * b[c] * x + 2.0 * b[c + 1]) * x + b[c + 2], 6.0 * b[c] * x + 2.0 * b[c + 1])


@register_jitable
def feedforward_terms(b, off, n, delta, ddelta, s, ds, K, D):
    """A kind-3 table at ``b[off:]`` (``n`` knots): ``(U(T(s)), delta - h(s), ddelta -
    h'(s) ds, dtau/ds, dtau/dds)`` (the last two the law's partials with gains ``K``,
    ``D``)."""
    j = interval(b, off, n, s)
    x = s - b[off + j]
    c = off + n + 4 * j
    r = ((b[c] * x + b[c + 1]) * x + b[c + 2]) * x + b[c + 3]
    r1 = (3.0 * b[c] * x + 2.0 * b[c + 1]) * x + b[c + 2]
    r2 = 6.0 * b[c] * x + 2.0 * b[c + 1]
    c += 4 * (n - 1)
    tt = ((b[c] * x + b[c + 1]) * x + b[c + 2]) * x + b[c + 3]
    dtt = (3.0 * b[c] * x + 2.0 * b[c + 1]) * x + b[c + 2]
    uoff = off + n + 8 * (n - 1)
    u, du, _u2 = cubic_at(b, uoff + 1, int(b[uoff]), tt)
    return u, delta - r, ddelta - r1 * ds, du * dtt + K * r1 + D * r2 * ds, D * r1


@register_jitable
def law_torque(b, i, delta, ddelta, s, ds, t):
    """Actuator ``i``'s torque [N m] of the law block ``b`` and its partial derivatives
    ``(tau, dtau/ddelta, dtau/dddelta, dtau/ds, dtau/dds)``: ``delta``, ``ddelta`` the joint
    angle [rad] and rate [rad/s], ``s``, ``ds`` the phase variable [rad] and its rate
    [rad/s], ``t`` the time [s] (the step began at ``b[2]``).  Plain Python on floats,
    callable from numba code as it is (``register_jitable``: the contact actuators'
    :mod:`walkerlab.models.contact.powered_kernels`) and copied into generated modules
    (:func:`kernel_source`)."""
    h = 3 + HEAD * i
    kind, c0, K, D = b[h], b[h + 1], b[h + 2], b[h + 3]
    g_s, g_ds = 0.0, 0.0
    if kind == PLAIN:
        err, derr = delta - b[h + 4], ddelta
    elif kind == PHASE:
        r, r1, r2 = table_value(b, int(b[h + 7]), int(b[h + 6]), s)
        err, derr = delta - r, ddelta - r1 * ds
        g_s, g_ds = K * r1 + D * r2 * ds, D * r1
    elif kind == TIME:
        r, r1, _r2 = table_value(b, int(b[h + 7]), int(b[h + 6]), t - b[2])
        err, derr = delta - r, ddelta - r1
    elif kind == TIME_FEEDFORWARD:  # U(t) of the time since the step began, held outside
        c0 = table_value(b, int(b[h + 7]), int(b[h + 6]), t - b[2])[0]
        err, derr = 0.0, 0.0
    elif kind == FEEDFORWARD:  # U(T(s)) and the reference h(s), extrapolated
        c0, err, derr, g_s, g_ds = feedforward_terms(b, int(b[h + 7]), int(b[h + 6]), delta,
                                                     ddelta, s, ds, K, D)
    else:  # PIECEWISE: the piece in force at s
        off, pieces = int(b[h + 7]), int(b[h + 6])
        k = 0
        for j in range(pieces - 1):
            if b[off] * (s - b[off + 1 + j]) >= 0.0:
                k += 1
        po = off + int(b[off + pieces + k])
        c0, err, derr, g_s, g_ds = feedforward_terms(b, po + 1, int(b[po]), delta, ddelta,
                                                     s, ds, K, D)
    tau = c0 - K * err - D * derr
    lim = b[h + 5]
    if tau > lim:
        return lim, 0.0, 0.0, 0.0, 0.0
    if tau < -lim:
        return -lim, 0.0, 0.0, 0.0, 0.0
    return tau, -K, -D, g_s, g_ds


def kernel_source() -> list[str]:
    """Source lines of :func:`table_value`, :func:`interval`, :func:`cubic_at`,
    :func:`feedforward_terms` and :func:`law_torque` as numba ``njit``
    functions (``cache=True``) with the constants they read, for a generated module."""
    import inspect

    out = [f"HEAD, PLAIN, PHASE, TIME, FEEDFORWARD, PIECEWISE = {HEAD}, {PLAIN}, {PHASE}, "
           f"{TIME}, {FEEDFORWARD}, {PIECEWISE}", f"TIME_FEEDFORWARD = {TIME_FEEDFORWARD}", ""]
    for fn in (table_value, interval, cubic_at, feedforward_terms, law_torque):
        src = inspect.getsource(fn).splitlines()
        body = [ln for ln in src if ln.strip() and not ln.startswith("@")]
        doc_end = next(k for k, ln in enumerate(body[1:], 1) if ln.rstrip().endswith('"""'))
        out += ["@njit(cache=True)", body[0] + "  # pragma: no cover - runs compiled",
                *body[doc_end + 1:], ""]
    return out
