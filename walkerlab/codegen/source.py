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
from typing import TYPE_CHECKING

import sympy as sp

from walkerlab.codegen.equations import Equations
from walkerlab.codegen.printers import (
    IND,
    PRINTER,
    array_literal,
    cse_lines,
    flow_lines,
    numpy_fn,
    reset_lines,
    start_module,
    unpack,
)

if TYPE_CHECKING:
    from walkerlab.codegen.foot_modes import FlatEquations
    from walkerlab.walker.description import Structure


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
                f"{IND}return {array_literal([PRINTER.doprint(e) for e in red])}"]
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
        f"{IND}return {array_literal(xs)}",
    ]




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
    hoisted = start_module(eq.params)
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
        *hoisted, *fast, *_section(eq),
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


# ------------------------------------------------------------ flat feet on ankle springs
def _scalar_fn(name: str, eq: FlatEquations, exprs: list, with_acc: bool) -> list[str]:
    """A Python function ``(t, x)`` or ``(x, qdd)`` returning a float or a tuple."""
    lines, red = cse_lines(exprs, PRINTER)
    head_unpack = unpack(eq)
    head = [f"    def {name}(x, qdd):" if with_acc else f"    def {name}(t, x):", head_unpack]
    if with_acc:
        head.append(f"{IND}{', '.join(str(s) for s in eq.qdd)}, = qdd")
    vals = [PRINTER.doprint(e) for e in red]
    ret = vals[0] if len(vals) == 1 and not with_acc else f"({', '.join(vals)},)"
    return head + lines + [f"{IND}return {ret}"]


def _grad_fn(name: str, eq: FlatEquations, expr) -> list[str]:
    x = [*eq.q, *eq.dq]
    lines, red = cse_lines([sp.diff(expr, s) for s in x], PRINTER)
    return [f"    def {name}(x):", unpack(eq), *lines,
            f"{IND}return np.array(({', '.join(PRINTER.doprint(e) for e in red)},))"]


def _fast_lines(eq) -> list[str]:
    """:func:`generate_flat`'s flows, resets, guards, ground reactions, double supports."""
    fast = []
    for mode, system in eq.flows.items():
        fast += flow_lines(system, False, f"flow_{mode}")
        fast += flow_lines(system, True, f"flow_{mode}_jacobian",
                           variational=f"flow_{mode}_variational")
    for name, system in eq.resets.items():
        fast += reset_lines(system, False, f"reset_{name}")
        fast += reset_lines(system, True, f"reset_{name}_jacobian")
    for name, expr in eq.guards.items():
        fast += _scalar_fn(f"guard_{name}", eq, [expr], False)
        fast += _grad_fn(f"grad_{name}", eq, expr)
    for pin, exprs in eq.ground.items():
        fast += _scalar_fn(f"ground_{pin}", eq, exprs, True)
    for lead in eq.double_support["leads"]:
        fast += _double_support_lines(eq, lead)
    return fast


def generate_flat(eq: FlatEquations, structure: Structure, key: str) -> str:
    """Source text of a flat-footed walker's generated module (``make(p)`` returns, by name:
    ``flow_<mode>``, ``flow_<mode>_jacobian``, ``flow_<mode>_variational`` for the three
    modes; ``reset_<name>`` and ``reset_<name>_jacobian`` for ``foot_slap``,
    ``heel_strike_heel``, ``heel_strike_toe``; ``guard_<name>``/``grad_<name>``;
    ``ground_heel(x, qdd) -> (N, N_toe)`` and ``ground_toe(x, qdd) -> (N,)`` [N];
    per leading-foot mode ``m`` of the double support (``heel_contact``, ``foot_flat``):
    ``flow_double_support_<m>(t, x, gen=None, level=0.0)``, ``double_support_<m>_forces(t,
    x, gen=None, level=0.0)`` (trailing toe normal and tangential, leading foot normal and
    its toe's share [N]; ``gen`` (3,) [N m] a generalised force in ``q``'s rows, joint
    torques' ``B tau``), ``double_support_<m>_entry(x, level=0.0) -> (x+, (Lam_n, Lam_t))``
    [N s]; and ``double_support_trailing(x, level=0.0) -> (b, db, held energy [J], trailing
    sole angle from the slope [rad])`` (``level`` [m]: the trailing toe's tread above the
    leading heel's line, along the normal: stairs, footholds; held: the trailing spring's
    energy, with feet of mass plus the trailing sole's kinetic energy beyond turning with
    its leg);
    ``section``/``from_section``; ``energies`` and, per pinned point, ``energies_heel`` /
    ``energies_toe`` (dicts ``kinetic``, ``potential`` [J]); ``points``; ``leg_angles``)."""
    hoisted = start_module(eq.params)
    fast = _fast_lines(eq)
    rest = "r_st_ankle" if structure.asymmetric else "r_ankle"
    section = [
        "    def section(x):",
        f"{IND}return np.asarray(x)[[0, 1, 3, 4, 5]]",
        "    def from_section(z):",
        f"{IND}z0, z1, z2, z3, z4, = z",
        f"{IND}return np.array((z0, z1, {rest} + 0.0 * z0, z2, z3, z4))",
    ]
    kin = eq.kinematics
    numpy = [
        *numpy_fn("_points_heel", eq, kin["heel"]["points"]),
        *numpy_fn("_points_toe", eq, kin["toe"]["points"]),
        *numpy_fn("energies_heel", eq, {"kinetic": kin["heel"]["kinetic"],
                                          "potential": kin["heel"]["potential"]}),
        *numpy_fn("energies_toe", eq, {"kinetic": kin["toe"]["kinetic"],
                                         "potential": kin["toe"]["potential"]}),
        "    def _on_toe(x):  # heel off: the foot turned heel up (phi < 0)",
        f"{IND}x = np.asarray(x)",
        f"{IND}return x[1] + x[2] + gamma < {-eq.heel_off_phi_rad!r}",
        "    def points(x):",
        f"{IND}if np.ndim(x) == 1:  # one state: one kinematics",
        f"{IND}    return _points_toe(x) if _on_toe(x) else _points_heel(x)",
        f"{IND}toe, h, o = _on_toe(x), _points_heel(x), _points_toe(x)",
        f"{IND}return {{k: np.where(toe, o[k], h[k]) for k in h}}",
        "    def energies(x):",
        f"{IND}toe, h, o = _on_toe(x), energies_heel(x), energies_toe(x)",
        f"{IND}return (np.where(toe, o['kinetic'], h['kinetic']),",
        f"{IND}        np.where(toe, o['potential'], h['potential']))",
        *numpy_fn("leg_angles", eq, eq.leg_angles),
        # last: the functions above keep their cse symbols' numbering
        *numpy_fn("push_off_heel", eq, eq.push_off["heel"], args="q"),
        *numpy_fn("push_off_toe", eq, eq.push_off["toe"], args="q"),
    ]
    body = [
        "def make(p):",
        f"    {', '.join(structure.param_names)}, = p",
        *hoisted, *fast, *section, *numpy,
        "    return {k: v for k, v in locals().items() if callable(v) and not k.startswith('_')}",
    ]
    head = [
        f"# walkerlab generated model code (walkerlab.codegen.source, flat feet); key {key}",
        "# Do not edit: regenerated when the walker description or the generator changes.",
        "from math import sin, cos, tan, sqrt, pi, asin  # noqa: F401",
        "import numpy  # noqa: F401",
        "import numpy as np",
        "",
    ]
    return "\n".join(head + body) + "\n"


def _double_support_lines(eq, lead: str) -> list[str]:
    """Source of ``_double_support_<lead>(x, gen=None, level=0.0) -> (xdot (6,), forces
    (4,))``
    (forces: the trailing toe's normal and tangential force, the leading foot's normal force
    and its toe's share [N]; ``gen`` (3,) [N m], if given, a generalised force in ``q``'s
    rows added to the right-hand side: joint torques' ``B tau``, the closed chain's
    ``[M -J^T; J 0] [Qdd; lam] = [-C dQ - G + (B tau, 0); -dJ dQ]``),
    ``double_support_<lead>_entry(x, level=0.0) -> (x+, (Lam_n, Lam_t))`` (the toe's
    impulse [N s]) and, once, ``double_support_trailing(x, level=0.0) -> (b, db, held [J],
    sole angle from the slope [rad])`` (``level`` [m]: the trailing toe's line above the
    leading heel's, along the normal; 0, the same line, runs the lines without it),
    ``held`` the trailing ankle spring's energy plus, for feet with mass, the
    trailing sole's kinetic energy beyond turning with its leg (``I ((dsw + db)^2 - dsw^2)
    / 2``: the part the walker's ``energies`` leave out, lost with the spring's at toe off)."""
    ds = eq.double_support
    sysd = ds[lead]
    n = len(eq.q)
    head = [unpack(eq)]
    lines, red = cse_lines([ds["b_of"]], PRINTER)
    head += lines + [f"{IND}{ds['b']} = {PRINTER.doprint(red[0])}",
                     f"{IND}if level:  # the trailing toe on a tread above the leading heel's",
                     f"{IND}    {ds['b']} = {PRINTER.doprint(ds['b_of_level'])}"]
    lines, red = cse_lines([ds["db_of"]], PRINTER)
    head += lines + [f"{IND}{ds['db']} = {PRINTER.doprint(red[0])}"]
    K, rhs = sysd["K"], sysd["rhs"]
    m = K.rows
    lines, red = cse_lines(list(K) + list(rhs), PRINTER)
    body = list(head) + lines
    body.append(f"{IND}_K = np.array(({', '.join(PRINTER.doprint(e) for e in red[:m * m])},),"
                f" dtype=float).reshape({m}, {m})")
    body.append(f"{IND}_b = np.array(({', '.join(PRINTER.doprint(e) for e in red[m * m:])},),"
                " dtype=float)")
    body.append(f"{IND}if gen is not None:  # joint torques' generalised force in q's rows")
    body.append(f"{IND}    _b[:{n}] += gen")
    body.append(f"{IND}_s = np.linalg.solve(_K, _b).tolist()")
    body += [f"{IND}{s} = _s[{i}]" for i, s in enumerate(eq.qdd)]
    body += [f"{IND}{ds['lam'][0]}, {ds['lam'][1]} = _s[4], _s[5]"]
    toe_share = (f"_s[6] / ({PRINTER.doprint(ds['sole'])})" if lead == "foot_flat" else "0.0")
    lines, red = cse_lines([ds["trail_normal"], ds["trail_tangential"], ds["lead_normal"]],
                           PRINTER)
    body += lines
    rates = ", ".join(str(s) for s in eq.dq)
    accs = ", ".join(str(s) for s in eq.qdd)
    body.append(f"{IND}return (np.array(({rates}, {accs})), "
                f"({', '.join(PRINTER.doprint(e) for e in red)}, {toe_share}))")
    out = [f"    def _double_support_{lead}(x, gen=None, level=0.0):", *body,
           f"    def flow_double_support_{lead}(t, x, gen=None, level=0.0):",
           f"{IND}return _double_support_{lead}(x, gen, level)[0]",
           f"    def double_support_{lead}_forces(t, x, gen=None, level=0.0):",
           f"{IND}return _double_support_{lead}(x, gen, level)[1]"]
    Ki, kr = sysd["Ki"], sysd["Ki_rhs"]
    mi = Ki.rows
    lines, red = cse_lines(list(Ki) + list(kr) + list(ds["u"]), PRINTER)
    nk = mi * mi + mi
    u = [PRINTER.doprint(e) for e in red[nk:]]
    names = ", ".join(str(s) for s in eq.q)
    out += [f"    def double_support_{lead}_entry(x, level=0.0):", *head, *lines,
            f"{IND}_K = np.array(({', '.join(PRINTER.doprint(e) for e in red[:mi * mi])},),"
            f" dtype=float).reshape({mi}, {mi})",
            f"{IND}_b = np.array(({', '.join(PRINTER.doprint(e) for e in red[mi * mi:nk])},),"
            " dtype=float)",
            f"{IND}_s = np.linalg.solve(_K, _b)"]
    if sysd.get("entry_on_Q"):  # feet with mass: the toe's impulse in world axes
        out += [f"{IND}_lx, _ly = float(_s[{n + 1}]), float(_s[{n + 2}])",
                f"{IND}_n = _lx * sin(gamma) + _ly * cos(gamma)",
                f"{IND}_t = _lx * cos(gamma) - _ly * sin(gamma)"]
    else:
        out += [f"{IND}_u = ({u[0]}, {u[1]})",
                f"{IND}_L = float(_s[{n}])",
                f"{IND}_n = (_u[0] * sin(gamma) + _u[1] * cos(gamma)) * _L",
                f"{IND}_t = (_u[0] * cos(gamma) - _u[1] * sin(gamma)) * _L"]
    out += [f"{IND}return np.array(({names}, *_s[:{n}])), (_n, _t)"]
    if lead == ds["leads"][0]:
        lines, red = cse_lines([ds["trailing_spring"], ds["foot_angle"]], PRINTER)
        out += ["    def double_support_trailing(x, level=0.0):", *head, *lines,
                f"{IND}return {ds['b']}, {ds['db']}, {PRINTER.doprint(red[0])}, "
                f"{PRINTER.doprint(red[1])}"]
    return out
