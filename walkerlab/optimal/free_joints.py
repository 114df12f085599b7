"""The optimal step of a five-link biped (free knees, a torso: the ``free_joints`` kind's
part of :data:`walkerlab.optimal.driver.PARTS`): collocated with its four joint torques from
the targets (Kelly 2017's set-up), closed by shooting, replayed on the rigid model, as
phase-variable laws and in the contact model; and the stick figures of a stored step.
"""

from __future__ import annotations

import numpy as np

from walkerlab.io.schemas.optimize import OptimizeData
from walkerlab.models.hybrid.rigid import make_rigid_walker
from walkerlab.optimal.outcome import history_and_energies, named_states, not_a_gait_outcome
from walkerlab.optimal.replay.contact import contact_replay_five_link
from walkerlab.optimal.replay.shooting import close_step
from walkerlab.optimal.replay.virtual_constraints import phase_replays
from walkerlab.optimal.transcription.free_joint_functions import JOINTS, five_link_functions
from walkerlab.optimal.transcription.free_joints import collocate_five_link, replay_five_link
from walkerlab.optimal.transcription.step import CollocationSpec

__all__ = ["CONTACT_STRIDES", "STICK", "five_link_replays", "optimize_five_link",
           "stick_figures"]


#: strides of the five-link contact replay (2 steps each; the first from the rigid state)
CONTACT_STRIDES = 2


def optimize_five_link(scene, plant, x_gait=None, period_s=None) -> OptimizeData:
    """Optimise, close and replay one step of the scene's five-link walker: collocated
    (:mod:`walkerlab.optimal.transcription.free_joints`, its four joint torques), closed by
    shooting under its own torques (:mod:`walkerlab.optimal.replay.shooting`), replayed on
    the rigid model's generated code, and with the torques as a function of the phase
    variable (feed-forward + PD, and the feed-forward alone:
    :mod:`walkerlab.optimal.replay.virtual_constraints`) on the rigid model and - the PD
    law - in the contact model (~35 rigid step maps and 2 contact strides).  Needs no
    upstream gait: the guess is built from the targets (Kelly 2017's set-up), which the
    driver requires first (:func:`walkerlab.optimal.driver.check_targets`).  ``plant``:
    the scene's :class:`~walkerlab.walker.plant.Plant`.

    Raises
    ------
    ValueError
        A walker the five-link generator does not handle (one line).
    """
    data = plant.data  # the scene's walker, described once (walkerlab.walker.plant.Plant)
    o = scene.optimize
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
    gait = bool(res.status == "Solve_Succeeded" and closed.converged
                and err <= o.replay_tolerance)
    why = "" if gait else (not_a_gait_outcome(err, res.status) if closed.converged else
                           "not replayed: not a gait (the shooting did not close the step)")
    phases, contact = five_link_replays(scene, plant, res, why)
    states, units = named_states(rigid, res)
    return OptimizeData(
        res.t, states, res.u, res.step_period_s, res.step_length_m, 0.0, res.objective, err,
        closed.multipliers, gait, res.status, res.iterations, res.wall_time_s, units,
        torque_names=JOINTS, start_shift=closed.shift, replay_step_period_s=closed.period_s,
        collocated_start_error=closed.open_loop_error, cpu_time_s=res.cpu_time_s,
        contact_step_period_s=contact[0], contact_outcome=contact[1], phase_replays=phases,
        **history_and_energies(scene, rigid, res))


def five_link_replays(scene, plant, res, not_gait: str = "") -> tuple[dict, tuple]:
    """The phase-variable replays
    (:func:`walkerlab.optimal.replay.virtual_constraints.phase_replays`) and the contact
    model's ``(step period [s], outcome)`` under the feed-forward + PD law from its closed
    start; an optimum that is not a gait is not replayed there (``not_gait``: why, the
    contact outcome); ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant`, from
    the stage."""

    data = plant.data

    if scene.optimize.phase_replay is False:  # None (the default) or True: replayed
        return {}, (float("nan"), "not replayed: optimize.phase_replay is off (the contact "
                    "replay runs the feed-forward + PD law)")
    try:
        replays, laws = phase_replays(data, res.t, res.x, res.u)
    except ValueError as exc:  # the phase variable is not monotonic: no such replay
        return {}, (float("nan"), f"not replayed: {exc}")
    if not_gait:
        return replays, (float("nan"), not_gait)
    fb = replays["feedback"]
    if not fb.closed:
        return replays, (float("nan"), "not replayed: the feed-forward + PD law did not "
                         "close on the rigid model")
    contact = contact_replay_five_link(scene, laws["feedback"], fb.x0, fb.step_period_s,
                                       strides=CONTACT_STRIDES, plant=plant)
    return replays, contact


#: the stick figure's polyline through the walker's named points
STICK = ("stance_foot", "stance_knee", "hip", "torso_top", "hip", "swing_knee", "swing_foot")


def stick_figures(data, d, frames: int = 8) -> list:
    """The five-link walker ``data`` (its :class:`~walkerlab.walker.description.WalkerData`,
    from the caller's :class:`~walkerlab.walker.plant.Plant`) at ``frames`` instants of the
    stored step ``d`` (a loaded ``optimize.h5``): polylines (7, 2) [m] through :data:`STICK`
    (the torso's top: its centre of mass, the generated ``torso_*`` point)."""
    w = make_rigid_walker(data, "biped", "derived")
    names = w.state_names()
    out = []
    for k in np.linspace(0, len(d.time) - 1, frames).round().astype(int):
        pts = w.points(np.array([d.states[n][k] for n in names]))
        top = next(v for key, v in pts.items() if key.startswith("torso_"))
        out.append(np.array([pts[n] if n != "torso_top" else top for n in STICK]))
    return out
