"""The printers every generated walker module is written with: sympy's ``cse`` and
``pycode`` on Python floats for the hot functions (the flow and its Jacobian with the small
linear solve written out as an adjugate over a determinant for n <= 3 and by LU factors
above, the resets), numpy code for the functions of whole trajectories (:func:`numpy_fn`),
and the parameter-only subexpressions hoisted into ``make(p)``
(:func:`start_module`); read by :mod:`walkerlab.codegen.source` (the Python module of a
walker, its flat feet's modes too), :mod:`walkerlab.codegen.compiled_source` (its numba
twin) and the other generators.
"""

from __future__ import annotations

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


def array_literal(rows) -> str:
    """``np.array((...))`` of printed entries: a row (list of str) or rows (list of lists)."""
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
        return head + lines + [f"{IND}return {array_literal([str(s) for s in dq] + qdd)}"]
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
    out = head + lines + [f"{IND}return {array_literal(rows)}"]
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
        out += head + lines + [f"{IND}return {array_literal(ret)}"]
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
        return head + lines + [f"{IND}return {array_literal(qn + dqn)}"]
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
    return head + lines + [f"{IND}return {array_literal(rows)}"]



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


