"""The symbolic pieces of virtual constraints on a walker's generated model: the outputs'
``h0(q)``, the phase variable ``theta(q)`` and their first and second derivatives, taken by
sympy from the SAME derivation as the walker's flow
(:func:`walkerlab.codegen.legged.derive_legged`: its ``leg_angles``, points and guards), so
the decoupling matrix ``L_g L_f h = (dh/dq) M^-1 B`` and ``L_f^2 h`` of the
computed-torque law (Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56, Eq. 38)
are those of the flow the walker integrates.

For ``h0`` (k outputs) and ``theta`` the module returns numpy functions of the state
``x = (q, dq)`` (complex-safe: numpy's elementary functions), each evaluated at once:

- ``h0``, ``Jh0 = dh0/dq`` (k, n), ``dd0 = sum_jl d2h0/dq_j dq_l dq_j dq_l`` (k,);
- ``theta``, ``dtheta = dtheta/dq`` (n,), ``ddtheta = dq^T (d2theta/dq2) dq``;
- the swing foot's height above the ground (the ``swing_clearance`` guard), whether it is
  ahead of the stance foot (``swing_foot_ahead``) and the hip's horizontal position, of
  ``q``.
"""

from __future__ import annotations

import hashlib

from walkerlab import codestore

__all__ = ["derive_equations", "generate_pieces", "output_expressions", "output_module",
           "resolve_link"]


def derive_equations(structure):
    """The walker's symbolic equations (:class:`walkerlab.codegen.equations.Equations`), as
    its generated flow derives them (:func:`walkerlab.codegen.legged.derive_legged`, the
    free-jointed kinds too)."""
    from walkerlab.codegen import legged  # light

    return legged.derive_legged(structure)


def resolve_link(leg_angles: dict, link: str, where: str):
    """The ``leg_angles`` expression of an output's ``link`` (:data:`walkerlab.config.
    actuation.OUTPUT_LINKS`: ``stance_leg`` / ``swing_leg`` are the generated ``stance`` /
    ``swing``).

    Raises
    ------
    ValueError
        The walker has no such link (one line naming ``where`` and the links it has).
    """
    key = {"stance_leg": "stance", "swing_leg": "swing"}.get(link, link)
    if key not in leg_angles:
        have = sorted({"stance": "stance_leg", "swing": "swing_leg"}.get(k, k)
                      for k in leg_angles)
        raise ValueError(f"{where}: {link} is not a link of this walker (its links: "
                         f"{', '.join(have)})")
    return leg_angles[key]


def _joint_expr(leg_angles: dict, joint: str, where: str):
    from walkerlab.walker.joints import joint_links  # light

    first, second = joint_links(leg_angles, joint, where)
    return leg_angles[second] - leg_angles[first]


def output_expressions(eq, outputs, phase, joints, prefix: str):
    """The outputs' ``h0`` (k sympy expressions), the phase variable ``theta`` and the
    actuated joints' angles, of the walker's symbols (its parameters not substituted): the
    one reading of a virtual-constraint spec on a derivation (the generated pieces and the
    optimiser's CasADi functions, :mod:`walkerlab.optimal.transcription.virtual_constraints`).

    Raises
    ------
    ValueError
        A link, joint or coordinate the walker does not have (one line naming the key).
    """
    la = eq.leg_angles
    q = list(eq.q)
    h0 = []
    for i, (kind, name) in enumerate(outputs):
        where = f"{prefix}.outputs.{i}.{kind}"
        h0.append(resolve_link(la, name, where) if kind == "link"
                  else _joint_expr(la, name, where))
    if phase.link is not None:
        th = resolve_link(la, phase.link, f"{prefix}.phase.link")
    elif phase.point is not None:
        th = _along(eq, eq.points["hip"])
    else:
        roles = [str(v)[2:] for v in q]
        bad = [k for k in phase.coordinates if k not in roles]
        if bad:
            raise ValueError(f"{prefix}.phase.coordinates.{bad[0]}: not a coordinate of "
                             f"this walker (its coordinates: {', '.join(roles)})")
        th = sum(c * q[roles.index(k)] for k, c in phase.coordinates.items())
    return h0, th, [_joint_expr(la, j, f"{prefix}.joints") for j in joints]


def _expressions(eq, params, outputs, phase, joints, prefix: str):
    """The flat lists of sympy expressions of the pieces (module docstring), the
    parameters substituted: ``(out, foot, B)``.

    Raises
    ------
    ValueError
        A link, joint or coordinate the walker does not have (one line naming the key).
    """
    import sympy as sp

    q, dq = list(eq.q), list(eq.dq)
    n = len(q)
    h0, th, joint_exprs = output_expressions(eq, outputs, phase, joints, prefix)
    sub = dict(zip(eq.params, params))

    def num(e):
        return sp.sympify(e).subs(sub)
    h0 = [num(e) for e in h0]
    th = num(th)
    J = [[sp.diff(e, v) for v in q] for e in h0]
    dd = [sum(sp.diff(J[i][j], q[m]) * dq[j] * dq[m] for j in range(n) for m in range(n))
          for i in range(len(h0))]
    gth = [sp.diff(th, v) for v in q]
    ddth = sum(sp.diff(gth[j], q[m]) * dq[j] * dq[m] for j in range(n) for m in range(n))
    B = [num(sp.diff(e, v)) for v in q for e in joint_exprs]
    foot = [num(eq.guards["swing_clearance"]), num(eq.guards["swing_foot_ahead"]),
            num(_along(eq, eq.points["hip"]))]
    out = [*h0, *(e for row in J for e in row), *dd, th, *gth, ddth]
    return out, foot, B


def _along(eq, point):
    """A point's coordinate along the ground (the slope's tangent), from the stance foot
    [m]."""
    import sympy as sp

    gamma = [p for p in eq.params if str(p) == "gamma"]
    g = gamma[0] if gamma else 0
    return point[0] * sp.cos(g) - point[1] * sp.sin(g)


def generate_pieces(eq, params, outputs, phase, joints, prefix: str, key: str) -> str:
    """Source of the pieces' module: ``out(x)``, ``foot(x)``, ``B(x)`` (flat lists, numpy
    code by :func:`sympy.lambdify`, common subexpressions eliminated) and ``K``, ``N``."""
    import inspect

    import numpy
    import sympy as sp

    out, foot, B = _expressions(eq, params, outputs, phase, joints, prefix)
    args = [*eq.q, *eq.dq]
    body, names = [], set()
    for name, exprs in (("out", out), ("foot", foot), ("B", B)):
        fn = sp.lambdify(args, exprs, "numpy", cse=True)
        src = inspect.getsource(fn).replace("def _lambdifygenerated(", f"def _{name}(", 1)
        body += [src, "", f"def {name}(x):", f"    return _{name}(*x)", ""]
        names |= _global_names(fn.__code__)
    # the names of numpy's star import that the functions use (lambdify's ``sin``, ``cos``,
    # ...): the same objects, without the star import's cost (it loads every lazy numpy
    # submodule, ~0.15 s a process)
    used = sorted(names & set(numpy.__all__))
    head = [f"# walkerlab virtual-constraint pieces (walkerlab.codegen.virtual_constraints); "
            f"key {key}",
            "# Do not edit: regenerated when the walker, its outputs or the generator change.",
            "import numpy"]
    if used:
        head.append(f"from numpy import {', '.join(used)}  # noqa: F401 (lambdify's names)")
    return "\n".join([*head, "", f"K, N = {len(outputs)}, {len(eq.q)}", "", *body]) + "\n"


def _global_names(code) -> set[str]:
    """The names a code object (and those nested in it) reads as globals or attributes."""
    names = set(code.co_names)
    for c in code.co_consts:
        if hasattr(c, "co_names"):
            names |= _global_names(c)
    return names


def _module(name: str, generate, structure, params, outputs, phase, joints, prefix):
    """The generated module ``<key>_<name>_<hash>.py`` of ``generate(eq, params, outputs,
    phase, joints, prefix, key) -> str`` on ``structure``'s derivation, the hash covering
    the parameters, outputs, phase, joints and this generator's source."""
    from walkerlab.codegen import cache

    key = cache.cache_key(structure)
    what = repr((tuple(float(p) for p in params), tuple(outputs), phase.model_dump_json(),
                 tuple(joints), codestore.source_hash(__file__)[:12]))
    tag = hashlib.sha256(what.encode()).hexdigest()[:12]
    return codestore.import_generated(
        f"{key}_{name}_{tag}.py", f"walkerlab_{name}_{key}_{tag}",
        lambda: generate(derive_equations(structure), params, outputs, phase, joints, prefix,
                         key))


def output_module(structure, params, outputs, phase, joints, prefix):
    """The generated module of the outputs and phase variable (module docstring; read by
    :class:`walkerlab.models.compiled_flows.OutputPieces`) of ``structure``'s derivation
    with ``params`` (generated on a cache miss, file ``<key>_vc_<hash>.py``: :func:`_module`).

    Raises
    ------
    ValueError
        A link, joint or coordinate the walker does not have (one line naming the key; on
        a cache miss, from the derivation).
    """
    return _module("vc", generate_pieces, structure, params, outputs, phase, joints, prefix)


#: the computed-torque law over the generated ``pieces`` and ``flow_terms`` (numba source,
#: appended to every compiled module: :func:`generate_compiled_controller`)
_LAW = '''
@njit(cache=True)
def _bezier(c, s):  # pragma: no cover - runs compiled
    k, m1 = c.shape
    M = m1 - 1
    hd = np.zeros(k) + 0.0 * s  # real or complex, as s
    hd1 = np.zeros(k) + 0.0 * s
    hd2 = np.zeros(k) + 0.0 * s
    ps = np.ones(m1) + 0.0 * s  # powers of s and of 1 - s by products, not **: a complex
    qs = np.ones(m1) + 0.0 * s  # power of a negative base (s outside [0, 1]) would go
    for j in range(M):          # through its argument and spoil the complex step
        ps[j + 1] = ps[j] * s
        qs[j + 1] = qs[j] * (1.0 - s)
    for j in range(M + 1):
        b = BINOM[M, j] * ps[j] * qs[M - j]
        for i in range(k):
            hd[i] += c[i, j] * b
    for j in range(M):
        b = BINOM[M - 1, j] * ps[j] * qs[M - 1 - j]
        for i in range(k):
            hd1[i] += M * (c[i, j + 1] - c[i, j]) * b
    for j in range(M - 1):
        b = BINOM[M - 2, j] * ps[j] * qs[M - 2 - j]
        for i in range(k):
            hd2[i] += M * (M - 1) * (c[i, j + 2] - 2.0 * c[i, j + 1] + c[i, j]) * b
    return hd, hd1, hd2


@njit(cache=True)
def law(x, alpha, theta_plus, dtheta, B, kp, kd, limit):  # pragma: no cover - runs compiled
    v = np.empty(NOUT, dtype=x.dtype)  # real or complex (complex-step derivatives), as x
    pieces(x, v)
    a = K + K * N
    th = v[a + K]
    ddth = v[a + K + 1 + N]
    ds = 0.0
    for j in range(N):
        ds += v[a + K + 1 + j] * x[N + j]
    ds /= dtheta
    hd, hd1, hd2 = _bezier(alpha, (th - theta_plus) / dtheta)
    J = np.empty((K, N), dtype=x.dtype)  # dh/dq
    for i in range(K):
        for j in range(N):
            J[i, j] = v[K + i * N + j] - hd1[i] * v[a + K + 1 + j] / dtheta
    Mm = np.empty((N, N), dtype=x.dtype)
    f = np.empty(N, dtype=x.dtype)
    flow_terms(x, Mm, f)
    rhs = np.empty((N, K + 1), dtype=x.dtype)
    rhs[:, :K] = B
    rhs[:, K] = f
    sol = np.linalg.solve(Mm, rhs)  # [M^-1 B, M^-1 (-C dq - G)]
    A = np.zeros((K, K + 1), dtype=x.dtype)  # [L_g L_f h, -(L_f^2 h + kp y + kd y')]
    for i in range(K):
        dy = 0.0
        Jf = 0.0
        for j in range(N):
            dy += J[i, j] * x[N + j]
            Jf += J[i, j] * sol[j, K]
            for m in range(K):
                A[i, m] += J[i, j] * sol[j, m]
        lf2 = v[K + K * N + i] - hd2[i] * ds * ds - hd1[i] * ddth / dtheta + Jf
        A[i, K] = -lf2 - kp * (v[i] - hd[i]) - kd * dy
    u = np.linalg.solve(A[:, :K].copy(), A[:, K:].copy())[:, 0].copy()
    if limit > 0.0:
        for i in range(K):
            if u[i].real > limit:  # the real parts compared, as the numpy law does
                u[i] = limit
            elif u[i].real < -limit:
                u[i] = -limit
    acc = np.zeros(N, dtype=x.dtype)
    for j in range(N):
        for m in range(K):
            acc[j] += sol[j, m] * u[m]
    return u, acc
'''


def generate_compiled_controller(eq, params, outputs, phase, joints, prefix: str,
                                 key: str) -> str:
    """numba source of the computed-torque law of :class:`walkerlab.models.virtual_constraints.
    VirtualConstraintController` (Westervelt, Grizzle & Koditschek 2003, Eq. 38) for real
    states: ``pieces(x, v)`` writes :func:`generate_pieces`' ``out`` into ``v``,
    ``flow_terms(x, M, f)`` the mass matrix ``M`` (n, n) and ``f = -C dq - G`` (n,) of the
    walker's flow (the same derivation, the parameters substituted), and ``law(x, alpha,
    theta_plus, dtheta, B, kp, kd, limit) -> (u (k,), M^-1 B u (n,))`` the saturated torques
    [N m] (``limit`` <= 0: none) and the acceleration they add [rad/s^2]."""
    import sympy as sp
    from sympy.printing.pycode import PythonCodePrinter

    pr = PythonCodePrinter({"fully_qualified_modules": False, "standard": "python3"})
    out, _foot, _B = _expressions(eq, params, outputs, phase, joints, prefix)
    sub = dict(zip(eq.params, params))
    n = len(eq.q)
    f = (-eq.C * sp.Matrix(eq.dq) - eq.G).subs(sub)
    Mm = eq.M.subs(sub)
    args = [*eq.q, *eq.dq]
    unpack = "\n".join(f"    {a} = x[{i}]" for i, a in enumerate(args))

    def function(name, targets):
        repl, red = sp.cse([sp.sympify(e) for _, e in targets],
                           symbols=sp.numbered_symbols("_s"), order="none")
        body = [f"    {pr.doprint(a)} = {pr.doprint(e)}" for a, e in repl]
        body += [f"    {t} = {pr.doprint(e)}" for (t, _), e in zip(targets, red)]
        sig = ", ".join(["x", *sorted({t.split("[")[0] for t, _ in targets})])
        return ["@njit(cache=True)", f"def {name}({sig}):  # pragma: no cover - runs compiled",
                unpack, *body, ""]

    lines = [f"# walkerlab compiled virtual-constraint law (walkerlab.codegen.virtual_constraints);"
             f" key {key}",
             "# Do not edit: regenerated when the walker, its outputs or the generator change.",
             "from numpy import sin, cos, tan, sqrt, arctan as atan, arctan2 as atan2, "
             "arccos as acos, arcsin as asin  # noqa: F401 (real and complex)",
             "import math", "import numpy as np", "from numba import njit", "",
             f"K, N, NOUT = {len(outputs)}, {n}, {len(out)}",
             "BINOM = np.array([[float(math.comb(a, b)) for b in range(16)] for a in range(16)])",
             ""]
    lines += function("pieces", [(f"v[{i}]", e) for i, e in enumerate(out)])
    lines += function("flow_terms", [(f"M[{i}, {j}]", Mm[i, j]) for i in range(n)
                                     for j in range(n)] + [(f"f[{i}]", f[i]) for i in range(n)])
    return "\n".join(lines) + _LAW


def compiled_controller(structure, params, outputs, phase, joints, prefix):
    """The imported numba module of :func:`generate_compiled_controller` (file
    ``<key>_vcnb_<hash>.py`` in the user cache, generated on a miss; numba's machine code
    cached there too), or None where numba cannot be imported (the numpy law is then used).

    Raises
    ------
    ValueError
        As :func:`output_module`.
    """
    try:
        import numba  # noqa: F401
    except ImportError:  # pragma: no cover - numba is a dependency
        return None
    return _module("vcnb", generate_compiled_controller, structure, params, outputs, phase,
                   joints, prefix)
