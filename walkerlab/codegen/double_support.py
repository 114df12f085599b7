"""Double support of a flat-footed walker after heel strike (the leading foot on its heel
or flat, the trailing foot on its toe): its symbolic closed-chain flow and toe-pinning entry
impact (:func:`derive_double_support`, part of
:func:`walkerlab.codegen.foot_modes.derive_flat`) and their generated source
(:func:`double_support_lines`, part of :func:`walkerlab.codegen.foot_modes.generate_flat`);
Wisse et al. 2006, "Ankle springs instead of arc-shaped feet for passive dynamic walkers".
"""

from __future__ import annotations

import sympy as sp

from walkerlab.codegen.source import IND, PRINTER, cse_lines, unpack

#: The leading foot's modes in double support (the trailing foot on its toe): on its heel
#: (turning about it) or flat (its angle locked).
DOUBLE_SUPPORT_LEADS = ("heel_contact", "foot_flat")


def _lead_system(lead: str, M4, rhs, J, dJ, M, g_row, Jl, dq, foot_inertia) -> dict:
    """One leading-foot mode's double support (:func:`derive_double_support`): the flow's
    system ``K [Qdd; lam] = rhs`` (``M4``, the toe's ``J``, ``dJ dQ``; foot flat adds the
    lock's row) and the entry's ``Ki [dq+; Lam] = Ki_rhs`` (on ``q`` with the pin's row
    ``g_row``, ``M`` the heel contact's mass matrix; with ``foot_inertia`` the impact on
    ``Q``, ``entry_on_Q``)."""
    rows = J if lead == "heel_contact" else J.col_join(sp.Matrix([[0, 1, 1, 0]]))
    gam = -dJ if lead == "heel_contact" else (-dJ).col_join(sp.zeros(1, 1))
    m = rows.rows
    K = sp.zeros(4 + m, 4 + m)
    K[:4, :4] = M4
    K[:4, 4:] = -rows.T
    K[4:, :4] = rows
    imp_rows = g_row if lead == "heel_contact" else g_row.col_join(Jl)
    mi = imp_rows.rows
    Ki = sp.zeros(3 + mi, 3 + mi)
    Ki[:3, :3] = M
    Ki[:3, 3:] = -imp_rows.T
    Ki[3:, :3] = imp_rows
    out = {"K": K, "rhs": rhs.col_join(gam), "Ki": Ki,
           "Ki_rhs": (M * sp.Matrix(dq)).col_join(sp.zeros(mi, 1))}
    if foot_inertia != 0:  # the toe pinned on Q (see derive_double_support)
        out["Ki"] = K
        out["Ki_rhs"] = (M4 * sp.Matrix([*dq, 0])).col_join(sp.zeros(m, 1))
        out["entry_on_Q"] = True
    return out


def derive_double_support(q, dq, qdd, flows, ankle, lead_force, trailing, sole, gamma, normal,
                    tangent, Jl, foot_inertia=0) -> dict:
    """Double support after heel strike (roles already swapped): the leading (stance) foot
    on its heel at ``O`` (heel contact) or flat (foot flat), the trailing (swing) foot on its
    toe at a point ``P`` of the slope.  The trailing foot's ankle angle ``b`` (its sole at
    ``swing + b``) is no state: with the toe on the slope, ``sin(swing + b + gamma) = -h/t``
    (``h`` the trailing ankle's height above the slope, ``t`` the toe length), the branch
    with the heel up (a toe on a line ``level`` [m] above the leading heel's, the tread it
    stood on when the heel struck a landing lower down: ``sin(swing + b + gamma) = (level -
    h)/t``); its rate from the toe's zero normal velocity.  The flow: Lagrange's
    equations on ``Q = (swing, stance, stance_ankle, b)`` (the foot massless: ``b``'s row
    holds the spring ``k (b - r)`` and damper ``c db`` against the toe's force), the toe
    pinned, ``[M, -J^T; J, 0] [Qdd; lam] = [-C dQ - G; -dJ dQ]`` (``J = dT/dQ`` (2 x 4) of
    the toe ``T``; foot flat adds ``phi = 0``'s row ``[0, 1, 1, 0]``), ``lam`` the ground's
    force on the toe (world axes) [N].  Entry (the plastic impact that pins the toe, Newton's
    restitution 0): in ``q`` the toe's pin is one row ``g = u^T dA/dq`` (``A`` the trailing
    ankle, ``u`` the unit vector from toe to ankle: a massless foot takes no impulsive
    moment, so the toe's impulse ``Lam u`` passes through the ankle) and
    ``[M, -g^T (, -Jl^T); g, 0 (; Jl, 0)] [dq+; Lam] = [M dq-; 0 (; 0)]``.

    Feet with mass (``foot_inertia`` ``I`` [kg m^2] about the ankle, the mass at the ankle
    already a body of ``flows``, whose swing foot turns with its leg): the trailing sole
    turns at ``d(swing + b)/dt``, so ``M`` gains ``I`` in the ``(swing, b)`` block beyond
    the locked foot's ``I`` in ``(swing, swing)``; the entry is then the impact on ``Q``
    with the toe pinned in both directions, ``[M4, -J^T (, -Jl4^T); J, 0 (; Jl4, 0)]
    [dQ+; Lam] = [M4 (dq-, 0); 0 (; 0)]`` (the foot turning with its leg before it,
    ``db- = 0``; ``Lam`` (2,) the toe's impulse in world axes [N s]), whose limit ``I -> 0``
    is the massless entry above."""
    b, db = sp.symbols("b_trail db_trail", real=True)
    t_len, k_b, r_b, c_b = trailing
    sw = q[0]
    h = (ankle.T * normal)[0]
    theta = sw + b
    toe = ankle + t_len * sp.Matrix([sp.cos(theta), sp.sin(theta)])
    Q, dQ = (*q, b), (*dq, db)
    Qv, dQv = sp.Matrix(Q), sp.Matrix(dQ)
    J = toe.jacobian(Qv)
    dJ = (J * dQv).jacobian(Qv) * dQv
    hc = flows["heel_contact"]
    M4 = sp.zeros(4, 4)
    M4[:3, :3] = hc.M
    M4[0, 3] = M4[3, 0] = M4[3, 3] = foot_inertia
    rhs = sp.zeros(4, 1)
    rhs[:3, 0] = -hc.C * sp.Matrix(dq) - hc.G
    rhs[3, 0] = -c_b * db - k_b * (b - r_b)
    b_of = sp.asin(-h / t_len) - gamma - sw
    # the trailing toe on a line ``level`` [m] above the leading heel's (along the normal):
    # the tread it stood on when the heel struck a lower landing (stairs, footholds)
    level = sp.Symbol("level", real=True)
    b_of_level = sp.asin((level - h) / t_len) - gamma - sw
    hdot = (sp.Matrix([h]).jacobian(sp.Matrix(q)) * sp.Matrix(dq))[0]
    db_of = -hdot / (t_len * sp.cos(theta + gamma)) - dq[0]
    dA = ankle.jacobian(sp.Matrix(q))
    u = -sp.Matrix([sp.cos(theta), sp.sin(theta)])  # toe -> ankle
    g_row = u.T * dA
    F, mom = lead_force
    held = k_b * (b - r_b) ** 2 / 2
    if foot_inertia != 0:  # the sole's kinetic energy beyond turning with its leg (held in M)
        held += foot_inertia * ((dq[0] + db) ** 2 - dq[0] ** 2) / 2
    out = {"b": b, "db": db, "b_of": b_of, "b_of_level": b_of_level, "db_of": db_of, "u": u,
           "toe": toe, "trailing_spring": held, "foot_angle": theta + gamma}
    for lead in DOUBLE_SUPPORT_LEADS:
        out[lead] = _lead_system(lead, M4, rhs, J, dJ, hc.M, g_row, Jl, dq, foot_inertia)
    # the leading foot's ground force: Newton's total (feet massless) less the toe's; in
    # foot flat its toe's share from the moment balance about its heel, less the trailing
    # toe's moment (the lock's multiplier is that moment: its toe force times the sole)
    lam = sp.Matrix(sp.symbols("lam_x lam_y", real=True))
    out["lead_normal"] = ((F - lam).T * normal)[0]
    out["trail_normal"] = (lam.T * normal)[0]
    out["trail_tangential"] = (lam.T * tangent)[0]
    out["lam"] = lam
    out["sole"] = sole
    return out


def double_support_lines(eq, lead: str) -> list[str]:
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
    if lead == DOUBLE_SUPPORT_LEADS[0]:
        lines, red = cse_lines([ds["trailing_spring"], ds["foot_angle"]], PRINTER)
        out += ["    def double_support_trailing(x, level=0.0):", *head, *lines,
                f"{IND}return {ds['b']}, {ds['db']}, {PRINTER.doprint(red[0])}, "
                f"{PRINTER.doprint(red[1])}"]
    return out

