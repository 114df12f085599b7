"""``walkerlab bench``: the benchmarks, run by name, results printed and stored as JSON.

Speed goals are checked here, never in tests.  This is a front end beside :mod:`walkerlab.cli`
and :mod:`walkerlab.api` (the sweep benchmark times the ``sweep`` stage as the command runs it);
the other benchmarks live in :mod:`walkerlab.bench.benchmarks`.

=============  ===============================================================  ==========
benchmark      what is timed                                                    target
=============  ===============================================================  ==========
``ideal``      5 strides (10 steps) of the paper walker from its fixed point,   <= 10 ms
               DOP853 rtol = atol = 1e-10, compute only (median); per backend
``fixedpoint`` ``walkerlab fixedpoint --force`` on the paper scene, whole       <= 1.0 s
               process (median of runs, model code cache warm); its CPU         <= 1.3 x
               over the bare scipy script's (walkerlab.bench.bare_fixedpoint),
               median of the pairs' ratios
``sweep``      fixed-point sweep over the slope (0.5-4.5 deg, 201 points), 2    >= 50 pt/s
               worker processes, pool start included (model code cache warm),
               to the finished artifact; the figure drawn after it timed apart
``sweep-``     ``walkerlab sweep`` of the paper walker, 8 and 32 points, 1      2 workers
``workers``    against 2 workers, whole process, alternating runs (medians)     <= 1
``basin``      ``walkerlab basin --grid 200x200 --force``, paper walker,        <= 120 s
               50 steps a cell at most, 2 workers, whole process
``fixedpoint-`` ``walkerlab fixedpoint --force`` of configs/hip_width.yaml (a     <= 5 s
``3d``         stride map, multipliers) and rimless_wheel_3d.yaml, whole
               process, warm, medians of 5
``contact``    the contact walker's work-precision benchmark
               (:func:`walkerlab.bench.contact.run_benchmark`); with scene
               files (``walkerlab bench contact configs/kneed.yaml ...``): each
               scene's walker, 5 contact strides at <= 1e-6 rad against a tight     kneed:
               reference, median time of the loosest tolerance band reaching it     <= 0.1 s
               (:func:`walkerlab.bench.contact.run_scene_benchmark`)
``main-job``   the paper's main job as a new user meets it: cold and warm       see
               ``contact-sim``, cold first ``report``, MFPT Monte Carlo CPU per  module
               heel strike against a minimal numba loop, mesh MFPT, robustness
               (:mod:`walkerlab.bench.main_job`; ``scripts/bench_main_job.py
               --vs DIR`` puts another code tree beside this one)
``optimize``   ``walkerlab optimize`` of every shipped optimisation scene,      compass,
               whole process, cold (fresh runs folder and code cache) and warm  Kuo <= 5 s,
               (``--force``), wall and CPU, medians of 3                        five-link
               (:mod:`walkerlab.bench.optimize`; ``scripts/bench_optimize.py``) <= 60 s;
               and the warm compass walker against the minimal CasADi script,   <= 2 x
               whole processes, 5 pairs in turn (``vs_script``)                 script
``powered``    a powered contact run (hip law, push-off, RABBIT's phase law) on <= 1.5x
               its compiled run against the passive run of the same walker,     passive
               CPU, medians (:mod:`walkerlab.bench.powered_contact`)
``powered-``   ``walkerlab contact-sim --force`` of the paper walker: passive,   <= 1.5x
``command``    zero-gain hip law, push-off 0.5 N s, whole process (periodic     passive
               gait included), CPU, rounds in turn, medians, warm cache
               (:mod:`walkerlab.bench.powered_command`)
``hzd``        the restricted Poincare map's delta^2 of RABBIT under virtual    <= 10 ms
               constraints (configs/rabbit_hzd.yaml), median; the whole zero
               dynamics and one full-order step beside it; the three-link       design:
               design against the minimal CasADi script from the same start:    <= 2 x
               build + solve, and ``walkerlab optimize`` as a whole process      script
               (:mod:`walkerlab.bench.hzd`; ``scripts/bench_hzd.py``)
``gym``        ``walkerlab/Walker-v0`` steps/s beside MuJoCo's ``Walker2d-v5``,  >= Walker2d
               threelink_hzd and rabbit_hzd, rigid and contact views, zero /
               random / scene-policy actions, the rigid view's compiled step
               and its Python yardstick (:mod:`walkerlab.bench.gym`)
``gym-vector`` one env against 8 in the native, sync and async vector forms,    native 8 >=
               zero and random actions (:mod:`walkerlab.bench.gym_vector`)       4x one env
=============  ===============================================================  ==========

The first ``walkerlab report`` of a fresh checkout is timed by ``scripts/bench_report.py``.
Results are printed and written as JSON to ``OUT/<what>.json`` with the machine and its load
noted (the machine may be shared: compare code trees side by side, in alternating runs).
"""
from __future__ import annotations

import importlib
import json
import tempfile
import time
from pathlib import Path

import numpy as np

from walkerlab.bench import benchmarks as B
from walkerlab.io.artifacts import atomic_write
from walkerlab.io.sweep_store import load_sweep

#: benchmark -> ``module:function`` that runs it with no arguments (imported when it runs:
#: CasADi, MuJoCo, Gymnasium, ...)
_RUNS = {"contact": "walkerlab.bench.contact:run_benchmark",
         "main-job": "walkerlab.bench.main_job:run_main_job",
         "optimize": "walkerlab.bench.optimize:bench_optimize",
         "powered": "walkerlab.bench.powered_contact:bench_powered_contact",
         "powered-command": "walkerlab.bench.powered_command:bench_powered_command",
         "hzd": "walkerlab.bench.hzd:bench_hzd", "gym": "walkerlab.bench.gym:bench_gym",
         "gym-vector": "walkerlab.bench.gym_vector:bench_vector"}
#: benchmarks whose module prints their result (its ``lines(result)``; the others: their JSON)
_LINES = tuple(n for n in _RUNS if n != "contact")

BENCHMARKS = ("ideal", "fixedpoint", "fixedpoint-3d", "sweep", "sweep-workers", "basin",
              "contact", "main-job", "optimize", "powered", "powered-command", "hzd", "gym",
              "gym-vector")


def bench_sweep(workers: int = 2, slopes: str = "0.5:4.5:0.02", cpu: bool = True) -> dict:
    """Fixed-point sweep over the slope with ``workers`` local processes (points/s).

    Timed from the call to the finished artifact (process pool start included), with the
    generated model code already in the runs folder's cache (as ``fixedpoint``'s benchmark:
    the one-off symbolic derivation of a fresh runs folder is not sweep throughput).  The
    figure ``walkerlab sweep`` draws after the artifact (a fixed cost, not throughput) is
    timed apart (``figure_wall_s``).  Also reported: Poincare maps per point (plain and
    variational, from the artifact) and, with ``cpu``, the CPU time per point of the same
    sweep run in this process (one worker).
    """
    from walkerlab.stages.sweep import draw, run  # light

    scene = B.paper_scene()
    param = [f"slope.angle_deg={slopes}"]
    with tempfile.TemporaryDirectory() as d:
        run(scene, ["slope.angle_deg=1"], "fixedpoint", workers=1, runs_root=d,
            name="warm", progress=False, figure=False)  # model code cache of this runs folder
        t0 = time.perf_counter()
        p = run(scene, param, "fixedpoint", workers=workers, runs_root=d, name="bench",
                progress=False, figure=False)
        wall = time.perf_counter() - t0
        t0 = time.perf_counter()
        draw(scene, p, d)
        figure_wall = time.perf_counter() - t0
        pts = load_sweep(p)["points"]
        cpu_pt = None
        if cpu:
            c0 = time.process_time()
            p1 = run(scene, param, "fixedpoint", workers=1, pool=False, runs_root=d,
                     name="bench_cpu", progress=False, figure=False)
            cpu_pt = (time.process_time() - c0) / load_sweep(p1)["points"]["index"].size
    outcomes = pts["outcome"].astype(str)
    n = int(outcomes.size)
    kinds, counts = np.unique(outcomes, return_counts=True)
    return {"points": n, "workers": workers, "wall_s": wall, "points_per_s": n / wall,
            "figure_wall_s": figure_wall,
            "maps_per_point": float(np.mean(pts["map_evaluations"])),
            "variational_maps_per_point": float(np.mean(pts["variational_maps"])),
            "point_wall_median_ms": 1e3 * float(np.median(pts["wall_time_s"])),
            "cpu_per_point_ms_in_process": None if cpu_pt is None else 1e3 * cpu_pt,
            "outcomes": {str(k): int(c) for k, c in zip(kinds, counts)},
            "note": "wall includes starting the process pool, not the figure drawn after "
                    "the artifact (figure_wall_s); model code cache warm",
            "target_points_per_s": 50}


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
        :func:`walkerlab.bench.contact.run_scene_benchmark` instead of the paper
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
        res = {"benchmark": name, **B.machine(), "result": _run_one(name, scenes)}
        text = json.dumps(res, indent=1, default=str).encode()
        atomic_write(out / f"{name}.json", lambda fh, text=text: fh.write(text))
        if name == "contact" and scenes:
            lines += [B.scene_line(r) for r in res["result"]["scenes"]]
        if name in _LINES:  # the benchmark's own printable lines
            module = _RUNS[name].partition(":")[0]
            lines += importlib.import_module(module).lines(res["result"])
            continue
        lines.append(f"{name}: {json.dumps(res['result'], default=str)[:2000]}")
    return lines


def _run_one(name: str, scenes) -> dict:
    if name == "contact" and scenes:
        return B.bench_contact_scenes(scenes)
    if name in _RUNS:
        module, _, function = _RUNS[name].partition(":")
        return getattr(importlib.import_module(module), function)()
    return {"ideal": B.bench_ideal, "fixedpoint": B.bench_fixedpoint,
            "fixedpoint-3d": B.bench_fixedpoint_3d, "sweep": bench_sweep,
            "basin": B.bench_basin, "sweep-workers": B.bench_sweep_workers}[name]()
