"""First and second ``walkerlab report`` on a fresh copy of the scenes (issue 10, part 3).

Copies the measured tree's ``configs/`` into an empty temporary folder (no runs, no
model-code cache: a fresh checkout, install excluded), runs ``walkerlab report`` there, then
runs it again, and prints both wall times (targets: <= 60 s and <= 3 s on 2 cores) with
the load average before each, the CPU time of the whole process tree and each stage's own
"computed in" time.

numba's on-disk cache lives next to the sources (``__pycache__``), so a plain run here would
reuse kernels compiled by earlier runs; a fresh checkout has none.  By default the first run
therefore gets an empty ``NUMBA_CACHE_DIR`` (the rerun keeps it); ``--warm-numba`` keeps the
source tree's cache instead.

``--vs DIR`` measures two code trees side by side (A = ``DIR``, e.g. the starting commit's
worktree; B = ``--code``, default this checkout), ``--rounds`` times, alternating which goes
first, and prints per-stage medians and the median of the paired ratios B/A.

Usage::

    python scripts/bench_report.py [--scene configs/paper.yaml] [--code DIR] [--vs DIR]
                                   [--rounds N] [--warm-numba]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

LINE = re.compile(r"^\s*([\w-]+): computed in ([0-9.]+) s")


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def one(code: Path, scene: str, cold_numba: bool) -> dict:
    """First run and rerun of ``walkerlab report`` with ``code`` on PYTHONPATH, on a copy of
    that tree's own ``configs/`` (scene files follow the code's schema)."""
    res = {"code": str(code)}
    with tempfile.TemporaryDirectory() as d:
        shutil.copytree(code / "configs", Path(d) / "configs")
        # generated model code cold (a fresh user cache per run), numba's cache warm (the
        # user's own) unless cold_numba
        env = dict(os.environ)
        env["PYTHONPATH"] = str(code)
        if not cold_numba and not env.get("NUMBA_CACHE_DIR"):  # walkerlab.usercache.root()
            base = os.environ.get("WALKERLAB_CACHE_DIR") or str(
                Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "walkerlab")
            env["NUMBA_CACHE_DIR"] = str(Path(base) / "numba")
        env["WALKERLAB_CACHE_DIR"] = str(Path(d) / "user_cache")
        if cold_numba:
            env["NUMBA_CACHE_DIR"] = str(Path(d) / "numba_cache")
        for label in ("first", "rerun"):
            load = os.getloadavg()[0]
            c0, t0 = _children_cpu(), time.perf_counter()
            p = subprocess.run([sys.executable, "-m", "walkerlab.cli", "report", scene],
                               cwd=d, env=env, capture_output=True, text=True)
            wall = time.perf_counter() - t0
            stages = {m.group(1): float(m.group(2)) for m in map(LINE.match,
                                                                p.stdout.splitlines()) if m}
            res[label] = {"wall_s": wall, "cpu_s": _children_cpu() - c0,
                          "loadavg_1min_before": load, "exit": p.returncode, "stages": stages}
            print(f"  {label:>6}: {wall:7.2f} s wall, {res[label]['cpu_s']:7.2f} s CPU "
                  f"(load avg before {load:.2f}, exit {p.returncode})  "
                  + ", ".join(f"{k} {v:.1f}" for k, v in stages.items()), flush=True)
            if p.returncode:
                print("        " + "\n        ".join((p.stdout + p.stderr).strip()
                                                   .splitlines()[-12:]))
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="configs/paper.yaml")
    ap.add_argument("--code", default=None, help="code tree to measure (default: this one)")
    ap.add_argument("--vs", default=None, help="code tree A to compare with (paired runs)")
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--warm-numba", action="store_true",
                    help="keep the source tree's numba cache (default: empty, as a fresh "
                    "checkout)")
    args = ap.parse_args()
    root = Path(__file__).resolve().parents[1]
    b = Path(args.code).resolve() if args.code else root
    a = Path(args.vs).resolve() if args.vs else None
    runs: list[dict] = []
    for r in range(args.rounds):
        order = [("B", b)] if a is None else ([("A", a), ("B", b)] if r % 2 == 0
                                              else [("B", b), ("A", a)])
        pair = {}
        for name, code in order:
            print(f"round {r + 1}, {name} = {code}", flush=True)
            pair[name] = one(code, args.scene, not args.warm_numba)
        runs.append(pair)
    summary = {}
    for name in ("A", "B"):
        got = [p[name] for p in runs if name in p]
        if not got:
            continue
        keys = sorted({k for g in got for k in g["first"]["stages"]})
        summary[name] = {
            "first_wall_s": statistics.median(g["first"]["wall_s"] for g in got),
            "first_cpu_s": statistics.median(g["first"]["cpu_s"] for g in got),
            "rerun_wall_s": statistics.median(g["rerun"]["wall_s"] for g in got),
            "stages_s": {k: statistics.median(g["first"]["stages"].get(k, float("nan"))
                                              for g in got) for k in keys}}
    if a is not None:
        def ratio(f):
            return statistics.median(f(p["B"]) / f(p["A"]) for p in runs)
        summary["ratio_B_over_A"] = {
            "first_wall": ratio(lambda g: g["first"]["wall_s"]),
            "first_cpu": ratio(lambda g: g["first"]["cpu_s"]),
            "rerun_wall": ratio(lambda g: g["rerun"]["wall_s"]),
            "stages": {k: ratio(lambda g, k=k: g["first"]["stages"][k])
                       for k in summary["B"]["stages_s"]
                       if all(k in p[n]["first"]["stages"] for p in runs for n in "AB")}}
    print(json.dumps(summary, indent=1))
    out = root / "runs" / "bench"
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.json").write_text(json.dumps({"runs": runs, "summary": summary,
                                                 "cold_numba": not args.warm_numba},
                                                indent=1))


if __name__ == "__main__":
    main()
