"""Benchmark: the powered fixed point against the passive one of the same walker (issue
goal: <= 1.5x), and the cost of the energy ledger in a simulate run (<= 5 %).

The walker is the paper's (Table 1).  Passive: on its 0.0174 rad slope.  Powered: level
ground with the 3 N s push-off (configs/powered_compass.yaml), the same with a spring-like
hip torque (a generated hip spring-damper), and with a PD hip law tracking a cubic phase
reference (a virtual constraint, saturated at 5 N m: its laws evaluated in the compiled
flow, walkerlab.codegen.actuated).  Each case solves its period-1 fixed point from the same
kind of start (its gait perturbed by 1e-3) with the scene's solver on the scene's backend
(``auto``: CyRK with the generated Python flows) and on ``cyrk_compiled`` (numba cfuncs),
median of ``--repeats`` runs in one process (warm: generated code compiled), so the ratios
hold on any machine.  ``--rabbit`` adds RABBIT's fixed point (configs/rabbit.yaml, five
links, four PD virtual constraints) on its LSODA and on DOP853 with compiled laws.

    python scripts/bench_powered.py [--repeats 5] [--rabbit]
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
#: a virtual constraint on the hip: h(s) the push-off gait's hip angle against its stance
#: angle (sampled at 7 knots), gentle gains, saturated
PD_REFERENCE = [{"joint": "hip", "max_torque_n_m": 5.0, "law": {
    "stiffness_n_m_per_rad": 2.0, "damping_n_m_s_per_rad": 0.3,
    "reference": {"phase_rad": [-0.18, -0.12, -0.06, 0.0, 0.06, 0.12, 0.18],
                  "angle_rad": [0.3469, 0.3257, 0.2367, 0.0, -0.2367, -0.3257, -0.3469],
                  "interpolation": "cubic"}}}]


def _scenes():
    from walkerlab.config import load_scene

    paper = load_scene(CONFIGS / "paper.yaml").model_dump(mode="json", exclude_none=True)
    push = load_scene(CONFIGS / "powered_compass.yaml").model_dump(mode="json",
                                                                   exclude_none=True)
    torque = json.loads(json.dumps(push))
    torque["walker"]["actuation"]["torques"] = TORQUE
    pd = json.loads(json.dumps(push))
    pd["walker"]["actuation"]["torques"] = PD_REFERENCE
    return {"passive (paper, slope)": paper, "push-off (level)": push,
            "push-off + hip torque (level)": torque,
            "push-off + PD phase reference (level)": pd}


def _fixed_point_time(scene: dict, repeats: int, backend: str | None = None,
                      method: str | None = None, gait: np.ndarray | None = None
                      ) -> tuple[float, int, np.ndarray]:
    """Median wall time [s], RHS evaluations and the fixed point of ``scene`` (solver
    ``backend``/``method`` replaced when given), from its gait (``gait``, else the scene's
    gait search) perturbed by 1e-3."""
    import walkerlab as wl
    from walkerlab.analysis.gait.poincare import find_fixed_point

    scene = json.loads(json.dumps(scene))
    if backend is not None:
        scene.setdefault("solver", {})["backend"] = backend
    if method is not None:
        scene["solver"]["method"] = method
    w = wl.Walker.from_scene(scene)
    guess = {"swing_angle_rad": -0.181, "stance_angle_rad": 0.181,
             "swing_rate_rad_per_s": -0.72, "stance_rate_rad_per_s": -0.88}
    if "torques" in scene["walker"].get("actuation", {}) and len(w.state_names()) == 4:
        scene["fixedpoint"]["initial_guess"] = guess  # the compass gait's torque cases
        w = wl.Walker.from_scene(scene)
    start = (w.fixed_point().x if gait is None else gait) * (1 + 1e-3)
    times, nfev = [], 0
    for _ in range(repeats):
        t = time.perf_counter()
        r = find_fixed_point(w.model, start, w.solver, max_step_time=w.max_step_time)
        times.append(time.perf_counter() - t)
        nfev = r.nfev
    return float(np.median(times)), int(nfev), r.x


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
    ap.add_argument("--rabbit", action="store_true", help="also RABBIT's fixed point (slow)")
    a = ap.parse_args()
    sc = _scenes()
    rows = {}
    for k, v in sc.items():  # the compiled flows first: their gait starts the Python path's
        rows[(k, "cyrk_compiled")] = _fixed_point_time(v, a.repeats, "cyrk_compiled")
        rows[(k, "auto")] = _fixed_point_time(v, a.repeats, "auto",
                                              gait=rows[(k, "cyrk_compiled")][2])
    rows = {key: rows[key] for key in sorted(rows, key=lambda r: (list(sc).index(r[0]),
                                                                  r[1] != "auto"))}
    base = {b: rows[("passive (paper, slope)", b)][0] for b in ("auto", "cyrk_compiled")}
    print(f"{'fixed point from a 1e-3 perturbed start':40s} {'backend':>13s} {'median s':>9s} "
          f"{'nfev':>7s} {'/ passive':>9s} {'/ passive auto':>14s} {'|x - x_auto|':>12s}")
    for (k, b), (t, n, x) in rows.items():
        dx = np.max(np.abs(x - rows[(k, "auto")][2]))
        print(f"{k:40s} {b:>13s} {t:9.3f} {n:7d} {t / base[b]:9.2f} "
              f"{t / base['auto']:14.2f} {dx:12.2e}")
    if a.rabbit:  # its scene's LSODA on the Python flows against DOP853 on compiled laws
        from walkerlab.config import load_scene

        rabbit = load_scene(CONFIGS / "rabbit.yaml").model_dump(mode="json", exclude_none=True)
        t1, n1, x1 = _fixed_point_time(rabbit, 1, "cyrk_compiled", "DOP853")
        t0, n0, x0 = _fixed_point_time(rabbit, 1, gait=x1)
        dx = np.max(np.abs(x1 - x0))
        print(f"rabbit fixed point: LSODA (scene) {t0:.1f} s, {n0} RHS; DOP853 compiled laws "
              f"{t1:.2f} s, {n1} RHS ({t0 / t1:.0f}x faster); max |dx| {dx:.1e}")
    stage_s, ledger_s = _simulate_stage_and_ledger(sc["push-off (level)"], a.repeats)
    print(f"simulate stage (push-off, 5 strides): {stage_s:.3f} s; its energy ledger "
          f"{ledger_s:.4f} s ({100 * ledger_s / stage_s:.1f} % of the stage)")


if __name__ == "__main__":
    main()
