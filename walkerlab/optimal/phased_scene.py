"""A scene's optimal gait when its walker's step is a sequence of phases (a kneed walker,
flat feet):
the transcription of :mod:`walkerlab.optimal.phased_collocation` set up from the scene,
started from one step of the scene's gait, replayed on the rigid model, its Floquet
multipliers from the replay, and replayed in the contact model (2 strides; a kneed walker's
hip torque acts between its thighs; flat feet are not replayed yet)."""

from __future__ import annotations

import numpy as np

__all__ = ["optimize_phased_scene"]


def optimize_phased_scene(scene, data, spec, x_gait: np.ndarray, period_s: float):
    """Optimise one step of the scene's walker phase by phase.

    Parameters
    ----------
    scene : Scene
        With ``optimize`` (its ``initial_guess`` unset: the scene's gait is the guess).
    data : WalkerData
        The scene's walker.
    spec : walkerlab.optimal.collocation.CollocationSpec
        From the ``optimize`` section (``intervals`` shared among the phases:
        :func:`walkerlab.optimal.phased_collocation.phased_guess`).
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

    from walkerlab.integrate.solver import Solver
    from walkerlab.io.schemas.optimize import OptimizeData
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.contact_replay import contact_replay_phased
    from walkerlab.optimal.phased_collocation import (
        collocate_phases,
        phase_torque_of_time,
        phased_guess,
        replay_phases,
    )
    from walkerlab.optimal.phases import mode_functions, phase_order
    from walkerlab.optimal.scene import phase_replays, step_record

    o = scene.optimize
    if o.initial_guess is not None:
        raise ValueError("optimize.initial_guess: a walker with phases starts from its own "
                         "gait today")
    walker = make_rigid_walker(data)
    guess, log = phased_guess(walker, x_gait, period_s, Solver.from_settings(scene.solver),
                              spec.intervals)
    t0 = time.perf_counter()
    fns = mode_functions(data, walker, phase_order(walker, log))
    build = time.perf_counter() - t0
    res = collocate_phases(fns, spec, guess)
    err, replayed = replay_phases(data, res)
    mu = _multipliers(replayed, res, scene, err)
    contact_period, contact_outcome = float("nan"), "not replayed: the rigid replay failed"
    if np.isfinite(err):
        contact_period, contact_outcome = contact_replay_phased(scene, res, strides=2)
    phases, phase_note = phase_replays(scene, data, res, phase_torque_of_time(res))
    names = list(walker.state_names())
    units = dict(zip(names, walker.state_units()))
    return OptimizeData(res.t, {n: res.x[:, k] for k, n in enumerate(names)}, res.u,
                        res.step_period_s, res.step_length_m, 0.0, res.objective, err, mu,
                        bool(err <= o.replay_tolerance and res.status == "Solve_Succeeded"),
                        res.status, res.iterations, res.wall_time_s, units,
                        objective_name=o.objective, objective_unit=_unit(o.objective),
                        terms=res.terms, contact_step_period_s=contact_period,
                        contact_outcome=contact_outcome,
                        cpu_time_s=res.cpu_time_s, phase_names=res.phase_names,
                        phase_start=res.phase_start, phase_duration_s=res.phase_duration_s,
                        build_time_s=build + res.build_time_s,
                        phase_replays=phases, phase_replay_outcome=phase_note,
                        **step_record(scene, walker, res))


def _unit(objective: str) -> str:
    """The objective's unit (a weighted sum's: ``-``)."""
    from walkerlab.optimal.collocation import OBJECTIVES

    return OBJECTIVES.get(objective, "-")


def _multipliers(replayed, res, scene, err: float) -> np.ndarray:
    """The replay map's Floquet multipliers at the start (variational equations +
    saltation; NaN when the replay failed)."""
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
