"""Per-map CPU cost of the ``cyrk`` vs ``cyrk_compiled`` backends, and the first call.

Usage: ``python scripts/bench_compiled.py [configs/paper.yaml] [repeats]``.

Same process, interleaved A/B rounds: one Poincaré map and one variational map (DP) of the
scene's walker at its fixed-point guess, DOP853 at the scene's tolerances (paper: rtol = atol =
1e-12); prints the median CPU time per call (``time.process_time``, each sample the mean of
a batch), the ratio, and the largest difference of the results.  Then, in fresh processes
(median of 3), the wall time of ``import + build walker + first compiled map`` with the numba
cache warm, against the same with the ``cyrk`` backend.
"""

from __future__ import annotations

import subprocess
import sys
import time

import numpy as np

from walkerlab.walker.plant import Plant

FRESH = """
import time; t0 = time.perf_counter()
from walkerlab.config import load_scene
from walkerlab.models.registry import build_walker
from walkerlab.integrate.solver import Solver
from walkerlab.analysis.gait.poincare import poincare_map
from walkerlab.walker.plant import Plant
sc = load_scene({path!r}); w = build_walker(Plant.from_scene(sc))
x = sc.fixedpoint.initial_guess.as_array(w.state_names())
poincare_map(w, x, Solver('DOP853', sc.solver.rtol, sc.solver.atol, None, {backend!r}))
print(time.perf_counter() - t0)
"""


def main(path: str = "configs/paper.yaml", repeats: int = 30) -> None:
    from walkerlab.analysis.gait.poincare import poincare_map
    from walkerlab.config import load_scene
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    sc = load_scene(path)
    w = build_walker(Plant.from_scene(sc))
    x = sc.fixedpoint.initial_guess.as_array(w.state_names())
    sv = {b: Solver("DOP853", sc.solver.rtol, sc.solver.atol, None, b)
          for b in ("cyrk", "cyrk_compiled")}
    for jac, batch in ((False, 20), (True, 5)):
        res = {b: poincare_map(w, x, s, jacobian=jac) for b, s in sv.items()}  # warm up
        times = {b: [] for b in sv}
        for _ in range(repeats):
            for b, s in sv.items():
                c0 = time.process_time()
                for _ in range(batch):
                    poincare_map(w, x, s, jacobian=jac)
                times[b].append((time.process_time() - c0) / batch)
        a, c = (np.median(times[b]) for b in sv)
        diff = np.max(np.abs(res["cyrk"][0] - res["cyrk_compiled"][0]))
        dp = np.max(np.abs(res["cyrk"][2] - res["cyrk_compiled"][2])) if jac else 0.0
        extra = f", max |DP_A - DP_B| {dp:.1e}" if jac else ""
        print(f"{'variational' if jac else 'plain'} map: cyrk {a * 1e3:.3f} ms, cyrk_compiled "
              f"{c * 1e3:.3f} ms (median CPU of {repeats}x{batch}), ratio {a / c:.1f}x; "
              f"max |x_A - x_B| {diff:.1e}{extra}")
    from walkerlab.analysis.gait.poincare import find_fixed_point

    times = {b: [] for b in sv}
    fps = {}
    for _ in range(max(3, repeats // 5)):
        for b, s in sv.items():
            c0 = time.process_time()
            fps[b] = find_fixed_point(w, x, s, fd_check=False)
            times[b].append(time.process_time() - c0)
    a, c = (np.median(times[b]) for b in sv)
    fa, fb = fps["cyrk"], fps["cyrk_compiled"]
    dmu = np.max(np.abs(fa.multipliers_variational - fb.multipliers_variational))
    print(f"fixed point (search + variational DP, no FD check): cyrk {a * 1e3:.1f} ms, "
          f"cyrk_compiled {c * 1e3:.1f} ms, ratio {a / c:.1f}x; "
          f"max |x*_A - x*_B| {np.max(np.abs(fa.x - fb.x)):.1e}, max |mult_A - mult_B| {dmu:.1e}")
    for b in sv:
        t = [float(subprocess.run([sys.executable, "-c", FRESH.format(path=path, backend=b)],
                                  capture_output=True, text=True, check=True).stdout)
             for _ in range(3)]
        print(f"fresh process, import + walker + first map, {b}: {np.median(t):.2f} s wall")


if __name__ == "__main__":
    main(*sys.argv[1:2], *(int(a) for a in sys.argv[2:3]))
