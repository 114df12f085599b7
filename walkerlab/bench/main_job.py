"""``walkerlab bench main-job``: the paper's main job, timed as a new user meets it.

Every measurement runs in a fresh Python process with ``PYTHONPATH`` set to the code tree
under test, so two trees (this one and, with ``vs``, e.g. a worktree of the previous main)
are measured side by side in one run, alternating which goes first; the ratios are taken
within the run (the machine may be shared).

=====================  ==============================================================  =======
measurement            what is timed                                                   goal
=====================  ==============================================================  =======
``contact_sim_cold``   ``walkerlab contact-sim SCENE --force``, whole process, in a      5 s
                       fresh private user cache (``WALKERLAB_CACHE_DIR`` an empty
                       folder: no generated code, no numba machine code, no drop
                       test) after ``walkerlab fixedpoint`` in that cache
``contact_sim_warm``   the same command again in that cache                              1 s
``contact_sim_warm_``  ... and once more: the steady state of repeated runs (an
``again``              upstream artifact changed less than 2 s before a check is
                       hashed again; from then on its hash is remembered in the user
                       cache, :mod:`walkerlab.io.artifacts`)
``warm_over_bare``     warm ``contact-sim --force`` against a bare numpy + scipy script   2.0 x
                       that finds the paper walker's fixed point
                       (:mod:`walkerlab.bench.bare_fixedpoint`), whole process against
                       whole process, ``pairs`` pairs alternating which goes first
                       (CPU of each; the median of the pairs' ratios)
``report_cold``        the first ``walkerlab report SCENE`` of a fresh runs folder and   90 s
                       a fresh user cache, whole process (the paper's report times its
                       work-precision study, ``workprecision.in_default_report``: about
                       a minute of repeats, which the 10 s of the report alone exclude)
``montecarlo``         CPU per heel strike of the MFPT Monte Carlo walks (one chunk    1.2 x
                       of ``walks`` walks of at most ``steps`` steps at ``sigma_mc``,
                       in process, :func:`walkerlab.studies.mfpt.run_walks`) against
                       the minimal numba loop over the same compass-gait flow at the
                       same accuracy and on the same slopes
                       (:mod:`walkerlab.bench.monte_carlo_yardstick`), interleaved; also
                       the median, min and max over the repeats of the two timed back
                       to back (``montecarlo_pair_ratio_*``)
``mesh``               wall time of the mesh MFPT at ``sigma_mesh`` (2 workers,         15 s
                       :func:`walkerlab.studies.mfpt.mesh`, the scene's mfpt settings)
                       and its CPU (``mesh_cpu_s``: the mesh alone, workers
                       included; ``mesh_process_cpu_s``: the whole process)
``robustness``         ``walkerlab robustness SCENE --force``, whole process (the
                       fixed point done before)
=====================  ==============================================================  =======

CPU times of a command are those of its whole process tree: the worker processes that end
after it (multiprocessing's forkserver, the report's side process, pool workers) are reaped
here and counted (:func:`walkerlab.bench.process_env.count_orphans`).
Medians over ``repeats`` (the mesh and the robustness study once per tree unless asked);
with a second tree also the median over the repeats of each repeat's ratio of the two trees
(``pair_ratios_this_over_vs``: the two runs of a pair are minutes apart at most, so a
change of the machine's load moves both).
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from walkerlab.bench.process_env import TREE, cli_command, code_env, timed_run
from walkerlab.io.stage_files import CONTACT_SIM

__all__ = ["run_main_job", "MC_CHILD", "MESH_CHILD"]

HERE = Path(__file__).resolve()
#: the plain-library yardstick of a warm contact run (no walkerlab import)
BARE = HERE.with_name("bare_fixedpoint.py")

#: Monte Carlo walks: the library's chunk of walks and the minimal numba loop, interleaved
MC_CHILD = r"""
import importlib.util, json, sys, time
import numpy as np
scene_path, sd, W, S, reps, base_file = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), \
    int(sys.argv[4]), int(sys.argv[5]), sys.argv[6]
from walkerlab.usercache import use_for_numba
use_for_numba()  # the yardstick's numba cache in the private user cache, not by its source
spec = importlib.util.spec_from_file_location("monte_carlo_yardstick", base_file)
mc = importlib.util.module_from_spec(spec); spec.loader.exec_module(mc)
from walkerlab.analysis.gait.scene import solve_scene
from walkerlab.analysis.robustness.mfpt import draw_slopes
from walkerlab.config import MfptSettings, load_scene
from walkerlab.walker.plant import Plant
from walkerlab.studies import mfpt as work
scene = load_scene(scene_path)
plant = Plant.from_scene(scene)
_, search = solve_scene(scene, fd_check=False, plant=plant)
x = np.asarray(search.gait.result.x, float)
st = scene.mfpt or MfptSettings()
base = scene.model_dump(mode="json")
task = work.WalkTask(base, tuple(map(float, x)), sd, tuple(range(W)), S, st.seed, "normal", 0,
                     plant=plant)
sm = work.step_map_for(base, plant=plant)
slopes = np.stack([draw_slopes(st.seed, w, S, sm.slope_rad, sd) for w in range(W)])
p = mc.params(scene.walker)
bs, bf = np.zeros(W, np.int64), np.zeros(W, bool)
def lib():
    return work.run_walks(task)[1:]
def minimal():
    mc.walks(x, slopes, p, st.rtol, st.atol, st.max_step_time_s, bs, bf)
    return bs, bf
lib(); minimal()  # compile / load, warm
t = {"library": [], "minimal": []}
for _ in range(reps):
    for name, fn in (("library", lib), ("minimal", minimal)):
        c = time.process_time(); s, f = fn(); t[name].append(time.process_time() - c)
        res = (s.copy(), f.copy()) if name == "library" else res
hs = int(res[0].sum() + res[1].sum())
out = {k: 1e6 * float(np.median(v)) / hs for k, v in t.items()}
print(json.dumps({"library_us_per_step": out["library"], "minimal_us_per_step": out["minimal"],
    "ratio": out["library"] / out["minimal"], "steps": hs, "falls": int(res[1].sum()),
    "mfpt_steps": float(res[0].sum() / max(res[1].sum(), 1)),
    "walks_differing_from_minimal": int(np.sum((res[0] != bs) | (res[1] != bf))),
    "pair_ratios": [a / b for a, b in zip(t["library"], t["minimal"])],
    "rtol": st.rtol, "atol": st.atol, "sigma_rad": sd, "walks": W, "max_steps": S}))
"""

#: the mesh MFPT at one sigma on 2 workers
MESH_CHILD = r"""
import json, sys, time
import numpy as np
from walkerlab.analysis.gait.scene import solve_scene
from walkerlab.config import MfptSettings, load_scene
from walkerlab.walker.plant import Plant
from walkerlab.studies import mfpt as work
scene = load_scene(sys.argv[1]); sd = float(sys.argv[2]); workers = int(sys.argv[3])
plant = Plant.from_scene(scene)
_, search = solve_scene(scene, fd_check=False, plant=plant)
x = np.asarray(search.gait.result.x, float)
import resource
def cpu():
    r = [resource.getrusage(k) for k in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
    return sum(u.ru_utime + u.ru_stime for u in r)
t, c = time.perf_counter(), cpu()
last, meshes = work.mesh(scene, x, sd, scene.mfpt or MfptSettings(), workers, plant=plant)
print(json.dumps({"wall_s": time.perf_counter() - t, "cpu_s": cpu() - c,
    "mfpt_steps": last.mfpt_steps,
    "cells": last.cells, "meshes": len(meshes), "converged": bool(last.converged),
    "change": last.change, "sigma_rad": sd, "workers": workers}))
"""


def contact_sim(code: Path, scene: str) -> dict:
    """Cold, warm and warm again ``contact-sim --force`` in a fresh user cache:
    ``{cold: (wall, cpu), warm: (wall, cpu), warm_again: (wall, cpu)}`` [s]."""
    with tempfile.TemporaryDirectory() as d:
        env = code_env(code, str(Path(d) / "cache"))
        runs = str(Path(d) / "runs")
        timed_run(cli_command("fixedpoint", scene, "--runs-dir", runs), env, code)
        cmd = cli_command(CONTACT_SIM.name, scene, "--force", "--runs-dir", runs)
        cold = timed_run(cmd, env, code)[:2]
        warm = timed_run(cmd, env, code)[:2]
        again = timed_run(cmd, env, code)[:2]
    return {"cold": cold, "warm": warm, "warm_again": again}


def warm_vs_bare(code: Path, scene: str, pairs: int = 5) -> dict:
    """Warm ``contact-sim --force`` and the bare scipy script (:data:`BARE`), ``pairs``
    times alternating, in one fresh user cache (fixed point and a first contact run done
    before): ``{"warm": [(wall, cpu), ...], "bare": [(wall, cpu), ...]}`` [s]."""
    with tempfile.TemporaryDirectory() as d:
        env = code_env(code, str(Path(d) / "cache"))
        runs = str(Path(d) / "runs")
        timed_run(cli_command("fixedpoint", scene, "--runs-dir", runs), env, code)
        warm = cli_command(CONTACT_SIM.name, scene, "--force", "--runs-dir", runs)
        timed_run(warm, env, code)
        timed_run(warm, env, code)  # the steady state (see contact_sim_warm_again)
        out: dict = {"warm": [], "bare": []}
        for i in range(pairs):
            for k in (("warm", "bare") if i % 2 == 0 else ("bare", "warm")):
                cmd = warm if k == "warm" else [sys.executable, str(BARE)]
                out[k].append(timed_run(cmd, env, code)[:2])
    return out


def report_cold(code: Path, scene: str) -> tuple[float, float]:
    """The first ``walkerlab report`` of a fresh runs folder and user cache: (wall, cpu)."""
    with tempfile.TemporaryDirectory() as d:
        env = code_env(code, str(Path(d) / "cache"))
        cmd = cli_command("report", scene, "--runs-dir", str(Path(d) / "runs"))
        return timed_run(cmd, env, code)[:2]


def robustness(code: Path, scene: str, runs: str) -> tuple[float, float]:
    """``walkerlab robustness --force`` with the fixed point done: (wall, cpu) [s]."""
    env = code_env(code)
    timed_run(cli_command("fixedpoint", scene, "--runs-dir", runs), env, code)
    return timed_run(cli_command("robustness", scene, "--force", "--runs-dir", runs), env, code)[:2]


def child(code: Path, src: str, *args) -> dict:
    """Run ``src`` (:data:`MC_CHILD` or :data:`MESH_CHILD`) in a fresh process; its JSON,
    with ``process_cpu_s``: the CPU [s] of the whole process tree (its workers included)."""
    _, cpu, out = timed_run([sys.executable, "-c", src, *map(str, args)], code_env(code), code)
    return {**json.loads(out.strip().splitlines()[-1]), "process_cpu_s": cpu}


def _median(rows: list, key: int) -> float:
    return float(np.median([r[key] for r in rows]))


def _one_tree(code: Path, scene: str, cfg: dict, runs: str) -> dict:
    """Every measurement of one repeat on one code tree."""
    out = {}
    if "contact_sim" in cfg["parts"]:
        out["contact_sim"] = contact_sim(code, scene)
    if "bare" in cfg["parts"]:
        out["bare"] = warm_vs_bare(code, scene)
    if "report" in cfg["parts"]:
        out["report_cold"] = report_cold(code, scene)
    return out


def run_main_job(scene: str = "configs/paper.yaml", code: Path | None = None,
                 vs: Path | None = None, repeats: int = 3, sigma_mc: float = 0.002,
                 walks: int = 500, steps: int = 100, sigma_mesh: float = 0.004,
                 mesh_repeats: int = 1, parts: tuple = ("contact_sim", "bare", "report",
                                                        "montecarlo", "mesh",
                                                        "robustness")) -> dict:
    """Run the main-job benchmark (module docstring) on ``code`` (default this tree) and,
    with ``vs``, on a second tree side by side.

    Parameters
    ----------
    scene : str
        Scene file, relative to each code tree (its own ``configs/``).
    code, vs : Path, optional
        Code trees (the folder holding ``walkerlab/``).
    repeats, mesh_repeats : int
        Repeats of the process and Monte Carlo measurements; of the mesh and robustness.
    sigma_mc, sigma_mesh : float
        Slope standard deviations [rad] of the Monte Carlo walks and of the mesh.
    walks, steps : int
        Monte Carlo walks and their step cap.
    parts : tuple of str
        Which measurements (``contact_sim``, ``bare`` (warm_over_bare), ``report``,
        ``montecarlo``, ``mesh``, ``robustness``).

    Returns
    -------
    dict
        ``{"trees": {label: {measurement: {...medians...}}}, "ratios": {...}}``; times in
        seconds, Monte Carlo in microseconds of CPU per heel strike.
    """
    trees = {"this": Path(code or TREE).resolve()}
    if vs is not None:
        trees["vs"] = Path(vs).resolve()
    cfg = {"parts": set(parts)}
    raw = {k: [] for k in trees}
    mc = {k: [] for k in trees}
    slow = {k: {"mesh": [], "robustness": []} for k in trees}
    with tempfile.TemporaryDirectory() as d:
        for r in range(repeats):
            order = list(trees) if r % 2 == 0 else list(trees)[::-1]
            for k in order:
                raw[k].append(_one_tree(trees[k], scene, cfg, str(Path(d) / k)))
        if "montecarlo" in cfg["parts"]:
            for r in range(max(1, repeats // 3)):
                for k in (list(trees) if r % 2 == 0 else list(trees)[::-1]):
                    mc[k].append(child(trees[k], MC_CHILD, scene, sigma_mc, walks, steps,
                                       max(3, repeats), HERE.with_name("monte_carlo_yardstick.py")))
        for r in range(mesh_repeats):
            for k in (list(trees) if r % 2 == 0 else list(trees)[::-1]):
                if "mesh" in cfg["parts"]:
                    slow[k]["mesh"].append(child(trees[k], MESH_CHILD, scene, sigma_mesh, 2))
                if "robustness" in cfg["parts"]:
                    slow[k]["robustness"].append(robustness(trees[k], scene,
                                                            str(Path(d) / f"rob_{k}")))
    res = {k: _summary(raw[k], mc[k], slow[k]) for k in trees}
    out = {"scene": scene, "trees": {k: str(v) for k, v in trees.items()}, "results": res}
    if vs is not None:
        out["ratios_this_over_vs"] = {m: res["this"][m] / res["vs"][m]
                                      for m in res["this"] if isinstance(res["this"][m], float)
                                      and res["vs"].get(m)}
        out["pair_ratios_this_over_vs"] = _pair_ratios(raw)
    return out


def _pair_ratios(raw: dict) -> dict:
    """Median over the repeats of (this tree / vs tree) of each process measurement."""
    per = {k: [_summary([r], [], {"mesh": [], "robustness": []}) for r in raw[k]]
           for k in raw}
    if not per["this"]:
        return {}
    return {m: float(np.median([a[m] / b[m] for a, b in zip(per["this"], per["vs"])]))
            for m in per["this"][0] if all(b.get(m) for b in per["vs"])}


def _summary(raw: list, mc: list, slow: dict) -> dict:
    out: dict = {}
    if raw and "contact_sim" in raw[0]:
        cs = [r["contact_sim"] for r in raw]
        out["contact_sim_cold_wall_s"] = float(np.median([c["cold"][0] for c in cs]))
        out["contact_sim_cold_cpu_s"] = float(np.median([c["cold"][1] for c in cs]))
        out["contact_sim_warm_wall_s"] = float(np.median([c["warm"][0] for c in cs]))
        out["contact_sim_warm_cpu_s"] = float(np.median([c["warm"][1] for c in cs]))
        if "warm_again" in cs[0]:
            out["contact_sim_warm_again_wall_s"] = _median([c["warm_again"] for c in cs], 0)
            out["contact_sim_warm_again_cpu_s"] = _median([c["warm_again"] for c in cs], 1)
    if raw and "bare" in raw[0]:
        warm = [c for r in raw for c in r["bare"]["warm"]]
        bare = [c for r in raw for c in r["bare"]["bare"]]
        out["bare_fixedpoint_wall_s"] = _median(bare, 0)
        out["bare_fixedpoint_cpu_s"] = _median(bare, 1)
        out["warm_paired_cpu_s"] = _median(warm, 1)
        out["warm_over_bare_cpu"] = float(np.median([w[1] / b[1]
                                                     for w, b in zip(warm, bare)]))
        out["warm_over_bare_wall"] = float(np.median([w[0] / b[0]
                                                      for w, b in zip(warm, bare)]))
    if raw and "report_cold" in raw[0]:
        out["report_cold_wall_s"] = _median([r["report_cold"] for r in raw], 0)
        out["report_cold_cpu_s"] = _median([r["report_cold"] for r in raw], 1)
    if mc:
        for key in ("library_us_per_step", "minimal_us_per_step", "ratio"):
            out[f"montecarlo_{key}"] = float(np.median([m[key] for m in mc]))
        pairs = [r for m in mc for r in m.get("pair_ratios", [])]
        if pairs:  # each repeat's library / minimal, the two timed back to back
            out["montecarlo_pair_ratio_median"] = float(np.median(pairs))
            out["montecarlo_pair_ratio_min"] = float(np.min(pairs))
            out["montecarlo_pair_ratio_max"] = float(np.max(pairs))
        out["montecarlo_detail"] = mc[-1]
    if slow["mesh"]:
        out["mesh_wall_s"] = float(np.median([m["wall_s"] for m in slow["mesh"]]))
        out["mesh_cpu_s"] = float(np.median([m["cpu_s"] for m in slow["mesh"]]))
        out["mesh_process_cpu_s"] = float(np.median([m["process_cpu_s"]
                                                     for m in slow["mesh"]]))
        out["mesh_detail"] = slow["mesh"][-1]
    if slow["robustness"]:
        out["robustness_wall_s"] = _median(slow["robustness"], 0)
        out["robustness_cpu_s"] = _median(slow["robustness"], 1)
    return out


def lines(res: dict) -> list[str]:
    """Printable table of :func:`run_main_job`'s result."""
    keys = [k for k, v in res["results"]["this"].items() if isinstance(v, float)]
    trees = list(res["results"])
    head = f"{'measurement':34s}" + "".join(f"{t:>12s}" for t in trees)
    if "ratios_this_over_vs" in res:
        head += f"{'this/vs':>10s}{'pairs':>10s}"
    rows = [head]
    for k in keys:
        row = f"{k:34s}" + "".join(f"{res['results'][t].get(k, float('nan')):12.3f}"
                                   for t in trees)
        if "ratios_this_over_vs" in res and k in res["ratios_this_over_vs"]:
            row += f"{res['ratios_this_over_vs'][k]:10.2f}"
        if k in res.get("pair_ratios_this_over_vs", {}):
            row += f"{res['pair_ratios_this_over_vs'][k]:10.2f}"
        rows.append(row)
    return rows
