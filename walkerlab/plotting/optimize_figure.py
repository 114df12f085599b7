"""The figure of ``optimize.h5``: the optimised hip torque and the leg angles over the step."""

from __future__ import annotations

from pathlib import Path

__all__ = ["save_optimize_figure"]


def save_optimize_figure(d, title: str, folder: Path) -> list[Path]:
    """Draw ``optimize.png`` / ``.svg`` from a loaded ``optimize.h5`` (``d``:
    :class:`walkerlab.io.schemas.optimize.OptimizeData`): left the hip torque [N m] at the
    collocation points, right every angle state [rad] over the step."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from walkerlab.plotting.figures import save

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10, 3.8))
    ax.plot(d.time, d.torque, "o-", ms=3, color="tab:red")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xlabel("time since heel strike [s]")
    ax.set_ylabel(f"hip torque [{d.torque_unit}] (+ on the swing leg)")
    work = d.terms.get("push_off_work", 0.0)
    ax.set_title(f"{d.objective_name} = {d.objective:.3g} {d.objective_unit}"
                 + (f"; push-off work {work:.3g} J" if work > 0 else ""), fontsize=10)
    for name, v in d.states.items():
        if d.state_units.get(name) == "rad":
            ax2.plot(d.time, v, label=name)
    ax2.set_xlabel("time since heel strike [s]")
    ax2.set_ylabel("angle [rad]")
    ax2.legend(fontsize=8, loc="best")
    speed = d.step_length_m / d.step_period_s
    ax2.set_title(f"step {d.step_period_s:.4g} s, {d.step_length_m:.4g} m, {speed:.3g} m/s; "
                  f"replay error {d.replay_error:.1g}", fontsize=9)
    fig.suptitle(f"{title}: optimised step (direct collocation)"
                 + ("" if d.gait else " — NOT a gait: the replay does not close"), fontsize=10)
    fig.tight_layout()
    return save(fig, Path(folder), "optimize")
