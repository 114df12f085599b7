"""Cost of a rigid step on stairs against a step on the slope (issue 49's speed goal: stair
steps at most 1.5x slope steps).

    PYTHONPATH=. python scripts/bench_stairs.py [scene.yaml] [--rows 2000] [--repeats 5]

For the scene's walker (default configs/paper.yaml) on its slope and on stairs of the slope
gait's drop per step (the same gait, so the same work per step): (a) the batched, compiled
step map (:class:`walkerlab.integrate.batch_step.BatchStepMap`, the MFPT workhorse: compiled
flow, compiled guards) on ``--rows`` copies of the fixed point, (b) one step with the scene's
solver (scipy, Python guards), best of ``--repeats``.  Prints microseconds per step and the
ratios.  A measurement, not a test: timings depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from walkerlab.analysis.gait.scene import solve_scene
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.integrate.batch_step import HEEL_STRIKE, BatchStepMap
from walkerlab.integrate.rigid import integrate_step
from walkerlab.integrate.solver import Solver
from walkerlab.walker.plant import Plant


def _best(fn, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("scene", nargs="?", default="configs/paper.yaml")
    ap.add_argument("--rows", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    sc = load_scene(a.scene)
    solver = Solver.from_settings(sc.solver)
    w_slope, s = solve_scene(sc, plant=Plant.from_scene(sc))
    x = s.result.x
    seg = integrate_step(w_slope, x, solver)
    foot = w_slope.points(seg.x_end)["swing_foot"]
    d = sc.model_dump(mode="json")
    d["slope"] = {"angle_rad": 0.0}
    d["terrain"] = {"kind": "stairs", "riser_m": -float(foot[1]), "tread_m": float(foot[0])}
    sc1 = scene_from_dict(d)
    w_stairs, s2 = solve_scene(sc1, plant=Plant.from_scene(sc1))
    print(f"{a.scene}: riser {-1e3 * float(foot[1]):.4f} mm; same gait: "
          f"{np.max(np.abs(s2.result.x - x)):.1e} rad")
    out = {}
    for label, w in (("slope", w_slope), ("stairs", w_stairs)):
        bm = BatchStepMap(w, lambda g, _w=w: _w, 1e-10, 1e-10)
        X = np.tile(x, (a.rows, 1))
        r = bm.step(X)  # compile and warm up
        assert np.all(r.outcome == HEEL_STRIKE), label
        tb = _best(lambda bm=bm, X=X: bm.step(X), a.repeats) / a.rows
        ts = _best(lambda w=w: integrate_step(w, x, solver), a.repeats)
        out[label] = (tb, ts)
        print(f"  {label:6s} batched compiled step {1e6 * tb:8.2f} us   scipy step "
              f"({solver.method}, rtol {solver.rtol:g}) {1e3 * ts:8.3f} ms")
    print(f"  stairs / slope: batched {out['stairs'][0] / out['slope'][0]:.3f}x, scipy "
          f"{out['stairs'][1] / out['slope'][1]:.3f}x (goal <= 1.5x)")


if __name__ == "__main__":
    main()
