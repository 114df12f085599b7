"""``walkerlab bench powered``: a powered contact run's compute time against the passive run
of the same walker (issue goal: <= 1.5x).

Cases, each on the scene's compiled contact solver (``cyrk_bdf``) from the walker's rigid
gait (the passive scene's for the paper walker), warm (generated code compiled), median of
``repeats`` runs of CPU time in this process:

- the paper walker (Table 1) on its slope, 5 heel strikes: passive; a hip torque law (a
  spring-damper of zero gains: the actuation's whole machinery, no torque); a push-off of
  0.5 N s (a 0.1 ms pulse before each touchdown);
- RABBIT (configs/rabbit.yaml: five links, four PD laws on the phase variable, the virtual
  stance leg's angle), 4 heel strikes, against the same walker without actuators from the
  same start, timed per simulated second (a passive RABBIT falls: its run is as long as it
  lasts).

The solve_ivp run (LSODA at the scene's tolerances) is timed beside each powered case: what
a powered contact run cost before its compiled run.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from walkerlab.analysis.contact.sim import scene_start, simulate_contact
from walkerlab.config import Scene, load_scene
from walkerlab.models.contact.scene import contact_setup
from walkerlab.walker.plant import Plant

__all__ = ["bench_powered_contact", "lines"]

CONFIGS = Path(__file__).resolve().parents[2] / "configs"
HIP_LAW = {"torques": [{"joint": "hip", "law": {"stiffness_n_m_per_rad": 0.0,
                                                "damping_n_m_s_per_rad": 0.0}}]}
PUSH_OFF = {"push_off": {"impulse_n_s": 0.5}}


def _scene(name: str, actuation):

    d = load_scene(CONFIGS / name).model_dump(mode="json", exclude_none=True)
    d["walker"].pop("actuation", None)
    if actuation is not None:
        d["walker"]["actuation"] = actuation
    return Scene.model_validate(d)


def _timed(scene, x_ideal, steps_s: float, repeats: int, method: str | None = None):
    """Median CPU time [s] of the scene's contact run from ``x_ideal`` over ``steps_s``,
    its simulated time [s] and heel strikes."""

    setup = contact_setup(scene, plant=Plant.from_scene(scene))
    walker, x0, limits, _ = scene_start(setup, x_ideal, 3)
    solver = setup.solver.model_copy(update={"method": method or "cyrk_bdf"})
    simulate_contact(walker, x0, steps_s, solver, limits)  # warm: compiled
    times = []
    for _ in range(repeats):
        c0 = time.process_time()
        res = simulate_contact(walker, x0, steps_s, solver, limits)
        times.append(time.process_time() - c0)
    span = float(res.t[-1] - res.t[0])
    return float(np.median(times)), span, len(res.heel_strike_times)


def bench_powered_contact(repeats: int = 7) -> dict:
    """The powered/passive compute-time ratios (module docstring).

    Returns
    -------
    dict
        Per case: CPU time [s], simulated time [s], heel strikes, the ratio to the passive
        run (per simulated second for RABBIT) and the solve_ivp run's time and ratio.
    """
    from walkerlab.analysis.contact.periodic import ideal_gait  # light

    out = {"repeats": repeats, "target_ratio": 1.5, "cases": {}}
    paper = _scene("paper.yaml", None)
    gait = ideal_gait(paper, plant=Plant.from_scene(paper))
    span = 5.0 * gait.period_s
    base, _, _ = _timed(paper, gait.x, span, repeats)
    out["cases"]["paper passive"] = {"cpu_s": base}
    for label, act in (("paper hip law (zero gains)", HIP_LAW),
                       ("paper push-off 0.5 N s", PUSH_OFF)):
        sc = _scene("paper.yaml", act)
        t, s, n = _timed(sc, gait.x, span, repeats)
        t_ivp, _, _ = _timed(sc, gait.x, span, max(1, repeats // 3), "LSODA")
        out["cases"][label] = {"cpu_s": t, "heel_strikes": n, "ratio": t / base,
                               "solve_ivp_cpu_s": t_ivp, "solve_ivp_ratio": t_ivp / base}
    rabbit = _scene("rabbit.yaml", _rabbit_actuation())
    rgait = ideal_gait(rabbit, plant=Plant.from_scene(rabbit))
    rspan = 4.0 * rgait.period_s
    t, s, n = _timed(rabbit, rgait.x, rspan, repeats)
    tp, sp, _ = _timed(_scene("rabbit.yaml", None), rgait.x, rspan, repeats)
    t_ivp, s_ivp, _ = _timed(rabbit, rgait.x, rspan, max(1, repeats // 3), "LSODA")
    out["cases"]["rabbit phase law"] = {
        "cpu_s": t, "simulated_s": s, "heel_strikes": n, "passive_cpu_s": tp,
        "passive_simulated_s": sp, "ratio": (t / s) / (tp / sp),
        "solve_ivp_cpu_s": t_ivp, "solve_ivp_ratio": (t_ivp / s_ivp) / (tp / sp)}
    return out


def _rabbit_actuation():
    return load_scene(CONFIGS / "rabbit.yaml").walker.actuation.model_dump(
        mode="json", exclude_none=True)


def lines(res: dict) -> list[str]:
    """Printable lines of :func:`bench_powered_contact`'s result."""
    out = []
    for label, c in res["cases"].items():
        if "ratio" not in c:
            out.append(f"powered: {label}: {1e3 * c['cpu_s']:.1f} ms")
            continue
        out.append(f"powered: {label}: {1e3 * c['cpu_s']:.1f} ms, {c['ratio']:.2f}x the "
                   f"passive run (target <= {res['target_ratio']}x; solve_ivp "
                   f"{c['solve_ivp_ratio']:.1f}x)")
    return out
