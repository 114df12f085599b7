"""A scene's optimal gait when its walker's legs differ: the stride transcription of
:mod:`walkerlab.optimal.transcription.stride` set up from the scene, started from one stride of the
scene's gait (``fixedpoint``: the stride map's fixed point), of a continuation artifact's
gait or from another stride's ``optimize.h5`` (``optimize.initial_guess``), replayed on the
rigid model,
the stride map's Floquet multipliers from the replay, and replayed in the contact model
(:func:`walkerlab.optimal.replay.contact.contact_replay_stride`)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

__all__ = ["optimize_stride_scene", "starting_stride"]


def _check(o, pushes: bool) -> None:
    """Refuse what the stride transcription does not take (one line naming the field);
    ``pushes``: the stride has a push-off (fixed or free)."""
    from walkerlab.optimal.transcription.mode_sequence import PHASED_OBJECTIVES

    asked = dict(o.weights or {}) if o.objective == "weighted" else {o.objective: 1.0}
    known = PHASED_OBJECTIVES + (("push_off_work",) if pushes else ())
    bad = [k for k in asked if k not in known]
    if bad:
        raise ValueError(f"optimize.objective: legs that differ take "
                         f"{', '.join(known)} (or their weighted sum), not "
                         f"{', '.join(bad)}" + ("" if pushes else " (push_off_work: with a "
                                                "push-off, walker.actuation.push_off or "
                                                "optimize.push_off: free)"))


def starting_stride(scene, walker, x_gait, period_s: float, intervals: int):
    """The stride collocation's start for ``scene``: its ``optimize.initial_guess`` (another
    stride's ``optimize.h5``: its four phases' states and torque; a continuation artifact's
    gait at ``at``: the stride map's start there), else one stride of its gait ``x_gait``
    (2n,) of mean step period ``period_s`` [s]; ``intervals`` a step.

    Returns
    -------
    guess : list of (name, t, x)
        The four phases :data:`walkerlab.optimal.transcription.stride.STRIDE_PHASES`
        (:func:`walkerlab.optimal.transcription.stride.stride_guess`, or
        :func:`walkerlab.optimal.transcription.mode_sequence.optimized_guess` on ``2 intervals``).
    torque : list of ndarray or None
        Each phase's hip torque [N m] (another ``optimize.h5``'s; None: 0).

    Raises
    ------
    ValueError
        An unusable artifact, one of another walker, or one without the stride's phases (a
        one-step optimisation; one line naming ``optimize.initial_guess``); the starting
        gait does not make a stride (one line).
    """
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.guess import read_guess
    from walkerlab.optimal.transcription.mode_sequence import optimized_guess
    from walkerlab.optimal.transcription.stride import STRIDE_PHASES, stride_guess

    kind, got = None, None
    if scene.optimize.initial_guess is not None:
        kind, got = read_guess(scene, list(walker.state_names()))
    if kind == "optimize":
        return optimized_guess(got, list(STRIDE_PHASES), 2 * intervals)
    x0 = got if kind == "continuation" else x_gait
    return stride_guess(walker, x0, period_s, Solver.from_settings(scene.solver),
                        intervals), None


def optimize_stride_scene(scene, data, spec, x_gait: np.ndarray, period_s: float):
    """Optimise one stride of the scene's walker (legs that differ).

    Parameters
    ----------
    scene : Scene
        With ``optimize`` (objective effort, cost_of_transport or peak_torque or their
        weighted sum; targets, torque limit, clearance, hip angle range, friction cone;
        the guess: :func:`starting_stride`).
    data : WalkerData
        The scene's walker (``data.mirror`` the other leg's step).
    spec : walkerlab.optimal.transcription.step.CollocationSpec
        From the ``optimize`` section (``intervals`` per step, shared among its phases).
    x_gait : ndarray (2n,)
        The scene's gait just after heel strike, ``leg1`` about to swing (``fixedpoint.h5``).
    period_s : float
        Its mean step period [s].

    Returns
    -------
    walkerlab.io.schemas.optimize.OptimizeData
        ``time`` over the stride, its four phases; ``step_period`` / ``step_length`` the
        mean step's (each step's duration: the phases'), the replay's return error over the
        stride and the stride map's multipliers.

    Raises
    ------
    ValueError
        An objective this transcription does not take, a push-off, an unusable guess, or
        the starting gait does not make a stride (one line).
    """
    import time

    from walkerlab.io.schemas.optimize import OptimizeData
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.drivers.mode_sequence import replay_multipliers
    from walkerlab.optimal.records import not_a_gait_outcome
    from walkerlab.optimal.replay.contact import contact_replay_stride
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.stride import replay_stride, stride_functions

    o = scene.optimize
    _check(o, bool(spec.push_off_free or spec.push_off_n_s))
    walker = make_rigid_walker(data)
    guess, guess_u = starting_stride(scene, _guide(walker, data, spec), x_gait, period_s,
                                     spec.intervals)
    t0 = time.perf_counter()
    fns = stride_functions(data)
    build = time.perf_counter() - t0
    res = collocate_phases(fns, replace(spec, warm_start=guess_u is not None), guess,
                           guess_u)
    err, replayed = replay_stride(data, res)
    mu = replay_multipliers(replayed, res, scene, err)  # the stride map's
    gait = bool(err <= o.replay_tolerance and res.status == "Solve_Succeeded")
    contact_period, contact_outcome = float("nan"), not_a_gait_outcome(err, res.status)
    if gait:  # the contact model replays a gait only
        contact_period, contact_outcome = contact_replay_stride(scene, res, strides=2)
    lengths = [float(p.step(res.x[k - 1])) for k, p in zip(
        [*res.phase_start[2::2], res.t.size], fns["phases"][1::2])]
    names = list(walker.state_names())
    units = dict(zip(names, walker.state_units()))
    return OptimizeData(res.t, {n: res.x[:, k] for k, n in enumerate(names)}, res.u,
                        res.step_period_s / 2, float(np.mean(lengths)), res.push_off_n_s,
                        res.objective,
                        err, mu, gait, res.status, res.iterations, res.wall_time_s, units,
                        objective_name=o.objective,
                        objective_unit=_unit(o.objective), terms=res.terms,
                        contact_step_period_s=contact_period,
                        contact_outcome=contact_outcome, cpu_time_s=res.cpu_time_s,
                        phase_names=res.phase_names, phase_start=res.phase_start,
                        phase_duration_s=res.phase_duration_s,
                        build_time_s=build + res.build_time_s, steps=2,
                        phase_replay_outcome="not replayed: a stride of legs that differ is "
                        "replayed as a function of time only" if o.phase_replay else "",
                        **_record(scene, walker, res))


def _guide(walker, data, spec):
    """The walker that steps the starting stride: ``walker``, with the scene's push-off
    (``spec.push_off_n_s`` > 0) before each heel strike when it has one (its gait, from
    ``fixedpoint``, is the pushed walker's)."""
    if not spec.push_off_n_s:
        return walker
    from walkerlab.config.actuation import Actuation, PushOff
    from walkerlab.models.hybrid.actuated import actuate

    return actuate(walker, data, Actuation(push_off=PushOff(impulse_n_s=spec.push_off_n_s)))


def _unit(objective: str) -> str:
    """The objective's unit (a weighted sum's: ``-``)."""
    from walkerlab.optimal.transcription.step import OBJECTIVES

    return OBJECTIVES.get(objective, "-")


def _record(scene, walker, res) -> dict:
    """IPOPT's history and the energies at the points, each step's from its own walker
    (leg B's step: the mirror's masses), as :class:`OptimizeData` keywords."""
    from walkerlab.optimal.records import step_record
    from walkerlab.optimal.transcription.stride import step_of

    parts = [step_record(scene, w, step_of(res, k))
             for k, w in enumerate((walker, walker.mirror))]
    out = step_record(scene, walker, res)
    out["energy"] = {kind: np.concatenate([p["energy"][kind] for p in parts])
                     for kind in out["energy"]}
    return out
