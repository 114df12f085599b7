"""First and second ``walkerlab report`` on a fresh copy of the scenes (issue 10, part 3).

Copies ``configs/`` into an empty temporary folder (no runs, no model-code cache: a fresh
checkout, install excluded), runs ``walkerlab report`` there, then runs it again, and prints
both wall times (targets: <= 60 s and <= 3 s on 2 cores) with the load average before each.

Usage::

    python scripts/bench_report.py [--scene configs/paper.yaml]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="configs/paper.yaml")
    args = ap.parse_args()
    root = Path(__file__).resolve().parents[1]
    res = {}
    with tempfile.TemporaryDirectory() as d:
        shutil.copytree(root / "configs", Path(d) / "configs")
        env = {k: v for k, v in os.environ.items() if k != "WALKERLAB_CACHE_DIR"}
        for label in ("first", "rerun"):
            load = os.getloadavg()[0]
            t0 = time.perf_counter()
            p = subprocess.run([sys.executable, "-m", "walkerlab.cli", "report", args.scene],
                               cwd=d, env=env, capture_output=True, text=True)
            wall = time.perf_counter() - t0
            res[label] = {"wall_s": wall, "loadavg_1min_before": load, "exit": p.returncode}
            print(f"{label:>6}: {wall:7.2f} s (load avg before {load:.2f}, exit {p.returncode})")
            print("        " + "\n        ".join(p.stdout.strip().splitlines()[:12]))
    out = root / "runs" / "bench"
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.json").write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
