"""A periodic gait of a walker with a mode sequence by multi-phase direct collocation
(CasADi ``Opti`` + IPOPT): one step as a fixed sequence of the walker's own phases, each
with its own free duration and Hermite-Simpson mesh, the guard ending each phase as a
constraint at its end, the intermediate resets (a knee strike, a foot slap) linking the
phases and the heel-strike reset as the periodic boundary condition.

Phase order (:func:`phase_order`).  Read from the rigid model
(:func:`walkerlab.models.hybrid.rigid.make_rigid_walker`): from its first phase, the one
guard that does not end in a fall leads to the next phase until the heel strike; where the
phases form a graph (a flat foot's modes crossed with early / late swing), the sequence a
step of the gait went through (its ``phase_log``).  A kneed walker (McGeer 1990, "Passive
walking with knees"; Hsu Chen 2007): ``unlocked_swing`` until ``knee_strike`` (the knee's
extension crosses zero upward; plastic knee strike), ``locked_swing`` until ``heel_strike``
(plastic, knee locked; roles swap).  Flat feet on ankle springs (Wisse et al. 2006; the
passive gait of configs/flat_feet.yaml): ``heel_contact:early_swing`` until ``foot_slap``
(plastic, the foot locks flat), ``foot_flat:early_swing`` until ``midstance`` (no jump),
``foot_flat:late_swing`` until ``heel_off`` (the heel's normal force reaches 0; no jump),
``heel_off:late_swing`` until ``heel_strike`` (the toe-pinned map).

Each phase's flow, guard and reset in CasADi come from the walker's symbolic equations
(:func:`walkerlab.codegen.legged.derive_legged`, :func:`walkerlab.codegen.foot_modes.derive_flat`:
the ones its generated code is printed from): a free flow ``M qdd = B u - C dq - G``; a
locked one (knee, flat foot) as the square system ``[S^T M; J] qdd = [S^T (-C dq - G); 0]``
with the hip torque's acceleration projected on the lock (``M^-1 (B u + a lam)``,
``a . qdd = 0``: the model layer's :meth:`walkerlab.models.hybrid.actuated.Actuators.
added_acceleration`); a plastic impact ``Mi dq+ = B dq-`` then the new coordinates (the
heel strike's role swap).  ``B`` is the gradient of the hip angle (swing minus stance
thigh or leg): ``+u`` on the swing leg, ``-u`` on the stance leg.  A guard on a contact
force (heel off) reads the ground reaction from the phase's accelerations, torque included;
flat feet's stance contacts are kept pushing (normal forces ``>= 0``) at every point.

Per phase ``p`` (:mod:`walkerlab.optimal.transcription.mode_sequence`; Kelly 2017, SIAM Review
59(4):849-904, Sec. 4, separated Hermite-Simpson; the multi-phase form of Betts 2010,
Ch. 4.7): ``2 N_p + 1`` points on ``[0, T_p]``, the defects of
:mod:`walkerlab.optimal.transcription.step`, and at the phase's end ``guard_p = 0`` with
``d * dguard_p/dt >= touchdown_rate`` (``d`` the guard's crossing direction: a transversal
crossing, as the rigid model's event needs; a force guard's rate leaves out the torque's
own rate), and the guard's sign kept inside the phase (``d * guard_p <= 0`` at its
interior points: the event has not happened earlier).  Links: ``x_{p+1}(0) =
reset_p(x_p(T_p))``; periodic: ``x_0(0) = heel_strike(x_last(T_last))``.  Objective:
``int u^2 dt`` (Simpson on every phase), the peak torque (epigraph), the cost of transport
(the hip's positive work by slack variables ``s >= 0, s >= u d(hip)/dt`` at every point of
every phase, per weight and step length, with a small effort weight; as
:mod:`walkerlab.optimal.transcription.step`) or a weighted sum.  Optional friction cone: the
ground's resultant on the stance foot (``sum m_i (a_i + g)``, the phase's accelerations;
a kneed walker's stance foot, flat feet's pinned point or whole flat foot) with ``F_n >= 0``
and ``|F_t| <= mu F_n`` at every point.  Push-off: Kuo's (2002) pre-emptive impulse ``P``
[N s] just before the heel strike, fixed or a decision variable (its work ``W`` [J] in the
cost of transport, its square in the effort: :mod:`walkerlab.optimal.transcription.
phase_nlp`), the heel strike's link then ``x_0(0) = push_off(x_last(T_last), P)``, the
rigid model's transition in CasADi: a kneed walker's (planar or in 3D) from its trailing
foot to its hip with the swing knee held locked through both impulses (McGeer 1990;
:class:`walkerlab.models.hybrid.push_off.PushOffTransition`), the one-step
transcription's form (:func:`walkerlab.optimal.transcription.step._reset_extended` with the
knee's lock); flat feet's at the trailing toe with the stance ankle held
(:class:`walkerlab.models.hybrid.toe_push_off.FlatPushOff`, from the same symbolic
systems).  The step period is ``sum T_p``.

A result is a gait after its replay on the rigid model (its generated code, its own
guards and resets) with the optimised torque as a function of the time since the heel
strike (each phase's piecewise quadratic): :func:`walkerlab.optimal.transcription.mode_sequence.
replay_phases`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.codegen.cache import derive_equations
from walkerlab.walker import parts as P

__all__ = ["ModePhase", "mode_functions", "phase_order"]

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
    keep : casadi.Function or None
        ``(x, u) -> v``: kept ``>= 0`` at every point of the phase (a unilateral contact's
        normal forces [N]: flat feet); None: nothing.
    clearance, step : casadi.Function
        ``x ->`` the swing foot's height above the slope [m] and its distance from the
        stance reference point [m] in the phase's kinematics.
    push_off : casadi.Function or None
        ``(x, P) -> (x+, W)``: a heel strike preceded by a push-off impulse ``P`` [N s]
        along the trailing leg (the extended-coordinate impact of
        :mod:`walkerlab.models.hybrid.actuated`; a kneed walker's with its swing knee held
        locked; flat feet's at the trailing toe, :mod:`walkerlab.models.hybrid.
        toe_push_off`) and the push-off's work ``W`` [J]; None for a phase that does not
        end in the heel strike.
    inside : bool
        The guard's sign is kept at the phase's interior points (the event has not
        happened earlier); False for a step of one phase, whose heel-strike guard the
        swing foot may cross mid-swing (straight legs scuff: the one-step transcription
        bounds the clearance instead, ``optimize.min_clearance_m``).
    grf : casadi.Function
        ``(x, u) -> (F_n, F_t)`` [N]: the ground's resultant force on the stance foot along
        the slope's normal and tangent (forward, downhill, positive), ``sum_i m_i (a_i + g
        y)`` over the mass points with the phase's accelerations (torque included): a
        kneed walker's stance foot; flat feet's pinned point (heel contact, heel off) or,
        foot flat, the heel's and the toe's together.
    """

    name: str
    guard_name: str
    direction: int
    flow: object
    guard: object
    guard_rate: object
    reset: object
    keep: object = None
    clearance: object = None
    step: object = None
    grf: object = None
    push_off: object = None
    inside: bool = True


def phase_order(walker, phase_log=None) -> list[tuple[str, str, int]]:
    """The step's phases of a rigid walker in order: ``(phase, guard ending it, its
    direction)``.  With ``phase_log`` (a step's
    :attr:`walkerlab.integrate.rigid.Segment.phase_log`: a flat foot's modes form a graph,
    its gait goes one way through it) the sequence that step met; else, following each
    phase's one guard that does not end in a fall to the next phase (its ``next_phase``,
    else the next in order) until the heel strike.

    Raises
    ------
    ValueError
        Without ``phase_log``, a phase with no such guard or several (no fixed sequence),
        or a loop; a logged guard the phase does not have (one line).
    """
    by_name = {ph.name: ph for ph in walker.phases}
    if phase_log is not None:
        out = []
        for name, _t0, _t1, ended in phase_log:
            g = next((g for g in by_name[name].guards if g.name == ended
                      and g.outcome != "fall"), None)
            if g is None:
                raise ValueError(f"optimize: the starting step's phase {name} ended by "
                                 f"{ended!r}, not a step of the gait")
            out.append((name, g.name, int(g.direction)))
        return out
    out, k = [], 0
    while len(out) <= len(walker.phases):
        ph = walker.phases[k]
        ends = [g for g in ph.guards if g.outcome != "fall"]
        if len(ends) != 1:
            raise ValueError(f"optimize: the phase {ph.name} ends {len(ends)} ways: the step "
                             "has no fixed phase sequence (give the gait's)")
        g = ends[0]
        out.append((ph.name, g.name, int(g.direction)))
        if g.outcome == "heel_strike":
            return out
        k = [p.name for p in walker.phases].index(g.next_phase) if g.next_phase else k + 1
    raise ValueError("optimize: the step's phases loop without a heel strike")


def refusal(structure) -> str | None:
    """Why this transcription has no symbolic form for ``structure``'s walker (one line
    naming the field), or None: a kind without phases, a planar walker's torso, a planar
    walker's arc feet (its modes pin the stance foot; an arc foot rolls), massless legs.  A
    3D kneed walker's discs (on its shanks) are in its equations: their rolling is the
    tree's holonomic advance, its push-off the extended impact at the disc's material
    contact point (:func:`walkerlab.optimal.transcription.step._reset_extended`)."""
    if structure.kind.phases is None:
        return "optimize: the walker's kind has no phased step"
    if structure.foot == "arc" and not structure.in_3d:
        return ("walker.leg.foot.kind: arc feet on a walker with knees are not in the "
                "collocation's phased step (knees or flat feet: point or flat feet, the "
                "stance foot pinned); optimise the walker on point feet (leg.foot.kind: point)")
    if (structure.torso and not structure.in_3d) or any(b.massless for b in structure.bodies):
        return ("optimize: the phased transcription takes massive legs with point or flat "
                "feet and no torso today")
    return None


def mode_functions(data, walker, order=None) -> dict:
    """CasADi functions of the step of ``data``'s walker (module docstring) from its
    symbolic equations, in the phase order ``order`` (:func:`phase_order`; default: the
    rigid model ``walker``'s fixed one): ``phases`` (list of :class:`ModePhase`),
    ``ahead(x)`` (> 0: the swing foot ahead), ``hip_angle(x)`` [rad], ``power(x, u)``
    (the hip torque's power ``u d(hip angle)/dt`` [W]), ``n``, ``total_mass_kg``,
    ``gravity`` [m/s^2].

    Raises
    ------
    ValueError
        A walker or phase this transcription has no symbolic form for (massless legs, a
        planar walker's torso, arc feet, free knees; one line).
    """
    import casadi as ca

    st = data.structure
    why = refusal(st)
    if why is not None:
        raise ValueError(why)
    modes = st.kind.phases.behaviour
    order = order if order is not None else phase_order(walker)
    kind = modes(data)
    n = kind.n
    x, u, P = ca.SX.sym("x", 2 * n), ca.SX.sym("u"), ca.SX.sym("P")
    phases = []
    for name, gname, direction in order:
        f = kind.flow(name, x, u)
        g = kind.guard(name, gname, x, f)
        phases.append(ModePhase(
            name, gname, direction, ca.Function(f"flow_{len(phases)}", [x, u], [f]),
            ca.Function(f"guard_{len(phases)}", [x, u], [g]),
            ca.Function(f"rate_{len(phases)}", [x, u], [ca.jacobian(g, x) @ f]),
            ca.Function(f"reset_{len(phases)}", [x], [kind.reset(name, gname, x)]),
            keep=kind.keep(name, x, f, u),
            clearance=ca.Function("clearance", [x], [kind.clearance(name, x)]),
            step=ca.Function("step", [x], [kind.step(name, x)]),
            grf=ca.Function(f"grf_{len(phases)}", [x, u], [kind.grf(name, x, f)]),
            push_off=kind.push_off(gname, x, P, len(phases), name),
            inside=kind.inside(gname)))
    hip = kind.cas([kind.hip], x)
    return {"phases": phases, "n": n,
            "ahead": ca.Function("ahead", [x], [kind.cas([kind.guards["swing_foot_ahead"]],
                                                         x)]),
            "hip_angle": ca.Function("hip_angle", [x], [hip]),
            "power": ca.Function("power", [x, u], [u * (ca.jacobian(hip, x[:n]) @ x[n:])]),
            "total_mass_kg": float(data.total_mass_kg),
            "gravity": float(data.gravity_m_per_s2)}


class _Modes:
    """The symbolic pieces of a walker's phases, in CasADi (subclasses name them)."""

    def __init__(self, data, eq, q, dq, params, leg_angles):
        self.data = data
        self.vals = dict(zip(params, data.params))
        self.xs = list(q) + list(dq)
        self.q, self.n = list(q), len(q)
        sw, st = ("swing_thigh", "stance_thigh") if "swing_thigh" in leg_angles \
            else ("swing", "stance")
        key = "" if sw in leg_angles else "_angle"
        self.hip = leg_angles[sw + key] - leg_angles[st + key]

    def cas(self, exprs, x, extra=(), values=()):
        """The sympy ``exprs`` at the CasADi state ``x`` (and ``extra`` symbols at
        ``values``)."""
        import casadi as ca

        from walkerlab.codegen.casadi_functions import casadi_function

        args = x if not extra else ca.vertcat(x, *values)
        return casadi_function(exprs, self.xs + list(extra), self.vals)(args)

    def accel(self, M, C, G, Mfree, lock, x, u):
        """``qdd`` of ``M qdd = -C dq - G`` plus the hip torque's ``Mfree^-1 B u`` (through
        the lock ``a . qdd = 0`` when ``lock``, a sympy expression, is given)."""
        import casadi as ca
        import sympy as sp

        n = self.n
        qdd = ca.solve(self.cas(M, x), -self.cas(C, x) @ x[n:] - self.cas(G, x))
        Mf = self.cas(Mfree, x)
        acc = ca.solve(Mf, self.cas(sp.Matrix([self.hip]).jacobian(self.q).T, x) * u)
        if lock is not None:  # the torque's share along the lock is taken by it
            a = self.cas(sp.Matrix([lock]).jacobian(self.q).T, x)
            Ma = ca.solve(Mf, a)
            acc = acc - Ma * (a.T @ acc) / (a.T @ Ma)
        return ca.vertcat(x[n:], qdd + acc)

    def impact(self, sys_, x):
        """``Mi dq+ = B dq-`` then ``q_new = relabel_q``, ``dq_new = relabel_rate dq+``."""
        import casadi as ca

        n = self.n
        dq_plus = ca.solve(self.cas(sys_.Mi, x), self.cas(sys_.B, x) @ x[n:])
        R = np.array(sys_.relabel_rate.subs(self.vals), float)
        return ca.vertcat(self.cas(sys_.relabel_q, x), ca.DM(R) @ dq_plus)

    def keep(self, name, x, f, u):
        return None

    def inside(self, gname) -> bool:
        """Whether the guard ``gname``'s sign is kept inside its phase
        (:attr:`ModePhase.inside`): yes."""
        return True

    def push_off(self, gname, x, P, k, name=None):
        """The phase ``name``'s heel strike with a push-off (:class:`ModePhase`
        ``push_off``), or None."""
        return None

    def resultant(self, points, x, f):
        """The ground's resultant on the walker (normal, tangential) [N] from its mass
        points (``points``: sympy positions by name) and the accelerations ``f[n:]``."""
        from types import SimpleNamespace

        from walkerlab.optimal.transcription.step import _ground_reaction

        eq = SimpleNamespace(q=self.q, dq=self.xs[self.n:], points=points,
                             De=getattr(getattr(self, "eq", None), "De", None))
        return _ground_reaction(self.data, eq, self.xs, self.vals, x, f[self.n:])


class _KneedModes(_Modes):
    """A kneed walker (or straight legs: :class:`_StraightModes`): ``unlocked_swing`` /
    ``early_swing`` / ``late_swing`` on the free flow, ``locked_swing`` on the locked one;
    ``knee_strike`` (the plastic knee strike), ``midstance`` (no jump), ``heel_strike``
    (the plain impact, or after a push-off: :meth:`push_off`)."""

    def __init__(self, data):
        eq = derive_equations(data.structure)  # a planar walker's or a 3D one's
        super().__init__(data, eq, eq.q, eq.dq, eq.params, eq.leg_angles)
        self.eq, self.guards = eq, eq.guards

    def flow(self, name, x, u):
        eq = self.eq
        if name == "locked_swing":
            return self.accel(*eq.locked, eq.M, eq.guards["knee_extension"], x, u)
        if name in ("unlocked_swing", "early_swing", "late_swing"):
            return self.accel(eq.M, eq.C, eq.G, eq.M, None, x, u)
        raise ValueError(f"optimize: no symbolic form of the phase {name}")

    def guard(self, name, gname, x, f):
        key = {"knee_strike": "knee_extension", "heel_strike": "heel_strike",
               "midstance": "swing_foot_ahead"}.get(gname)
        if key is None:
            raise ValueError(f"optimize: no symbolic form of the guard {gname}")
        return self.cas([self.eq.guards[key]], x)

    def reset(self, name, gname, x):
        import sympy as sp

        eq, n = self.eq, self.n
        if gname == "knee_strike":  # the shank's angle set to the thigh's, dq+ from Mk, Bk
            Mk, Bk = eq.knee_impact
            tied = eq.section_tied or {}  # the shank's angle: the thigh's (straight knee)
            lock = sp.Matrix([eq.q[tied.get(j, j)] for j in range(n)])
            return self.impact(_Impact(Mk, Bk, lock, sp.eye(n)), x)
        if gname == "heel_strike":
            return self.impact(_Impact(eq.Mi, eq.B, eq.relabel_q, eq.relabel_rate), x)
        return x

    def push_off(self, gname, x, P, k, name=None):
        """The heel strike after a push-off ``P`` [N s] along the trailing leg with the swing
        knee held locked through both impulses (the rigid kneed model's transition,
        :meth:`walkerlab.models.hybrid.push_off.PushOffTransition.hold_lock`): the one-step
        transcription's extended-coordinate map (:mod:`walkerlab.optimal.transcription.
        step`) holding the knee's extension; None at another guard."""
        return self._push_off(gname, x, P, k, self.eq.guards["knee_extension"])

    def _push_off(self, gname, x, P, k, lock):
        """The heel strike's push-off map holding ``lock`` (None: nothing held)."""
        import casadi as ca

        from walkerlab.optimal.transcription.step import _reset_extended

        if gname != "heel_strike":
            return None
        x_plus, work = _reset_extended(self.eq, self.xs, self.vals, x, P,
                                       self.data.total_mass_kg, lock=lock)
        return ca.Function(f"push_off_{k}", [x, P], [x_plus, work])

    def clearance(self, name, x):
        return self.cas([self.eq.guards["swing_clearance"]], x)

    def grf(self, name, x, f):
        return self.resultant(self.eq.points, x, f)

    def step(self, name, x):
        import casadi as ca

        foot = self.cas(self.eq.points["swing_foot"], x)
        return ca.sqrt(foot[0] ** 2 + foot[1] ** 2)


class _StraightModes(_KneedModes):
    """Straight legs (``early_swing``, ``late_swing``): the kneed walker's free flow and
    guards, and a heel strike that may follow a push-off."""

    def inside(self, gname) -> bool:
        """The heel strike's sign is kept inside late swing when the swing foot is level with
        the stance foot as the legs cross (its clearance zero at ``swing = stance``: planar
        legs, a 3D walker of zero hip width), so that late swing starts on the slope.  A 3D
        walker with hip width has its swing foot ``w sin(roll)`` off the slope there (Kuo
        1999): it dips through the slope early in late swing, which the rigid model ignores
        as it ignores the planar legs' mid-stance scuff (its heel strike is the downward
        crossing); the transcription then bounds the clearance instead, as one step's
        (``optimize.min_clearance_m``)."""
        import sympy as sp

        if gname != "heel_strike":
            return True
        sw, st = self.eq.leg_angles["swing"], self.eq.leg_angles["stance"]
        q = next(c for c in self.q if c in sw.free_symbols)  # the swing leg's coordinate
        crossed = {q: sp.solve(sp.Eq(sw, st), q)[0]}
        h = self.eq.guards["swing_clearance"].subs(crossed).subs(self.vals)
        return sp.simplify(h) == 0

    def push_off(self, gname, x, P, k, name=None):
        """Straight legs' heel strike after a push-off ``P`` [N s]: the one-step
        transcription's extended-coordinate map (:mod:`walkerlab.optimal.transcription.step`),
        nothing held."""
        return self._push_off(gname, x, P, k, None)


class _FlatModes(_Modes):
    """Flat feet (:mod:`walkerlab.codegen.foot_modes`): phases ``<mode>:<swing part>`` on the
    mode's flow (foot flat: the locked one, the lock ``phi = stance + ankle + gamma``);
    ``foot_slap`` (plastic), ``midstance`` (no jump), ``heel_off`` (the heel's normal force
    ``N - N_toe`` from the mode's accelerations; no jump), ``heel_strike`` (the mode's own
    map, or after a push-off at the trailing toe: :meth:`push_off`); the stance contacts'
    normal forces kept ``>= 0``."""

    PIN = {"heel_contact": "heel", "foot_flat": "heel", "heel_off": "toe"}

    def __init__(self, data):
        from walkerlab.codegen.foot_modes import derive_flat  # light

        eq = derive_flat(data.structure)
        super().__init__(data, eq, eq.q, eq.dq, eq.params, eq.leg_angles)
        self.eq, self.guards = eq, eq.guards

    def _mode(self, name):
        mode = name.split(":", 1)[0]
        if mode not in self.PIN:
            raise ValueError(f"optimize: no symbolic form of the phase {name}")
        return mode, self.PIN[mode]

    def flow(self, name, x, u):
        mode, pin = self._mode(name)
        fl = self.eq.flows[mode]
        free = self.eq.flows["heel_off" if pin == "toe" else "heel_contact"].M
        lock = self.eq.guards["foot_angle"] if mode == "foot_flat" else None
        return self.accel(fl.M, fl.C, fl.G, free, lock, x, u)

    def forces(self, name, x, f):
        """The stance contacts' normal forces [N] in the phase (heel pinned: ``N, N_toe``;
        toe: ``N``) from the phase's accelerations ``f[n:]``."""
        _mode, pin = self._mode(name)
        return self.cas(self.eq.ground[pin], x, self.eq.qdd, [f[self.n:]])

    def guard(self, name, gname, x, f):
        _mode, pin = self._mode(name)
        if gname == "heel_off":
            N = self.forces(name, x, f)
            return N[0] - N[1]
        key = {"foot_slap": "foot_angle", "midstance": "swing_foot_ahead",
               "heel_strike": f"swing_heel_height_{pin}"}.get(gname)
        if key is None:
            raise ValueError(f"optimize: no symbolic form of the guard {gname}")
        return self.cas([self.eq.guards[key]], x)

    def reset(self, name, gname, x):
        _mode, pin = self._mode(name)
        if gname == "foot_slap":
            return self.impact(self.eq.resets["foot_slap"], x)
        if gname == "heel_strike":
            return self.impact(self.eq.resets[f"heel_strike_{pin}"], x)
        return x

    def push_off(self, gname, x, P, k, name=None):
        """The heel strike of the phase ``name`` after a push-off ``P`` [N s] at the trailing
        toe, from it to the hip, the stance ankle held through it (a massless foot passes
        an impulse off its ankle's line only with an impulsive ankle torque), then the
        heel strike with the trailing foot free and the role swap: the rigid model's
        :class:`walkerlab.models.hybrid.toe_push_off.FlatPushOff` in CasADi, from the
        same symbolic systems (:func:`walkerlab.codegen.foot_modes.derive_flat`'s
        ``push_off[pin]``, the pin the phase's mode's)::

            [De  -a^T] [dqe' - dqe-]   [Jt^T P e]
            [a     0 ] [    lam    ] = [   0    ],      a = d(ankle)/dqe

            Mi dq+ = Be dqe',   x+ = (relabel_q, relabel_rate dq+)

        and the push-off's work ``(dqe'^T De dqe' - dqe-^T De dqe-) / 2`` [J]; None at
        another guard."""
        import casadi as ca

        if gname != "heel_strike":
            return None
        n = self.n
        sysm = self.eq.push_off[self._mode(name)[1]]
        De, Jt, Mi, Be = (self.cas(sysm[key], x) for key in ("De", "Jt", "Mi", "Be"))
        r = self.cas(sysm["push"], x)
        e = r / ca.sqrt(r[0] ** 2 + r[1] ** 2)
        m = De.shape[0]  # the extended coordinates: q and the pinned point's translations
        a = ca.DM.zeros(1, m)
        a[2] = 1.0  # the stance ankle's angle
        K = ca.vertcat(ca.horzcat(De, -a.T), ca.horzcat(a, ca.DM.zeros(1, 1)))
        dqe = ca.vertcat(x[n:], ca.SX.zeros(m - n))
        dqe_po = dqe + ca.solve(K, ca.vertcat(Jt.T @ (P * e), 0))[:m]
        dq_plus = ca.solve(Mi, Be @ dqe_po)
        x_plus = ca.vertcat(self.cas(sysm["relabel_q"], x),
                            self.cas(sysm["relabel_rate"], x) @ dq_plus)
        work = 0.5 * (dqe_po.T @ De @ dqe_po - dqe.T @ De @ dqe)
        return ca.Function(f"push_off_{k}", [x, P], [x_plus, work])

    def keep(self, name, x, f, u):
        import casadi as ca

        mode, _pin = self._mode(name)
        N = self.forces(name, x, f)
        # heel contact / heel off: the pinned point's; foot flat: the toe's (the heel's is
        # the heel-off guard, kept by its sign inside the phase)
        return ca.Function("keep", [x, u], [N[1] if mode == "foot_flat" else N[0]])

    def clearance(self, name, x):
        return self.cas([self.eq.guards[f"swing_heel_height_{self._mode(name)[1]}"]], x)

    def grf(self, name, x, f):
        return self.resultant(self.eq.kinematics[self._mode(name)[1]]["points"], x, f)

    def step(self, name, x):
        import casadi as ca

        foot = self.cas(self.eq.kinematics[self._mode(name)[1]]["points"]["swing_foot"], x)
        return ca.sqrt(foot[0] ** 2 + foot[1] ** 2)


@dataclass(frozen=True)
class _Impact:
    """A plastic impact ``Mi dq+ = B dq-`` and the coordinates after it (sympy)."""

    Mi: object
    B: object
    relabel_q: object
    relabel_rate: object


# each kind's phases part (:attr:`walkerlab.walker.kinds.Kind.phases`) given the symbolic
# pieces of its phases (a five-link biped has its own transcription,
# :mod:`walkerlab.optimal.transcription.free_joints`; a spoked wheel none)
P.PHASES_STRAIGHT_LEGS.provide(_StraightModes)
P.PHASES_LOCKING_KNEES.provide(_KneedModes)
P.PHASES_FLAT_FEET.provide(_FlatModes)
