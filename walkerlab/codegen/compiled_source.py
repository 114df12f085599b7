"""Numba source of a walker's equations: the compiled twin of :mod:`walkerlab.codegen.source`.

:func:`generate_compiled` prints the same symbolic equations (the same ``cse`` lines, so the
same round-off) as numba ``cfunc`` right-hand sides of CyRK's signature ``(dy, t, y, d)``:
the flow, its variational form, the guards as CyRK's extra outputs and the heel-strike reset
(:mod:`walkerlab.codegen.compiled` imports and caches the module).
"""

from __future__ import annotations

import re
from dataclasses import replace
from typing import TYPE_CHECKING

import sympy as sp

from walkerlab.codegen.equations import Equations
from walkerlab.codegen.printers import (
    IND,
    PRINTER,
    cse_lines,
    flow_lines,
    reset_lines,
    start_module,
)

if TYPE_CHECKING:
    from walkerlab.codegen.foot_modes import FlatEquations
    from walkerlab.walker.description import Structure

__all__ = ["cfunc_lines", "compiled_head", "generate_compiled", "generate_flat_compiled"]


def _reset_cfunc(eq: Equations, consts: list[str], reset: list[str]) -> list[str]:
    """``reset_flow()``: the heel-strike reset (``reset_lines``' equations, same
    expressions) of the pre-impact state ``y`` into ``dy``, a numba ``cfunc`` ``(dy, t, y,
    d)`` of the flows' signature (``d`` the data vector; ``t`` unused), compiled on the
    first call of ``reset_flow()`` (cfuncs compile when made: lazily, as every njit)."""
    names = [str(s) for s in (*eq.q, *eq.dq)]
    ret = reset[-1].strip()
    assert ret.startswith("return np.array((") and ret.endswith(",))")
    out = ["def _reset_flow(dy, t, y, d):  # pragma: no cover - runs compiled"]
    out += [f"    {c} = d[{i}]" for i, c in enumerate(consts)]
    out += [f"    {a} = y[{i}]" for i, a in enumerate(names)]
    out += [ln[4:] for ln in reset[2:-1]]
    out += [f"    _res = ({ret[len('return np.array(('):-3]},)",
            f"    for _k in range({len(names)}):", "        dy[_k] = _res[_k]", "", "",
            "_RESET_FLOW = []", "", "",
            "def reset_flow():",
            '    """The heel-strike reset, a cfunc of the flows\' signature (compiled on first',
            '    use: a walker that never walks on per-step slopes does not compile it)."""',
            "    if not _RESET_FLOW:",
            "        _RESET_FLOW.append(cfunc(SIG, cache=True, error_model='numpy')(_reset_flow))",
            "    return _RESET_FLOW[0]"]
    return out + [""]


def cfunc_lines(name: str, eq: Equations, consts: list[str], parts: list, variational: bool,
           guards: tuple[list[str], list] | None, lazy: bool = False) -> list[str]:
    """A numba ``cfunc`` ``(dy, t, y, d)`` (CyRK's ``cyjit_sig``) writing the flow (and with
    ``variational`` the product ``A Phi`` of the flow Jacobian with ``y[2n:]``, row-major
    (2n, 2n)) into ``dy``, then the guard values (CyRK's extra outputs; none when ``guards``
    is None); ``d`` holds the constants, then a call counter.  ``lazy``: the plain Python
    function (no decorator), made a cfunc on first use (:func:`_stage_cfuncs`).

    Each row of ``A Phi`` is one loop over ``Phi``'s columns, its nonzero entries of ``A``
    named before it: the same sums, term by term in the same order, as one statement per
    entry, in a tenth of the code (numba compiles the 3D hip-roll walker's variational flow
    in about 5 s instead of 18 s)."""
    m = 2 * len(eq.q)
    names = [str(s) for s in (*eq.q, *eq.dq)]
    out = [] if lazy else ["@cfunc(SIG, cache=True, error_model='numpy')"]
    out += [f"def {name}(dy, t, y, d):  # pragma: no cover - runs compiled"]
    out += [f"    {c} = d[{i}]" for i, c in enumerate(consts)]
    out += [f"    {a} = y[{i}]" for i, a in enumerate(names)]
    (fl, fo) = parts[0]
    out += [ln[4:] for ln in fl]
    out += [f"    dy[{i}] = {e}" for i, e in enumerate(fo)]
    if variational:  # row i of A Phi: a loop over Phi's columns j (one statement a row)
        jl, rows = parts[1]
        out += [ln[4:] for ln in jl]
        for i in range(m):
            terms, coeffs = [], []
            for k in range(m):
                a = rows[i][k].strip("()")
                if a in ("0", "0.0"):
                    continue
                phi = f"y[{m + k * m} + _j]"
                if a == "1.0":
                    terms.append(phi)
                else:   # the entry once, before the loop (the same value in every column)
                    coeffs.append(f"    _a{i}_{k} = {a}")
                    terms.append(f"(_a{i}_{k}) * {phi}")
            out += coeffs
            out += [f"    for _j in range({m}):",
                    f"        dy[{m + i * m} + _j] = {' + '.join(terms) or '0.0'}"]
    k0 = m + m * m if variational else m
    if guards is not None:
        out += [ln[4:] for ln in guards[0]]
        out += [f"    dy[{k0 + j}] = {PRINTER.doprint(e)}" for j, e in enumerate(guards[1])]
    out.append(f"    d[{len(consts)}] += 1.0")
    return out


def _needed(lines: list[str], expr: str) -> list[str]:
    """The assignments of ``lines`` (``name = rhs``, in order) that ``expr`` needs."""
    need = set(re.findall(r"[A-Za-z_]\w*", expr))
    keep = []
    for ln in reversed(lines):
        name, rhs = ln.strip().split(" = ", 1)
        if name in need:
            keep.append(ln)
            need |= set(re.findall(r"[A-Za-z_]\w*", rhs))
    return keep[::-1]


def _guard_cfunc(eq: Equations, consts: list[str], guards: tuple[list[str], list]) -> list[str]:
    """``_guard_one(dy, t, y, d)``: the guard number ``int(dy[0])`` (its index in ``GUARDS``)
    of the state ``y`` into ``dy[0]``, with the lines and expressions of the flows' guard
    outputs (the same values bit for bit), only those that guard needs; no call counted."""
    names = [str(s) for s in (*eq.q, *eq.dq)]
    out = ["def _guard_one(dy, t, y, d):  # pragma: no cover - runs compiled"]
    out += [f"    {c} = d[{i}]" for i, c in enumerate(consts)]
    out += [f"    {a} = y[{i}]" for i, a in enumerate(names)]
    out.append("    j = int(dy[0])")
    for j, e in enumerate(guards[1]):
        text = PRINTER.doprint(e)
        out.append(f"    {'if' if j == 0 else 'elif'} j == {j}:")
        out += _needed(guards[0], text) + [f"{IND}dy[0] = {text}"]
    return out + [""]


def _stage_cfuncs(flows) -> list[str]:
    """``plain_flow(name)`` and ``guard_one()``: made cfuncs on first use (a walker that never
    runs the per-row integrator does not compile them)."""
    return ["_LAZY = {}", "", "",
            "def _lazy(name):",
            "    if name not in _LAZY:",
            "        _LAZY[name] = cfunc(SIG, cache=True, error_model='numpy')(globals()[name])",
            "    return _LAZY[name]", "", "",
            "def plain_flow(name):",
            '    """The cfunc ``name`` (one of ' + ", ".join(f"``{k}``" for k in flows)
            + ') without its guard',
            '    outputs: the same 2n values and call count (the DOP853 stages)."""',
            "    return _lazy(f'_{name}_plain')", "", "",
            "def guard_one():",
            '    """The cfunc writing guard ``int(dy[0])`` of ``y`` into ``dy[0]``."""',
            "    return _lazy('_guard_one')", ""]


def generate_compiled(eq: Equations, param_names, key: str) -> str:
    """Source of the compiled module of a walker: numba ``cfunc`` right-hand sides for CyRK's
    C++ integrators (``CyRK.nb.numba_solver.cyjit_sig``), ``cache=True``.

    Defines ``constants(p) -> ndarray (NCONST + 1,)`` (the parameters, the parameter-only
    subexpressions and a zeroed call counter: the data vector of every cfunc), its compiled
    twin for many parameter rows ``constants_rows(P (N, NP)) -> (N, NCONST + 1)`` (numba,
    lazy), ``NCONST``, the heel-strike reset as a cfunc of the flows' signature
    (``reset_flow()`` makes it on first use),
    ``GUARDS`` (the guard names) and the cfuncs ``flow`` (2n outputs) and
    ``flow_variational`` (``2n + (2n)^2`` outputs: the flow and ``A(x) Phi``; compiled when
    first read, by the module's ``__getattr__``: a run without multipliers does not), plus
    ``flow_locked``/``flow_locked_variational`` for a kneed walker; each writes the values
    of ``GUARDS`` after its outputs (CyRK's "extra outputs", recorded at every step).  For
    the per-row integrator (:mod:`walkerlab.integrate.rows_dop853`), made on first use:
    ``plain_flow(name)``, the flow ``name`` without the guard outputs (its stages), and
    ``guard_one()``, one guard's value (its crossing's location), the same lines and values
    bit for bit.  ``FLOWS`` names the flows and each flow's functions stay plain Python
    functions too (``_<name>_full`` with the guard outputs, ``_<name>_plain``, beside
    ``_guard_one`` and ``_reset_flow``): the per-row integrator's loops specialised to them
    (:func:`walkerlab.integrate.rows_dop853.kernels`).  The equations are those of
    :func:`walkerlab.codegen.source.generate` (same expressions, same key).
    """
    hoisted = start_module(eq.params)
    flows = {"flow": eq}
    if eq.locked is not None:
        flows["flow_locked"] = replace(eq, M=eq.locked[0], C=eq.locked[1], G=eq.locked[2])
    parts = {k: (flow_lines(e, False, parts=True), flow_lines(e, True, parts=True))
             for k, e in flows.items()}
    guards = cse_lines(list(eq.guards.values()), PRINTER)
    reset = reset_lines(eq, False)  # (its parameter-only subexpressions join the constants)
    consts = list(param_names) + [h.split("=")[0].strip() for h in hoisted]
    body = ["def constants(p):",
            f"    {', '.join(param_names)}, = p",
            *hoisted,
            f"    return np.array(({', '.join(consts)}, 0.0), dtype=np.float64)",
            "", f"NCONST = {len(consts)}",
            f"GUARDS = {tuple(eq.guards)!r}  # extra outputs, in this order", "",
            "_constants_jit = njit(cache=True)(constants)", "", "",
            "@njit(cache=True)",
            "def constants_rows(P):  # pragma: no cover - runs compiled",
            '    """Data vectors (N, NCONST + 1) of the parameter rows P (N, NP)."""',
            "    out = np.empty((P.shape[0], NCONST + 1))",
            "    for i in range(P.shape[0]):",
            "        out[i] = _constants_jit(P[i])",
            "    return out", ""]
    for k, e in flows.items():  # the flow: a plain function, its cfunc, its njit (kernels)
        body += cfunc_lines(f"_{k}_full", e, consts, parts[k], False, guards, lazy=True) + [""]
        body += [f"{k} = cfunc(SIG, cache=True, error_model='numpy')(_{k}_full)", ""]
        body += cfunc_lines(f"_{k}_variational", e, consts, parts[k], True, guards,
                            lazy=True) + [""]
        body += cfunc_lines(f"_{k}_plain", e, consts, parts[k], False, None, lazy=True) + [""]
    body += _guard_cfunc(eq, consts, guards)
    body += _stage_cfuncs(flows)
    body += _reset_cfunc(eq, consts, reset)
    body += [f"FLOWS = {tuple(flows)!r}  # _<name>_full, _<name>_plain: plain functions", "",
             "", "def __getattr__(name):",
             '    """``<flow>_variational``: its cfunc, compiled on first use (PEP 562)."""',
             "    if name.endswith('_variational') and f'_{name}' in globals():",
             "        return _lazy(f'_{name}')",
             "    raise AttributeError(name)", ""]
    return "\n".join(compiled_head("model code (walkerlab.codegen.source)", key,
                                   "sin, cos, tan, sqrt", "cfunc, njit, types") + body) + "\n"


def compiled_head(what: str, key: str, maths: str, numba: str) -> list[str]:
    """The first lines of a compiled module: what it is, its key, the names it imports from
    ``math`` and ``numba``, and CyRK's cfunc signature ``SIG``."""
    return [f"# walkerlab compiled {what}; key {key}",
            "# Do not edit: regenerated when the walker description or the generator changes.",
            f"from math import {maths}  # noqa: F401", "import numpy as np",
            f"from numba import {numba}", "",
            "SIG = types.void(types.CPointer(types.float64), types.float64,",
            "                 types.CPointer(types.float64), types.CPointer(types.float64))", ""]


#: Ground reactions each compiled flow writes after the state guards (extra outputs) [N]:
#: the pinned contact's normal force ``N``; the toe's share ``N_toe`` in a heel-pinned mode
#: (the moment balance about the heel) or ``N`` in heel off; the heel's ``N - N_toe`` (0 in
#: heel off).  Each mode writes them with its own ``qdd``, as the Python guards read them.
FORCES = ("normal_force", "toe_force", "heel_force")


def _extra_outputs(eq: FlatEquations, mode: str) -> tuple[list[str], list]:
    """Lines and expressions of a mode's extra outputs: every state guard of ``eq.guards``
    (each through its own ``cse``, as its Python function) then :data:`FORCES` (the ground
    reactions of ``ground_<pin>``, through the same ``cse``; ``qdd`` the mode's ``_a0..``)."""
    lines, exprs = [], []
    for expr in eq.guards.values():
        gl, red = cse_lines([expr], PRINTER)
        lines += gl
        exprs.append(red[0])
    pin = "toe" if mode == "heel_off" else "heel"
    lines += [f"{IND}{s} = _a{i}" for i, s in enumerate(eq.qdd)]
    gl, red = cse_lines(eq.ground[pin], PRINTER)
    lines += gl + [f"{IND}_gN = {PRINTER.doprint(red[0])}"]
    normal = sp.Symbol("_gN")
    if pin == "toe":
        return lines, exprs + [normal, normal, sp.Integer(0)]
    lines += [f"{IND}_gT = {PRINTER.doprint(red[1])}", f"{IND}_gH = _gN - _gT"]
    return lines, exprs + [normal, sp.Symbol("_gT"), sp.Symbol("_gH")]


def generate_flat_compiled(eq: FlatEquations, structure: Structure, key: str) -> str:
    """Source of a flat-footed walker's compiled module: numba ``cfunc`` right-hand sides
    ``flow_<mode>`` (2n outputs) and ``flow_<mode>_variational`` (``2n + (2n)^2``) for CyRK's
    C++ integrators, the same equations as :func:`walkerlab.codegen.source.generate_flat`
    (same lines, same key),
    each writing ``GUARDS`` after its outputs (the state guards, then :data:`FORCES`);
    ``constants(p)`` (the data vector: parameters, parameter-only subexpressions, a zeroed
    call counter) and ``NCONST``, as :func:`walkerlab.codegen.compiled_source.generate_compiled`."""

    hoisted = start_module(eq.params)  # filled as the lines below are generated
    parts = {mode: (flow_lines(system, False, parts=True), flow_lines(system, True, parts=True))
             for mode, system in eq.flows.items()}
    extras = {mode: _extra_outputs(eq, mode) for mode in eq.flows}
    consts = list(structure.param_names) + [h.split("=")[0].strip() for h in hoisted]
    body = ["def constants(p):", f"    {', '.join(structure.param_names)}, = p", *hoisted,
            f"    return np.array(({', '.join(consts)}, 0.0), dtype=np.float64)", "",
            f"NCONST = {len(consts)}",
            f"GUARDS = {(*eq.guards, *FORCES)!r}  # extra outputs, in this order", ""]
    for mode, system in eq.flows.items():
        for var in (False, True):
            name = f"flow_{mode}_variational" if var else f"flow_{mode}"
            body += cfunc_lines(name, system, consts, parts[mode], var, extras[mode]) + [""]
    return "\n".join(compiled_head("model code (walkerlab.codegen.compiled_source, flat feet)", key,
                                   "sin, cos, tan, sqrt, pi", "cfunc, types") + body) + "\n"
