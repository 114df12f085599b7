"""Benchmark: the powered fixed point against the passive one of the same walker (issue
goal: <= 1.5x), and the cost of the energy ledger in a simulate run (<= 5 %).

The walker is the paper's (Table 1).  Passive: on its 0.0174 rad slope.  Powered: level
ground with the 3 N s push-off (configs/powered_compass.yaml), and the same with a
spring-like hip torque.  Each case solves its period-1 fixed point from the same kind of
start (its gait perturbed by 1e-3) with the scene's solver, median of ``--repeats`` runs in
one process (warm: generated code compiled), so the ratios hold on any machine.

    python scripts/bench_powered.py [--repeats 5]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
TORQUE = [{"joint": "hip", "law": {"constant_n_m": 0.5, "stiffness_n_m_per_rad": 1.0,
                                   "damping_n_m_s_per_rad": 0.2}}]


def _scenes():
    from walkerlab.config import load_scene

    paper = load_scene(CONFIGS / "paper.yaml").model_dump(mode="json", exclude_none=True)
    push = load_scene(CONFIGS / "powered_compass.yaml").model_dump(mode="json",
                                                                   exclude_none=True)
    torque = json.loads(json.dumps(push))
    torque["walker"]["actuation"]["torques"] = TORQUE
    return {"passive (paper, slope)": paper, "push-off (level)": push,
            "push-off + hip torque (level)": torque}


def _fixed_point_time(scene: dict, repeats: int) -> tuple[float, int]:
    import walkerlab as wl
    from walkerlab.analysis.gait.poincare import find_fixed_point

    w = wl.Walker.from_scene(scene)
    guess = {"swing_angle_rad": -0.181, "stance_angle_rad": 0.181,
             "swing_rate_rad_per_s": -0.72, "stance_rate_rad_per_s": -0.88}
    if "torques" in scene["walker"].get("actuation", {}):
        scene["fixedpoint"]["initial_guess"] = guess
        w = wl.Walker.from_scene(scene)
    g = w.fixed_point()
    start = g.x * (1 + 1e-3)
    times, nfev = [], 0
    for _ in range(repeats):
        t = time.perf_counter()
        r = find_fixed_point(w.model, start, w.solver, max_step_time=w.max_step_time)
        times.append(time.perf_counter() - t)
        nfev = r.nfev
    return float(np.median(times)), int(nfev)


def _simulate_stage_and_ledger(scene: dict, repeats: int) -> tuple[float, float]:
    """Median wall time [s] of the ``simulate`` stage (5 strides, artifact written; its
    ledger included) and of the ledger alone on the same trajectory."""
    import tempfile

    import walkerlab as wl
    from walkerlab.analysis.gait.energy import trajectory_ledger
    from walkerlab.config import scene_from_dict
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.stages import pipeline
    from walkerlab.stages import simulate as stage

    sc = scene_from_dict(scene)
    w = wl.Walker.from_scene(scene)
    g = w.fixed_point()
    stage_t, ledger_t = [], []
    with tempfile.TemporaryDirectory() as d:
        pipeline.run("fixedpoint", sc, d)
        for _ in range(repeats):
            t = time.perf_counter()
            stage.run(sc, d, force=True)
            stage_t.append(time.perf_counter() - t)
            traj = simulate_steps(w.model, g.x, 2 * sc.simulate.strides, w.solver)
            t = time.perf_counter()
            trajectory_ledger(traj)
            ledger_t.append(time.perf_counter() - t)
    return float(np.median(stage_t)), float(np.median(ledger_t))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    sc = _scenes()
    rows = {k: _fixed_point_time(v, a.repeats) for k, v in sc.items()}
    base = rows["passive (paper, slope)"][0]
    print(f"{'fixed point from a 1e-3 perturbed start':42s} {'median s':>9s} {'nfev':>7s} "
          f"{'/ passive':>9s}")
    for k, (t, n) in rows.items():
        print(f"{k:42s} {t:9.3f} {n:7d} {t / base:9.2f}")
    stage_s, ledger_s = _simulate_stage_and_ledger(sc["push-off (level)"], a.repeats)
    print(f"simulate stage (push-off, 5 strides): {stage_s:.3f} s; its energy ledger "
          f"{ledger_s:.4f} s ({100 * ledger_s / stage_s:.1f} % of the stage)")


if __name__ == "__main__":
    main()
