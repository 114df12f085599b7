"""A periodic gait of a walker whose legs differ, by multi-phase direct collocation of one
**stride**: leg A's step (``leg1`` swinging, ``leg2`` in stance), its heel strike, leg B's
step (the rigid model's ``mirror`` walker: ``leg2`` swinging), its heel strike back to the
start.

One step would close on itself only for mirror-image legs: with legs that differ it closes
with the wrong leg in stance every other step (a false gait); the Poincaré map of such a
walker is a stride (:func:`walkerlab.analysis.gait.poincare.poincare_map`, Goswami, Thuilot
& Espiau 1998; Moon & Spong 2010), and so is the periodic boundary condition here.

The stride is a fixed sequence of four phases of :mod:`walkerlab.optimal.transcription.phases`: each
step's ``early_swing`` (until ``midstance``, the legs passing: the point foot scuffs through
the ground there, which the rigid model ignores, paper Sec. 3.2) and ``late_swing`` (until
``heel_strike``: the swing foot above the slope inside it, the guard zero with a minimum
crossing rate at its end), each phase with its own free duration and Hermite-Simpson mesh
(:func:`walkerlab.optimal.transcription.mode_sequence.collocate_phases`); leg A's phases from the
symbolic equations with ``data``'s numbers, leg B's with ``data.mirror``'s (the same
equations, the other leg's numbers), leg A's heel strike (its reset: the impact with A's
numbers, roles swapped) links them, leg B's closes the stride.  Targets (speed, step
length, step period) are the stride's mean step's.  The cost of transport is both steps'
positive hip work over ``M g`` and the stride's distance (both step lengths): the power
``u d(hip angle)/dt``, the hip angle (swing minus stance) and the swing foot ahead are leg
A's functions, used on leg B's step as well - the same expressions in the mirror's state
(its swing leg first), no leg's number in them.  The friction cone bounds each phase's
ground reaction, from its own walker's masses.  A push-off (fixed, or free: one decision
variable) acts before both heel strikes, each with its own leg's numbers (the extended-
coordinate impact of :mod:`walkerlab.models.hybrid.actuated`); its work joins the cost of
transport and can be the objective (``push_off_work``, both strikes').

On stairs and footholds (:func:`walkerlab.optimal.transcription.landing.step_ground`) each
step's late swing is :func:`walkerlab.optimal.transcription.landing.landing_phase` of that
step's own phase (the rigid model's guard ``swing_clearance + riser cos(gamma)``; Kuo 1999's
walker with hip width as the planar legs: the treads are level across the walking direction,
so the lateral offset of the feet does not move the landing;
:func:`walkerlab.models.hybrid.ground.on_landing`), each step advancing one tread on stairs;
on footholds of two heights leg A's step lands on the first, leg B's on the second
(:func:`walkerlab.models.hybrid.ground.on_footholds`' order: the stride is their period).
Measured on configs/hip_width_stairs.yaml (least effort, 40 intervals a step): effort 2.3e-7
N^2 m^2 s (peak 0.6 mN m), the replay closing to 7.9e-7 (1.6e-7 on 60) - the passive stair
gait advances 0.3409354 m, 5 um more than the tread, so the held tread costs that little
torque; on treads of the passive advance the optimum is the passive gait. On
configs/hip_width_footholds.yaml (+-0.5 mm) the least effort is 1e-25 N^2 m^2 s, the passive
period-2 gait, its replay closing to 2.0e-7 on 60 intervals (tests/test_optimize_3d.py).
More than two heights are refused
(:data:`walkerlab.optimal.transcription.landing.FOOTHOLDS_STRIDE`).

A 3D walker with locking knees (``order``: :func:`walkerlab.optimal.transcription.phases.
phase_order` of its rigid model) takes each step as the planar kneed walker's phases,
``unlocked_swing`` until ``knee_strike`` (its plastic reset links the phases) and
``locked_swing`` until ``heel_strike`` (the stride's four phases
``leg1_swing:unlocked_swing`` ... ``leg2_swing:locked_swing``), the hip torque between the
thighs; started from one stride of its rigid gait and replayed alike.  Measured on
configs/kneed_3d_stabilised.yaml (least effort, 80 intervals a step): objective 1.6e-20
N^2 m^2 s, the start 4.8e-7 from the shooting fixed point, the replay closing to 2.2e-7
(tests/test_optimize_3d.py).

A result is a gait after its replay on the rigid model (:func:`replay_stride`): the
actuated walker and its mirror, each step's torque the optimised one as a function of the
time since that step's heel strike, one stride from the optimised start; its return error
and the stride map's Floquet multipliers.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from walkerlab.optimal.transcription.landing import check_stride_ground, landing_phase

__all__ = ["STEP_PHASES", "STRIDE_PHASES", "check_objective", "on_ground", "replay_stride",
           "step_of", "stride_functions", "stride_guess", "stride_phases", "stride_walker"]

#: the rigid model's phases of a straight-legged step
#: (:func:`walkerlab.optimal.transcription.phases.
#: phase_order` of it), each step of the stride named by its swinging leg
STEP_PHASES = (("early_swing", "midstance", 1), ("late_swing", "heel_strike", -1))
#: the stride's steps: the leg that swings in each (the rigid model's ``legs`` order)
SWINGING = ("leg1", "leg2")


def _named(leg: str, name: str) -> str:
    """A stride phase's name: ``<swinging leg>:<rigid phase>``."""
    return f"{leg}_swing:{name}"


def stride_phases(order=STEP_PHASES) -> tuple[str, ...]:
    """The stride's phase names in order, each step going through ``order`` (a step's
    ``(phase, guard, direction)``: :func:`walkerlab.optimal.transcription.phases.
    phase_order`; default the straight legs' :data:`STEP_PHASES`)."""
    return tuple(_named(leg, name) for leg in SWINGING for name, _g, _d in order)


#: the straight legs' stride's four phases in order (:func:`stride_functions`' ``phases``)
STRIDE_PHASES = stride_phases()


def check_objective(o, pushes: bool) -> None:
    """Refuse an objective of the ``optimize`` section ``o`` the stride transcription does
    not take (one line naming the field); ``pushes``: the stride has a push-off (fixed or
    free)."""
    from walkerlab.optimal.transcription.mode_sequence import PHASED_OBJECTIVES

    asked = dict(o.weights or {}) if o.objective == "weighted" else {o.objective: 1.0}
    known = PHASED_OBJECTIVES + (("push_off_work",) if pushes else ())
    bad = [k for k in asked if k not in known]
    if bad:
        raise ValueError(f"optimize.objective: legs that differ take "
                         f"{', '.join(known)} (or their weighted sum), not "
                         f"{', '.join(bad)}" + ("" if pushes else " (push_off_work: with a "
                                                "push-off, walker.actuation.push_off or "
                                                "optimize.push_off: free)"))


def stride_functions(data, ground=None, hold_advance: bool = True, order=None) -> dict:
    """CasADi functions of the stride of ``data``'s walker (legs that differ: ``data.mirror``
    not None): as :func:`walkerlab.optimal.transcription.phases.mode_functions`, its ``phases``
    those of the stride (module docstring): each step's ``order``, named
    ``leg1_swing:early_swing`` ...

    Parameters
    ----------
    data : WalkerData
    ground : walkerlab.optimal.transcription.landing.StepGround, optional
        Stairs, or footholds of one or two heights: step ``k`` (0: leg A's, 1: leg B's)
        lands ``ground.drops_m[k % p]`` [m] below its stance foot's level (``p`` the
        footholds' period; the order of :func:`walkerlab.models.hybrid.ground.on_footholds`)
        (:func:`walkerlab.optimal.transcription.landing.landing_phase` on that step's own
        phase: the guard ``swing_clearance + drop cos(gamma)`` of
        :func:`walkerlab.models.hybrid.ground.on_landing`, the advance along the slope
        ``sqrt(|foot|^2 - (drop cos gamma)^2)``, ``|foot|`` the swing foot's distance in the
        sagittal plane (along the slope and its normal; the hip width's lateral offset is not
        part of it)); None: the slope's heel strike, bit for bit.
    order : list of (phase, guard, direction), optional
        Each step's phases (:func:`walkerlab.optimal.transcription.phases.phase_order` of
        the rigid walker: a 3D kneed walker's ``unlocked_swing`` until ``knee_strike``,
        ``locked_swing`` until ``heel_strike``); None: the straight legs'
        :data:`STEP_PHASES`.
    hold_advance : bool
        Stairs (``ground.advance_m``): each step advances one tread (``constrain``: both
        steps' advance ``== ground.advance_m`` [m]); False when a target step length holds
        the mean step instead.

    Raises
    ------
    ValueError
        Mirror-image legs (one step is the map), flat or planar arc feet, knees without their
        ``order`` (or knees that do not lock), a planar walker's torso (a 3D walker's upper
        body on the bisecting hip is in its equations), massless legs; footholds of more
        than two heights (one line).
    """
    from walkerlab.optimal.transcription.step_cache import cached_mode_functions

    st = data.structure
    if data.mirror is None:
        raise ValueError("optimize: a stride is for legs that differ (mirror-image legs take "
                         "one step)")
    one_step = st.kind.collocation is not None and st.kind.collocation.one_step
    kneed = order is not None and st.kind.knees_lock and st.kind.phases is not None
    if (not (one_step or kneed) or (st.foot == "arc" and not st.in_3d)
            or (st.torso and not st.in_3d) or any(b.massless for b in st.bodies)):
        raise ValueError("optimize: a stride of legs that differ takes massive straight or "
                         "locking-knee legs with point feet (a 3D walker's discs too) today "
                         "(flat or planar arc feet, a planar torso: not yet)")
    check_stride_ground(ground, data)
    order = list(order) if order is not None else list(STEP_PHASES)
    fns, phases = None, []
    for k, (leg, d) in enumerate(zip(SWINGING, (replace(data, mirror_params=None),
                                                data.mirror))):
        f = cached_mode_functions(d, None, order)
        step = [replace(p, name=_named(leg, p.name)) for p in f["phases"]]
        if ground is not None:
            step[-1] = _landing(step[-1], f["n"], ground, k)
        phases += step
        fns = fns or f
    out = {**fns, "phases": phases}
    if ground is not None and ground.advance_m is not None and hold_advance:
        ends = [k for k, p in enumerate(phases) if p.guard_name == "heel_strike"]

        def constrain(opti, Xs, _Us, _Ts, advance=float(ground.advance_m)):
            for k in ends:  # one tread a step (the stairs' period is one step)
                opti.subject_to(phases[k].step(Xs[k][:, -1]) == advance)
        out["constrain"] = constrain
    return out


def _landing(phase, n: int, ground, k: int):
    """Step ``k``'s heel-strike ``phase`` landing on ``ground`` (:func:`walkerlab.optimal.
    transcription.landing.landing_phase` on the step's own flow, clearance and step)."""
    own = {"n": n, "flow": phase.flow, "clearance": phase.clearance, "step": phase.step}
    drop = ground.drops_m[k % len(ground.drops_m)]
    return landing_phase(phase, own, drop, ground.slope_rad, phase.name)


def on_ground(walker, data, ground, finish=None):
    """The rigid ``walker`` of ``data`` (legs that differ: with its ``mirror``) on the
    stride's ``ground``: None, the walker itself; stairs or footholds of one height (one
    drop): :func:`walkerlab.
    models.hybrid.ground.on_landing`; footholds of two heights: :func:`walkerlab.models.
    hybrid.ground.on_footholds` (its ``cycle``: leg A's step on the first, leg B's on the
    second).  ``finish(walker, data)`` (the actuators) is applied to every step's walker."""
    from walkerlab.models.hybrid.ground import on_footholds, on_landing  # light

    finish = finish or (lambda w, _d: w)
    if ground is None or len(ground.drops_m) == 1:
        drop = 0.0 if ground is None else ground.drops_m[0]
        return finish(on_landing(walker, data, drop), data)  # drop 0: the walker itself
    return on_footholds(lambda _g: walker, lambda _g: data,
                        [(d, ground.slope_rad) for d in ground.drops_m], True, finish)


def _steps(walker) -> tuple:
    """The stride's two steps' walkers: its ``cycle`` (footholds) or it and its mirror."""
    return tuple(walker.cycle) if walker.cycle else (walker, walker.mirror)


def stride_guess(walker, x0, period_s: float, solver, intervals: int, order=None) -> list:
    """One stride of the rigid ``walker`` (legs that differ: ``walker.mirror``) from the
    post-impact state ``x0`` (2n,), each step sampled on ``intervals`` intervals shared
    among its phases (:func:`walkerlab.optimal.transcription.mode_sequence.phased_guess`).

    Parameters
    ----------
    period_s : float
        The gait's (mean) step period [s]: a step longer than three is no step.
    order : list of (phase, guard, direction), optional
        Each step's phases (:func:`stride_functions`' ``order``); None: the straight legs'
        :data:`STEP_PHASES`.

    Returns
    -------
    list of (name, t (2 N_p + 1,) [s from the phase's start], x (2 N_p + 1, 2n))
        The phases of :func:`stride_functions` in order (each step's ``order``).

    Raises
    ------
    ValueError
        A step does not end in a heel strike or crosses other phases (one line).
    """
    from walkerlab.optimal.transcription.mode_sequence import phased_guess

    names = tuple(p for p, _g, _d in (order if order is not None else STEP_PHASES))
    out, x = [], np.asarray(x0, float)
    for leg, w in zip(SWINGING, _steps(walker)):
        guess, log = phased_guess(w, x, period_s, solver, intervals)
        if tuple(g[0] for g in guess) != names:
            raise ValueError(f"optimize: the starting gait's {leg} step crosses "
                             f"{[g[0] for g in guess]}, not {' and '.join(names)}")
        out += [(_named(leg, name), t, xs) for name, t, xs in guess]
        x = np.asarray(w.reset(guess[-1][2][-1]), float)
    return out


def step_of(res, k: int):
    """Step ``k`` (0: leg A's, 1: leg B's) of an optimised stride
    (:class:`walkerlab.optimal.transcription.mode_sequence.PhasedResult`) as a result of its own:
    its points, phases and durations, its times from its heel strike [s] (each step has half
    the stride's phases)."""
    P = len(res.phase_names) // 2
    bounds = list(res.phase_start) + [res.t.size]
    a, b = bounds[k * P], bounds[(k + 1) * P]
    t0 = float(res.t[a])
    return replace(res, t=res.t[a:b] - t0, x=res.x[a:b], u=res.u[a:b],
                   phase_names=res.phase_names[k * P:(k + 1) * P],
                   phase_start=np.asarray(res.phase_start[k * P:(k + 1) * P]) - a,
                   phase_duration_s=res.phase_duration_s[k * P:(k + 1) * P],
                   step_period_s=float(np.sum(res.phase_duration_s[k * P:(k + 1) * P])))


def stride_walker(data, res, ground=None):
    """The rigid walker of ``data`` and its mirror with a hip actuator each, whose torque is
    the optimised one of its own step (:func:`walkerlab.optimal.transcription.mode_sequence.
    phase_torque_of_time` of :func:`step_of`) from that step's heel strike, and the
    stride's push-off impulse ``res.push_off_n_s`` [N s] before each heel strike (if
    any); its heel strikes on the stride's ``ground`` (:func:`on_ground`; None: the
    slope's)."""
    from walkerlab.config.actuation import Actuation, JointTorque, PushOff, TorqueLaw  # light
    from walkerlab.models.hybrid.actuated import actuate  # light
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.transcription.mode_sequence import phase_torque_of_time

    push = PushOff(impulse_n_s=res.push_off_n_s) if res.push_off_n_s > 0.0 else None
    spec = Actuation(push_off=push, torques=[JointTorque(joint="hip", law=TorqueLaw(),
                                                         max_torque_n_m=1e6)])
    walker = on_ground(make_rigid_walker(data, "biped", "derived"), data, ground,
                       lambda w, d: actuate(w, d, spec))
    for k, w in enumerate(_steps(walker)):
        tau, acts = phase_torque_of_time(step_of(res, k)), w.actuators
        acts.torques = (lambda tau_k, a: lambda t, x: np.array(
            [tau_k(float(np.real(t)) - a.t_origin)]))(tau, acts)
    return walker


def replay_stride(data, res, solver=None, ground=None):
    """The optimised stride replayed on the rigid model (its generated code, its own phases,
    guards and resets; not the CasADi expressions): :func:`stride_walker`, one stride
    (:func:`walkerlab.analysis.gait.poincare.poincare_map`) from ``x_0`` (DOP853 at rtol =
    atol = 1e-12 unless ``solver`` is given), on the stride's ``ground`` (:func:`on_ground`;
    None: the slope).

    Returns
    -------
    error : float
        Max-norm return error ``|x_0' - x_0|`` [rad, rad/s] (inf when a step does not end
        in a heel strike or crosses other phases than the optimised ones).
    walker : HybridWalker
        The replayed walker (with its mirror).
    """
    from walkerlab.analysis.gait.poincare import StepFailed, poincare_map  # light
    from walkerlab.integrate.solver import Solver

    walker = stride_walker(data, res, ground)
    solver = solver or Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    x0, segs = np.asarray(res.x[0], float), []
    try:
        x1 = poincare_map(walker, x0, solver, max_step_time=3.0 * res.step_period_s,
                          steps=segs)[0]
    except StepFailed:
        return float("inf"), walker
    crossed = tuple(_named(leg, ph.name) for leg, s in zip(SWINGING, segs)
                    for ph, _s, _ab in s.pieces)
    if crossed != tuple(res.phase_names):
        return float("inf"), walker
    return float(np.max(np.abs(x1 - x0))), walker
