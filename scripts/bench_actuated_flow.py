"""Benchmark: the generated actuated flow against the passive flow of the same walker
(issue 48's goal: <= 1.3x), compiled, in the rigid and the contact view.

Each actuated case adds one torque actuator with a zero-gain law to a shipped scene, so
its trajectory (and the integrator's steps, ``nfev``) is the passive one's and the ratio
is the cost of the generated actuated flow itself (``B(q) tau`` and the law evaluated at
every right-hand side call):

- the paper's walker (configs/paper.yaml) with a hip PD law tracking a cubic phase
  reference (a virtual constraint; gains 0), saturated;
- the kneed walker (configs/kneed.yaml) with a swing-knee torque;
- the arc-foot walker (configs/round_feet.yaml) with a hip torque;
- flat feet (configs/flat_feet.yaml) with a stance-ankle torque.

Rigid view (the ``cyrk_compiled`` backend: numba cfuncs): CPU per Poincaré map (one
step) and per right-hand side call (map / ``nfev``), and per fixed point (from the gait
perturbed by 1e-3); passive and actuated interleaved, median of ``--repeats``.  Contact
view (``walkerlab contact-sim``'s run, :meth:`walkerlab.api.walker.ContactWalker.simulate`,
``--strides``): the paper's walker against the same with the zero-gain hip law, and the
push-off walker (configs/powered_compass.yaml: the same walker, level ground, 3 N s), CPU
per simulated second (the runs' lengths differ: a powered run ends at a heel strike, the
passive one at its end time).  Everything in one process, warm (generated code compiled
first).

    python scripts/bench_actuated_flow.py [--repeats 7] [--strides 2] [--no-contact]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
ZERO = {"stiffness_n_m_per_rad": 0.0, "damping_n_m_s_per_rad": 0.0}
#: a virtual constraint on the hip, gains 0 (the law evaluated, the trajectory passive)
PD_REFERENCE = {"joint": "hip", "max_torque_n_m": 5.0, "law": {**ZERO, "reference": {
    "phase_rad": [-0.18, -0.12, -0.06, 0.0, 0.06, 0.12, 0.18],
    "angle_rad": [0.3469, 0.3257, 0.2367, 0.0, -0.2367, -0.3257, -0.3469],
    "interpolation": "cubic"}}}
#: (label, scene, torque actuator)
CASES = (
    ("paper, hip PD (phase reference)", "paper.yaml", PD_REFERENCE),
    ("kneed, swing-knee torque", "kneed.yaml", {"joint": "swing_knee",
                                                "law": {"constant_n_m": 0.0, **ZERO}}),
    ("arc feet, hip torque", "round_feet.yaml", {"joint": "hip",
                                                 "law": {"constant_n_m": 0.0, **ZERO}}),
    ("flat feet, stance-ankle torque", "flat_feet.yaml",
     {"joint": "stance_ankle", "law": {"constant_n_m": 0.0, **ZERO}}),
)


def _scene(name: str, torque: dict | None, backend: str | None = "cyrk_compiled") -> dict:
    from walkerlab.config import load_scene

    sc = load_scene(CONFIGS / name).model_dump(mode="json", exclude_none=True)
    if backend is not None:
        sc.setdefault("solver", {})["backend"] = backend
    if torque is not None:
        sc["walker"].setdefault("actuation", {})["torques"] = [json.loads(json.dumps(torque))]
    return sc


def _cpu(fn) -> tuple[float, object]:
    c = time.process_time()
    out = fn()
    return time.process_time() - c, out


def rigid_case(name: str, torque: dict, repeats: int) -> dict:
    """CPU [s] per map, per RHS call and per fixed point: passive and actuated."""
    import walkerlab as wl
    from walkerlab.analysis.gait.poincare import find_fixed_point, poincare_map

    ws = {k: wl.Walker.from_scene(_scene(name, t)) for k, t in (("passive", None),
                                                                ("actuated", torque))}
    x = ws["passive"].fixed_point().x
    start = x * (1 + 1e-3)
    res = {k: {"map": [], "fp": [], "nfev": 0, "model": type(w.model).__name__,
               "backend": w.solver.backend} for k, w in ws.items()}
    xs = {}
    for k, w in ws.items():  # warm: compiled, first map and fixed point
        xs[k] = poincare_map(w.model, x, w.solver)[0]
        find_fixed_point(w.model, start, w.solver, max_step_time=w.max_step_time)
    batch = 5
    for _ in range(repeats):
        for k, w in ws.items():
            t, out = _cpu(lambda w=w: [poincare_map(w.model, x, w.solver)
                                       for _ in range(batch)][-1])
            res[k]["map"].append(t / batch)
            res[k]["nfev"] = int(out[-1])
            t, fp = _cpu(lambda w=w: find_fixed_point(w.model, start, w.solver,
                                                      max_step_time=w.max_step_time))
            res[k]["fp"].append(t)
            res[k]["fp_x"] = fp.x
    out = {k: {"map_s": float(np.median(r["map"])), "fp_s": float(np.median(r["fp"])),
               "nfev": r["nfev"], "model": r["model"], "backend": r["backend"]}
           for k, r in res.items()}
    for r in out.values():
        r["rhs_us"] = 1e6 * r["map_s"] / r["nfev"]
    out["dx_map"] = float(np.max(np.abs(xs["actuated"] - xs["passive"])))
    out["dx_fp"] = float(np.max(np.abs(res["actuated"]["fp_x"] - res["passive"]["fp_x"])))
    return out


def contact_cases(repeats: int, strides: int) -> dict:
    """CPU [s] per simulated second of the contact run: paper, paper + zero-gain hip law,
    the push-off walker."""
    import walkerlab as wl

    hip = {"joint": "hip", "law": {"constant_n_m": 0.0, **ZERO}}
    cws = {"paper (passive)": wl.ContactWalker.from_scene(_scene("paper.yaml", None, None)),
           "paper + zero-gain hip law": wl.ContactWalker.from_scene(
               _scene("paper.yaml", hip, None)),
           "paper + hip PD (phase reference, gains 0)": wl.ContactWalker.from_scene(
               _scene("paper.yaml", PD_REFERENCE, None)),
           "push-off (powered_compass, level)": wl.ContactWalker.from_scene(
               _scene("powered_compass.yaml", None, None))}
    runs = {k: [] for k in cws}
    info = {}
    for k, cw in cws.items():  # warm: the rigid gait, the compiled contact code
        walk = cw.simulate(strides=strides)
        info[k] = walk
    for _ in range(repeats):
        for k, cw in cws.items():
            t, walk = _cpu(lambda cw=cw: cw.simulate(strides=strides))
            runs[k].append(t / float(walk.t[-1] - walk.t[0]))
    out = {}
    for k in cws:
        walk = info[k]
        out[k] = {"cpu_per_sim_s": float(np.median(runs[k])),
                  "sim_s": float(walk.t[-1] - walk.t[0]),
                  "steps": int(len(walk.steps["period"])) if hasattr(walk, "steps") else -1,
                  "spread": (float(np.min(runs[k])), float(np.max(runs[k])))}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--strides", type=int, default=2)
    ap.add_argument("--no-contact", action="store_true")
    ap.add_argument("--only", nargs="*", default=None, help="case labels' first words")
    a = ap.parse_args()
    print("| walker, actuator (gains 0) | model | map CPU ms passive / actuated | ratio | "
          "RHS us passive / actuated | fixed point CPU ms passive / actuated | ratio | "
          "max dx (map, fp) |")
    print("|---|---|---|---|---|---|---|---|")
    for label, name, torque in CASES:
        if a.only and not any(label.startswith(o) for o in a.only):
            continue
        try:
            r = rigid_case(name, torque, a.repeats)
        except Exception as e:  # noqa: BLE001 - a benchmark row that cannot run says why
            print(f"| {label} | refused/failed: {str(e).splitlines()[0][:150]} |")
            continue
        p, q = r["passive"], r["actuated"]
        print(f"| {label} | {p['model']} -> {q['model']} ({q['backend']}) | "
              f"{1e3 * p['map_s']:.3f} / {1e3 * q['map_s']:.3f} | "
              f"{q['map_s'] / p['map_s']:.2f} | {p['rhs_us']:.2f} / {q['rhs_us']:.2f} "
              f"(nfev {p['nfev']} / {q['nfev']}) | {1e3 * p['fp_s']:.1f} / "
              f"{1e3 * q['fp_s']:.1f} | {q['fp_s'] / p['fp_s']:.2f} | "
              f"{r['dx_map']:.0e}, {r['dx_fp']:.0e} |", flush=True)
    if a.no_contact:
        return
    c = contact_cases(max(3, a.repeats // 2), a.strides)
    base = c["paper (passive)"]["cpu_per_sim_s"]
    print("\n| contact run | simulated s | CPU s per simulated s (min-max) | / paper passive |")
    print("|---|---|---|---|")
    for k, r in c.items():
        lo, hi = r["spread"]
        print(f"| {k} | {r['sim_s']:.3f} | {r['cpu_per_sim_s']:.3f} ({lo:.3f}-{hi:.3f}) | "
              f"{r['cpu_per_sim_s'] / base:.2f} |")


if __name__ == "__main__":
    main()
