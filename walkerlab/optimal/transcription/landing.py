"""The collocation's heel strike on the scene's ground: stairs (every step lands a riser below,
or above, the stance foot's level) and footholds (step ``k`` lands ``-h_k`` below it), as the
rigid model meets them (:mod:`walkerlab.models.hybrid.ground`).

The rigid model's landing is the generated swing-foot clearance above the slope line through
the stance foot plus a constant (:func:`walkerlab.models.hybrid.ground.on_landing`),

    ``g(x) = swing_clearance(x) + drop_m cos(gamma)``  (crossed downward),

with the walker's own impact map; this module gives the one-step transcription
(:mod:`walkerlab.optimal.transcription.step`) the same guard.  A step's landing phase
(:func:`landing_phase`) is the slope's step phase (:func:`walkerlab.optimal.transcription.
mode_sequence.step_phase`) with that guard (its rate ``dg/dx f(x, u)``, so the swing foot
comes down onto the tread: ``-dg/dt >= touchdown_rate``, in m/s here), its step the advance
along the slope ``sqrt(|foot|^2 - (drop cos gamma)^2)`` (on level treads: the horizontal
distance between the feet, the tread's depth on stairs) and its clearance measured from the
lower of the two treads (a step down: the next one; up: the stance tread).  The reset (heel
strike, push-off included) and the periodicity ``x_0 = reset(x_end)`` are the slope's: the
state is the legs' angles and rates, which do not know the feet's heights.

Stairs take one step per stair: a gait that repeats on them advances one tread a step, so the
step's advance is constrained to ``terrain.tread_m`` (:class:`StepGround`); footholds are
period-``p`` (one phase per foothold, :func:`walkerlab.optimal.transcription.mode_sequence.
collocate_step`): each step lands at its foothold's height, the stride is the ``p`` steps.
A walker whose legs differ (the 3D straight legs with hip width) lands each step of its
stride on stairs or on footholds of one or two heights through :func:`landing_phase` as
well (:func:`walkerlab.optimal.transcription.stride.stride_functions`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

__all__ = ["FOOTHOLDS_STRIDE", "StepGround", "check_stride_ground", "landing_phase",
           "replay_footholds", "step_ground"]

#: why a stride (legs that differ) refuses footholds of more than two heights
FOOTHOLDS_STRIDE = ("terrain.foothold_heights_m: legs that differ (a walker with hip width) "
                    "are collocated as a stride of two steps, the walker's and its "
                    "mirror's, each landing on its foothold: p > 2 heights make a period of "
                    "lcm(p, 2) steps, more than one stride; give one or two heights")


@dataclass(frozen=True)
class StepGround:
    """The ground the collocation's steps land on.

    Attributes
    ----------
    drops_m : tuple of float
        Each step's landing depth [m] below the stance foot's level (stairs down: the
        riser; up: minus it; footholds: ``-h_k``), one per step of the ground's period.
    slope_rad : float
        The slope the landings are measured on (0 on stairs' level treads) [rad].
    advance_m : float or None
        The step's advance along the slope every step must make [m] (stairs: the tread's
        depth); None: free.
    kind : str
        ``terrain.kind`` (for messages).
    """

    drops_m: tuple
    slope_rad: float
    advance_m: float | None = None
    kind: str = "stairs"


def step_ground(scene) -> StepGround | None:
    """The ground of ``scene``'s collocation: None on the slope (the slope's guard, bit for
    bit), else its :class:`StepGround` (stairs: one drop, the advance the tread;
    footholds: one drop per foothold).

    Raises
    ------
    ValueError
        Footholds of their own slopes (``terrain.foothold_slopes_rad``), or a target step
        length on stairs other than the tread (one line naming the field).
    """
    from walkerlab.models.ground import landing_drops  # light

    t = scene.terrain
    if t is None or t.kind not in ("stairs", "footholds"):
        return None
    if t.kind == "footholds" and t.foothold_slopes_rad is not None:
        raise ValueError("terrain.foothold_slopes_rad: optimize transcribes footholds of one "
                         "slope (the scene's), at their heights; give foothold_heights_m "
                         "alone")
    drops = tuple(float(d) for d in landing_drops(t))
    advance = None
    if t.kind == "stairs":
        advance = float(t.tread_m)
        d = scene.optimize.target_step_length_m if scene.optimize is not None else None
        if d is not None and abs(float(d) - advance) > 1e-12:
            raise ValueError(f"optimize.target_step_length_m: {float(d):g} m, but on stairs "
                             f"the gait advances one tread a step (terrain.tread_m: "
                             f"{advance:g} m): leave it out or give the tread")
    if all(d == 0.0 for d in drops) and advance is None:
        return None  # footholds at the stance foot's level: the slope itself
    return StepGround(drops, float(scene.slope.phi_rad), advance, t.kind)


def check_stride_ground(ground: StepGround | None, data) -> None:
    """Refuse footholds of more than two heights for legs that differ (``data.mirror``):
    :data:`FOOTHOLDS_STRIDE` (a ValueError; one line)."""
    if ground is not None and data.mirror is not None and len(ground.drops_m) > 2:
        raise ValueError(FOOTHOLDS_STRIDE)


def landing_phase(base, fns: dict, drop_m: float, slope_rad: float, name: str = "step"):
    """One step of straight legs landing ``drop_m`` [m] below the stance foot's level
    (module docstring): :func:`walkerlab.optimal.transcription.mode_sequence.step_phase`'s
    phase with the landing's guard, its rate, the step's advance and the clearance from
    the lower tread.

    Parameters
    ----------
    base : walkerlab.optimal.transcription.phases.ModePhase
        The slope's step phase (:func:`walkerlab.optimal.transcription.mode_sequence.
        step_phase` of ``fns``).
    fns : dict
        :func:`walkerlab.optimal.transcription.step.step_functions` of the walker.
    drop_m : float
        Landing depth [m] (negative: above).
    slope_rad : float
        The slope the walker's clearance is measured from [rad].
    name : str
        The phase's name (footholds: ``step_<k>``).

    Returns
    -------
    walkerlab.optimal.transcription.phases.ModePhase
    """
    import casadi as ca

    offset = float(drop_m) * math.cos(float(slope_rad))
    x, u = ca.MX.sym("x", 2 * fns["n"]), ca.MX.sym("u")
    clear = fns["clearance"](x)
    guard = clear + offset
    rate = ca.jacobian(guard, x) @ fns["flow"](x, u)
    advance = ca.sqrt(ca.fmax(fns["step"](x) ** 2 - offset ** 2, 0.0))
    # a landing above the stance foot's level (offset < 0): the swing foot passes below it
    # as the legs cross (the planar legs' scuff, which the rigid model ignores: its heel
    # strike is the downward crossing), so the guard's sign is not kept inside the phase
    inside = base.inside and offset >= 0.0
    return replace(base, name=name, inside=inside,
                   guard=ca.Function("guard", [x, u], [guard]),
                   guard_rate=ca.Function("guard_rate", [x, u], [rate]),
                   clearance=ca.Function("clearance", [x], [clear + max(offset, 0.0)]),
                   step=ca.Function("step", [x], [advance]))


def replay_footholds(data, res, ground: StepGround, solver=None):
    """The optimised period on footholds (:func:`walkerlab.optimal.transcription.
    mode_sequence.collocate_footholds`) replayed on the rigid model on those footholds
    (:func:`walkerlab.models.hybrid.ground.on_footholds`: step ``k``'s heel strike at its
    foothold, the generated code and impact map): each step's walker with a hip actuator
    whose torque is its own step's (the quadratic through its interval's points, from its
    heel strike) and the optimised push-off, one period of the map
    (:func:`walkerlab.analysis.gait.poincare.poincare_map`) from ``x_0`` (DOP853 at rtol =
    atol = 1e-12 unless ``solver`` is given).

    Returns
    -------
    error : float
        Max-norm return error ``|x_0' - x_0|`` after the ``p`` steps (inf when a step does
        not end in a heel strike).
    walker : HybridWalker
        The replayed walker (its ``cycle`` the steps' walkers).
    """
    from types import SimpleNamespace

    import numpy as np

    from walkerlab.analysis.gait.poincare import StepFailed, poincare_map  # light
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.hybrid.actuated import actuate  # light
    from walkerlab.models.hybrid.ground import on_footholds  # light
    from walkerlab.optimal.transcription.step import replay_actuation, torque_of_time  # light

    spec, passive = replay_actuation(data, res.push_off_n_s)
    walker = on_footholds(lambda _g: passive, lambda _g: data,
                          [(d, ground.slope_rad) for d in ground.drops_m], True,
                          lambda w, d: actuate(w, d, spec))
    bounds = [*res.phase_start, res.t.size]
    zero = np.zeros((1, 2 * walker.actuators.n))
    for k, w in enumerate(walker.cycle):
        a, b = bounds[k], bounds[k + 1]
        tau = torque_of_time(SimpleNamespace(t=res.t[a:b] - res.t[a], u=res.u[a:b]))
        acts = w.actuators
        acts.torques = (lambda tau_k, ac: lambda t, x: np.array(
            [tau_k(float(np.real(t)) - ac.t_origin)]))(tau, acts)
        acts.torque_jacobian = lambda t, x: zero  # a torque of time alone
    solver = solver or Solver(method="DOP853", rtol=1e-12, atol=1e-12)
    x0 = np.asarray(res.x[0], float)
    try:
        x1 = poincare_map(walker, x0, solver, max_step_time=3.0 * res.step_period_s)[0]
    except StepFailed:
        return float("inf"), walker
    return float(np.max(np.abs(np.asarray(x1) - x0))), walker
