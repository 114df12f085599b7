"""A scene's figure groups, drawn from loaded artifacts and saved as PNG + SVG.

``trajectories``: stick diagrams (Figs. 2, 6), angles and rates (Fig. 7), errors (Fig. 8),
limit cycles (Fig. 9), energy (Fig. 10) and the drop test's restitution;
``workprecision``: one work-precision diagram per model.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from functools import partial
from pathlib import Path

from walkerlab.io.schemas.workprecision import pareto
from walkerlab.io.trajectory import NamedTrajectory
from walkerlab.plotting import CONTACT_LABEL, IDEAL_LABEL
from walkerlab.plotting import figures as F
from walkerlab.plotting.figure_3d import top_and_front
from walkerlab.units import Units, for_scene

#: stems of the trajectory figures drawn from the rigid run (``simulate.h5``) alone: the same
#: figure whether or not the scene also has a contact run
IDEAL_ONLY = ("energy_ledger", "fig2_stick_ideal")


def trajectory_plan(trajs: dict[str, NamedTrajectory], title: str, slope_rad: float,
                    units: Units, terrain: dict | None = None, compare=None, drop=None,
                    k_paper: float | None = None) -> list[tuple[str, Callable]]:
    """The trajectory figures (paper order: Figs. 2, 6, then 7-10) as ``(stem, build)``
    pairs: ``build()`` draws the figure ``stem`` and returns it (unsaved).

    Parameters
    ----------
    trajs : dict
        ``{model label: NamedTrajectory}`` (:data:`walkerlab.plotting.IDEAL_LABEL`, ...).
    terrain : dict, optional
        The contact walker's ground (:func:`walkerlab.io.terrain.load_terrain`).
    compare : CompareArtifact, optional
        Loaded ``compare.h5`` (Fig. 8).
    drop : optional
        The drop test of ``contact_sim.h5`` (restitution against stiffness, with the scene's
        stiffness ``k_paper`` marked).
    """
    plan: list[tuple[str, Callable]] = []
    for label, tr in trajs.items():
        stem = "fig2_stick_ideal" if label == IDEAL_LABEL else "fig6_stick_contact"
        ground = None if label == IDEAL_LABEL else terrain  # the contact walker's checkerboard
        plan.append((stem, partial(F.stick_diagram, tr, label, slope_rad=slope_rad,
                                   units=units, terrain=ground)))
    if any(len(p) > 2 for tr in trajs.values() for p in tr.points.values()):
        plan.append(("gait_3d_top_front", partial(top_and_front, trajs, title,
                                                  units=units)))
    plan += [("fig7_angles_rates", partial(F.fig7_angles_rates, trajs, title, units=units)),
             ("fig9_limit_cycles", partial(F.fig9_limit_cycle, trajs, units=units)),
             ("fig10_energy", partial(F.fig10_energy, trajs, units=units))]
    if compare is not None:
        c = compare
        phase = (c.step_phase, c.phase_errors) if c.phase_errors is not None else None
        plan.append(("fig8_errors", partial(F.fig8_errors, c.time, c.errors, c.error_units,
                                            "contact - ideal", scene_units=units,
                                            phase=phase)))
    if drop is not None:
        from walkerlab.plotting.sweep_figures import restitution_figure  # light

        plan.append(("drop_restitution", partial(
            restitution_figure, drop.stiffness, drop.restitution, unit=drop.unit,
            k_paper=k_paper, mass_kg=drop.mass_kg, units=units)))
    return plan


def scene_figure_plan(scene, sim, contact, terrain, compare) -> list[tuple[str, Callable]]:
    """A scene's trajectory figures as ``(stem, build)`` pairs (:func:`trajectory_plan`,
    titled by its walker model, after the energy ledger of ``simulate.h5`` if it has one).

    Parameters
    ----------
    scene : walkerlab.config.Scene
    sim, contact : SimulateArtifact or ContactSimArtifact, optional
        Loaded ``simulate.h5`` and ``contact_sim.h5`` (at least one).
    terrain : dict, optional
        The contact walker's ground (:func:`walkerlab.io.terrain.load_terrain`).
    compare : CompareArtifact, optional
        Loaded ``compare.h5``.
    """
    trajs = {label: a.samples for label, a in ((IDEAL_LABEL, sim), (CONTACT_LABEL, contact))
             if a is not None}
    title = f"{str(getattr(scene.walker, 'model', 'walker')).replace('_', ' ')} walking"
    if any(len(p) > 2 for a in (sim, contact) if a is not None
           for p in a.samples.points.values()):  # world points in 3D: a walker in 3D
        title = title.replace(" walking", " in 3D walking")
    has_drop = contact is not None and scene.contact is not None and contact.drop is not None
    ledger = [] if sim is None or not sim.ledger else [
        ("energy_ledger", partial(energy_ledger, sim, for_scene(scene)))]
    return ledger + trajectory_plan(
        trajs, title, scene.slope.phi_rad, for_scene(scene), terrain, compare,
        contact.drop if has_drop else None,
        float(scene.contact.written("stiffness")[0]) if has_drop else None)


def scene_trajectory_figures(scene, sim, contact, terrain, compare, out_dir: Path,
                             only: Collection[str] | None = None) -> list[Path]:
    """Draw and save the figures of :func:`scene_figure_plan` (same parameters) into
    ``out_dir`` (the report's figures folder); ``only``: just the figures of these stems.
    Returns the written files."""
    written: list[Path] = []
    for stem, build in scene_figure_plan(scene, sim, contact, terrain, compare):
        if only is None or stem in only:
            written += F.save(build(), out_dir, stem)
    return written


def workprecision_figures(wp, out_dir: Path, units: Units) -> list[Path]:
    """One work-precision diagram per model of a loaded ``workprecision.h5`` (``wp``), with
    its Pareto front; returns the written files."""
    written: list[Path] = []
    for model, m in wp.models.items():
        rows = {meth: {k: v for k, v in cols.items() if k != "repeats"}
                for meth, cols in m.rows.items()}
        written += F.save(F.work_precision(rows, f"work-precision, {model} model",
                                           pareto(m.choice), units=units),
                          out_dir, f"work_precision_{model}")
    return written


#: the ledger's sources (above zero) and sinks (below), in stacking order
_SOURCES = (("push_off_work", "push-off"), ("actuator_work_positive", "actuators (+)"),
            ("potential_work", "gravity and springs"))
_SINKS = (("heel_strike_loss", "heel-strike collision"), ("actuator_work_negative",
                                                           "actuators (-)"),
          ("internal_collision_loss", "knee strikes, foot slaps"), ("damper_work", "dampers"))


def energy_ledger(sim, units: Units):
    """Sources and sinks of mechanical energy per step (stacked bars, from ``simulate.h5``'s
    ``ledger/``) and the cost of transport per step: the figure (unsaved)."""
    import matplotlib.pyplot as plt
    import numpy as np

    led = sim.ledger
    steps = np.arange(len(led["closure"]))
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10, 4), gridspec_kw={"width_ratios": [3, 1]})
    up = np.zeros(steps.size)
    down = np.zeros(steps.size)
    scale = max(float(np.max(np.abs(np.nan_to_num(np.asarray(led[k], float)))))
                for k, _ in _SOURCES + _SINKS)
    tiny = 1e-9 * max(scale, 1e-300)  # round-off (the closure's size) is not drawn
    for key, label in _SOURCES:
        v = np.nan_to_num(np.asarray(led[key], float))
        pos, neg = np.clip(v, 0, None), np.clip(v, None, 0)
        if np.any(pos > tiny):
            ax.bar(steps, pos, bottom=up, label=label)
            up += pos
        if np.any(neg < -tiny):
            ax.bar(steps, neg, bottom=down, label=f"{label} (stored)")
            down += neg
    for key, label in _SINKS:
        v = np.nan_to_num(np.asarray(led[key], float))
        v = -np.abs(v)
        if np.any(v < -tiny):
            ax.bar(steps, v, bottom=down, label=label)
            down += v
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("step")
    ax.set_ylabel(f"energy per step [{units.energy}]")
    ax.set_title("where the energy goes: sources (+) and sinks (-) per step")
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))
    cot = np.asarray(led["cost_of_transport"], float)
    ax2.plot(steps, cot, "o-")
    top = float(np.nanmax(cot)) if np.isfinite(cot).any() else 1.0
    ax2.set_ylim(0.0, 1.25 * top if top > 0 else 1.0)
    ax2.ticklabel_format(axis="y", useOffset=False)
    from matplotlib.ticker import MaxNLocator

    ax2.xaxis.set_major_locator(MaxNLocator(integer=True))  # steps, not fractions
    ax2.set_xlabel("step")
    ax2.set_ylabel("cost of transport [-]")
    ax2.set_title("cost of transport")
    fig.tight_layout()
    return fig
