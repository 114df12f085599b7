"""A scene's optimal gait when its walker's legs differ: the stride transcription of
:mod:`walkerlab.optimal.stride` set up from the scene, started from one stride of the
scene's gait (``fixedpoint``: the stride map's fixed point), replayed on the rigid model,
the stride map's Floquet multipliers from the replay, and replayed in the contact model
(:func:`walkerlab.optimal.contact_replay.contact_replay_stride`)."""

from __future__ import annotations

import numpy as np

__all__ = ["optimize_stride_scene"]


def _check(o) -> None:
    """Refuse what the stride transcription does not take (one line naming the field)."""
    asked = dict(o.weights or {}) if o.objective == "weighted" else {o.objective: 1.0}
    bad = [k for k in asked if k not in ("effort", "peak_torque")]
    if bad:
        raise ValueError(f"optimize.objective: legs that differ take effort or peak_torque "
                         f"(or their weighted sum) today, not {', '.join(bad)}")
    if o.push_off == "free":
        raise ValueError("optimize.push_off: legs that differ have no push-off today")
    if o.friction_coefficient is not None:
        raise ValueError("optimize.friction_coefficient: not yet for legs that differ")
    if o.initial_guess is not None:
        raise ValueError("optimize.initial_guess: legs that differ start from their own "
                         "gait today")


def optimize_stride_scene(scene, data, spec, x_gait: np.ndarray, period_s: float):
    """Optimise one stride of the scene's walker (legs that differ).

    Parameters
    ----------
    scene : Scene
        With ``optimize`` (objective effort or peak_torque; targets, torque limit,
        clearance, hip angle range).
    data : WalkerData
        The scene's walker (``data.mirror`` the other leg's step).
    spec : walkerlab.optimal.collocation.CollocationSpec
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
        An objective, constraint or guess this transcription does not take, a push-off, or
        the starting gait does not make a stride (one line).
    """
    import time

    from walkerlab.integrate.solver import Solver
    from walkerlab.io.schemas.optimize import OptimizeData
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.contact_replay import contact_replay_stride
    from walkerlab.optimal.phased_collocation import collocate_phases
    from walkerlab.optimal.phased_scene import replay_multipliers
    from walkerlab.optimal.stride import replay_stride, stride_functions, stride_guess

    o = scene.optimize
    _check(o)
    if spec.push_off_n_s:
        raise ValueError("walker.actuation.push_off: legs that differ have no push-off in "
                         "the stride transcription today")
    walker = make_rigid_walker(data)
    guess = stride_guess(walker, x_gait, period_s, Solver.from_settings(scene.solver),
                         spec.intervals)
    t0 = time.perf_counter()
    fns = stride_functions(data)
    build = time.perf_counter() - t0
    res = collocate_phases(fns, spec, guess)
    err, replayed = replay_stride(data, res)
    mu = replay_multipliers(replayed, res, scene, err)  # the stride map's
    contact_period, contact_outcome = float("nan"), "not replayed: the rigid replay failed"
    if np.isfinite(err):
        contact_period, contact_outcome = contact_replay_stride(scene, res, strides=2)
    lengths = [float(p.step(res.x[k - 1])) for k, p in zip(
        [*res.phase_start[2::2], res.t.size], fns["phases"][1::2])]
    names = list(walker.state_names())
    units = dict(zip(names, walker.state_units()))
    return OptimizeData(res.t, {n: res.x[:, k] for k, n in enumerate(names)}, res.u,
                        res.step_period_s / 2, float(np.mean(lengths)), 0.0, res.objective,
                        err, mu, bool(err <= o.replay_tolerance
                                      and res.status == "Solve_Succeeded"),
                        res.status, res.iterations, res.wall_time_s, units,
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


def _unit(objective: str) -> str:
    """The objective's unit (a weighted sum's: ``-``)."""
    from walkerlab.optimal.collocation import OBJECTIVES

    return OBJECTIVES.get(objective, "-")


def _record(scene, walker, res) -> dict:
    """IPOPT's history and the energies at the points, each step's from its own walker
    (leg B's step: the mirror's masses), as :class:`OptimizeData` keywords."""
    from walkerlab.optimal.scene import step_record
    from walkerlab.optimal.stride import step_of

    parts = [step_record(scene, w, step_of(res, k))
             for k, w in enumerate((walker, walker.mirror))]
    out = step_record(scene, walker, res)
    out["energy"] = {kind: np.concatenate([p["energy"][kind] for p in parts])
                     for kind in out["energy"]}
    return out
