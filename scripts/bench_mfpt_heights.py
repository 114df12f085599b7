"""Benchmark: the rigid Monte Carlo on per-step landing heights against per-step slopes
(issue 49's speed goal: MFPT on rough terrain at the same microseconds per heel strike as
today's per-step slopes), one process, the paper walker, whole walks compiled.

    python scripts/bench_mfpt_heights.py [--walks 2000] [--repeats 3]

The two roughnesses are chosen so the walks are of similar length (MFPT of a few tens of
steps: sigma 4 mrad of slope, 1.6 mm of height); the first call of each compiles (or loads
from numba's cache) and is not timed.  Prints JSON: heel strikes, wall time and
microseconds per heel strike of each, and their ratio.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--walks", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.analysis.robustness import mfpt as M
    from walkerlab.config import load_scene
    from walkerlab.studies.mfpt import step_map_for

    sc = load_scene(ROOT / "configs" / "paper.yaml")
    plant = Plant.from_scene(sc)
    _, search = solve_scene(sc, plant=plant)
    x = search.result.x
    base = sc.model_dump(mode="json")
    cases = {"slopes": (step_map_for(base, plant=plant), 0.004, None),
             "heights": (step_map_for(base, True, plant=plant), 0.0, ("normal", 0.0016))}
    out = {}
    for name, (sm, sd, heights) in cases.items():
        M.monte_carlo(sm, x, sd, range(20), 200, 1, heights=heights)  # compile / load
        best = None
        for _ in range(a.repeats):
            t = time.perf_counter()
            r = M.monte_carlo(sm, x, sd, range(a.walks), 2000, 0, heights=heights)
            dt = time.perf_counter() - t
            best = dt if best is None else min(best, dt)
        hs = int(r.steps.sum())
        out[name] = {"heel_strikes": hs, "mfpt_steps": r.mfpt[0], "wall_s": best,
                     "us_per_heel_strike": 1e6 * best / hs}
    out["ratio_heights_to_slopes"] = (out["heights"]["us_per_heel_strike"]
                                      / out["slopes"]["us_per_heel_strike"])
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
