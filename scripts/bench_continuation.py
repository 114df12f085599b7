"""Speed goals of the continuation (issue 23).

1. The paper walker from 0.5 deg to past its period-4 onset (5.1 deg; onset 4.914 deg), with
   both branch switches (period 1 -> 2 -> 4): goal <= 20 s on 2 cores.
2. The kneed walker's fold in the thigh mass position (from the scene's 0.30 m down to
   0.25 m): goal <= 30 s.

Each case runs ``--repeats`` times in this process (the generated model code is built once,
outside the timing: one warm-up run); the median wall time is printed with the special points
found and the map counts, and the CPU time of this process (the run is serial: on a shared
machine the wall time is the CPU time stretched by the load; give the load with the numbers).

Usage::

    python scripts/bench_continuation.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]

CASES = {
    "paper_0.5_to_5.1_deg_two_switches": ("paper.yaml", "slope.angle_deg", 0.5, 5.1, 2, 20.0),
    "kneed_thigh_mass_fold": ("kneed.yaml", "walker.leg.bodies.thigh_mass.from_hip_m", 0.25,
                              0.30, 0, 30.0),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    import warnings

    from walkerlab.config import load_scene
    from walkerlab.models.registry import build_walker
    from walkerlab.studies.continuation import run_continuation

    warnings.simplefilter("ignore")
    out = {"load_average": os.getloadavg(), "cpus": os.cpu_count(), "cases": {}}
    for name, (cfg, path, a, b, switch, goal) in CASES.items():
        scene = load_scene(ROOT / "configs" / cfg)
        build_walker(Plant.from_scene(scene))  # generated code built / loaded once, not timed
        times, cpu = [], []
        for _ in range(args.repeats):
            t0, c0 = time.perf_counter(), time.process_time()
            res, _c = run_continuation(scene, path, a, b, switch, plant=Plant.from_scene(scene))
            times.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        med = statistics.median(times)
        out["cases"][name] = {
            "median_s": round(med, 3), "runs_s": [round(t, 3) for t in times],
            "median_cpu_s": round(statistics.median(cpu), 3),
            "goal_s": goal, "met": med <= goal, "maps": res.maps,
            "variational_maps": res.variational_maps,
            "special_points": [(s.kind, s.period, round(s.p, 10), s.cause)
                               for s in res.specials]}
        print(f"{name}: median {med:.2f} s wall, {statistics.median(cpu):.2f} s CPU "
              f"(goal {goal:g} s) runs "
              f"{', '.join(f'{t:.2f}' for t in times)}; {res.maps} maps + "
              f"{res.variational_maps} variational; "
              + "; ".join(f"{s.kind} (period {s.period}) at {s.p:.8g}" for s in res.specials),
              flush=True)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
