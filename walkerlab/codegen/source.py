"""Python source of a walker's equations, generated from
:class:`~walkerlab.codegen.equations.Equations`.

The generated module defines one function, ``make(p) -> dict[str, callable]``, that binds the
parameter vector ``p`` (``Structure.param_names`` order) in closures.  The hot functions
(``flow``, ``flow_jacobian``, ``reset``, ``reset_jacobian``, guards) are straight-line scalar
code on Python floats (sympy ``cse`` + ``pycode``, ``math`` functions) with the small linear
solve written out as an adjugate / determinant for n <= 3, by LU factors above; the
functions used on whole trajectories (``energies``, ``points``, ``leg_angles``) are numpy code
that accepts states of shape (2n,) or (2n, k).

Generated functions (``x`` is the role-ordered state ``[q, dq]``, shape (2n,)):

==================  ==========================================================================
``flow(t, x)``      ``[dq, qdd]`` with ``M qdd = -C dq - G`` (2n,)
``flow_jacobian``   ``(t, x) -> d flow / dx`` (2n, 2n), for variational equations / stiff solvers
``flow_variational`` ``(t, [x, Phi]) -> [flow, (d flow / dx) Phi]`` (2n + 4n^2,), row-major Phi
``reset(x)``        heel-strike impact and role swap (2n,)
``reset_jacobian``  ``x -> d reset / dx`` (2n, 2n)
``guard_<name>``    ``(t, x) -> float``; ``grad_<name>(x)`` its gradient (2n,)
``section(x)``      state without the coordinate eliminated on the heel-strike surface (2n-1,)
``from_section(z)`` inverse of ``section`` on that surface (2n,)
``energies(X)``     ``(kinetic, potential)`` [J]
``points(X)``       dict of named positions (2,) or (2, k) [m] ((3,) ... in 3D)
``point_velocities`` ``X -> dict`` of the same points' velocities (2,) or (2, k) [m/s]
``leg_angles(X)``   dict ``stance_angle, swing_angle, stance_rate, swing_rate`` (absolute)
``matrices(x)``     ``(M, C, G)`` numpy arrays
``impact_matrices`` ``q -> (De, E)`` extended impact system (paper Eq. 6-7)
==================  ==========================================================================
"""

from __future__ import annotations

import re
from dataclasses import replace

import sympy as sp
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.pycode import PythonCodePrinter

from walkerlab.codegen.equations import Equations

PRINTER = PythonCodePrinter({"fully_qualified_modules": False, "standard": "python3"})
_NP = NumPyPrinter({"fully_qualified_modules": True})
IND = "        "


_HOISTED: list[str] = []  # parameter-only subexpressions, computed once in make(p)
_PARAMS: set = set()  # the parameters and every hoisted symbol
_COUNT = [0]


def start_module(params) -> list[str]:
    """Start the source of one generated module: no hoisted lines yet, ``params`` (symbols)
    the only parameter-only names, numbering of the common subexpressions from 0.  Returns
    the list of hoisted lines (parameter-only subexpressions computed once in ``make(p)``),
    filled as the module's functions are generated."""
    _HOISTED.clear()
    _PARAMS.clear()
    _PARAMS.update(params)
    _COUNT[0] = 0
    return _HOISTED


def cse_lines(exprs, printer):
    """``(lines, reduced)``: common subexpressions as assignments, and the reduced exprs.

    Subexpressions of the parameters only are moved to ``make(p)`` (closure constants)."""
    _COUNT[0] += 1
    repl, reduced = sp.cse(list(exprs), symbols=sp.numbered_symbols(f"_c{_COUNT[0]}_"),
                           order="none")
    lines = []
    for a, e in repl:
        if e.free_symbols <= _PARAMS:
            _PARAMS.add(a)
            _HOISTED.append(f"    {printer.doprint(a)} = {printer.doprint(e)}")
        else:
            lines.append(f"{IND}{printer.doprint(a)} = {printer.doprint(e)}")
    return lines, reduced


def unpack(eq: Equations) -> str:
    """Unpack ``x`` into Python floats (``tolist``: float arithmetic is faster than numpy's)."""
    names = ", ".join(str(s) for s in (*eq.q, *eq.dq))
    return (f"{IND}try:\n{IND}    {names}, = x.tolist()\n{IND}except AttributeError:\n"
            f"{IND}    {names}, = x")


def _bind(names, exprs) -> tuple[list[str], list[str]]:
    """Assign ``exprs`` to ``names``: zero entries become ``"0"`` (pruned by the solve and the
    products below), parameter-only entries are computed once in ``make(p)``.

    Returns the lines and the name (or ``"0"``) that now holds each expression."""
    _COUNT[0] += 1
    lines, out = [], []
    for a, e in zip(names, exprs):
        if e == 0:
            out.append("0")
        elif e.free_symbols <= _PARAMS:
            h = f"_k{_COUNT[0]}{a}"
            _HOISTED.append(f"    {h} = {PRINTER.doprint(e)}")
            _PARAMS.add(sp.Symbol(h))
            out.append(h)
        else:
            lines.append(f"{IND}{a} = {PRINTER.doprint(e)}")
            out.append(a)
    return lines, out


#: the largest matrix whose inverse is written as its adjugate over its determinant; a
#: larger one (a walker in 3D, the five-link biped) is inverted by its LU factors
ADJUGATE_MAX_N = 3


def _solve_lines(n: int, mnames, prefix: str) -> tuple[list[str], list[list[str]]]:
    """Lines computing the inverse of the n x n matrix whose entries are named ``mnames``
    (``"0"`` for an entry known to vanish: the adjugate then drops its terms), named
    ``{prefix}{i}{j}`` (``"0"`` for an entry that vanishes).

    Up to :data:`ADJUGATE_MAX_N` the adjugate over the determinant; above it the LU factors
    (:func:`_lu_inverse_lines`): a determinant expanded for n >= 4 sums many products much
    larger than itself, and the cancellation left the six-coordinate kneed walker's
    accelerations with round-off of 1e-10 relative (cond(M) about 1.5e3), 1e-16 by its
    factors."""
    if n > ADJUGATE_MAX_N:
        return _lu_inverse_lines(n, mnames, prefix)
    S = sp.Matrix(n, n, lambda i, j: 0 if mnames[i][j] == "0" else sp.Symbol(mnames[i][j]))
    det = S.det(method="berkowitz")
    adj = S.adjugate()
    lines = [f"{IND}{prefix}id = 1.0 / ({PRINTER.doprint(det)})"]
    inv = [["0"] * n for _ in range(n)]
    for i in range(n):
        for j in range(n):
            if adj[i, j] != 0:
                inv[i][j] = f"{prefix}{i}{j}"
                lines.append(f"{IND}{inv[i][j]} = ({PRINTER.doprint(adj[i, j])}) * {prefix}id")
    return lines, inv


def _lu_inverse_lines(n: int, mnames, prefix: str) -> tuple[list[str], list[list[str]]]:
    """Lines computing the inverse of the n x n matrix whose entries are named ``mnames``
    from its LU factors (Doolittle, no pivoting: the matrices inverted are a walker's mass
    matrix or its impact matrix, symmetric positive definite, whose elimination without
    pivoting is backward stable; Golub & Van Loan 2013, Sec. 4.2), then the inverse's
    columns by forward and back substitution on the unit vectors.  Every intermediate is a
    named line, so the code grows as n^3 (the adjugate's as n!), and entries known to vanish
    (``"0"``) drop their terms.  Returns the lines and the inverse's entry names, as
    :func:`_solve_lines`."""
    zero, one = sp.Integer(0), sp.Integer(1)
    A = [[zero if mnames[i][j] == "0" else sp.Symbol(mnames[i][j]) for j in range(n)]
         for i in range(n)]
    lines: list[str] = []

    def bind(tag: str, e):
        if e == 0 or e == 1 or e.is_Symbol:
            return e
        s = sp.Symbol(f"{prefix}{tag}")
        lines.append(f"{IND}{s} = {PRINTER.doprint(e)}")
        return s

    L = [[zero] * n for _ in range(n)]
    rp = [zero] * n  # the pivots' reciprocals
    for k in range(n):
        rp[k] = bind(f"p{k}", 1 / A[k][k])
        for i in range(k + 1, n):
            if A[i][k] == 0:
                continue
            L[i][k] = bind(f"l{i}_{k}", A[i][k] * rp[k])
            for j in range(k + 1, n):
                if A[k][j] != 0:
                    A[i][j] = bind(f"u{k}_{i}_{j}", A[i][j] - L[i][k] * A[k][j])
    inv = [["0"] * n for _ in range(n)]
    for c in range(n):
        y = [zero] * n
        for i in range(n):
            y[i] = bind(f"y{c}_{i}", (one if i == c else zero)
                        - sum((L[i][k] * y[k] for k in range(i)), zero))
        x = [zero] * n
        for i in reversed(range(n)):
            e = (y[i] - sum((A[i][j] * x[j] for j in range(i + 1, n)), zero)) * rp[i]
            if e != 0:
                x[i] = sp.Symbol(f"{prefix}{i}{c}")
                inv[i][c] = str(x[i])
                lines.append(f"{IND}{x[i]} = {PRINTER.doprint(e)}")
    return lines, inv


def _matvec(inv, vec) -> list[str]:
    """``inv @ vec`` as expressions, without the terms of entries named ``"0"``."""
    out = []
    for row in inv:
        terms = [f"{a} * {b}" for a, b in zip(row, vec) if a != "0" and b != "0"]
        out.append(" + ".join(terms) if terms else "0.0")
    return out


def _array(rows) -> str:
    if rows and isinstance(rows[0], list):
        return "np.array((" + ", ".join("(" + ", ".join(r) + ",)" for r in rows) + ",))"
    return "np.array((" + ", ".join(rows) + ",))"


def flow_lines(eq: Equations, jac: bool, name: str | None = None,
          variational: str | None = None, parts: bool = False):
    """``flow``, or with ``jac`` its Jacobian; with ``variational`` (a name) also the
    right-hand side of the variational equations from the same lines,
    ``(t, y) -> [flow(x), (flow_jacobian(x) @ Phi).ravel()]`` for ``y = [x, Phi.ravel()]``
    (the Jacobian's entries are never put into an array, its identity rows are copies).
    ``parts``: ``(body lines, outputs)`` instead, the outputs being the 2n expressions (flow)
    or 2n rows of 2n (Jacobian), for
    :func:`walkerlab.codegen.compiled_source.generate_compiled`."""
    n = len(eq.q)
    q, dq = eq.q, eq.dq
    r = -eq.C * sp.Matrix(dq) - eq.G
    exprs = list(eq.M) + list(r)
    if jac:
        exprs += [sp.diff(eq.M[i, j], q[k]) for k in range(n) for i in range(n) for j in range(n)]
        exprs += [sp.diff(r[i], q[k]) for k in range(n) for i in range(n)]
        exprs += [sp.diff(r[i], dq[k]) for k in range(n) for i in range(n)]
    lines, red = cse_lines(exprs, PRINTER)
    bound, names = _bind([f"_M{i}{j}" for i in range(n) for j in range(n)]
                         + [f"_r{i}" for i in range(n)], red[:n * n + n])
    lines += bound
    mn = [names[i * n:(i + 1) * n] for i in range(n)]
    rn = names[n * n:]
    inv_lines, inv = _solve_lines(n, mn, "_i")
    lines += inv_lines
    qdd = [f"_a{i}" for i in range(n)]
    lines += [f"{IND}{a} = {e}" for a, e in zip(qdd, _matvec(inv, rn))]
    name = name or ("flow_jacobian" if jac else "flow")
    head = [f"    def {name}(t, x):", unpack(eq)]
    if not jac:
        if parts:
            return lines, [str(s) for s in dq] + qdd
        return head + lines + [f"{IND}return {_array([str(s) for s in dq] + qdd)}"]
    k0 = n * n + n
    dM = red[k0:k0 + n ** 3]
    dr_q = red[k0 + n ** 3:k0 + n ** 3 + n * n]
    dr_dq = red[k0 + n ** 3 + n * n:]
    cols = []
    for k in range(n):  # d qdd / d q_k = Minv (dr/dq_k - dM/dq_k qdd)
        w = []
        for i in range(n):
            e = dr_q[k * n + i] - sum(dM[k * n * n + i * n + j] * sp.Symbol(qdd[j])
                                      for j in range(n))
            w.append("0" if e == 0 else f"_w{k}_{i}")
            if e != 0:
                lines.append(f"{IND}_w{k}_{i} = {PRINTER.doprint(e)}")
        cols.append(_matvec(inv, w))
    for k in range(n):  # d qdd / d dq_k = Minv dr/d dq_k
        bound, w = _bind([f"_v{k}_{i}" for i in range(n)], dr_dq[k * n:(k + 1) * n])
        lines += bound
        cols.append(_matvec(inv, w))
    rows = [["0.0"] * (2 * n) for _ in range(n)]
    for i in range(n):
        rows[i][n + i] = "1.0"
    for i in range(n):
        rows.append([f"({cols[c][i]})" for c in range(2 * n)])
    if parts:
        return lines, rows
    out = head + lines + [f"{IND}return {_array(rows)}"]
    if variational:
        N = 2 * n
        names = ", ".join(str(v) for v in (*q, *dq))
        head = [f"    def {variational}(t, y):",
                f"{IND}_y = y.tolist() if hasattr(y, 'tolist') else list(y)",
                f"{IND}{names}, = _y[:{N}]", f"{IND}_P = _y[{N}:]"]
        ret = [str(v) for v in dq] + qdd
        for i in range(n):  # d q / dt = dq: rows of Phi
            ret += [f"_P[{(n + i) * N + k}]" for k in range(N)]
        for i in range(n):
            nz = [c for c in range(N) if cols[c][i] != "0.0"]
            lines += [f"{IND}_J{i}_{c} = {cols[c][i]}" for c in nz]
            ret += [" + ".join(f"_J{i}_{c} * _P[{c * N + k}]" for c in nz) or "0.0"
                    for k in range(N)]
        out += head + lines + [f"{IND}return {_array(ret)}"]
    return out


def reset_lines(eq: Equations, jac: bool, name: str | None = None) -> list[str]:
    """``Mi dq+ = B dq-`` then the role swap ``q_new = relabel_q(q)``, ``dq_new = R dq+``."""
    n = len(eq.q)
    q, dq = eq.q, eq.dq
    exprs = list(eq.Mi) + list(eq.B)
    if jac:
        exprs += [sp.diff(eq.Mi[i, j], q[k]) for k in range(n) for i in range(n) for j in range(n)]
        exprs += [sp.diff(eq.B[i, j], q[k]) for k in range(n) for i in range(n) for j in range(n)]
    lines, red = cse_lines(exprs, PRINTER)
    bound, names = _bind([f"_M{i}{j}" for i in range(n) for j in range(n)]
                         + [f"_B{i}{j}" for i in range(n) for j in range(n)], red[:2 * n * n])
    lines += bound
    mn = [names[i * n:(i + 1) * n] for i in range(n)]
    bn = [names[n * n + i * n:n * n + (i + 1) * n] for i in range(n)]
    inv_lines, inv = _solve_lines(n, mn, "_i")
    lines += inv_lines
    dqs = [str(s) for s in dq]
    lines += [f"{IND}_h{i} = {e}" for i, e in enumerate(_matvec(bn, dqs))]
    post = [f"_p{i}" for i in range(n)]
    lines += [f"{IND}{a} = {e}" for a, e in zip(post, _matvec(inv, [f"_h{i}" for i in range(n)]))]
    R = eq.relabel_rate
    qn = [PRINTER.doprint(e) for e in eq.relabel_q]
    dqn = [PRINTER.doprint(e) for e in R * sp.Matrix([sp.Symbol(p) for p in post])]
    name = name or ("reset_jacobian" if jac else "reset")
    head = [f"    def {name}(x):", unpack(eq)]
    if not jac:
        return head + lines + [f"{IND}return {_array(qn + dqn)}"]
    k0 = 2 * n * n
    dMi, dB = red[k0:k0 + n ** 3], red[k0 + n ** 3:]
    # d dq+ / d q_k = Minv (dB/dq_k dq- - dMi/dq_k dq+);  d dq+ / d dq- = Minv B
    D = sp.zeros(n, 2 * n)
    for k in range(n):
        for i in range(n):
            w = sum(dB[k * n * n + i * n + j] * dq[j]
                    - dMi[k * n * n + i * n + j] * sp.Symbol(post[j]) for j in range(n))
            lines.append(f"{IND}_w{k}_{i} = {PRINTER.doprint(w)}")
        col = _matvec(inv, [f"_w{k}_{i}" for i in range(n)])
        for i in range(n):
            lines.append(f"{IND}_D{i}_{k} = {col[i]}")
            D[i, k] = sp.Symbol(f"_D{i}_{k}")
    for k in range(n):
        col = _matvec(inv, [bn[i][k] for i in range(n)])
        for i in range(n):
            lines.append(f"{IND}_D{i}_{n + k} = {col[i]}")
            D[i, n + k] = sp.Symbol(f"_D{i}_{n + k}")
    Jq = eq.relabel_q.jacobian(sp.Matrix(q))
    rows = [[PRINTER.doprint(Jq[i, j]) for j in range(n)] + ["0.0"] * n for i in range(n)]
    RD = R * D
    rows += [[PRINTER.doprint(RD[i, j]) for j in range(2 * n)] for i in range(n)]
    return head + lines + [f"{IND}return {_array(rows)}"]


def _guards(eq: Equations) -> list[str]:
    x = sp.Matrix([*eq.q, *eq.dq])
    out = []
    for name, g in eq.guards.items():
        lines, red = cse_lines([g], PRINTER)
        out += [f"    def guard_{name}(t, x):", unpack(eq), *lines,
                f"{IND}return {PRINTER.doprint(red[0])}"]
        grad = [sp.diff(g, s) for s in x]
        lines, red = cse_lines(grad, PRINTER)
        out += [f"    def grad_{name}(x):", unpack(eq), *lines,
                f"{IND}return {_array([PRINTER.doprint(e) for e in red])}"]
    return out


def _section(eq: Equations) -> list[str]:
    n = len(eq.q)
    d = eq.section_drop
    tied = eq.section_tied or {}
    keep = [i for i in range(2 * n) if i != d and i not in tied]
    z = sp.symbols(f"z0:{len(keep)}")
    full = sp.Matrix([*eq.q, *eq.dq])
    sub = {full[i]: z[k] for k, i in enumerate(keep)}
    xs = [str(z[keep.index(i)]) if i in keep else PRINTER.doprint(eq.drop_solution.subs(sub))
          for i in range(2 * n)]
    for i, j in tied.items():
        xs[i] = xs[j]
    # a closed-form angle (acos, atan2 of math) takes real numbers only: complex input (a
    # complex-step derivative) is refused, so that the caller differentiates otherwise
    real_only = ([f"{IND}if np.iscomplexobj(z):",
                  f"{IND}    raise TypeError('from_section: real section coordinates only')"]
                 if eq.drop_solution.has(sp.acos, sp.atan2) else [])
    return [
        "    def section(x):",
        f"{IND}return np.asarray(x)[{keep!r}]",
        "    def from_section(z):",
        *real_only,
        f"{IND}{', '.join(str(s) for s in z)}, = z",
        f"{IND}return {_array(xs)}",
    ]


def numpy_fn(name: str, eq: Equations, named: dict, args: str = "x",
             slices: dict | None = None) -> list[str]:
    """A numpy function returning ``{key: expr or Matrix}`` for states (2n,) or (2n, k).

    Parameters
    ----------
    name : str
        The function's name.
    eq : Equations
    named : dict
        ``{key: sympy expression or Matrix}``, the returned dict's entries.
    args : {"x", "q"}
        The argument: the state ``x = [q, dq]`` (2n,) or the coordinates ``q`` (n,).
    slices : dict, optional
        ``{function name: (key, index)}``: beside the function, one function per entry
        returning the ``index``-th element (flattened, row-major) of ``named[key]`` alone,
        with only the common subexpressions it needs - the same printed expressions on the
        same numbers, so the same value bit for bit as ``name(x)[key][index]`` (a point's
        coordinate for a reward, without the other points).

    Returns
    -------
    list of str
        The source lines (indented for :func:`generate`'s ``make``).
    """
    keys = list(named)
    flat, shapes = [], []
    for k in keys:
        e = named[k]
        if isinstance(e, sp.MatrixBase):
            shapes.append(e.shape)
            flat += list(e)
        else:
            shapes.append(None)
            flat.append(e)
    _COUNT[0] += 1
    repl, red = sp.cse(flat, symbols=sp.numbered_symbols(f"_n{_COUNT[0]}_"), order="none")
    lines = [f"{IND}{_NP.doprint(a)} = {_NP.doprint(e)}" for a, e in repl]
    state = set(eq.q + eq.dq)
    for a, e in repl:  # cse symbols that depend on the state
        if e.free_symbols & state:
            state.add(a)
    ref = str(eq.q[0])
    out, pos = [], 0

    def pr(e):  # constants are broadcast to the shape of the state's rows
        s = _NP.doprint(e)
        return s if e.free_symbols & state else f"({s}) + 0.0 * {ref}"

    for k, shp in zip(keys, shapes):
        if shp is None:
            out.append(f"{k!r}: {pr(red[pos])}")
            pos += 1
        else:
            r, c = shp
            vals = [pr(e) for e in red[pos:pos + r * c]]
            pos += r * c
            if c == 1:
                out.append(f"{k!r}: np.array(({', '.join(vals)},))")
            else:
                rows = ["(" + ", ".join(vals[i * c:(i + 1) * c]) + ",)" for i in range(r)]
                out.append(f"{k!r}: np.array(({', '.join(rows)},))")
    unpack = f"{IND}{', '.join(str(s) for s in (*eq.q, *eq.dq))}, = x" if args == "x" else \
        f"{IND}{', '.join(str(s) for s in eq.q)}, = q"
    fns = [f"    def {name}({args}):", unpack, *lines, f"{IND}return {{{', '.join(out)}}}"]
    starts, at = {}, 0
    for k, shp in zip(keys, shapes):
        starts[k] = at
        at += 1 if shp is None else shp[0] * shp[1]
    for fname, (key, index) in (slices or {}).items():
        fns += _slice_fn(fname, args, unpack, repl, red[starts[key] + index], pr)
    return fns


def _slice_fn(fname: str, args: str, unpack: str, repl: list, expr, pr) -> list[str]:
    """One entry of :func:`numpy_fn`'s output as a function of its own: the common
    subexpressions ``expr`` needs (``repl``'s, in their order) and ``expr`` printed as the
    whole function prints it (``pr``)."""
    need = set(expr.free_symbols)
    kept = []
    for a, e in reversed(repl):
        if a in need:
            kept.append((a, e))
            need |= e.free_symbols
    lines = [f"{IND}{_NP.doprint(a)} = {_NP.doprint(e)}" for a, e in reversed(kept)]
    return [f"    def {fname}({args}):", unpack, *lines, f"{IND}return {pr(expr)}"]


def _point_velocities(eq: Equations) -> dict:
    """Velocities (2, 1) [m/s] of the named points, ``d(point)/dq dq`` (exact, linear in
    ``dq``): evaluated with complex numbers they are analytic in the whole state, so a complex
    step differentiates through them (a point's Jacobian by a complex step cannot be)."""
    q, dq = sp.Matrix(eq.q), sp.Matrix(eq.dq)
    return {k: sp.Matrix(v).jacobian(q) * dq for k, v in eq.points.items()}


def generate(eq: Equations, param_names, key: str) -> str:
    """Source text of the generated module (see module docstring).

    Parameters
    ----------
    eq : Equations
    param_names : sequence of str
        Parameter vector order.
    key : str
        Cache key, written into the header.
    """
    la = eq.leg_angles
    rates = {k: sum(sp.diff(v, qi) * dqi for qi, dqi in zip(eq.q, eq.dq)) for k, v in la.items()}
    start_module(eq.params)
    fast = [*flow_lines(eq, False), *flow_lines(eq, True, variational="flow_variational"),
            *reset_lines(eq, False), *reset_lines(eq, True), *_guards(eq)]
    if eq.locked is not None:  # kneed walker: knee-locked flow and the knee strike
        lk = replace(eq, M=eq.locked[0], C=eq.locked[1], G=eq.locked[2])
        # the knee strike's coordinates: the shank's angle the thigh's (its section tie)
        tied = eq.section_tied or {}
        q_lock = sp.Matrix([eq.q[tied.get(i, i)] for i in range(len(eq.q))])
        kn = replace(eq, Mi=eq.knee_impact[0], B=eq.knee_impact[1], relabel_q=q_lock,
                     relabel_rate=sp.eye(len(eq.q)))
        fast += [*flow_lines(lk, False, "flow_locked"),
                 *flow_lines(lk, True, "flow_locked_jacobian",
                             variational="flow_locked_variational"),
                 *reset_lines(kn, False, "knee_reset"),
                 *reset_lines(kn, True, "knee_reset_jacobian")]
    body = [
        "def make(p):",
        f"    {', '.join(param_names)}, = p",
        *_HOISTED, *fast, *_section(eq),
        *numpy_fn("_energies", eq, {"kinetic": eq.kinetic, "potential": eq.potential}),
        "    def energies(x):",
        f"{IND}d = _energies(x)",
        f"{IND}return d['kinetic'], d['potential']",
        *numpy_fn("points", eq, eq.points,
                  slices={"hip_x": ("hip", 0)} if "hip" in eq.points else None),
        *numpy_fn("leg_angles", eq, {**{f"{k}_angle": v for k, v in la.items()},
                                      **{f"{k}_rate": v for k, v in rates.items()}}),
        *numpy_fn("_matrices", eq, {"M": eq.M, "C": eq.C, "G": eq.G}),
        "    def matrices(x):",
        f"{IND}d = _matrices(x)",
        f"{IND}return d['M'], d['C'], np.reshape(d['G'], (len(d['M']),) + np.shape(d['G'])[1:])",
        *numpy_fn("_impact_matrices", eq, {"De": eq.De, "E": eq.E}, args="q"),
        "    def impact_matrices(q):",
        f"{IND}d = _impact_matrices(q)",
        f"{IND}return d['De'], d['E']",
        # last: the cse symbols' numbering of the functions above stays as before (their
        # printed expressions, and so their round-off, unchanged)
        *numpy_fn("point_velocities", eq, _point_velocities(eq)),
        "    return {k: v for k, v in locals().items() if callable(v) and not k.startswith('_')}",
    ]
    head = [
        f"# walkerlab generated model code (walkerlab.codegen.source); key {key}",
        "# Do not edit: regenerated when the walker description or the generator changes.",
        "from math import sin, cos, tan, sqrt  # noqa: F401",
        "import numpy  # noqa: F401",
        "import numpy as np",
        "",
    ]
    # a closed-form angle (a 3D walker's section): imported only where used, so that every
    # other walker's source is unchanged
    used = sorted(set(re.findall(r"(?<![\w.])(atan2|acos)\(", "\n".join(body))))
    if used:
        head.insert(3, f"from math import {', '.join(used)}  # noqa: F401")
    return "\n".join(head + body) + "\n"
