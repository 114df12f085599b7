"""Stage ``rigid-limit``: the contact walker's periodic gait along the one rigid-limit family
-> ``rigid_limit.h5`` (``walkerlab compare --rigid-limit``).

For each stiffness factor ``kappa`` (default the walker kind's,
:attr:`walkerlab.models.contact.parts.ContactPart.rigid_limit_kappas`: :data:`KAPPAS`, a
walker in 3D one octave at a time to 8, or the three decades with its heading held,
``contact.hold_heading``) the scene's contact is scaled by
:mod:`walkerlab.models.contact.rigid_limit` and the contact walker's own periodic gait is found
(:func:`walkerlab.analysis.contact.rigid_limit.convergence`); the artifact holds its step period,
step length and slow Floquet multipliers against ``kappa``, the rigid gait's as scalars, and the
observed orders of convergence (layout: :mod:`walkerlab.io.schemas.rigid_limit`).  Any
walker with a ``contact`` and a ``fixedpoint`` section.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io.runpaths import figures_dir
from walkerlab.io.schemas.rigid_limit import RigidLimitRun, load_rigid_limit, write_rigid_limit
from walkerlab.models.contact.parts import ContactPart, contact_part, periodic_gait_refusal
from walkerlab.models.contact.rigid_limit import expected_order
from walkerlab.models.contact.scene import build
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached, with_defaults
from walkerlab.walker.plant import Plant

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint", "contact", "terrain")
#: Default stiffness factors [-] of a planar walker: the scene's contact and three decades
#: stiffer.
KAPPAS = (1.0, 10.0, 100.0, 1000.0)


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        kappas=None) -> StageOutcome:
    """Compute (or reuse) ``rigid_limit.h5`` at the stiffness factors ``kappas`` [-]
    (default the walker kind's).

    Raises
    ------
    StageError
        No ``contact`` or ``fixedpoint`` section (one line).
    """
    scene = with_defaults(scene, "contact", "rigid-limit")  # left out: the paper's contact law
    require(scene, "fixedpoint", "rigid-limit")
    _periodic_gait_taken(scene)
    if kappas is None:   # the kind's; with the heading held no stiff torsional mode
        # limits a 3D walker's: the three decades of ContactPart's (planar walkers')
        part = contact_part(Plant.from_scene(scene).data.structure)
        kappas = (ContactPart.rigid_limit_kappas if scene.contact.hold_heading
                  else part.rigid_limit_kappas)
    kappas = tuple(float(k) for k in kappas)

    def compute():
        from walkerlab.analysis.contact.periodic import ideal_gait  # light
        from walkerlab.analysis.contact.rigid_limit import convergence, observed_order  # light

        plant = Plant.from_scene(scene)  # the walker described once, handed down
        ideal = ideal_gait(scene, plant)
        walker, _ = build(scene, ideal.x, 2, plant=plant)
        tab = convergence(walker, ideal, kappas)
        orders = {"period": observed_order(tab.kappa, tab.period_gap_s),
                  "step_length": observed_order(tab.kappa, tab.step_gap_m)}
        summary = {"kappa": tab.kappa.tolist(), "period_gap_s": tab.period_gap_s.tolist(),
                   "step_gap_m": tab.step_gap_m.tolist(),
                   "observed_order_period": orders["period"].tolist(),
                   "observed_order_step_length": orders["step_length"].tolist(),
                   "expected_order": expected_order(walker.contact.e)}

        run = RigidLimitRun(tab, orders, summary["expected_order"])
        return (lambda f: write_rigid_limit(f, run)), summary

    return run_cached("rigid-limit", scene, runs_root, SECTIONS, (), compute, force,
                      extra_key=repr(kappas))


def _periodic_gait_taken(scene: Scene) -> None:
    """Refuse, before anything runs, a walker whose contact periodic gait the kind's contact
    part does not find (a rimless wheel: its spokes have no mid-stance), in one line.

    Raises
    ------
    StageError
    """

    why = periodic_gait_refusal(scene, Plant.from_scene(scene).data)
    if why is not None:
        raise StageError(f"compare --rigid-limit (the contact periodic gait at each "
                         f"stiffness): scene '{scene.name}': {why}")


def draw(scene: Scene, runs_root: Path | str, path: Path) -> list[Path]:
    """Draw ``rigid_limit.png/svg`` into the scene's figures folder from the artifact."""
    from walkerlab.plotting.figures import save  # light
    from walkerlab.plotting.rigid_limit_figure import rigid_limit_figure  # light

    return save(rigid_limit_figure(load_rigid_limit(path), scene.name or "walker"),
                figures_dir(scene, runs_root, claim=True), "rigid_limit")
