"""The paper's main job, timed as a new user meets it (``walkerlab bench main-job``), with
another code tree side by side.

    python scripts/bench_main_job.py [--vs DIR] [--repeats 3] [--parts contact_sim,bare,report,...]
                                     [--out runs/bench/main_job.json]

``--vs DIR``: a second code tree (e.g. ``git worktree add prev_tree <commit>``) measured in
the same run, alternating which goes first; the table gives this/vs ratios.  What is
measured and the goals: :mod:`walkerlab.bench.main_job`.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    import sys

    sys.path.insert(0, str(ROOT))
    from walkerlab.bench.benchmarks import machine
    from walkerlab.bench.main_job import lines, run_main_job
    from walkerlab.io.artifacts import atomic_write

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vs", type=Path, default=None)
    ap.add_argument("--scene", default="configs/paper.yaml")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--mesh-repeats", type=int, default=1)
    ap.add_argument("--walks", type=int, default=500)
    ap.add_argument("--parts", default="contact_sim,bare,report,montecarlo,mesh,robustness")
    ap.add_argument("--out", type=Path, default=ROOT / "runs" / "bench" / "main_job.json")
    a = ap.parse_args()
    res = run_main_job(a.scene, ROOT, a.vs, a.repeats, walks=a.walks,
                       mesh_repeats=a.mesh_repeats, parts=tuple(a.parts.split(",")))
    res = {"benchmark": "main-job", **machine(), "result": res}
    a.out.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(res, indent=1, default=str).encode()
    atomic_write(a.out, lambda fh: fh.write(text))
    print("\n".join(lines(res["result"])))
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
