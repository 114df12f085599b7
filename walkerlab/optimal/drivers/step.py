"""A scene's optimal gait (``walkerlab optimize``): the collocation of
:mod:`walkerlab.optimal.transcription.step` set up from the scene (its walker, slope,
push-off and ``optimize`` section), started from the scene's gait (a walker with none, a
passive walker on level ground: from the targets), replayed on the rigid model, its
Floquet multipliers from the replay."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from walkerlab.optimal.records import not_a_gait_outcome, phase_replays, step_record

__all__ = ["collocation_spec", "five_link", "needs_gait", "no_gait_of_its_own",
           "not_a_gait_outcome", "optimize_scene", "phase_replays", "step_record"]


def collocation_spec(scene):
    """The :class:`walkerlab.optimal.transcription.step.CollocationSpec` of the scene's
    ``optimize`` section (the push-off's value, fixed or the free one's start, from the
    scene's actuation)."""
    from walkerlab.optimal.transcription.step import CollocationSpec

    o = scene.optimize
    act = getattr(scene.walker, "actuation", None)
    push = float(act.push_off.impulse_n_s) if act is not None and act.push_off else 0.0
    return CollocationSpec(intervals=o.intervals, push_off_n_s=push,
                           push_off_free=o.push_off == "free",
                           push_off_max_n_s=o.push_off_max_n_s,
                           push_off_weight=o.push_off_weight_per_s,
                           max_torque_n_m=o.max_torque_n_m,
                           target_speed_m_per_s=o.target_speed_m_per_s,
                           target_step_length_m=o.target_step_length_m,
                           target_step_period_s=o.target_step_period_s,
                           objective=o.objective, weights=tuple((o.weights or {}).items()),
                           cost_of_transport_effort_weight=(
                               o.cost_of_transport_effort_weight),
                           min_clearance_m=o.min_clearance_m,
                           friction_coefficient=o.friction_coefficient,
                           hip_angle_range_rad=o.hip_angle_range_rad,
                           touchdown_rate_rad_per_s=o.touchdown_rate_rad_per_s)


def needs_gait(scene) -> bool:
    """Whether the scene's optimisation starts from its own gait (``fixedpoint.h5``): every
    walker but a five-link biped (``walker.leg.knee.lock: free``), whose guess is built from
    the targets (:mod:`walkerlab.optimal.drivers.free_joints`), and a walker with no gait of its
    own (:func:`no_gait_of_its_own`), whose step is built from them too
    (:func:`walkerlab.optimal.guess.target_step`)."""
    return not five_link(scene) and not no_gait_of_its_own(scene)


def five_link(scene) -> bool:
    """Whether the scene's walker is a five-link biped (``walker.leg.knee.lock: free``)."""
    knee = getattr(getattr(scene.walker, "leg", None), "knee", None)
    return getattr(knee, "lock", None) == "free"


def no_gait_of_its_own(scene) -> bool:
    """Whether the scene's walker has no period-1 gait to start an optimisation from: a
    passive walker (no ``walker.actuation``) on level or uphill ground (slope <= 0) loses
    energy at every heel strike and gains none from gravity over a step, so it has no gait
    (the gait search says "a passive walker needs a downhill slope"); and no
    ``optimize.initial_guess`` names another start.  Its optimal gait (a free push-off or
    the hip torque powering it: Srinivasan & Ruina 2006, Kelly 2017's OptimTraj) starts
    from the targets."""
    o = getattr(scene, "optimize", None)
    return (getattr(scene.walker, "actuation", None) is None and scene.slope.phi_rad <= 0.0
            and (o is None or o.initial_guess is None))


def optimize_scene(scene, x_gait: np.ndarray, period_s: float):
    """Optimise one step of the scene's walker (the ``optimize`` section).

    Parameters
    ----------
    scene : Scene
        With ``optimize``; straight legs, point feet, massive legs or massless ones with a
        hip mass; or a kneed or flat-footed walker (a step of phases:
        :func:`walkerlab.optimal.drivers.mode_sequence.optimize_phased_scene`); or legs that differ
        (a stride: :func:`walkerlab.optimal.drivers.stride.optimize_stride_scene`).
    x_gait : ndarray (2n,) or None
        The scene's gait just after heel strike (``fixedpoint.h5``): the initial guess is
        one step of it (unless ``optimize.initial_guess`` names an artifact); None: the
        walker has none (:func:`no_gait_of_its_own`), the guess is built from the targets
        (straight legs, point feet: :func:`walkerlab.optimal.guess.target_step`).
    period_s : float or None
        Its step period [s].

    Returns
    -------
    walkerlab.io.schemas.optimize.OptimizeData

    Raises
    ------
    ValueError
        A walker the transcription does not handle, the starting gait does not make a step,
        the initial guess's artifact is unusable, or no gait and a walker the targets' guess
        does not build (legs with knees, flat feet, legs that differ) (one line).
    """
    from walkerlab.analysis.gait.poincare import poincare_map
    from walkerlab.integrate.solver import Solver
    from walkerlab.io.schemas.optimize import OptimizeData
    from walkerlab.models.registry import build_walker
    from walkerlab.optimal.guess import starting_step
    from walkerlab.optimal.replay.contact import contact_replay
    from walkerlab.optimal.transcription.step import collocate_step, replay, torque_of_time
    from walkerlab.optimal.transcription.step_cache import cached_step_functions
    from walkerlab.walker.description import walker_data

    try:
        import casadi  # noqa: F401 - the collocation's modelling layer and IPOPT
    except ImportError:
        raise ValueError("optimize needs CasADi: pip install -e '.[optimize]'") from None
    o = scene.optimize
    data = walker_data(scene.walker, scene.slope.phi_rad)
    spec = collocation_spec(scene)
    walker = build_walker(scene)
    if x_gait is None and (data.mirror is not None or data.structure.knee
                           or data.structure.foot == "flat"):
        raise ValueError("optimize: the walker has no gait of its own to start from (passive "
                         "on level ground), and a step from the targets is built for "
                         "straight legs with point feet only; give optimize.initial_guess "
                         "(another optimize.h5) or a downhill slope")
    if data.mirror is not None:  # legs that differ: a stride of two different steps
        from walkerlab.optimal.drivers.stride import optimize_stride_scene

        return optimize_stride_scene(scene, data, spec, x_gait, period_s)
    if data.structure.knee or data.structure.foot == "flat":  # a step of phases: its own
        from walkerlab.optimal.drivers.mode_sequence import optimize_phased_scene

        return optimize_phased_scene(scene, data, spec, x_gait, period_s)  # transcription
    t, guess, guess_u, guess_p = starting_step(scene, walker, x_gait, period_s)
    if guess_p is not None and spec.push_off_free:
        spec = replace(spec, push_off_n_s=guess_p)
    if guess_u is not None:  # another optimize.h5: an optimum
        spec = replace(spec, warm_start=True)
    res = collocate_step(data, None, spec, t, guess, guess_u, cached_step_functions(data))
    err, replayed = replay(data, res)
    mu = np.full(res.x.shape[1], np.nan, complex)
    if np.isfinite(err):
        try:  # the replay map's Jacobian at the start (variational equations + saltation)
            DP = poincare_map(replayed, res.x[0], Solver.from_settings(scene.solver),
                              max_step_time=3.0 * res.step_period_s, jacobian=True)[2]
            mu = np.linalg.eigvals(DP).astype(complex)
        except Exception:  # noqa: BLE001 - the replay's multipliers are a report, not a gate
            pass
    gait = bool(err <= o.replay_tolerance and res.status == "Solve_Succeeded")
    contact_period, contact_outcome = float("nan"), not_a_gait_outcome(err, res.status)
    if gait:  # the contact model replays a gait only
        contact_period, contact_outcome = contact_replay(scene, res)
    phases, phase_note = phase_replays(scene, data, res, torque_of_time(res))
    names = list(walker.state_names())
    units = dict(zip(names, walker.state_units()))
    return OptimizeData(res.t, {n: res.x[:, k] for k, n in enumerate(names)}, res.u,
                        res.step_period_s, res.step_length_m, res.push_off_n_s,
                        res.objective, err, mu, gait,
                        res.status, res.iterations, res.wall_time_s, units,
                        objective_name=o.objective, objective_unit=_unit(o, data),
                        terms=res.terms, contact_step_period_s=contact_period,
                        contact_outcome=contact_outcome,
                        torque_unit="N m/kg" if _massless(data) else "N m",
                        phase_replays=phases, phase_replay_outcome=phase_note,
                        **step_record(scene, walker, res))


def _unit(o, data) -> str:
    """The objective's unit (a weighted sum's: ``-``; the torque per foot mass on massless
    legs: N m/kg in place of N m)."""
    from walkerlab.optimal.transcription.step import OBJECTIVES

    unit = OBJECTIVES.get(o.objective, "-")
    if _massless(data):
        unit = {"N^2 m^2 s": "N^2 m^2 s / kg^2", "N m": "N m/kg"}.get(unit, unit)
    return unit


def _massless(data) -> bool:
    """The legs are massless (the torque is per foot mass)."""
    return bool(data.structure.bodies) and all(b.massless for b in data.structure.bodies)
