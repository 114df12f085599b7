"""The hip-roll law of a 3D walker's Adams dataset (``walker.hip_roll``;
:mod:`walkerlab.export.adams_3d`): the rigid model's law
(:func:`walkerlab.codegen.legged.derive_legged`), as the MJCF's stepping loop runs it
(:class:`walkerlab.export.mujoco_walk.HipRollLoop`), written as ``VARIABLE`` expressions of
Adams runtime functions and one ``GFORCE`` per leg.

Each body's roll about the fall line ``s`` is read from its pitch axis ``a`` (a marker
``100 p + 5`` one metre along it from the body's origin): ``phi = ATAN2(-a . n, a . z_w)``
(``n`` the slope's normal, ``z_w`` walkerlab's z: the ground marker :data:`ROLL_FRAME`'s y and
z axes, its x the fall line), its rate ``omega . s`` (``WX`` in that frame).  With ``phi`` the
stance leg's, ``phi_p`` the pelvis', ``phi_w`` the swing leg's (N mm, rad)::

    tau_st = k_p phi_p + c_p dphi_p,
    tau_sw = -k_s (phi_w - g_l phi - g_r dphi) - c_s (dphi_w - dphi_p)

each a torque on its leg about the pelvis' roll axis, its reaction on the pelvis (a
``GFORCE`` with ``TZ`` along the pelvis' roll marker, ``JFLOAT`` on the pelvis): a MuJoCo
``qfrc_applied`` at the hinge ``leg<i>_roll``.  The roles are the planar dataset's force
test (:mod:`walkerlab.export.adams_actuation`): the stance leg is the one whose foot carries
the larger normal contact force (VARIABLE/303: +1 while leg2 stands, a tie as at the start
leg2), so they swap at the heel strike with no latched state.
"""

from __future__ import annotations

from walkerlab.export.adams_statements import MM, _chain_sum, _f, _var

__all__ = ["HIP_ROLL_GFORCE", "ROLL_FRAME", "ROLL_VARIABLES", "hip_roll_statements",
           "role_statements"]

#: The ground marker whose axes are the fall line, the slope's normal and walkerlab's z.
ROLL_FRAME = 104
#: The GFORCEs of leg1's and leg2's roll torque.
HIP_ROLL_GFORCE = {"leg1": 31, "leg2": 32}
#: VARIABLE ids: the feet's normal forces and the role sign, each body's roll and rate
#: (pelvis, leg1, leg2), the stance and swing legs', the swing roll's error from its
#: reference, the two torques, each leg's torque [N mm].
ROLL_VARIABLES = {"force_leg1": 301, "force_leg2": 302, "sign": 303,
                  "roll": (311, 312, 313), "rate": (321, 322, 323),
                  "roll_stance": 331, "roll_swing": 332, "rate_stance": 333,
                  "rate_swing": 334, "tau_stance": 341, "roll_error": 342, "tau_swing": 343,
                  "tau": {"leg1": 351, "leg2": 352}}


def _by_role(sign: int, leg1: int, leg2: int, stance: bool) -> str:
    """``VARVAL(leg1)`` or ``VARVAL(leg2)``: the stance (or swing) leg's by the role sign."""
    st, sw = f"VARVAL({leg2})", f"VARVAL({leg1})"
    a, b = (sw, st) if stance else (st, sw)  # sign < 0: leg1 stands
    return f"IF(VARVAL({sign}):{a},{b},{b})"


def role_statements(contacts: dict) -> list[str]:
    """The roles' force test: each foot's normal contact force [N] (the sum over its
    CONTACTs, VARIABLE/301, 302) and the role sign (VARIABLE/303: +1 while leg2 stands, -1
    while leg1 stands, a tie leg2's), the planar dataset's
    (:func:`walkerlab.export.adams_actuation.actuation_statements`).

    Parameters
    ----------
    contacts : dict
        CONTACT ids by leg (``leg1``, ``leg2``).

    Returns
    -------
    list of str
    """
    V = ROLL_VARIABLES
    out = []
    for g, base in (("leg1", 410), ("leg2", 460)):
        out += _chain_sum(base, V[f"force_{g}"],
                          [f"CONTACT({c},0,1,0)" for c in contacts[g]])
    return out + [_var(V["sign"], f"IF(VARVAL({V['force_leg1']})-VARVAL({V['force_leg2']}):"
                       "1,1,-1)")]


def hip_roll_statements(law: dict, parts: dict, contacts: dict) -> list[str]:
    """The law's statements.

    Parameters
    ----------
    law : dict
        ``walker.hip_roll``'s numbers (SI: ``pelvis_stiffness_n_m_per_rad``, ...,
        ``lean_gain``, ``lean_rate_gain_s``).
    parts : dict
        PART id by body: ``pelvis``, ``leg1``, ``leg2`` (their markers ``100 p + 2`` at the
        hip, the pelvis' with z along its roll axis, ``100 p + 5`` one metre along the
        pitch axis; the pelvis' ``100 p + 6``, ``+ 7`` floating).
    contacts : dict
        CONTACT ids by leg.

    Returns
    -------
    list of str
    """
    V = ROLL_VARIABLES
    kp, cp = law["pelvis_stiffness_n_m_per_rad"] * MM, law["pelvis_damping_n_m_s_per_rad"] * MM
    ks, cs = law["swing_stiffness_n_m_per_rad"] * MM, law["swing_damping_n_m_s_per_rad"] * MM
    gl, gr = law["lean_gain"], law["lean_rate_gain_s"]
    out = ["!", "! ---- the hip-roll law (walker.hip_roll), N mm, rad ----",
           "! the roles: the stance leg's foot carries the larger normal contact force",
           "! (VARIABLE/301, 302 [N]); VARIABLE/303: +1 while leg2 stands, -1 while leg1",
           "! stands. Rolls about the fall line from each body's pitch axis (marker",
           f"! 100 p + 5), in the ground frame MARKER/{ROLL_FRAME} (x fall line, y normal)."]
    out += role_statements(contacts)
    for k, body in enumerate(("pelvis", "leg1", "leg2")):
        p = parts[body]
        o, a = 100 * p + 2, 100 * p + 5
        out += [_var(V["roll"][k], f"ATAN2(-DY({a},{o},{ROLL_FRAME}),"
                                   f"DZ({a},{o},{ROLL_FRAME}))"),
                _var(V["rate"][k], f"WX({o},{ROLL_FRAME},{ROLL_FRAME})")]
    r, w = V["roll"], V["rate"]
    out += [_var(V["roll_stance"], _by_role(V["sign"], r[1], r[2], True)),
            _var(V["roll_swing"], _by_role(V["sign"], r[1], r[2], False)),
            _var(V["rate_stance"], _by_role(V["sign"], w[1], w[2], True)),
            _var(V["rate_swing"], _by_role(V["sign"], w[1], w[2], False)),
            _var(V["tau_stance"], f"{_f(kp)}*VARVAL({r[0]})+{_f(cp)}*VARVAL({w[0]})"),
            _var(V["roll_error"], f"VARVAL({V['roll_swing']})"
                                  f"-({_f(gl)})*VARVAL({V['roll_stance']})"
                                  f"-({_f(gr)})*VARVAL({V['rate_stance']})"),
            _var(V["tau_swing"], f"-{_f(ks)}*VARVAL({V['roll_error']})-{_f(cs)}*("
                                 f"VARVAL({V['rate_swing']})-VARVAL({w[0]}))")]
    tau_sw = V["tau_swing"]
    pelvis = parts["pelvis"]
    for j, g in enumerate(("leg1", "leg2")):
        stance_first = g == "leg2"  # sign > 0: leg2 stands
        st, sw = f"VARVAL({V['tau_stance']})", f"VARVAL({tau_sw})"
        a, b = (sw, st) if stance_first else (st, sw)
        out += [_var(V["tau"][g], f"IF(VARVAL({V['sign']}):{a},{b},{b})"),
                f"MARKER/{100 * pelvis + 6 + j}, PART={pelvis}, FLOATING",
                f"GFORCE/{HIP_ROLL_GFORCE[g]}, I={100 * parts[g] + 2}, "
                f"JFLOAT={100 * pelvis + 6 + j}, RM={100 * pelvis + 2}",
                ", FX=0.0\\FY=0.0\\FZ=0.0\\TX=0.0\\TY=0.0\\",
                f", TZ=VARVAL({V['tau'][g]})"]
    return out
