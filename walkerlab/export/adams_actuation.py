"""The actuation of the Adams Solver dataset (:mod:`walkerlab.export.adams`): joint torques
(``SFORCE``), the push-off pulse (``GFORCE``) and the ankle push-off, every expression a
``VARIABLE`` of Adams runtime functions (the roles by the feet's normal contact forces;
see :mod:`walkerlab.export.adams`'s "Actuation")."""

from __future__ import annotations

import math

import numpy as np

from walkerlab.config import Scene
from walkerlab.config.contact import ContactSettings
from walkerlab.export.adams_feet import FOOT_FORCES, adams_feet, contact_pairs, hip_link, leg_end
from walkerlab.export.adams_statements import MM, _chain_sum, _f, _plus, _var, marker_id
from walkerlab.walker.capability_cells import FREE_JOINT_TORQUES
from walkerlab.walker.kinds import KINDS

__all__ = ["ACT_BLOCK", "ACT_VARIABLES", "ANKLE_SFORCE", "ANKLE_TORQUE_SFORCE",
           "ANKLE_VARIABLES", "HIP_SFORCE", "HIP_TORQUE_SUM", "JOINT_SFORCE",
           "TORSO_HIP_VARIABLES", "TORSO_SHARE", "hip_laws",
           "PUSH_FLOAT_MARKER", "PUSH_GFORCE", "PUSH_MIN_STEP_M", "actuation_statements",
           "check_adams_actuation", "hip_torque_ids", "table_terms"]

#: VARIABLE ids of the actuation's shared quantities: each foot's normal contact force, the
#: role sign, the hip angle and rate, the phase variable and its rate, constants (sin and
#: cos of the slope, the pulse's duration, the impulse), each foot's penetration, its rate
#: and its extrapolation, the swing foot's lead along the slope.
ACT_VARIABLES = {"force_leg1": 301, "force_leg2": 302, "sign": 303, "delta": 304,
                 "ddelta": 305, "phase": 306, "dphase": 307, "sin": 330, "cos": 331,
                 "pulse_s": 332, "impulse": 333, "pen_leg1": 341, "pen_leg2": 342,
                 "rate_leg1": 343, "rate_leg2": 344, "lead_leg1": 345, "lead_leg2": 346,
                 "ahead": 347, "push_leg1": 361, "push_leg2": 362}
#: First VARIABLE id of actuator ``k``'s block: ``ACT_BLOCK (k + 1)`` (its reference table,
#: error, torque: :func:`hip_torque_ids`).
ACT_BLOCK = 1000
#: VARIABLE of the hip torques' sum [N mm] (the swing leg's torque).
HIP_TORQUE_SUM = 9099
#: SFORCE id of the hip torques (action-reaction between leg1 and leg2 at the hip).
HIP_SFORCE = 10
#: GFORCE ids of the push-off pulse at leg1's and leg2's foot (while that leg stands).
PUSH_GFORCE = {"leg1": 1, "leg2": 2}
#: The floating ground marker that takes the push-off's reaction.
PUSH_FLOAT_MARKER = 104
#: A touchdown starts a push-off pulse only this far [m] ahead of the stance foot
#: (:attr:`walkerlab.models.contact.actuation.ContactActuators.min_step_m`).
PUSH_MIN_STEP_M = 0.05


def hip_torque_ids(k: int) -> dict[str, int]:
    """VARIABLE ids of hip actuator ``k``: ``error``, ``rate_error`` (of delta and its rate
    from the reference [rad, rad/s]), ``tau`` (the law's torque, saturated where it has a
    limit [N mm]) and, with a phase reference, ``h`` / ``dh`` (the reference [rad] and its
    rate [rad/s])."""
    base = ACT_BLOCK * (k + 1)
    return {"error": base + 100, "rate_error": base + 101, "tau": base + 109,
            "h": base + 98, "dh": base + 99}


def check_adams_actuation(scene: Scene) -> None:
    """Refuse the actuation the dataset cannot carry (one line).

    Raises
    ------
    ValueError
        A torque at a five-link joint (those walkers are refused anyway); a
        ``time_reference`` (the time since heel strike is a state latched at touchdown,
        which needs a SENSOR's stored value or a user subroutine: not written); a push-off with
        ``contact.push_off_duration_s: 0`` (an impulse has no Adams force form).
    """
    act = scene.walker.actuation
    if act is None:
        return
    for i, t in enumerate(act.torques):
        if t.law.time_reference is not None:
            raise ValueError(f"walker.actuation.torques.{i}.law.time_reference: the time "
                             "since heel strike is a state latched at touchdown that the "
                             "dataset does not write (use a phase reference, or --format "
                             "mjcf)")
    pulse_s = (scene.contact or ContactSettings()).push_off_pulse_s()
    if act.push_off is not None and pulse_s <= 0:
        raise ValueError("contact.push_off_duration_s: 0 is an impulse, which has no force "
                         "form in ADAMS: give the pulse a duration (default 0.0001 s)")



def table_terms(table) -> tuple[float, float, tuple, list]:
    """A reference table as the dataset writes it: ``h(u) = p0(u - s0) + sum_k d_k (u -
    s_k)_+^m`` on the abscissa clamped to the table, ``u = min(max(s, s0), sn)``: the
    truncated-power form of the piecewise polynomial
    :func:`walkerlab.models.actuation.phase_reference` evaluates (the not-a-knot
    :class:`scipy.interpolate.CubicSpline`'s jumps of its cubic coefficient, ``m = 3``; a
    piecewise-linear table's slope jumps, ``m = 1``).

    Returns
    -------
    s0, sn : float
        The table's ends [rad].
    poly : tuple of float
        ``p0``'s coefficients, highest degree first (4 for cubic, 2 for linear).
    jumps : list of (float, float, int)
        Inner knots ``s_k`` [rad], the jumps ``d_k`` and the power ``m``.
    """
    s, y = np.asarray(table.phase_rad, float), np.asarray(table.values_rad, float)
    if table.interpolation == "cubic" and len(s) >= 3:
        from scipy.interpolate import CubicSpline

        c = CubicSpline(s, y, bc_type="not-a-knot").c  # as phase_reference builds it
        jumps = [(float(s[k]), float(c[0, k] - c[0, k - 1]), 3) for k in range(1, len(s) - 1)]
        return float(s[0]), float(s[-1]), tuple(float(x) for x in c[:, 0]), jumps
    slope = np.diff(y) / np.diff(s)
    jumps = [(float(s[k]), float(slope[k] - slope[k - 1]), 1) for k in range(1, len(s) - 1)]
    return float(s[0]), float(s[-1]), (float(slope[0]), float(y[0])), jumps


def _reference(k: int, table, phase: str, dphase: str) -> list[str]:
    """VARIABLEs of actuator ``k``'s reference ``h(s)`` and its rate ``h'(s) ds`` (held at
    the end values outside the table, rate 0 there; :func:`table_terms`)."""
    base, ids = ACT_BLOCK * (k + 1), hip_torque_ids(k)
    s0, sn, poly, jumps = table_terms(table)
    u, x = base + 1, base + 2
    X = f"VARVAL({x})"
    out = [_var(u, f"MIN(MAX({phase},{_f(s0)}),{_f(sn)})"), _var(x, f"VARVAL({u})-({_f(s0)})")]
    if len(poly) == 4:  # Horner, a constant a line: p0 and its slope
        a3, a2, a1, a0 = poly
        out += [_var(base + 3, _f(a3)), _var(base + 4, f"VARVAL({base + 3})*{X}{_plus(a2)}"),
                _var(base + 5, f"VARVAL({base + 4})*{X}{_plus(a1)}"),
                _var(base + 6, f"VARVAL({base + 5})*{X}{_plus(a0)}"),
                _var(base + 7, _f(3 * a3)),
                _var(base + 8, f"VARVAL({base + 7})*{X}{_plus(2 * a2)}"),
                _var(base + 9, f"VARVAL({base + 8})*{X}{_plus(a1)}")]
    else:
        a1, a0 = poly
        out += [_var(base + 6, f"{_f(a1)}*{X}{_plus(a0)}"), _var(base + 9, _f(a1))]
    h, dh, vid = base + 6, base + 9, base + 200  # four ids a knot, up to 199 knots
    for sk, d, m in jumps:
        out.append(_var(vid, f"MAX(0.0,VARVAL({u})-({_f(sk)}))"))
        if m == 3:
            out += [_var(vid + 1, f"VARVAL({h}){_plus(d)}*VARVAL({vid})**3"),
                    _var(vid + 2, f"VARVAL({dh}){_plus(3 * d)}*VARVAL({vid})**2")]
        else:  # the slope's jump where u passes s_k
            out += [_var(vid + 1, f"VARVAL({h}){_plus(d)}*VARVAL({vid})"),
                    _var(vid + 3, f"IF(VARVAL({vid}):0,0,1)"),
                    _var(vid + 2, f"VARVAL({dh}){_plus(d)}*VARVAL({vid + 3})")]
        h, dh, vid = vid + 1, vid + 2, vid + 4
    inside = base + 97  # the rate inside the table only (held values outside: slope 0)
    out += [_var(inside, f"IF({phase}-({_f(s0)}):0,0,IF({phase}-({_f(sn)}):1,0,0))"),
            _var(ids["h"], f"VARVAL({h})"),
            _var(ids["dh"], f"VARVAL({dh})*{dphase}*VARVAL({inside})")]
    return out


def _law(k: int, t, delta: int, ddelta: int) -> list[str]:
    """Actuator ``k``'s law (:class:`walkerlab.config.actuation.JointTorque` ``t``) as
    VARIABLEs on its joint's angle and rate (VARIABLEs ``delta``, ``ddelta``) and the phase
    variable (:data:`ACT_VARIABLES` ``phase``, ``dphase``); its torque [N mm] in
    ``hip_torque_ids(k)["tau"]``."""
    V = ACT_VARIABLES
    law, ids = t.law, hip_torque_ids(k)
    base = ACT_BLOCK * (k + 1)
    out = []
    if law.reference is not None:
        out.append(f"! actuator {k} ({t.joint}): -K (delta - h(s)) - D (ddelta - h'(s) ds)")
        out += _reference(k, law.reference, f"VARVAL({V['phase']})", f"VARVAL({V['dphase']})")
        err = f"VARVAL({delta})-VARVAL({ids['h']})"
        derr = f"VARVAL({ddelta})-VARVAL({ids['dh']})"
    else:
        out.append(f"! actuator {k} ({t.joint}): constant - K (delta - rest) - D ddelta")
        err = f"VARVAL({delta}){_plus(-law.rest_angle_rad)}"
        derr = f"VARVAL({ddelta})"
    out += [_var(ids["error"], err), _var(ids["rate_error"], derr),
            _var(base + 102, _f(law.constant_n_m * MM)),
            _var(base + 103, f"{_f(law.stiffness_n_m_per_rad * MM)}*VARVAL({ids['error']})"),
            _var(base + 104, f"{_f(law.damping_n_m_s_per_rad * MM)}*VARVAL({ids['rate_error']})")]
    raw = f"VARVAL({base + 102})-VARVAL({base + 103})-VARVAL({base + 104})"
    if t.max_torque_n_m is None:
        return out + [_var(ids["tau"], raw)]
    # saturation |tau| <= max_torque_n_m
    return out + [_var(base + 105, raw), _var(base + 106, _f(t.max_torque_n_m * MM)),
                  _var(ids["tau"], f"MIN(MAX(VARVAL({base + 105}),-VARVAL({base + 106})),"
                       f"VARVAL({base + 106}))")]


#: the share of a torque ``tau`` between an upper body on the bisecting hip and a leg
#: (``joint: stance_hip`` / ``swing_hip``, the angle leg minus upper body) that acts as the
#: hip torque, and of the hip angle ``delta = swing - stance`` that is its angle: the upper
#: body's pitch is the legs' mean (Wisse, Hobbelen & Schwab 2007), so ``stance - torso =
#: -delta / 2`` and ``swing - torso = delta / 2``, and the virtual work ``tau d(alpha)`` is
#: the hip torque's ``(-+ tau / 2) d(delta)`` (the rigid model's flows equal:
#: tests/test_torso_3d.py)
TORSO_SHARE = {"stance_hip": -0.5, "swing_hip": 0.5}
#: VARIABLE ids (angle [rad], rate [rad/s]) of the upper body's joints as shares of the hip's
TORSO_HIP_VARIABLES = {"stance_hip": (625, 626), "swing_hip": (627, 628)}


def hip_laws(act, ks: list) -> tuple[list[str], list[str]]:
    """The laws of actuators ``ks`` on the hip angle (VARIABLEs ``delta``, ``ddelta`` of
    :data:`ACT_VARIABLES`, written before): ``joint: hip`` on it, an upper body's
    ``stance_hip`` / ``swing_hip`` on its share of it (:data:`TORSO_SHARE`).

    Returns
    -------
    statements : list of str
    terms : list of str
        The hip torque's terms [N mm]: each law's torque, an upper body's times its share.
    """
    V = ACT_VARIABLES
    out, terms = [], []
    torso = sorted({act.torques[k].joint for k in ks} - {"hip"})
    if torso:
        out += ["! a torque between the upper body and a leg (alpha = leg - upper body) as",
                "! its hip torque: on the bisecting hip alpha = -+ delta / 2 (stance, swing),",
                "! the hip torque -+ tau / 2 (the same virtual work)"]
    for j in torso:
        a, r = TORSO_HIP_VARIABLES[j]
        out += [_var(a, f"{_f(TORSO_SHARE[j])}*VARVAL({V['delta']})"),
                _var(r, f"{_f(TORSO_SHARE[j])}*VARVAL({V['ddelta']})")]
    for k in ks:
        j, tau = act.torques[k].joint, f"VARVAL({hip_torque_ids(k)['tau']})"
        if j == "hip":
            out += _law(k, act.torques[k], V["delta"], V["ddelta"])
            terms.append(tau)
        else:
            out += _law(k, act.torques[k], *TORSO_HIP_VARIABLES[j])
            terms.append(f"({_f(TORSO_SHARE[j])}*{tau})")
    return out, terms


def _hip_torques(act, m1: int, m2: int, ks: list | None = None) -> list[str]:
    """The hip torques' laws (actuators ``ks``, default all) as VARIABLEs and one SFORCE
    between leg1 (I) and leg2 (J)."""
    ks = list(range(len(act.torques))) if ks is None else ks
    V = ACT_VARIABLES
    out = ["! hip torques (walker.actuation.torques) [N mm]: +tau on the swing leg, -tau",
           "! on the stance leg; delta = swing - stance leg angle (AZ of leg1's hip marker",
           "! about leg2's, times the role sign), the phase variable the stance leg's",
           "! angle from the downward vertical (AZ about the ground's marker 101)",
           _var(V["delta"], f"VARVAL({V['sign']})*AZ({m1},{m2})"),
           _var(V["ddelta"], f"VARVAL({V['sign']})*WZ({m1},{m2},{m2})"),
           _var(V["phase"], f"IF(VARVAL({V['sign']}):AZ({m1},101),0,AZ({m2},101))"),
           _var(V["dphase"], f"IF(VARVAL({V['sign']}):WZ({m1},101,101),0,WZ({m2},101,101))")]
    laws, terms = hip_laws(act, ks)
    out += laws + _chain_sum(HIP_TORQUE_SUM - 50, HIP_TORQUE_SUM, terms)
    out += ["! their sum on leg1 (I) about z, the reaction on leg2 (J): sign * tau (the",
            "! swing leg's torque on leg1 while it swings, minus it while leg1 stands)",
            f"SFORCE/{HIP_SFORCE}, ROTATION, I={m1}, J={m2}",
            f", FUNCTION=VARVAL({V['sign']})*VARVAL({HIP_TORQUE_SUM})"]
    return out


#: VARIABLE ids (angle [rad], rate [rad/s]) of a five-link biped's role joints
#: (:data:`walkerlab.config.actuation.FIVE_LINK_JOINTS`: hip = thigh - torso, knee = shank -
#: thigh) and of the sums of their laws [N mm].
ROLE_JOINT_VARIABLES = {"stance_hip": (370, 371), "swing_hip": (372, 373),
                        "stance_knee": (374, 375), "swing_knee": (376, 377)}
ROLE_TORQUE_SUM = {"stance_hip": 9101, "swing_hip": 9102, "stance_knee": 9103,
                   "swing_knee": 9104}
#: SFORCE ids of a five-link biped's physical joints: (kind, leg) -> id.
JOINT_SFORCE = {("hip", "leg1"): 11, ("hip", "leg2"): 12, ("knee", "leg1"): 13,
                ("knee", "leg2"): 14}


def _joint_torques(mb, act, ids: dict, feet: dict) -> list[str]:
    """A free-jointed biped's joint torques (a hinged torso on thighs and free knees, or on
    straight legs): the role joints' angles picked by the role sign, the phase variable
    the virtual stance leg's angle, one SFORCE per physical joint (the knees' only on
    kneed legs)."""
    V = ACT_VARIABLES
    th = {g: marker_id(ids[hip_link(mb, g)], "joint") for g in ("leg1", "leg2")}
    kneed = all(f"{g}_shank" in ids for g in ("leg1", "leg2"))
    if kneed:
        kn = {g: marker_id(ids[f"{g}_thigh"], "knee") for g in ("leg1", "leg2")}
        sh = {g: marker_id(ids[f"{g}_shank"], "joint") for g in ("leg1", "leg2")}
    to = marker_id(ids["torso"], "joint")
    sgn = f"VARVAL({V['sign']})"
    out = (["! joint torques (walker.actuation.torques) [N mm] of a five-link biped: +tau on",
            "! the second link of the joint (thigh, shank), -tau on the first (torso,",
            "! thigh); the joints follow the roles: stance_hip = stance thigh - torso,",
            "! swing_knee = swing shank - swing thigh, ... (the role sign picks the leg);"]
           if kneed else
           ["! joint torques (walker.actuation.torques) [N mm] between a hinged torso and",
            "! straight legs: +tau on the leg, -tau on the torso; the joints follow the",
            "! roles: stance_hip = stance leg - torso, swing_hip = swing leg - torso (the",
            "! role sign picks the leg);"]) + [
           "! the phase variable the angle of the line from the hip to the stance foot",
           "! from the downward vertical, ATAN2(dx, -dy), and its rate"]
    for g, (a, r) in (("leg1", (380, 382)), ("leg2", (381, 383))):
        f, h = feet[g], th[g]
        out += [_var(a, f"ATAN2(DX({f},{h}),-DY({f},{h}))"),
                _var(r + 4, f"DX({f},{h})*VY({f},{h})-VX({f},{h})*DY({f},{h})"),
                _var(r, f"VARVAL({r + 4})/DM({f},{h})**2")]
    out += [_var(V["phase"], f"IF({sgn}:VARVAL(380),0,VARVAL(381))"),
            _var(V["dphase"], f"IF({sgn}:VARVAL(382),0,VARVAL(383))")]
    angle = {"hip": lambda g: (f"AZ({th[g]},{to})", f"WZ({th[g]},{to},{to})")}
    if kneed:
        angle["knee"] = lambda g: (f"AZ({sh[g]},{kn[g]})", f"WZ({sh[g]},{kn[g]},{kn[g]})")
    joints = {j: v for j, v in ROLE_JOINT_VARIABLES.items() if j.split("_")[1] in angle}
    for joint, (a, r) in joints.items():
        role, kind = joint.split("_")
        first, second = ("leg1", "leg2") if role == "stance" else ("leg2", "leg1")
        (a1, r1), (a2, r2) = angle[kind](first), angle[kind](second)
        out += [_var(a, f"IF({sgn}:{a1},0,{a2})"), _var(r, f"IF({sgn}:{r1},0,{r2})")]
    for k, t in enumerate(act.torques):
        out += _law(k, t, *ROLE_JOINT_VARIABLES[t.joint])
    for joint, total in ROLE_TORQUE_SUM.items():
        if joint not in joints:
            continue
        taus = [f"VARVAL({hip_torque_ids(k)['tau']})" for k, t in enumerate(act.torques)
                if t.joint == joint]
        out += _chain_sum(total - 100 + 10 * list(ROLE_TORQUE_SUM).index(joint), total, taus)
    for (kind, g), sid in JOINT_SFORCE.items():
        if kind not in angle:
            continue
        i_m, j_m = (th[g], to) if kind == "hip" else (sh[g], kn[g])
        st, sw = ROLE_TORQUE_SUM[f"stance_{kind}"], ROLE_TORQUE_SUM[f"swing_{kind}"]
        a, b = (st, sw) if g == "leg1" else (sw, st)  # sign < 0: leg1 stands
        out += [f"! {g}'s {kind}: the {'stance' if g == 'leg1' else 'swing'} law while leg1 "
                "stands, else the other",
                f"SFORCE/{sid}, ROTATION, I={i_m}, J={j_m}",
                f", FUNCTION=IF({sgn}:VARVAL({a}),0,VARVAL({b}))"]
    return out


def push_impulse(po, W: dict, first: int, speed_marker: int) -> list[str]:
    """The push-off's impulse ``P`` [N s] as VARIABLE ``W["impulse"]``: constant, or with a
    speed gain ``P = max(0, P0 + k (v_ref - v))`` from the speed of ``speed_marker`` (Kuo 2002,
    "Energetics of actively powered locomotion using the simplest walking model",
    J. Biomech. Eng. 124(1); the rigid model's
    :func:`walkerlab.models.actuation.push_off_impulse`).

    Parameters
    ----------
    po : walkerlab.config.actuation.PushOff
        ``impulse_n_s`` [N s], ``speed_gain_n_s2_per_m`` [N s^2/m], ``reference_speed_m_per_s``
        [m/s].
    W : dict
        VARIABLE ids by name (``impulse``).
    first : int
        First of the four VARIABLE ids the speed gain's terms take (``P0``, ``k``, ``v_ref``,
        ``v_ref - v`` [m/s]).
    speed_marker : int
        The marker whose speed ``VM`` [mm/s] is ``v``.

    Returns
    -------
    list of str
        The VARIABLE statements.
    """
    if not po.speed_gain_n_s2_per_m:
        return [_var(W["impulse"], _f(po.impulse_n_s))]
    p0, gain, ref, dv = first, first + 1, first + 2, first + 3
    return [_var(p0, _f(po.impulse_n_s)), _var(gain, _f(po.speed_gain_n_s2_per_m)),
            _var(ref, _f(po.reference_speed_m_per_s)),
            _var(dv, f"VARVAL({ref})-VM({speed_marker})/{_f(MM)}"),
            _var(W["impulse"], f"MAX(0.0,VARVAL({p0})+VARVAL({gain})*VARVAL({dv}))")]


def push_forces(W: dict, first: int, hips: dict, feet: dict, gforce: dict, float_marker: int,
                planar: bool) -> list[str]:
    """Each leg's push-off switch and pulse: on while that leg stands (the role sign
    ``ACT_VARIABLES["sign"]``), the other foot's touchdown is predicted within the pulse's
    duration and that foot is at least :data:`PUSH_MIN_STEP_M` ahead; then a force
    ``P / T`` [N] at the foot along the line to its own hip (a ``GFORCE``, the reaction on a
    floating ground marker), the contact view's push-off (Kuo 2002, "Energetics of actively
    powered locomotion using the simplest walking model", J. Biomech. Eng. 124(1)).

    Parameters
    ----------
    W : dict
        VARIABLE ids by name: ``pen_<leg>``, ``lead_<leg>``, ``ahead``, ``push_<leg>``,
        ``impulse``, ``pulse_s``.
    first : int
        First VARIABLE id of the switches (``first + 2 i``, ``+ 1``, ``+ 5`` for leg ``i``).
    hips, feet : dict
        Marker ids by leg: the hip, the foot the force acts at.
    gforce : dict
        GFORCE id by leg.
    float_marker : int
        The floating ground marker that takes the reaction.
    planar : bool
        No force along z (the planar dataset).

    Returns
    -------
    list of str
        The statements, leg1's then leg2's.
    """
    sign = ACT_VARIABLES["sign"]
    min_step = PUSH_MIN_STEP_M * MM
    out = []
    for i, (g, o) in enumerate((("leg1", "leg2"), ("leg2", "leg1"))):
        on = first + 2 * i
        stands = "1,0,0" if g == "leg1" else "0,0,1"  # sign < 0: leg1 stands
        ahead = f"VARVAL({W['ahead']})" if g == "leg1" else f"-VARVAL({W['ahead']})"
        h, f = hips[g], feet[g]
        push = W[f"push_{g}"]
        out += [f"! {g} stands, {o}'s touchdown is predicted within T, {o} is ahead",
                _var(on, f"IF(VARVAL({sign}):{stands})*IF(VARVAL({W[f'lead_{o}']}):0,0,1)"),
                _var(on + 1, f"VARVAL({on})*IF(VARVAL({W[f'pen_{o}']}):1,0,0)"),
                _var(on + 5, f"VARVAL({on + 1})*IF({ahead}-{_f(min_step)}:0,0,1)"),
                _var(push, f"VARVAL({on + 5})*VARVAL({W['impulse']})/VARVAL({W['pulse_s']})"),
                f"GFORCE/{gforce[g]}, I={f}, JFLOAT={float_marker}, RM=101",
                f", FX=VARVAL({push})*DX({h},{f})/DM({h},{f})\\",
                f", FY=VARVAL({push})*DY({h},{f})/DM({h},{f})\\"]
        out += ([", FZ=0.0\\TX=0.0\\TY=0.0\\TZ=0.0"] if planar else
                [f", FZ=VARVAL({push})*DZ({h},{f})/DM({h},{f})\\", ", TX=0.0\\TY=0.0\\TZ=0.0"])
    return out


def _push_off(mb, T: float, po, feet: dict, hips: dict, touch: dict | None = None
              ) -> list[str]:
    """The push-off pulse: a GFORCE at each foot (marker ``feet[leg]``), on while that leg
    stands and the other foot's touchdown (marker ``touch[leg]``, default ``feet``: a flat
    foot pushes at its toe and lands on its heel) is predicted less than ``T`` ahead (the
    contact view's start).  An arc foot's marker is its centre: its penetration is ``R``
    minus the centre's height."""
    touch = feet if touch is None else touch
    lift = mb.foot_radius_m * MM if mb.foot == "arc" and mb.foot_radius_m > 0 else 0.0
    pen0 = f"{_f(lift)}" if lift else ""
    V = ACT_VARIABLES
    min_step = PUSH_MIN_STEP_M * MM
    out = [f"! push-off (walker.actuation.push_off): a force P / T for T = {T:g} s",
           "! (contact.push_off_duration_s) at the stance (trailing) foot, from the foot",
           "! towards the hip, on from when the swing foot's penetration extrapolated T",
           "! ahead at its rate crosses 0 (the touchdown T ahead: the contact view's start)",
           f"! at least {min_step:g} mm ahead of the stance foot, until that touchdown (a",
           "! touchdown earlier than predicted ends it); the reaction on the ground (a",
           "! floating marker).  Penetration [mm]: minus the foot point's height above",
           "! the ground line; P from the hip's present speed.",
           f"MARKER/{PUSH_FLOAT_MARKER}, PART=1, FLOATING",
           _var(V["sin"], _f(math.sin(mb.slope_rad))), _var(V["cos"], _f(math.cos(mb.slope_rad))),
           _var(V["pulse_s"], _f(T))]
    out += push_impulse(po, V, 334, hips["leg1"])
    for g in ("leg1", "leg2"):
        f = touch[g]
        out += [_var(V[f"pen_{g}"],
                     f"{pen0}-(VARVAL(330)*DX({f},101)+VARVAL(331)*DY({f},101))"),
                _var(V[f"rate_{g}"], f"-(VARVAL(330)*VX({f})+VARVAL(331)*VY({f}))"),
                _var(V[f"lead_{g}"], f"VARVAL({V[f'pen_{g}']})+VARVAL(332)*"
                     f"VARVAL({V[f'rate_{g}']})")]
    out.append(_var(V["ahead"], f"VARVAL(331)*DX({touch['leg2']},{touch['leg1']})-VARVAL(330)*"
                    f"DY({touch['leg2']},{touch['leg1']})"))
    return out + push_forces(V, 350, hips, feet, PUSH_GFORCE, PUSH_FLOAT_MARKER, planar=True)


def actuation_statements(mb, scene: Scene, ids: dict, n_patches: tuple, lanes: bool
                         ) -> list[str]:
    """The actuation's statements (none for a passive walker): the feet's contact forces
    and the roles, the hip torques, the push-off.

    Raises
    ------
    ValueError
        Torques at joints the walker's kind lacks (ankles without flat feet; the five-link
        roles without free knees and a torso), one line naming the field.
    """
    act = scene.walker.actuation
    if act is None:
        return []
    V = ACT_VARIABLES
    part = adams_feet(mb)
    hips = {g: marker_id(ids[hip_link(mb, g)], "joint") for g in ("leg1", "leg2")}
    feet = {g: marker_id(ids[leg_end(mb, g)], "foot") for g in ("leg1", "leg2")}
    out = ["!", "! ---- actuation (walker.actuation), mm-kg-s: torques N mm, forces N ----",
           "! the roles: the stance leg is the one whose foot carries the larger normal",
           "! contact force (VARIABLE/301, 302 [N]: the sum over its CONTACTs; a tie, as",
           "! at the start, is leg2, the start's stance leg), so the roles swap when the",
           "! leading foot's force passes the trailing foot's at heel strike: the contact",
           "! view's touchdown switch as a force test (no latched state).  VARIABLE/303:",
           "! +1 while leg2 stands (leg1 swings), -1 while leg1 stands."]
    pairs = contact_pairs(mb, ids, lanes, n_patches)
    for g in ("leg1", "leg2"):
        def terms(role, g=g):
            return [f"CONTACT({c},0,1,0)" for c, leg, r, _i, _j in pairs
                    if leg == g and r == role]
        out += part.normal_force(g, V[f"force_{g}"], terms)
    out.append(_var(V["sign"], f"IF(VARVAL({V['force_leg1']})-VARVAL({V['force_leg2']}):"
                    "1,1,-1)"))
    ankle = [k for k, t in enumerate(act.torques) if t.joint.endswith("_ankle")]
    hip = [k for k, t in enumerate(act.torques) if t.joint == "hip"]
    if ankle:
        KINDS[mb.kind].require("ankle_torque", "adams", "walker.actuation.torques")
        if hip:
            out += _hip_torques(act, hips["leg1"], hips["leg2"], hip)
        out += _ankle_torques(mb, act, ids, hips, ankle, phase=not hip)
    elif "torso" in ids and not KINDS[mb.kind].joints_free and all(
            t.joint in TORSO_SHARE or t.joint == "hip" for t in act.torques):
        out += _hip_torques(act, hips["leg1"], hips["leg2"])   # the bisecting hip's
    elif any(t.joint != "hip" for t in act.torques):
        if "torso" not in ids or not KINDS[mb.kind].joints_free:
            raise ValueError(f"walker.actuation.torques: {FREE_JOINT_TORQUES}")
        if any(t.joint == "hip" for t in act.torques):
            raise ValueError("walker.actuation.torques: the Adams dataset drives a hinged "
                             "torso's walker at its joints (stance_hip, swing_hip, knees), "
                             "not also between the legs (joint: hip)")
        out += _joint_torques(mb, act, ids, feet)
    elif act.torques:
        out += _hip_torques(act, hips["leg1"], hips["leg2"])
    if act.push_off is not None:
        T = (scene.contact or ContactSettings()).push_off_pulse_s()
        push, touch = part.push_markers(ids, feet)  # flat feet: at the toe, the heel lands
        out += _push_off(mb, T, act.push_off, push, hips, touch)
    if act.ankle_push_off is not None:
        out += _ankle_push_off(mb, act.ankle_push_off, ids)
    return out


#: Flat feet's ankle torques: VARIABLE ids (angle [rad], rate [rad/s]) of the role ankles
#: (the sole from the leg's perpendicular, toe up > 0), the sums of their laws [N mm] and
#: the SFORCE ids of leg1's and leg2's ankles.
ANKLE_ROLE_VARIABLES = {"stance_ankle": (384, 385), "swing_ankle": (388, 389)}
ANKLE_TORQUE_SUM = {"stance_ankle": 9105, "swing_ankle": 9106}
ANKLE_TORQUE_SFORCE = {"leg1": 17, "leg2": 18}


def _ankle_torques(mb, act, ids: dict, hips: dict, ks: list, phase: bool) -> list[str]:
    """Flat feet's ``stance_ankle`` / ``swing_ankle`` torques (actuators ``ks``): the role
    ankles' angles ``AZ(foot, leg)`` picked by the role sign, each law on its role's angle
    (the phase variable the stance leg's angle, written here when no hip torque wrote it:
    ``phase``), one SFORCE per physical ankle (I the foot, J the leg) with its present
    role's sum (+tau raises the toe)."""
    V = ACT_VARIABLES
    sgn = f"VARVAL({V['sign']})"
    fj = {g: marker_id(ids[f"{g}_foot"], "joint") for g in ("leg1", "leg2")}
    lf = {g: marker_id(ids[leg_end(mb, g)], "foot") for g in ("leg1", "leg2")}
    out = ["! ankle torques (walker.actuation.torques) [N mm] of flat feet: +tau on the",
           "! foot (raises the toe), -tau on the leg; stance_ankle is the standing leg's",
           "! ankle angle AZ(foot, leg), swing_ankle the other's (the role sign picks)"]
    if phase:
        m1, m2 = hips["leg1"], hips["leg2"]
        out += [_var(V["phase"], f"IF({sgn}:AZ({m1},101),0,AZ({m2},101))"),
                _var(V["dphase"], f"IF({sgn}:WZ({m1},101,101),0,WZ({m2},101,101))")]
    for joint, (a, r) in ANKLE_ROLE_VARIABLES.items():
        first, second = ("leg1", "leg2") if joint == "stance_ankle" else ("leg2", "leg1")
        out += [_var(a, f"IF({sgn}:AZ({fj[first]},{lf[first]}),0,"
                     f"AZ({fj[second]},{lf[second]}))"),
                _var(r, f"IF({sgn}:WZ({fj[first]},{lf[first]},{lf[first]}),0,"
                     f"WZ({fj[second]},{lf[second]},{lf[second]}))")]
    for k in ks:
        out += _law(k, act.torques[k], *ANKLE_ROLE_VARIABLES[act.torques[k].joint])
    for i, (joint, total) in enumerate(ANKLE_TORQUE_SUM.items()):
        taus = [f"VARVAL({hip_torque_ids(k)['tau']})" for k in ks
                if act.torques[k].joint == joint]
        out += _chain_sum(9041 + 10 * i, total, taus)
    st, sw = ANKLE_TORQUE_SUM["stance_ankle"], ANKLE_TORQUE_SUM["swing_ankle"]
    for g in ("leg1", "leg2"):
        a, b = (st, sw) if g == "leg1" else (sw, st)  # sign < 0: leg1 stands
        out += [f"SFORCE/{ANKLE_TORQUE_SFORCE[g]}, ROTATION, I={fj[g]}, J={lf[g]}",
                f", FUNCTION=IF({sgn}:VARVAL({a}),0,VARVAL({b}))"]
    return out


#: The ankle push-off: VARIABLE ids by leg of the ankle angle [rad], the on switch (0 or
#: 1) and the torque [N mm]; SFORCE ids by leg.
ANKLE_VARIABLES = {"leg1": {"angle": 390, "heel_off": 396, "on": 392, "tau": 394},
                   "leg2": {"angle": 391, "heel_off": 397, "on": 393, "tau": 395}}
ANKLE_SFORCE = {"leg1": 15, "leg2": 16}


def _ankle_push_off(mb, po, ids: dict) -> list[str]:
    """The ankle push-off (:class:`walkerlab.config.actuation.AnklePushOff`): an SFORCE on
    each ankle (I the foot, J the leg), ``-k (a - rest) - tau0`` [N mm] on the ankle angle
    ``a = AZ(foot, leg)`` while that leg stands (the role sign), its heel carries no
    normal force and its toe does (heel off; the contact view latches heel off at the
    heel's lift-off and ends it at the swing foot's touchdown: here it ends when the roles
    swap, as the landing foot's force passes the trailing foot's), else 0."""
    V = ACT_VARIABLES
    k, rest, tau0 = po.stiffness_n_m_per_rad * MM, po.rest_angle_rad, po.constant_n_m * MM
    out = ["! ankle push-off (walker.actuation.ankle_push_off) [N mm]: -k (a - rest) - tau0",
           f"! (k = {k:g} N mm/rad, rest = {rest:g} rad, tau0 = {tau0:g} N mm) on the stance",
           "! ankle from heel off (its heel's normal force 0, its toe's > 0) to the roles'",
           "! swap after heel strike; a = AZ(foot, leg), toe up > 0"]
    for g in ("leg1", "leg2"):
        W, (heel, toe) = ANKLE_VARIABLES[g], FOOT_FORCES[g]
        fj = marker_id(ids[f"{g}_foot"], "joint")
        lf = marker_id(ids[leg_end(mb, g)], "foot")
        stands = "1,0,0" if g == "leg1" else "0,0,1"  # sign < 0: leg1 stands
        law = f"-{_f(tau0)}" if tau0 >= 0 else f"+{_f(-tau0)}"
        if k:
            law = f"-{_f(k)}*(VARVAL({W['angle']}){_plus(-rest)}){law}"
        out += [_var(W["angle"], f"AZ({fj},{lf})"),
                _var(W["heel_off"], f"IF(VARVAL({heel}):1,1,0)*IF(VARVAL({toe}):0,0,1)"),
                _var(W["on"], f"IF(VARVAL({V['sign']}):{stands})*VARVAL({W['heel_off']})"),
                _var(W["tau"], f"VARVAL({W['on']})*({law})"),
                f"SFORCE/{ANKLE_SFORCE[g]}, ROTATION, I={fj}, J={lf}",
                f", FUNCTION=VARVAL({W['tau']})"]
    return out

