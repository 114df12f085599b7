"""The 3D walker's dynamics from the generated equations against Pinocchio's, per call, in
one run (the choice of walkerlab.codegen.derive_3d: sympy's generated code or Pinocchio).

    python scripts/bench_dynamics_3d.py [--calls 20000]

For configs/hip_width.yaml: the generated Python flow ``flow(t, x)`` (what scipy's
integrators call; CyRK's integrators call its numba twin, compiled from the same equations),
against Pinocchio's
articulated-body algorithm (``pinocchio.aba``) on the exported URDF (a free pelvis and two
legs: the same walker with the stance foot's constraint left out - Pinocchio would need the
contact's constraint dynamics on top, so this is its lower bound).  Medians of 5 repeats, in
microseconds per call; also the one-off cost of each (sympy's derivation, the URDF's
parsing).  Needs the ``engines`` extra (pinocchio).
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _per_call(fn, calls: int) -> float:
    best = []
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        best.append((time.perf_counter() - t0) / calls * 1e6)
    return float(np.median(best))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=20000)
    calls = ap.parse_args().calls
    import pinocchio as pin

    from walkerlab.codegen.cache import functions
    from walkerlab.config import load_scene
    from walkerlab.stages import export
    from walkerlab.walker.description import walker_data

    scene = load_scene(ROOT / "configs" / "hip_width.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    t0 = time.perf_counter()
    f = functions(data)
    t_gen = time.perf_counter() - t0
    x = np.array([0.04, -0.2, 0.17, 0.3, -0.6, -0.85])
    flow = f["flow"]
    out = {"generated_python_flow_us": _per_call(lambda: flow(0.0, x), calls),
           "model_functions_load_s": t_gen}
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        path = export.write(scene, tmp, "urdf").path
        model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        out["pinocchio_model_build_s"] = time.perf_counter() - t0
    pdata = model.createData()
    q = pin.neutral(model)
    v = np.zeros(model.nv)
    tau = np.zeros(model.nv)
    out["pinocchio_aba_us"] = _per_call(lambda: pin.aba(model, pdata, q, v, tau), calls)
    out["pinocchio_crba_us"] = _per_call(lambda: pin.crba(model, pdata, q), calls)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
