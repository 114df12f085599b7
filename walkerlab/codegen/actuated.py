"""Compiled flows of a walker driven by joint-torque laws: numba ``cfunc`` right-hand sides
(CyRK's signature, as :func:`walkerlab.codegen.compiled_source.generate_compiled`) in which the laws
are evaluated (:mod:`walkerlab.codegen.torque_law`), so a phase-reference (virtual
constraint), time-table or saturated law runs without a Python callback.

Equations: ``M qdd + C dq + G = sum_k B_k tau_k`` with ``delta_k = leg_angles[second_k] -
leg_angles[first_k]`` the joint angle of actuator ``k`` and ``B_k = d delta_k / dq`` its
generalised-force direction (``+tau`` on the second link, ``-tau`` on the first: the hip of a
straight-legged walker, ``(stance, swing)``; a five-link biped's joints), the phase variable
``s = leg_angles["stance"]``; the torques are symbols ``_tau_k`` in the generated lines
(:func:`walkerlab.codegen.printers.flow_lines` on ``G - sum_k B_k _tau_k``) and take the law's
values at run time.  The variational right-hand side adds the chain term
``(M^-1 B_k) (d tau_k / dx)`` to the Jacobian at fixed torques, with ``d tau_k / dx`` from the
law's partial derivatives and the symbolic gradients of ``delta_k``, its rate, ``s`` and
``ds``.

The data vector of each cfunc: ``constants(p)`` (``NCONST`` entries: parameters and
parameter-only subexpressions), the law block (:func:`walkerlab.codegen.torque_law.pack_laws`,
its length first), then the call counter (last, as every compiled flow's).
"""

from __future__ import annotations

import hashlib
import re
from dataclasses import replace
from pathlib import Path

from walkerlab import codestore
from walkerlab.codegen import cache

__all__ = ["actuated_module", "generate_actuated"]


def _defined(lines: list[str]) -> set[str]:
    return {ln.split("=", 1)[0].strip() for ln in lines if "=" in ln}


#: The planar kneed walker's locked knee (:mod:`walkerlab.codegen.legged`): ``S`` spans
#: the null space of the lock ``J_k = [-1, 1, 0]`` in ``(swing thigh, swing shank, stance)``
#: (thigh and shank together); the locked flow's rows are ``[S^T M; J_k]``, its forces
#: ``[S^T (B tau - C dq - G); 0]``.  Any kneed walker's (the 3D one's too) is read from its
#: lock's row: :func:`lock_basis`.
KNEE_LOCK_BASIS = ((1, 0), (1, 0), (0, 1))


def lock_basis(eq) -> tuple:
    """``S`` (n, n - 1) of a kneed walker's locked knee, as
    :func:`walkerlab.codegen.lagrange.knee_lock` builds it, read from the lock's row ``J_k``
    (the locked rows' last: -1 at the swing thigh, +1 at its shank): the shank moving with
    the thigh, every other coordinate alone (:data:`KNEE_LOCK_BASIS` for the planar
    walker's three coordinates, its lean besides for the 3D walker's)."""
    n = len(eq.q)
    jk = [eq.locked[0][n - 1, i] for i in range(n)]
    thigh, shank = jk.index(-1), jk.index(1)
    cols = [i for i in range(n) if i != shank]
    return tuple(tuple(int(i == c or (i == shank and c == thigh)) for c in cols)
                 for i in range(n))


def _joint_exprs(eq, joints):
    """Per actuator ``(delta, ddelta, B (n,))``, and ``(s, ds)``, as sympy expressions (the
    phase variable ``s``: the stance leg's angle, a kneed walker's stance thigh's)."""
    import sympy as sp

    la = eq.leg_angles

    def rate(e):
        return sum(sp.diff(e, qi) * dqi for qi, dqi in zip(eq.q, eq.dq))
    out = []
    for first, second in joints:
        d = la[second] - la[first]
        out.append((d, rate(d), [sp.diff(d, qi) for qi in eq.q]))
    s = la["stance"] if "stance" in la else la["stance_thigh"]
    return out, (s, rate(s))


def _locked(acts, S):
    """The actuators' generalised-force directions in the locked flow's rows: ``[S^T B;
    0]`` (``S``: :func:`lock_basis`)."""
    return [(d, dd, [sum(S[i][r] * B[i] for i in range(len(B))) for r in range(len(S[0]))]
             + [0]) for d, dd, B in acts]


def _law_lines(eq, joints, printer, cse_lines):
    """Lines that evaluate the laws (``_tau{k}`` and its partials ``_t{k}_0..3``) and the
    symbolic pieces the variational equations need: ``(lines, acts, grads)``."""
    import sympy as sp

    acts, (s, ds) = _joint_exprs(eq, joints)
    exprs = [s, ds] + [e for d, dd, _B in acts for e in (d, dd)]
    lines, red = cse_lines(exprs, printer)
    ind = "        "
    lines += [f"{ind}_s = {printer.doprint(red[0])}", f"{ind}_ds = {printer.doprint(red[1])}"]
    for k in range(len(acts)):
        lines.append(f"{ind}_tau{k}, _t{k}_0, _t{k}_1, _t{k}_2, _t{k}_3 = law_torque("
                     f"_law, {k}, {printer.doprint(red[2 + 2 * k])}, "
                     f"{printer.doprint(red[3 + 2 * k])}, _s, _ds, t)")
    x = [*eq.q, *eq.dq]
    grads = [[sp.diff(e, v) for v in x] for e in exprs]  # rows: s, ds, delta_k, ddelta_k
    return lines, acts, grads


def _body(eq, joints, variational, guards, printer, locked: bool = False) -> list[str]:
    """The lines of one cfunc after its constants' unpacking (see the module docstring);
    ``NCONST`` is the module's constant count (a compile-time global for numba).
    ``locked``: a kneed walker's flow with its swing knee locked (``eq.locked``'s rows,
    :func:`lock_basis`)."""
    import sympy as sp

    from walkerlab.codegen.printers import cse_lines, flow_lines  # light

    n = len(eq.q)
    m = 2 * n
    law_lines, acts, grads = _law_lines(eq, joints, printer, cse_lines)
    if locked:
        acts = _locked(acts, lock_basis(eq))
        eq = replace(eq, M=eq.locked[0], C=eq.locked[1], G=eq.locked[2])
    taus = [sp.Symbol(f"_tau{k}", real=True) for k in range(len(acts))]
    G = eq.G - sum((sp.Matrix(B) * tau for (_d, _dd, B), tau in zip(acts, taus)),
                   sp.zeros(n, 1))
    fl, fo = flow_lines(replace(eq, G=G), variational, parts=True)
    names = [str(v) for v in (*eq.q, *eq.dq)]
    out = ["    _L = int(d[NCONST])",
           "    _law = carray(d, (NCONST + _L + 1,))[NCONST:NCONST + _L]"]
    out += [f"    {a} = y[{i}]" for i, a in enumerate(names)]
    out += [ln[4:] for ln in law_lines] + [ln[4:] for ln in fl]
    if not variational:
        out += [f"    dy[{i}] = {e}" for i, e in enumerate(fo)]
    else:
        out += _variational_lines(eq, acts, grads, fl, fo, printer, cse_lines)
    k0 = m + m * m if variational else m
    out += [ln[4:] for ln in guards[0]]
    out += [f"    dy[{k0 + j}] = {printer.doprint(e)}" for j, e in enumerate(guards[1])]
    out.append("    d[NCONST + _L] += 1.0")
    return out


def _variational_lines(eq, acts, grads, fl, rows, printer, cse_lines) -> list[str]:
    """The flow and ``(J + chain) Phi`` of the variational cfunc: ``rows`` the Jacobian at
    fixed torques (``flow_lines``' parts), the chain ``(M^-1 B_k) (d tau_k / dx)``."""
    n = len(eq.q)
    m = 2 * n
    names = [str(v) for v in (*eq.q, *eq.dq)]
    defined = _defined(fl)
    out = [f"    dy[{i}] = {v}" for i, v in enumerate(names[n:])]
    out += [f"    dy[{n + i}] = _a{i}" for i in range(n)]
    gl, gred = cse_lines([g for row in grads for g in row], printer)
    out += [ln[4:] for ln in gl]
    g = [[printer.doprint(gred[r * m + c]) for c in range(m)] for r in range(len(grads))]
    for k in range(len(acts)):  # d tau_k / dx_c: the law's partials, the symbolic gradients
        for c in range(m):
            terms = [f"_t{k}_{j} * ({g[r][c]})" for j, r in ((2, 0), (3, 1), (0, 2 + 2 * k),
                                                            (1, 3 + 2 * k)) if g[r][c] != "0"]
            out.append(f"    _g{k}_{c} = {' + '.join(terms) or '0.0'}")
    for k, (_d, _dd, B) in enumerate(acts):  # M^-1 B_k from the inverse's entries ``_i{i}{j}``
        bl = [printer.doprint(b) for b in B]
        for i in range(n):
            terms = [f"_i{i}{j} * ({bl[j]})" for j in range(n)
                     if f"_i{i}{j}" in defined and B[j] != 0]
            out.append(f"    _mb{k}_{i} = {' + '.join(terms) or '0.0'}")
    for i in range(m):
        for c in range(m):
            a = rows[i][c].strip("()")
            if i >= n and acts:
                chain = " + ".join(f"_mb{k}_{i - n} * _g{k}_{c}" for k in range(len(acts)))
                a = chain if a in ("0", "0.0") else f"({a}) + {chain}"
            out.append(f"    _J{i}_{c} = {a}")
    for i in range(m):
        for j in range(m):
            terms = [f"_J{i}_{k} * y[{m + k * m + j}]" for k in range(m)]
            out.append(f"    dy[{m + i * m + j}] = {' + '.join(terms)}")
    return out


#: a name's negative whole power in a generated line (``_c2_3**(-2)``: :func:`_reciprocal_power`)
_NEGATIVE_POWER = re.compile(r"\b([A-Za-z_]\w*)\*\*\(-(\d+)\)")


def _reciprocal_power(match) -> str:
    """``x**(-k)`` (``match`` of :data:`_NEGATIVE_POWER`) written as numba computes it,
    ``1/(x*x)`` for ``k = 2`` (its power by a whole-number literal: the product of the
    squarings by binary exponentiation, then its reciprocal; the same operations in the same
    order, so the same number bit for bit), without numba's zero test: numba compiles that
    reciprocal with Python's error model whatever the cfunc's (``error_model='numpy'``), so
    ``0.0**(-2)`` raised ``ZeroDivisionError`` inside the cfunc, which a cfunc cannot
    return: it was written to ``sys.unraisablehook``, the call's outputs left as the last
    call's.  Written so, ``1/(0.0*0.0)`` is ``inf`` as every other division by zero in the
    cfunc (the integrator's step then fails its error test, or the piece ends not finite:
    the view's ``solver_failure``)."""
    name, k = match.group(1), int(match.group(2))
    res, val = None, name
    while k:
        if k & 1:  # (numba's first product, 1.0 * val, is val itself)
            res = val if res is None else f"{res}*{val}"
        k >>= 1
        if k:
            val = f"({val}*{val})"
    # (in parentheses: the power's precedence, as in a / x**(-2))
    return f"(1/{res})" if res.startswith("(") and res == val else f"(1/({res}))"


def generate_actuated(eq, param_names, joints, key: str) -> str:
    """Source of the compiled module of an actuated walker (module docstring): ``constants``,
    ``NCONST``, ``GUARDS`` (``eq.guards``' names, written after the outputs as
    :func:`walkerlab.codegen.compiled_source.generate_compiled` does) and the right-hand sides
    ``flow`` (2n outputs) and ``flow_variational`` (``2n + (2n)^2``), and for a kneed walker
    ``flow_locked`` and ``flow_locked_variational`` (its swing knee locked), each made a
    cfunc by ``cfunc_of(name)`` on first use (the five-link biped's variational cfunc is
    the longest to compile).

    Parameters
    ----------
    eq : walkerlab.codegen.equations.Equations
    param_names : sequence of str
    joints : tuple of (str, str)
        Each actuator's (first, second) key of ``eq.leg_angles``.
    key : str
        Written into the header.
    """
    from walkerlab.codegen.compiled_source import compiled_head  # light
    from walkerlab.codegen.printers import PRINTER, cse_lines, start_module  # light
    from walkerlab.codegen.torque_law import kernel_source

    hoisted = start_module(eq.params)  # filled as the bodies are generated
    guards = cse_lines(list(eq.guards.values()), PRINTER)
    bodies = {nm: _body(eq, joints, var, guards, PRINTER)
              for nm, var in (("flow", False), ("flow_variational", True))}
    if eq.locked is not None:  # a kneed walker: its flow with the swing knee locked too
        bodies.update({nm: _body(eq, joints, var, guards, PRINTER, locked=True)
                       for nm, var in (("flow_locked", False),
                                       ("flow_locked_variational", True))})
    consts = list(param_names) + [h.split("=")[0].strip() for h in hoisted]
    text = []
    for nm, lines in bodies.items():  # plain functions: made cfuncs on first use
        text += [f"def {nm}(dy, t, y, d):  # pragma: no cover - runs compiled",
                 *[f"    {c} = d[{i}]" for i, c in enumerate(consts)],
                 *[_NEGATIVE_POWER.sub(_reciprocal_power, ln) for ln in lines], ""]
    text += ["_LAZY = {}", "", "",
             "def cfunc_of(name):",
             '    """The cfunc ``name`` (compiled, or loaded from numba\'s cache, on first use: a',
             '    walker that never runs its variational equations does not compile them)."""',
             "    if name not in _LAZY:",
             "        _LAZY[name] = cfunc(SIG, cache=True, error_model='numpy')(globals()[name])",
             "    return _LAZY[name]", ""]
    body = ["def constants(p):", f"    {', '.join(param_names)}, = p", *hoisted,
            f"    return np.array(({', '.join(consts)},), dtype=np.float64)", "",
            f"NCONST = {len(consts)}",
            f"GUARDS = {tuple(eq.guards)!r}  # extra outputs, in this order", "",
            *kernel_source(), *text]
    return "\n".join(compiled_head("actuated model code (walkerlab.codegen.actuated)", key,
                                   "sin, cos, tan, sqrt, atan, acos",
                                   "carray, cfunc, njit, types") + body) + "\n"




def actuated_module(structure, joints):
    """The imported compiled module of ``structure`` driven at ``joints`` (generated on a
    cache miss; file ``<key>_act_<hash>_nb.py``, the hash covering the joints and this
    generator's sources).

    Raises
    ------
    ImportError
        numba is not installed.
    """
    key = cache.cache_key(structure)
    here = Path(__file__).parent
    sources = codestore.source_hash(here / "actuated.py", here / "torque_law.py")
    tag = hashlib.sha256(f"{joints!r}{sources[:12]}".encode()).hexdigest()[:12]

    def build() -> str:
        eq = cache.derive_equations(structure)   # a biped's, planar or 3D
        return generate_actuated(eq, structure.param_names, tuple(joints), key)

    return codestore.import_generated(f"{key}_act_{tag}_nb.py", f"walkerlab_actuated_{key}_{tag}",
                                  build)
