"""The stages as objects: one :class:`Stage` per stage, in :data:`STAGES`.

A stage names its module (its ``run``, and ``check``, ``sections``, ``warm_up`` where it has
them), the stages whose artifacts it reads, its artifact (:mod:`walkerlab.io.stage_files`),
its figures, what the report says of it, and whether the report's plan for a scene runs it.
The pipeline (:mod:`walkerlab.stages.pipeline`), the report's DAG run
(:mod:`walkerlab.stages.report_dag`), what the report shows
(:mod:`walkerlab.stages.report_inputs`) and the figures (:mod:`walkerlab.stages.plot`) read
them here.

A new stage: its module under ``walkerlab/stages/``, its artifact in
:data:`walkerlab.io.stage_files.ARTIFACTS` (with a schema under ``walkerlab/io/schemas/``),
one :class:`Stage` here, and its CLI command (and, shown in the report, its section under
``walkerlab/report/``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from walkerlab.config import Scene
from walkerlab.io import stage_files as art
from walkerlab.io.stage_files import StageArtifact
from walkerlab.models.actuation import refuse_actuators
from walkerlab.models.contact.parts import attribution_refusal
from walkerlab.walker.description import walker_data
from walkerlab.walker.kinds import KindRefused
from walkerlab.walker.plant import Plant

#: when the report runs a stage (:func:`walkerlab.stages.report_dag.run_report`): the gait
#: first, then the trajectories (the contact walker after its kernels' warm-up), the
#: work-precision study in a thread of its own, the rest after the study (their workers
#: and timed cases must not share its cores)
PHASES = ("gait", "trajectories", "study", "after")


@dataclass(frozen=True)
class Stage:
    """One stage.

    Attributes
    ----------
    name : str
        The stage's name (its CLI command; its artifact's name).
    module : str
        Its module under :mod:`walkerlab.stages` (imported on first use: the CLI stays
        light).
    artifact : StageArtifact or None
        Its HDF5 artifact (file, loader); None: it writes none (``animate``).
    needs : tuple of str
        The stages it reads the artifacts of (with their default options; a scene may need
        fewer: :func:`needs`).
    figures : str or None
        The figure group drawn from its artifact (:data:`walkerlab.stages.plot.PARTS`), or
        ``own``: the report draws its module's ``draw(scene, runs_root)`` after it runs.
    not_run : str or None
        What the scene lacks when the report does not run it (completing "the scene has
        ..."); None: the stage is not one the report shows.
    earlier : str
        Shown although the report did not compute it, when computed for the scene's current
        sections ('' : never; else why one computed for other settings is left out).
    in_plan : callable or None
        ``in_plan(scene, full, plan) -> bool``: whether the report runs it for ``scene``
        (``plan``: the decisions on the stages before it); None: never.
    phase : str
        When the report runs it (:data:`PHASES`).
    warm_up : bool
        Its module compiles kernels in the report's side process before it runs
        (``rhs_beside`` and ``warm_up``).
    """

    name: str
    module: str
    artifact: StageArtifact | None = None
    needs: tuple[str, ...] = ()
    figures: str | None = None
    not_run: str | None = "no section for it"
    earlier: str = ""
    in_plan: Callable[[Scene, bool, dict], bool] | None = None
    phase: str = "after"
    warm_up: bool = False


def _stage(artifact: StageArtifact, module: str, *args, **kwargs) -> Stage:
    """The stage that writes ``artifact`` (named as it)."""
    return Stage(artifact.name, module, artifact, *args, **kwargs)


def contact_walks_ground(scene: Scene) -> bool:
    """Whether the walker's kind walks the scene's ground in the contact view, with the
    scene's actuators (their cells of :data:`walkerlab.walker.kinds.CAPABILITIES`; the
    slope always, a passive walker always: a 3D walker's actuators are the rigid model's
    so far)."""
    ground = "slope" if scene.terrain is None else scene.terrain.kind
    drawn = ground in ("stairs", "footholds", "profile")
    act = getattr(scene.walker, "actuation", None)
    if not drawn and act is None:
        return True
    kind = walker_data(scene.walker, scene.slope.phi_rad).structure.kind
    if drawn and not kind.supports(ground, "contact"):
        return False
    try:
        if act is not None:
            refuse_actuators(kind, act, "contact")
    except KindRefused:
        return False
    return True


def attribution_refused(scene: Scene) -> str | None:
    """Why the scene's walker gets no Section-5 attribution (no contact periodic gait, or a
    walker in 3D: :func:`walkerlab.models.contact.parts.attribution_refusal`), one line
    without the scene's name, or None."""

    return attribution_refusal(scene, walker_data(scene.walker, scene.slope.phi_rad))


def needs(stage: str, scene: Scene) -> tuple[str, ...]:
    """The stages ``stage`` reads the artifacts of, for ``scene`` (direct dependencies):
    ``simulate`` reads ``fixedpoint.h5`` only when ``simulate.initial_state`` is the fixed
    point, ``optimize`` only for a walker whose guess is built from the gait."""
    if stage == art.SIMULATE.name and scene.simulate is not None \
            and scene.simulate.initial_state != "fixed_point":
        return ()
    if stage == art.OPTIMIZE.name:
        from walkerlab.optimal.driver import needs_gait  # light: the optimal layer

        # a five-link biped: its guess is built from the targets
        if not needs_gait(scene, Plant.from_scene(scene)):
            return ()
    return STAGES[stage].needs if stage in STAGES else ()


def _reads_gait(stage: StageArtifact, scene: Scene) -> bool:
    return art.FIXEDPOINT.name in needs(stage.name, scene)


def _contact_asked(scene: Scene) -> bool:
    """A contact run the scene asks for (a ``contact_sim`` section) on a ground its walker
    walks in the contact view."""
    return scene.contact is not None and scene.contact_sim is not None \
        and contact_walks_ground(scene)


def _gait_in_plan(scene: Scene, full: bool, plan: dict) -> bool:
    # a simulation that starts from the gait runs (and shows) the fixed point it starts from,
    # with the section's defaults when the scene has none; so does a contact run the scene
    # asks for (a 'contact_sim' section), as `walkerlab contact-sim` does
    return scene.fixedpoint is not None \
        or (scene.simulate is not None and _reads_gait(art.SIMULATE, scene)) \
        or (_contact_asked(scene) and _reads_gait(art.CONTACT_SIM, scene))


def _contact_in_plan(scene: Scene, full: bool, plan: dict) -> bool:
    # a contact section alone, without a gait to start from (a five-link optimum's contact
    # replay reads it), runs no contact-sim; nor one whose walker the contact view refuses
    # on the scene's ground (flat feet on stairs: the section carries the MJCF's foot mass
    # and contact law)
    return scene.contact is not None \
        and (plan[art.FIXEDPOINT.name] or not _reads_gait(art.CONTACT_SIM, scene)) \
        and contact_walks_ground(scene)


#: every stage the pipeline runs by name, in the report's order
STAGES: dict[str, Stage] = {s.name: s for s in (
    _stage(art.FIXEDPOINT, "fixedpoint", phase="gait", in_plan=_gait_in_plan,
          not_run="no 'fixedpoint' section (nor a 'simulate' or 'contact_sim' that starts "
                  "from the gait)"),
    _stage(art.SIMULATE, "simulate", (art.FIXEDPOINT.name,), "trajectories",
          "no 'simulate' section", phase="trajectories",
          in_plan=lambda scene, full, plan: scene.simulate is not None),
    _stage(art.CONTACT_SIM, "contact_sim", (art.FIXEDPOINT.name,), "trajectories",
          "a 'contact' section but no 'contact_sim' or 'fixedpoint' section",
          phase="trajectories", in_plan=_contact_in_plan, warm_up=True),
    _stage(art.COMPARE, "compare", (art.SIMULATE.name, art.CONTACT_SIM.name), "trajectories",
          phase="trajectories", in_plan=lambda scene, full, plan:
          plan[art.CONTACT_SIM.name] and plan[art.SIMULATE.name]),
    _stage(art.WORKPRECISION, "workprecision", (art.FIXEDPOINT.name,), "workprecision",
          "no 'workprecision' section", phase="study",
          earlier="measured for other settings; `walkerlab report --full` measures it again",
          in_plan=lambda scene, full, plan: scene.workprecision is not None
          and (full or scene.workprecision.in_default_report)),
    _stage(art.BIFURCATION, "bifurcation",
          earlier="computed for another walker, slope or solver"),
    _stage(art.BASIN, "basin", (art.FIXEDPOINT.name,),
          not_run="no 'basin' section (or no 'fixedpoint')",
          in_plan=lambda scene, full, plan: scene.basin is not None
          and scene.fixedpoint is not None),
    _stage(art.ROBUSTNESS, "robustness", (art.FIXEDPOINT.name,),
          not_run="no 'robustness' section (or no 'fixedpoint')",
          in_plan=lambda scene, full, plan: scene.robustness is not None
          and scene.fixedpoint is not None),
    _stage(art.MFPT, "mfpt", (art.FIXEDPOINT.name,),
          not_run="no 'mfpt' section (or no 'fixedpoint')",
          earlier="computed for other settings: rerun `walkerlab mfpt`"),
    _stage(art.ATTRIBUTION, "attribution", (art.FIXEDPOINT.name,),
          not_run="no 'contact' or 'fixedpoint' section",
          earlier="computed for other settings; `walkerlab report --full` computes it again",
          in_plan=lambda scene, full, plan: full and plan[art.CONTACT_SIM.name]
          and scene.fixedpoint is not None and attribution_refused(scene) is None),
    _stage(art.OPTIMIZE, "optimize", (art.FIXEDPOINT.name,), "own",
          "no 'optimize' section (or no 'fixedpoint')",
          in_plan=lambda scene, full, plan: getattr(scene, "optimize", None) is not None
          and (scene.fixedpoint is not None or not needs(art.OPTIMIZE.name, scene))),
    Stage("animate", "animate", None, (art.SIMULATE.name,), not_run=None),
)}


def report_plan(scene: Scene, full: bool = False) -> list[str]:
    """The stages ``report`` runs for this scene, in order (each :attr:`Stage.in_plan`):
    each only when the scene has its sections (``fixedpoint``, with the section's defaults,
    also when ``simulate`` starts from the gait or the scene asks for a contact run:
    ``contact`` and ``contact_sim``); the work-precision study (it times every solver
    setting: most of a cold report) only with ``full`` or where the scene's
    ``workprecision.in_default_report`` asks for it (the paper's scene), and the Section-5
    attribution (seven periodic-gait searches) only with ``full``."""
    plan: dict[str, bool] = {}
    for s in STAGES.values():
        plan[s.name] = s.in_plan is not None and bool(s.in_plan(scene, full, plan))
    return [s for s, on in plan.items() if on]


def shown() -> tuple[str, ...]:
    """The stages whose artifact the report shows, in the report's order."""
    return tuple(s.name for s in STAGES.values() if s.not_run is not None)


def in_phase(phase: str) -> tuple[Stage, ...]:
    """The stages the report runs in ``phase`` (:data:`PHASES`), in order."""
    return tuple(s for s in STAGES.values() if s.phase == phase and s.in_plan is not None)
