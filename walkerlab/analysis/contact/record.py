"""What a contact run records beside its trajectory: the drop test of the scene's contact
law, the rates an initial rate scale multiplies, and the run's headline numbers.

:func:`contact_sim_run` is the ``contact-sim`` stage's whole run (start, periodic gait, drop
test, headline numbers); the stage writes it through :mod:`walkerlab.io.schemas.contact_sim`.
"""

from __future__ import annotations

import numpy as np

from walkerlab.analysis.contact import sim as contact_run
from walkerlab.analysis.contact.drop import restitution_curve
from walkerlab.analysis.contact.ledger import (
    STEP_LEDGER_DESCRIPTIONS,
    STEP_LEDGER_UNITS,
    contact_step_ledger,
)
from walkerlab.analysis.contact.search_budget import PeriodicGaitError
from walkerlab.config import ContactSettings
from walkerlab.config.contact import CONTACT_QUANTITIES
from walkerlab.models.contact.scene import (
    SEVERAL_STEPS_OUTCOME,
    SEVERAL_STEPS_PERIODIC,
    ContactSetup,
)

#: stiffness values of the drop test stored with every contact run, relative to the scene's
#: own stiffness (the paper's k = 1e5 N/mm^2.2: 1e4 ... 1e9 N/mm^2.2)
DROP_STIFFNESS_RATIO = (0.1, 0.3, 1.0, 3.0, 1e1, 3e1, 1e2, 3e2, 1e3, 3e3, 1e4)
#: downward speed of the drop test at first contact [m/s, or the scene's speed unit]
DROP_SPEED = 0.3
#: the legs of a contact run, in the order of ``initial_rate_scale`` (swing, stance)
LEGS = ["leg1", "leg2"]


def drop_test(law: ContactSettings, mass_kg: float) -> dict:
    """The drop test of the scene's contact law ``law`` (its ``contact`` section as written;
    :func:`walkerlab.analysis.contact.drop.restitution_curve`): the walker's total mass
    ``mass_kg`` [kg] meeting flat ground at :data:`DROP_SPEED`, at the stiffnesses
    :data:`DROP_STIFFNESS_RATIO` x the scene's.

    The stiffnesses are in the unit the scene writes its stiffness in (``unit`` of the
    result, ``N/mm^e`` for ``stiffness_n_per_mm_pow_e``).  The rigid-limit family starts
    from the scene's own contact (its stiffness is the reference) when the scene follows the
    paper family, so both curves pass through the scene's contact whatever its units (the
    reference stiffness defaults to the paper's 1e5 N/mm^2.2, far from e.g.
    round_feet.yaml's 4e9 N/m^2.2).
    """
    k, unit, _ = law.written("stiffness")
    if law.stiffness_family == "paper":
        law = law.with_written("reference_stiffness", k, unit)
    ks = [k * r for r in DROP_STIFFNESS_RATIO]
    out = restitution_curve(law, ks, mass_kg=float(mass_kg), v_in_m_per_s=DROP_SPEED)
    return {**out, "unit": CONTACT_QUANTITIES["stiffness"][unit][1]}


def rate_states(walker, leg: str) -> list[str]:
    """Names of the rate states of ``leg``'s links (what one entry of
    ``initial_rate_scale`` multiplies): ``dtheta1``; kneed ``dtheta1_thigh dtheta1_shank``
    (each in [rad/s])."""
    lay = walker.layout()
    return [lay.rate_of(s) for s in walker.leg_angle_states(leg)]


def _finite_mean(v) -> float:
    """Mean of the finite entries of ``v`` (NaN if none)."""
    v = np.asarray(v, float)
    v = v[np.isfinite(v)]
    return float(v.mean()) if v.size else float("nan")


def run_summary(res) -> dict:
    """Headline numbers of a contact run ``res`` (ContactResult): how it ended, heel strikes,
    strides, stance slip, its path and double-support creep [mm], the friction work per
    stance [J], peak penetration [mm], bounces,
    scuffs, RHS/Jacobian evaluations and the integration's wall time [s]."""
    steps = res.steps
    slips = np.array([s.stance_slip_mm for s in steps])
    creep = np.array([s.double_support_creep_mm for s in steps])
    turns = np.array([s.stance_turn_mrad for s in steps])
    # a walker in 3D: the stance foot's largest turn a step (its torsional friction's creep)
    turn = ({"max_abs_stance_turn_mrad": float(np.nanmax(np.abs(turns)))}
            if np.isfinite(turns).any() else {})
    return {**turn,
        "termination": res.termination,
        "outcome": res.outcome.kind,
        "heel_strikes": int(res.walked_steps),
        "strides_completed": int(res.walked_steps // 2),
        "mean_abs_stance_slip_mm": float(np.nanmean(np.abs(slips)))
        if np.isfinite(slips).any() else np.nan,
        "max_abs_stance_slip_mm": float(res.max_stance_slip_mm),
        "total_double_support_creep_mm": float(np.sum(creep)) if creep.size else 0.0,
        "mean_stance_slip_path_mm": _finite_mean([s.stance_slip_path_mm for s in steps]),
        "mean_friction_work_j": _finite_mean([s.friction_work_j for s in steps]),
        "peak_penetration_mm": float(max((s.peak_penetration_m for s in steps),
                                         default=np.nan) * 1e3),
        "total_bounces": int(sum(s.bounce_count for s in steps)),
        "total_scuffs": int(sum(s.scuff_count for s in steps)),
        "nfev": int(res.nfev), "njev": int(res.njev), "wall_time_s": float(res.wall_time_s),
    }


def contact_walk(setup: ContactSetup, x_ideal: np.ndarray, period: float,
                 adjust: bool = False, solver=None):
    """The walking run of the ``contact-sim`` stage (its start and its integration, without
    the periodic gait search, the drop test or the headline numbers): the contact walker of
    a scene (its ``setup``, :func:`walkerlab.models.contact.scene.contact_setup`) started from
    the ideal state ``x_ideal`` with the scene's rate scale, the rates ``adjust`` searches
    (kept only when they walk better than the scene's own, or as well and match the ideal gait
    better: :func:`~walkerlab.analysis.contact.adjust.better_start`), or the contact model's
    own periodic gait (``contact_sim.start: periodic_gait``), for ``setup.sim.n_strides``
    strides.  :func:`contact_sim_run` and the in-memory contact walker
    (:class:`walkerlab.api.walker.ContactWalker`) both run it.

    Parameters
    ----------
    setup : ContactSetup
    x_ideal : ndarray, shape (2n,)
        Rigid post-impact state (the rigid walker's ``state_names()``, leg1 swing, leg2
        stance) [rad, rad/s]; the stage's is the fixed point of ``fixedpoint.h5``.
    period : float
        Rigid step period [s] from ``x_ideal`` (sizes the run's end time).
    adjust : bool
        Search the initial rates (``--adjust``; also with ``contact_sim.start: adjusted``).
    solver : walkerlab.integrate.solver.Solver, optional
        The run's integrator (default: the scene's ``contact_solver``, ``setup.solver``).

    Returns
    -------
    walker : walkerlab.models.contact.model.ContactWalker
        The contact model on the run's terrain.
    result : walkerlab.analysis.contact.result.ContactResult
    x0 : ndarray, shape (N,)
        The contact walker's initial state [m, rad, m/s, rad/s].
    step_length : float
        The patches' spacing [m] (ideal step length, or the periodic gait's).
    scale : tuple of float or None
        Multipliers on the (swing, stance) rates used (None: the scene's own).
    gait : walkerlab.analysis.contact.periodic.ContactPeriodicGait or None
        The periodic gait started from (``start: periodic_gait``), else None.
    adjust : dict or None
        The ``--adjust`` search's record (None without it).

    Raises
    ------
    walkerlab.analysis.contact.step_map.PeriodicGaitError
        ``start: periodic_gait`` and the gait was not found (one line naming the field).
    """
    cs = setup.sim
    adj = scale = gait = None
    tried = {}  # the --adjust search's runs of the scene's start and the best start
    adjust = adjust or cs.start == "adjusted"
    if adjust:
        from walkerlab.analysis.contact.adjust import adjust_rates, better_start  # light

        adj = adjust_rates(setup, x_ideal, period)
        tried = adj.pop("runs", None) or {}  # not made again
        scale = adj["scale"]
    if cs.start == "periodic_gait":  # steady state: the contact model's own periodic gait
        walker, res, x0, step_length, gait = _periodic_start(setup, x_ideal, solver)
        scale = (1.0, 1.0)  # the start is the gait's state, not scaled rates
    else:
        run = tried.get("best") or contact_run.simulate_from(
            setup, x_ideal, period, scale, solver=solver)
        if adjust:  # the adjusted start must walk better than the scene's own
            plain = tried.get("scene") or contact_run.simulate_from(
                setup, x_ideal, period, None, solver=solver)
            adj["kept"], adj["kept_reason"] = better_start(
                plain[1], run[1], adj.get("scene_objective", np.nan),
                adj.get("objective", np.nan))
            if adj["kept"] == "scene":
                run, scale = plain, None
        walker, res, x0, step_length = run
    return walker, res, x0, step_length, scale, gait, adj


def _periodic_start(setup: ContactSetup, x_ideal, solver):
    """:func:`contact_walk` from the contact model's own periodic gait
    (``contact_sim.start: periodic_gait``): ``(walker, result, x0, step_length, gait)`` of
    :func:`~walkerlab.analysis.contact.periodic.simulate_from_periodic_gait`; its
    ``PeriodicGaitError`` again with the scene and the field named."""
    from walkerlab.analysis.contact.periodic import simulate_from_periodic_gait  # light

    try:
        return simulate_from_periodic_gait(setup, x_ideal, solver=solver)
    except PeriodicGaitError as exc:
        raise PeriodicGaitError(exc.kind, f"scene '{setup.name}': contact_sim.start: "
                                "periodic_gait: "
                                f"the contact walker's periodic gait was not found ({exc})"
                                ) from None


def contact_sim_run(setup: ContactSetup, fp, adjust: bool = False, periodic: bool = False):
    """The ``contact-sim`` stage's run: the contact walker of a scene (its ``setup``,
    :func:`walkerlab.models.contact.scene.contact_setup`) started from the ideal fixed point
    ``fp`` (a loaded ``fixedpoint.h5``) as :func:`contact_walk` runs it; with ``periodic``
    (or ``contact_sim.start: periodic_gait``) its periodic gait and Floquet multipliers (on
    footholds of several heights not searched: recorded as not found, outcome
    ``several_steps``, the one-step map's reason); the drop test and the headline numbers.

    Returns
    -------
    walkerlab.io.schemas.contact_sim.ContactSimRun

    Raises
    ------
    walkerlab.analysis.contact.step_map.PeriodicGaitError
        ``start: periodic_gait`` and the gait was not found (one line naming the field).
    """
    from walkerlab.io.schemas.contact_sim import ContactSimRun  # light

    cs = setup.sim
    gait_error = None
    walker, res, x0, step_length, scale, gait, adj = contact_walk(
        setup, fp.x, fp.step_period_s, adjust)
    if periodic and gait is None and setup.steps_differ:

        # the step map is one step's; this ground's gait is of several (not searched)
        gait_error = PeriodicGaitError(SEVERAL_STEPS_OUTCOME, SEVERAL_STEPS_PERIODIC)
    elif periodic and gait is None:
        from walkerlab.analysis.contact.periodic import (  # light
            converged_gait,
            find_contact_periodic_gait,
            search_bounds,
        )

        try:  # an unconverged search is a gait not found (its outcome and message)
            gait = converged_gait(find_contact_periodic_gait(walker, fp.x,
                                                             **search_bounds(cs)))
        except PeriodicGaitError as exc:
            gait_error = exc
    return ContactSimRun(
        walker=walker, result=res, samples=contact_run.named_trajectory(walker, res, LEGS),
        initial_state=x0, step_length_m=step_length, fixed_point=fp.x,
        fixed_point_names=fp.state_names, legs=LEGS,
        rate_names=[" ".join(rate_states(walker, leg)) for leg in LEGS],
        initial_rate_scale=np.asarray(scale if scale is not None else cs.initial_rate_scale),
        stiffness_family=setup.law.stiffness_family,
        drop=drop_test(setup.law, walker.total_mass), drop_speed_m_per_s=DROP_SPEED,
        summary=run_summary(res), gait=gait, gait_error=gait_error, adjust=adj,
        **_step_ledger(walker, res))


def _step_ledger(walker, res) -> dict:
    """A powered run's ledger per step and its columns' units and descriptions (the
    :class:`ContactSimRun` fields), or nothing."""
    if getattr(res, "work", None) is None:
        return {}
    return {"step_ledger": contact_step_ledger(walker, res.t, res.x, res.work,
                                               res.heel_strike_times),
            "step_ledger_units": STEP_LEDGER_UNITS,
            "step_ledger_descriptions": STEP_LEDGER_DESCRIPTIONS}
