"""Benchmarks behind ``walkerlab bench`` (speed goals are checked here, never in tests).

``ideal``: wall time of the fixed-point search (compute part, derivation cached) and of a
5-stride simulation (median of repeats), with RHS counts.  ``contact``: the contact
walker's work-precision benchmark (:func:`walkerlab.contact.bench.run_benchmark`).
Results are printed and written as JSON to ``OUT/<what>.json`` with the machine noted.
"""

from __future__ import annotations

import json
import os
import platform
import time
from pathlib import Path

import numpy as np

from walkerlab.published import paper


def _machine() -> dict:
    return {"machine": platform.machine(), "processor": platform.processor(),
            "cpus": os.cpu_count(), "python": platform.python_version()}


def bench_ideal(repeats: int = 5) -> dict:
    from walkerlab.analysis.hybrid import Solver, simulate_steps
    from walkerlab.analysis.poincare import find_fixed_point
    from walkerlab.models.compass_gait import make_compass_gait
    from walkerlab.models.derivation import compass_gait_functions

    t0 = time.perf_counter()
    compass_gait_functions()
    derive_s = time.perf_counter() - t0
    w = make_compass_gait(1.0, 5.0, 10.0, 9.81, 0.5, 0.0174)
    sv = Solver("DOP853", 1e-12, 1e-12)
    fp_t, sim_t = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fp = find_fixed_point(w, np.array(paper.EQ11_STATE), sv)
        fp_t.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        tr = simulate_steps(w, fp.x, 10, sv)
        sim_t.append(time.perf_counter() - t0)
    return {"sympy_derivation_s": derive_s, "fixedpoint_median_s": float(np.median(fp_t)),
            "fixedpoint_nfev": fp.nfev, "simulate_5_strides_median_s": float(np.median(sim_t)),
            "simulate_5_strides_nfev": tr.nfev, "solver": "DOP853 rtol=atol=1e-12"}


def run_bench(what: str, out: Path) -> list[str]:
    """Run the named benchmarks; return printable lines."""
    out.mkdir(parents=True, exist_ok=True)
    lines = []
    todo = ["ideal", "contact"] if what == "all" else [what]
    for name in todo:
        if name == "ideal":
            res = bench_ideal()
        elif name == "contact":
            from walkerlab.contact.bench import run_benchmark

            res = run_benchmark()
        else:
            raise ValueError(f"bench: unknown benchmark {name!r} (ideal | contact | all)")
        res = {"benchmark": name, **_machine(), "result": res}
        (out / f"{name}.json").write_text(json.dumps(res, indent=1, default=str))
        lines.append(f"{name}: {json.dumps(res['result'], default=str)[:2000]}")
    return lines
