"""Which library integrates the rigid walker fastest? (issue 10, part 1)

One step of the paper walker from its fixed point (both phases, guards as events), each
library with the walker's own flow (``walker.phases[k].flow``, the generated code) and its
events, at rtol = atol = 1e-10.  Prints the median CPU time per step, the RHS evaluations and
the error of the heel-strike time and state against a DOP853 run at 1e-13.

Candidates that install here with pip: scipy ``solve_ivp`` (DOP853, RK45, LSODA), CyRK
``pysolve_ivp`` (DOP853, RK45; C++ stepping, Brent's method on the dense output for events),
SUNDIALS CVODE through scikit-sundae (Adams, BDF; root finding built in), and scipy ``odeint``
(LSODA, no events: integrated to the known heel-strike time, a lower bound).  numbalsoda
does not install (needs a Fortran compiler: no wheel for this Python).

Usage::

    python scripts/bench_integrators.py [--repeats 7]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from walkerlab.walker.plant import Plant


def _cvode_functions(phase):
    """CVODE's ``rhs(t, y, yp)`` and ``events(t, y, e)`` for one phase (3 arguments each:
    scikit-sundae counts arguments to detect user data)."""
    f, guards = phase.flow, phase.guards

    def rhs(t, y, yp):
        yp[:] = f(t, y)

    def ev(t, y, e):
        for i, gd in enumerate(guards):
            e[i] = gd.function(t, y)
    return rhs, ev


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--rtol", type=float, default=1e-10)
    args = ap.parse_args()
    from walkerlab.analysis.gait.poincare import find_fixed_point
    from walkerlab.config import default_scene_path as default_scene
    from walkerlab.config import load_scene
    from walkerlab.integrate.rigid import integrate_step
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    scene = load_scene(default_scene())
    w = build_walker(Plant.from_scene(scene))
    names = w.state_names()
    try:
        guess = scene.fixedpoint.initial_guess.as_array(names)
    except TypeError:
        guess = scene.fixedpoint.initial_guess.as_array()
    x0 = find_fixed_point(w, guess, Solver("DOP853", 1e-12, 1e-12)).x
    ref = integrate_step(w, x0, Solver("DOP853", 1e-13, 1e-13, None, "scipy"))
    rt = args.rtol
    cases = {}

    def timed(label, fn):
        fn()
        cpu = []
        for _ in range(args.repeats):
            c0 = time.process_time()
            t_end, x_end, nfev = fn()
            cpu.append(time.process_time() - c0)
        cases[label] = {"cpu_ms": 1e3 * float(np.median(cpu)), "nfev": int(nfev),
                        "t_err": abs(t_end - ref.t_end),
                        "x_err": float(np.max(np.abs(np.asarray(x_end) - ref.x_end)))}
        c = cases[label]
        print(f"{label:28s} {c['cpu_ms']:8.3f} ms  nfev {c['nfev']:5d}  "
              f"t err {c['t_err']:.1e}  x err {c['x_err']:.1e}")

    for backend, method in (("scipy", "DOP853"), ("scipy", "RK45"), ("scipy", "LSODA"),
                            ("cyrk", "DOP853"), ("cyrk", "RK45")):
        sv = Solver(method, rt, rt, None, backend)

        def run(sv=sv):
            s = integrate_step(w, x0, sv)
            return s.t_end, s.x_end, s.nfev
        timed(f"{backend} {method}", run)
    try:
        from sksundae.cvode import CVODE

        def cvode(method):
            def run():
                t, x, nfev = 0.0, x0, 0
                for ph in w.phases:
                    rhs, ev = _cvode_functions(ph)
                    gds = ph.guards
                    ev.terminal = [True] * len(gds)
                    ev.direction = [gd.direction for gd in gds]
                    s = CVODE(rhs, method=method, rtol=rt, atol=rt, eventsfn=ev,
                              num_events=len(gds), max_num_steps=100000)
                    r = s.solve((t, t + 5.0), x)
                    t, x, nfev = r.t[-1], r.y[-1].copy(), nfev + r.nfev
                return t, x, nfev
            return run
        timed("scikit-sundae CVODE Adams", cvode("Adams"))
        timed("scikit-sundae CVODE BDF", cvode("BDF"))
    except ImportError:
        print("scikit-sundae not installed: CVODE skipped")
    from scipy.integrate import odeint

    f = w.phases[0].flow  # one flow for both phases of the compass gait (no events!)

    def od():
        y, info = odeint(f, x0, [0.0, ref.t_end], tfirst=True, rtol=rt, atol=rt,
                         full_output=True)
        return ref.t_end, y[-1], int(info["nfe"][-1])
    timed("scipy odeint (no events)", od)
    out = Path("runs/bench")
    out.mkdir(parents=True, exist_ok=True)
    (out / "integrators.json").write_text(json.dumps({"rtol": rt, "cases": cases}, indent=1))
    print(f"wrote {out / 'integrators.json'}")


if __name__ == "__main__":
    main()
