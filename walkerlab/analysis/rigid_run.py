"""N strides of a scene's rigid walker, sampled, with its step table and headline numbers
(what the ``simulate`` stage records)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.analysis.metrics import sample_trajectory, step_table
from walkerlab.config import Scene
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.io.trajectory import NamedTrajectory


@dataclass
class RigidRun:
    """A sampled rigid run.

    Attributes
    ----------
    trajectory : walkerlab.integrate.rigid.HybridTrajectory
    samples : NamedTrajectory
        At ``simulate.sample_rate_hz``.
    steps : dict[str, ndarray (n_steps,)]
        :func:`walkerlab.analysis.metrics.step_table`.
    summary : dict
        ``termination``, ``steps_completed``, ``wall_time_s`` [s], ``nfev``, and over the
        steps that ended by a heel strike ``mean_period_s`` [s], ``mean_step_length_m`` [m],
        ``mean_hip_speed_m_per_s`` [m/s] (NaN: none), ``mean_total_energy_J`` [J].
    """

    trajectory: object
    samples: NamedTrajectory
    steps: dict
    summary: dict


def simulate_scene(scene: Scene, walker, x0: np.ndarray) -> RigidRun:
    """Simulate ``2 * simulate.strides`` steps of ``walker`` (the scene's) from ``x0`` with
    the scene's solver and sample them.

    Raises
    ------
    ValueError
        More samples than :data:`walkerlab.config.MAX_SIMULATE_SAMPLES`
        (:func:`walkerlab.analysis.metrics.sample_trajectory`).
    """
    sim = scene.simulate
    traj = simulate_steps(walker, x0, 2 * sim.strides, Solver.from_settings(scene.solver),
                          max_step_time=sim.max_step_time_s)
    samples = sample_trajectory(traj, sim.sample_rate_hz)
    steps = step_table(traj)
    ok = steps["termination"] == "heel_strike"
    summary = {
        "termination": traj.termination,
        "steps_completed": int(ok.sum()),
        "wall_time_s": traj.wall_time_s,
        "nfev": traj.nfev,
        "mean_period_s": float(np.mean(steps["period"][ok])) if ok.any() else np.nan,
        "mean_step_length_m": float(np.mean(steps["step_length"][ok])) if ok.any() else np.nan,
        "mean_hip_speed_m_per_s": (float(np.mean(steps["hip_speed"][ok])) if ok.any()
                                   else np.nan),
        "mean_total_energy_J": float(np.mean(samples.total)),
    }
    return RigidRun(traj, samples, steps, summary)
