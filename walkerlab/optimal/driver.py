"""A scene's optimal gait (``walkerlab optimize``): one driver that sets the collocation up
from the scene - its walker, slope, push-off and ``optimize`` section - starts it from the
scene's gait (or from the targets, or another optimisation), replays the optimum on the
rigid model (its Floquet multipliers from the replay), in the contact model and as a
phase-variable law, and returns it as ``optimize.h5``'s record
(:class:`walkerlab.io.schemas.optimize.OptimizeData`, the one record type of an optimum;
the stage fills in the scene's energy unit and the replays' records:
:func:`walkerlab.io.schemas.optimize.optimize_record`).

The transcription follows the walker's kind (:class:`walkerlab.walker.kinds.Kind`), reached
through the kind's part (its collocation part's behaviour, a :class:`Collocation` holding the kind's
transcription, guess and replays; Hermite-Simpson collocation, CasADi + IPOPT); a kind the
collocation does not take, and a feature the kind lacks here, are refused from the
capability table (:func:`check_kind`):

- ``straight_legs`` (point or arc feet, a torso, massless legs with a hip mass): one
  step, one phase, the heel strike's reset (push-off included) the periodic boundary
  condition (:mod:`walkerlab.optimal.transcription.step`); legs that differ: a stride, the
  step sequence of the walker and its mirror (:mod:`walkerlab.optimal.transcription.
  stride`, on the multi-phase transcription);
- ``locking_knees``, ``flat_feet``: the step as the walker's sequence of phases, each with
  its guard and reset from the generated model
  (:mod:`walkerlab.optimal.transcription.mode_sequence`); ``locking_knees_3d``: a stride
  of two such steps, the walker's and its mirror's;
- ``free_joints`` (a five-link biped): one phase with its four joint torques, from the
  targets (Kelly 2017's set-up; :mod:`walkerlab.optimal.transcription.free_joints`),
  closed by shooting and replayed as virtual constraints (:mod:`walkerlab.optimal.
  free_joints`);
- ``rolling_polygon``: refused (a spoked wheel has no joint to drive).

The ground (:mod:`walkerlab.optimal.transcription.landing`): the slope for every kind; for
straight legs of one build also stairs (the heel strike on the next tread, one tread a
step) and footholds (of one height: one step; of several: a period of one step per
foothold, :func:`_footholds`), legs that differ (a stride) stairs and footholds of one or
two heights, each replayed on that ground; a profile and the other kinds on stairs or
footholds are refused from the table.

What every set-up reports of its optimum (outcome, units, replays' multipliers) is
:mod:`walkerlab.optimal.outcome`'s.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import partial

import numpy as np

from walkerlab.io.schemas.optimize import OptimizeData
from walkerlab.optimal import outcome as reported
from walkerlab.optimal.free_joints import optimize_five_link
from walkerlab.optimal.guess import pushed
from walkerlab.optimal.outcome import history_and_energies, not_a_gait_outcome, replay_multipliers
from walkerlab.optimal.replay.contact import (
    contact_replay,
    contact_replay_phased,
    contact_replay_stride,
)
from walkerlab.optimal.transcription.landing import step_ground
from walkerlab.optimal.transcription.phases import refusal as phased_refusal
from walkerlab.optimal.transcription.stride import check_objective as _check_stride
from walkerlab.optimal.virtual_constraints import (
    check_design,
    designs_controller,
    optimize_virtual_constraints,
)
from walkerlab.walker import parts as P
from walkerlab.walker.capability_cells import TOROIDAL_OPTIMIZE
from walkerlab.walker.plant import Plant

__all__ = ["Collocation", "check_kind", "check_scene", "check_targets",
           "collocation_spec", "guess_from_targets", "needs_gait", "no_gait_of_its_own",
           "optimize_scene", "starting_phases", "starting_stride"]


# -- the scene's set-up ------------------------------------------------------------------

def collocation_spec(scene):
    """The :class:`walkerlab.optimal.transcription.step.CollocationSpec` of the scene's
    ``optimize`` section (the push-off's value, fixed or the free one's start, from the
    scene's actuation)."""
    from walkerlab.optimal.transcription.step import CollocationSpec

    o = scene.optimize
    act = scene.walker.actuation
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


def _part(structure) -> Collocation:
    """The collocation's part for the walker kind of ``structure`` (its
    :attr:`~walkerlab.walker.kinds.Kind.collocation`'s behaviour).

    Raises
    ------
    walkerlab.walker.kinds.KindRefused
        A kind the collocation does not take (the capability table's line, ``walker: ...``).
    """
    structure.kind.require("walk", "optimize", "walker")
    return structure.kind.collocation.behaviour


def needs_gait(scene, plant: Plant) -> bool:
    """Whether the scene's optimisation starts from its own gait (``fixedpoint.h5``): every
    walker kind but one whose guess is built from the targets (a five-link biped:
    :attr:`Collocation.from_targets`) and a walker with no gait of its own
    (:func:`no_gait_of_its_own`), whose step is built from them too
    (:func:`walkerlab.optimal.guess.target_step`).  A kind the collocation does not take
    needs none (the stage refuses it at once).  ``plant``: the scene's
    :class:`~walkerlab.walker.plant.Plant`."""
    if designs_controller(scene):  # starts from the scene's own controller
        return False
    c = plant.kind.collocation
    part = c.behaviour if c is not None else None
    return part is not None and not part.from_targets and not no_gait_of_its_own(scene)


def guess_from_targets(scene, plant: Plant) -> bool:
    """Whether the scene's walker kind starts its optimisation from the targets alone, with
    no upstream gait, and needs them (:func:`check_targets`): a five-link biped
    (:attr:`Collocation.from_targets`).  ``plant``: the scene's
    :class:`~walkerlab.walker.plant.Plant`.

    Raises
    ------
    walkerlab.walker.kinds.KindRefused
        A kind the collocation does not take (one line).
    """
    return _part(plant.structure).from_targets


def no_gait_of_its_own(scene) -> bool:
    """Whether the scene's walker has no period-1 gait to start an optimisation from: a
    passive walker (no ``walker.actuation``) on level or uphill ground (slope <= 0) loses
    energy at every heel strike and gains none from gravity over a step, so it has no gait
    (the gait search says "a passive walker needs a downhill slope"); and no
    ``optimize.initial_guess`` names another start.  Its optimal gait (a free push-off or
    the hip torque powering it: Srinivasan & Ruina 2006, Kelly 2017's OptimTraj) starts
    from the targets.  On stairs or footholds the walker descends the mean landing depth a
    step too (:func:`walkerlab.models.ground.landing_drops`): down stairs' level treads
    give a passive gait (configs/stairs.yaml), up stairs none."""
    from walkerlab.models.ground import landing_drops

    o = getattr(scene, "optimize", None)
    try:
        drops = landing_drops(scene.terrain)
    except ValueError:  # footholds of their own slopes: refused by the collocation
        drops = (0.0,)
    descends = scene.slope.phi_rad > 0.0 or (scene.slope.phi_rad == 0.0
                                             and sum(drops) > 0.0)
    return (scene.walker.actuation is None and not descends
            and (o is None or o.initial_guess is None))


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


# -- the one entry point -----------------------------------------------------------------

def optimize_scene(scene, x_gait: np.ndarray | None = None,
                   period_s: float | None = None, *, plant: Plant) -> OptimizeData:
    """Optimise the scene's gait (the ``optimize`` section) by its walker kind's part
    (its collocation part): a step, a step of phases, a stride of two steps (legs that differ) or
    a five-link biped's step (module docstring).

    Parameters
    ----------
    scene : Scene
        With ``optimize``.
    x_gait : ndarray (2n,) or None
        The scene's gait just after heel strike (``fixedpoint.h5``): the initial guess is
        one step of it (unless ``optimize.initial_guess`` names an artifact); None: the
        walker has none (:func:`no_gait_of_its_own`; a five-link biped), the guess is built
        from the targets.
    period_s : float or None
        Its step period [s].
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once (by the stage).

    Returns
    -------
    walkerlab.io.schemas.optimize.OptimizeData
        The optimum and its replays (``phase_replays``: the replays themselves,
        :class:`walkerlab.optimal.replay.phase.PhaseReplay`; the stage's
        :func:`walkerlab.io.schemas.optimize.optimize_record` makes them records and sets
        the scene's energy unit).

    Raises
    ------
    ValueError
        A walker kind or feature the collocation does not take (the capability table's
        line: :func:`check_kind`), the starting gait does not make a step, the initial
        guess's artifact is unusable, no gait and a walker the targets' guess does not
        build (legs with knees, flat feet, legs that differ), a five-link biped without a
        target (one line).
    """
    try:
        import casadi  # noqa: F401 - the collocation's modelling layer and IPOPT
    except ImportError:
        raise ValueError("optimize needs CasADi: pip install -e '.[optimize]'") from None
    data = plant.data
    if designs_controller(scene):  # virtual constraints: any kind the table lets through
        check_scene(scene, data)
        return optimize_virtual_constraints(scene, plant, collocation_spec(scene))
    part = _part(data.structure)
    check_scene(scene, data)
    if x_gait is None and not part.from_targets and (data.mirror is not None
                                                     or not part.target_step):
        raise ValueError("optimize: the walker has no gait of its own to start from (passive "
                         "on level ground), and a step from the targets is built for "
                         "straight legs with point feet only; give optimize.initial_guess "
                         "(another optimize.h5) or a downhill slope")
    if part.from_targets:
        check_targets(scene.optimize)
    return part.optimize(scene, plant, x_gait, period_s)


def check_kind(scene, kind) -> None:
    """Refuse what the walker's kind does not have in the collocation, from the capability
    table (:data:`walkerlab.walker.kinds.CAPABILITIES`, view ``optimize``): the walker
    itself (a spoked wheel), a push-off (fixed, ``walker.actuation.push_off``, or
    ``optimize.push_off: free``), an ankle push-off, an ankle torque.

    Parameters
    ----------
    scene : Scene
        With ``optimize``.
    kind : walkerlab.walker.kinds.Kind
        Its walker's.

    Raises
    ------
    walkerlab.walker.kinds.KindRefused
        ``walker: ...``, ``terrain.kind: ...``, ``optimize.push_off: ...`` or
        ``walker.actuation.ankle_push_off: ...`` (one line).
    """
    kind.require("walk", "optimize", "walker")
    ground = "slope" if scene.terrain is None else scene.terrain.kind
    if ground in ("stairs", "footholds", "profile"):  # the kind's cell of that ground
        kind.require(ground, "optimize", f"terrain.kind: {ground}")
    act = scene.walker.actuation
    if act is not None and act.virtual_constraints is not None:
        kind.require("virtual_constraints", "optimize", "walker.actuation.virtual_constraints")
        raise ValueError("optimize.design: the walker is driven by its virtual constraints "
                         "(walker.actuation.virtual_constraints): give design: "
                         "virtual_constraints to optimise them (open-loop torques would "
                         "replace the controller)")
    if scene.optimize.push_off == "free" or (act is not None and act.push_off
                                             and act.push_off.impulse_n_s):
        kind.require("push_off", "optimize", "optimize.push_off")
    if act is not None and act.ankle_push_off is not None:
        kind.require("ankle_push_off", "optimize", "walker.actuation.ankle_push_off")
    for i, t in enumerate(act.torques if act is not None else ()):
        if t.joint.endswith("_ankle"):  # a step from targets builds no rigid walker to ask
            kind.require("ankle_torque", "optimize", f"walker.actuation.torques.{i}.joint")


def check_scene(scene, data) -> None:
    """Refuse, before any stage runs, what the collocation cannot do: what the walker's
    kind does not have (:func:`check_kind`: a spoked wheel, a push-off on a five-link
    walker, 3D disc feet; knees on arc feet: the phased step's
    :func:`~walkerlab.optimal.transcription.phases.refusal`) and a clearance that cannot hold
    (``optimize.min_clearance_m > 0``: :func:`_feet_level_when_legs_cross`).

    Parameters
    ----------
    scene : Scene
    data : WalkerData
        The scene's walker (:attr:`walkerlab.walker.plant.Plant.data` of the stage's plant).

    Raises
    ------
    ValueError
        ``walker: ...``, ``optimize.push_off: ...``, ``optimize.min_clearance_m: ...``,
        a ground straight legs do not land on (``terrain.foothold_slopes_rad``, a target
        step other than the stairs' tread: :func:`walkerlab.optimal.transcription.landing.
        step_ground`) with the reason and what to give instead (one line).
    """
    o = getattr(scene, "optimize", None)
    if o is None:
        return
    if designs_controller(scene):
        check_design(scene, data.structure.kind)
        return
    check_kind(scene, data.structure.kind)
    if data.structure.in_3d and data.structure.foot == "toroidal":
        raise ValueError(TOROIDAL_OPTIMIZE)
    if data.structure.in_3d and data.structure.foot == "arc":  # a 3D walker's discs
        data.structure.kind.require("round_feet_3d", "optimize", "walker.foot_radius_m")
    elif data.structure.foot == "arc" and not data.structure.kind.collocation.one_step:
        raise ValueError(phased_refusal(data.structure))   # knees on rolling feet
    if data.structure.kind.collocation.one_step or data.structure.in_3d:  # the ground a step
        # lands on (a 3D stride's steps too): refused early
        from walkerlab.optimal.transcription.landing import check_stride_ground

        check_stride_ground(step_ground(scene), data)
    if (o.min_clearance_m or 0.0) > 0.0 and _feet_level_when_legs_cross(scene, data):
        raise ValueError(
            "optimize.min_clearance_m: straight legs cannot clear the ground mid-swing: the "
            "swing foot is level with the stance foot when the legs cross (as at both ends "
            "of the step), so a clearance > 0 cannot hold; give 0 (no scuffing below the "
            "slope) or a walker with knees (walker.leg.knee)")


def _feet_level_when_legs_cross(scene, data) -> bool:
    """Whether the swing foot is level with the stance foot when the legs cross: a kind
    whose legs are straight (:attr:`Collocation.legs_cross_level`), of one length and
    foot.  With the legs at angles ``theta`` (stance) and ``phi`` (swing) from the slope's
    normal, the swing foot's clearance is ``l (cos theta - cos phi)`` (point feet; arc
    feet alike, the arcs' centres at the same distance), zero when ``phi = theta``: the
    swing leg passes the stance leg mid-step, so no clearance > 0 holds over the swing -
    the straight-legged models ignore that scuffing (McGeer 1990, Int. J. Robotics
    Research 9(2):62-82; Garcia et al. 1998, J. Biomech. Eng. 120:281-288)."""
    if not _part(data.structure).legs_cross_level:
        return False
    w = scene.walker.model_dump()
    legs = [leg for leg in [w.get("leg")] + list(w.get("legs") or []) if leg]
    return len({(repr(leg.get("length_m")), repr(leg.get("foot"))) for leg in legs}) <= 1


# -- one step of straight legs -----------------------------------------------------------

def _straight_legs(scene, plant, x_gait, period_s) -> OptimizeData:
    """Straight legs: one step (:func:`_step`), or a stride of two steps when the legs
    differ (:func:`_stride`)."""
    data, spec = plant.data, collocation_spec(scene)
    return (_step(scene, plant, spec, x_gait, period_s) if data.mirror is None
            else _stride(scene, plant, spec, x_gait, period_s))


def _step(scene, plant, spec, x_gait, period_s) -> OptimizeData:
    """One step of straight legs (point or arc feet, a torso, massless legs with a hip
    mass): :func:`walkerlab.optimal.transcription.mode_sequence.collocate_step`."""
    from walkerlab.models.registry import build_walker
    from walkerlab.optimal.guess import starting_step
    from walkerlab.optimal.transcription.landing import step_ground
    from walkerlab.optimal.transcription.mode_sequence import collocate_step
    from walkerlab.optimal.transcription.step import replay, torque_of_time
    from walkerlab.optimal.transcription.step_cache import cached_step_functions

    data, o = plant.data, scene.optimize
    ground = step_ground(scene)
    if ground is not None and len(ground.drops_m) > 1:  # footholds that differ: a period
        return _footholds(scene, plant, spec, x_gait, period_s, ground)
    walker = build_walker(plant.with_(scene))
    t, guess, guess_u, guess_p = starting_step(scene, walker, x_gait, period_s)
    if guess_p is not None and spec.push_off_free:
        spec = replace(spec, push_off_n_s=guess_p)
    if guess_u is not None:  # another optimize.h5: an optimum
        spec = replace(spec, warm_start=True)
    res = collocate_step(data, None, spec, t, guess, guess_u, cached_step_functions(data),
                         ground)
    err, replayed = replay(data, res, drop_m=0.0 if ground is None else ground.drops_m[0])
    mu = replay_multipliers(replayed, res, scene, err)
    gait, contact_period, contact_outcome = reported.optimum_outcome(
        scene, res, err, lambda: contact_replay(scene, res, plant=plant))
    phases, phase_note = reported.hip_phase_replays_of(scene, data, res, torque_of_time(res))
    states, units = reported.named_states(walker, res)
    return OptimizeData(res.t, states, res.u, res.step_period_s, res.step_length_m,
                        res.push_off_n_s, res.objective, err, mu, gait, res.status,
                        res.iterations, res.wall_time_s, units, objective_name=o.objective,
                        objective_unit=reported.unit_of_objective(o, data), terms=res.terms,
                        contact_step_period_s=contact_period, contact_outcome=contact_outcome,
                        torque_unit="N m/kg" if reported.massless_legs(data) else "N m",
                        phase_replays=phases, phase_replay_outcome=phase_note,
                        **history_and_energies(scene, walker, res))


def _footholds(scene, plant, spec, x_gait, period_s, ground) -> OptimizeData:
    """Straight legs on footholds that differ from step to step: one period of ``p``
    steps, each landing at its foothold
    (:func:`walkerlab.optimal.transcription.mode_sequence.collocate_footholds`), started
    from the scene's period-``p`` gait (``x_gait``; ``period_s`` its mean step [s]) and
    replayed on the footholds (:func:`walkerlab.optimal.transcription.landing.
    replay_footholds`); its ``step_period_s`` / ``step_length_m`` the mean step's, the
    multipliers the period map's."""
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker
    from walkerlab.optimal.transcription.landing import replay_footholds
    from walkerlab.optimal.transcription.mode_sequence import (
        collocate_footholds,
        footholds_guess,
    )
    from walkerlab.optimal.transcription.step_cache import cached_step_functions

    data = plant.data
    o = scene.optimize
    if o.initial_guess is not None or x_gait is None:
        raise ValueError("optimize.initial_guess: footholds of several heights start from "
                         "the scene's own period gait (walkerlab fixedpoint); leave it out")
    walker = build_walker(plant.with_(scene))
    guess = footholds_guess(walker, x_gait, period_s, Solver.from_settings(scene.solver),
                            spec.intervals)
    fns = cached_step_functions(data)
    res = collocate_footholds(fns, spec, ground, guess)
    err, replayed = replay_footholds(data, res, ground)
    mu = replay_multipliers(replayed, res, scene, err)
    p = len(ground.drops_m)
    gait = bool(err <= o.replay_tolerance and res.status == "Solve_Succeeded")
    outcome = "" if gait else not_a_gait_outcome(err, res.status)
    if gait:
        outcome = ("not replayed: the contact replay of footholds of several heights is "
                   "not built (the rigid replay walks them)")
    lengths = [float(ph.step(res.x[b - 1])) for ph, b in zip(
        _foothold_phases(fns, ground), [*res.phase_start[1:], res.t.size])]
    states, units = reported.named_states(walker, res)
    return OptimizeData(res.t, states, res.u, res.step_period_s / p, float(np.mean(lengths)),
                        res.push_off_n_s, res.objective, err, mu, gait, res.status,
                        res.iterations, res.wall_time_s, units, objective_name=o.objective,
                        objective_unit=reported.unit_of_objective(o, data), terms=res.terms,
                        contact_step_period_s=float("nan"), contact_outcome=outcome,
                        cpu_time_s=res.cpu_time_s, phase_names=res.phase_names,
                        phase_start=res.phase_start, phase_duration_s=res.phase_duration_s,
                        build_time_s=res.build_time_s, steps=p,
                        torque_unit="N m/kg" if reported.massless_legs(data) else "N m",
                        phase_replay_outcome="not replayed: a period on footholds is "
                        "replayed as a function of time only" if o.phase_replay else "",
                        **history_and_energies(scene, walker, res))


def _foothold_phases(fns, ground):
    """The footholds' step phases (their advance functions, for the step lengths)."""
    from walkerlab.optimal.transcription.landing import landing_phase
    from walkerlab.optimal.transcription.mode_sequence import step_phase

    base = step_phase(fns)
    return [landing_phase(base, fns, d, ground.slope_rad) for d in ground.drops_m]


# -- a step of phases (knees, flat feet) -------------------------------------------------

def starting_phases(scene, walker, x_gait, period_s: float, intervals: int):
    """The phased collocation's starting step for ``scene`` (its ``optimize.
    initial_guess``, else one step of its gait ``x_gait`` (2n,) of period ``period_s``
    [s]), on about ``intervals`` intervals.

    Returns
    -------
    guess : list of (name, t, x)
        :func:`walkerlab.optimal.transcription.mode_sequence.phased_guess` (the scene's or a
        continuation artifact's gait) or :func:`~walkerlab.optimal.transcription.
        mode_sequence.optimized_guess` (another ``optimize.h5``).
    torque : list of ndarray or None
        Each phase's hip torque [N m] (another ``optimize.h5``'s; None: 0).
    order : list of (phase, guard, direction)
        The phases the starting gait's step goes through
        (:func:`walkerlab.optimal.transcription.phases.phase_order`).

    Raises
    ------
    ValueError
        An unusable artifact, or one whose phases are not the gait's (one line naming
        ``optimize.initial_guess``).
    """
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.guess import read_guess
    from walkerlab.optimal.transcription.mode_sequence import optimized_guess, phased_guess
    from walkerlab.optimal.transcription.phases import phase_order

    kind, got = None, None
    if scene.optimize.initial_guess is not None:
        kind, got = read_guess(scene, list(walker.state_names()))
    x0 = got if kind == "continuation" else x_gait
    guess, log = phased_guess(walker, x0, period_s, Solver.from_settings(scene.solver),
                              intervals)
    order = phase_order(walker, log)
    if kind != "optimize":
        return guess, None, order
    return (*optimized_guess(got, [n for n, _g, _d in order], intervals), order)


def _phased(scene, plant, x_gait, period_s, resolve_gait: bool = False) -> OptimizeData:
    """One step of a kneed or flat-footed walker phase by phase
    (:func:`walkerlab.optimal.transcription.mode_sequence.collocate_phases`), replayed on
    the rigid model and in the contact model (2 strides; the hip torque acts between a
    kneed walker's thighs, between a flat-footed walker's legs).  ``resolve_gait``: the
    scene's gait has a double-support phase the collocation's walker has not (flat feet),
    so the start is that walker's own gait, solved here (``x_gait``, ``period_s``
    unused).  A 3D walker's steps mirror each other: a stride (:func:`_stride`, phased)."""
    import time

    if plant.kind.in_3d and plant.data.mirror is not None:  # steps mirrored sideways
        return _stride(scene, plant, collocation_spec(scene), x_gait, period_s, phased=True)
    from walkerlab.analysis.gait.scene import solve_scene  # light
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.transcription.mode_sequence import (
        collocate_phases,
        phase_torque_of_time,
        replay_phases,
    )
    from walkerlab.optimal.transcription.step_cache import cached_mode_functions

    data = plant.data
    o = scene.optimize
    spec = collocation_spec(scene)
    walker = make_rigid_walker(data, double_support=False)  # no double-support phase yet
    guide = pushed(walker, data, spec.push_off_n_s)  # the scene's push-off: x_gait is its gait
    if resolve_gait:  # fixedpoint's gait has its double support
        g = solve_scene(scene, False, walker=guide, plant=plant)[1].gait.result
        x_gait, period_s = g.x, float(g.period_s)
    guess, guess_u, order = starting_phases(scene, guide, x_gait, period_s, spec.intervals)
    t0 = time.perf_counter()
    fns = cached_mode_functions(data, walker, order)
    build = time.perf_counter() - t0
    res = collocate_phases(fns, replace(spec, warm_start=guess_u is not None), guess,
                           guess_u)
    err, replayed = replay_phases(data, res)
    mu = replay_multipliers(replayed, res, scene, err)
    gait, contact_period, contact_outcome = reported.optimum_outcome(
        scene, res, err, lambda: contact_replay_phased(scene, res, strides=2, plant=plant))
    phases, phase_note = reported.hip_phase_replays_of(scene, data, res, phase_torque_of_time(res))
    states, units = reported.named_states(walker, res)
    return OptimizeData(res.t, states, res.u, res.step_period_s, res.step_length_m,
                        res.push_off_n_s, res.objective, err, mu, gait, res.status,
                        res.iterations, res.wall_time_s, units, objective_name=o.objective,
                        objective_unit=reported.unit_of_objective(o), terms=res.terms,
                        contact_step_period_s=contact_period, contact_outcome=contact_outcome,
                        cpu_time_s=res.cpu_time_s, phase_names=res.phase_names,
                        phase_start=res.phase_start, phase_duration_s=res.phase_duration_s,
                        build_time_s=build + res.build_time_s, phase_replays=phases,
                        phase_replay_outcome=phase_note,
                        **history_and_energies(scene, walker, res))


# -- a stride of two steps (legs that differ) --------------------------------------------

def starting_stride(scene, walker, x_gait, period_s: float, intervals: int, order=None):
    """The stride collocation's start for ``scene``: its ``optimize.initial_guess`` (another
    stride's ``optimize.h5``: its phases' states and torque; a continuation artifact's
    gait at ``at``: the stride map's start there), else one stride of its gait ``x_gait``
    (2n,) of mean step period ``period_s`` [s]; ``intervals`` a step; ``order`` each step's
    phases (None: the straight legs' :data:`~walkerlab.optimal.transcription.stride.STEP_PHASES`).

    Returns
    -------
    guess : list of (name, t, x)
        :func:`walkerlab.optimal.transcription.stride.stride_phases` of ``order``
        (:func:`walkerlab.optimal.transcription.stride.stride_guess`, or
        :func:`walkerlab.optimal.transcription.mode_sequence.optimized_guess` on
        ``2 intervals``).
    torque : list of ndarray or None
        Each phase's hip torque [N m] (another ``optimize.h5``'s; None: 0).

    Raises
    ------
    ValueError
        An unusable artifact, one of another walker, or one without the stride's phases (a
        one-step optimisation; one line naming ``optimize.initial_guess``); the starting
        gait does not make a stride (one line).
    """
    from walkerlab.integrate.solver import Solver
    from walkerlab.optimal.guess import read_guess
    from walkerlab.optimal.transcription.mode_sequence import optimized_guess
    from walkerlab.optimal.transcription.stride import STEP_PHASES, stride_guess, stride_phases

    kind, got = None, None
    if scene.optimize.initial_guess is not None:
        kind, got = read_guess(scene, list(walker.state_names()))
    if kind == "optimize":
        return optimized_guess(got, list(stride_phases(order or STEP_PHASES)), 2 * intervals)
    x0 = got if kind == "continuation" else x_gait
    return stride_guess(walker, x0, period_s, Solver.from_settings(scene.solver),
                        intervals, order), None


def _stride(scene, plant, spec, x_gait, period_s, phased: bool = False) -> OptimizeData:
    """One stride of a walker whose legs differ (the step sequence of the walker and its
    mirror: :func:`walkerlab.optimal.transcription.stride.stride_functions` on
    :func:`~walkerlab.optimal.transcription.mode_sequence.collocate_phases`); its
    ``step_period_s`` / ``step_length_m`` the mean step's, the multipliers the stride
    map's, each step's energies from its own walker (leg B's step: the mirror's masses);
    on stairs or footholds started and replayed there (:func:`~walkerlab.optimal.
    transcription.stride.on_ground`).  ``phased``: each step through the rigid walker's own
    phases (a 3D kneed walker's: :func:`~walkerlab.optimal.transcription.phases.phase_order`)."""
    import time

    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.transcription import stride
    from walkerlab.optimal.transcription.mode_sequence import collocate_phases
    from walkerlab.optimal.transcription.phases import phase_order  # the kneed steps'
    from walkerlab.optimal.transcription.step import ipopt_options  # their barrier's

    o, data = scene.optimize, plant.data
    _check_stride(o, bool(spec.push_off_free or spec.push_off_n_s))
    ground, base = step_ground(scene), make_rigid_walker(data)
    order = phase_order(base) if phased else None  # None: the straight legs' STEP_PHASES
    walker = stride.on_ground(base, data, ground)  # no ground: the walker itself
    guide = stride.on_ground(base, data, ground, lambda w, d: pushed(w, d, spec.push_off_n_s))
    guess, guess_u = starting_stride(scene, guide, x_gait, period_s, spec.intervals, order)
    t0 = time.perf_counter()
    fns = stride.stride_functions(data, ground, hold_advance=spec.target_step_length_m is None,
                                  order=order)
    build = time.perf_counter() - t0
    if phased:  # from the gait itself, a small barrier (IPOPT's 0.1 pushes it away)
        fns["solver"] = ({}, {**ipopt_options(spec), "mu_init": 1e-9})
    res = collocate_phases(fns, replace(spec, warm_start=guess_u is not None), guess,
                           guess_u)
    err, replayed = stride.replay_stride(data, res, ground=ground)
    mu = replay_multipliers(replayed, res, scene, err)  # the stride map's
    gait, contact_period, contact_outcome = reported.optimum_outcome(
        scene, res, err, lambda: contact_replay_stride(scene, res, strides=2, plant=plant))
    per = len(fns["phases"]) // 2  # each step's phases: its last ends in the heel strike
    lengths = [float(p.step(res.x[k - 1])) for k, p in zip(
        [*res.phase_start[per::per], res.t.size], fns["phases"][per - 1::per])]
    record = history_and_energies(scene, walker, res)
    parts = [history_and_energies(scene, w, stride.step_of(res, k))
             for k, w in enumerate((walker, walker.mirror))]
    record["energy"] = {kind: np.concatenate([p["energy"][kind] for p in parts])
                        for kind in record["energy"]}
    states, units = reported.named_states(walker, res)
    return OptimizeData(res.t, states, res.u, res.step_period_s / 2, float(np.mean(lengths)),
                        res.push_off_n_s, res.objective, err, mu, gait, res.status,
                        res.iterations, res.wall_time_s, units, objective_name=o.objective,
                        objective_unit=reported.unit_of_objective(o), terms=res.terms,
                        contact_step_period_s=contact_period, contact_outcome=contact_outcome,
                        cpu_time_s=res.cpu_time_s, phase_names=res.phase_names,
                        phase_start=res.phase_start, phase_duration_s=res.phase_duration_s,
                        build_time_s=build + res.build_time_s, steps=2,
                        phase_replay_outcome="not replayed: a stride of legs that differ is "
                        "replayed as a function of time only" if o.phase_replay else "",
                        **record)


# -- the collocation's part per walker kind ----------------------------------------------

@dataclass(frozen=True)
class Collocation:
    """How ``walkerlab optimize`` finds and replays the optimal gait of one walker kind
    (:class:`walkerlab.walker.kinds.Kind`): its transcription, starting guess and replay
    laws, reached through the kind's collocation part.

    Attributes
    ----------
    optimize : callable
        ``(scene, plant, x_gait, period_s) -> OptimizeData``: set up, started, solved and
        replayed (``plant``: the scene's :class:`~walkerlab.walker.plant.Plant`;
        ``x_gait`` (2n,), ``period_s`` [s]: the scene's gait, or None).
    from_targets : bool
        The guess is built from the targets alone, which are required
        (:func:`check_targets`), with no upstream gait (Kelly 2017's set-up).
    target_step : bool
        A walker of the kind with no gait of its own starts from a step built from the
        targets (:func:`walkerlab.optimal.guess.target_step`).
    legs_cross_level : bool
        The legs are straight: the swing foot is level with the stance foot when the legs
        of one length cross (:func:`_feet_level_when_legs_cross`).
    """

    optimize: Callable[..., OptimizeData]
    from_targets: bool = False
    target_step: bool = False
    legs_cross_level: bool = False


# each kind's collocation part (:attr:`walkerlab.walker.kinds.Kind.collocation`) given its
# transcription (the spoked wheel has none: refused from the capability table, :func:`_part`)
P.COLLOCATION_STRAIGHT_LEGS.provide(Collocation(_straight_legs, target_step=True,
                                                legs_cross_level=True))
P.COLLOCATION_LOCKING_KNEES.provide(Collocation(_phased))
P.COLLOCATION_FLAT_FEET.provide(Collocation(partial(_phased, resolve_gait=True)))
P.COLLOCATION_FIVE_LINK.provide(Collocation(optimize_five_link, from_targets=True))
