"""``walkerlab bench powered-command``: the whole ``contact-sim`` command of a powered walker
against the passive one (issue goal: <= 1.5x the passive command's CPU).

:mod:`walkerlab.bench.powered_contact` times the contact run alone, in this process; a user
runs the whole command, whose cost also holds what the run does not: the scene's set-up, the
rigid gait the run starts from, the contact model's own periodic gait and its Floquet
multipliers (``contact_sim.periodic_gait``: the step map evaluated some hundred times, on
compiled segments for a powered walker, :mod:`walkerlab.integrate.contact_powered_step`), the
artifact.  Here each case is ``walkerlab contact-sim SCENE --force`` as a separate process:

- ``paper passive``: ``configs/paper.yaml`` (the paper walker on its slope, its compiled
  contact solver, 5 strides, the periodic gait);
- ``paper hip law (zero gains)``: the same scene with a hip torque law of stiffness 0 and
  damping 0 (``walker.actuation.torques``: the actuation's whole machinery, no torque);
- ``paper push-off 0.5 N s``: the same scene with a push-off of 0.5 N s
  (``walker.actuation.push_off``, the contact model's default pulse).

The three scene files are written to a temporary folder (the ``published`` key left out of
all three alike), with a fresh private user cache and runs folder.  A first run of each
warms the cache (generated code, numba's machine code, the rigid fixed point) and is not
counted; then ``repeats`` rounds run the three in turn (a shared machine's load falls on all
alike).  Measured: each process's CPU (user + system of the process tree, its orphans
reaped and counted: :func:`walkerlab.bench.process_env.timed_run`) and wall time; per case the
median over the rounds and the median over the rounds of the ratio to the same round's
passive run.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import yaml

from walkerlab.bench.process_env import TREE, cli_command, code_env, timed_run
from walkerlab.io.stage_files import CONTACT_SIM

__all__ = ["CASES", "bench_powered_command", "lines"]

#: case -> the ``walker.actuation`` block put into configs/paper.yaml (None: passive)
CASES = {
    "paper passive": None,
    "paper hip law (zero gains)": {"torques": [{"joint": "hip", "law": {
        "stiffness_n_m_per_rad": 0.0, "damping_n_m_s_per_rad": 0.0}}]},
    "paper push-off 0.5 N s": {"push_off": {"impulse_n_s": 0.5}},
}
#: the goal: each powered command's CPU at most this many times the passive one's
TARGET_RATIO = 1.5


def _scene_files(folder: Path) -> dict[str, Path]:
    """The cases' scene files in ``folder``: configs/paper.yaml with each actuation."""
    base = yaml.safe_load((TREE / "configs" / "paper.yaml").read_text())
    base.pop("published", None)  # alike in all three: the stage does not read it
    out = {}
    for k, (label, act) in enumerate(CASES.items()):
        d = dict(base, walker=dict(base["walker"]))
        if act is not None:
            d["walker"]["actuation"] = act
        path = folder / f"paper_case{k}.yaml"
        path.write_text(yaml.safe_dump(d, sort_keys=False))
        out[label] = path
    return out


def bench_powered_command(repeats: int = 5, code: Path = TREE) -> dict:
    """The whole-command CPU of the cases (module docstring).

    Parameters
    ----------
    repeats : int
        Counted rounds (each runs the three cases in turn).
    code : Path
        The code tree whose ``walkerlab`` runs (``PYTHONPATH`` of the child processes).

    Returns
    -------
    dict
        ``cases``: per case the CPU [s] and wall [s] of every counted run, their medians,
        and (powered cases) the median over the rounds of the CPU ratio to the round's
        passive run; ``target_ratio``; ``repeats``.

    Raises
    ------
    RuntimeError
        A command failed (its exit code and the end of its error output).
    """
    with tempfile.TemporaryDirectory() as d:
        folder = Path(d)
        env = code_env(code, str(folder / "cache"))
        runs = str(folder / "runs")
        scenes = _scene_files(folder)
        cmds = {k: cli_command(CONTACT_SIM.name, str(p), "--force", "--runs-dir", runs)
                for k, p in scenes.items()}
        for cmd in cmds.values():  # warm: generated code, machine code, rigid gait
            timed_run(cmd, env, folder)
        got = {k: [] for k in cmds}
        for _ in range(repeats):
            for k, cmd in cmds.items():
                got[k].append(timed_run(cmd, env, folder)[:2])
    base = np.array([c for _, c in got["paper passive"]])
    out = {"repeats": repeats, "target_ratio": TARGET_RATIO, "cases": {}}
    for k, runs_k in got.items():
        wall = np.array([w for w, _ in runs_k])
        cpu = np.array([c for _, c in runs_k])
        case = {"cpu_s": cpu.tolist(), "wall_s": wall.tolist(),
                "cpu_median_s": float(np.median(cpu)), "wall_median_s": float(np.median(wall))}
        if k != "paper passive":
            case["cpu_ratio_median"] = float(np.median(cpu / base))
        out["cases"][k] = case
    return out


def lines(res: dict) -> list[str]:
    """Printable lines of :func:`bench_powered_command`'s result."""
    out = []
    for label, c in res["cases"].items():
        text = (f"powered-command: contact-sim {label}: CPU {c['cpu_median_s']:.2f} s, "
                f"wall {c['wall_median_s']:.2f} s (medians of {res['repeats']})")
        if "cpu_ratio_median" in c:
            text += (f", {c['cpu_ratio_median']:.2f}x the passive command's CPU (target <= "
                     f"{res['target_ratio']}x)")
        out.append(text)
    return out
