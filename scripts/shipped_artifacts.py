"""Write every shipped scene's artifacts into one runs folder, for a restructuring's
before/after comparison by ``scripts/compare_artifacts.py``.

    python scripts/shipped_artifacts.py RUNS_DIR [--stages fixedpoint,simulate,contact-sim]
                                        [--scenes paper,kneed]

Runs, for each scene in ``configs/`` (of the current folder: run it from the checkout whose
scenes and code are compared), ``walkerlab fixedpoint``, ``simulate`` and ``contact-sim``
(and ``optimize`` for a scene that has an ``optimize`` section), each in its own process;
a stage the scene's walker does not take ends in its one-line refusal, which is recorded
beside the others in ``RUNS_DIR/exit_codes.tsv`` (scene, stage, exit code, seconds), so a
before/after pair also compares which stages refused.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

import yaml

STAGES = ("fixedpoint", "simulate", "contact-sim")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs_dir", type=Path)
    ap.add_argument("--stages", default=",".join(STAGES + ("optimize",)))
    ap.add_argument("--scenes", default="")
    ap.add_argument("--timeout", type=float, default=900.0)
    a = ap.parse_args()
    a.runs_dir.mkdir(parents=True, exist_ok=True)
    stages = [s for s in a.stages.split(",") if s]
    scenes = sorted((Path.cwd() / "configs").glob("*.yaml"))
    if a.scenes:
        keep = set(a.scenes.split(","))
        scenes = [s for s in scenes if s.stem in keep]
    log = (a.runs_dir / "exit_codes.tsv").open("a")
    for scene in scenes:
        with scene.open() as fh:
            has_optimize = "optimize" in (yaml.safe_load(fh) or {})
        for stage in stages:
            if stage == "optimize" and not has_optimize:
                continue
            t0 = time.perf_counter()
            try:
                rc = subprocess.run(["walkerlab", "-q", stage, str(scene), "--runs-dir",
                                     str(a.runs_dir)], stdout=subprocess.DEVNULL,
                                    stderr=subprocess.PIPE, timeout=a.timeout,
                                    text=True).returncode
            except subprocess.TimeoutExpired:
                rc = "timeout"
            dt = time.perf_counter() - t0
            log.write(f"{scene.stem}\t{stage}\t{rc}\t{dt:.1f}\n")
            log.flush()
            print(f"{scene.stem:28s} {stage:12s} rc={rc} {dt:6.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
