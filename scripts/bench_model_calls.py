"""Per-call cost of the generated model functions (flow, flow Jacobian, reset, reset Jacobian).

Usage: ``python scripts/bench_model_calls.py [configs/paper.yaml ...]``; prints microseconds per
call (best of 7 repeats, timeit) for each scene's walker at its fixed-point guess.  Run it with
``PYTHONPATH`` pointing at two checkouts to compare before/after (the numbers of the closing note
of issue 9/10 were taken this way).
"""

from __future__ import annotations

import sys
import timeit
from pathlib import Path

from walkerlab.config import load_scene
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant


def per_call_us(fn, number: int) -> float:
    return min(timeit.repeat(fn, number=number, repeat=7)) / number * 1e6


def main(paths: list[str]) -> None:
    for p in paths or ["configs/paper.yaml", "configs/paper_rods.yaml", "configs/simplest.yaml"]:
        sc = load_scene(p)
        w = build_walker(Plant.from_scene(sc))
        names = w.state_names()
        try:
            x = sc.fixedpoint.initial_guess.as_array(names)
        except TypeError:  # checkouts before the state-by-name scenes
            x = sc.fixedpoint.initial_guess.as_array()
        f, J = w.phases[0].flow, w.variational
        row = {"flow": per_call_us(lambda f=f, x=x: f(0.0, x), 5000),
               "flow_jacobian": per_call_us(lambda J=J, x=x: J(0.0, x), 2000),
               "reset": per_call_us(lambda w=w, x=x: w.reset(x), 2000),
               "reset_jacobian": per_call_us(lambda w=w, x=x: w.reset_jacobian(x), 2000)}
        print(Path(p).stem, "  ".join(f"{k} {v:.2f} us" for k, v in row.items()))


if __name__ == "__main__":
    main(sys.argv[1:])
