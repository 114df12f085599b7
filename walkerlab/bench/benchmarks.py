"""The benchmarks behind ``walkerlab bench`` that time the library or a whole command.

Each returns a JSON-able dict of timings (the table of benchmarks and targets is in
:mod:`walkerlab.cli.bench`); whole-command benchmarks run ``python -m walkerlab.cli`` as a
separate process.  Speed goals are checked here, never in tests.
"""

from __future__ import annotations

import gc
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from walkerlab.bench.contact import run_scene_benchmark
from walkerlab.bench.process_env import installed_env
from walkerlab.config import default_scene_path as default_scene
from walkerlab.config import load_scene
from walkerlab.config.loader import shipped_scene_path
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.schemas.continuation import initial_state
from walkerlab.walker.plant import Plant


def machine() -> dict:
    """The machine a benchmark ran on: architecture, processor, CPU count, Python version and
    the 1-minute load average (None where the platform has none)."""
    return {"machine": platform.machine(), "processor": platform.processor(),
            "cpus": os.cpu_count(), "python": platform.python_version(),
            "loadavg_1min": os.getloadavg()[0] if hasattr(os, "getloadavg") else None}


def paper_scene():
    """The default scene (``configs/paper.yaml``), loaded and validated.

    Raises
    ------
    SceneError
        The scene file is missing or does not validate (:func:`load_scene`).
    """

    return load_scene(default_scene())


def bench_ideal(repeats: int = 7) -> dict:
    """5 ideal strides at rtol 1e-10 per integrator backend, and the fixed-point search."""
    from walkerlab.analysis.gait.poincare import find_fixed_point  # light
    from walkerlab.models.registry import build_walker

    scene = paper_scene()
    t0 = time.perf_counter()
    w = build_walker(Plant.from_scene(scene))
    build_s = time.perf_counter() - t0
    guess = np.asarray(initial_state(scene.fixedpoint.initial_guess, w.state_names()))
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


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "walkerlab.cli", *args]


def _time_process(cmd: list[str], runs: int, cwd: Path | None = None) -> dict:
    walls = []
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True, cwd=cwd, env=installed_env())
        walls.append(time.perf_counter() - t0)
    return {"wall_median_s": float(np.median(walls)), "wall_min_s": float(np.min(walls)),
            "wall_max_s": float(np.max(walls)), "runs": runs}


def _cpu_process(cmd: list[str]) -> float:
    """CPU time [s] (user + system) of one finished process ``cmd``."""
    import resource

    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, capture_output=True, env=installed_env())
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime)


def bench_fixedpoint(runs: int = 5) -> dict:
    """``walkerlab fixedpoint --force`` on the paper scene, whole process: its wall time
    (target 1 s) and, against the bare numpy + scipy script that finds the same fixed point
    (:mod:`walkerlab.bench.bare_fixedpoint`), the median over ``runs`` pairs (alternating
    which goes first) of the ratio of their CPU times (issue goal: <= 1.3)."""
    bare = [sys.executable, str(Path(__file__).with_name("bare_fixedpoint.py"))]
    with tempfile.TemporaryDirectory() as d:
        cmd = _cli("fixedpoint", "--force", "--runs-dir", d)
        # warm the model code cache (and write walkerlab's bytecode: :mod:`.process_env`)
        subprocess.run(cmd, check=True, capture_output=True, env=installed_env())
        out = {**_time_process(cmd, runs), "command": " ".join(cmd[2:]), "target_s": 1.0}
        pairs = []
        for i in range(runs):
            order = (cmd, bare) if i % 2 == 0 else (bare, cmd)
            cpu = {id(c): _cpu_process(c) for c in order}
            pairs.append((cpu[id(cmd)], cpu[id(bare)]))
    out.update(cpu_median_s=float(np.median([p[0] for p in pairs])),
               bare_cpu_median_s=float(np.median([p[1] for p in pairs])),
               cpu_over_bare=float(np.median([p[0] / p[1] for p in pairs])),
               target_over_bare=1.3)
    return out


def bench_fixedpoint_3d(runs: int = 5) -> dict:
    """``walkerlab fixedpoint --force`` of the 3D walkers (the hip-width walker, its stride
    map with multipliers, and the 3D rimless wheel at Drake's defaults), whole process, warm
    (the generated code cached by a first run), medians of ``runs``; target 5 s each."""

    out: dict = {"target_s": 5.0, "scenes": {}}
    with tempfile.TemporaryDirectory() as d:
        for scene in ("hip_width", "rimless_wheel_3d"):
            cmd = _cli("fixedpoint", str(shipped_scene_path(scene)), "--force",
                       "--runs-dir", d)
            subprocess.run(cmd, check=True, capture_output=True,
                           env=installed_env())  # the model code cached
            out["scenes"][scene] = _time_process(cmd, runs)
    return out


def bench_sweep_workers(points=(8, 32), runs: int = 3) -> dict:
    """``walkerlab sweep`` of the paper scene over the slope with 1 and with 2 workers,
    whole process, for sweeps of ``points`` points (8 and 32: fixed-point points of a few ms,
    where a pool's start-up would cost more than the points); the runs alternate 1 and 2
    workers (a shared machine's load falls on both alike), medians of ``runs``.  Target: 2
    workers never slower than 1 (the sweep runs a small job in its own process,
    :func:`walkerlab.studies.runner.pool_pays`)."""
    out: dict = {"target": "2 workers <= 1 worker (ratio <= 1)", "sweeps": []}
    with tempfile.TemporaryDirectory() as d:
        subprocess.run(_cli("fixedpoint", "--runs-dir", d), check=True, capture_output=True,
                       env=installed_env())
        for n in points:
            hi = 2.5 + 0.01 * (n - 1)
            walls: dict[int, list[float]] = {1: [], 2: []}
            for k in range(runs):
                for w in (1, 2):
                    cmd = _cli("sweep", "--param", f"slope.angle_deg=2.5:{hi:.2f}:0.01",
                               "--workers", str(w), "--name", f"w{w}_{n}_{k}",
                               "--runs-dir", d)
                    walls[w].append(_time_process(cmd, 1)["wall_median_s"])
            m1, m2 = float(np.median(walls[1])), float(np.median(walls[2]))
            out["sweeps"].append({"points": n, "workers_1_wall_median_s": m1,
                                  "workers_2_wall_median_s": m2, "ratio_2_to_1": m2 / m1,
                                  "walls_s": {str(w): v for w, v in walls.items()}})
    return out


def bench_basin(grid: str = "200x200", workers: int = 2) -> dict:
    """``walkerlab basin --grid 200x200 --force`` on the paper scene, whole process.

    ``grid``: ``"<nx>x<ny>"`` cells; the result carries the wall time [s] against a
    ``target_s`` of 120 s and the cells per outcome.
    """
    with tempfile.TemporaryDirectory() as d:
        subprocess.run(_cli("fixedpoint", "--runs-dir", d), check=True, capture_output=True,
                       env=installed_env())
        cmd = _cli("basin", "--grid", grid, "--workers", str(workers), "--force",
                   "--runs-dir", d)
        res = _time_process(cmd, 1)
        from walkerlab.io.schemas.basin import load_basin

        b = load_basin(stage_artifact(paper_scene(), d, "basin"))
    out = b.outcome
    return {**res, "grid": grid, "workers": workers, "target_s": 120.0,
            "outcomes": {o: int(np.sum(out == i)) for i, o in enumerate(b.outcomes)}}


def scene_line(res: dict) -> str:
    """One line of a scene's result ``res`` in :func:`bench_contact_scenes`: per method the
    median wall time [s] that reached the target error [rad], or that it did not."""
    parts = []
    for method, t in res["target"].items():
        if t["reached"]:
            parts.append(f"{method} {t['median_wall_time_s']:.4f} s (rtol {t['rtols'][-1]:.2g}"
                         f"..{t['rtols'][0]:.2g}, worst error {t['worst_error_rad']:.2g} rad)")
        else:
            parts.append(f"{method} did not reach the target")
    ref = res["reference"]
    short = ("" if ref.get("complete", True) else
             f"; the reference stopped at t = {ref['end_time_s']:.4g} s of "
             f"{res['t_final_s']:.4g} s ({ref['termination']}: {ref['message']}): no method "
             "can be judged over the span")
    return (f"contact {res['scene']}: {res['n_strides']} strides at <= 1e-6 rad: "
            + "; ".join(parts) + f" [reference {ref['wall_time_s']:.3f} s]" + short)


def bench_contact_scenes(scenes) -> dict:
    """:func:`~walkerlab.bench.contact.run_scene_benchmark` for each scene file.

    Raises
    ------
    ConfigError
        A scene file is missing or invalid (one line, from :func:`load_scene`).
    """

    loaded = [load_scene(p) for p in scenes]  # every file checked before the first run
    return {"scenes": [run_scene_benchmark(sc) for sc in loaded]}
