"""Benchmark: 5 ideal strides and the fixed point of the flat-footed walker
(configs/flat_feet.yaml) against the kneed walker's (configs/kneed.yaml), on the Python flows
(backend ``cyrk``: CyRK with the generated Python right-hand sides, the scenes' default) and on
the compiled flows (``cyrk_compiled``: numba cfuncs, the guards and a flat foot's ground
reactions as extra outputs).  Issue goal: flat feet <= 2x the kneed walker.

Strides: DOP853 at rtol = atol = 1e-10 from each walker's gait; the cases are interleaved
(one run of each per round), CPU time per run, median of ``--rounds``; warm (generated code
imported and compiled), so the ratios hold on any machine.  Fixed point: the scene's solver
from its initial guess, median of 3.

    python scripts/bench_flat_feet.py [--rounds 15] [--contact]

``--contact``: also the contact model of both walkers at the issue's 1e-6 rad (``walkerlab
bench contact``'s scan, :func:`walkerlab.bench.contact.run_scene_benchmark`, CyRK's BDF only,
3 runs per rtol): the band found, its median wall time and RHS calls, and flat feet over
kneed.  Measured on the same scan with CPU times (session 12, load ~10): flat feet 74 ms
against kneed's 134 ms (0.55x), 47 k RHS calls against 160 k; with a flat foot's rates held
to the angles' atol, 460 ms (2.8x).
"""

from __future__ import annotations

import argparse
import gc
import time
from pathlib import Path

import numpy as np

from walkerlab.walker.plant import Plant

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
        w = build_walker(Plant.from_scene(sc))
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
    ap.add_argument("--contact", action="store_true",
                    help="also the contact model at 1e-6 rad (see the module docstring)")
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
    if a.contact:
        contact()


def contact() -> None:
    """Flat feet against the kneed walker at 1e-6 rad, contact model, one run."""
    from walkerlab.bench.contact import run_scene_benchmark
    from walkerlab.config import load_scene

    out = {}
    for name in ("kneed", "flat_feet"):
        r = run_scene_benchmark(load_scene(CONFIGS / f"{name}.yaml"), methods=("cyrk_bdf",),
                                repeats=3)
        out[name] = t = r["target"]["cyrk_bdf"]
        if t["reached"]:
            print(f"contact {name:10s} band from rtol {t['rtols'][0]:.3g}: median wall "
                  f"{1e3 * t['median_wall_time_s']:.1f} ms, RHS calls {int(np.median(t['nfev']))}, "
                  f"worst error {t['worst_error_rad']:.2g} rad")
        else:
            print(f"contact {name:10s}: 1e-6 rad not reached")
    if all(t["reached"] for t in out.values()):
        k, f = out["kneed"], out["flat_feet"]
        wall = f["median_wall_time_s"] / k["median_wall_time_s"]
        print(f"contact flat feet / kneed: wall {wall:.2f}, "
              f"RHS calls {np.median(f['nfev']) / np.median(k['nfev']):.2f}")


if __name__ == "__main__":
    main()
