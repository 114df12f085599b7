"""A scene's optimal gait when its walker's step is a sequence of phases (a kneed walker,
flat feet):
the transcription of :mod:`walkerlab.optimal.transcription.mode_sequence` set up from the scene,
started from one step of the scene's gait, replayed on the rigid model, its Floquet
multipliers from the replay, and replayed in the contact model (2 strides; the hip torque
acts between a kneed walker's thighs, between a flat-footed walker's legs)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

__all__ = ["optimize_phased_scene", "replay_multipliers", "starting_phases"]


def optimize_phased_scene(scene, data, spec, x_gait: np.ndarray, period_s: float):
    """Optimise one step of the scene's walker phase by phase.

    Parameters
    ----------
    scene : Scene
        With ``optimize``: the guess is one step of the scene's gait, of a continuation
        artifact's gait (``initial_guess`` with ``at``) or another ``optimize.h5`` of the
        walker with the same phases (its states and torque).
    data : WalkerData
        The scene's walker.
    spec : walkerlab.optimal.transcription.step.CollocationSpec
        From the ``optimize`` section (``intervals`` shared among the phases:
        :func:`walkerlab.optimal.transcription.mode_sequence.phased_guess`).
    x_gait : ndarray (2n,)
        The scene's gait just after heel strike (``fixedpoint.h5``).
    period_s : float
        Its step period [s].

    Returns
    -------
    walkerlab.io.schemas.optimize.OptimizeData
        With the phases (names, first points, durations).

    Raises
    ------
    ValueError
        An objective, constraint or guess the phased transcription does not take, or the
        starting gait does not make a step (one line).
    """
    import time

    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.io.schemas.optimize import OptimizeData
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.records import not_a_gait_outcome, phase_replays, step_record
    from walkerlab.optimal.replay.contact import contact_replay_phased
    from walkerlab.optimal.transcription.mode_sequence import (
        collocate_phases,
        phase_torque_of_time,
        replay_phases,
    )
    from walkerlab.optimal.transcription.step_cache import cached_mode_functions

    o = scene.optimize
    _refuse(scene)
    walker = make_rigid_walker(data, double_support=False)  # no double support phases yet
    if data.structure.foot == "flat":  # fixedpoint's gait has its double support
        g = solve_scene(scene, False, walker=walker)[1].gait.result
        x_gait, period_s = g.x, float(g.period_s)
    guess, guess_u, order = starting_phases(scene, walker, x_gait, period_s, spec.intervals)
    t0 = time.perf_counter()
    fns = cached_mode_functions(data, walker, order)
    build = time.perf_counter() - t0
    res = collocate_phases(fns, replace(spec, warm_start=guess_u is not None), guess,
                           guess_u)
    err, replayed = replay_phases(data, res)
    mu = replay_multipliers(replayed, res, scene, err)
    gait = bool(err <= o.replay_tolerance and res.status == "Solve_Succeeded")
    contact_period, contact_outcome = float("nan"), not_a_gait_outcome(err, res.status)
    if gait:  # the contact model replays a gait only
        contact_period, contact_outcome = contact_replay_phased(scene, res, strides=2)
    phases, phase_note = phase_replays(scene, data, res, phase_torque_of_time(res))
    names = list(walker.state_names())
    units = dict(zip(names, walker.state_units()))
    return OptimizeData(res.t, {n: res.x[:, k] for k, n in enumerate(names)}, res.u,
                        res.step_period_s, res.step_length_m, 0.0, res.objective, err, mu,
                        gait,
                        res.status, res.iterations, res.wall_time_s, units,
                        objective_name=o.objective, objective_unit=_unit(o.objective),
                        terms=res.terms, contact_step_period_s=contact_period,
                        contact_outcome=contact_outcome,
                        cpu_time_s=res.cpu_time_s, phase_names=res.phase_names,
                        phase_start=res.phase_start, phase_duration_s=res.phase_duration_s,
                        build_time_s=build + res.build_time_s,
                        phase_replays=phases, phase_replay_outcome=phase_note,
                        **step_record(scene, walker, res))


def _refuse(scene) -> None:
    """Refuse an actuator the phased transcription does not model (one line)."""
    act = getattr(scene.walker, "actuation", None)
    if act is not None and getattr(act, "ankle_push_off", None) is not None:
        raise ValueError("walker.actuation.ankle_push_off: the phased transcription has a hip "
                         "torque only (the rigid flat feet take an ankle push-off or hip "
                         "torques, not together)")


def starting_phases(scene, walker, x_gait, period_s: float, intervals: int):
    """The phased collocation's starting step for ``scene`` (its ``optimize.
    initial_guess``, else one step of its gait ``x_gait`` (2n,) of period ``period_s``
    [s]), on about ``intervals`` intervals.

    Returns
    -------
    guess : list of (name, t, x)
        :func:`walkerlab.optimal.transcription.mode_sequence.phased_guess` (the scene's or a
        continuation artifact's gait) or :func:`~walkerlab.optimal.transcription.mode_sequence.
        optimized_guess` (another ``optimize.h5``).
    torque : list of ndarray or None
        Each phase's hip torque [N m] (another ``optimize.h5``'s; None: 0).
    order : list of (phase, guard, direction)
        The phases the starting gait's step goes through
        (:func:`walkerlab.optimal.transcription.phases.phase_order`).

    Raises
    ------
    ValueError
        An unusable artifact, or one whose phases are not the gait's (one line naming
        ``optimize.initial_guess``).
    """
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.guess import read_guess
    from walkerlab.optimal.transcription.mode_sequence import optimized_guess, phased_guess
    from walkerlab.optimal.transcription.phases import phase_order

    kind, got = None, None
    if scene.optimize.initial_guess is not None:
        kind, got = read_guess(scene, list(walker.state_names()))
    x0 = got if kind == "continuation" else x_gait
    guess, log = phased_guess(walker, x0, period_s, Solver.from_settings(scene.solver),
                              intervals)
    order = phase_order(walker, log)
    if kind != "optimize":
        return guess, None, order
    return (*optimized_guess(got, [n for n, _g, _d in order], intervals), order)


def _unit(objective: str) -> str:
    """The objective's unit (a weighted sum's: ``-``)."""
    from walkerlab.optimal.transcription.step import OBJECTIVES

    return OBJECTIVES.get(objective, "-")


def replay_multipliers(replayed, res, scene, err: float) -> np.ndarray:
    """The replay map's Floquet multipliers at the start (variational equations +
    saltation through every phase, or both steps of a stride).

    Parameters
    ----------
    replayed : HybridWalker
        The rigid walker under the optimised torques.
    res : PhasedResult
        The optimum (its start ``res.x[0]``, shape (n,), and ``step_period_s`` [s]).
    scene : Scene
        Its ``solver`` integrates the map.
    err : float
        The replay's return error (NaN: the replay failed).

    Returns
    -------
    ndarray, shape (n,), complex
        The multipliers, NaN when the replay or the map failed (a report, not a gate).
    """
    from walkerlab.analysis.gait.poincare import poincare_map
    from walkerlab.integrate.solver import Solver

    mu = np.full(res.x.shape[1], np.nan, complex)
    if not np.isfinite(err):
        return mu
    try:
        DP = poincare_map(replayed, res.x[0], Solver.from_settings(scene.solver),
                          max_step_time=3.0 * res.step_period_s, jacobian=True)[2]
        return np.linalg.eigvals(DP).astype(complex)
    except Exception:  # noqa: BLE001 - the replay's multipliers are a report, not a gate
        return mu
