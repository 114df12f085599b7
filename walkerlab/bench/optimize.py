"""Benchmark of ``walkerlab optimize`` on the shipped optimisation scenes: the whole command
as a new process, cold and warm, wall and CPU, medians.

The goals (the optimal-gaits issue): the compass walker <= 5 s, Kuo's walker <= 5 s, the
five-link biped <= 60 s on 2 cores (IPOPT with MUMPS; the collocation's expressions built once
per walker and cached like the generated flows).  Each scene is timed

- **cold**: a fresh runs folder and a fresh code cache (``WALKERLAB_CACHE_DIR``): the
  generated model code, the upstream ``fixedpoint`` stage (straight legs), the symbolic
  collocation expressions (the five-link's cached CasADi functions), the optimisation, the
  rigid and contact replays and the figure;
- **warm**: the same folders again with ``--force`` (the optimisation and everything after
  it recomputed; the generated code, the cached expressions and the upstream gait reused),

each ``repeats`` times, the medians reported with their spread.  Also read: the stage's own
compute time (the CLI's ``compute`` line: the optimisation and its replays, no start-up),
IPOPT's solve wall time and iterations (``optimize.h5``), and the CPU time (user + sys of the
finished process, the operating system's accounting: it suffers less than wall time from a
shared machine).  Speed goals are checked here, never in tests.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from walkerlab.bench.process_env import installed_env

__all__ = ["GOALS_S", "SCENES", "TARGET_OVER_SCRIPT", "bench_optimize", "bench_vs_script",
           "lines"]

#: the shipped optimisation scenes and their goals [s] (the optimal-gaits issue)
GOALS_S = {"compass_optimal": 5.0, "kuo2002": 5.0, "rabbit_optimal": 60.0}
SCENES = tuple(GOALS_S)
_CONFIGS = Path(__file__).resolve().parents[2] / "configs"
#: the issue's goal for warm ``walkerlab optimize configs/compass_optimal.yaml --force``
#: against the minimal CasADi script (:mod:`walkerlab.bench.minimal_casadi`), whole process
TARGET_OVER_SCRIPT = 2.0


def _run(scene_path: Path, folder: Path, force: bool, tree: Path | None = None) -> dict:
    """One ``walkerlab optimize`` process with ``folder`` as its runs folder and code
    cache (``tree``: another code tree's ``walkerlab`` first on the child's path): wall
    [s], CPU (user + sys of the finished child, the children's rusage) [s], the stage's
    ``compute`` seconds from its output (None when not printed), the exit code, and IPOPT's
    wall time, iterations and status and the gait flag from ``optimize.h5``."""
    import resource

    # the child starts in ``folder`` (``-m`` puts the current folder first on the path)
    # with the tree's walkerlab first on PYTHONPATH (this tree's when ``tree`` is None)
    env = installed_env(WALKERLAB_CACHE_DIR=str(folder / "cache"),
                        PYTHONPATH=os.pathsep.join([str(tree or _CONFIGS.parent),
                                                    os.environ.get("PYTHONPATH", "")]))
    cmd = [sys.executable, "-m", "walkerlab.cli", "optimize", str(scene_path),
           "--runs-dir", str(folder / "runs")] + (["--force"] if force else [])
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=folder, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    text = proc.stdout.decode(errors="replace")
    m = re.search(r"optimize\.h5 \(compute ([0-9.]+) s", text)
    res = {"wall_s": wall, "cpu_s": (after.ru_utime - before.ru_utime)
           + (after.ru_stime - before.ru_stime),
           "compute_s": float(m.group(1)) if m else None, "returncode": proc.returncode,
           "tail": text.strip().splitlines()[-3:]}
    art = folder / "runs" / scene_path.stem / "optimize.h5"
    if proc.returncode == 0 and art.exists():  # not an earlier run's artifact
        from walkerlab.io.schemas.optimize import load  # light

        d = load(art)
        res.update(ipopt_wall_s=float(d.wall_time_s), ipopt_iterations=int(d.iterations),
                   ipopt_status=str(d.status), gait=bool(d.gait))
    return res


def _median(runs: list[dict], key: str):
    vals = [r[key] for r in runs if r.get(key) is not None]
    if not vals:
        return None
    return {"median": float(np.median(vals)), "min": float(min(vals)),
            "max": float(max(vals))}


def bench_scene(name: str, repeats: int = 3, vs: Path | None = None) -> dict:
    """Cold and warm ``walkerlab optimize`` of ``configs/<name>.yaml``, ``repeats`` each
    (module docstring); cold then warm in one fresh folder, repeated.  With ``vs`` (another
    code tree) each repeat runs this tree and that one in turn, and the ratios this / vs
    are taken pair by pair (medians), so the machine's drift hits both alike."""
    path = _CONFIGS / f"{name}.yaml"
    runs = {"this": {"cold": [], "warm": []}, "vs": {"cold": [], "warm": []}}
    for _ in range(repeats):
        for which, tree in (("this", None), ("vs", vs)) if vs is not None else (("this",
                                                                                 None),):
            with tempfile.TemporaryDirectory(prefix="wl_bench_opt_") as d:
                runs[which]["cold"].append(_run(path, Path(d), False, tree))
                runs[which]["warm"].append(_run(path, Path(d), True, tree))
    keys = ("wall_s", "cpu_s", "compute_s", "ipopt_wall_s", "ipopt_iterations")
    this = runs["this"]
    out = {"scene": name, "goal_s": GOALS_S.get(name), "repeats": repeats,
           "cold": {k: _median(this["cold"], k) for k in keys},
           "warm": {k: _median(this["warm"], k) for k in keys},
           "status": sorted({r.get("ipopt_status", f"exit {r['returncode']}")
                             for r in this["cold"] + this["warm"]}),
           "gait": all(r.get("gait", False) for r in this["cold"] + this["warm"])}
    if vs is not None:
        out["vs"] = {"tree": str(vs), **{m: {k: _median(runs["vs"][m], k) for k in keys}
                                         for m in ("cold", "warm")}}
        out["ratio_this_over_vs"] = {m: {k: _paired(this[m], runs["vs"][m], k)
                                         for k in ("wall_s", "cpu_s")}
                                     for m in ("cold", "warm")}
    bad = [r for r in this["cold"] + this["warm"] if r["returncode"] != 0]
    if bad:
        out["failure"] = f"exit {bad[0]['returncode']}: {bad[0]['tail']}"
    return out


def _paired(a: list[dict], b: list[dict], key: str):
    """The ratios ``a[i][key] / b[i][key]`` run by run: median, min, max."""
    return _median([{key: x[key] / y[key]} for x, y in zip(a, b)
                    if x.get(key) and y.get(key)], key)


def process_times(cmd: list[str], env: dict | None = None, cwd=None) -> tuple[float, float]:
    """(wall, CPU) [s] of the finished process ``cmd`` (CPU: user + sys, the children's
    rusage); its output thrown away.

    Raises
    ------
    RuntimeError
        The process exited non-zero (its output's last lines).
    """
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, check=False)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd[:4]))}: exit {proc.returncode}: "
                           f"{proc.stderr.decode(errors='replace')[-500:]}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def paired(this: list[tuple[float, float]], script: list[tuple[float, float]]) -> dict:
    """Medians [min, max] of ``this`` and ``script`` ((wall, CPU) pairs [s], run in turn)
    and of their ratios pair by pair (the machine's drift hits both of a pair alike)."""
    def stats(v):
        return {"median": float(np.median(v)), "min": float(min(v)), "max": float(max(v))}

    return {"wall_s": stats([a[0] for a in this]), "cpu_s": stats([a[1] for a in this]),
            "script_wall_s": stats([b[0] for b in script]),
            "script_cpu_s": stats([b[1] for b in script]),
            "wall_ratio": stats([a[0] / b[0] for a, b in zip(this, script)]),
            "cpu_ratio": stats([a[1] / b[1] for a, b in zip(this, script)])}


def _cell(d: dict | None) -> str:
    """A median and its spread, ``median [min, max]`` (``-`` for None)."""
    return "-" if d is None else f"{d['median']:.2f} [{d['min']:.2f}, {d['max']:.2f}]"


def paired_text(p: dict) -> str:
    """:func:`paired`'s numbers as text, with the verdict of the wall ratio's median
    against the goal.

    Parameters
    ----------
    p : dict
        :func:`in_turn`'s result (medians [min, max] [s] and ratios) and ``target_ratio``,
        the goal on the wall ratio's median.

    Returns
    -------
    str
        ``wall A s against B s, ratio R (target <= T: met); cpu A s against B s, ratio R``
        (``NOT MET`` past the goal).
    """
    ok = "met" if p["wall_ratio"]["median"] <= p["target_ratio"] else "NOT MET"
    return (f"wall {_cell(p['wall_s'])} s against {_cell(p['script_wall_s'])} s, ratio "
            f"{_cell(p['wall_ratio'])} (target <= {p['target_ratio']:g}: {ok}); cpu "
            f"{_cell(p['cpu_s'])} s against {_cell(p['script_cpu_s'])} s, ratio "
            f"{_cell(p['cpu_ratio'])}")


def in_turn(cmd: list[str], env: dict, cwd, script: list[str], pairs: int) -> dict:
    """``pairs`` pairs of the command ``cmd`` (in ``env``, ``cwd``) and the yardstick
    ``script`` (from ``/``), which runs first alternating pair by pair: :func:`paired`'s
    medians and ratios."""
    this, theirs = [], []
    for i in range(pairs):
        for which in ("this", "script") if i % 2 == 0 else ("script", "this"):
            if which == "this":
                this.append(process_times(cmd, env, cwd))
            else:
                theirs.append(process_times(script, installed_env(), cwd="/"))
    return paired(this, theirs)


def bench_vs_script(pairs: int = 5) -> dict:
    """Warm ``walkerlab optimize configs/compass_optimal.yaml --force`` (the optimisation,
    its rigid and contact replays, the artifact and the figure; the generated code and the
    upstream gait cached by a first run) against the minimal CasADi + IPOPT script of the
    same collocation (:mod:`walkerlab.bench.minimal_casadi`), whole process against whole
    process, ``pairs`` pairs alternating which runs first: wall and CPU medians and the
    medians of the pairs' ratios (goal :data:`TARGET_OVER_SCRIPT`)."""
    script = [sys.executable, str(Path(__file__).with_name("minimal_casadi.py"))]
    with tempfile.TemporaryDirectory(prefix="wl_bench_opt_") as d:
        env = installed_env(WALKERLAB_CACHE_DIR=str(Path(d) / "cache"),
                            PYTHONPATH=os.pathsep.join([str(_CONFIGS.parent),
                                                        os.environ.get("PYTHONPATH", "")]))
        cmd = [sys.executable, "-m", "walkerlab.cli", "optimize",
               str(_CONFIGS / "compass_optimal.yaml"), "--runs-dir", str(Path(d) / "runs")]
        process_times(cmd, env, d)  # cold: the generated code, the fixed point
        cmd.append("--force")
        process_times(cmd, env, d)  # the steady state of repeated runs
        times = in_turn(cmd, env, d, script, pairs)
    return {"scene": "compass_optimal", "pairs": pairs, **times,
            "target_ratio": TARGET_OVER_SCRIPT}


def bench_optimize(scenes=SCENES, repeats: int = 3, vs: Path | None = None,
                   script: bool = True) -> dict:
    """:func:`bench_scene` of every scene (against the code tree ``vs`` if given) and, with
    ``script``, :func:`bench_vs_script`; the load average before and after."""
    load0 = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    res = [bench_scene(s, repeats, vs) for s in scenes]
    yard = bench_vs_script() if script else None
    load1 = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    return {"scenes": res, "vs_script": yard,
            "loadavg_1min_before": load0, "loadavg_1min_after": load1,
            "note": "whole process (python -m walkerlab.cli optimize); cold: fresh runs "
                    "folder and code cache; warm: the same with --force; cpu: user + sys "
                    "of the process; compute: the stage's own; medians [min, max]"}


def lines(result: dict) -> list[str]:
    """The benchmark as a table, one line a scene and mode."""
    out = ["optimize: scene | mode | wall s | cpu s | compute s | ipopt s | iterations | goal s"]
    for s in result["scenes"]:
        for mode in ("cold", "warm"):
            m = s[mode]
            out.append(f"  {s['scene']} | {mode} | {_cell(m['wall_s'])} | {_cell(m['cpu_s'])} | "
                       f"{_cell(m['compute_s'])} | {_cell(m['ipopt_wall_s'])} | "
                       f"{_cell(m['ipopt_iterations'])} | {s['goal_s']}")
        out.append(f"  {s['scene']}: IPOPT {', '.join(s['status'])}; a gait: {s['gait']}"
                   + (f"; FAILED: {s['failure']}" if "failure" in s else ""))
        for mode, r in s.get("ratio_this_over_vs", {}).items():
            v = s["vs"][mode]
            out.append(f"  {s['scene']} | {mode} | vs {s['vs']['tree']}: wall "
                       f"{_cell(v['wall_s'])}, cpu {_cell(v['cpu_s'])}; this / vs paired: "
                       f"wall {_cell(r['wall_s'])}, cpu {_cell(r['cpu_s'])}")
    y = result.get("vs_script")
    if y:
        out.append(f"  {y['scene']} | warm | vs the minimal CasADi script (whole process, "
                   f"{y['pairs']} pairs in turn): {paired_text(y)}")
    return out
