"""A five-link biped scene's least-effort step (``walkerlab optimize`` on a walker with free
knees): collocated (:mod:`walkerlab.optimal.transcription.free_joints`), closed by shooting
under its own torques (:mod:`walkerlab.optimal.replay.shooting`), replayed on the rigid
model's generated code, and replayed with the torques as a function of the phase variable
(feed-forward + PD on the collocated joint trajectory, and the feed-forward alone:
:mod:`walkerlab.optimal.replay.virtual_constraints`) on the rigid model and - the PD law - in the
contact model (:func:`walkerlab.optimal.replay.contact.contact_replay_five_link`); stored
as ``optimize.h5``.  Needs no upstream gait: the guess is built from the targets (Kelly
2017's set-up)."""

from __future__ import annotations

__all__ = ["check_targets", "optimize_five_link_scene", "stick_figures"]


def check_targets(o) -> None:
    """Refuse a five-link biped's ``optimize`` section ``o`` without a target (speed, step
    length or step period): the least effort of a free step is a shuffle (RABBIT: a 1 mm
    step at 0.0024 m/s, 1.2e-5 N² m² s), not a gait to optimise; Kelly (2017) fixes the
    step length and period.

    Raises
    ------
    ValueError
        No target (one line saying which fields to give).
    """
    from walkerlab.optimal.guess import has_target

    if not has_target(o):
        raise ValueError("a five-link biped's optimal step needs a target (without one the "
                         "least effort is a 1 mm shuffle): give optimize.target_step_length_m"
                         " and target_step_period_s, or target_speed_m_per_s, as "
                         "configs/rabbit_optimal.yaml (0.5 m in 0.7 s)")


def optimize_five_link_scene(scene):
    """Optimise, close and replay one step of the scene's five-link walker.

    Parameters
    ----------
    scene : Scene
        A walker with free knees (``walker.leg.knee.lock: free``) and an ``optimize``
        section (``intervals``, ``max_torque_n_m``, the targets).

    Returns
    -------
    walkerlab.io.schemas.optimize.OptimizeData
        The collocated states and torques by name; ``replay_error`` the rigid model's
        return error from the closed start; ``gait`` when IPOPT converged, the shooting
        closed and the replay returns within ``optimize.replay_tolerance``;
        ``phase_replays`` the phase-variable laws' rigid replays (``feedback``: closed,
        ``feedforward``: from the collocated start) and ``contact_step_period_s`` the
        contact model's under the feedback law (~35 rigid step maps on the compiled flows,
        and 2 contact strides).

    Raises
    ------
    ValueError
        No target (:func:`check_targets`), a push-off asked for, a walker the five-link
        generator does not handle (one line).
    """
    from walkerlab.io.schemas.optimize import OptimizeData
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.records import not_a_gait_outcome, step_record
    from walkerlab.optimal.replay.shooting import close_step
    from walkerlab.optimal.transcription.free_joint_functions import JOINTS, five_link_functions
    from walkerlab.optimal.transcription.free_joints import collocate_five_link, replay_five_link
    from walkerlab.optimal.transcription.step import CollocationSpec
    from walkerlab.walker.description import walker_data

    o = scene.optimize
    check_targets(o)
    if o.push_off == "free":
        raise ValueError("optimize.push_off: a five-link biped has no push-off (its hips and "
                         "knees are driven)")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    fns = five_link_functions(data.structure)
    spec = CollocationSpec(intervals=o.intervals, max_torque_n_m=o.max_torque_n_m,
                           target_speed_m_per_s=o.target_speed_m_per_s,
                           target_step_length_m=o.target_step_length_m,
                           target_step_period_s=o.target_step_period_s)
    res = collocate_five_link(data, spec, fns)
    closed = close_step(fns, data.params, res.t, res.x, res.u)
    err = float("inf")
    if closed.converged:
        err = replay_five_link(data, res, closed.x0)[0]
    rigid = make_rigid_walker(data, "biped", "derived")
    names = list(rigid.state_names())
    units = dict(zip(names, rigid.state_units()))
    gait = bool(res.status == "Solve_Succeeded" and closed.converged
                and err <= o.replay_tolerance)
    why = "" if gait else (not_a_gait_outcome(err, res.status) if closed.converged else
                           "not replayed: not a gait (the shooting did not close the step)")
    phases, contact = _phase_replays(scene, data, res, why)
    return OptimizeData(
        res.t, {n: res.x[:, k] for k, n in enumerate(names)}, res.u, res.step_period_s,
        res.step_length_m, 0.0, res.objective, err, closed.multipliers, gait, res.status,
        res.iterations, res.wall_time_s, units, torque_names=JOINTS,
        start_shift=closed.shift, replay_step_period_s=closed.period_s,
        collocated_start_error=closed.open_loop_error, cpu_time_s=res.cpu_time_s,
        contact_step_period_s=contact[0], contact_outcome=contact[1], phase_replays=phases,
        **step_record(scene, rigid, res))


#: strides of the contact replay (2 steps each; the first step starts from the rigid state)
CONTACT_STRIDES = 2


def _phase_replays(scene, data, res, not_gait: str = "") -> tuple[dict, tuple[float, str]]:
    """The phase-variable replays
    (:func:`walkerlab.optimal.replay.virtual_constraints.phase_replays`)
    as ``optimize.h5``'s records, and the contact model's ``(step period [s], outcome)``
    under the feed-forward + PD law from its closed start; an optimum that is not a gait
    is not replayed there (``not_gait``: why, the contact outcome)."""
    from walkerlab.optimal.replay.contact import contact_replay_five_link
    from walkerlab.optimal.replay.phase import records
    from walkerlab.optimal.replay.virtual_constraints import phase_replays

    if scene.optimize.phase_replay is False:  # None (the default) or True: replayed
        return {}, (float("nan"), "not replayed: optimize.phase_replay is off (the contact "
                    "replay runs the feed-forward + PD law)")
    try:
        replays, laws = phase_replays(data, res.t, res.x, res.u)
    except ValueError as exc:  # the phase variable is not monotonic: no such replay
        return {}, (float("nan"), f"not replayed: {exc}")
    out = records(replays)
    if not_gait:
        return out, (float("nan"), not_gait)
    fb = replays["feedback"]
    if not fb.closed:
        return out, (float("nan"), "not replayed: the feed-forward + PD law did not close "
                     "on the rigid model")
    contact = contact_replay_five_link(scene, laws["feedback"], fb.x0, fb.step_period_s,
                                       strides=CONTACT_STRIDES)
    return out, contact


#: the stick figure's polyline through the walker's named points
STICK = ("stance_foot", "stance_knee", "hip", "torso_top", "hip", "swing_knee", "swing_foot")


def stick_figures(scene, d, frames: int = 8) -> list:
    """The five-link walker of ``scene`` at ``frames`` instants of the stored step ``d``
    (a loaded ``optimize.h5``): polylines (7, 2) [m] through :data:`STICK` (the torso's
    top: its centre of mass, the generated ``torso_*`` point)."""
    import numpy as np

    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.walker.description import walker_data

    w = make_rigid_walker(walker_data(scene.walker, scene.slope.phi_rad), "biped", "derived")
    names = w.state_names()
    out = []
    for k in np.linspace(0, len(d.time) - 1, frames).round().astype(int):
        pts = w.points(np.array([d.states[n][k] for n in names]))
        top = next(v for key, v in pts.items() if key.startswith("torso_"))
        out.append(np.array([pts[n] if n != "torso_top" else top for n in STICK]))
    return out
