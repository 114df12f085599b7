"""The independent reference of :func:`walkerlab.codegen.foot_modes.derive_flat` (the flat feet's
modes from the body tree): the same modes written as leg-vector sums (each point
``sum length * e(angle)`` of absolute link angles, so velocities and the mass matrix come out
in ``cos(a - b)`` form), sharing no kinematics with the tree.  Formerly walkerlab's
generator.

Flat feet on ankle springs: the rigid hybrid view's modes, derived with sympy from a
:class:`~walkerlab.walker.description.Structure` (``foot == "flat"``) and written as Python
source (the same ``make(p)`` module form as :mod:`walkerlab.codegen.source`, through its
printers and solvers).

Coordinates ``q = (swing, stance, stance_ankle)``: the absolute leg angles (from the
vertical, positive foot ahead of the hip) and the stance ankle's angle ``a``: the sole's
angle from the stance leg's perpendicular, positive toe up (the ankle spring's deflection
plus its rest angle).  The sole angle from the horizontal is ``theta_f = stance + a``; on a
slope ``gamma`` the foot lies flat when ``phi = stance + a + gamma = 0``.  Feet are massless
(Wisse et al. 2006, "Ankle springs instead of arc-shaped feet for passive dynamic walkers",
IEEE-RAS Humanoids) or, with ``structure.foot_mass``, each a body of mass ``m_foot`` at its
ankle and inertia ``I_foot`` about it; the ankle lies on the sole line, ``heel`` behind and
``toe`` ahead of it.  The swing foot carries no load and sits at its spring's rest angle
``r_sw`` (no coordinate; with mass it turns with its leg, the limit of its stiff, overdamped
ankle: its spring-damper's time constant ``c / k`` is 25 ms on configs/flat_feet.yaml, its
inertial torque ``I_foot`` times the leg's angular acceleration ~5e-3 N m).

A *mode* is a pinned contact point plus locked coordinates; each is derived from the same
bodies with Lagrange's equations ``M qdd + C dq + G = 0`` (``C`` in Christoffel form plus
the ankle damper, ``G`` from gravity and the ankle spring ``k (a - r)^2 / 2``):

- ``heel_contact``: the stance heel pinned at the step's reference point ``O`` (the heel's
  touchdown point); the foot turns about it (``phi > 0``, toe up);
- ``foot_flat``: heel pinned and the foot's angle locked (``J = d phi / dq = [0, 1, 1]``,
  ``S`` a basis of its null space): ``[S^T M; J] qdd = [S^T (-C dq - G); 0]``;
- ``heel_off``: the stance toe pinned at ``O + (heel + toe) t`` (``t`` the downhill slope
  direction); the foot turns about it (``phi < 0``, heel up).

The kinematics of a state follow from the sign of ``phi`` (both maps give the same positions at
``phi = 0``), so ``points`` and ``energies`` need no mode (see :data:`HEEL_OFF_PHI_RAD`).

Resets (plastic impulses; the impulse acts only where a contact is made):

- foot slap (``phi`` reaches 0 in heel contact): ``[S^T M; J] dq+ = [S^T M; 0] dq-`` (the toe
  impulse's generalised force lies along ``J^T``: the knee lock's projection);
- heel strike (the swing heel reaches the slope, in any stance mode): the post-impact
  velocities project the pre-impact momenta onto the coordinates with the swing heel pinned
  and the new stance ankle at the swing foot's rest angle, ``Mi dq+ = sum_i J_i+^T m_i v_i-``
  (``Mi = sum_i J_i+^T m_i J_i+`` plus rotational terms; feet with mass among the bodies,
  the trailing sole's angular momentum projected on its leg's turn), then the leg roles
  swap; the trailing foot is released (it snaps to its rest angle) unless the double
  support keeps its toe down (below).

Double support (after heel strike, roles swapped;
:func:`walkerlab.codegen.foot_modes.derive_double_support`): the leading foot
on its heel (or flat), the trailing foot on its toe, pinned (no slip); its ankle angle ``b``
follows from the toe on the slope, the flow is Lagrange's equations on ``(q, b)`` with the
toe's constraint and its force as multipliers (a numeric KKT solve in the generated code);
the entry impact pins the toe (an impulse through the trailing ankle: the massless foot takes
no impulsive moment), the second stage of the two-contact plastic impact.

Ground reaction (for the heel-off and lift-off guards): the total force from Newton,
``F = sum m_i (a_i - g)`` over the bodies (feet with mass among them), normal part ``N = F . n``;
in foot flat the toe's share from the moment balance about the heel,
``N_toe (heel + toe) = sum (r_i x m_i (a_i - g)) + I_i alpha_i`` (friction along the slope
has no moment about the heel), and the heel's ``N - N_toe``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import sympy as sp

from tests.independent.link_sums import add_length, dot_terms, position_of, velocity_terms
from walkerlab.codegen.foot_modes import (  # the containers, and the double support
    FlatEquations,
    _System,
    derive_double_support,
)
from walkerlab.codegen.frames import planar_slope_axes
from walkerlab.codegen.lagrange import christoffel
from walkerlab.walker.description import ROLE_TAG, Structure

#: Index of the stance ankle's angle in ``q``.
ANKLE = 2
#: ``points``/``energies`` read a state as heel off (toe pinned) once ``phi`` is below minus
#: this [rad].  Both kinematics give the same positions at ``phi = 0`` but not the same
#: velocities while the foot turns: at the foot slap (``phi = 0`` to round-off, the foot
#: turning at ~20 rad/s) the state is still heel contact; just after heel off (``phi`` ~
#: ``-phi_dd t^2 / 2``) the foot's rate is ``sqrt(2 |phi_dd| |phi|)`` < 2e-5 rad/s at this
#: threshold (``|phi_dd|`` < 100 rad/s^2), so the kinetic energy read there is off by < 1e-4 J
#: for a microsecond.
HEEL_OFF_PHI_RAD = 1e-12


@dataclass(frozen=True)
class _Walker:
    """The symbols and numbers every section of :func:`derive_flat` reads: ``q``, ``dq``,
    ``qdd``, the parameters (``P`` by name) and the bodies of a pinned ankle
    (:meth:`bodies_from`)."""

    structure: Structure
    q: tuple
    dq: tuple
    qdd: tuple
    par: tuple
    P: dict

    def fp(self, kind: str, role: str):
        """A foot's number (per role when the legs differ)."""
        t = f"{ROLE_TAG[role]}_" if self.structure.asymmetric else ""
        return self.P[{"heel": f"heel_{t}m", "toe": f"toe_{t}m", "k": f"k_{t}ankle",
                       "r": f"r_{t}ankle", "c": f"c_{t}ankle"}[kind]]

    def bp(self, kind: str, name: str, role: str):
        """A leg body's number (per role when the legs differ)."""
        return self.P[f"{kind}_{ROLE_TAG[role]}_{name}" if self.structure.asymmetric
                      else f"{kind}_{name}"]

    def bodies_from(self, ankle_lin: dict, pinned: str = "stance", foot_angle=None):
        """(mass, lin, inertia, link angle, name) of every body, the hip's lin and the
        other leg's ankle's lin, for the ``pinned`` leg's ankle at ``ankle_lin``; names
        and numbers by the pre-impact roles (``pinned="swing"``: after a heel strike).

        Feet with mass (``structure.foot_mass``): each foot a body ``<role>_foot_body`` at
        its ankle, mass ``m_foot``, inertia ``I_foot`` about it; the pinned leg's foot at
        the sole angle ``foot_angle`` (default the stance sole's ``stance + a``), the other
        leg's foot at its spring's rest angle from that leg (its angle no coordinate)."""
        structure, P, bp = self.structure, self.P, self.bp
        ps_sw, ps_st, _a = self.q
        L, half = P["L"], sp.pi / 2
        other = {"stance": "swing", "swing": "stance"}[pinned]
        leg_psi = {"stance": ps_st, "swing": ps_sw}
        hip = add_length(ankle_lin, leg_psi[pinned], -L)
        out = []
        if structure.hip_mass:
            out.append((P["M_hip"], hip, 0, leg_psi[pinned], "hip"))
        for b in structure.bodies:
            for role in (pinned, other):
                psi = leg_psi[role]
                lin = add_length(hip, psi, bp("d", b.name, role))
                if b.off_axis:
                    lin = add_length(lin, psi + half, bp("e", b.name, role))
                inertia = bp("I", b.name, role) if b.kind == "rod" else 0
                out.append((bp("m", b.name, role), lin, inertia, psi, f"{role}_{b.name}"))
        psi_t = (ps_sw + ps_st) / 2
        for b in structure.torso:
            lin = add_length(hip, psi_t, -P[f"d_torso_{b.name}"])
            if b.off_axis:
                lin = add_length(lin, psi_t + half, P[f"e_torso_{b.name}"])
            inertia = P[f"I_torso_{b.name}"] if b.kind == "rigid_body" else 0
            out.append((P[f"m_torso_{b.name}"], lin, inertia, psi_t, f"torso_{b.name}"))
        other_ankle = add_length(hip, leg_psi[other], L)
        if structure.foot_mass:
            if foot_angle is None:
                foot_angle = ps_st + _a
            out.append((P["m_foot"], ankle_lin, P["I_foot"], foot_angle, f"{pinned}_foot_body"))
            out.append((P["m_foot"], other_ankle, P["I_foot"],
                        leg_psi[other] + self.fp("r", other), f"{other}_foot_body"))
        return out, hip, other_ankle


@cache
def derive_flat(structure: Structure) -> FlatEquations:
    """Derive the modes, resets, guards, ground reactions and points of a flat-footed biped:
    the pinned modes (:func:`_pinned_modes`), foot flat and the resets
    (:func:`_locked_and_resets`), the push-off systems
    (:func:`walkerlab.codegen.push_off.push_off_systems`) and the
    double support (:func:`walkerlab.codegen.foot_modes.derive_double_support`).

    Returns
    -------
    FlatEquations

    Raises
    ------
    ValueError
        Not a flat-footed straight-legged walker in absolute coordinates, or massless bodies.
    """
    if structure.foot != "flat" or structure.knee or structure.coordinates != "absolute":
        raise ValueError("walker.leg.foot: the flat-foot derivation needs straight legs, "
                         "flat feet and absolute coordinates")
    if any(b.massless for b in structure.bodies):
        raise ValueError("walker.leg.bodies: flat feet need massive bodies (mass_kg > 0)")
    q = sp.symbols("q_swing q_stance q_stance_ankle", real=True)
    dq = sp.symbols("dq_swing dq_stance dq_stance_ankle", real=True)
    qdd = sp.symbols("ddq_swing ddq_stance ddq_stance_ankle", real=True)
    par = sp.symbols(structure.param_names, real=True)
    P = dict(zip(structure.param_names, par))
    w = _Walker(structure, q, dq, qdd, par, P)
    gamma = P["gamma"]
    ps_sw, ps_st, a = q
    fp = w.fp
    hs, ts = fp("heel", "stance"), fp("toe", "stance")
    rw = fp("r", "swing")
    half = sp.pi / 2
    normal, tangent = planar_slope_axes(gamma)
    theta_f = ps_st + a
    # positions = sum of {angle: length} e(angle) + a constant offset (e(angle + pi/2) is
    # the unit vector at ``angle`` from the x axis)
    anchors = {"heel": ({theta_f + half: hs}, sp.zeros(2, 1)),
               "toe": ({theta_f + half: -ts}, (hs + ts) * tangent)}
    flows, kin, ground, guards, lead_force, trailing_ankle = _pinned_modes(
        w, anchors, normal)
    guards["swing_foot_ahead"] = ps_sw - ps_st
    guards["foot_angle"] = ps_st + a + gamma
    Jl = sp.Matrix([[0, 1, 1]])
    resets, post_q, post = _locked_and_resets(w, anchors, flows, Jl)
    push_off = push_off_systems(q, anchors, w.bodies_from, kin, flows, resets, post_q, post)
    leg_angles = {"swing_angle": ps_sw, "stance_angle": ps_st, "stance_ankle_angle": a,
                  "swing_ankle_angle": rw + 0 * ps_sw,
                  "swing_rate": dq[0], "stance_rate": dq[1], "stance_ankle_rate": dq[2],
                  "swing_ankle_rate": 0 * dq[0]}
    double = derive_double_support(q, dq, qdd, flows, trailing_ankle, lead_force["heel"],
                                   (fp("toe", "swing"), fp("k", "swing"), fp("r", "swing"),
                                    fp("c", "swing")), hs + ts, gamma, normal, tangent, Jl,
                                   P["I_foot"] if structure.foot_mass else 0)
    return FlatEquations(q=q, dq=dq, qdd=qdd, params=tuple(par), flows=flows, resets=resets,
                         guards=guards, ground=ground, kinematics=kin, leg_angles=leg_angles,
                         push_off=push_off, double_support=double)


def _pinned_modes(w: _Walker, anchors: dict, normal):
    """Per pinned point (``heel``, ``toe``): the flow ``heel_contact`` / ``heel_off``
    (:func:`_pinned_dynamics`), the kinematics (points, energies), the ground reaction
    (Newton's total and, heel pinned, the toe's share from the moment balance about the
    heel: module docstring) and the guards on the swing heel's and the hip's heights.

    Returns
    -------
    flows, kinematics, ground, guards : dict
    lead_force : dict
        Per pin, Newton's total force and moment ``(F, mom)``.
    trailing_ankle : Matrix (2, 1)
        The swing ankle's position, heel pinned.
    """
    q, fp = w.q, w.fp
    ps_sw, ps_st, a = q
    half = sp.pi / 2
    hs, ts = fp("heel", "stance"), fp("toe", "stance")
    hw, tw, rw = fp("heel", "swing"), fp("toe", "swing"), fp("r", "swing")
    theta_f = ps_st + a
    dqv = sp.Matrix(w.dq)
    link_angle = {"swing": ps_sw, "stance": ps_st, "torso": (ps_sw + ps_st) / 2}
    flows, kin, ground, guards = {}, {}, {}, {}
    lead_force = {}
    for pin, (ankle_lin, off) in anchors.items():
        bodies, hip, sw_ankle = w.bodies_from(ankle_lin)
        if pin == "heel":
            trailing_ankle = position_of(sw_ankle)

        def at(lin, _off=off):
            return position_of(lin) + _off
        M, C, G, V, F, mom = _pinned_dynamics(w, bodies, at, link_angle)
        mode = "heel_contact" if pin == "heel" else "heel_off"
        flows[mode] = _System(q, w.dq, M=M, C=C, G=G)
        N = (F.T * normal)[0]
        lead_force[pin] = (F, mom)
        # moment balance about the pinned heel: the toe's normal force (see module docstring)
        ground[pin] = [N, mom / (hs + ts)] if pin == "heel" else [N]
        heel_sw = at(add_length(sw_ankle, ps_sw + rw + half, -hw))
        toe_sw = at(add_length(sw_ankle, ps_sw + rw + half, tw))
        points = {"stance_heel": at(add_length(ankle_lin, theta_f + half, -hs)),
                  "stance_toe": at(add_length(ankle_lin, theta_f + half, ts)),
                  "stance_ankle": at(ankle_lin), "hip": at(hip),
                  "swing_ankle": at(sw_ankle), "swing_heel": heel_sw, "swing_toe": toe_sw}
        # the contract's names: the stance foot is the stance leg's end, the swing foot the
        # next step's reference point (the swing heel)
        points["stance_foot"] = points["stance_ankle"]
        points["swing_foot"] = heel_sw
        for _m, lin, _i, _p, name in bodies:
            if name != "hip" and not name.endswith("_foot_body"):  # feet: at the ankles
                points[name] = at(lin)
        T = sp.Rational(1, 2) * (dqv.T * M * dqv)[0]
        kin[pin] = {"points": points, "kinetic": T, "potential": V}
        guards[f"swing_heel_height_{pin}"] = (heel_sw.T * normal)[0]
        guards[f"hip_height_{pin}"] = (at(hip).T * normal)[0]
    return flows, kin, ground, guards, lead_force, trailing_ankle


def _pinned_dynamics(w: _Walker, bodies: list, at, link_angle: dict):
    """Lagrange's equations of one pinned mode: ``M``, ``C`` (Christoffel form plus the
    ankle's and the springs' dampers), ``G`` and the potential ``V`` (gravity, the ankle
    spring, the springs between links), and Newton's total force ``F`` and moment ``mom``
    about the origin of the bodies (positions ``at(lin)``)."""
    q, dq, P, structure = w.q, w.dq, w.P, w.structure
    _ps_sw, _ps_st, a = q
    g = P["g"]
    k_a, r_a, c_a = w.fp("k", "stance"), w.fp("r", "stance"), w.fp("c", "stance")
    qv, dqv, ddv = sp.Matrix(q), sp.Matrix(dq), sp.Matrix(w.qdd)
    M = sp.zeros(3, 3)
    V = k_a * (a - r_a) ** 2 / 2
    F = sp.zeros(2, 1)
    mom = sp.Integer(0)
    for mass, lin, inertia, psi, _name in bodies:
        d = velocity_terms(lin, q)
        wr = sp.Matrix([[sp.diff(psi, s) for s in q]])
        for i in range(3):
            for j in range(3):
                M[i, j] += mass * dot_terms(d[i], d[j])
        M += inertia * wr.T * wr
        pos = at(lin)
        V += mass * g * pos[1]
        vel = pos.jacobian(qv) * dqv
        acc = vel.jacobian(qv) * dqv + vel.jacobian(dqv) * ddv
        f = mass * (acc + sp.Matrix([0, g]))
        F += f
        mom += pos[0] * f[1] - pos[1] * f[0] + inertia * (wr * ddv)[0]
    for i, (first, second) in enumerate(structure.springs):  # springs between links
        delta = link_angle[second] - link_angle[first]
        V += P[f"k_s{i}"] * (delta - P[f"r_s{i}"]) ** 2 / 2
    M = M.applyfunc(sp.factor_terms)
    G = sp.Matrix([sp.diff(V, s) for s in q])
    C = christoffel(M, q, dq)
    C[ANKLE, ANKLE] += c_a  # the ankle damper: torque -c da/dt on the ankle coordinate
    for i, (first, second) in enumerate(structure.springs):
        delta = link_angle[second] - link_angle[first]
        Jd = sp.Matrix([[sp.diff(delta, s) for s in q]])
        C += P[f"c_s{i}"] * Jd.T * Jd
    return M, C, G, V, F, mom


def _locked_and_resets(w: _Walker, anchors: dict, flows: dict, Jl):
    """Add the ``foot_flat`` flow (the heel-contact flow with the foot's angle locked,
    ``Jl = d phi / dq``) to ``flows``; return the resets (``foot_slap``, ``heel_strike_heel``,
    ``heel_strike_toe``), the post-impact coordinates and the post-impact bodies by name.

    Heel strike: post-impact coordinates ``(swing, stance, b)`` with the swing heel pinned
    and the swing foot at angle ``swing + b`` (``b`` its rest angle at impact), in the
    pre-impact labelling; then the roles swap (new swing = old stance, new stance = old
    swing)."""
    q, dq = w.q, w.dq
    ps_sw, ps_st, _a = q
    half = sp.pi / 2
    hw, rw = w.fp("heel", "swing"), w.fp("r", "swing")
    b_new = sp.Symbol("b_new_ankle", real=True)  # the swing ankle, once it is the stance one
    qv = sp.Matrix(q)
    S = sp.Matrix([[1, 0], [0, 1], [0, -1]])
    hc = flows["heel_contact"]
    flows["foot_flat"] = _System(q, dq, M=(S.T * hc.M).col_join(Jl),
                                 C=(S.T * hc.C).col_join(sp.zeros(1, 3)),
                                 G=(S.T * hc.G).col_join(sp.zeros(1, 1)))
    resets = {"foot_slap": _System(q, dq, Mi=(S.T * hc.M).col_join(Jl),
                                   B=(S.T * hc.M).col_join(sp.zeros(1, 3)),
                                   relabel_q=qv, relabel_rate=sp.eye(3))}
    post_q = (ps_sw, ps_st, b_new)
    post_bodies, _h, _a = w.bodies_from({ps_sw + b_new + half: hw}, "swing", ps_sw + b_new)
    post = {b[4]: b for b in post_bodies}
    relabel_q = sp.Matrix([ps_st, ps_sw, rw])
    relabel_rate = sp.Matrix([[0, 1, 0], [1, 0, 0], [0, 0, 1]])
    for pin, (ankle_lin, _off) in anchors.items():
        pre_bodies, _h, _a = w.bodies_from(ankle_lin)
        Mi, Bm = sp.zeros(3, 3), sp.zeros(3, 3)
        for mass, lin, inertia, psi, name in pre_bodies:
            pmass, plin, pinertia, ppsi, _n = post[name]
            dn, dl = velocity_terms(plin, post_q), velocity_terms(lin, q)
            wn = sp.Matrix([[sp.diff(ppsi, s) for s in post_q]])
            wl = sp.Matrix([[sp.diff(psi, s) for s in q]])
            for i in range(3):
                for j in range(3):
                    Mi[i, j] += mass * dot_terms(dn[i], dn[j])
                    Bm[i, j] += mass * dot_terms(dn[i], dl[j])
            Mi += inertia * wn.T * wn
            Bm += inertia * wn.T * wl
        Mi, Bm = (X.subs(b_new, rw).applyfunc(sp.factor_terms) for X in (Mi, Bm))
        resets[f"heel_strike_{pin}"] = _System(q, dq, Mi=Mi, B=Bm, relabel_q=relabel_q,
                                               relabel_rate=relabel_rate)
    return resets, post_q, post


def _translation_rows(lin: dict, qs) -> sp.Matrix:
    """``d position / d q`` (len(qs), 2) of a ``{angle: length}`` leg-vector sum, row ``i``
    the position's rate for ``dq = e_i`` (``e'(a) = (cos a, sin a)``)."""
    rows = [[sum((c * sp.cos(a) for a, c in t), sp.Integer(0)),
             sum((c * sp.sin(a) for a, c in t), sp.Integer(0))]
            for t in velocity_terms(lin, qs)]
    return sp.Matrix(rows)


def push_off_systems(q, anchors, bodies_from, kin, flows, resets, post_q, post) -> dict:
    """The extended impact system of each pinned point (``heel``, ``toe``): the push-off at
    the stance toe and the heel strike after it.

    Extended coordinates ``qe = (q, x_f, y_f)``: the walker translated by ``(x_f, y_f)``
    with its pinned point.  Per pin: ``De`` (5, 5), the Hessian of the kinetic energy in
    ``dqe`` (``[M, Mt; Mt^T, m I]``, ``Mt = sum m dr/dq``; singular along the massless
    foot's turn about the ankle, which the push-off holds); ``Jt`` (2, 5), the stance toe's
    Jacobian; ``Jh`` (2, 3), the hip's (its speed for a push-off law); ``Mi`` (3, 3) and
    ``Be`` (3, 5), the heel strike's ``Mi dq+ = Be dqe-`` (momenta of the pre-impact
    velocities, the trailing foot free and moving, projected on the post-impact coordinates
    with the swing heel pinned: ``Be = [B | sum J+^T m]``, ``B`` the passive heel strike's,
    so ``Be [dq; 0] = B dq`` to round-off); ``push`` (2,) the vector toe -> hip;
    ``relabel_q`` (3,) and ``relabel_rate`` (3, 3) the role swap."""
    qv = sp.Matrix(q)
    out = {}
    mode = {"heel": "heel_contact", "toe": "heel_off"}
    for pin, (ankle_lin, _off) in anchors.items():
        pre_bodies, _h, _a = bodies_from(ankle_lin)
        Mt, trans, mass = sp.zeros(3, 2), sp.zeros(3, 2), sp.Integer(0)
        for m_, lin, _i, _psi, name in pre_bodies:
            mass += m_
            Mt += m_ * _translation_rows(lin, q)
            trans += m_ * _translation_rows(post[name][1], post_q)
        hs = resets[f"heel_strike_{pin}"]
        b_new = post_q[2]
        trans = trans.subs(b_new, hs.relabel_q[2]).applyfunc(sp.factor_terms)
        De = flows[mode[pin]].M.row_join(Mt).col_join(Mt.T.row_join(mass * sp.eye(2)))
        pts = kin[pin]["points"]
        toe = pts["stance_toe"]
        out[pin] = {"De": De, "Jt": toe.jacobian(qv).row_join(sp.eye(2)),
                    "Jh": pts["hip"].jacobian(qv), "Mi": hs.Mi, "Be": hs.B.row_join(trans),
                    "push": pts["hip"] - toe, "relabel_q": hs.relabel_q,
                    "relabel_rate": hs.relabel_rate}
    return out
