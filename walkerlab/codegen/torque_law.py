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
"""

from __future__ import annotations

import numpy as np

__all__ = ["FIELDS", "HEAD", "kernel_source", "law_torque", "pack_laws", "table_value"]

#: An actuator's header fields in the law block, in order.
FIELDS = ("kind", "constant_n_m", "stiffness_n_m_per_rad", "damping_n_m_s_per_rad",
          "rest_angle_rad", "limit_n_m", "knots", "table_offset")
HEAD = len(FIELDS)
#: Law kinds.
PLAIN, PHASE, TIME = 0, 1, 2


def pack_laws(laws) -> np.ndarray:
    """The law block (module docstring) of ``laws``, with the step's start time 0.

    Parameters
    ----------
    laws : sequence of tuple
        Per actuator ``(kind, constant, stiffness, damping, rest, limit, knots, coefs)``:
        ``kind`` one of :data:`PLAIN`, :data:`PHASE`, :data:`TIME`; ``limit`` [N m] or None;
        ``knots`` (n,) increasing and ``coefs`` (4, n - 1) (PPoly order, highest degree
        first), both None for a plain law.

    Returns
    -------
    ndarray (L,)
    """
    head = np.zeros((len(laws), HEAD))
    tables = []
    offset = 3 + HEAD * len(laws)
    for i, (kind, c, k, d, rest, limit, knots, coefs) in enumerate(laws):
        n = 0 if knots is None else len(knots)
        head[i] = (kind, c, k, d, rest, np.inf if limit is None else limit, n, offset)
        if n:
            block = np.concatenate([np.asarray(knots, float),
                                    np.asarray(coefs, float).T.ravel()])
            tables.append(block)
            offset += block.size
    body = np.concatenate([head.ravel(), *tables]) if tables else head.ravel()
    return np.concatenate([[3.0 + body.size, float(len(laws)), 0.0], body])


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


def law_torque(b, i, delta, ddelta, s, ds, t):
    """Actuator ``i``'s torque [N m] of the law block ``b`` and its partial derivatives
    ``(tau, dtau/ddelta, dtau/dddelta, dtau/ds, dtau/dds)``: ``delta``, ``ddelta`` the joint
    angle [rad] and rate [rad/s], ``s``, ``ds`` the phase variable [rad] and its rate
    [rad/s], ``t`` the time [s] (the step began at ``b[2]``).  Plain Python on floats and
    numba-compilable as it is (:func:`kernel_source`)."""
    h = 3 + HEAD * i
    kind, c0, K, D = b[h], b[h + 1], b[h + 2], b[h + 3]
    g_s, g_ds = 0.0, 0.0
    if kind == PLAIN:
        err, derr = delta - b[h + 4], ddelta
    elif kind == PHASE:
        r, r1, r2 = table_value(b, int(b[h + 7]), int(b[h + 6]), s)
        err, derr = delta - r, ddelta - r1 * ds
        g_s, g_ds = K * r1 + D * r2 * ds, D * r1
    else:
        r, r1, _r2 = table_value(b, int(b[h + 7]), int(b[h + 6]), t - b[2])
        err, derr = delta - r, ddelta - r1
    tau = c0 - K * err - D * derr
    lim = b[h + 5]
    if tau > lim:
        return lim, 0.0, 0.0, 0.0, 0.0
    if tau < -lim:
        return -lim, 0.0, 0.0, 0.0, 0.0
    return tau, -K, -D, g_s, g_ds


def kernel_source() -> list[str]:
    """Source lines of :func:`table_value` and :func:`law_torque` as numba ``njit``
    functions (``cache=True``) with the constants they read, for a generated module."""
    import inspect

    out = [f"HEAD, PLAIN, PHASE, TIME = {HEAD}, {PLAIN}, {PHASE}, {TIME}", ""]
    for fn in (table_value, law_torque):
        src = inspect.getsource(fn).splitlines()
        body = [ln for ln in src if ln.strip()]
        doc_end = next(k for k, ln in enumerate(body[1:], 1) if ln.rstrip().endswith('"""'))
        out += ["@njit(cache=True)", body[0] + "  # pragma: no cover - runs compiled",
                *body[doc_end + 1:], ""]
    return out
