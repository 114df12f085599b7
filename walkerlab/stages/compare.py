"""Stage ``compare``: ideal vs contact -> ``compare.h5`` (Fig. 8 errors, Table 3 metrics)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.analysis.compare import aligned_errors, limit_cycle_distance
from walkerlab.analysis.tables import gait_metrics
from walkerlab.config import Scene
from walkerlab.io.artifacts import open_artifact, put
from walkerlab.io.netcdf import coordinate
from walkerlab.io.trajectory import read_samples
from walkerlab.stages import contact_sim, simulate
from walkerlab.stages.common import StageOutcome, artifact_path, run_cached

METRIC_UNITS = {"t_left_s": "s", "t_right_s": "s", "t_cycle_s": "s", "v_com_m_per_s": "m/s",
                "E_avg_J": "J", "E_avg_stance_frame_J": "J", "step_length_m": "m",
                "step_length_left_m": "m", "step_length_right_m": "m",
                "n_steps": "-"}


def compare_files(ideal_path: Path, contact_path: Path):
    """Errors and metrics of the two trajectory artifacts (pure function of the files).

    The total mass and gravity come from the ideal artifact (written by the walker model).
    """
    with open_artifact(ideal_path, "simulate") as f:
        ideal = read_samples(f)
        mass_kg, g = float(f.attrs["total_mass_kg"]), float(f.attrs["gravity_m_per_s2"])
    with open_artifact(contact_path, "contact-sim") as f:
        contact = read_samples(f)
    t, err = aligned_errors(ideal, contact)
    metrics = {"ideal": gait_metrics(ideal, mass_kg=mass_kg, g=g),
               "contact": gait_metrics(contact, mass_kg=mass_kg, g=g)}
    lc = {a.removesuffix("_angle"): limit_cycle_distance(ideal, contact, a, r)
          for a, r in ideal.phase_pairs() if a in contact.coordinates and r in contact.coordinates}
    return ideal, t, err, metrics, lc


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False) -> StageOutcome:
    """Run (or reuse) ``simulate`` and ``contact-sim``, then compare them."""
    simulate.run(scene, runs_root)
    contact_sim.run(scene, runs_root)
    up = (artifact_path(scene, runs_root, "simulate"),
          artifact_path(scene, runs_root, "contact-sim"))

    def compute():
        ideal, t, err, metrics, lc = compare_files(up[0], up[1])
        ang = [n for n in err if ideal.units[n] == "rad"]
        rat = [n for n in err if ideal.units[n].startswith("rad/")]  # rad/s, or per time unit
        summary = {"max_angle_error_rad": float(max(np.max(np.abs(err[n])) for n in ang)),
                   "max_rate_error_rad_per_s": float(max(np.max(np.abs(err[n])) for n in rat)),
                   "compared_until_s": float(t[-1]), "metrics": metrics,
                   "limit_cycle_distance": lc}

        def writer(f):
            g = f.create_group("errors")
            g.attrs["legs"] = ideal.legs
            g.attrs["coordinates"] = list(err)
            g.attrs["definition"] = "contact - ideal, on the ideal sample times"
            coordinate(g, "time", t, "s", "ideal sample times within the common span")
            for n, e in err.items():
                put(g, f"coordinates/{n}", e, ideal.units[n], f"{n} error (contact - ideal)",
                    dims=("time",))
            for stem, d in lc.items():
                put(g, f"limit_cycle_distance/{stem}", d, "rad (rates in rad/s)",
                    f"mean distance from the ideal phase curve of {stem} to the contact one")
            put(g, "max_abs_angle", summary["max_angle_error_rad"], "rad", "")
            put(g, "max_abs_rate", summary["max_rate_error_rad_per_s"], "rad/s", "")
            for model, m in metrics.items():
                for k, v in m.items():
                    put(f, f"metrics/{model}/{k}", v, METRIC_UNITS.get(k, "-"), k)
        return writer, summary

    return run_cached("compare", scene, runs_root, ("walker",), up, compute, force)
