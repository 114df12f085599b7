"""An exported file walked in its engine where the engine is installed (``walkerlab export
--walk``): MuJoCo for the MJCF (:func:`walkerlab.export.mujoco_walk.walk`), OpenSim for the
OpenSim model (:func:`walkerlab.export.opensim_walk.walk`, in a process of its own), from the
file's own start (the MJCF's ``gait`` keyframe, the OpenSim model's default state: the rigid
gait just after heel strike) for ``steps`` rigid step periods and a third, its heel strikes'
mean step period set against the rigid gait's.

A spoked wheel's MJCF rolls (:func:`walkerlab.export.mujoco_walk.roll`: its spoke strikes
are its steps), as its OpenSim model does (the spokes' touchdowns,
:mod:`walkerlab.export.opensim_walk`).  A format no engine here walks (a URDF has no
ground, an Adams dataset needs Adams Solver) and an engine that is not installed give one
line saying why, and no walk.
"""

from __future__ import annotations

import importlib.util
import math
from dataclasses import dataclass
from pathlib import Path

__all__ = ["DEFAULT_STEPS", "DEFAULT_TOLERANCE", "EngineWalk", "not_walked", "walk_export"]

#: Heel strikes a walk must reach (the MuJoCo check of every shipped scene: >= 10 alternating
#: strikes).
DEFAULT_STEPS = 10
#: Relative step-period tolerance against the rigid gait (MuJoCo's contact is soft and
#: linear: walkerlab's own contact model differs from the rigid one by 0.1-1 %).
DEFAULT_TOLERANCE = 0.01
#: Engines by format: (name, importable module, extra that installs it).
ENGINES = {"mjcf": ("MuJoCo", "mujoco", "engines"), "osim": ("OpenSim", "opensim", "osim")}
#: Why a format is walked by no engine here.
NO_ENGINE = {"urdf": "a URDF has no ground or contact (walk the MJCF: --format mjcf)",
             "adm": "Adams Solver is not a Python engine (run walker.acf in Adams Solver)"}


@dataclass(frozen=True)
class EngineWalk:
    """An export's walk in its engine, or why there was none.

    Attributes
    ----------
    engine : str
        "MuJoCo", "OpenSim" or "" (no engine for the format).
    reason : str
        Why the file was not walked ("" when it was): one line.
    strikes : int
        Heel strikes seen.
    alternating : bool
        Every strike by the other leg than the one before (a wheel: by the next spoke).
    strikes_in_turn : int
        The strikes from the first on, each by the other leg than the one before (a wheel:
        by the next spoke), before the first out of turn (``strikes`` when ``alternating``):
        how long a laterally unstable walker holds its gait before its lateral mode ends
        the walk, by a fall or by feet striking out of turn.
    first_leg : str
        The leg of the first strike (leg2 stands at the start: "leg1"; a spoked wheel's
        spoke 0 stands: "spoke1"; "" without strikes).
    fell : bool
        The hip fell below half its height (the loops' fall test).
    t_end_s : float
        Simulated time [s].
    period_s : float
        Mean time between heel strikes [s] (nan with fewer than two).
    rigid_period_s : float
        The rigid gait's step period [s] (a stride's two steps: their mean).
    steps : int
        Heel strikes asked for.
    tolerance : float
        Relative step-period tolerance.
    contact_period_s : float
        The contact model's mean step period [s] over the last steps of the scene's
        up-to-date ``contact_sim.h5`` (NaN: none), the other reference the walk is set
        against.
    rolling : bool
        A spoked wheel's roll: its strikes are spokes landing one after another (no legs
        to alternate: :attr:`line` does not call them alternating).
    """

    engine: str
    reason: str = ""
    strikes: int = 0
    alternating: bool = False
    first_leg: str = ""
    fell: bool = False
    t_end_s: float = 0.0
    strikes_in_turn: int = 0
    period_s: float = math.nan
    rigid_period_s: float = math.nan
    steps: int = DEFAULT_STEPS
    tolerance: float = DEFAULT_TOLERANCE
    contact_period_s: float = math.nan
    rolling: bool = False

    @property
    def walked(self) -> bool:
        """The engine ran the file."""
        return not self.reason

    @property
    def relative(self) -> float:
        """The step period against the rigid one, ``period / rigid - 1`` [-]."""
        return self.period_s / self.rigid_period_s - 1.0

    @property
    def ok(self) -> bool:
        """At least ``steps`` alternating heel strikes, no fall, the mean step period within
        ``tolerance`` of the rigid gait's."""
        return (self.walked and not self.fell and self.alternating
                and self.strikes >= self.steps and abs(self.relative) <= self.tolerance)

    @property
    def line(self) -> str:
        """The walk in one line (or why there was none)."""
        if not self.walked:
            return f"not walked: {self.reason}"
        how = ("each by the next spoke" if self.rolling and self.alternating else
               "not each by the next spoke" if self.rolling else
               "alternating" if self.alternating else "not alternating")
        head = (f"walked in {self.engine}: {self.strikes} heel strikes ({how}) in "
                f"{self.t_end_s:.4g} s")
        if self.fell:
            head += ", then fell"
        if self.strikes < 2:
            return head + f"; the rigid gait steps every {self.rigid_period_s:.6g} s"
        verdict = "within" if abs(self.relative) <= self.tolerance else "outside"
        contact = ("" if not math.isfinite(self.contact_period_s) else
                   f"; the contact model's {self.contact_period_s:.6g} s "
                   f"({100 * (self.period_s / self.contact_period_s - 1):+.2f} %)")
        return (f"{head}; mean step period {self.period_s:.6g} s against the rigid gait's "
                f"{self.rigid_period_s:.6g} s ({100 * self.relative:+.2f} %, {verdict} "
                f"{100 * self.tolerance:g} %){contact}")


def not_walked(reason: str) -> EngineWalk:
    """No walk, for ``reason`` (one line)."""
    return EngineWalk("", reason=reason)


def walk_export(path: Path | str, fmt: str, rigid_period_s: float,
                steps: int = DEFAULT_STEPS, tolerance: float = DEFAULT_TOLERANCE,
                spokes: bool = False, feedback=None) -> EngineWalk:
    """Walk the exported file ``path`` (format ``fmt``) in its engine for ``steps + 1.3``
    rigid step periods (module docstring).

    Parameters
    ----------
    path : path
        The file (``walker.xml``, ``walker.osim``; other formats: no engine).
    fmt : str
        "mjcf", "osim", "urdf" or "adm".
    rigid_period_s : float
        The rigid gait's step period [s].
    steps : int
        Heel strikes asked for.
    tolerance : float
        Relative step-period tolerance.
    spokes : bool
        A spoked wheel: its spoke strikes (the MJCF's
        :func:`walkerlab.export.mujoco_walk.roll`, the OpenSim model's spoke touchdowns)
        instead of two legs' heel strikes.
    feedback : walkerlab.export.mujoco_walk.VirtualConstraintFeedback, optional
        The scene's virtual constraints (the MJCF's stepping loop evaluates them).

    Returns
    -------
    EngineWalk
        Not walked (one line why) for a format without an engine here or an engine that is
        not importable.
    """
    if fmt not in ENGINES:
        return not_walked(NO_ENGINE.get(fmt, f"no engine for {fmt}"))
    engine, module, extra = ENGINES[fmt]
    if importlib.util.find_spec(module) is None:
        return not_walked(f"{engine} is not importable here (pip install -e '.[{extra}]')")
    duration = (steps + 1.3) * rigid_period_s
    if fmt == "mjcf" and spokes:
        from walkerlab.export.mujoco_walk import roll as walk  # light
    elif fmt == "mjcf":
        from walkerlab.export.mujoco_walk import walk  # light
    else:
        from walkerlab.export.opensim_walk import walk  # light
    run = walk(path, duration) if feedback is None else walk(path, duration, feedback=feedback)
    periods = run.step_periods_s
    legs = list(run.legs)
    in_turn = next((k + 1 for k, (a, b) in enumerate(zip(legs, legs[1:])) if a == b),
                   len(legs))
    return EngineWalk(engine, strikes=len(run.times_s), alternating=run.alternating,
                      first_leg=legs[0] if legs else "", fell=bool(run.fell),
                      t_end_s=float(run.t_end_s), strikes_in_turn=in_turn,
                      period_s=float(periods.mean()) if len(periods) else math.nan,
                      rigid_period_s=float(rigid_period_s), steps=steps, tolerance=tolerance,
                      rolling=bool(spokes))
