"""The MFPT Monte Carlo walks on three integrators, in one process, interleaved: CPU per heel
strike of walkerlab's compiled walk (:mod:`walkerlab.integrate.rows_dop853` through
:func:`walkerlab.studies.mfpt.run_walks`), of CyRK's compiled DOP853 driven from a numba
loop, and of the minimal numba loop (:mod:`walkerlab.bench.monte_carlo_yardstick`).

    python scripts/bench_mc_cyrk.py [--scene configs/paper.yaml] [--walks 500] [--steps 100]
                                    [--sigma 0.002] [--repeats 5] [--out FILE.json]

CyRK's variant is the best one CyRK offers this loop: its numba-callable C entry point
(``CyRK.nb.numba_solver.c_numba_cysolve_ivp``, what ``nbsolve2_ivp`` calls) with a numba
``cfunc`` right-hand side, DOP853 with dense output, called from a numba loop once per
time chunk of a step, the guards checked on CyRK's accepted steps and the heel strike
located on its dense output (``c_call``) by secant/bisection to 1e-14 s, as the minimal
loop does on its own.  Each call spans ``--chunk`` seconds (default: 1.1 times the
previous heel strike's time, so that a call rarely integrates far past the heel strike,
where the walker, with no impact applied, runs on into a fall and its steps multiply, nor
stops short of it, which costs a new call and a new initial step).  That entry point takes
no events (CyRK's numba bridge passes none);
``pysolve_ivp`` has events but calls a Python right-hand side, and ``cysolve_ivp`` takes
Cython functions only.  CyRK's error norm is scipy's RMS over the 4 components, the other
two use the 2-norm (``BatchStepMap``'s criterion), so CyRK gets ``rtol / 2`` and
``atol / 2`` (the same accuracy).  The slopes, the start (the scene's gait) and the step
cap are the same for the three; the walks whose step count or fall differs from the
minimal loop's are counted.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def _cyrk_walks(mc):
    """The numba walk loop on CyRK's DOP853 (compiled on first call)."""
    from CyRK.cy.pyhelpers import find_ode_method_int
    from CyRK.nb import numba_solver as ns
    from numba import carray, cfunc, njit

    flow = mc.flow

    @cfunc(ns.cyjit_sig, cache=False)
    def rhs(dy, t, y, args):  # pragma: no cover - compiled
        yy = carray(y, 4)
        pp = carray(args, 5)
        out = carray(dy, 4)
        flow(yy, pp, out)

    addr = rhs.address
    solve, size, t_ptr, y_ptr, free, call = (ns.c_numba_cysolve_ivp, ns.c_get_size,
                                             ns.c_get_t_ptr, ns.c_get_y_ptr, ns.c_free,
                                             ns.c_call)
    success = ns.c_get_success
    dop853 = find_ode_method_int("DOP853")
    big = ns.MAX_SIZE
    impact = mc.impact

    @njit
    def guard(y, gamma, which):  # pragma: no cover - compiled
        return y[0] - y[1] if which == 0 else y[0] + y[1] + 2.0 * gamma

    @njit
    def locate(ptr, ta, tb, gamma, out):  # pragma: no cover - compiled
        """Heel strike time in [ta, tb] on the dense output, state into ``out``."""
        call(ptr, ta, out.ctypes.data)
        ga = guard(out, gamma, 1)
        call(ptr, tb, out.ctypes.data)
        gb = guard(out, gamma, 1)
        lo, hi, glo, ghi = ta, tb, ga, gb
        x = hi
        for it in range(80):
            x = hi - ghi * (hi - lo) / (ghi - glo) if it % 3 != 2 else 0.5 * (lo + hi)
            if not lo < x < hi:
                x = 0.5 * (lo + hi)
            call(ptr, x, out.ctypes.data)
            gx = guard(out, gamma, 1)
            if (gx > 0) == (glo > 0):
                lo, glo = x, gx
            else:
                hi, ghi = x, gx
            if hi - lo < 1e-14 or gx == 0.0:
                break
        call(ptr, x, out.ctypes.data)
        return x

    @njit
    def step(x0, gamma, p, rt, at, max_time, chunk, out, ev, empty, th):  # pragma: no cover
        y = x0.copy()
        t0 = 0.0
        armed = False
        while t0 < max_time:
            t1 = min(t0 + chunk, max_time)
            ptr = solve(np.uint64(addr), t0, t1, y.ctypes.data, np.uint64(4), np.int32(dop853),
                        np.uint64(0), np.uint64(0), p.ctypes.data, np.uint64(40),
                        np.uint64(0), np.uint64(2000), True, empty.ctypes.data, np.uint64(0),
                        0, 0, np.uint64(0), rt.ctypes.data, np.uint64(1), at.ctypes.data,
                        np.uint64(1), big, 0.0, True)
            if not success(ptr):
                free(ptr)
                return False
            n = size(ptr)
            T = carray(t_ptr(ptr), n)
            Y = carray(y_ptr(ptr), (n, 4))
            for i in range(1, n):
                if abs(Y[i, 1]) >= 0.5 * math.pi:
                    free(ptr)
                    return False  # the hip reaches the ground
                if not armed and guard(Y[i], gamma, 0) > 0 >= guard(Y[i - 1], gamma, 0):
                    armed = True
                elif armed and guard(Y[i], gamma, 0) < 0:
                    free(ptr)
                    return False  # the swing leg falls back
                if armed and guard(Y[i], gamma, 1) <= 0 < guard(Y[i - 1], gamma, 1):
                    th[0] = locate(ptr, T[i - 1], T[i], gamma, ev)
                    free(ptr)
                    impact(ev, p, out)
                    return True
            for k in range(4):
                y[k] = Y[n - 1, k]
            t0 = T[n - 1]
            free(ptr)
        return False

    @njit
    def walks(x0, slopes, p, rtol, atol, max_time, chunk, steps_out, fell_out):  # pragma: no cover
        x = np.empty(4)
        nxt = np.empty(4)
        ev = np.empty(4)
        empty = np.empty(1)
        rt = np.array([rtol])
        at = np.array([atol])
        th = np.zeros(1)
        tprev = 0.0
        for w in range(slopes.shape[0]):
            x[:] = x0
            steps_out[w] = 0
            fell_out[w] = False
            for k in range(slopes.shape[1]):
                # chunk < 0: each call spans -chunk times the previous heel strike's time
                span = chunk if chunk > 0 or tprev == 0.0 else -chunk * tprev
                if not step(x, slopes[w, k], p, rt, at, max_time, span if span > 0 else 1.0,
                            nxt, ev, empty, th):
                    fell_out[w] = True
                    break
                tprev = th[0]
                steps_out[w] += 1
                x[:] = nxt

    return walks


def measure(scene_path: str, walks: int = 500, steps: int = 100, sigma: float = 0.002,
            repeats: int = 5, chunk: float = -1.1) -> dict:
    """CPU per heel strike [us] of the three loops (module docstring), their ratios to the
    minimal loop (medians and each repeat's), and the walks that differ from it."""
    sys.path.insert(0, str(ROOT))
    from walkerlab.usercache import use_for_numba

    use_for_numba()  # the yardstick's numba cache in the user cache, not by its source
    spec = importlib.util.spec_from_file_location(
        "monte_carlo_yardstick", ROOT / "walkerlab" / "bench" / "monte_carlo_yardstick.py")
    mc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mc)
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.analysis.robustness.mfpt import draw_slopes
    from walkerlab.bench.benchmarks import machine
    from walkerlab.config import MfptSettings, load_scene
    from walkerlab.studies import mfpt as work

    scene = load_scene(scene_path)
    plant = Plant.from_scene(scene)
    _, search = solve_scene(scene, fd_check=False, plant=plant)
    x = np.asarray(search.gait.result.x, float)
    st = scene.mfpt or MfptSettings()
    W, S = walks, steps
    base = scene.model_dump(mode="json")
    task = work.WalkTask(base, tuple(map(float, x)), sigma, tuple(range(W)), S, st.seed,
                         "normal", 0, plant=plant)
    sm = work.step_map_for(base, plant=plant)
    slopes = np.stack([draw_slopes(st.seed, w, S, sm.slope_rad, sigma) for w in range(W)])
    p = mc.params(scene.walker)
    cy_walks = _cyrk_walks(mc)
    res = {k: (np.zeros(W, np.int64), np.zeros(W, bool)) for k in ("minimal", "cyrk")}

    def lib():
        return work.run_walks(task)[1:]

    def minimal():
        s, f = res["minimal"]
        mc.walks(x, slopes, p, st.rtol, st.atol, st.max_step_time_s, s, f)
        return s, f

    def cyrk():
        s, f = res["cyrk"]
        cy_walks(x, slopes, p, st.rtol / 2, st.atol / 2, st.max_step_time_s, chunk, s, f)
        return s, f

    runs = {"library": lib, "cyrk": cyrk, "minimal": minimal}
    out_runs = {k: fn() for k, fn in runs.items()}  # compile / load, warm
    t = {k: [] for k in runs}
    for r in range(repeats):
        order = list(runs) if r % 2 == 0 else list(runs)[::-1]
        for k in order:
            c = time.process_time()
            out_runs[k] = runs[k]()
            t[k].append(time.process_time() - c)
    ref = out_runs["minimal"]
    hs = {k: int(v[0].sum() + v[1].sum()) for k, v in out_runs.items()}
    us = {k: 1e6 * float(np.median(v)) / hs[k] for k, v in t.items()}
    return {"us_per_heel_strike": us,
            "over_minimal": {k: us[k] / us["minimal"] for k in us},
            "pair_ratios_over_minimal": {k: [a_ / b for a_, b in zip(t[k], t["minimal"])]
                                         for k in t},
            "heel_strikes": hs,
            "falls": {k: int(v[1].sum()) for k, v in out_runs.items()},
            "walks_differing_from_minimal": {
                k: int(np.sum((v[0] != ref[0]) | (v[1] != ref[1])))
                for k, v in out_runs.items()},
            "walks": W, "max_steps": S, "sigma_rad": sigma, "rtol": st.rtol,
            "atol": st.atol, "repeats": repeats, "chunk_s": chunk, **machine()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default=str(ROOT / "configs" / "paper.yaml"))
    ap.add_argument("--walks", type=int, default=500)
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--sigma", type=float, default=0.002)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--chunk", type=float, default=-1.1,
                    help="time span [s] of one CyRK call (a step needs ~0.7 s); negative: "
                    "that many times the previous heel strike's time")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()
    out = measure(a.scene, a.walks, a.steps, a.sigma, a.repeats, a.chunk)
    for k, us in out["us_per_heel_strike"].items():
        print(f"{k:8s} {us:8.2f} us/heel strike  x{out['over_minimal'][k]:.3f} of the "
              f"minimal loop  walks differing {out['walks_differing_from_minimal'][k]}")
    if a.out is not None:
        a.out.write_text(json.dumps(out, indent=1, default=str))


if __name__ == "__main__":
    main()
