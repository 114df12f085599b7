"""N strides of a scene's rigid walker, sampled, with its step table and headline numbers
(what the ``simulate`` stage records)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from walkerlab.analysis.gait.metrics import sample_trajectory, step_table
from walkerlab.config import Scene
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.io.schemas.continuation import initial_state
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
        :func:`walkerlab.analysis.gait.metrics.step_table`.
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
        (:func:`walkerlab.analysis.gait.metrics.sample_trajectory`).
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


def simulate_run(scene: Scene, fixed_point=None):
    """The ``simulate`` stage's run: the scene's walker from the fixed point ``fixed_point``
    (a loaded ``fixedpoint.h5``, when ``simulate.initial_state`` is ``fixed_point``) or from
    the scene's explicit initial state, simulated and sampled (:func:`simulate_scene`).

    Returns
    -------
    walkerlab.io.schemas.simulate.SimulateRun

    Raises
    ------
    ValueError
        More samples than :data:`walkerlab.config.MAX_SIMULATE_SAMPLES` (said before
        integrating when the period is known); an initial state that does not fit the
        walker (one line naming the field).
    """
    from walkerlab.analysis.gait.metrics import total_mass_kg
    from walkerlab.config import MAX_SIMULATE_SAMPLES
    from walkerlab.io.schemas.simulate import SimulateRun
    from walkerlab.models.registry import build_walker

    sim = scene.simulate
    walker = build_walker(scene)
    if sim.initial_state == "fixed_point":
        x0, period = fixed_point.x, fixed_point.step_period_s
        # refuse before integrating what could not be sampled (sample_trajectory checks
        # the exact count afterwards for any initial state)
        n = 2 * sim.strides * period * sim.sample_rate_hz
        if n > MAX_SIMULATE_SAMPLES:
            raise ValueError(f"simulate.sample_rate_hz: {sim.sample_rate_hz:g} Hz over "
                             f"{sim.strides} strides of {2 * period:.3g} s "
                             f"gives {n:.3g} samples; at most {MAX_SIMULATE_SAMPLES:,} "
                             "are kept (lower simulate.sample_rate_hz or simulate.strides)")
    else:
        try:
            x0 = initial_state(sim.initial_state, walker.state_names())
        except ValueError as exc:
            raise ValueError(f"simulate.initial_state: {exc}") from None
    r = simulate_scene(scene, walker, x0)
    from walkerlab.analysis.gait.energy import trajectory_ledger

    return SimulateRun(walker, r.trajectory, r.samples, r.steps, x0, sim.strides,
                       total_mass_kg(walker), r.summary, trajectory_ledger(r.trajectory))
