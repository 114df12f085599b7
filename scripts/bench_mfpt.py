"""Benchmark of the MFPT study (issue 24): 10^5 rigid Monte Carlo steps and the paper walker's
mesh MFPT at one sigma, on local worker processes.

    python scripts/bench_mfpt.py [--workers 2] [--sigma-mc 0.002] [--sigma-mesh 0.004]

Goals: 10^5 Monte Carlo steps <= 10 s; the mesh MFPT at one sigma <= 60 s (2 cores).
Wall times include the worker pool's start-up (each worker imports numba and loads the
compiled model from the disk cache).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def cpu_s() -> float:
    """User + system CPU time of this process and its reaped children [s] (worker processes
    started through a forkserver are not its children: time the whole command from outside,
    e.g. ``/usr/bin/time -v``, for their CPU time)."""
    import resource

    a, b = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return a.ru_utime + a.ru_stime + b.ru_utime + b.ru_stime


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--sigma-mc", type=float, default=0.002)
    ap.add_argument("--sigma-mesh", type=float, default=0.004)
    ap.add_argument("--walks", type=int, default=1000)
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--skip-mesh", action="store_true")
    a = ap.parse_args()

    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.config import MfptSettings, load_scene
    from walkerlab.studies import mfpt as work

    scene = load_scene(ROOT / "configs" / "paper.yaml")
    plant = Plant.from_scene(scene)
    _, search = solve_scene(scene, fd_check=False, plant=plant)
    x = search.gait.result.x
    out = {}
    t, c = time.perf_counter(), cpu_s()
    mc = work.monte_carlo(scene, x, a.sigma_mc, a.walks, a.steps, seed=0, workers=a.workers,
                          plant=plant)
    wall, cpu = time.perf_counter() - t, cpu_s() - c
    n = int(mc.steps.sum() + mc.fell.sum())
    out["montecarlo"] = {"sigma_rad": a.sigma_mc, "steps": n, "wall_s": wall, "cpu_s": cpu,
                         "us_per_step": 1e6 * wall / n, "falls": int(mc.fell.sum()),
                         "goal": "1e5 steps <= 10 s"}
    print(f"Monte Carlo: {n} steps in {wall:.2f} s wall ({1e6 * wall / n:.0f} us/step, "
          f"{a.workers} workers; this process's CPU {cpu:.2f} s)")
    if not a.skip_mesh:
        st = MfptSettings()
        t, c = time.perf_counter(), cpu_s()
        last, meshes = work.mesh(scene, x, a.sigma_mesh, st, a.workers, plant=plant)
        wall, cpu = time.perf_counter() - t, cpu_s() - c
        out["mesh"] = {"sigma_rad": a.sigma_mesh, "wall_s": wall, "cpu_s": cpu,
                       "meshes": [{"cells": r.cells, "h": r.h, "mfpt_steps": r.mfpt_steps}
                                  for r in meshes],
                       "converged": bool(last.converged), "change": last.change,
                       "goal": "<= 60 s"}
        print(f"mesh: MFPT {last.mfpt_steps:.1f} steps, {last.cells} cells, "
              f"{len(meshes)} meshes, change {last.change:.3f}, converged {last.converged}, "
              f"{wall:.1f} s wall, {cpu:.1f} s CPU")
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
