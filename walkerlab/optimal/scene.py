"""A scene's optimal gait (``walkerlab optimize``): the collocation of
:mod:`walkerlab.optimal.collocation` set up from the scene (its walker, slope,
push-off and ``optimize`` section), started from the scene's gait, replayed on the rigid
model, its Floquet multipliers from the replay."""

from __future__ import annotations

import numpy as np

__all__ = ["needs_gait", "optimize_scene"]


def needs_gait(scene) -> bool:
    """Whether the scene's optimisation starts from its own gait (``fixedpoint.h5``): every
    walker but a five-link biped (``walker.leg.knee.lock: free``), whose guess is built from
    the targets (:mod:`walkerlab.optimal.five_link_scene`)."""
    knee = getattr(getattr(scene.walker, "leg", None), "knee", None)
    return getattr(knee, "lock", None) != "free"


def optimize_scene(scene, x_gait: np.ndarray, period_s: float):
    """Optimise one step of the scene's walker (the ``optimize`` section).

    Parameters
    ----------
    scene : Scene
        With ``optimize``; straight legs, point feet, massive legs.
    x_gait : ndarray (2n,)
        The scene's gait just after heel strike (``fixedpoint.h5``): the initial guess is
        one step of it.
    period_s : float
        Its step period [s].

    Returns
    -------
    walkerlab.io.schemas.optimize.OptimizeData

    Raises
    ------
    ValueError
        A walker the transcription does not handle, or the scene's gait does not make a
        step (one line).
    """
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.codegen import symbolic
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.io.schemas.optimize import OptimizeData
    from walkerlab.models.registry import build_walker
    from walkerlab.optimal.collocation import CollocationSpec, collocate_step, replay
    from walkerlab.walker.description import walker_data

    try:
        import casadi  # noqa: F401 - the collocation's modelling layer and IPOPT
    except ImportError:
        raise ValueError("optimize needs CasADi: pip install -e '.[optimize]'") from None
    o = scene.optimize
    act = getattr(scene.walker, "actuation", None)
    push = float(act.push_off.impulse_n_s) if act is not None and act.push_off else 0.0
    data = walker_data(scene.walker, scene.slope.phi_rad)
    spec = CollocationSpec(intervals=o.intervals, push_off_n_s=push,
                           push_off_free=o.push_off == "free",
                           push_off_max_n_s=o.push_off_max_n_s,
                           push_off_weight=o.push_off_weight_per_s,
                           max_torque_n_m=o.max_torque_n_m,
                           target_speed_m_per_s=o.target_speed_m_per_s,
                           target_step_length_m=o.target_step_length_m,
                           target_step_period_s=o.target_step_period_s)
    walker = build_walker(scene)
    solver = Solver.from_settings(scene.solver)
    seg = simulate_steps(walker, np.asarray(x_gait, float), 1, solver,
                         max_step_time=3.0 * period_s).segments[0]
    if seg.termination != "heel_strike":
        raise ValueError("optimize: the scene's gait does not make a step to start from")
    t = np.linspace(seg.t_start, seg.t_end, 400)
    guess = np.empty((t.size, x_gait.size))
    for k, (_ph, sol, (a, b)) in enumerate(seg.pieces):  # each phase's dense output
        last = k == len(seg.pieces) - 1
        sel = (t >= a) & ((t <= b) if last else (t < b))
        if sel.any():
            guess[sel] = np.asarray(sol(t[sel]), float)[:x_gait.size].T
    res = collocate_step(data, symbolic.derive(data.structure), spec, t - t[0], guess)
    err, replayed = replay(data, res)
    mu = np.full(res.x.shape[1], np.nan, complex)
    if np.isfinite(err):
        try:
            mu = find_fixed_point(replayed, res.x[0], Solver("DOP853", 1e-12, 1e-12),
                                  max_step_time=3.0 * res.step_period_s).multipliers_variational
        except Exception:  # noqa: BLE001 - the replay's multipliers are a report, not a gate
            pass
    names = list(walker.state_names())
    units = dict(zip(names, walker.state_units()))
    return OptimizeData(res.t, {n: res.x[:, k] for k, n in enumerate(names)}, res.u,
                        res.step_period_s, res.step_length_m, res.push_off_n_s,
                        res.objective, err, mu, bool(err <= o.replay_tolerance
                                                     and res.status == "Solve_Succeeded"),
                        res.status, res.iterations, res.wall_time_s, units)
