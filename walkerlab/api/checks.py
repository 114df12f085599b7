"""The checks of the in-memory walker's arguments (:mod:`walkerlab.api.walker`,
:mod:`walkerlab.api.targets`), each refusing a bad value in one line that names it, and the
map's failures said in the walker's terms."""

from __future__ import annotations

from contextlib import contextmanager
from typing import TYPE_CHECKING

from walkerlab.integrate.work_limit import StepWorkLimit, step_work_limit
from walkerlab.rigid_walker import STEP_EVALUATIONS, positive, short

if TYPE_CHECKING:  # pragma: no cover
    from walkerlab.config import Scene

__all__ = ["STEP_EVALUATIONS", "bounded_steps", "check_target", "clear_step_failure",
           "positive", "short", "simulate_options"]

def simulate_options(strides, sample_rate_hz) -> tuple[int, float]:
    """``(strides, sample_rate_hz)`` checked by the ``simulate`` section's own fields
    (whole strides from 1 to the cap, a positive rate up to its cap); one line each."""
    import numbers

    from pydantic import ValidationError

    from walkerlab.config import SceneError  # light
    from walkerlab.config.studies import SimulateSettings  # light

    if isinstance(strides, bool) or not isinstance(strides, numbers.Integral):
        raise SceneError(f"simulate: strides={short(strides)}: give a whole number of "
                         "strides (an int, e.g. strides=10)")
    if isinstance(sample_rate_hz, bool) or not isinstance(sample_rate_hz, numbers.Real):
        raise SceneError(f"simulate: sample_rate_hz={short(sample_rate_hz)}: give a "
                         "number of samples per second, e.g. 500")
    try:
        sim = SimulateSettings.model_validate({"strides": int(strides),
                                               "sample_rate_hz": float(sample_rate_hz)})
    except ValidationError as err:
        e = err.errors()[0]
        field = e["loc"][0]
        value = strides if field == "strides" else sample_rate_hz
        raise SceneError(f"simulate: {field}={short(value)}: {e['msg'].lower()} "
                         f"(as simulate.{field})") from None
    return sim.strides, sim.sample_rate_hz


def clear_step_failure(exc, max_step_time: float):
    """A :class:`StepFailed` of the map said in the walker's terms (one line: how the step
    ended, when, and what to do), not in the integrator's."""
    from walkerlab.analysis.gait.poincare import StepFailed  # light

    t = f"t = {exc.t:.4g} s"
    why = {
        "fall": f"the walker fell at {t}, before its heel strike (a fall guard fired): the "
                "state is not on a walking gait; start from a gait (w.fixed_point().x) or "
                "nearer to it",
        "t_final": f"no heel strike within max_step_time_s = {max_step_time:g} s "
                   "(fixedpoint.max_step_time_s): the walker stalled",
        "solver_failure": f"the integrator stopped at {t}: "
                          f"{' '.join(str(exc).split(' s ', 1)[-1].split())}",
    }.get(exc.termination)
    if why is None:
        return exc
    out = StepFailed(exc.termination, exc.t, exc.x)
    out.args = (f"step: {why}",)
    return out



def check_target(scene: Scene, vary, target: dict) -> tuple[str, float]:
    """The field and target of :meth:`walkerlab.api.walker.Walker.find_gait_for` (and
    ``walkerlab target``) checked before any map.

    Parameters
    ----------
    scene : walkerlab.config.Scene
    vary : str
        Dotted scene field to solve for.
    target : dict
        ``{measure: value}``, one of
        :data:`walkerlab.analysis.continuation.target.MEASURES`.

    Returns
    -------
    name : str
        The measure (``speed_m_per_s``, ``step_length_m`` or ``step_period_s``).
    value : float
        The target [m/s, m or s].

    Raises
    ------
    walkerlab.config.SceneError
        Not exactly one known measure; a value that is not a positive finite number (a
        speed, a step length and a step period are all > 0); ``vary`` not a string, a field
        outside the ``walker`` and ``slope`` sections, a whole-number field or one whose
        value is no number (one line each).
    walkerlab.studies.params.SweepError
        ``vary`` names no field of the scene (with the closest name).
    """
    import math
    import numbers

    from walkerlab.analysis.continuation.target import MEASURES  # light
    from walkerlab.config import SceneError  # light
    from walkerlab.studies.continuation import scene_value  # light
    from walkerlab.studies.params import ParamAxis, check_axes, takes_whole_numbers  # light

    if len(target) != 1 or next(iter(target)) not in MEASURES:
        raise SceneError(f"target: give exactly one of {', '.join(MEASURES)} (got "
                         f"{', '.join(target) or 'none'})")
    (name, value), = target.items()
    unit = MEASURES[name][1]
    if (isinstance(value, bool) or not isinstance(value, numbers.Real)
            or not math.isfinite(value) or value <= 0):
        raise SceneError(f"target {name} (--{name.replace('_', '-')}) = {short(value)}: "
                         f"give a positive finite number [{unit}]")
    if not isinstance(vary, str) or not vary.startswith(("walker.", "slope.")):
        raise SceneError(f"target --vary {short(vary)}: vary a numeric field of the walker "
                         "or the slope (e.g. walker.actuation.push_off.impulse_n_s); the "
                         "gait depends on no other section")
    from walkerlab.studies.params import SweepError  # light

    try:
        # an unknown field: SweepError with the closest name
        check_axes(scene, [ParamAxis(vary, (), vary)], values=False)
    except SweepError as exc:
        raise SweepError(str(exc).replace("--param ", "target --vary ", 1)) from None
    if takes_whole_numbers(scene, ParamAxis(vary, (), vary)):
        raise SceneError(f"target --vary {vary}: the field takes whole numbers; a target is "
                         "solved over a real-valued field")
    scene_value(scene, vary)  # unset or not a number: one line
    return name, float(value)


@contextmanager
def bounded_steps(step_evaluations: int, max_step_time: float):
    """Each walking step inside bounded to ``step_evaluations`` right-hand-side evaluations
    (work, not time: the same step ends the same way on any machine); a failed step said in
    one line (how and when it ended, what to do: :func:`clear_step_failure`).

    Raises
    ------
    walkerlab.analysis.gait.poincare.StepFailed
        A step used up its evaluations (``work_limit``), or ended otherwise than at a heel
        strike (its one line).
    """
    from walkerlab.analysis.gait.poincare import StepFailed  # light

    try:
        with step_work_limit(step_evaluations):
            yield
    except StepWorkLimit:
        out = StepFailed("work_limit", float("nan"), None)
        out.args = (f"step: a walking step used up its {step_evaluations:.3g} right-hand-side "
                    "evaluations (Walker(..., step_evaluations=...)): a state far from any "
                    "gait, or a very stiff spring, makes the integrator crawl",)
        raise out from None
    except StepFailed as exc:
        raise clear_step_failure(exc, max_step_time) from None
