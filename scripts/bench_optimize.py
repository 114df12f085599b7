"""Benchmark: ``walkerlab optimize`` of the shipped optimisation scenes (compass_optimal,
kuo2002, rabbit_optimal), whole process, cold (fresh runs folder and code cache) and warm
(``--force``), wall and CPU medians (:mod:`walkerlab.bench.optimize`; also
``walkerlab bench optimize``).  Goals: compass and Kuo <= 5 s, the five-link <= 60 s.

    python scripts/bench_optimize.py [--repeats 3] [--scenes compass_optimal kuo2002]
                                     [--out bench_optimize.json] [--vs OTHER_TREE]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from walkerlab.bench.optimize import SCENES, bench_optimize, lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    ap.add_argument("--out", type=Path, default=None, help="JSON results file")
    ap.add_argument("--vs", type=Path, default=None, help="another code tree (its folder "
                    "holding walkerlab/), run in turn with this one, ratios pair by pair")
    a = ap.parse_args()
    res = bench_optimize(a.scenes, a.repeats, a.vs)
    print("\n".join(lines(res)))
    if a.out is not None:
        from walkerlab.io.artifacts import atomic_write

        text = json.dumps(res, indent=1, default=str).encode()
        atomic_write(a.out, lambda fh: fh.write(text))


if __name__ == "__main__":
    main()
