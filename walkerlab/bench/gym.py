"""Benchmark ``gym``: environment steps per second of ``walkerlab/Walker-v0`` beside MuJoCo's
``Walker2d-v5`` in the same process and run (issue goal: every walkerlab case at least
Walker2d's rate under the same kind of action).

Cases: the scenes ``configs/threelink_hzd.yaml`` (the three-link walker, 10 ms control
period) and ``configs/rabbit_hzd.yaml`` (RABBIT, the five-link biped), each in the rigid
and the contact view, each under

- ``zero``: zero action (the walker as written, without its feedback controller: it falls
  and is reset, the resets timed with the steps, as Walker2d's passive collapse is);
- ``random``: uniform random actions over the action space (``numpy`` generator, seed 0);
- ``scene``: ``policy="scene"`` (the scene's virtual-constraint controller sampled at each
  period's start and held) with a zero action: the walker walks.

Walker2d-v5 runs ``zero`` and ``random`` (it has no scene policy).  Each case: the
environment built and reset (seed 0) and ``warmup`` steps taken before the clock starts (the
walker's gait search, code generation and numba's cache load are set-up, not throughput);
then ``steps`` calls of ``step``, reset on an episode's end; wall time
(:func:`time.perf_counter`), the clock started after a full garbage collection (the cases
timed before leave theirs; a case's own garbage is collected inside its clock).  The cases
run in turn, ``repeats`` rounds (a shared machine's load falls on all alike); per case the
median rate and the median over the rounds of Walker2d's rate (same kind of action;
``scene`` against ``zero``) divided by it.

The rigid view runs its compiled control step (:class:`walkerlab.gym.rigid_view.RigidView`:
the flow with the action's torques compiled by numba, CyRK's DOP853 in C++); ``compiled:
false`` rows time the scene's own solver (``solve_ivp`` with a Python right-hand side) for
the same cases, the yardstick of that step.

Needs gymnasium and, for Walker2d, ``gymnasium[mujoco]`` (MuJoCo and imageio; without them
the Walker2d rows say so and the ratios are left out).
"""

from __future__ import annotations

import gc
import statistics
import time
from pathlib import Path

import numpy as np

__all__ = ["SCENES", "bench_gym", "lines"]

#: the walkerlab scenes timed
SCENES = ("configs/threelink_hzd.yaml", "configs/rabbit_hzd.yaml")
#: the kinds of action (``scene`` is compared with Walker2d's ``zero``)
ACTIONS = ("zero", "random", "scene")

_ROOT = Path(__file__).resolve().parents[2]


def _rate(env, action: str, steps: int, warmup: int) -> float:
    """Steps per second of ``env`` under ``action`` (module docstring)."""
    rng = np.random.default_rng(0)
    space = env.action_space
    zero = np.zeros(space.shape, space.dtype)

    def act():
        if action == "random":
            return rng.uniform(space.low, space.high).astype(space.dtype)
        return zero

    env.reset(seed=0)
    for _ in range(warmup):
        _, _, term, trunc, _ = env.step(act())
        if term or trunc:
            env.reset()
    env.reset(seed=0)
    gc.collect()  # the garbage of the environments timed before: not inside this clock
    t0 = time.perf_counter()
    for _ in range(steps):
        _, _, term, trunc, _ = env.step(act())
        if term or trunc:
            env.reset()
    return steps / (time.perf_counter() - t0)


def _walker2d():
    """``gym.make("Walker2d-v5")``, or the reason it cannot be built here (a string)."""
    import gymnasium as gym

    try:
        return gym.make("Walker2d-v5")
    except Exception as exc:  # noqa: BLE001 - the bench reports what is missing
        return f"Walker2d-v5 not available ({type(exc).__name__}: {exc}); " \
               f"pip install 'gymnasium[mujoco]'"


def bench_gym(scenes=SCENES, views=("rigid", "contact"), steps: int = 1000,
              warmup: int = 50, repeats: int = 3, python_steps: int = 200) -> dict:
    """Run the benchmark (module docstring).

    Parameters
    ----------
    scenes : sequence of str
        Scene files (relative paths are the repository's when not found here).
    views : sequence of {"rigid", "contact"}
    steps, warmup : int
        Timed and untimed ``step`` calls per case and round.
    repeats : int
        Rounds.
    python_steps : int
        Timed steps of the rigid view's ``compiled: false`` rows (the slow yardstick; 0:
        left out).

    Returns
    -------
    dict
        ``cases``: one row per case (``scene``, ``view``, ``action``, ``compiled``,
        ``steps_per_s`` median, ``rates`` per round, ``walker2d_over_walkerlab`` median
        ratio or None); ``walker2d``: Walker2d-v5's rows (``action``, ``steps_per_s``,
        ``rates``) or ``walker2d_missing`` (why not).
    """
    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0
    from walkerlab.gym import WalkerEnv  # light

    envs, rows = {}, []
    for sc in scenes:
        path = str(_ROOT / sc) if not Path(sc).exists() and (_ROOT / sc).exists() else sc
        for view in views:
            for action in ACTIONS:
                env = WalkerEnv(path, view=view, policy="scene" if action == "scene" else None)
                envs[(sc, view, action, True)] = env
                if view == "rigid" and python_steps:
                    envs[(sc, view, action, False)] = WalkerEnv(
                        path, view=view, policy="scene" if action == "scene" else None,
                        compiled_step=False)  # the scene's solver, Python flows
    w2d = _walker2d()
    rates: dict = {k: [] for k in envs}
    wrates = {"zero": [], "random": []}
    for _ in range(repeats):
        if not isinstance(w2d, str):
            for action in wrates:
                wrates[action].append(_rate(w2d, action, steps, warmup))
        for key, env in envs.items():
            n = steps if key[3] else python_steps
            rates[key].append(_rate(env, key[2], n, min(warmup, n)))
    for (sc, view, action, compiled), r in rates.items():
        ref = wrates["random" if action == "random" else "zero"]
        ratio = (statistics.median(w / x for w, x in zip(ref, r)) if ref else None)
        rows.append({"scene": sc, "view": view, "action": action,
                     "compiled": compiled if view == "rigid" else None,
                     "steps_per_s": statistics.median(r), "rates": r,
                     "walker2d_over_walkerlab": ratio})
    out = {"steps": steps, "warmup": warmup, "repeats": repeats, "cases": rows}
    if isinstance(w2d, str):
        out["walker2d_missing"] = w2d
    else:
        out["walker2d"] = [{"action": a, "steps_per_s": statistics.median(r), "rates": r}
                           for a, r in wrates.items()]
        w2d.close()
    for env in envs.values():
        env.close()
    return out


def lines(result: dict) -> list[str]:
    """Printable lines of :func:`bench_gym`'s result."""
    out = [f"gym: steps per second, medians of {result['repeats']} rounds of "
           f"{result['steps']} steps (Walker2d-v5 / walkerlab: > 1 means walkerlab is "
           f"slower)"]
    if "walker2d_missing" in result:
        out.append(f"  {result['walker2d_missing']}")
    for w in result.get("walker2d", []):
        out.append(f"  Walker2d-v5          {w['action']:6s} {w['steps_per_s']:8.0f}/s")
    for r in result["cases"]:
        step = {True: "compiled", False: "python", None: ""}[r["compiled"]]
        ratio = (f"  Walker2d/walkerlab {r['walker2d_over_walkerlab']:.2f}x"
                 if r["walker2d_over_walkerlab"] is not None else "")
        out.append(f"  {Path(r['scene']).stem:12s} {r['view']:7s} {r['action']:6s} "
                   f"{r['steps_per_s']:8.0f}/s {step:8s}{ratio}")
    return out
