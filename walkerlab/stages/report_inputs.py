"""What the report shows: the artifacts of its stages that exist, and which are current.

An artifact the report produced is shown; one it did not produce (an earlier standalone run)
is shown only when :data:`EARLIER` allows it and it was computed for the scene's current
sections (:func:`computed_for`); everything left out is named in one line.
"""

from __future__ import annotations

from itertools import combinations
from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io.artifacts import stored_content_hash_matches, stored_hash
from walkerlab.io.freshness import changed_fields, drawing_key, input_hash, stamp_matches
from walkerlab.io.runpaths import bifurcation_artifacts, figures_dir, stage_artifact
from walkerlab.io.stage_files import (
    ATTRIBUTION,
    BIFURCATION,
    COMPARE,
    CONTACT_SIM,
    SIMULATE,
    WORKPRECISION,
)
from walkerlab.stages.pipeline import contact_walks_ground, needs, stage_module
from walkerlab.stages.registry import STAGES, shown

REPORT_STAGES = shown()


def not_run(scene: Scene, stage: str) -> str:
    """Why the report does not run ``stage`` for ``scene`` (completing "the scene has ...");
    the contact stages by what the scene lacks, or the capability table's cell that
    refuses its ground (:func:`walkerlab.stages.pipeline.report_plan`)."""
    if stage == COMPARE.name and scene.simulate is None:
        return (f"no 'simulate' section (compare needs '{SIMULATE.name}' and "
                f"'{CONTACT_SIM.name}')")
    if stage in (CONTACT_SIM.name, COMPARE.name):
        if scene.contact is None:
            return "no 'contact' section"
        if not contact_walks_ground(scene):
            ground = scene.terrain.kind if scene.terrain is not None else "slope"
            if scene.walker.actuation is not None and ground == "slope":
                return ("a walker whose actuators the contact view does not take "
                        "(`walkerlab capabilities`)")
            return (f"a walker the contact view does not walk on {ground} "
                    "(`walkerlab capabilities`)")
        return str(STAGES[CONTACT_SIM.name].not_run)
    return (STAGES[stage].not_run if stage in STAGES else None) or "no section for it"


#: artifacts shown although this report did not compute them, when computed for the
#: scene's current sections: (their stage, why one is left out)
EARLIER = {s.name: s.earlier for s in STAGES.values() if s.earlier}


#: the stamp beside ``animation.gif``: the drawing key of the artifacts it was drawn from
#: (written by ``walkerlab animate``)
ANIMATION_STAMP = ".drawn_from_animation"


def animation_current(scene: Scene, runs_root) -> str:
    """Why ``animation.gif`` must not be shown beside the run folder's current artifacts
    ('' if it may): no stamp (drawn before stamps were written, or half written), or drawn
    from other artifacts than the ``simulate.h5`` (and ``contact_sim.h5``) there now."""
    stamp = figures_dir(scene, runs_root) / ANIMATION_STAMP
    sim, contact = (stage_artifact(scene, runs_root, s) for s in (SIMULATE.name,
                                                                   CONTACT_SIM.name))
    if not stamp.is_file() or not sim.is_file():
        return "not drawn from this run folder's simulate.h5: rerun `walkerlab animate`"
    keys = [drawing_key({SIMULATE.name: sim})]
    if contact.is_file():
        keys.append(drawing_key({SIMULATE.name: sim, CONTACT_SIM.name: contact}))
    if not any(stamp_matches(stamp, k) for k in keys):
        return "drawn from an earlier simulate.h5 or contact_sim.h5: rerun `walkerlab animate`"
    return ""



def computed_for(scene: Scene, runs_root, stage: str, variants: tuple[str, ...] = ()) -> str:
    """Why the existing artifact of ``stage`` must not be used beside the scene's current
    results ('' if it may): changed after it was written, or written for other inputs than
    the scene's current ones (with any subset of the stage's ``variants``, e.g. contact-sim's
    ``adjust`` and ``periodic``, in its input hash)."""
    path = stage_artifact(scene, runs_root, stage)
    if not stored_content_hash_matches(path):
        return f"{path.name} was changed after it was written"
    up = tuple(stage_artifact(scene, runs_root, s) for s in needs(stage, scene))
    have, sections = stored_hash(path), stage_sections(stage, scene)
    for extra in (c for k in range(len(variants) + 1) for c in combinations(variants, k)):
        if have == input_hash(stage, scene, sections + extra, up):
            return ""
    return f"{path.name} was computed for another scene or fixed point"


def existing_artifacts(scene: Scene, runs_root) -> dict[str, Path]:
    """``{stage: path}`` of the report's stages whose artifact exists for ``scene``, and
    ``{bifurcation_<field>: path}`` of bifurcations over other fields (``--param``)."""
    out = {s: p for s in REPORT_STAGES if (p := stage_artifact(scene, runs_root, s)).is_file()}
    return out | bifurcation_artifacts(scene, runs_root)


def _why_left_out(scene: Scene, stage: str, p: Path, full: bool) -> str:
    """'' when the artifact ``p`` the report did not produce is shown all the same."""
    kind = BIFURCATION.name if stage.startswith(BIFURCATION.name) else stage
    wp = scene.workprecision
    if kind not in EARLIER or (kind == WORKPRECISION.name and (
            wp is None or full or wp.in_default_report)) or (
            kind == ATTRIBUTION.name and (scene.contact is None or full)):
        return f"an earlier standalone run: the scene has {not_run(scene, stage)}"
    if kind == BIFURCATION.name and not stored_content_hash_matches(p):  # edited by hand (26)
        return "changed after it was written: rerun 'walkerlab bifurcation'"
    return EARLIER[kind] if changed_fields(p, scene, stage_sections(kind, scene)) else ""


def stage_sections(stage: str, scene: Scene) -> tuple[str, ...]:
    """The scene sections ``stage``'s input hash covers (a module's ``sections(scene)``
    where it depends on the scene, e.g. simulate on a drawn ground; else ``SECTIONS``)."""
    mod = stage_module(stage)
    return mod.sections(scene) if hasattr(mod, "sections") else mod.SECTIONS


def report_artifacts(scene: Scene, runs_root, done: list, full: bool = False
                     ) -> tuple[dict[str, Path], str]:
    """The artifacts the report shows (those this report produced, ``done``: its
    ``StageOutcome`` list, and those of :data:`EARLIER` computed for the current scene) and
    one line on what it leaves out ('' when nothing)."""
    produced, paths, left = {o.stage for o in done}, {}, []
    for stage, p in existing_artifacts(scene, runs_root).items():
        why = "" if stage in produced else _why_left_out(scene, stage, p, full)
        if why:
            left.append(f"{p.name} ({why})")
        else:
            paths[stage] = p
    if (figures_dir(scene, runs_root) / "animation.gif").is_file() \
            and (why := animation_current(scene, runs_root)):
        left.append(f"animation.gif ({why})")
    return paths, ("report: leaves out " + "; ".join(left)) if left else ""
