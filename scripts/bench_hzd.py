"""Timing of the hybrid zero dynamics of a scene under virtual constraints (benchmark, not
a test): the restricted Poincare map's multiplier delta^2 alone, the whole zero dynamics
(V, V_max, zeta*, the period by quadrature) and one full-order step map of the closed loop
for scale (Westervelt, Grizzle & Koditschek 2003, IEEE TAC 48(1):42-56, Sec. V).

Usage: ``python scripts/bench_hzd.py [configs/rabbit_hzd.yaml] [repeats]``.  The issue's
target: delta^2 <= 10 ms.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from walkerlab.analysis.gait.poincare import poincare_map
from walkerlab.analysis.gait.zero_dynamics import impact_multiplier, zero_dynamics
from walkerlab.config import load_scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker


def main(path: str = "configs/rabbit_hzd.yaml", repeats: int = 50) -> None:
    scene = load_scene(path)
    t = time.perf_counter()
    walker = build_walker(scene)
    build = time.perf_counter() - t
    ctrl = walker.actuators.controller
    times = {"delta^2": [], "zero dynamics": []}
    for _ in range(repeats):
        t = time.perf_counter()
        d2 = impact_multiplier(ctrl)
        times["delta^2"].append(time.perf_counter() - t)
        t = time.perf_counter()
        zd = zero_dynamics(ctrl)
        times["zero dynamics"].append(time.perf_counter() - t)
    t = time.perf_counter()
    poincare_map(walker, zd.x_plus, Solver.from_settings(scene.solver))
    step = time.perf_counter() - t
    print(f"{scene.name}: delta^2 = {d2:.10f}, step period {zd.step_period_s:.10f} s "
          f"(quadrature)")
    for k, v in times.items():
        print(f"  {k:<14s} median {np.median(v) * 1e3:8.3f} ms, min {np.min(v) * 1e3:8.3f} ms "
              f"({repeats} runs)")
    print(f"  controller build (derivation, invariance, checks) {build:.3f} s; one full-order "
          f"step map {step:.3f} s")


if __name__ == "__main__":
    main(*(sys.argv[1:2] or ["configs/rabbit_hzd.yaml"]),
         *([int(sys.argv[2])] if len(sys.argv) > 2 else []))
