"""The value of one field whose period-1 gait meets a target speed, step length or step
period (:func:`target`, ``walkerlab target``), solved in memory with the walker of
:mod:`walkerlab.api.walker`."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from walkerlab.api.walker import Walker
from walkerlab.api.walks import Gait
from walkerlab.units import field_unit

if TYPE_CHECKING:  # pragma: no cover
    from walkerlab.config import Scene

__all__ = ["Target", "target"]


@dataclass(frozen=True)
class Target:
    """The value of one field whose period-1 gait meets a target (:func:`target`).

    Attributes
    ----------
    field : str
        The dotted scene field solved for.
    value : float
        Its value [the field's unit, ``unit``].
    unit : str
        The field's unit (``-`` when it has none).
    walker : Walker
        The walker with ``field`` set to ``value``.
    gait : Gait
        Its period-1 gait (step length, speed, cost of transport, multipliers ...).
    """

    field: str
    value: float
    unit: str
    walker: Walker
    gait: Gait


def target(scene: Scene | str | Path | dict[str, Any], vary: str, *,
           speed_m_per_s: float | None = None, step_length_m: float | None = None,
           step_period_s: float | None = None) -> Target:
    """The value of ``vary`` whose period-1 gait has a target speed, step length or step
    period, solved with the fixed point (``walkerlab target``; Kuo's DynLoco
    ``findgait(target=speed, varying=P)``), in memory: nothing is written.

    Parameters
    ----------
    scene : Scene, str, Path or dict
        A scene (:func:`walkerlab.api.load_scene`); its gait at its own value of ``vary``
        starts the solve.
    vary : str
        A real-valued field of the ``walker`` or ``slope`` section
        (``"walker.actuation.push_off.impulse_n_s"``).
    speed_m_per_s, step_length_m, step_period_s : float
        Exactly one target, a positive finite number [m/s, m, s].

    Returns
    -------
    Target

    Raises
    ------
    walkerlab.config.SceneError
        The checks of ``walkerlab target`` (:func:`check_target`), before any map.
    walkerlab.studies.params.SweepError
        ``vary`` names no field of the scene.
    walkerlab.analysis.continuation.target.TargetNotReached
        No gait meets the target near the scene's own (one line).
    walkerlab.analysis.gait.search.GaitNotFound
        No gait at the scene's own value to start from.

    Examples
    --------
    >>> t = wl.target("configs/powered_compass.yaml",
    ...               "walker.actuation.push_off.impulse_n_s", speed_m_per_s=0.45)  # doctest: +SKIP
    >>> t.value, t.gait.step_period, t.gait.cost_of_transport                      # doctest: +SKIP
    """
    from walkerlab.studies.continuation import scene_value  # light

    given = {k: v for k, v in (("speed_m_per_s", speed_m_per_s),
                               ("step_length_m", step_length_m),
                               ("step_period_s", step_period_s)) if v is not None}
    walker, gait = Walker.from_scene(scene).find_gait_for(vary, **given)
    return Target(vary, scene_value(walker.scene, vary), field_unit(vary) or "-", walker, gait)
