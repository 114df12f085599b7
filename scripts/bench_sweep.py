"""Sweep throughput with 1 and 2 workers (target: >= 1.8x on 2 cores).

Runs the same fixed-point sweep (slope x hip mass, continuation along the slope) in this
process (1 worker) and on a local process pool (2 workers), checks both give identical
rows, prints points per second and writes ``runs/bench/sweep_bench.json``.

Usage::

    python scripts/bench_sweep.py [--scene configs/goswami1996.yaml] [--runs runs]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np

from walkerlab.config import load_scene
from walkerlab.io.sweep_store import load_sweep
from walkerlab.stages.sweep import run
from walkerlab.studies.outcomes import COLUMNS
from walkerlab.studies.points import warm_up

PARAMS = ["slope.angle_deg=1:4:0.125", "walker.hip_mass_kg=8,10,12,14"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default=str(Path(__file__).resolve().parents[1] / "configs" /
                                           "goswami1996.yaml"))
    ap.add_argument("--runs", default="runs")
    ap.add_argument("--param", action="append", default=None)
    args = ap.parse_args()
    params = args.param or PARAMS
    scene = load_scene(args.scene)
    tmp_root = Path(args.runs) / "bench"
    warm_up()  # in-process runner: exclude the one-off model build from the timing
    results = {}
    for label, workers, pool in (("in-process", 1, False), ("pool-1", 1, True),
                                 ("pool-2", 2, True)):
        load = os.getloadavg()
        t0 = time.perf_counter()
        cpu0 = time.process_time()
        p = run(scene, params, "fixedpoint", workers=workers, runs_root=tmp_root,
                name=f"bench_{label}", progress=False, pool=pool)
        wall = time.perf_counter() - t0
        d = load_sweep(p)
        n = int(d["points"]["index"].size)
        results[label] = {
            "runner": label, "workers": workers, "points": n, "wall_time_s": wall,
            "points_per_s": n / wall,
            "sum_point_wall_time_s": float(np.sum(d["points"]["wall_time_s"])),
            "main_process_cpu_s": time.process_time() - cpu0,
            "loadavg_1min_before": load[0],
            "outcomes": {o: int(c) for o, c in zip(*np.unique(d["points"]["outcome"].astype(str),
                                                              return_counts=True))},
            "artifact": str(p),
            "_rows": d["points"],
        }
        print(f"{label:>10} ({workers} worker(s)): {n} points in {wall:.2f} s -> "
              f"{n / wall:.2f} points/s "
              f"(load avg before {load[0]:.2f})")
    rows = {k: v.pop("_rows") for k, v in results.items()}
    identical = all(np.array_equal(rows[k][c], rows["in-process"][c], equal_nan=True)
                    for k in rows for c in COLUMNS["fixedpoint"])
    speedup = results["pool-1"]["wall_time_s"] / results["pool-2"]["wall_time_s"]
    speedup_inproc = results["in-process"]["wall_time_s"] / results["pool-2"]["wall_time_s"]
    print(f"speedup pool 2 vs pool 1 worker: {speedup:.2f}x (target 1.8x); 2-worker pool vs "
          f"warm in-process runner: {speedup_inproc:.2f}x; identical rows: {identical}")
    out = {"params": params, "stage": "fixedpoint", "scene": args.scene,
           "cpu_count": os.cpu_count(), "python": platform.python_version(),
           "speedup_pool2_vs_pool1": speedup, "speedup_pool2_vs_inprocess": speedup_inproc,
           "identical_rows": bool(identical), "runs": list(results.values()),
           "note": "pool times include starting the process pool (forkserver + model build); "
                   "the machine may be shared: see loadavg_1min_before"}
    tmp_root.mkdir(parents=True, exist_ok=True)
    path = tmp_root / "sweep_bench.json"
    path.write_text(json.dumps(out, indent=2))
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
