"""The contact, MJCF and OpenSim cells of a reference case whose passive gait is unstable
(:data:`walkerlab.walker.reference_cases.FIRST_STEPS`: the 3D kneed walker, whose lateral
mode grows x40 a stride and which no foot-placement law stabilises in its rigid model): a
walk started a little off the rigid gait leaves it within a few steps, as the rigid walker
itself would, so the cell holds the walk's first steps, from the rigid gait's heel strike
(the contact run's and the MJCF keyframe's start, ``t = 0``), to the rigid gait's: the mean
of their step periods against the rigid gait's step period (relative; the cell's tolerance,
3 %), each step's deviation listed.  The walks are ``walkerlab contact-sim``, the
exported MJCF walked in MuJoCo (:func:`walkerlab.export.mujoco_walk.walk`) and the OpenSim
model walked by OpenSim (:func:`walkerlab.export.opensim_walk.walk`), each for as long as
it walks.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

__all__ = ["first_steps", "quantity"]


def quantity(view: str, steps: int) -> str:
    """The cell's quantity in words for ``view`` ("contact" or "mjcf") over ``steps``."""
    walk = {"contact": "contact-sim", "mjcf": "the MJCF walked in MuJoCo",
            "osim": "the OpenSim model walked by OpenSim"}[view]
    return (f"{walk}: the mean step period of its first {steps} steps from the rigid gait's "
            "heel strike against the rigid gait's (its passive gait is laterally unstable, "
            "x40 a stride: the walk leaves it within a few steps, as the rigid walk does)")


def _verdict(times, period: float, steps: int, what: str, end: str) -> tuple[float, str]:
    """The first ``steps`` step periods of heel-strike ``times`` [s] (from 0) against the
    rigid ``period`` [s]: ``(relative deviation of their mean, one line)``."""
    times = np.asarray(times, float)
    if times.size < steps:
        return math.nan, (f"{what} walked {times.size} heel strikes of the {steps} "
                          f"measured{end}")
    T = np.diff(np.r_[0.0, times[:steps]])
    dev = float(T.mean() / period - 1.0)
    each = ", ".join(f"{100 * (t / period - 1):+.2f} %" for t in T)
    return dev, (f"{what}: its first {steps} steps {', '.join(f'{t:.5f}' for t in T)} s "
                 f"({each}) against the rigid gait's {period:.5f} s: mean {100 * dev:+.2f} %; "
                 f"{times.size} heel strikes in all{end}")


def first_steps(view: str, steps: int):
    """The measuring function of ``view`` ("contact", "mjcf", "osim") over the first ``steps`` steps
    (module docstring), called as the views' of :mod:`walkerlab.api.capabilities`:
    ``(scene, d, runs) -> (value, detail, extra)`` (``extra``: the quantity)."""
    def contact(scene, d, runs: Path):
        from walkerlab.io.artifacts import open_artifact  # light: h5py
        from walkerlab.io.stage_files import CONTACT_SIM  # light: as the pipeline below
        from walkerlab.stages import pipeline

        cs = pipeline.run(CONTACT_SIM.name, scene, runs).path
        fp = pipeline.run("fixedpoint", scene, runs).path
        with open_artifact(Path(cs)) as f, open_artifact(Path(fp)) as g:
            times = np.asarray(f["events/heel_strike_times"][:], float)
            why = " ".join(str(f.attrs.get("outcome_message", "")).split())
            period = float(g["step_period"][()])
        end = f" (then {why})" if why else ""
        return (*_verdict(times, period, steps, "contact-sim", end),
                {"quantity": quantity(view, steps)})

    def engine(fmt: str, engine_name: str, walk):
        """The view that writes ``fmt`` and walks it in its engine (``walk(path, t_end)``)."""
        def measure(scene, d, runs: Path):
            from walkerlab.stages import export  # light

            out = export.write(scene, runs, fmt)
            period = float(out.step_period_s)
            run = walk(out.path, (steps + 1.3) * period)
            end = (f" (then fell at {run.t_end_s:.3f} s)" if run.fell else "")
            if not run.alternating:
                return math.nan, f"{engine_name}'s heel strikes do not alternate: {run.legs}", {}
            return (*_verdict(run.times_s, period, steps, f"walked in {engine_name}", end),
                    {"quantity": quantity(view, steps)})
        return measure

    def mjcf(scene, d, runs: Path):
        from walkerlab.export.mujoco_walk import walk  # light: mujoco

        return engine("mjcf", "MuJoCo", walk)(scene, d, runs)

    def osim(scene, d, runs: Path):
        from walkerlab.export.opensim_walk import walk  # light: opensim, in its process

        return engine("osim", "OpenSim", walk)(scene, d, runs)

    return {"contact": contact, "mjcf": mjcf, "osim": osim}[view]
