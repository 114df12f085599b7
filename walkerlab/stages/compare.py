"""Stage ``compare``: ideal vs contact -> ``compare.h5`` (Fig. 8 errors, Table 3 metrics)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.analysis.compare import aligned_errors, limit_cycle_distance
from walkerlab.analysis.tables import gait_metrics
from walkerlab.config import Scene
from walkerlab.io.artifacts import open_artifact, put
from walkerlab.io.trajectory import read_samples
from walkerlab.stages import contact_sim, simulate
from walkerlab.stages.common import StageOutcome, artifact_path, run_cached

METRIC_UNITS = {"t_left_s": "s", "t_right_s": "s", "t_cycle_s": "s", "v_com_m_per_s": "m/s",
                "E_avg_J": "J", "E_avg_stance_frame_J": "J", "step_length_m": "m",
                "n_steps": "-"}


def compare_files(ideal_path: Path, contact_path: Path, mass_kg: float, g: float):
    """Errors and metrics of the two trajectory artifacts (pure function of the files)."""
    with open_artifact(ideal_path, "simulate") as f:
        ideal = read_samples(f)
    with open_artifact(contact_path, "contact-sim") as f:
        contact = read_samples(f)
    t, ae, re = aligned_errors(ideal, contact)
    metrics = {"ideal": gait_metrics(ideal, mass_kg=mass_kg, g=g),
               "contact": gait_metrics(contact, mass_kg=mass_kg, g=g)}
    lc = {leg: limit_cycle_distance(ideal, contact, leg) for leg in ideal.legs}
    return ideal, t, ae, re, metrics, lc


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False) -> StageOutcome:
    """Run (or reuse) ``simulate`` and ``contact-sim``, then compare them."""
    simulate.run(scene, runs_root)
    contact_sim.run(scene, runs_root)
    up = (artifact_path(scene, runs_root, "simulate"), artifact_path(scene, runs_root, "contact-sim"))
    w = scene.walker

    def compute():
        ideal, t, ae, re, metrics, lc = compare_files(
            up[0], up[1], w.hip_mass_kg + 2 * w.leg_mass_kg, w.gravity_m_per_s2)
        summary = {"max_angle_error_rad": float(max(np.max(np.abs(v)) for v in ae.values())),
                   "max_rate_error_rad_per_s": float(max(np.max(np.abs(v)) for v in re.values())),
                   "compared_until_s": float(t[-1]), "metrics": metrics,
                   "limit_cycle_distance": lc}

        def writer(f):
            g = f.create_group("errors")
            g.attrs["legs"] = ideal.legs
            g.attrs["definition"] = "contact - ideal, on the ideal sample times"
            put(g, "time", t, "s", "ideal sample times within the common span")
            for leg in ideal.legs:
                put(g, f"angle/{leg}", ae[leg], "rad", f"{leg} angle error")
                put(g, f"rate/{leg}", re[leg], "rad/s", f"{leg} rate error")
                put(g, f"limit_cycle_distance/{leg}", lc[leg], "rad (rates in rad/s)",
                    "mean distance from the ideal phase curve to the contact one")
            put(g, "max_abs_angle", summary["max_angle_error_rad"], "rad", "")
            put(g, "max_abs_rate", summary["max_rate_error_rad_per_s"], "rad/s", "")
            for model, m in metrics.items():
                for k, v in m.items():
                    put(f, f"metrics/{model}/{k}", v, METRIC_UNITS.get(k, "-"), k)
        return writer, summary

    return run_cached("compare", scene, runs_root, ("walker",), up, compute, force)
