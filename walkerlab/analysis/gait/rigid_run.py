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
        ``mean_hip_speed_m_per_s`` [m/s] (NaN: none), ``mean_total_energy_J`` [J]; on a
        finite ground shorter than the run (``terrain.periodic: false``) ``ground_steps``,
        its steps (the walk ends there); on a height profile ``trip_time_s`` [s],
        ``trip_x_m``, ``trip_y_m`` [m] (the swing foot entered the profile there: the walk
        ended as a ``trip``) and ``midstance_scuff_depth_m`` [m] (the ignored foot-through
        of straight legs at mid-stance), each only when it happened.
    """

    trajectory: object
    samples: NamedTrajectory
    steps: dict
    summary: dict


def simulate_scene(scene: Scene, walker, x0: np.ndarray, plant) -> RigidRun:
    """Simulate ``2 * simulate.strides`` steps of ``walker`` (the scene's) from ``x0`` with
    the scene's solver and sample them (``plant``: the scene's
    :class:`~walkerlab.walker.plant.Plant`, for a height profile's walkers, :func:`walk_scene`).

    Raises
    ------
    ValueError
        More samples than :data:`walkerlab.config.MAX_SIMULATE_SAMPLES`
        (:func:`walkerlab.analysis.gait.metrics.sample_trajectory`).
    """
    sim = scene.simulate
    traj = walk_scene(scene, walker, x0, 2 * sim.strides, Solver.from_settings(scene.solver),
                      sim.max_step_time_s, plant)
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
    trip = getattr(traj, "profile_trip", None)  # a height profile's swing-foot check
    if trip is not None:
        summary.update(trip_time_s=trip[0], trip_x_m=trip[1], trip_y_m=trip[2])
    if getattr(traj, "midstance_scuff_depth_m", 0.0) > 0.0:
        summary["midstance_scuff_depth_m"] = float(traj.midstance_scuff_depth_m)
    ends = getattr(walker, "ground_steps", None)
    if ends is not None and traj.termination == "heel_strike" and ends < 2 * sim.strides:
        summary["ground_steps"] = int(ends)  # a finite ground ended the walk
    return RigidRun(traj, samples, steps, summary)


def walk_scene(scene: Scene, walker, x0: np.ndarray, n_steps: int, solver: Solver,
               max_step_time: float, plant):
    """``n_steps`` steps of the scene's rigid walker from ``x0`` on the scene's ground: the
    walk of the ``simulate`` stage and of :meth:`walkerlab.api.walker.Walker.simulate`.

    ``walker`` carries the ground of a slope, per-step slopes, stairs and footholds (its
    heel-strike guard: :func:`walkerlab.models.registry.build_walker`, or a drawn rough
    ground, :func:`rough_ground_walker`) and is walked by
    :func:`walkerlab.integrate.rigid.simulate_steps`; a height profile
    (``terrain.kind: profile``) is walked segment by segment (:func:`profile_walk`), whose
    walkers are built per segment from the scene.

    Parameters
    ----------
    scene : walkerlab.config.Scene
    walker : walkerlab.models.hybrid.HybridWalker
        The scene's rigid walker.
    x0 : ndarray (2n,)
        State just after heel strike [rad, rad/s].
    n_steps : int
    solver : walkerlab.integrate.solver.Solver
        The scene's integrator (``solver`` section).
    max_step_time : float
        Longest simulated time of one step [s].
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (the caller's); a height profile's walkers are
        built from it.

    Returns
    -------
    walkerlab.integrate.rigid.HybridTrajectory

    Raises
    ------
    ValueError
        A profile the rigid walk does not read (:func:`profile_walk`; one line naming the
        field).
    """
    if scene.terrain is not None and scene.terrain.kind == "profile":
        return profile_walk(scene, x0, n_steps, solver, max_step_time, plant=plant)
    return simulate_steps(walker, x0, n_steps, solver, max_step_time=max_step_time)


def simulate_run(scene: Scene, fixed_point, plant):
    """The ``simulate`` stage's run: the scene's walker from the fixed point ``fixed_point``
    (a loaded ``fixedpoint.h5``, when ``simulate.initial_state`` is ``fixed_point``) or from
    the scene's explicit initial state, simulated and sampled (:func:`simulate_scene`);
    ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant`, from the stage.

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
    walker = build_walker(plant.with_(scene))
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
    if sim.terrain_seed is not None:
        walker = rough_ground_walker(scene, 2 * sim.strides, plant)
    r = simulate_scene(scene, walker, x0, plant)
    from walkerlab.analysis.gait.energy import trajectory_ledger

    return SimulateRun(walker, r.trajectory, r.samples, r.steps, x0, sim.strides,
                       total_mass_kg(walker), r.summary, trajectory_ledger(r.trajectory))


def rough_ground_steps(scene, n_steps: int) -> list[tuple[float, float]]:
    """``[(drop_m, slope_rad), ...]`` of the first ``n_steps`` steps of the per-step ground
    ``terrain.per_step`` drawn from ``simulate.terrain_seed``: walk 0 of that seed's Monte
    Carlo streams (:func:`walkerlab.analysis.robustness.slope_stream.slope_rows`, the
    landing heights :func:`walkerlab.analysis.robustness.mfpt.height_rows`), so a seed
    names one ground, the same on every run and machine; ``drop_m`` is minus the height.

    Raises
    ------
    ValueError
        No ``terrain.per_step`` section (one line).
    """
    from walkerlab.analysis.robustness.mfpt import height_rows
    from walkerlab.analysis.robustness.slope_stream import slope_rows

    per = scene.terrain.per_step if scene.terrain is not None else None
    if per is None:
        raise ValueError("simulate.terrain_seed: the scene has no terrain.per_step (the "
                         "distribution of each step's slope and landing height)")
    seed = int(scene.simulate.terrain_seed)
    g = slope_rows(seed, [0], 0, n_steps, scene.slope.phi_rad, per.slope_sd_rad,
                   per.slope_distribution)[0]
    dist, sd = per.heights
    h = height_rows(seed, [0], 0, n_steps, sd, dist)[0] if sd > 0 else np.zeros(n_steps)
    return [(-float(hk), float(gk)) for hk, gk in zip(h, g)]


def rough_ground_walker(scene, n_steps: int, plant):
    """The scene's rigid walker on :func:`rough_ground_steps` (its walk ends after them;
    ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant`).

    Raises
    ------
    ValueError
        As :func:`rough_ground_steps` and
        :func:`walkerlab.models.registry.build_walker_on_steps` (one line).
    """
    from walkerlab.models.registry import build_walker_on_steps

    return build_walker_on_steps(plant.with_(scene), rough_ground_steps(scene, n_steps))


def profile_walk(scene, x0: np.ndarray, n_steps: int, solver: Solver | None = None,
                 max_step_time: float | None = None, *, plant):
    """``n_steps`` steps of the scene's rigid walker on its height profile from ``x0``
    (:func:`walkerlab.analysis.gait.profile_walk.simulate_on_profile`), with ``solver``
    (default the scene's) and ``max_step_time`` [s] (default ``simulate.max_step_time_s``);
    ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant` (:func:`profile_ground`).

    Raises
    ------
    ValueError
        A profile only in a CSV file, a walker with actuators or printed equations (one
        line).
    """
    from walkerlab.analysis.gait.profile_walk import simulate_on_profile  # light

    ground = profile_ground(scene, plant)
    solver = Solver.from_settings(scene.solver) if solver is None else solver
    if max_step_time is None:
        max_step_time = scene.simulate.max_step_time_s
    return simulate_on_profile(ground.walker_at, ground.data_at, ground.P, x0, n_steps,
                               solver, max_step_time=max_step_time)


def profile_ground(scene, plant):
    """The scene's height profile as the steps of a rigid walk
    (:class:`walkerlab.analysis.gait.profile_walk.ProfileGround`: each step's walker on its
    landing segment), for :func:`profile_walk` and the Gymnasium environment's rigid view.
    ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant` (its walker described once,
    by the caller).

    Raises
    ------
    ValueError
        A profile only in a CSV file, a walker with actuators or printed equations (one
        line).
    """
    from walkerlab.analysis.gait.profile_walk import ProfileGround, profile_points  # light
    from walkerlab.models.registry import passive_walker_at
    from walkerlab.walker.capability_cells import PROFILE_PASSIVE

    if scene.walker.actuation is not None or scene.ideal.variant != "derived":
        raise ValueError(f"terrain.kind: profile: {PROFILE_PASSIVE}")
    if scene.walker.model != "compass_gait" or plant.kind.in_3d:  # a described walker, a
        # walker in 3D: its kind's cell
        plant.kind.require("profile", "rigid", "terrain.kind: profile")
    P = profile_points(scene.terrain)
    at, data_at = passive_walker_at(plant.with_(scene))
    return ProfileGround(at, data_at, P)
