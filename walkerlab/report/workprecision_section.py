"""Report section of the work-precision study (``workprecision.h5``): the fastest setting
reaching the target error, the Pareto front per model, and the table of every (method,
tolerance) point; from the loaded artifact only."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from walkerlab.report.markdown import num, table

if TYPE_CHECKING:  # loaded artifacts (walkerlab.io.schemas)
    from walkerlab.io.schemas.workprecision import WorkPrecisionArtifact


def _ms(t: float) -> str:
    return f"{num(1e3 * t, 3)} ms"


def workprecision_choice(attrs) -> str:
    """The work-precision study's choice for one model (attributes of its group), in one
    sentence that says how noisy the timing was: a setting is named fastest only when its
    slowest run beats every other qualifying setting's fastest run; otherwise the
    timings cannot separate them."""
    if "best_method" not in attrs:
        return f"no setting reaches the target error {attrs['target_error']:.0e}."
    target = f"{attrs['target_error']:.0e}"  # settings, printed as given
    name = f"{attrs['best_method']} rtol {attrs['best_rtol']:.0e}"
    if "best_separated" not in attrs:  # an artifact from before the spread was stored
        return (f"fastest median run reaching the target error {target}: {name} "
                f"({_ms(attrs['best_time'])}; timing spread not recorded).")
    spread = (f"median {_ms(attrs['best_time'])} CPU, {_ms(attrs['best_time_min'])}–"
              f"{_ms(attrs['best_time_max'])} over {int(attrs['best_repeats'])} runs")
    if bool(attrs["best_separated"]):
        return (f"fastest setting reaching the target error {target}: **{name}** ({spread}; "
                "faster than every run of any other setting that reaches it).")
    tied = [f"{m} rtol {r:.0e} ({_ms(a)}–{_ms(b)})" for m, r, a, b in zip(
        attrs["tied_methods"], attrs["tied_rtol"], attrs["tied_time_min"],
        attrs["tied_time_max"])]
    return (f"the timings cannot separate the settings reaching the target error {target}: "
            + ", ".join(tied) + " (min–max CPU time of the integration over the repeats "
            "overlap, or a setting was timed once): indistinguishable; the lowest median is "
            + name + ".")


def workprecision_text(wp: WorkPrecisionArtifact) -> str:
    """One line per model of a workprecision artifact: its choice and the timing noise."""
    return "\n".join(f"{model}: {workprecision_choice(m.choice)}"
                     for model, m in wp.models.items())


def workprecision_table(wp: WorkPrecisionArtifact, model: str) -> str:
    """Every (method, rtol) point of one model of ``workprecision.h5``."""
    rows, clock = [], "wall"
    for m, d in wp.models[model].rows.items():
        if "wall_time" in d:  # times are the integration's CPU time (older artifacts: wall)
            clock = "CPU"
        lo = d.get("time_min", d["time"])
        hi = d.get("time_max", d["time"])
        reps = d["repeats"] if "repeats" in d else np.ones(len(lo), int)
        for rt, t, a, b, k, e, n in zip(d["rtol"], d["time"], lo, hi, reps, d["error"],
                                        d["nfev"]):
            rows.append([m, num(rt, 1), num(t * 1e3, 3), f"{num(a * 1e3, 3)}–"
                         f"{num(b * 1e3, 3)}", int(k), num(e, 2), int(n)])
    return table(["method", "rtol", f"median {clock} [ms]", f"min–max {clock} [ms]", "runs",
                  "error vs reference", "RHS evals"], rows)


def _solver_text(scene, model: str) -> str:
    from walkerlab.config import SolverSettings  # light

    sv = (scene.solver if model == "ideal"
          else scene.contact_solver or SolverSettings.for_contact())
    return f"{sv.method} rtol {sv.rtol:.0e}."


def workprecision_summary(scene, arts: dict) -> list[str]:
    """The fastest setting reaching the target error, only where the timing noise allows
    naming one, and the Pareto front per model (raw points fold under the figure)."""
    wp = arts.get("workprecision")
    if wp is None:
        return []
    out = ["## Error against run time (work-precision)", ""]
    for model, m in wp.models.items():
        out += [f"### {model} model", ""]
        out.append("Choice: " + workprecision_choice(m.choice) + " Scene default: "
                   + _solver_text(scene, model))
        pm = [str(s) for s in m.choice.get("pareto_methods", [])]
        pr = list(m.choice.get("pareto_rtol", []))
        out += ["", "Pareto front (no setting is both more accurate and faster by more than "
                "the spread of the repeats' CPU times; of two settings whose times overlap "
                "only the more accurate is kept): "
                + ", ".join(f"{a} {r:.0e}" for a, r in zip(pm, pr)) + ".", ""]
    return out
