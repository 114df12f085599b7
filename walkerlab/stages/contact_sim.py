"""Stage ``contact-sim``: the compliant-contact (MSC ADAMS style) walker -> ``contact_sim.h5``.

The walker of the scene as free bodies on the scene's terrain, started from the ideal fixed
point (``fixedpoint.h5``; paper Table 2, MATLAB column) with the stance foot at its static
penetration, initial rates scaled by ``contact_sim.initial_rate_scale`` (``contact_sim.start:
ideal``, the default), or by the rates ``--adjust`` searches (``start: adjusted``), or from
the contact model's own periodic gait at mid-stance (``start: periodic_gait``: the steady
state without start-up transients; the gait is stored as with ``periodic_gait: true``).  Layout:
:mod:`walkerlab.io.schemas.contact_sim`.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.analysis.contact_record import contact_sim_run
from walkerlab.config import Scene
from walkerlab.integrate.ends import CONTACT_WALKED
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.schemas.contact_sim import run_end, write_contact_sim
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.models.contact import scene as contact_scene
from walkerlab.stages.common import (
    StageError,
    StageOutcome,
    require,
    run_cached,
)

SECTIONS = ("walker", "slope", "contact", "terrain", "contact_sim", "contact_solver")


def _compute(scene: Scene, fixedpoint: Path, adjust: bool, periodic: bool):
    from walkerlab.analysis.contact_periodic import PeriodicGaitError

    try:
        run = contact_sim_run(scene, load_fixedpoint(fixedpoint), adjust, periodic)
    except PeriodicGaitError as exc:  # the start asked for a gait that was not found
        raise StageError(str(exc)) from None
    return (lambda f: write_contact_sim(f, run)), run.summary


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        adjust: bool = False, periodic: bool = False) -> StageOutcome:
    """Simulate the contact walker (optionally after ``--adjust``) from ``fixedpoint.h5``
    (which must exist: :mod:`walkerlab.stages.pipeline` runs it first) and write the artifact.

    ``StageOutcome.failure`` says so when the walker did not walk (trip, fall, ...).

    Raises
    ------
    StageError
        The scene has no ``contact`` section.
    walkerlab.io.artifacts.ArtifactError
        ``fixedpoint.h5`` is missing or unreadable.
    """
    require(scene, "contact", "contact-sim")
    periodic = periodic or contact_scene.settings(scene)[2].periodic_gait
    up = (stage_artifact(scene, runs_root, "fixedpoint"),)
    sections = SECTIONS + (("adjust",) if adjust else ()) + (("periodic",) if periodic else ())
    out = run_cached("contact-sim", scene, runs_root, sections, up,
                     lambda: _compute(scene, up[0], adjust, periodic), force)
    kind, why = run_end(out.path)
    # like simulate: a walker that does not walk fails the run (the shared run ends,
    # walkerlab.integrate.ends: trip, fall, airborne, no_heel_strike, ...)
    if kind not in CONTACT_WALKED:
        out.failure = (f"the contact walker did not complete the run: {kind}"
                       + (f" ({why})" if why else ""))
    return out
