"""Benchmark: 5 ideal strides and the fixed point of the flat-footed walker
(configs/flat_feet.yaml) against the kneed walker's (configs/kneed.yaml), on the Python flows
(backend ``cyrk``: CyRK with the generated Python right-hand sides, the scenes' default) and on
the compiled flows (``cyrk_compiled``: numba cfuncs, the guards and a flat foot's ground
reactions as extra outputs).  Issue goal: flat feet <= 2x the kneed walker.

Strides: DOP853 at rtol = atol = 1e-10 from each walker's gait; the cases are interleaved
(one run of each per round), CPU time per run, median of ``--rounds``; warm (generated code
imported and compiled), so the ratios hold on any machine.  Fixed point: the scene's solver
from its initial guess, median of 3.

    python scripts/bench_flat_feet.py [--rounds 15]
"""

from __future__ import annotations

import argparse
import gc
import time
from pathlib import Path

import numpy as np

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
BACKENDS = ("cyrk", "cyrk_compiled")


def _cases():
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.config import load_scene
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    out = {}
    for name in ("kneed", "flat_feet"):
        sc = load_scene(CONFIGS / f"{name}.yaml")
        w = build_walker(sc)
        guess = sc.fixedpoint.initial_guess.as_array(w.state_names())
        for b in BACKENDS:
            sv = Solver(sc.solver.method, sc.solver.rtol, sc.solver.atol, None, b)
            x = find_fixed_point(w, guess, sv).x  # warm
            s = Solver("DOP853", 1e-10, 1e-10, None, b)
            simulate_steps(w, x, 10, s)
            out[(name, b)] = (w, x, s, sv, guess)
    return out


def main() -> None:
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.integrate.rigid import simulate_steps

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=15)
    a = ap.parse_args()
    cases = _cases()
    gc.collect()
    gc.freeze()
    cpu = {k: [] for k in cases}
    nfev = {}
    for _ in range(a.rounds):
        for k, (w, x, s, _sv, _g) in cases.items():
            c0 = time.process_time()
            tr = simulate_steps(w, x, 10, s)
            cpu[k].append(time.process_time() - c0)
            nfev[k] = tr.nfev
    fp = {}
    for k, (w, _x, _s, sv, guess) in cases.items():
        t = []
        for _ in range(3):
            c0 = time.process_time()
            find_fixed_point(w, guess, sv)
            t.append(time.process_time() - c0)
        fp[k] = float(np.median(t))
    med = {k: float(np.median(v)) for k, v in cpu.items()}
    print(f"{'walker':10s} {'backend':14s} {'5 strides ms':>12s} {'nfev':>6s} "
          f"{'/ kneed same':>12s} {'/ kneed comp.':>13s} {'fixed point s':>13s}")
    for (name, b), m in med.items():
        print(f"{name:10s} {b:14s} {1e3 * m:12.2f} {nfev[(name, b)]:6d} "
              f"{m / med[('kneed', b)]:12.2f} {m / med[('kneed', 'cyrk_compiled')]:13.2f} "
              f"{fp[(name, b)]:13.3f}")


if __name__ == "__main__":
    main()
