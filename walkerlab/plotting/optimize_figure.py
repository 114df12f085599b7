"""The figure of ``optimize.h5``: the optimised torques and the link angles over the step
(and, for a walker whose stick figure is given, the step as stop-action frames); below, the
energies over the step and IPOPT's convergence, where the artifact holds them; for designed
virtual-constraint controllers, a row with every controller's outputs against the phase
(the Bezier polynomials, Westervelt, Grizzle & Koditschek 2003, Eq. 36) and what each
controller gives."""

from __future__ import annotations

from pathlib import Path

__all__ = ["save_optimize_figure"]


def save_optimize_figure(d, title: str, folder: Path, sticks: list | None = None,
                         svg: bool = True, key: str | None = None) -> list[Path]:
    """Draw ``optimize.png`` / ``.svg`` (``svg`` False: the PNG alone; ``key`` stored in the
    PNG, :func:`walkerlab.plotting.figures.save`) from a loaded
    ``optimize.h5`` (``d``: :class:`walkerlab.io.schemas.optimize.OptimizeData`): left every
    torque [N m] at the collocation points (by name), middle every angle state [rad] over
    the step, and with ``sticks`` (a list of (m, 2) polylines [m], e.g. stance foot - knee -
    hip - torso / hip - swing knee - swing foot at a few instants) a third panel with them
    drawn over each other (stop action). A second row, where the artifact has them: the
    kinetic, potential and total mechanical energy's change since the heel strike [J] (the
    total changes by the actuators' work), and IPOPT's primal and dual infeasibility per
    iteration (log scale)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from walkerlab.plotting.figures import save  # light

    rows = 2 if (d.energy or d.ipopt_history) else 1
    ctrl_row = rows if d.controllers else None  # the designed controllers' row
    rows += d.controllers is not None and len(d.controllers) > 0
    cols = 3 if sticks else 2
    fig, grid = plt.subplots(rows, cols, figsize=(5 * cols, 3.8 * rows), squeeze=False)
    axes = grid[0]
    ax, ax2 = axes[0], axes[1]
    _torque_panel(ax, d)
    for name, v in d.states.items():
        if d.state_units.get(name) == "rad":
            ax2.plot(d.time, v, label=name)
    ax2.set_xlabel("time since heel strike [s]")
    ax2.set_ylabel("angle [rad]")
    ax2.legend(fontsize=8, loc="best")
    speed = d.step_length_m / d.step_period_s
    ax2.set_title(f"step {d.step_period_s:.4g} s, {d.step_length_m:.4g} m, {speed:.3g} m/s; "
                  f"replay error {d.replay_error:.1g}", fontsize=9)
    if sticks:
        ax3 = axes[2]
        for k, line in enumerate(sticks):
            line = np.asarray(line, float)
            ax3.plot(line[:, 0], line[:, 1], "-o", ms=2, lw=1.2,
                     color=plt.cm.viridis(k / max(len(sticks) - 1, 1)))
        ax3.axhline(0.0, color="0.4", lw=1)
        ax3.set_aspect("equal")
        ax3.set_xlabel("x [m] (stance foot at 0)")
        ax3.set_ylabel("y [m]")
        ax3.set_title("the step, stop action (early: dark, late: yellow)", fontsize=9)
    if (rows == 2 and ctrl_row is None) or rows == 3:
        _energy_and_convergence(d, grid[1])
    if ctrl_row is not None:
        _controllers(d, grid[ctrl_row])
        n = len(d.controllers)
        ax.set_title(ax.get_title() + f"\ncontroller 1 of {n} "
                     f"({d.controllers[0].target_speed_m_per_s:g} m/s; all {n}: bottom row)",
                     fontsize=9)
    steps = int(getattr(d, "steps", 1))
    if steps > 1:  # a stride of legs that differ: its inner heel strikes marked
        per = len(d.phase_names) // steps
        for k in range(1, steps):
            for a in (*axes[:2], *(grid[1][:1] if rows >= 2 and ctrl_row != 1 else ())):
                a.axvline(d.time[d.phase_start[k * per]], color="0.3", ls=":", lw=1)
        ax2.set_title(f"stride of {steps} steps (dotted: heel strike)\nmean step "
                      f"{d.step_period_s:.4g} s, {d.step_length_m:.4g} m, {speed:.3g} m/s; "
                      f"replay error {d.replay_error:.1g}", fontsize=9)
    fig.suptitle(f"{title}: optimised {'stride' if steps > 1 else 'step'} (direct collocation)"
                 + ("" if d.gait else " — NOT a gait: the replay does not close"), fontsize=10)
    fig.tight_layout()
    return save(fig, Path(folder), "optimize", svg, key)


def _torque_panel(ax, d) -> None:
    """First panel: every torque [``d.torque_unit``] at the collocation points (by name)
    over the step, titled with the objective (and the push-off's work)."""
    tq = d.torque.reshape(len(d.time), -1)
    for k, name in enumerate(d.torque_names):
        ax.plot(d.time, tq[:, k], "o-", ms=2, label=name,
                color="tab:red" if len(d.torque_names) == 1 else None)
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xlabel("time since heel strike [s]")
    if d.torque_names == ("hip",):
        ax.set_ylabel(f"hip torque [{d.torque_unit}] (+ on the swing leg)")
    else:
        ax.set_ylabel(f"joint torque [{d.torque_unit}] (+ on the joint's second link)")
        ax.legend(fontsize=8, loc="best")
    work = d.terms.get("push_off_work", 0.0)
    cot = (f" (CoT {float(d.terms['cost_of_transport']):.3g} + effort term)"
           if d.objective_name == "cost_of_transport" and "cost_of_transport" in d.terms
           else "")
    ax.set_title(f"{d.objective_name} = {d.objective:.3g} {d.objective_unit}{cot}"
                 + (f"; push-off work {work:.3g} J" if work > 0 else ""), fontsize=10)


def _energy_and_convergence(d, axes) -> None:
    """Second row: energies over the step, IPOPT's infeasibilities per iteration."""
    import numpy as np

    ax = axes[0]
    if not d.energy:
        ax.axis("off")  # no energies in the artifact: no empty panel
    if d.energy:
        ke, pe = d.energy["kinetic"], d.energy["potential"]
        for v, name in ((ke, "kinetic"), (pe, "potential"), (ke + pe, "total")):
            ax.plot(d.time, v - v[0], label=name, lw=2 if name == "total" else 1)
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_xlabel("time since heel strike [s]")
        ax.set_ylabel(f"energy change since heel strike [{d.energy_unit}]")
        inner = " and the collisions inside it" if len(d.phase_names) > 1 else ""
        ax.set_title(f"total changes by {(ke + pe)[-1] - (ke + pe)[0]:.3g} {d.energy_unit} "
                     f"over the {'stride' if getattr(d, 'steps', 1) > 1 else 'step'} "
                     f"(the actuators' net work{inner})", fontsize=9)
        ax.legend(fontsize=8, loc="best")
    ax = axes[1]
    h = d.ipopt_history
    if not (h and len(h.get("objective", ()))):
        ax.axis("off")  # no convergence history: no empty panel
    else:
        it = np.arange(len(h["objective"]))
        for key in ("primal_infeasibility", "dual_infeasibility"):
            ax.semilogy(it, np.maximum(h[key], 1e-20), label=key.replace("_", " "))
        ax.set_xlabel("IPOPT iteration")
        ax.set_ylabel("infeasibility")
        ax.set_title(f"IPOPT: {d.status}, {d.iterations} iterations", fontsize=9)
        ax.legend(fontsize=8, loc="best")
    for extra in axes[2:]:
        extra.axis("off")


def _controllers(d, axes) -> None:
    """The designed controllers' row: left, every controller's outputs ``hd(s)`` [rad]
    against the phase ``s`` in [0, 1] (colour per controller, line style per output);
    right, what each controller gives (target speed, step, largest torque, largest
    multiplier, IPOPT's status)."""
    import matplotlib.pyplot as plt
    import numpy as np

    from walkerlab.models.virtual_constraints import bezier  # light

    ax = axes[0]
    s = np.linspace(0.0, 1.0, 101)
    styles = ("-", "--", ":", "-.")
    for i, c in enumerate(d.controllers):
        alpha = np.atleast_2d(np.asarray(c.bezier_rad, float))
        hd = np.array([bezier(alpha, v)[0] for v in s])
        color = plt.cm.viridis(i / max(len(d.controllers) - 1, 1))
        for k, name in enumerate(c.output_names):
            ax.plot(s, hd[:, k], ls=styles[k % 4], color=color,
                    label=f"{name}, controller {i + 1}")
            ax.plot(np.linspace(0, 1, alpha.shape[1]), alpha[k], "o", ms=3, color=color)
    ax.set_xlabel("phase s (0: after heel strike, 1: at the next)")
    ax.set_ylabel("output hd(s) [rad] (dots: Bezier coefficients)")
    ax.set_title(f"outputs against the phase, all {len(d.controllers)} controllers",
                 fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    ax = axes[1]
    ax.axis("off")
    lines = ["controller  speed [m/s]  step [s, m]  max |u| [N m]  max |multiplier|  IPOPT"]
    for i, c in enumerate(d.controllers):
        mult = np.max(np.abs(c.multipliers)) if np.size(c.multipliers) else float("nan")
        lines.append(f"{i + 1:>10d}  {c.target_speed_m_per_s:>11.3g}  "
                     f"{c.step_period_s:.4g}, {c.step_length_m:.4g}  "
                     f"{c.max_torque_n_m:>13.3g}  {mult:>16.3g}  {c.status}")
    ax.text(0.0, 0.95, "\n".join(lines), family="monospace", fontsize=7, va="top",
            transform=ax.transAxes)
    ax.set_title("what each controller gives", fontsize=9)
    for extra in axes[2:]:
        extra.axis("off")
