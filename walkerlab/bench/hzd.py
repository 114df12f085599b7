"""Benchmark ``hzd``: the hybrid zero dynamics of RABBIT under virtual constraints
(``configs/rabbit_hzd.yaml``): the restricted Poincare map's multiplier ``delta^2`` alone
(target <= 10 ms), the whole zero dynamics (V, V_max, zeta*, the step period by quadrature)
and, for scale, one full-order step map of the closed loop (Westervelt, Grizzle &
Koditschek 2003, IEEE TAC 48(1):42-56, Sec. V).  Medians of ``repeats`` runs, wall time
(:func:`time.perf_counter`).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

__all__ = ["bench_hzd", "lines"]

#: the issue's target for delta^2 [s]
TARGET_S = 0.010


def bench_hzd(scene_path: Path | str | None = None, repeats: int = 50) -> dict:
    """Timings of the zero dynamics of ``scene_path`` (default: the shipped RABBIT under
    virtual constraints).

    Returns
    -------
    dict
        ``delta2`` [-], ``delta2_s``, ``delta2_min_s``, ``zero_dynamics_s``,
        ``build_s`` (the walker with its controller), ``step_map_s`` (one full-order step)
        [s], ``target_s``, ``step_period_s`` (by quadrature) [s].
    """
    from walkerlab.analysis.gait.poincare import poincare_map
    from walkerlab.analysis.gait.zero_dynamics import impact_multiplier, zero_dynamics
    from walkerlab.config import load_scene
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    path = scene_path or Path(__file__).resolve().parents[2] / "configs" / "rabbit_hzd.yaml"
    scene = load_scene(path)
    t = time.perf_counter()
    walker = build_walker(scene)
    build = time.perf_counter() - t
    ctrl = walker.actuators.controller
    d2_times, zd_times = [], []
    for _ in range(repeats):
        t = time.perf_counter()
        d2 = impact_multiplier(ctrl)
        d2_times.append(time.perf_counter() - t)
        t = time.perf_counter()
        zd = zero_dynamics(ctrl)
        zd_times.append(time.perf_counter() - t)
    t = time.perf_counter()
    poincare_map(walker, zd.x_plus, Solver.from_settings(scene.solver))
    step = time.perf_counter() - t
    return {"scene": scene.name, "repeats": repeats, "delta2": d2,
            "delta2_s": float(np.median(d2_times)), "delta2_min_s": float(np.min(d2_times)),
            "zero_dynamics_s": float(np.median(zd_times)), "build_s": build,
            "step_map_s": step, "target_s": TARGET_S, "step_period_s": zd.step_period_s}


def lines(res: dict) -> list[str]:
    """Printable lines of :func:`bench_hzd`'s result."""
    ok = "met" if res["delta2_s"] <= res["target_s"] else "NOT MET"
    return [f"hzd: {res['scene']}: delta^2 = {res['delta2']:.10f} in "
            f"{1e3 * res['delta2_s']:.3f} ms (median of {res['repeats']}; target <= "
            f"{1e3 * res['target_s']:.0f} ms: {ok})",
            f"hzd: zero dynamics (V, V_max, zeta*, period {res['step_period_s']:.10f} s) "
            f"{1e3 * res['zero_dynamics_s']:.1f} ms; controller build {res['build_s']:.2f} s; "
            f"one full-order step map {res['step_map_s']:.3f} s"]
