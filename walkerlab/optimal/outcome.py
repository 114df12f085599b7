"""What every collocation set-up of ``walkerlab optimize`` reports about its optimum: whether
it is a gait and its contact replay's outcome, the objective's unit, the collocated states by
name, the hip torque's phase-variable replays, IPOPT's history with the walker's energies,
and the replay map's Floquet multipliers (fields of
:class:`walkerlab.io.schemas.optimize.OptimizeData`; :mod:`walkerlab.optimal.driver` sets the
collocation up per walker kind).
"""

from __future__ import annotations

import numpy as np

from walkerlab.integrate.solver import Solver
from walkerlab.optimal.replay.hip_phase import hip_phase_replays
from walkerlab.optimal.transcription.step import OBJECTIVES

__all__ = ["hip_phase_replays_of", "history_and_energies", "massless_legs", "named_states",
           "not_a_gait_outcome", "optimum_outcome", "replay_multipliers", "unit_of_objective"]


def optimum_outcome(scene, res, err: float, contact) -> tuple[bool, float, str]:
    """``(gait, contact step period [s], contact outcome)``: a gait when IPOPT converged
    and the replay closed within ``optimize.replay_tolerance``; the contact model replays
    a gait only (``contact()``: its ``(period, outcome)``)."""
    gait = bool(err <= scene.optimize.replay_tolerance and res.status == "Solve_Succeeded")
    if not gait:
        return gait, float("nan"), not_a_gait_outcome(err, res.status)
    return (gait, *contact())


def unit_of_objective(o, data=None) -> str:
    """The objective's unit (a weighted sum's: ``-``; the torque per foot mass on massless
    legs: N m/kg in place of N m)."""
    unit = OBJECTIVES.get(o.objective, "-")
    if data is not None and massless_legs(data):
        unit = {"N^2 m^2 s": "N^2 m^2 s / kg^2", "N m": "N m/kg"}.get(unit, unit)
    return unit


def massless_legs(data) -> bool:
    """The legs are massless (the torque is per foot mass)."""
    return bool(data.structure.bodies) and all(b.massless for b in data.structure.bodies)


def named_states(walker, res) -> tuple[dict, dict]:
    """The collocated states by the walker's names, and their units."""
    names = list(walker.state_names())
    return ({n: res.x[:, k] for k, n in enumerate(names)},
            dict(zip(names, walker.state_units())))


def hip_phase_replays_of(scene, data, res, tau) -> tuple[dict, str]:
    """The hip torque's phase-variable replays of the optimised step ``res`` (``tau``: its
    torque of the time since the heel strike;
    :func:`walkerlab.optimal.replay.hip_phase.hip_phase_replays`, the scene's solver), and
    why there are none (``({}, "")`` unless ``optimize.phase_replay`` is on: off by default
    here; nor on stairs or footholds: the replays walk the slope)."""
    if not scene.optimize.phase_replay:  # None: off (a five-link biped's default is on)
        return {}, ""
    t = scene.terrain
    if t is not None and t.kind in ("stairs", "footholds", "profile"):
        return {}, (f"not replayed: the phase-variable replays walk the slope, not "
                    f"terrain.kind: {t.kind}")
    try:
        return hip_phase_replays(data, res, tau, Solver.from_settings(scene.solver)), ""
    except ValueError as exc:
        return {}, f"not replayed: {exc}"


def history_and_energies(scene, walker, res) -> dict:
    """IPOPT's iteration history and the walker's kinetic and potential energy at the
    collocation points (``res``: a collocation result with ``x`` (2N + 1, 2n) in the
    walker's state order and ``history``), as
    :class:`~walkerlab.io.schemas.optimize.OptimizeData` keywords (J); with the constraint
    groups IPOPT left violated (``res.violations``, when it did not converge)."""
    ke, pe = walker.energies(np.asarray(res.x, float).T)
    return {"ipopt_history": dict(res.history),
            "energy": {"kinetic": np.asarray(ke, float), "potential": np.asarray(pe, float)},
            "violations": str(getattr(res, "violations", ""))}


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


def replay_multipliers(replayed, res, scene, err: float) -> np.ndarray:
    """The replay map's Floquet multipliers at the start (variational equations +
    saltation through every phase, or both steps of a stride).

    Parameters
    ----------
    replayed : HybridWalker
        The rigid walker under the optimised torques.
    res : CollocationResult or PhasedResult
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
    from walkerlab.analysis.gait.poincare import poincare_map  # light

    mu = np.full(res.x.shape[1], np.nan, complex)
    if not np.isfinite(err):
        return mu
    try:
        DP = poincare_map(replayed, res.x[0], Solver.from_settings(scene.solver),
                          max_step_time=3.0 * res.step_period_s, jacobian=True)[2]
        return np.linalg.eigvals(DP).astype(complex)
    except Exception:  # noqa: BLE001 - the replay's multipliers are a report, not a gate
        return mu
