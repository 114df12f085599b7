"""Benchmarks behind ``walkerlab bench`` (speed goals are checked here, never in tests).

=============  ===============================================================  ==========
benchmark      what is timed                                                    target
=============  ===============================================================  ==========
``ideal``      5 strides (10 steps) of the paper walker from its fixed point,   <= 10 ms
               DOP853 rtol = atol = 1e-10, compute only (median); per backend
``fixedpoint`` ``walkerlab fixedpoint --force`` on the paper scene, whole       <= 1.0 s
               process (median of runs, model code cache warm)
``sweep``      fixed-point sweep over the slope (0.5-4.5 deg, 201 points), 2    >= 50 pt/s
               worker processes, pool start included (model code cache warm)
``basin``      ``walkerlab basin --grid 200x200 --force``, paper walker,        <= 120 s
               50 steps a cell at most, 2 workers, whole process
``contact``    the contact walker's work-precision benchmark
               (:func:`walkerlab.analysis.contact_bench.run_benchmark`); with scene
               files (``walkerlab bench contact configs/kneed.yaml ...``): each
               scene's walker, 5 contact strides at <= 1e-6 rad against a tight     kneed:
               reference, median time of the loosest tolerance band reaching it     <= 0.1 s
               (:func:`walkerlab.analysis.contact_bench.run_scene_benchmark`)
=============  ===============================================================  ==========

The first ``walkerlab report`` of a fresh checkout is timed by ``scripts/bench_report.py``.
Results are printed and written as JSON to ``OUT/<what>.json`` with the machine and its load
noted (the machine may be shared: compare runs side by side, e.g. with ``farm-bench``).
"""

from __future__ import annotations

import gc
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

BENCHMARKS = ("ideal", "fixedpoint", "sweep", "basin", "contact")


def _machine() -> dict:
    return {"machine": platform.machine(), "processor": platform.processor(),
            "cpus": os.cpu_count(), "python": platform.python_version(),
            "loadavg_1min": os.getloadavg()[0] if hasattr(os, "getloadavg") else None}


def _paper_scene():
    from walkerlab.config import default_scene_path as default_scene
    from walkerlab.config import load_scene

    return load_scene(default_scene())


def bench_ideal(repeats: int = 7) -> dict:
    """5 ideal strides at rtol 1e-10 per integrator backend, and the fixed-point search."""
    from walkerlab.analysis.poincare import find_fixed_point
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    scene = _paper_scene()
    t0 = time.perf_counter()
    w = build_walker(scene)
    build_s = time.perf_counter() - t0
    guess = np.asarray(scene.fixedpoint.initial_guess.as_array(w.state_names())
                       if _takes_names(scene) else scene.fixedpoint.initial_guess.as_array())
    sv = Solver.from_settings(scene.solver)
    fp = find_fixed_point(w, guess, sv)
    out = {"build_walker_s": build_s}
    for backend in ("cyrk", "scipy"):
        s = Solver("DOP853", 1e-10, 1e-10, None, backend)
        simulate_steps(w, fp.x, 10, s)  # warm (imports)
        # as the sweep/work-precision workers do: the loaded libraries' objects are not
        # traversed by the cyclic GC in every timed run (without this the first dozen runs
        # of a process take ~1.8x longer, which a 7-run median sees)
        gc.collect()
        gc.freeze()
        t, c = [], []
        for _ in range(repeats):
            t0, c0 = time.perf_counter(), time.process_time()
            tr = simulate_steps(w, fp.x, 10, s)
            t.append(time.perf_counter() - t0)
            c.append(time.process_time() - c0)
        out[f"simulate_5_strides_{backend}_median_s"] = float(np.median(t))
        out[f"simulate_5_strides_{backend}_cpu_median_s"] = float(np.median(c))
        out[f"simulate_5_strides_{backend}_nfev"] = tr.nfev
    t = []
    for _ in range(3):
        t0 = time.perf_counter()
        fp = find_fixed_point(w, guess, sv)
        t.append(time.perf_counter() - t0)
    out.update({"fixedpoint_compute_median_s": float(np.median(t)), "fixedpoint_nfev": fp.nfev,
                "fixedpoint_solver": f"{sv.method} rtol={sv.rtol:g} backend={sv.backend}",
                "target_simulate_5_strides_s": 0.010})
    return out


def _takes_names(scene) -> bool:
    import inspect

    return bool(inspect.signature(scene.fixedpoint.initial_guess.as_array).parameters)


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "walkerlab.cli", *args]


def _time_process(cmd: list[str], runs: int, cwd: Path | None = None) -> dict:
    walls = []
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True, cwd=cwd)
        walls.append(time.perf_counter() - t0)
    return {"wall_median_s": float(np.median(walls)), "wall_min_s": float(np.min(walls)),
            "wall_max_s": float(np.max(walls)), "runs": runs}


def bench_fixedpoint(runs: int = 5) -> dict:
    """``walkerlab fixedpoint --force`` on the paper scene, whole process."""
    with tempfile.TemporaryDirectory() as d:
        cmd = _cli("fixedpoint", "--force", "--runs-dir", d)
        subprocess.run(cmd, check=True, capture_output=True)  # warm the model code cache
        return {**_time_process(cmd, runs), "command": " ".join(cmd[2:]), "target_s": 1.0}


def bench_sweep(workers: int = 2, slopes: str = "0.5:4.5:0.02", cpu: bool = True) -> dict:
    """Fixed-point sweep over the slope with ``workers`` local processes (points/s).

    Timed from the call to the finished artifact (process pool start included), with the
    generated model code already in the runs folder's cache (as ``fixedpoint``'s benchmark:
    the one-off symbolic derivation of a fresh runs folder is not sweep throughput).  Also
    reported: Poincare maps per point (plain and variational, from the artifact) and, with
    ``cpu``, the CPU time per point of the same sweep run in this process (one worker).
    """
    from walkerlab.io.sweep_store import load_sweep
    from walkerlab.stages.sweep import run

    scene = _paper_scene()
    param = [f"slope.angle_deg={slopes}"]
    with tempfile.TemporaryDirectory() as d:
        run(scene, ["slope.angle_deg=1"], "fixedpoint", workers=1, runs_root=d,
            name="warm", progress=False)  # model code cache of this runs folder
        t0 = time.perf_counter()
        p = run(scene, param, "fixedpoint", workers=workers, runs_root=d, name="bench",
                progress=False)
        wall = time.perf_counter() - t0
        pts = load_sweep(p)["points"]
        cpu_pt = None
        if cpu:
            c0 = time.process_time()
            p1 = run(scene, param, "fixedpoint", workers=1, pool=False, runs_root=d,
                     name="bench_cpu", progress=False)
            cpu_pt = (time.process_time() - c0) / load_sweep(p1)["points"]["index"].size
    outcomes = pts["outcome"].astype(str)
    n = int(outcomes.size)
    kinds, counts = np.unique(outcomes, return_counts=True)
    return {"points": n, "workers": workers, "wall_s": wall, "points_per_s": n / wall,
            "maps_per_point": float(np.mean(pts["map_evaluations"])),
            "variational_maps_per_point": float(np.mean(pts["variational_maps"])),
            "point_wall_median_ms": 1e3 * float(np.median(pts["wall_time_s"])),
            "cpu_per_point_ms_in_process": None if cpu_pt is None else 1e3 * cpu_pt,
            "outcomes": {str(k): int(c) for k, c in zip(kinds, counts)},
            "note": "wall includes starting the process pool; model code cache warm",
            "target_points_per_s": 50}


def bench_basin(grid: str = "200x200", workers: int = 2) -> dict:
    """``walkerlab basin --grid 200x200 --force`` on the paper scene, whole process."""
    with tempfile.TemporaryDirectory() as d:
        subprocess.run(_cli("fixedpoint", "--runs-dir", d), check=True, capture_output=True)
        cmd = _cli("basin", "--grid", grid, "--workers", str(workers), "--force",
                   "--runs-dir", d)
        res = _time_process(cmd, 1)
        from walkerlab.io.schemas.basin import load_basin
        from walkerlab.stages.common import artifact_path

        b = load_basin(artifact_path(_paper_scene(), d, "basin"))
    out = b.outcome
    return {**res, "grid": grid, "workers": workers, "target_s": 120.0,
            "outcomes": {o: int(np.sum(out == i)) for i, o in enumerate(b.outcomes)}}


def _scene_line(res: dict) -> str:
    parts = []
    for method, t in res["target"].items():
        if t["reached"]:
            parts.append(f"{method} {t['median_wall_time_s']:.4f} s (rtol {t['rtols'][-1]:.2g}"
                         f"..{t['rtols'][0]:.2g}, worst error {t['worst_error_rad']:.2g} rad)")
        else:
            parts.append(f"{method} did not reach the target")
    return (f"contact {res['scene']}: {res['n_strides']} strides at <= 1e-6 rad: "
            + "; ".join(parts) + f" [reference {res['reference']['wall_time_s']:.3f} s]")


def bench_contact_scenes(scenes) -> dict:
    """:func:`~walkerlab.analysis.contact_bench.run_scene_benchmark` for each scene file.

    Raises
    ------
    ConfigError
        A scene file is missing or invalid (one line, from :func:`load_scene`).
    """
    from walkerlab.analysis.contact_bench import run_scene_benchmark
    from walkerlab.config import load_scene

    loaded = [load_scene(p) for p in scenes]  # every file checked before the first run
    return {"scenes": [run_scene_benchmark(sc) for sc in loaded]}


def run_bench(what: str, out: Path, scenes=None) -> list[str]:
    """Run the named benchmarks; return printable lines.

    Parameters
    ----------
    what : str
        A name of :data:`BENCHMARKS` or "all".
    out : Path
        Folder of the JSON results.
    scenes : sequence of Path, optional
        Contact benchmark only: scene files timed by
        :func:`walkerlab.analysis.contact_bench.run_scene_benchmark` instead of the paper
        walker's work-precision study.

    Raises
    ------
    ValueError
        Unknown benchmark name; scene files given for another benchmark than contact.
    """
    if scenes and what != "contact":
        raise ValueError(f"bench {what}: scene files apply to 'bench contact' only")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"bench --out {out}: is a file; --out names a folder (results go to "
                         f"<folder>/<benchmark>.json): give a folder or remove the file")
    lines = []
    todo = ["ideal", "fixedpoint", "sweep", "contact"] if what == "all" else [what]
    unknown = [n for n in todo if n not in BENCHMARKS]
    if unknown:
        raise ValueError(f"bench: unknown benchmark {unknown[0]!r} "
                         f"({' | '.join(BENCHMARKS)} | all)")
    out.mkdir(parents=True, exist_ok=True)
    for name in todo:
        if name == "ideal":
            res = bench_ideal()
        elif name == "fixedpoint":
            res = bench_fixedpoint()
        elif name == "sweep":
            res = bench_sweep()
        elif name == "basin":
            res = bench_basin()
        elif name == "contact":
            if scenes:
                res = bench_contact_scenes(scenes)
            else:
                from walkerlab.analysis.contact_bench import run_benchmark

                res = run_benchmark()
        else:
            raise ValueError(f"bench: unknown benchmark {name!r} "
                             f"({' | '.join(BENCHMARKS)} | all)")
        res = {"benchmark": name, **_machine(), "result": res}
        from walkerlab.io.artifacts import atomic_write

        text = json.dumps(res, indent=1, default=str).encode()
        atomic_write(out / f"{name}.json", lambda fh, text=text: fh.write(text))
        if name == "contact" and scenes:
            lines += [_scene_line(r) for r in res["result"]["scenes"]]
        lines.append(f"{name}: {json.dumps(res['result'], default=str)[:2000]}")
    return lines
