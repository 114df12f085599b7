"""Timing of the hybrid zero dynamics of a scene under virtual constraints (benchmark, not
a test): :func:`walkerlab.bench.hzd.bench_hzd` (``walkerlab bench hzd`` on the shipped
RABBIT) on any scene file.  The issue's target: delta^2 <= 10 ms.

Usage: ``python scripts/bench_hzd.py [configs/rabbit_hzd.yaml] [repeats]``.
"""

from __future__ import annotations

import sys

from walkerlab.bench.hzd import bench_hzd, lines

if __name__ == "__main__":
    path = sys.argv[1] if len(sys.argv) > 1 else "configs/rabbit_hzd.yaml"
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 50
    print("\n".join(lines(bench_hzd(path, repeats))))
