"""Stage ``attribution``: the paper's Section-5 comparison per walker -> ``attribution.h5``.

The contact-vs-rigid gap of the contact model's periodic gait split by cause (friction
creep, compliance, residual), the energy per step by sink and the initial-rate adjustment's
effect with whether the adjusted start lies in the rigid walker's basin
(:mod:`walkerlab.analysis.contact.attribution`).  Reads ``fixedpoint.h5``; any walker with a
``contact`` section.  Cost: seven periodic-gait searches and three short runs, so
``walkerlab report`` runs it only with ``--full``.
Layout: :mod:`walkerlab.io.schemas.attribution`.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from walkerlab.config import Scene
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.schemas.attribution import AttributionRun, write_attribution
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.models.contact.scene import build
from walkerlab.stages.common import StageError, StageOutcome, run_cached, with_defaults
from walkerlab.stages.registry import attribution_refused
from walkerlab.walker.plant import Plant

SECTIONS = ("walker", "slope", "ideal", "solver", "contact", "terrain", "contact_sim",
            "contact_solver")


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False) -> StageOutcome:
    """Compute (or reuse) ``attribution.h5`` from ``fixedpoint.h5`` (which must exist:
    :mod:`walkerlab.stages.pipeline` runs it first).

    Raises
    ------
    StageError
        A walker whose attribution is not computed (no contact periodic gait, a walker in
        3D: :func:`walkerlab.stages.registry.attribution_refused`; one line).
    walkerlab.io.artifacts.ArtifactError
        ``fixedpoint.h5`` is missing or unreadable.
    """
    scene = with_defaults(scene, "contact", "attribution")  # left out: the paper's contact law
    why = attribution_refused(scene)
    if why is not None:
        raise StageError(f"attribution: scene '{scene.name}': {why}")
    up = (stage_artifact(scene, runs_root, "fixedpoint"),)

    def compute():
        from walkerlab.analysis.contact.attribution import adjustment_effect, attribute

        fp = load_fixedpoint(up[0])
        ideal = SimpleNamespace(x=fp.x, period_s=float(fp.step_period_s))
        plant = Plant.from_scene(scene)  # the walker described once, handed down
        walker, _ = build(scene, fp.x, 2, plant=plant)
        res = AttributionRun(attribute(walker, ideal),
                             adjustment_effect(scene, ideal, plant=plant), ideal.period_s)
        a = res.attribution
        summary = {"period_gap_s": a.period_gap_s, "creep_s": a.creep_s,
                   "compliance_s": a.compliance_s, "residual_s": a.residual_s}
        return (lambda f: write_attribution(f, res)), summary

    return run_cached("attribution", scene, runs_root, SECTIONS, up, compute, force)

