"""``optimize.h5``'s records of an optimised step that every transcription's scene driver
writes the same way (:mod:`walkerlab.optimal.drivers.step`,
:mod:`walkerlab.optimal.drivers.mode_sequence`,
:mod:`walkerlab.optimal.drivers.stride`, :mod:`walkerlab.optimal.drivers.free_joints`): the
phase-variable replays and the solver's history with the walker's energies."""

from __future__ import annotations

import numpy as np

__all__ = ["not_a_gait_outcome", "phase_replays", "step_record"]


def phase_replays(scene, data, res, tau) -> tuple[dict, str]:
    """The phase-variable replays of the optimised step ``res`` (``tau``: its torque of
    the time since the heel strike) as ``optimize.h5``'s records, and why there are none
    (:func:`walkerlab.optimal.replay.hip_phase.hip_phase_records`, the scene's solver;
    ``({}, "")`` unless ``optimize.phase_replay`` is on: off by default here)."""
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.replay.hip_phase import hip_phase_records

    if not scene.optimize.phase_replay:  # None: off (a five-link biped's default is on)
        return {}, ""
    return hip_phase_records(data, res, tau, Solver.from_settings(scene.solver))


def step_record(scene, walker, res) -> dict:
    """IPOPT's iteration history and the walker's kinetic and potential energy at the
    collocation points (``res``: a collocation result with ``x`` (2N + 1, 2n) in the
    walker's state order and ``history``), as :class:`OptimizeData` keywords."""
    from walkerlab.units import for_scene

    ke, pe = walker.energies(np.asarray(res.x, float).T)
    return {"ipopt_history": dict(res.history),
            "energy": {"kinetic": np.asarray(ke, float), "potential": np.asarray(pe, float)},
            "energy_unit": for_scene(scene).energy}


def not_a_gait_outcome(err: float, status: str) -> str:
    """The contact replay's outcome of an optimum that is not a gait (it is not replayed:
    a step that does not close on the rigid model says nothing of the contact one).

    Parameters
    ----------
    err : float
        The rigid replay's return error [rad, rad/s] (inf or NaN: the replay failed).
    status : str
        IPOPT's status.
    """
    if not np.isfinite(err):
        return "not replayed: the rigid replay failed"
    if status != "Solve_Succeeded":
        return f"not replayed: not a gait (IPOPT: {status})"
    return (f"not replayed: not a gait (the rigid replay returns {err:.2g} away, more than "
            "optimize.replay_tolerance)")
