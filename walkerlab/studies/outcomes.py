"""Typed outcomes of a sweep point and the result columns of each swept stage.

Every point of a sweep ends in exactly one outcome (never an unhandled exception).  How a
run ended uses the shared run-end names (:mod:`walkerlab.integrate.ends`: ``fall``, ``trip``,
``scuff``, ``slip``, ``airborne``, ``no_heel_strike``, ``solver_failure``, ``time_limit``,
``work_limit``);
a run that walked is ``ok``; the others are a sweep's own verdicts:

==================  =======================================================================
``ok``              the stage succeeded (fixed point found / all steps walked)
``no_fixed_point``  the root finder stopped without a fixed point (``residual`` column)
``fall``            the walker fell (``fall_time_s``, ``fall_leg`` = stance leg, ``message``
                    = guard that fired; contact model: hip below the fall height)
``trip``            contact model: a foot hit the side of a patch below its top
                    (``fall_time_s``, ``fall_leg`` = the foot, ``trip_edge_m`` = the edge)
``scuff``           the swing foot hit the ground before heel strike (contact model: a
                    touchdown of the swing foot that is not a heel strike; rigid model: only
                    when ``options["scuff_limit_m"]`` is set, since the ideal model ignores it)
``slip``            contact model: the stance foot slid more than ``slip_limit_mm``
``airborne``        contact model: the hip rose above 1.5 leg lengths (flew off the ground)
``no_heel_strike``  the walker made no step (contact: no heel strike by the end time)
``bounce``          contact model: the stance foot left the ground and touched down again
``solver_failure``  the integrator stopped (``message`` = scipy's message)
``max_steps``       a budget ran out before a verdict: a step lasted longer than
                    ``max_step_time_s`` (rigid), or the contact walker stalled (too few steps)
``time_limit``      contact model: the run's wall-time limit (set by the user) ran out first
``work_limit``      contact model: the run's work bound (``contact_sim.max_rhs_evaluations``)
                    ran out first
``invalid_config``  the point's scene does not validate (``message`` = pydantic's, one line)
``error``           any other exception (type and message recorded; should not happen)
==================  =======================================================================
"""

from __future__ import annotations

from walkerlab.integrate.ends import RUN_END_NAMES
from walkerlab.io.stage_files import CONTACT_SIM

#: Run ends that are a verdict of their own (the others, heel_strike / t_final, are ``ok``).
RUN_END_OUTCOMES = tuple(k for k in RUN_END_NAMES if k not in ("heel_strike", "t_final"))

OUTCOMES = ("ok", "no_fixed_point", *RUN_END_OUTCOMES, "bounce", "max_steps",
            "invalid_config", "error")

# column name -> (unit, description); all stored as float64 (NaN = not applicable).
# Columns that depend on the walker's state (fixed point, initial state, multipliers) are
# added by :func:`columns` from ``walker.state_names()``; these are the walker-free ones.
# shared by the stages' tables: how a walk ended (simulate, contact-sim), the cost (all)
_RUN_END = {
    "t_end_s": ("s", "time at which the run ended"),
    "fall_time_s": ("s", "time of the fall (NaN if none)"),
}
_NFEV = {"nfev": ("-", "right-hand-side evaluations")}

_FP = {
    "step_period_s": ("s", "step period of the period-1 gait"),
    "min_normal_force_n": ("N", "smallest normal force on the stance foot (< 0: the gait "
                           "needs the ground to pull; NaN: not checked, e.g. flat feet)"),
    "max_friction_ratio": ("-", "largest |tangential| / normal ground force at every foot "
                           "on the ground (inf: a foot unloads while it carries a "
                           "tangential force): the friction coefficient the gait needs"),
    "friction_coefficient": ("-", "the ground's static friction coefficient (contact."
                             "mu_static or its default)"),
    "inside_friction_cone": ("-", "1 if max_friction_ratio <= friction_coefficient, 0 if "
                             "not, NaN if not checked"),
    "max_twist_n_m": ("N m", "a walker in 3D: largest moment about the slope's normal on "
                      "the stance foot (its rigid stance joint turns no further; NaN in the "
                      "plane)"),
    "residual": ("rad or rad/s", "max |P(x) - x| at the last iterate"),
    "max_abs_multiplier": ("-", "largest |Floquet multiplier|"),
    "stable": ("-", "1 if all |multipliers| < 1, else 0"),
    "map_evaluations": ("-", "Poincare-map calls of the root finder"),
    "variational_maps": ("-", "maps with the variational equations (Jacobians asked by the "
                         "root finder + the one for the multipliers)"),
    **_NFEV,
}

_SIM = {
    "steps_completed": ("-", "heel strikes before the run ended"),
    **_RUN_END,
    "mean_step_period_s": ("s", "mean period of the completed steps"),
    "mean_step_length_m": ("m", "mean step length (foot to foot at heel strike)"),
    "mean_hip_speed_m_per_s": ("m/s", "mean step length / mean step period"),
    "interleg_angle_last_rad": ("rad", "inter-leg angle at the last heel strike"),
    "scuff_depth_m": ("m", "largest depth of the swing foot below the slope before heel "
                           "strike (the ideal model ignores it)"),
    **_NFEV,
}

_CONTACT = {
    "heel_strikes": ("-", "heel strikes detected"),
    "steps_expected": ("-", "2 * contact_sim.n_strides"),
    **_RUN_END,
    "mean_step_period_s": ("s", "mean period of the complete steps"),
    "max_slip_mm": ("mm", "largest along-slope slide of a stance foot over a stance phase "
                    "(touchdown to lift-off; phases that do not end are left out)"),
    "double_support_creep_mm": ("mm", "along-slope travel of both feet while both are loaded"),
    "trip_edge_m": ("m", "along-slope position of the patch side hit by a trip (NaN if none)"),
    "hip_height_end_m": ("m", "hip height above the ground line at the end of the run"),
    "bounces": ("-", "touchdowns of a stance foot after it lifted off within its step"),
    "scuffs": ("-", "touchdowns of the swing foot that are not heel strikes"),
    "peak_penetration_mm": ("mm", "largest penetration of either foot"),
    "ideal_step_length_m": ("m", "step length of the ideal gait (checkerboard spacing)"),
    "ideal_step_period_s": ("s", "step period of the ideal gait"),
    "integration_wall_time_s": ("s", "wall time of the contact integration alone"),
    **_NFEV,
}

COLUMNS: dict[str, dict[str, tuple[str, str]]] = {
    "fixedpoint": _FP, "simulate": _SIM, CONTACT_SIM.name: _CONTACT,
}

# string columns shared by every stage
STRING_COLUMNS = {
    "outcome": "typed outcome (see walkerlab.studies.outcomes)",
    "message": "human-readable detail (exception text, solver message, guard name)",
    "fall_leg": "physical leg in stance when the walker fell ('' if none)",
    "guess_source": "where the chosen gait's root finder started (as walkerlab fixedpoint "
                    "searches, the point alone): 'scene' (its initial_guess), "
                    "'zero_dynamics' (the restricted map's orbit), 'search' (scale-free "
                    "seeds or deflation: walkerlab.analysis.gait.search), or ''",
}

STAGES = tuple(COLUMNS)


def state_column(name: str, unit: str) -> str:
    """Column name of a state component: the name with its unit (``swing_angle_rad``)."""
    return f"{name}_{unit.replace('/', '_per_')}"


def columns(stage: str, state_names: list[str], state_units: list[str]) -> dict[str, tuple]:
    """All float columns of ``stage`` for a walker with these state names and units.

    Parameters
    ----------
    stage : str
        One of :data:`STAGES`.
    state_names, state_units : list of str, length 2n
        ``walker.state_names()`` and ``walker.state_units()``.

    Returns
    -------
    dict
        column -> (unit, description); the fixed point (``<state>_<unit>``) and the 2n
        Floquet multipliers (``multiplier_<k>_re|im``) for ``fixedpoint``, the initial state
        (``x0_<state>_<unit>``) for ``simulate``.
    """
    out = dict(COLUMNS[stage])
    named = [(state_column(n, u), u, n) for n, u in zip(state_names, state_units)]
    if stage == "fixedpoint":
        out.update({c: (u, f"fixed point, {n} just after heel strike") for c, u, n in named})
        out.update({f"multiplier_{k}_{p}": ("-", f"Floquet multiplier {k} (variational, sorted "
                                            f"by modulus), {'real' if p == 're' else 'imaginary'}"
                                            " part")
                    for k in range(len(state_names)) for p in ("re", "im")})
    elif stage == "simulate":
        out.update({f"x0_{c}": (u, f"initial state, {n}") for c, u, n in named})
    return out


def walker_columns(stage: str, plant) -> dict[str, tuple]:
    """:func:`columns` for the rigid walker of the plant's scene (its state names from the
    walker's description: :func:`walkerlab.models.registry.state_layout`, no walker built).

    Parameters
    ----------
    stage : str
        The swept stage.
    plant : walkerlab.walker.plant.Plant
        The sweep's plant, handed down by the stage.

    Returns
    -------
    dict
        Column name -> ``(unit, description)``.
    """
    if stage not in ("fixedpoint", "simulate"):
        return dict(COLUMNS[stage])
    from walkerlab.models.registry import state_layout  # light

    scene = plant.scene
    out = columns(stage, *state_layout(plant))
    act = scene.walker.actuation if hasattr(scene.walker, "actuation") else None
    if stage == "fixedpoint" and act is not None and act.virtual_constraints is not None:
        out.update(ZERO_DYNAMICS_COLUMNS)  # a scene under virtual constraints: its HZD too
    return out


#: a sweep's fixedpoint columns of a scene under virtual constraints: its hybrid zero
#: dynamics (:func:`walkerlab.analysis.gait.zero_dynamics.zero_dynamics`)
ZERO_DYNAMICS_COLUMNS = {
    "delta2": ("-", "restricted Poincare map's multiplier delta^2"),
    "v_minus": ("kg^2 m^4/s^2", "V(theta-) of the zero dynamics"),
    "v_max": ("kg^2 m^4/s^2", "largest V over the step"),
    "existence_margin": ("kg^2 m^4/s^2", "delta^2/(1-delta^2) V(theta-) + V_max (< 0: the "
                         "zero dynamics' fixed point exists)"),
    "hzd_step_period_s": ("s", "step period of the zero dynamics' orbit (quadrature)"),
}


def empty_row(stage: str, index: int) -> dict:
    """A row with every column of ``stage`` at its 'not applicable' value."""
    row = {c: float("nan") for c in COLUMNS[stage]}
    row.update({c: "" for c in STRING_COLUMNS})
    row.update(index=int(index), wall_time_s=float("nan"))
    return row
