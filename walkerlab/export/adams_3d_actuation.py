"""The actuation of a 3D walker's Adams dataset (``walker.actuation``;
:mod:`walkerlab.export.adams_3d`): the hip torque law (``joint: hip``), a kneed walker's knee
torques and the push-off pulse, the planar dataset's statements
(:mod:`walkerlab.export.adams_actuation`: the same laws as ``VARIABLE`` expressions, an
``SFORCE`` or ``GFORCE`` per torque, a ``GFORCE`` pulse at the trailing foot) on the 3D
walker's parts, as the rigid model has them
(:class:`walkerlab.models.hybrid.actuated._Legs3d`; Kuo 2002, "Energetics of actively powered
locomotion using the simplest walking model", J. Biomech. Eng. 124(1)).

Each leg's pitch ``theta`` is its rotation about its own (rolled) hip axis, the rigid leg
being ``Rot(s, phi_leg) Rot(z, theta)`` in the slope's frame (``s`` the fall line): with
``d`` the leg's axis from its hip marker (``100 p + 2``) to its foot marker (``100 p + 3``) in
the ground frame :data:`~walkerlab.export.adams_hip_roll.ROLL_FRAME` (x the fall line, y the
slope's normal, z walkerlab's z), ``d = |d| (sin theta_s s - cos theta_s n')`` with ``n'``
the rolled normal, so ``theta = ATAN2(d_x, SQRT(d_y^2 + d_z^2)) - gamma`` (``theta_s`` from
the slope's normal, ``gamma`` the slope: the rigid model's pitch from the vertical, as the
export's hinge reads it), and its rate ``WZ`` of the hip marker (z along the pitch axis; the
roll's rate is along ``s``, normal to it).  The law's angle ``delta = theta_sw - theta_st``
(the role sign: the planar dataset's force test, VARIABLE/303), the phase variable the
stance leg's pitch.

The torque ``+tau`` on the swing leg about its pitch axis, ``-tau`` on the stance leg about
its own (the rigid model's virtual work ``tau delta(theta_sw - theta_st)``): without
hip-roll joints the pelvis is fixed to leg2 and both legs pitch about one axis, so one
``SFORCE/ROTATION`` on leg1's revolute (I on leg1, J on the pelvis) carries it, as the
planar dataset's between the legs; with hip-roll joints the pitch axes differ, so each leg
has a ``GFORCE`` torque about its own pitch axis (``RM`` its hip marker), the reaction on
the pelvis (an ``SFORCE/ROTATION`` needs its I and J z axes parallel).

An upper body on the bisecting hip (``walker.torso``, no hip-roll joints: the dataset's
COUPLER holds it on the legs' revolutes) takes a torque between it and a leg (``joint:
stance_hip`` / ``swing_hip``, the angle leg minus upper body) as the hip torque it is: the
upper body's pitch is the legs' mean, so the law's angle is ``-+ delta / 2`` (stance,
swing) and its virtual work ``tau d(alpha)`` the hip torque's ``(-+ tau / 2) d(delta)``
(:data:`~walkerlab.export.adams_actuation.TORSO_SHARE`; the rigid model takes
``d(alpha)/dq`` from the tree, and the two flows agree: ``tests/test_torso_3d.py``).

A kneed walker (``locking_knees_3d``): a leg's pitch is its thigh's (the hip marker to the
knee revolute's J marker ``100 t + 10 + s``, as the rigid model's hip law reads the thighs:
:class:`walkerlab.models.hybrid.actuated._KneedLegs3d`), its foot the shank's, and a knee
torque (``stance_knee``, ``swing_knee``: the law on the knee angle ``shank - thigh``, the
phase variable the stance leg's pitch) one ``SFORCE/ROTATION`` on each knee revolute (I on
the shank, J on the thigh, z along the leg's own pitch axis, so ``AZ(I, J)`` is the knee
angle and ``+tau`` on the shank about it is the rigid model's generalised force ``tau
d(theta_sh - theta_th)``), the role sign picking the stance or the swing law, as the planar
five-link dataset's knees (:mod:`walkerlab.export.adams_actuation`).

The push-off: the planar dataset's pulse ``P / T`` at the stance foot along the line to its
own hip (a ``GFORCE``, the reaction on a floating ground marker), on while that leg stands,
the other foot's touchdown extrapolated ``T`` ahead at its rate is reached and that foot is
at least :data:`~walkerlab.export.adams_actuation.PUSH_MIN_STEP_M` ahead along the fall
line; a foot's penetration is minus its sphere centre's height above the slope's plane
through the origin (the patches' tops lie the sphere's radius below it).  The speed gain's
speed is the pelvis' (the hips' midpoint).
"""

from __future__ import annotations

from walkerlab.config.contact import ContactSettings
from walkerlab.export.adams_actuation import (
    ACT_VARIABLES,
    HIP_SFORCE,
    HIP_TORQUE_SUM,
    JOINT_SFORCE,
    PUSH_MIN_STEP_M,
    ROLE_TORQUE_SUM,
    TORSO_SHARE,
    _law,
    hip_laws,
    hip_torque_ids,
    push_forces,
    push_impulse,
)
from walkerlab.export.adams_hip_roll import ROLL_FRAME, role_statements
from walkerlab.export.adams_statements import MM, _chain_sum, _f, _plus, _var
from walkerlab.export.axes_3d import slope_axes

__all__ = ["ACT_3D_VARIABLES", "HIP_TORQUE_GFORCE", "PUSH_3D_FLOAT_MARKER",
           "PUSH_3D_GFORCE", "actuation_3d_statements"]

#: VARIABLE ids of the 3D actuation: each leg's pitch [rad] and rate [rad/s] (its axis'
#: components along the fall line and across it [mm]), the push-off's
#: constants (the slope normal's x and z, the fall line's, the pulse's length [s], the
#: impulse [N s]), each foot's penetration [mm], its rate [mm/s] and extrapolation, the
#: swing foot's lead along the fall line [mm], each leg's push [N]; the law's angle, rate
#: and phase are the planar dataset's (:data:`walkerlab.export.adams_actuation.
#: ACT_VARIABLES`: 304-307), its torques' sum :data:`~walkerlab.export.adams_actuation.
#: HIP_TORQUE_SUM`.
ACT_3D_VARIABLES = {"pitch_leg1": 611, "pitch_leg2": 612, "rate_leg1": 613, "rate_leg2": 614,
                    "along_leg1": 615, "across_leg1": 616, "along_leg2": 617,
                    "across_leg2": 618,
                    "nx": 630, "nz": 631, "pulse_s": 632, "impulse": 633, "tx": 638,
                    "tz": 639, "pen_leg1": 641, "pen_leg2": 642, "dpen_leg1": 643,
                    "dpen_leg2": 644, "lead_leg1": 645, "lead_leg2": 646, "ahead": 647,
                    "push_leg1": 661, "push_leg2": 662,
                    "knee_stance": 621, "knee_rate_stance": 622, "knee_swing": 623,
                    "knee_rate_swing": 624}
#: GFORCE ids of the push-off at leg1's and leg2's foot (the hip-roll law's are 31, 32).
PUSH_3D_GFORCE = {"leg1": 1, "leg2": 2}
#: GFORCE ids of each leg's hip torque with hip-roll joints.
HIP_TORQUE_GFORCE = {"leg1": 41, "leg2": 42}
#: The floating ground marker that takes the push-off's reaction (the ground's 104 is
#: :data:`~walkerlab.export.adams_hip_roll.ROLL_FRAME`).
PUSH_3D_FLOAT_MARKER = 105


def _ends(parts: dict, leg: str) -> tuple[int, int, int]:
    """Leg ``leg``'s hip marker, the marker at the far end of its hip link (a straight
    leg's foot, a thigh's knee: the J marker ``100 t + 10 + s`` of its knee revolute) and
    its foot marker (on the leg, or on its shank ``leg<i>_shank``)."""
    hip, shank = 100 * parts[leg] + 2, parts.get(f"{leg}_shank")
    if shank is None:
        return hip, 100 * parts[leg] + 3, 100 * parts[leg] + 3
    return hip, 100 * parts[leg] + 10 + shank, 100 * shank + 3


def _pitches(parts: dict, slope_rad: float) -> list[str]:
    """Each leg's pitch and rate (module docstring): a kneed leg's its thigh's."""
    V = ACT_3D_VARIABLES
    out = []
    for g in ("leg1", "leg2"):
        h, f, _foot = _ends(parts, g)
        d = [f"D{a}({f},{h},{ROLL_FRAME})" for a in "XYZ"]
        a, b = V[f"along_{g}"], V[f"across_{g}"]
        out += [_var(a, d[0]), _var(b, f"SQRT({d[1]}**2+{d[2]}**2)"),
                _var(V[f"pitch_{g}"], f"ATAN2(VARVAL({a}),VARVAL({b})){_plus(-slope_rad)}"),
                _var(V[f"rate_{g}"], f"WZ({h},101,{h})")]
    return out


def _phase() -> list[str]:
    """The laws' phase variable, the stance leg's pitch, and its rate (VARIABLE/306, 307)."""
    V, W = ACT_VARIABLES, ACT_3D_VARIABLES
    sgn = f"VARVAL({V['sign']})"
    return [_var(V["phase"], f"IF({sgn}:VARVAL({W['pitch_leg1']}),0,"
                 f"VARVAL({W['pitch_leg2']}))"),
            _var(V["dphase"], f"IF({sgn}:VARVAL({W['rate_leg1']}),0,"
                 f"VARVAL({W['rate_leg2']}))")]


def _hip_torque(act, parts: dict, rolled: bool, ks: list) -> list[str]:
    """The hip torques' laws (actuators ``ks``, ``joint: hip``) and their force (module
    docstring)."""
    V, W = ACT_VARIABLES, ACT_3D_VARIABLES
    sgn = f"VARVAL({V['sign']})"
    out = ["! hip torques (walker.actuation.torques) [N mm]: +tau on the swing leg about",
           "! its pitch axis, -tau on the stance leg about its own; delta = swing - stance",
           "! pitch (times the role sign), the phase variable the stance leg's pitch",
           _var(V["delta"], f"{sgn}*(VARVAL({W['pitch_leg1']})-VARVAL({W['pitch_leg2']}))"),
           _var(V["ddelta"], f"{sgn}*(VARVAL({W['rate_leg1']})-VARVAL({W['rate_leg2']}))"),
           *_phase()]
    laws, terms = hip_laws(act, ks)
    out += laws
    out += _chain_sum(HIP_TORQUE_SUM - 50, HIP_TORQUE_SUM, terms)
    p1, pp = parts["leg1"], parts["pelvis"]
    if not rolled:
        return out + [
            "! their sum on leg1 (I) about its revolute's axis, the reaction on the pelvis",
            "! (fixed to leg2; both legs pitch about one axis): sign * tau",
            f"SFORCE/{HIP_SFORCE}, ROTATION, I={100 * p1 + 2}, J={100 * pp + 10 + p1}",
            f", FUNCTION={sgn}*VARVAL({HIP_TORQUE_SUM})"]
    out += ["! each leg's torque about its own pitch axis (RM its hip marker), the reaction",
            "! on the pelvis: sign * tau on leg1, -sign * tau on leg2"]
    for j, g in enumerate(("leg1", "leg2")):
        m = 100 * parts[g] + 2
        out += [f"MARKER/{100 * pp + 8 + j}, PART={pp}, FLOATING",
                f"GFORCE/{HIP_TORQUE_GFORCE[g]}, I={m}, JFLOAT={100 * pp + 8 + j}, RM={m}",
                ", FX=0.0\\FY=0.0\\FZ=0.0\\TX=0.0\\TY=0.0\\",
                f", TZ={'' if g == 'leg1' else '-'}{sgn}*VARVAL({HIP_TORQUE_SUM})"]
    return out


def _knee_torques(act, parts: dict, ks: list, phase: bool) -> list[str]:
    """A kneed walker's knee torques (actuators ``ks``: ``stance_knee``, ``swing_knee``;
    module docstring), with the phase variable's VARIABLEs where no hip torque wrote them
    (``phase``)."""
    V, W = ACT_VARIABLES, ACT_3D_VARIABLES
    sgn = f"VARVAL({V['sign']})"
    knee = {}
    for g in ("leg1", "leg2"):
        i_m, j_m = 100 * parts[f"{g}_shank"] + 2, 100 * parts[g] + 10 + parts[f"{g}_shank"]
        knee[g] = (i_m, j_m, f"AZ({i_m},{j_m})", f"WZ({i_m},{j_m},{j_m})")
    out = ["! knee torques (walker.actuation.torques) [N mm]: +tau on the shank about its",
           "! knee revolute's axis (the leg's pitch axis), -tau on the thigh; the knee angle",
           "! shank - thigh (AZ of the revolute's I about J), the role sign picking the leg",
           *(_phase() if phase else [])]
    for role, (a, b) in (("stance", ("leg1", "leg2")), ("swing", ("leg2", "leg1"))):
        out += [_var(W[f"knee_{role}"], f"IF({sgn}:{knee[a][2]},0,{knee[b][2]})"),
                _var(W[f"knee_rate_{role}"], f"IF({sgn}:{knee[a][3]},0,{knee[b][3]})")]
    for k in ks:
        role = act.torques[k].joint.split("_")[0]
        out += _law(k, act.torques[k], W[f"knee_{role}"], W[f"knee_rate_{role}"])
    for j, role in enumerate(("stance", "swing")):
        total = ROLE_TORQUE_SUM[f"{role}_knee"]
        out += _chain_sum(total - 100 + 10 * (2 + j), total,
                          [f"VARVAL({hip_torque_ids(k)['tau']})" for k in ks
                           if act.torques[k].joint == f"{role}_knee"])
    st, sw = ROLE_TORQUE_SUM["stance_knee"], ROLE_TORQUE_SUM["swing_knee"]
    for g, (a, b) in (("leg1", (st, sw)), ("leg2", (sw, st))):  # sign < 0: leg1 stands
        out += [f"! {g}'s knee: the stance law while {g} stands, else the swing law",
                f"SFORCE/{JOINT_SFORCE[('knee', g)]}, ROTATION, I={knee[g][0]}, "
                f"J={knee[g][1]}", f", FUNCTION=IF({sgn}:VARVAL({a}),0,VARVAL({b}))"]
    return out


def _push_off(po, T: float, parts: dict, slope_rad: float) -> list[str]:
    """The push-off pulse (module docstring)."""
    W = ACT_3D_VARIABLES
    t, n = slope_axes(slope_rad)
    foot = {g: _ends(parts, g)[2] for g in ("leg1", "leg2")}
    hip = {g: 100 * parts[g] + 2 for g in ("leg1", "leg2")}
    min_step = PUSH_MIN_STEP_M * MM
    out = [f"! push-off (walker.actuation.push_off): a force P / T for T = {T:g} s",
           "! (contact.push_off_duration_s) at the stance (trailing) foot, from the foot",
           "! towards its own hip, on from when the swing foot's penetration extrapolated T",
           "! ahead at its rate crosses 0 (the touchdown T ahead: the contact view's start)",
           f"! at least {min_step:g} mm ahead of the stance foot along the fall line, until",
           "! that touchdown; the reaction on the ground (a floating marker).  Penetration",
           "! [mm]: minus the foot sphere centre's height above the slope's plane.",
           f"MARKER/{PUSH_3D_FLOAT_MARKER}, PART=1, FLOATING",
           _var(W["nx"], _f(float(n[0]))), _var(W["nz"], _f(float(n[2]))),
           _var(W["tx"], _f(float(t[0]))), _var(W["tz"], _f(float(t[2]))),
           _var(W["pulse_s"], _f(T))]
    out += push_impulse(po, W, 634, 100 * parts["pelvis"] + 1)
    nx, nz = f"VARVAL({W['nx']})", f"VARVAL({W['nz']})"
    for g in ("leg1", "leg2"):
        f = foot[g]
        out += [_var(W[f"pen_{g}"], f"-({nx}*DX({f},101)+{nz}*DZ({f},101))"),
                _var(W[f"dpen_{g}"], f"-({nx}*VX({f})+{nz}*VZ({f}))"),
                _var(W[f"lead_{g}"], f"VARVAL({W[f'pen_{g}']})+VARVAL({W['pulse_s']})*"
                     f"VARVAL({W[f'dpen_{g}']})")]
    f1, f2 = foot["leg1"], foot["leg2"]
    out.append(_var(W["ahead"], f"VARVAL({W['tx']})*DX({f2},{f1})+VARVAL({W['tz']})*"
                    f"DZ({f2},{f1})"))
    return out + push_forces(W, 650, hip, foot, PUSH_3D_GFORCE, PUSH_3D_FLOAT_MARKER,
                             planar=False)


def actuation_3d_statements(scene, parts: dict, contacts: dict, slope_rad: float,
                            rolled: bool) -> list[str]:
    """The 3D walker's actuation statements (none for a passive walker; module docstring).

    Parameters
    ----------
    scene : walkerlab.config.Scene
        Its ``walker.actuation`` (hip torques ``joint: hip``, with an upper body
        ``stance_hip`` and ``swing_hip``, a kneed walker's knee torques, a push-off) and
        ``contact.push_off_duration_s``.
    parts : dict
        PART id by body: ``pelvis``, ``leg1``, ``leg2`` (markers ``100 p + 2`` at each hip,
        z along the leg's pitch axis, ``100 p + 3`` its foot; the pelvis' ``100 p + 10 + q``
        the J marker of leg ``q``'s revolute) and a kneed walker's ``leg1_shank``,
        ``leg2_shank`` (the foot ``100 s + 3``, the knee revolute's I ``100 s + 2`` and J
        ``100 t + 10 + s`` on the thigh ``t``).
    contacts : dict
        CONTACT ids by leg (the roles' force test).
    slope_rad : float
        The slope [rad].
    rolled : bool
        Hip-roll joints: the roles are the hip-roll law's (written before), the torque a
        GFORCE on each leg.

    Returns
    -------
    list of str

    Raises
    ------
    ValueError
        A torque at a joint other than the hips and a kneed walker's knees (one line naming
        ``walker.actuation.torques.<i>.joint``).
    """
    act = scene.walker.actuation
    if act is None:
        return []
    out = ["!", "! ---- actuation (walker.actuation), mm-kg-s: torques N mm, forces N ----"]
    if not rolled:  # the hip-roll law's block writes the roles where it is
        out += ["! the roles: the stance leg's foot carries the larger normal contact force",
                "! (VARIABLE/301, 302 [N]); VARIABLE/303: +1 while leg2 stands, -1 while "
                "leg1", "! stands."]
        out += role_statements(contacts)
    out += ["! each leg's pitch [rad] about its own hip axis from the vertical, and its "
            "rate", f"! (the ground frame MARKER/{ROLL_FRAME}: x the fall line, y the normal)"]
    out += _pitches(parts, slope_rad)
    hips = ("hip", *TORSO_SHARE) if "torso" in parts else ("hip",)   # an upper body's too
    hip = [k for k, t in enumerate(act.torques) if t.joint in hips]
    knees = [k for k, t in enumerate(act.torques) if t.joint.endswith("_knee")]
    if len(hip) + len(knees) < len(act.torques) or (knees and "leg1_shank" not in parts):
        k = next(k for k, t in enumerate(act.torques) if k not in hip and (
            k not in knees or "leg1_shank" not in parts))
        raise ValueError(f"walker.actuation.torques.{k}.joint: the 3D walker's Adams dataset "
                         "drives the hips (joint: hip; with an upper body stance_hip, "
                         "swing_hip) and a kneed walker's knees (stance_knee, swing_knee), "
                         f"not {act.torques[k].joint}")
    if hip:
        out += _hip_torque(act, parts, rolled, hip)
    if knees:
        out += _knee_torques(act, parts, knees, phase=not hip)
    if act.push_off is not None:
        T = (scene.contact or ContactSettings()).push_off_pulse_s()
        out += _push_off(act.push_off, T, parts, slope_rad)
    return out
