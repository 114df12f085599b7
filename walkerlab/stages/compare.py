"""Stage ``compare``: ideal vs contact -> ``compare.h5`` (Fig. 8 errors, Table 3 metrics).

Layout: :mod:`walkerlab.io.schemas.compare`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.comparison.errors import (
    aligned_errors,
    limit_cycle_distance,
    phase_aligned_errors,
)
from walkerlab.comparison.tables import gait_metrics
from walkerlab.config import Scene
from walkerlab.io.freshness import NOT_FINAL_ATTR, not_final
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.schemas.compare import METRIC_UNITS, Comparison, write_compare
from walkerlab.io.schemas.contact_sim import load_contact_sim
from walkerlab.io.schemas.simulate import load_simulate
from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.stages.common import StageOutcome, run_cached


def compare_files(ideal_path: Path, contact_path: Path) -> Comparison:
    """Errors and metrics of the two trajectory artifacts (pure function of the files).

    The total mass and gravity come from the ideal artifact (written by the walker model).
    """
    sim = load_simulate(ideal_path)
    ideal, contact = sim.samples, load_contact_sim(contact_path).samples
    mass_kg, g = sim.total_mass_kg, sim.gravity_m_per_s2
    t, err = aligned_errors(ideal, contact)
    step_phase, perr = phase_aligned_errors(ideal, contact)
    metrics = {"ideal": gait_metrics(ideal, mass_kg=mass_kg, g=g),
               "contact": gait_metrics(contact, mass_kg=mass_kg, g=g)}
    lc = {a.removesuffix("_angle"): limit_cycle_distance(ideal, contact, a, r)
          for a, r in ideal.phase_pairs() if a in contact.coordinates and r in contact.coordinates}
    # the largest errors over the coordinates both views name (none in common: NaN)
    ang = [n for n in err if ideal.units[n] == "rad"]
    rat = [n for n in err if ideal.units[n].startswith("rad/")]  # rad/s, or per time unit
    return Comparison(
        legs=ideal.legs, time=t, errors=err, error_units={n: ideal.units[n] for n in err},
        limit_cycle_distance=lc,
        max_abs_angle_rad=float(max((np.max(np.abs(err[n])) for n in ang if err[n].size),
                                    default=np.nan)),
        max_abs_rate_rad_per_s=float(max((np.max(np.abs(err[n])) for n in rat if err[n].size),
                                         default=np.nan)),
        metrics=metrics, metric_units=METRIC_UNITS, step_phase=step_phase, phase_errors=perr)


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False) -> StageOutcome:
    """Compare ``simulate.h5`` with ``contact_sim.h5`` (both must exist:
    :mod:`walkerlab.stages.pipeline` runs them first)."""
    up = (stage_artifact(scene, runs_root, "simulate"),
          stage_artifact(scene, runs_root, CONTACT_SIM.name))

    def compute():
        c = compare_files(*up)
        # a contact run a wall-clock limit cut short: the comparison is not kept either
        c.contact_cut_short = not_final(up[1])
        summary = {"max_angle_error_rad": c.max_abs_angle_rad,
                   "max_rate_error_rad_per_s": c.max_abs_rate_rad_per_s,
                   "max_phase_aligned_angle_error_rad": float(max(
                       (np.max(np.abs(e)) for n, e in c.phase_errors.items()
                        if c.error_units[n] == "rad" and e.size), default=np.nan)),
                   "compared_until_s": float(c.time[-1]), "metrics": c.metrics,
                   "limit_cycle_distance": c.limit_cycle_distance}
        def writer(f):
            write_compare(f, c)
            if c.contact_cut_short:
                f.attrs[NOT_FINAL_ATTR] = c.contact_cut_short
        return writer, summary

    return run_cached("compare", scene, runs_root, ("walker",), up, compute, force)
