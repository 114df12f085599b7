"""Robustness table of shipped walkers (issue 24): |lambda|max in absolute and relative
angles, the gait sensitivity norm of each disturbance (linearised, and the nonlinear check),
the state-indicator norm in both coordinate choices (Jin et al. 2021), for the slope change,
floor height step and mid-stance push, and the largest tolerable single step-down and step-up
(bisection brackets, 1 mm) and mid-stance push forward/backward (1 mm/s).

    python scripts/robustness_table.py [paper kneed ...]
    python scripts/robustness_table.py --contact [paper kneed ...]

``--contact``: the contact model's largest single step-down and step-up instead (patches at
the step's height, from the contact model's periodic gait - or from the contact run's own
start when none is found within contact_sim.periodic_max_step_maps - surviving 10 heel strikes;
bisection brackets to 1 mm, walks on 2 local worker processes).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
WALKERS = ("paper", "goswami1996", "paper_rods", "round_feet", "kneed", "simplest",
           "schwab_wisse2001", "hip_spring", "torso_bhm", "asymmetric_legs")


def row(name: str) -> str:
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.analysis.robustness import measures as R
    from walkerlab.config import load_scene
    from walkerlab.integrate.batch_step import BatchStepMap
    from walkerlab.models.registry import build_walker
    from walkerlab.studies.mfpt import scene_walker_at

    t = time.perf_counter()
    sc = load_scene(ROOT / "configs" / f"{name}.yaml")
    plant = Plant.from_scene(sc)
    try:
        sm = BatchStepMap(build_walker(plant), scene_walker_at(sc, plant=plant),
                          1e-12, 1e-12)
    except ValueError as exc:
        return f"| {name} | not supported: {exc} |"
    w, s = solve_scene(sc, fd_check=False, plant=plant)
    if w.steps_per_map != 1:
        return f"| {name} | not supported: legs that differ (a stride map) |"
    g = s.gait.result
    A, x = g.jacobian_variational, g.x
    T = R.relative_coordinates(w.state_names())
    lam = np.max(np.abs(np.linalg.eigvals(A)))
    lam_rel = np.max(np.abs(np.linalg.eigvals(T @ A @ np.linalg.inv(T))))
    cells = [name, f"{lam:.4f} / {lam_rel:.4f}"]
    for dist in ("slope", "floor_height", "push"):
        lin = R.linearise(sm, x, A, dist)
        gl = lin.gsn()
        gn = R.gsn_nonlinear(sm, x, dist, 1e-5, steps=60)
        cells += [f"{gl:.4g} ({abs(gl - gn) / gl:.0e})",
                  f"{R.state_gsn(lin):.4g} / {R.state_gsn(lin, T):.4g}"]
    L = float(w.params.get("leg_length_m", 1.0))
    for dist, cap, tol, scale in (("floor_height", 0.25 * L, 0.001, 1000),
                                  ("push", 1.0, 0.001, 1)):
        for sign in (1.0, -1.0):
            lo, hi = R.largest_by_bisection(sm, x, dist, cap, tol, sign=sign)
            cells.append(f"{scale * lo:.4g}-{scale * hi:.4g}")
    cells.append(f"{time.perf_counter() - t:.0f}")
    return "| " + " | ".join(cells) + " |"


def contact_row(name: str) -> str:
    from walkerlab.analysis.contact.rough import contact_start
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.config import load_scene
    from walkerlab.studies.contact_rough import contact_largest_step

    t = time.perf_counter()
    sc = load_scene(ROOT / "configs" / f"{name}.yaml")
    if sc.contact is None:
        return f"| {name} | no contact section |"
    plant = Plant.from_scene(sc)
    _, s = solve_scene(sc, fd_check=False, plant=plant)
    start = "periodic gait"
    try:
        st = contact_start(sc, s.gait.result.x, plant=plant)
    except Exception:  # no periodic gait in time: the contact run's own start (a transient)
        st = contact_start(sc, s.gait.result.x, periodic=False, plant=plant)
        start = "contact-sim start (no periodic gait found in time)"
    cells = [name, f"{st.period_s:.6f} ({start})"]
    for sign in (1.0, -1.0):
        lo, hi = contact_largest_step(st, sign, 0.05, 0.001, 10, workers=2)
        cells.append(f"{1000 * lo:.4g}-{1000 * hi:.4g}" if lo == lo else
                     "falls without a step")
    cells.append(f"{time.perf_counter() - t:.0f}")
    return "| " + " | ".join(cells) + " |"


def main() -> None:
    args = sys.argv[1:]
    if args and args[0] == "--contact":
        print("| walker | contact gait period [s] | step-down [mm] | step-up [mm] | s |")
        print("|---|---|---|---|---|")
        for n in args[1:] or WALKERS:
            print(contact_row(n), flush=True)
        return
    names = args or WALKERS
    print("| walker | abs lambda max (abs / rel angles) | GSN slope [1/rad] (lin vs nonlin) "
          "| state norm slope (abs / rel) | GSN floor height [1/m] (lin vs nonlin) "
          "| state norm height (abs / rel) | GSN push [s/m] (lin vs nonlin) "
          "| state norm push (abs / rel) | step-down [mm] | step-up [mm] "
          "| push forward [m/s] | push backward [m/s] | s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for n in names:
        print(row(n), flush=True)


if __name__ == "__main__":
    main()
