"""Section-5 attribution table per walker: the contact-vs-rigid gap of the periodic gait split
by cause, the energy per step by sink, the initial-rate adjustment's effect and whether the
adjusted start lies in the rigid walker's basin (walkerlab.analysis.contact.attribution).

    python scripts/attribution_table.py configs/paper.yaml configs/kneed.yaml ...
"""

import sys

from walkerlab.analysis.contact.attribution import adjustment_effect, attribute
from walkerlab.analysis.contact.periodic import ideal_gait
from walkerlab.config import load_scene
from walkerlab.models.contact.scene import build
from walkerlab.walker.plant import Plant


def main(paths):
    for path in paths:
        scene = load_scene(path)
        plant = Plant.from_scene(scene)
        ideal = ideal_gait(scene, plant=plant)
        walker, _ = build(scene, ideal.x, 2, plant=plant)
        a = attribute(walker, ideal)
        adj = adjustment_effect(scene, ideal, plant=plant)
        print(f"## {scene.name}: rigid step period {ideal.period_s:.6f} s")
        print("| cause | period gap [ms] | step-length gap [mm] |")
        print("|---|---|---|")
        for name, T, L in (("total (periodic gait)", a.period_gap_s, a.step_gap_m),
                           ("friction creep", a.creep_s, a.creep_m),
                           ("compliance", a.compliance_s, a.compliance_m),
                           ("residual", a.residual_s, a.residual_m)):
            print(f"| {name} | {T * 1e3:+.4f} | {L * 1e3:+.4f} |")
        print("energy per step [J]: " + ", ".join(f"{k} {v:.4g}" for k, v in a.energy_J.items()))
        print(f"initial-rate adjustment {adj['rate_scale']}: mean step period of the run "
              f"{adj['adjusted_s']:.5f} s (unadjusted start: {adj['unadjusted_s']:.5f} s); "
              f"rigid walker from the adjusted start: {adj['rigid_from_adjusted']} after "
              f"{adj['rigid_heel_strikes']} heel strikes")
        print()


if __name__ == "__main__":
    main(sys.argv[1:])
