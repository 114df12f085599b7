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

from walkerlab.analysis.contact.record import contact_sim_run
from walkerlab.config import Scene
from walkerlab.integrate.ends import CONTACT_WALKED
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.schemas.contact_sim import run_end, write_contact_sim
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.models.contact.scene import ContactSetup, contact_setup
from walkerlab.stages.common import (
    StageError,
    StageOutcome,
    run_cached,
)

SECTIONS = ("walker", "slope", "contact", "terrain", "contact_sim", "contact_solver")


def _compute(setup: ContactSetup, fixedpoint: Path, adjust: bool, periodic: bool):
    from walkerlab.analysis.contact.step_map import PeriodicGaitError

    try:
        run = contact_sim_run(setup, load_fixedpoint(fixedpoint), adjust, periodic)
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
    walkerlab.models.contact.scene.ContactSceneError
        The scene has no ``contact`` section, or its walker cannot stand on contacts
        (:func:`walkerlab.models.contact.scene.contact_setup`; one line).
    walkerlab.io.artifacts.ArtifactError
        ``fixedpoint.h5`` is missing or unreadable.
    """
    setup = contact_setup(scene)  # the scene read once: all the run needs, typed
    periodic = periodic or setup.sim.periodic_gait
    up = (stage_artifact(scene, runs_root, "fixedpoint"),)
    sections = SECTIONS + (("adjust",) if adjust else ()) + (("periodic",) if periodic else ())
    out = run_cached("contact-sim", scene, runs_root, sections, up,
                     lambda: _compute(setup, up[0], adjust, periodic), force)
    kind, why = run_end(out.path)
    # like simulate: a walker that does not walk fails the run (the shared run ends,
    # walkerlab.integrate.ends: trip, fall, airborne, no_heel_strike, ...)
    if kind not in CONTACT_WALKED:
        out.failure = (f"the contact walker did not complete the run: {kind}"
                       + (f" ({why})" if why else ""))
    return out


def warm_up(scene: Scene) -> bool:
    """Compile the numba kernels of the scene's contact run into the user cache, untimed
    (:func:`walkerlab.analysis.contact.warm.compile_run_kernels`): ``walkerlab report`` runs
    it in a side process while its rigid stages run, so :func:`run` only loads them.
    Returns False when nothing was compiled (numba is not installed).

    Raises
    ------
    walkerlab.models.contact.scene.ContactSceneError
        As :func:`run` (no ``contact`` section, a walker that cannot stand on contacts).
    """
    from walkerlab.analysis.contact.warm import compile_run_kernels
    from walkerlab.usercache import use_for_numba

    use_for_numba()  # the same cache folder as the run's (set before numba is imported)
    return compile_run_kernels(contact_setup(scene))
