"""Benchmark ``hzd``: the hybrid zero dynamics of RABBIT under virtual constraints
(``configs/rabbit_hzd.yaml``): the restricted Poincare map's multiplier ``delta^2`` alone
(target <= 10 ms), the whole zero dynamics (V, V_max, zeta*, the step period by quadrature)
and, for scale, one full-order step map of the closed loop (Westervelt, Grizzle &
Koditschek 2003, IEEE TAC 48(1):42-56, Sec. V).  Medians of ``repeats`` runs, wall time
(:func:`time.perf_counter`).

And the design of the three-link walker's virtual constraints (``optimize.design:
virtual_constraints``, configs/threelink_hzd.yaml's controller as the start, 0.8 m/s,
``delta^2 <= 0.6``, 20 intervals) against the minimal CasADi script of the same formulation
(:mod:`walkerlab.bench.minimal_casadi_hzd`, run as a process from the same start): the
programme's build plus IPOPT's solve on each side (target: walkerlab <= 2x the script), and
the whole ``walkerlab optimize`` computation (the start, the build, the solve, the written
controller's zero dynamics and full-order fixed point; not the artifact's writing).
The design as a whole process, too (:func:`bench_design_process`): warm ``walkerlab
optimize`` against the minimal script as a process, given the same start and the same
problem (the command's friction cone), pairs in turn (target: <= 2x the script).
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from walkerlab.analysis.gait.zero_dynamics import impact_multiplier, zero_dynamics
from walkerlab.bench.optimize import paired_text
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.walker.plant import Plant

__all__ = ["bench_design", "bench_design_process", "bench_hzd", "lines"]

#: the issue's target for delta^2 [s]
TARGET_S = 0.010
#: the issue's target for the design: walkerlab's time over the minimal script's
TARGET_RATIO = 2.0
#: the three-link design (tests/test_optimize_virtual_constraints.py's)
DESIGN = {"design": "virtual_constraints", "max_multiplier": 0.6, "target_speed_m_per_s": 0.8,
          "intervals": 20, "max_torque_n_m": 150.0, "friction_coefficient": 0.8}


def bench_hzd(scene_path: Path | str | None = None, repeats: int = 50,
              design: bool = True) -> dict:
    """Timings of the zero dynamics of ``scene_path`` (default: the shipped RABBIT under
    virtual constraints) and, with ``design``, of the three-link design
    (:func:`bench_design`, under ``design``).

    Returns
    -------
    dict
        ``delta2`` [-], ``delta2_s``, ``delta2_min_s``, ``zero_dynamics_s``,
        ``build_s`` (the walker with its controller), ``step_map_s`` (one full-order step
        on the scene's solver), ``step_map_compiled_s`` (the same step on the compiled
        closed loop, DOP853 at the scene's tolerances) [s], ``target_s``, ``step_period_s``
        (by quadrature) [s].
    """
    from walkerlab.analysis.gait.poincare import poincare_map  # light
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    path = scene_path or Path(__file__).resolve().parents[2] / "configs" / "rabbit_hzd.yaml"
    scene = load_scene(path)
    t = time.perf_counter()
    walker = build_walker(Plant.from_scene(scene))
    build = time.perf_counter() - t
    ctrl = walker.actuators.controller
    d2_times, zd_times = [], []
    for _ in range(repeats):
        t = time.perf_counter()
        d2 = impact_multiplier(ctrl)
        d2_times.append(time.perf_counter() - t)
        t = time.perf_counter()
        zd = zero_dynamics(ctrl)
        zd_times.append(time.perf_counter() - t)
    t = time.perf_counter()
    poincare_map(walker, zd.x_plus, Solver.from_settings(scene.solver))
    step = time.perf_counter() - t
    # the same step on the compiled closed loop (DOP853 at the scene's tolerances on CyRK:
    # walkerlab.codegen.virtual_constraint_flow), its cfuncs loaded by a first run
    compiled = replace(Solver.from_settings(scene.solver), method="DOP853",
                       backend="cyrk_compiled")
    poincare_map(walker, zd.x_plus, compiled)
    t = time.perf_counter()
    poincare_map(walker, zd.x_plus, compiled)
    step_compiled = time.perf_counter() - t
    out = {"scene": scene.name, "repeats": repeats, "delta2": d2,
           "delta2_s": float(np.median(d2_times)), "delta2_min_s": float(np.min(d2_times)),
           "zero_dynamics_s": float(np.median(zd_times)), "build_s": build,
           "step_map_s": step, "step_map_compiled_s": step_compiled, "target_s": TARGET_S,
           "step_period_s": zd.step_period_s}
    if design:
        out["design"] = bench_design()
        out["design_process"] = bench_design_process()
    return out


def bench_design_process(pairs: int = 3) -> dict:
    """The three-link design as a whole process: warm ``walkerlab optimize DESIGN.yaml
    --force`` (configs/threelink_hzd.yaml with :data:`DESIGN` as its ``optimize``
    section: the start, the collocation, the written controller's closed loop, its
    contact replay, the artifact and the figure; the generated code cached by a first
    run) against the minimal CasADi script (:mod:`walkerlab.bench.minimal_casadi_hzd`)
    given the same start and the problem the command solves (its friction cone:
    :func:`walkerlab.optimal.virtual_constraints.design_spec`), ``pairs`` pairs
    alternating which runs first: wall and CPU medians, the pairs' ratios (target
    :data:`TARGET_RATIO`), and both optima (the same one: the comparison is of the same
    answer).
    """
    import os
    import subprocess
    import sys
    import tempfile

    import yaml

    from walkerlab.bench.optimize import in_turn, process_times
    from walkerlab.bench.process_env import installed_env
    from walkerlab.integrate.solver import Solver
    from walkerlab.io.schemas.optimize import load  # light
    from walkerlab.models.registry import build_walker
    from walkerlab.optimal.driver import collocation_spec  # light
    from walkerlab.optimal.virtual_constraints import controller_step, design_spec  # light

    root = Path(__file__).resolve().parents[2]
    script = [sys.executable, str(root / "walkerlab" / "bench" / "minimal_casadi_hzd.py")]
    with tempfile.TemporaryDirectory(prefix="wl_bench_hzd_") as d:
        cfg = yaml.safe_load((root / "configs" / "threelink_hzd.yaml").read_text())
        cfg.update(name="threelink_design", optimize=dict(DESIGN))
        path = Path(d) / "threelink_design.yaml"
        path.write_text(yaml.safe_dump(cfg))
        scene = load_scene(path)
        vc = scene.walker.actuation.virtual_constraints
        spec = design_spec(scene, collocation_spec(scene))
        t, x, u, alpha, _zd = controller_step(build_walker(Plant.from_scene(scene)),
                                              Solver.from_settings(scene.solver),
                                              2 * DESIGN["intervals"] + 1)
        npz = Path(d) / "start.npz"
        _write_start(npz, (t, x, u, alpha), vc, spec.max_torque_n_m, spec.friction_coefficient)
        script.append(str(npz))
        env = installed_env(PYTHONPATH=os.pathsep.join([str(root),
                                                        os.environ.get("PYTHONPATH", "")]))
        cmd = [sys.executable, "-m", "walkerlab.cli", "optimize", str(path), "--runs-dir",
               str(Path(d) / "runs")]
        process_times(cmd, env, d)  # the generated code and the upstream stages cached
        cmd.append("--force")
        times = in_turn(cmd, env, d, script, pairs)
        words = subprocess.run(script, capture_output=True, text=True, check=True,
                               cwd="/").stdout.split()
        ours = load(Path(d) / "runs" / "threelink_design" / "optimize.h5")
    return {"pairs": pairs, **times, "target_ratio": TARGET_RATIO,
            "walkerlab": {"status": str(ours.status), "iterations": int(ours.iterations),
                          "objective": float(ours.objective),
                          "period_s": float(ours.step_period_s)},
            "script": {"status": words[0],
                       "iterations": int(words[words.index("iterations") + 1]),
                       "objective": float(words[words.index("objective") + 1]),
                       "period_s": float(words[words.index("period") + 1])}}


def bench_design(repeats: int = 3) -> dict:
    """Timings of the three-link walker's design (module docstring): medians of
    ``repeats`` runs of walkerlab's collocation (:func:`walkerlab.optimal.transcription.
    virtual_constraints.hzd_functions` and :func:`~walkerlab.optimal.transcription.
    virtual_constraints.collocate_virtual_constraints`) and of the minimal script, from the
    same start; one run of the whole stage.

    Returns
    -------
    dict
        ``walkerlab_s`` (the median of the runs after the first: each reads the CasADi
        functions from the disk cache, as a new process does), ``walkerlab_cold_s`` (the
        first: on an empty cache it derives them with sympy),
        ``script_s`` (build + solve) [s], ``ratio``, ``target_ratio``,
        ``stage_s`` [s], the two optima (``objective`` [N^2 m s], ``delta2``, ``period_s``),
        IPOPT's status and iterations on each side.
    """
    import yaml

    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker
    from walkerlab.optimal.driver import optimize_scene  # light
    from walkerlab.optimal.virtual_constraints import controller_step  # light

    root = Path(__file__).resolve().parents[2]
    cfg = yaml.safe_load((root / "configs" / "threelink_hzd.yaml").read_text())
    cfg.update(name="threelink_design", optimize=dict(DESIGN))
    scene = scene_from_dict(cfg)
    vc = scene.walker.actuation.virtual_constraints
    plant = Plant.from_scene(scene)  # the bench's scene, described once
    K = 2 * DESIGN["intervals"] + 1
    start = controller_step(build_walker(plant), Solver.from_settings(scene.solver),
                            K)[:4]
    ours, res = _time_collocation(scene, plant.data, start, repeats)
    theirs, words = _time_script(root / "walkerlab" / "bench" / "minimal_casadi_hzd.py",
                                 start, vc, repeats)
    t0 = time.perf_counter()
    optimize_scene(scene, None, None, plant=plant)  # the stage's computation (not its file writing)
    stage = time.perf_counter() - t0

    def word(key):
        return float(words[words.index(key) + 1])
    warm = ours[1:] or ours  # the first run may derive the model (sympy, an empty cache)
    ratio = float(np.median(warm) / np.median(theirs))
    return {"walkerlab_s": float(np.median(warm)), "walkerlab_cold_s": ours[0],
            "script_s": float(np.median(theirs)),
            "ratio": ratio, "target_ratio": TARGET_RATIO, "stage_s": stage,
            "repeats": repeats, "walkerlab": {
                "status": res.status, "iterations": res.iterations,
                "objective": res.objective, "delta2": res.delta2,
                "period_s": res.step_period_s},
            "script": {"status": words[0], "iterations": int(word("iterations")),
                       "objective": word("objective"), "delta2": word("delta2"),
                       "period_s": word("period")}}


def _write_start(npz: Path, start: tuple, vc, u_max: float, mu: float) -> None:
    """The minimal script's input: the start ``(t, x, u, alpha)`` (the scene's controller's
    step), :data:`DESIGN`'s numbers, the controller's feedback gains ``vc.feedback``, the
    torque bound ``u_max`` [N m] and the friction coefficient ``mu`` [-], as ``npz``."""
    t, x, u, alpha = start
    np.savez(npz, t=t, x=x, u=u, alpha=alpha, N=DESIGN["intervals"],
             speed=DESIGN["target_speed_m_per_s"], max_multiplier=DESIGN["max_multiplier"],
             kp=vc.feedback.kp_per_s2, kd=vc.feedback.kd_per_s, u_max=u_max, mu=mu)


def _time_collocation(scene, data, start: tuple, repeats: int
                      ) -> tuple[list[float], object]:
    """Wall times [s] of ``repeats`` runs of walkerlab's build and solve of the design of
    the walker ``data`` (its plant's description) from ``start`` ``(t, x, u, alpha)`` (each
    reading its CasADi functions from the disk cache, as a new process does), and the last
    run's result."""
    from walkerlab.codegen.casadi_functions import clear_memo
    from walkerlab.optimal.driver import collocation_spec  # light
    from walkerlab.optimal.transcription.virtual_constraints import (
        collocate_virtual_constraints,
        hzd_functions,
    )

    vc = scene.walker.actuation.virtual_constraints
    spec = collocation_spec(scene)
    t, x, u, alpha = start
    ours, res = [], None
    for _ in range(repeats):
        clear_memo()  # each run reads its functions as a new process would (disk cache)
        t0 = time.perf_counter()
        fns = hzd_functions(data, vc)
        res = collocate_virtual_constraints(
            fns, spec, t, x, u, alpha, DESIGN["max_multiplier"],
            (vc.feedback.kp_per_s2, vc.feedback.kd_per_s))
        ours.append(time.perf_counter() - t0)
    return ours, res


def _time_script(script: Path, start: tuple, vc, repeats: int) -> tuple[list[float], list[str]]:
    """Build-plus-solve times [s] of ``repeats`` runs of the minimal CasADi ``script`` from
    ``start`` (as processes), and the words the last run printed.

    Raises
    ------
    RuntimeError
        If the script fails.
    """
    import subprocess
    import sys
    import tempfile

    theirs, words = [], []
    with tempfile.TemporaryDirectory() as d:
        npz = Path(d) / "start.npz"
        _write_start(npz, start, vc, DESIGN["max_torque_n_m"], DESIGN["friction_coefficient"])
        for _ in range(repeats):
            run = subprocess.run([sys.executable, str(script), str(npz)], capture_output=True,
                                 text=True, timeout=600, cwd="/")
            if run.returncode != 0:
                raise RuntimeError(f"bench hzd: the minimal script failed: {run.stderr[-500:]}")
            words = run.stdout.split()
            theirs.append(float(words[words.index("build_s") + 1])
                          + float(words[words.index("solve_s") + 1]))
    return theirs, words


def lines(res: dict) -> list[str]:
    """Printable lines of :func:`bench_hzd`'s result."""
    ok = "met" if res["delta2_s"] <= res["target_s"] else "NOT MET"
    return [f"hzd: {res['scene']}: delta^2 = {res['delta2']:.10f} in "
            f"{1e3 * res['delta2_s']:.3f} ms (median of {res['repeats']}; target <= "
            f"{1e3 * res['target_s']:.0f} ms: {ok})",
            f"hzd: zero dynamics (V, V_max, zeta*, period {res['step_period_s']:.10f} s) "
            f"{1e3 * res['zero_dynamics_s']:.1f} ms; controller build {res['build_s']:.2f} s; "
            f"one full-order step map {res['step_map_s']:.3f} s (the scene's solver; "
            f"on the compiled closed loop, DOP853: {res['step_map_compiled_s']:.3f} s)"
            ] + _design_lines(res)


def _design_lines(res: dict) -> list[str]:
    d = res.get("design")
    if not d:
        return []
    return _build_solve_lines(d) + _process_lines(res.get("design_process"))


def _process_lines(p: dict | None) -> list[str]:
    if not p:
        return []
    return [f"hzd: three-link design as a whole process (walkerlab optimize --force, warm) "
            f"against the minimal script from the same start, {p['pairs']} pairs in turn: "
            f"{paired_text(p)}",
            f"hzd: whole process: {_optima(p['walkerlab'], p['script'])}"]


def _optima(w: dict, s: dict) -> str:
    """Both sides' optima as text: IPOPT's status and iterations, the objective [N^2 m s],
    ``delta^2`` (where measured) and the step period [s] of walkerlab's (``w``) and the
    script's (``s``)."""
    def side(o):
        d2 = f", delta^2 {o['delta2']:.10g}" if "delta2" in o else ""
        return (f"{o['status']} in {o['iterations']} iterations, objective "
                f"{o['objective']:.10g} N^2 m s{d2}, period {o['period_s']:.10g} s")

    return f"optima: walkerlab {side(w)}; script {side(s)}"


def _build_solve_lines(d: dict) -> list[str]:
    ok = "met" if d["ratio"] <= d["target_ratio"] else "NOT MET"
    return [f"hzd: three-link design (0.8 m/s, delta^2 <= 0.6): walkerlab "
            f"{d['walkerlab_s']:.2f} s, minimal CasADi script {d['script_s']:.2f} s (build + "
            f"solve, medians of {d['repeats']}; walkerlab's after its first, from the disk "
            f"cache): "
            f"{d['ratio']:.2f}x (target <= "
            f"{d['target_ratio']:.0f}x: {ok}); the first run (sympy on an empty cache) "
            f"{d['walkerlab_cold_s']:.2f} s; the whole optimize computation {d['stage_s']:.1f} s",
            f"hzd: {_optima(d['walkerlab'], d['script'])}"]
