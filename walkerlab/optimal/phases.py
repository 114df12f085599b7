"""A periodic gait of a walker with a mode sequence by multi-phase direct collocation
(CasADi ``Opti`` + IPOPT): one step as the walker's own fixed sequence of phases, each with
its own free duration and Hermite-Simpson mesh, the guard ending each phase as a
constraint at its end, the intermediate resets (a knee strike) linking the phases and the
heel-strike reset as the periodic boundary condition.

Phase order.  Read from the rigid model (:func:`walkerlab.models.hybrid.rigid.
make_rigid_walker`): from its first phase, the guard that does not end in a fall leads to
the next phase (through its reset, if any) until the heel strike (:func:`phase_order`).  A
kneed walker (McGeer 1990, "Passive walking with knees"; Hsu Chen 2007): ``unlocked_swing``
(three links) until ``knee_strike`` (the knee extension crosses zero upward; plastic knee
strike), ``locked_swing`` (the knee locked) until ``heel_strike`` (plastic, knee locked;
roles swap, the new swing knee starts straight).

Each phase's flow, guard and reset in CasADi come from the walker's symbolic equations
(:func:`walkerlab.codegen.symbolic.derive`, the same ones its generated code is printed
from): the free flow ``M qdd = B u - C dq - G``, the locked flow as the square system
``[S^T M; J_k] qdd = [S^T (-C dq - G); 0]`` with the hip torque's acceleration projected on
the lock (``M^-1 (B u + a lam)``, ``a . qdd = 0``, ``a`` the lock's gradient; the model
layer's :meth:`walkerlab.models.hybrid.actuated.Actuators.added_acceleration`), the knee
strike ``Mk dq+ = Bk dq-`` (the shank's angle set to the thigh's), the heel strike
``Mi dq+ = B dq-`` then the role swap.  ``B`` is the gradient of the hip angle (swing thigh
minus stance thigh): ``+u`` on the swing thigh, ``-u`` on the stance leg.

Per phase ``p`` (Kelly 2017, SIAM Review 59(4):849-904, Sec. 4, separated Hermite-Simpson;
the multi-phase form of Sec. 8 / Betts 2010, Ch. 4.7): ``2 N_p + 1`` points on ``[0, T_p]``,
the defects of :mod:`walkerlab.optimal.collocation`, and at the phase's end ``guard_p = 0``
with ``d * guard_p' >= touchdown_rate`` (``d`` the guard's crossing direction: the
crossing is transversal, as the rigid model's event needs), and the guard's sign kept
inside the phase (``d * guard_p <= 0`` at its interior points: the event has not happened
earlier).  Links: ``x_{p+1}(0) = reset_p(x_p(T_p))``; periodic: ``x_0(0) =
heel_strike(x_last(T_last))``.  Objective: ``int u^2 dt`` (Simpson on every phase) or the
peak torque (epigraph).  The step period is ``sum T_p``.

A result is a gait after its replay on the rigid model (its generated code, its own
guards and resets) with the optimised torque as a function of the time since the heel
strike (each phase's piecewise quadratic): :func:`replay_phases`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PHASE_FLOWS", "PHASE_GUARDS", "ModePhase", "mode_functions", "phase_order"]

#: the symbolic flow of each rigid phase: ``(equations, lock)`` - ``free`` (``M, C, G``) or
#: ``locked`` (``Equations.locked``), ``lock`` the generated guard whose gradient the lock
#: holds (None: unconstrained)
PHASE_FLOWS = {"unlocked_swing": ("free", None), "locked_swing": ("locked", "knee_extension"),
               "early_swing": ("free", None), "late_swing": ("free", None)}
#: the symbolic guard and reset of each rigid guard that ends a phase: ``(generated guard,
#: reset)``, the reset ``knee`` (plastic knee strike), ``heel`` (heel strike + role swap) or
#: None (no jump)
PHASE_GUARDS = {"knee_strike": ("knee_extension", "knee"), "heel_strike": ("heel_strike", "heel"),
                "midstance": ("swing_foot_ahead", None)}


@dataclass(frozen=True)
class ModePhase:
    """One phase of the step in CasADi.

    Attributes
    ----------
    name : str
        The rigid model's phase name.
    guard_name : str
        The rigid model's guard ending it.
    direction : int
        Its crossing direction (+1 upward, -1 downward).
    flow : casadi.Function
        ``(x (2n,), u) -> dx/dt (2n,)``.
    guard, guard_rate : casadi.Function
        ``x -> g``, ``(x, u) -> dg/dt``.
    reset : casadi.Function
        ``x -> x+`` at the guard (identity when it has none; the last phase's: heel strike
        with the role swap).
    """

    name: str
    guard_name: str
    direction: int
    flow: object
    guard: object
    guard_rate: object
    reset: object


def phase_order(walker) -> list[tuple[str, str, int]]:
    """The step's phases of a rigid walker in order: ``(phase, guard ending it, its
    direction)``, following each phase's guard that does not end in a fall to the next
    phase (its ``next_phase``, else the next in order) until the heel strike.

    Raises
    ------
    ValueError
        A phase with no such guard, or one with several (the step's phase sequence is not
        fixed: a flat foot's mode graph), or a loop (one line).
    """
    by_name = {ph.name: k for k, ph in enumerate(walker.phases)}
    out, k = [], 0
    while len(out) <= len(walker.phases):
        ph = walker.phases[k]
        ends = [g for g in ph.guards if g.outcome != "fall"]
        if len(ends) != 1:
            raise ValueError(f"optimize: the phase {ph.name} ends {len(ends)} ways: the step "
                             "has no fixed phase sequence (not yet)")
        g = ends[0]
        out.append((ph.name, g.name, int(g.direction)))
        if g.outcome == "heel_strike":
            return out
        k = by_name[g.next_phase] if g.next_phase else k + 1
    raise ValueError("optimize: the step's phases loop without a heel strike")


def _hip_gradient(eq):
    """The hip angle (swing thigh minus stance thigh; straight legs: swing minus stance)."""
    la = eq.leg_angles
    sw, st = ("swing_thigh", "stance_thigh") if "swing_thigh" in la else ("swing", "stance")
    return la[sw] - la[st]


def mode_functions(data, eq, walker) -> dict:
    """CasADi functions of the step of ``data``'s walker (module docstring) from its
    symbolic equations ``eq``, in the phase order of its rigid model ``walker``:
    ``phases`` (list of :class:`ModePhase`), ``step(x)`` (the feet's distance [m]),
    ``ahead(x)`` (> 0: the swing foot ahead), ``clearance(x)`` (the swing foot above the
    slope [m]), ``hip_angle(x)`` [rad], ``power(x, u)`` [W], ``n``.

    Raises
    ------
    ValueError
        A phase or guard this transcription has no symbolic form for, massless legs, a
        torso (one line).
    """
    import casadi as ca
    import sympy as sp

    from walkerlab.optimal.collocation import _to_casadi

    st = data.structure
    if eq.limit or st.torso or st.free_knees or st.foot != "point":
        raise ValueError("optimize: the phased transcription takes massive legs with point "
                         "feet and no torso today")
    order = phase_order(walker)
    n = len(eq.q)
    vals = dict(zip(eq.params, data.params))
    xs = list(eq.q) + list(eq.dq)
    x, u = ca.SX.sym("x", 2 * n), ca.SX.sym("u")

    def cas(exprs):
        return _to_casadi(exprs, xs, vals)(x)
    hip = _hip_gradient(eq)
    Bu = cas(sp.Matrix([hip]).jacobian(eq.q).T) * u
    M = cas(eq.M)
    acc = ca.solve(M, Bu)
    phases = []
    for name, gname, direction in order:
        if name not in PHASE_FLOWS or gname not in PHASE_GUARDS:
            raise ValueError(f"optimize: no symbolic form of the phase {name} / guard {gname}")
        kind, lock = PHASE_FLOWS[name]
        Mp, Cp, Gp = (eq.M, eq.C, eq.G) if kind == "free" else eq.locked
        qdd = ca.solve(cas(Mp), -cas(Cp) @ x[n:] - cas(Gp))
        if lock is None:
            qdd = qdd + acc
        else:  # the torque's share along the lock is taken by it
            a = cas(sp.Matrix([eq.guards[lock]]).jacobian(eq.q).T)
            Ma = ca.solve(M, a)
            qdd = qdd + acc - Ma * (a.T @ acc) / (a.T @ Ma)
        f = ca.vertcat(x[n:], qdd)
        gkey, rkind = PHASE_GUARDS[gname]
        g = cas([eq.guards[gkey]])
        phases.append(ModePhase(
            name, gname, direction, ca.Function(f"flow_{name}", [x, u], [f]),
            ca.Function(f"guard_{gname}", [x], [g]),
            ca.Function(f"rate_{gname}", [x, u], [ca.jacobian(g, x) @ f]),
            ca.Function(f"reset_{gname}", [x], [_reset(eq, rkind, cas, x, n, vals)])))
    foot = cas(eq.points["swing_foot"])
    hip_angle = cas([hip])
    return {"phases": phases, "n": n,
            "step": ca.Function("step", [x], [ca.sqrt(foot[0] ** 2 + foot[1] ** 2)]),
            "ahead": ca.Function("ahead", [x], [cas([eq.guards["swing_foot_ahead"]])]),
            "clearance": ca.Function("clearance", [x], [cas([eq.guards["swing_clearance"]])]),
            "hip_angle": ca.Function("hip_angle", [x], [hip_angle]),
            "power": ca.Function("power", [x, u], [u * ca.jacobian(hip_angle, x[:n])
                                                   @ x[n:]])}


def _reset(eq, kind, cas, x, n, vals):
    """The reset of a guard (CasADi): ``knee`` ``Mk dq+ = Bk dq-`` with the shank's angle
    set to the thigh's (:mod:`walkerlab.codegen.source`'s ``knee_reset``), ``heel``
    ``Mi dq+ = B dq-`` and the role swap, None the identity."""
    import casadi as ca
    import sympy as sp

    if kind is None:
        return x
    if kind == "knee":
        Mk, Bk = eq.knee_impact
        q_lock = sp.Matrix([eq.q[j] for j in (0, 0, *range(2, n))])
        return ca.vertcat(cas(q_lock), ca.solve(cas(Mk), cas(Bk) @ x[n:]))
    dq_plus = ca.solve(cas(eq.Mi), cas(eq.B) @ x[n:])
    R = np.array(eq.relabel_rate.subs(vals), float)
    return ca.vertcat(cas(eq.relabel_q), ca.DM(R) @ dq_plus)
