"""A contact run: integrate the compliant-contact walker, then read its gait (``contact-sim``).

:func:`simulate_contact` = :func:`walkerlab.integrate.contact.integrate_contact` (samples,
events) + :func:`walkerlab.analysis.contact.gait.gait_events` (heel strikes, steps) + the
typed outcome.  :func:`simulate_from` runs the contact walker of a scene (its
:class:`~walkerlab.models.contact.scene.ContactSetup`) from the ideal gait, the one code
path of the ``contact-sim`` stage, the adjustment
(:mod:`walkerlab.analysis.contact.adjust`), the sweeps and the work-precision study, so a
scene means the same contact run everywhere.  States are read by name
(``walker.state_names()``), never by row.  Where a run starts from the rigid gait is
:mod:`walkerlab.analysis.contact.start`, its samples in the shared named layout
:mod:`walkerlab.analysis.contact.named` (their names re-exported here).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from walkerlab.analysis.contact.gait import gait_events, heel_strike_count
from walkerlab.analysis.contact.named import named_trajectory, trajectory_names
from walkerlab.analysis.contact.result import ContactResult
from walkerlab.analysis.contact.start import initial_state_from_ideal, rigid_mid_stance
from walkerlab.analysis.contact.terrain_fit import patch_fit
from walkerlab.analysis.contact.verdict import classify, scuff_cause
from walkerlab.config.solver import SolverSettings
from walkerlab.integrate.contact import ContactLimits, integrate_contact
from walkerlab.integrate.ends import RunEnd
from walkerlab.integrate.solver import Solver
from walkerlab.models.contact.scene import ContactSceneError, ContactSetup
from walkerlab.models.ground import FALL_HIP_FRACTION

__all__ = ["AIRBORNE_HEIGHT_FACTOR", "initial_state_from_ideal", "named_trajectory",
           "rigid_mid_stance", "scene_start", "simulate_contact", "simulate_from",
           "trajectory_names"]

#: A walker whose hip rises above this many leg lengths has left the ground for good
#: (a foot can touch the ground only while the hip is within one leg length of it).
AIRBORNE_HEIGHT_FACTOR = 1.5


def simulate_contact(walker, x0: np.ndarray, t_final: float,
                     solver: Solver | SolverSettings | None = None,
                     limits: ContactLimits | None = None, *,
                     max_heel_strikes: int | None = None, slip_limit_mm: float | None = None,
                     min_step_m: float = 0.05, initial_stance: str = "leg2",
                     t_more: float | None = None) -> ContactResult:
    """Simulate the floating walker with compliant feet and classify its gait.

    Parameters
    ----------
    walker : ContactWalker
    x0 : ndarray (N,)
        Initial state, named by ``walker.state_names()`` (SI).
    t_final : float
        End time [s].
    solver : Solver or SolverSettings, optional
        The integrator, as one object (default: ``SolverSettings.for_contact()``, cyrk_bdf at
        rtol 1e-8, atol 1e-10); the scene's settings become a :class:`Solver` here.
    limits : ContactLimits, optional
        Sampling, pinning, event heights, wall-time limit, chunking.  A
        ``fall_hip_height_m`` / ``airborne_hip_height_m`` left at its default is set to 0.5
        / :data:`AIRBORNE_HEIGHT_FACTOR` leg lengths.
    max_heel_strikes : int, optional
        Strides cap: stop (termination and outcome ``heel_strike``) at the end of the chunk
        in which this many heel strikes have happened.  A run that ends in a trip, fall,
        flight, solver failure or the wall-time limit after ``max_heel_strikes - 1`` heel
        strikes (the strides asked for) ends by the cap too, its end named in the message
        and in :attr:`~walkerlab.analysis.contact.verdict.Outcome.after` (a trip, fall or
        flight there makes :func:`~walkerlab.analysis.contact.verdict.walk_verdict` say the run
        does not walk).  A trip, fall or scuff on a checkerboard whose patches the footfalls
        drifted off adds :meth:`~walkerlab.analysis.contact.terrain_fit.PatchFit.note` to the
        message.
    slip_limit_mm : float, optional
        A stance phase sliding farther than this [mm] makes the outcome ``slip``.
    min_step_m : float
        A touchdown of the swing foot counts as a heel strike only if it lands at least this
        far [m] downhill of the stance foot's touchdown point (else it is a scuff).
    initial_stance : str
        The foot in stance at the start.
    t_more : float, optional
        With ``max_heel_strikes``: a run that reaches ``t_final`` [s] short of the strides
        asked for (fewer than ``max_heel_strikes - 1`` heel strikes: contact steps slower
        than the rigid ones the end time was sized by) goes on from there until the cap or
        ``t_more`` [s] (the samples up to
        ``t_final`` are those of the run without it).  Not for a powered walker (its stance
        leg is a state of one run): it gets ``t_more`` as its end time at once.

    Returns
    -------
    ContactResult

    Raises
    ------
    ValueError
        Unknown method; ``max_step_s`` with numbalsoda; numbalsoda not installed.
    """
    solver = Solver.from_settings(solver or SolverSettings.for_contact())
    limits = _with_heights(walker, limits or ContactLimits())
    stop = after = None
    if max_heel_strikes is not None:
        def stop(t, X):
            return heel_strike_count(walker, t, X, min_step_m, initial_stance) \
                >= max_heel_strikes
    powered = getattr(walker, "actuators", None) is not None
    if powered and t_more is not None and stop is not None:
        t_final = max(t_final, t_more)
    run = integrate_contact(walker, x0, 0.0, t_final, solver, limits, stop)
    if (t_more is not None and stop is not None and not powered
            and run.termination == "t_final" and t_more > t_final
            and heel_strike_count(walker, run.t, run.X, min_step_m, initial_stance)
            < max_heel_strikes - 1):  # short of the strides asked for (2 N heel strikes)
        run = _go_on(walker, run, t_more, solver, limits, stop)
    if stop is not None and (run.event is not None or run.termination in _EVENTLESS_ENDS):
        run, after = _strides_then_end(walker, run, min_step_m, initial_stance,
                                       max_heel_strikes)
    ev = gait_events(walker, run.t, run.X, min_step_m, initial_stance)
    out = _run_outcome(walker, run, ev, after, limits, slip_limit_mm, initial_stance)
    return _contact_result(walker, run, ev, out, solver.method)


def _contact_result(walker, run, ev, out, method: str) -> ContactResult:
    """The :class:`ContactResult` of the integration ``run``, its gait events ``ev``
    (:func:`gait_events`) and outcome ``out``."""
    return ContactResult(t=run.t, x=run.X, state_names=tuple(walker.state_names()),
                         feet=ev["feet"], heel_strike_times=ev["hs_t"],
                         heel_strike_legs=ev["hs_leg"], steps=ev["steps"],
                         termination=run.termination, message=run.message, nfev=run.nfev,
                         njev=run.njev, wall_time_s=run.wall_time_s, method=method,
                         pin_end_time=run.pin_end_time, outcome=out, points=ev["points"],
                         work=run.work)


def _strides_then_end(walker, run, min_step_m, initial_stance, max_heel_strikes):
    """``(run, after)``: a run that made the strides asked for (2 N heel strikes; the cap
    stops at the one after) before its event, solver failure or wall-time limit made its
    promise, its end comes after it: the run cut at them, and the end that followed
    (``(termination, time [s], message)``, kept to name; ``(run, None)`` when none did)."""
    def made(t, X):
        return heel_strike_count(walker, t, X, min_step_m, initial_stance) \
            >= max_heel_strikes - 1
    before = run
    run = _made_before_event(run, made) if run.event is not None \
        else _made_before_end(run, made)
    after = None
    if run is not before:  # the end that followed the strides asked for, kept to name
        after = (before.termination, float(before.event[2]) if before.event is not None
                 else float(before.t[-1]), before.message)
    return run, after


def _run_outcome(walker, run, ev, after, limits, slip_limit_mm, initial_stance):
    """The run's typed outcome (:func:`walkerlab.analysis.contact.verdict.classify`) from
    its termination and steps ``ev`` (:func:`gait_events`), with the end that followed the
    strides asked for (``after``) and, when the footfalls left the patches, the
    checkerboard's note (:meth:`walkerlab.analysis.contact.terrain_fit.PatchFit.note`)."""
    hh = float(walker.hip_height(run.X[-1:])[0])
    how = walker.fall_how(run.X[-1]) if run.termination == "fall" else ""
    out = classify(run.termination, run.event, run.t, hh, ev["steps"], run.message, limits,
                   slip_limit_mm, limits.wall_time_limit_s, scuff_cause(walker), how)
    if after is not None:
        out = _named_after(out, after, ev, hh)
    # a walker in 3D that capsized sideways went down across its patches, not off them
    if (out.after or out.kind in _OFF_THE_PATCHES) and not how.startswith("capsized"):
        fit = patch_fit(walker, run.t, ev["feet"], ev["hs_t"], ev["hs_leg"], initial_stance)
        note = fit.note() if fit is not None else ""
        if note:
            out = replace(out, message=f"{out.message}; {note}")
    return out


#: the ends without an event that a run met after its strides asked for still ends by the cap
_EVENTLESS_ENDS = (RunEnd.SOLVER_FAILURE.value, RunEnd.TIME_LIMIT.value,
                   RunEnd.WORK_LIMIT.value)
#: outcomes a checkerboard laid out for another step can cause (its fit is then named)
_OFF_THE_PATCHES = ("trip", "fall", "scuff")
#: how the end that followed the strides asked for reads after "then"
_AFTER_WORDS = {"trip": "tripped", "fall": "fell", "airborne": "left the ground",
                "solver_failure": "the solver failed", "time_limit": "the wall time ran out",
                "work_limit": "the work bound ran out"}
#: a foot this far [m] below the ground line over a gap at the run's end fell into it
_IN_A_GAP_M = 0.01


def _named_after(out, after, ev, hip_height_m: float):
    """The outcome ``out`` of a run ended by its strides cap with the end that followed the
    strides asked for (``after``: termination, time [s], the integration's message) named:
    :attr:`Outcome.after` and its time, and the message "walked: ..., then fell into a gap
    ..." (a foot more than :data:`_IN_A_GAP_M` below the ground line over a gap at the end)."""
    kind, t_after, msg = after
    low = [(float(ft.penetration[-1]), name) for name, ft in ev["feet"].items()
           if not ft.on_ground[-1] and ft.penetration[-1] > _IN_A_GAP_M]
    what = _AFTER_WORDS.get(kind, kind.replace("_", " "))
    if low and kind in ("trip", "fall"):
        feet = " and ".join(f"{name} {depth:.3f} m" for depth, name in sorted(low)[::-1])
        what = f"fell into a gap ({feet} below the ground line)"
    what = f"{what} at t = {t_after:.4g} s"
    return replace(out, after=kind, after_time_s=t_after, after_message=what,
                   message=f"{out.message}, then {what}, hip {hip_height_m:.3f} m above the "
                   f"ground (after the strides asked for: {msg})")


def _made_before_event(run, stop):
    """A run whose strides cap was met before the event (trip, fall, flight) that ended the
    chunk it was met in: cut before the event, ended by the cap (the event is named in the
    message)."""
    k = max(int(run.event[1]), 1)
    if not stop(run.t[:k], run.X[:k]):
        return run
    msg = (f"the heel strikes asked for were made; a {run.event[0]} followed at "
           f"t = {float(run.event[2]):.4g} s (after the last of them: not part of the run)")
    return replace(run, t=run.t[:k], X=run.X[:k], event=None, termination="heel_strike",
                   message=msg, work=None if run.work is None else run.work[:k])


def _made_before_end(run, stop):
    """A run whose strides cap was met before the solver failed or the wall-time limit ran
    out (in the chunk after the cap's heel strikes, or, powered, in the step after them:
    its stop is asked at touchdowns, which it counts once samples follow them): ended by
    the cap, the failure named in the message.  Every sample is kept: the run's samples
    end where the solver last succeeded."""
    if not stop(run.t, run.X):
        return run
    msg = (f"the heel strikes asked for were made; a {run.termination.replace('_', ' ')} "
           f"followed ({run.message}; after the last of them: not part of the run)")
    return replace(run, termination="heel_strike", message=msg)


def _go_on(walker, run, t_more: float, solver, limits, stop):
    """``run`` (ended at its end time short of the strides cap) continued from its last
    sample until the cap or ``t_more`` [s]; the cap counts the heel strikes of both parts."""
    t0, X0 = run.t, run.X

    def stop_all(t, X):
        return stop(np.concatenate([t0, t[1:]]), np.vstack([X0, X[1:]]))

    more = integrate_contact(walker, X0[-1], float(t0[-1]), t_more, solver, limits, stop_all)
    event = more.event
    if event is not None:  # sample indices of the combined run
        event = (event[0], event[1] + len(t0) - 1, *event[2:])
    return replace(more, t=np.concatenate([t0, more.t[1:]]), X=np.vstack([X0, more.X[1:]]),
                   nfev=run.nfev + more.nfev, njev=run.njev + more.njev, event=event,
                   wall_time_s=run.wall_time_s + more.wall_time_s,
                   pin_end_time=run.pin_end_time)


def _with_heights(walker, limits: ContactLimits) -> ContactLimits:
    """``limits`` with default event heights taken from the walker's leg length."""
    d = ContactLimits()
    upd = {}
    if limits.fall_hip_height_m == d.fall_hip_height_m:
        upd["fall_hip_height_m"] = FALL_HIP_FRACTION * walker.L
    if limits.airborne_hip_height_m == d.airborne_hip_height_m:
        upd["airborne_hip_height_m"] = AIRBORNE_HEIGHT_FACTOR * walker.L
    return replace(limits, **upd)


def scene_start(setup: ContactSetup, x_ideal: np.ndarray, n_strides: int, rate_scale=None,
                step_length_m: float | None = None):
    """The contact walker of a scene, its initial state and run limits (the start of
    :func:`simulate_from`, shared with the benchmark).

    Parameters
    ----------
    setup : ContactSetup
        The scene's contact model (:func:`walkerlab.models.contact.scene.contact_setup`).
    x_ideal : ndarray (n,)
        Ideal post-impact state (rigid walker's ``state_names()`` order) [rad, rad/s]; the
        patches are laid from it, and the run starts from it, or with ``contact_sim.start:
        mid_stance`` from the rigid gait's mid-stance that follows it
        (:func:`rigid_mid_stance`), plus ``contact_sim.start_offset``.
    n_strides : int
        Strides the run may take (patches are laid out for them).
    rate_scale : (float, float), optional
        Multipliers on the initial rates (default ``contact_sim.initial_rate_scale``).
    step_length_m : float, optional
        Patch spacing [m] instead of the ideal step length of ``x_ideal``
        (:meth:`ContactSetup.build`).

    Returns
    -------
    walker, x0, limits, step_length
        :class:`ContactWalker`, the initial state (N,), :class:`ContactLimits` from the
        scene's ``contact_sim`` section, the ideal step length [m] (footholds of several
        heights: the mean of the rigid gait's steps, whose footfalls the patches lie at,
        :func:`walkerlab.analysis.contact.footfalls.rigid_step_lengths`).
    """
    cs = setup.sim
    lengths = None
    if step_length_m is None and setup.steps_differ:  # the rigid period-n gait's footfalls
        from walkerlab.analysis.contact.footfalls import rigid_step_lengths

        lengths = rigid_step_lengths(setup.scene, setup.model(), x_ideal, setup.plant)
    walker, step_length = setup.build(x_ideal, 2 * n_strides, step_length_m, lengths)
    scale = cs.initial_rate_scale if rate_scale is None else rate_scale
    x_start = (rigid_mid_stance(setup.scene, x_ideal, setup.plant)
               if cs.start == "mid_stance" else x_ideal)
    if cs.start_offset is not None:  # a change to the start (the patches stay)

        try:
            dx = cs.start_offset.as_array(list(walker.rigid_layout().names))
        except ValueError as exc:
            raise ContactSceneError(f"scene '{setup.scene.name}': contact_sim.start_offset."
                                    f"{exc}") from None
        x_start = np.asarray(x_start, float) + dx
    x0 = initial_state_from_ideal(walker, *np.asarray(x_start, float), rate_scale=tuple(scale))
    limits = ContactLimits(
        sample_rate_hz=cs.sample_rate_hz, pin_stance_until=cs.pin_stance_until,
        pin_time_s=cs.pin_time_s,
        fall_hip_height_m=cs.fall_hip_height_m or ContactLimits().fall_hip_height_m,
        wall_time_limit_s=cs.wall_time_limit_s, max_rhs_evaluations=cs.max_rhs_evaluations)
    return walker, x0, limits, step_length


def simulate_from(setup: ContactSetup, x_ideal: np.ndarray, period: float, rate_scale=None,
                  solver: SolverSettings | None = None, strides: int | None = None):
    """Run the contact walker of a scene from the ideal fixed point ``x_ideal``.

    Parameters
    ----------
    setup : ContactSetup
        The scene's contact model (:func:`walkerlab.models.contact.scene.contact_setup`).
    x_ideal : ndarray (n,)
        Ideal post-impact state in the rigid walker's ``state_names()`` order (leg1 = swing,
        leg2 = stance) [rad, rad/s].
    period : float
        Ideal step period [s] (sets the default simulated time).
    rate_scale : (float, float), optional
        Multipliers on the initial rates (default ``contact_sim.initial_rate_scale``).
    solver : SolverSettings, optional
        Default: the scene's ``contact_solver``.
    strides : int, optional
        Strides to simulate (default ``contact_sim.n_strides``).

    Returns
    -------
    walker, result, x0, step_length
        :class:`ContactWalker`, :class:`ContactResult`, the initial state (N,), the ideal
        step length [m].  On footholds a run that left the patches at the rigid footfalls (a
        trip, fall or scuff) is run again on patches at its own footfalls
        (:func:`_at_own_footfalls`): the walker and result are the last run's.
    """
    cs, sv = setup.sim, solver or setup.solver
    n_strides = strides or cs.n_strides
    walker, x0, limits, step_length = scene_start(setup, x_ideal, n_strides, rate_scale)
    # from mid-stance the first heel strike comes half a step in: one step more
    t_final = cs.t_final_s or (2 * n_strides + (1.5 if cs.start == "mid_stance" else 0.5)
                               ) * period
    # without an end time of its own, a run whose contact steps are slower than the rigid
    # ones goes on until its strides are made (or twice the rigid strides' time)
    t_more = 2.0 * t_final if cs.t_final_s is None else None
    cap = 2 * n_strides + 1 if cs.stop_after_strides else None
    res = simulate_contact(walker, x0, t_final, sv, limits, max_heel_strikes=cap,
                           t_more=t_more)
    if setup.patches_follow_feet:  # footholds: where the feet land
        walker, res = _at_own_footfalls(setup, walker, res, lambda w: simulate_contact(
            w, x0, t_final, sv, limits, max_heel_strikes=cap, t_more=t_more))
    return walker, res, x0, step_length


def _at_own_footfalls(setup: ContactSetup, walker, res, run):
    """``(walker, res)`` of a run on footholds that left the patches laid at the rigid
    gait's footfalls (a trip, fall or scuff): run ``run(walker)`` again with
    the patches moved to its own footfalls
    (:func:`walkerlab.analysis.contact.footfalls.own_footfall_lanes`), up to
    :data:`~walkerlab.analysis.contact.footfalls.MAX_RELAYS` times while each walks further
    (more heel strikes); the last that did is kept."""
    from walkerlab.analysis.contact.footfalls import MAX_RELAYS, own_footfall_lanes
    from walkerlab.models.contact.terrain import ground_drops

    period = len(ground_drops(setup.terrain))
    for _ in range(MAX_RELAYS):
        if res.outcome.kind not in _OFF_THE_PATCHES:
            break
        moved = own_footfall_lanes(walker, res, period)
        if moved is None:
            break
        again = run(moved)
        if len(again.heel_strike_times) <= len(res.heel_strike_times):
            break
        walker, res = moved, again
    return walker, res
