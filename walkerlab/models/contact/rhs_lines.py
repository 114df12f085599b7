"""The straight-line numba source of a compliant-contact walker's right-hand side
(:func:`rhs_source`), part of its generated contact module
(:func:`walkerlab.models.contact.generated.contact_source`, whose cache key reads this
file too)."""

from __future__ import annotations

__all__ = ["rhs_source"]


def _cholesky_lines(nq: int, nz: set) -> list[str]:
    """:func:`rhs_source`'s solve ``M a = Q`` (``_M<i>_<j>``, ``_Q<i>`` -> ``_a<i>``): an
    unrolled Cholesky ``M = L L^T`` with the structural zeros ``nz`` of ``M``'s lower
    triangle (and the fill-in) tracked, then the two triangular solves."""
    lines, Lnz = [], set()
    for j in range(nq):
        terms = [f" - _L{j}_{k} * _L{j}_{k}" for k in range(j) if (j, k) in Lnz]
        lines.append(f"    _L{j}_{j} = sqrt(_M{j}_{j}{''.join(terms)})")
        lines.append(f"    _d{j} = 1.0 / _L{j}_{j}")
        for i in range(j + 1, nq):
            terms = [f" - _L{i}_{k} * _L{j}_{k}" for k in range(j)
                     if (i, k) in Lnz and (j, k) in Lnz]
            if (i, j) in nz or terms:
                Lnz.add((i, j))
                head = f"_M{i}_{j}" if (i, j) in nz else "0.0"
                lines.append(f"    _L{i}_{j} = ({head}{''.join(terms)}) * _d{j}")
    for i in range(nq):
        terms = [f" - _L{i}_{k} * _y{k}" for k in range(i) if (i, k) in Lnz]
        lines.append(f"    _y{i} = (_Q{i}{''.join(terms)}) * _d{i}")
    for i in reversed(range(nq)):
        terms = [f" - _L{k}_{i} * _a{k}" for k in range(i + 1, nq) if (k, i) in Lnz]
        lines.append(f"    _a{i} = (_y{i}{''.join(terms)}) * _d{i}")
    return lines


def _force_lines(point_legs, Fs, forced: bool, d: int = 2) -> list[str]:
    """:func:`rhs_source`'s contact forces ``Fs`` (``d`` per point: x, y (, z)) in the world
    from each point's ``_point`` result ``_r<i>`` (normal and friction force
    along the ground's normal and tangent; in 3D the lateral friction); ``forced``: a ghost
    point's (of leg ``G[0]``, ``G[1]`` ahead of the other leg's points) zero."""
    lines = []
    for i, leg in enumerate(point_legs):
        # (Fn, Ff) in the world, along the ground's normal (the slope's: _sp, _cp)
        comps = [f"_r{i}[4] * _r{i}[10] + _r{i}[5] * _r{i}[11]",
                 f"_r{i}[4] * _r{i}[11] - _r{i}[5] * _r{i}[10]", f"_r{i}[13]"][:d]
        if forced:  # a ghost point: of leg G[0], ahead of the other leg's points by G[1]
            others = ", ".join(f"_r{j}[3]" for j, lg in enumerate(point_legs) if lg != leg)
            front = f"max({others}, -1e300)" if others.count(",") else f"{others}"
            lines.append(f"    _ghost{i} = S[NQ + 10] == {float(leg)} and "
                         f"_r{i}[3] - {front} >= S[NQ + 11]")
            comps = [f"0.0 if _ghost{i} else {c}" for c in comps]
        lines += [f"    {Fs[d * i + k]} = {c}" for k, c in enumerate(comps)]
    return lines


def _knee_lines(eq, red, pr, Q, power: list, d: int = 2) -> list[str]:
    """:func:`rhs_source`'s knee-stop torques ``_T<k>`` of each leg's knee (none without
    knees), from its extension and rate and its foot's penetration (``red``: the feet's
    reduced kinematics, ``2 d`` per point, printed by ``pr``); each added into ``Q`` (+ on
    the thigh, - on the shank) and its power ``-T d(ext)/dt`` appended to ``power``."""
    import sympy as sp

    lines = []
    for k, (t, sh) in enumerate(eq.knees or ()):  # (thigh, shank) in q; leg k: point k
        T = sp.Symbol(f"_T{k}", real=True)
        # penetration of leg k's foot, -(p . n)
        # (a polyline ground: the penetration into it, _point's)
        # on patches of several heights (stairs, footholds) from the nearest patch's top
        # (the latch's ground: assembly.latch_ground; 0.0 on the slope)
        dl = (f"(_r{k}[0] if PC[I_CONT] > 1.5 else "
              f"-(({pr.doprint(red[2 * d * k])}) * _sp + "
              f"({pr.doprint(red[2 * d * k + 1])}) * _cp) "
              f"+ _asm.latch_ground(_r{k}[3], {('c1', 'c2')[k]}, PC))")
        lines.append(f"    {T} = _knee_torque({eq.q[sh]} - {eq.q[t]}, "
                     f"{eq.dq[sh]} - {eq.dq[t]}, PC, {dl})")
        Q[t] += T
        Q[sh] -= T
        power.append(f"-{T} * ({eq.dq[sh]} - {eq.dq[t]})")
    return lines


def _stance_lines(eq, Q, pr=None, power=None) -> list[str]:
    """:func:`rhs_source`'s stance-dependent internal forces
    (:attr:`walkerlab.codegen.floating.FloatingEquations.stance_forces`: a walker in 3D
    with hip-roll joints, Kuo 1999's law) added into ``Q``: each leg's law weighted by its
    foot's share of the normal load, ``_w<k> = (Fn_k + e) / (Fn_1 + Fn_2 + 2 e)`` (the
    point results ``_r<i>``; ``e`` = ``PC[I_WEPS]``, 1e-3 of the walker's weight: the
    stance leg's law in single support to 0.1 %, the two blended through the double
    support, halves in flight, and continuous through a bounce, where both loads
    vanish).  With ``power`` (a list: :func:`rhs_source`'s forced variant) the law's power
    ``sum_k w_k F_k . dq`` [W] is appended to it as text (its terms computed here,
    printed by ``pr``)."""
    import sympy as sp

    if not eq.stance_forces:
        return []
    loads = [" + ".join(f"_r{i}[4]" for i, lg in enumerate(eq.point_legs) if lg == leg)
             for leg in (0, 1)]
    lines = [f"    _load0 = {loads[0]} + PC[I_WEPS]", f"    _load1 = {loads[1]} + PC[I_WEPS]",
             "    _w1 = _load1 / (_load0 + _load1)", "    _w0 = 1.0 - _w1"]
    for k, F in enumerate(eq.stance_forces):  # leg k + 1 in stance (Q in place)
        w = sp.Symbol(f"_w{k}", real=True)
        for i in range(len(Q)):
            Q[i] += w * F[i]
    if power is not None:  # each leg's law's power F_k . dq, weighted as its force
        dqv = sp.Matrix(eq.dq)
        pk = [(F.T * dqv)[0] for F in eq.stance_forces]
        repl, red = sp.cse(pk, symbols=sp.numbered_symbols("_pl"), order="none")
        lines += [f"    {pr.doprint(a)} = {pr.doprint(b)}" for a, b in repl]
        lines += [f"    _plaw{k} = {pr.doprint(r)}" for k, r in enumerate(red)]
        power.append(" + ".join(f"_w{k} * _plaw{k}" for k in range(len(red))))
    return lines


def _point_lines(eq, pr, dqv, d: int, lines: list) -> tuple:
    """:func:`rhs_source`'s contact points, appended to ``lines``: each point's position
    and material velocity (``d`` components) and its spin about the normal (3D), common
    subexpressions shared, and its ``_point`` result ``_r<i>`` (a planar point in its plane,
    ``z = 0``) on its leg's
    lane.  Returns the reduced kinematics, the force symbols (``d`` per point) and each
    point's power ``F . v`` as text."""
    import sympy as sp

    kin = []
    for pos, J in eq.feet:
        v = J * dqv
        kin += [*pos[:d], *v[:d]]
    kin += [(Jn * dqv)[0] for Jn in eq.spins]  # each point's spin about the normal
    repl, red = sp.cse(kin, symbols=sp.numbered_symbols("_k"), order="none")
    lines += [f"    {pr.doprint(a)} = {pr.doprint(b)}" for a, b in repl]
    axes = "xyz"[:d]
    Fs = sp.symbols(" ".join(f"_F{a}{i}" for i in range(len(eq.feet)) for a in axes),
                    real=True)
    power = []  # forced: each point's F . v
    for i, leg in enumerate(eq.point_legs):  # each point on its leg's lane
        pos, vel = ([pr.doprint(e) for e in red[2 * d * i + k * d:2 * d * i + (k + 1) * d]]
                    + ["0.0"] * (3 - d) for k in (0, 1))
        args = ", ".join(pos + vel)
        power.append(" + ".join(f"{Fs[d * i + k]} * ({pr.doprint(red[2 * d * i + d + k])})"
                                for k in range(d)))
        lines += [f"    _r{i} = _point({args}, _sp, _cp, PC, {('c1', 'c2')[leg]})"]
    return red, Fs, power


def rhs_source(eq, forced: bool = False) -> str:
    """Straight-line numba source of ``rhs(x, PC, p, c1, c2)`` for the floating equations
    ``eq`` (:class:`walkerlab.codegen.floating.FloatingEquations`): the feet's contact points
    and material velocities, the contact forces and knee-stop torques from the laws, then
    ``M`` and ``Q - h`` (common subexpressions shared) and an unrolled Cholesky solve that
    skips the structural zeros of ``M`` (fill-in tracked).  Same equations as the array
    functions ``dyn``/``feet`` (tests check the two agree), cheaper per call, which is
    what CyRK's BDF pays per step.

    The generated ``rhs`` takes the state ``x`` of shape (2 nq,) [m, rad, m/s, rad/s], the
    contact parameters ``PC`` (SI), the walker's parameters ``p`` (SI) and the kernel lanes
    ``c1``, ``c2`` [m], and returns dx/dt of shape (2 nq,).

    ``forced``: the source of ``rhs_q(x, PC, p, c1, c2, S, out)`` instead (dx/dt written
    into ``out``, the first 2 nq entries; ``S`` the scratch of
    :mod:`walkerlab.models.contact.powered_source`), the same arithmetic with the
    generalised force ``S[:nq]`` [N, N m] added to ``Q - h`` before the solve (an actuated
    walker's forces), and ``S[nq + 6]``, ``S[nq + 7]`` filled with the contact forces' power
    ``sum F . v`` over the contact points (their material velocities) and the joints' own
    laws' power: the knee stops' ``-T d(ext)/dt``, a 3D walker's hip-roll law's
    ``sum_k w_k F_k . dq`` [W]; ``S[nq + 10:nq + 12]`` = ``G``:
    the contact points of leg ``G[0]`` (0: leg1, 1: leg2; -1: none) at least ``G[1]`` [m]
    ahead (along the ground) of every point of the other leg carry no contact force (a
    *ghost* swing foot: up to its touchdown ahead the run is the same, and a compiled run
    locates that touchdown without integrating the collision it starts,
    :mod:`walkerlab.integrate.compiled_segments`).
    """
    import sympy as sp
    from sympy.printing.pycode import PythonCodePrinter

    pr = PythonCodePrinter({"fully_qualified_modules": False, "standard": "python3"})
    nq = len(eq.q)
    dqv = sp.Matrix(eq.dq)
    head = ("def rhs_q(x, PC, p, c1, c2, S, out):" if forced
            else "def rhs(x, PC, p, c1, c2):")
    lines = ["@njit(cache=True, error_model='numpy')", head,
             '    """dx/dt (NX,) of the free-floating walker (generated straight-line code)."""',
             f"    {', '.join(str(s) for s in eq.params)}, = p"]
    lines += [f"    {s} = x[{i}]" for i, s in enumerate(eq.q)]
    lines += [f"    {s} = x[{nq + i}]" for i, s in enumerate(eq.dq)]
    lines += ["    _sp = _sin(PC[I_PHI])", "    _cp = _cos(PC[I_PHI])"]
    d = eq.feet[0][0].shape[0]  # the world's dimension: 2 (planar) or 3
    red, Fs, power = _point_lines(eq, pr, dqv, d, lines)
    lines += _force_lines(eq.point_legs, Fs, forced, d)
    Q = -eq.h
    for i, (_, J) in enumerate(eq.feet):
        Q += J.T * sp.Matrix(Fs[d * i:d * (i + 1)])
    for i, Jn in enumerate(eq.spins):  # the patches' torsional friction (3D)
        spin = pr.doprint(red[2 * d * len(eq.feet) + i])
        tw = sp.Symbol(f"_tw{i}", real=True)
        lines.append(f"    {tw} = _twist({spin}, _r{i}[4], PC)"
                     + (f" if not _ghost{i} else 0.0" if forced else ""))
        Q += Jn.T * tw
        power[i] += f" + {tw} * ({spin})"
    lines += _knee_lines(eq, red, pr, Q, power, d)
    lines += _stance_lines(eq, Q, pr, power if forced else None)
    nz = {(i, j) for i in range(nq) for j in range(i + 1) if eq.M[i, j] != 0}
    mexprs = [eq.M[i, j] for i in range(nq) for j in range(i + 1) if (i, j) in nz]
    repl, red = sp.cse(mexprs + list(Q), symbols=sp.numbered_symbols("_m"), order="none")
    lines += [f"    {pr.doprint(a)} = {pr.doprint(b)}" for a, b in repl]
    it = iter(red)
    for i in range(nq):
        for j in range(i + 1):
            if (i, j) in nz:
                lines.append(f"    _M{i}_{j} = {pr.doprint(next(it))}")
    for i in range(nq):
        lines.append(f"    _Q{i} = {pr.doprint(next(it))}" + (f" + S[{i}]" if forced else ""))
    if forced:
        nf = len(eq.feet)
        lines.append(f"    S[NQ + 6] = {' + '.join(power[:nf])}")
        lines.append(f"    S[NQ + 7] = {' + '.join(power[nf:]) or '0.0'}")
    lines += _cholesky_lines(nq, nz)
    outs = [str(s) for s in eq.dq] + [f"_a{i}" for i in range(nq)]
    if forced:  # into the caller's array (no allocation per call)
        lines += [f"    out[{i}] = {o}" for i, o in enumerate(outs)]
    else:
        lines.append(f"    return np.array(({', '.join(outs)},))")
    return "\n".join(lines) + "\n"
