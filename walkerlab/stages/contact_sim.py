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

import contextlib
import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING

from walkerlab.analysis.contact.record import contact_sim_run
from walkerlab.analysis.contact.search_budget import PeriodicGaitError
from walkerlab.analysis.contact.warm import compile_rhs_kernels, compile_run_kernels
from walkerlab.config import Scene, SceneError
from walkerlab.config.options import with_contact_strides
from walkerlab.execution.pending import CompiledElsewhere
from walkerlab.integrate.contact_grid import COMPILED_METHODS
from walkerlab.integrate.ends import CONTACT_WALKED
from walkerlab.io.artifacts import ArtifactError
from walkerlab.io.freshness import NOT_FINAL_ATTR
from walkerlab.io.runpaths import stage_artifact
from walkerlab.io.schemas.contact_sim import run_end, write_contact_sim
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.models.contact.scene import ContactSetup, contact_setup
from walkerlab.stages.common import (
    StageError,
    StageOutcome,
    run_cached,
    with_defaults,
)
from walkerlab.usercache import use_for_numba
from walkerlab.walker.plant import Plant

if TYPE_CHECKING:
    from collections.abc import Callable
    from concurrent.futures import Future

    from walkerlab.execution.pending import CompiledElsewhere
    from walkerlab.execution.side import SideWorker

SECTIONS = ("walker", "slope", "contact", "terrain", "contact_sim", "contact_solver")


def _compute(setup: ContactSetup, fixedpoint: Path, adjust: bool, periodic: bool):

    try:
        run = contact_sim_run(setup, load_fixedpoint(fixedpoint), adjust, periodic)
    except PeriodicGaitError as exc:  # the start asked for a gait that was not found
        if exc.kind == "time_limit":  # the machine's speed, not the scene's answer
            raise StageError(f"{exc} (contact_sim.periodic_time_limit_s: a wall-clock limit; "
                             "nothing was stored)") from None
        raise StageError(str(exc)) from None
    cut = cut_short(run)

    def writer(f):
        write_contact_sim(f, run)
        if cut:  # stored to be read and shown, never reused as the scene's result
            f.attrs[NOT_FINAL_ATTR] = cut
    return writer, run.summary


def cut_short(run) -> str:
    """What a wall-clock limit cut short in a contact run (a
    :class:`walkerlab.io.schemas.contact_sim.ContactSimRun`): the walking run, its periodic
    gait's search, runs of its adjust search; "" when nothing (the work bounds end a run the
    same way on any machine: such a run is a result)."""
    cut = []
    if run.result.termination == "time_limit":
        cut.append("the contact run: contact_sim.wall_time_limit_s")
    if getattr(run.gait_error, "kind", "") == "time_limit":
        cut.append("the periodic-gait search: contact_sim.periodic_time_limit_s")
    if run.adjust and run.adjust.get("time_limited_runs"):
        cut.append(f"{run.adjust['time_limited_runs']} run(s) of the adjust search: "
                   "contact_sim.wall_time_limit_s")
    return "; ".join(cut)


def rhs_beside(setup: ContactSetup, side: Callable[[], SideWorker]
               ) -> tuple[CompiledElsewhere, SideWorker, Future] | None:
    """On the first contact run of a walker structure (its generated contact module not in
    the user cache yet: numba compiles every kernel of the run) with a compiled walk, have
    a side process (``side()``, a :class:`~walkerlab.execution.side.SideWorker`, asked for
    only then) compile the solver's compiled right-hand side (:func:`warm_rhs`), and this
    process's walk wait for it there and load it while this process generates the model
    and compiles the other kernels (the contact table, the pinned start).

    Returns the hand-off (a :class:`walkerlab.execution.pending.CompiledElsewhere`: the
    caller passes it to the run as ``ContactSetup.rhs_ready``), the side worker and its
    future, else None: a warm run, no user cache to share the kernel through, a walk on
    scipy's solvers, or no side process (disabled, or it broke).  The numbers are the same
    either way."""
    from walkerlab.models.contact.generated import contact_module_state  # light

    name, cached = contact_module_state(setup.walker.structure, setup.law.hold_heading)
    if cached is not False or not _compiled_walk(setup):
        return None
    worker = side()
    fut = worker.submit(warm_rhs, setup)
    if fut is None:
        return None
    return CompiledElsewhere(name, "build_cyrk", lambda: worker.wait(fut)), worker, fut


def _own_side() -> SideWorker:
    from walkerlab.execution.side import SideWorker

    return SideWorker(idle_only=True)


@contextlib.contextmanager
def _rhs_beside(setup: ContactSetup, rhs_ready: CompiledElsewhere | None):
    """:func:`rhs_beside` on a side process of this run's own, started only when it has
    work (a warm run imports no process machinery; never on one core or on a busy
    machine: ``idle_only``; nor when the caller's process compiles the kernel already:
    ``rhs_ready``, the report's side process), and stopped if the run never needed it.
    Yields the setup the run uses (with the hand-off, if any).  A side process that fails
    only means the right-hand side is compiled here."""
    if rhs_ready is not None:
        yield dataclasses.replace(setup, rhs_ready=rhs_ready)
        return
    beside = rhs_beside(setup, _own_side)
    if beside is None:
        yield setup
        return
    ready, side, fut = beside
    try:
        yield dataclasses.replace(setup, rhs_ready=ready)
    except BaseException:
        side.close(cancel=True)
        raise
    # never needed here (an up-to-date artifact, or a run that ended before its walk)
    side.close(cancel=not fut.done())


def check(scene: Scene, strides: int | None = None, periodic: bool = False,
          **_options) -> None:
    """Refuse, before anything runs (:func:`walkerlab.stages.pipeline.run`: before the gait
    search upstream), a bad ``--strides`` and whatever the scene alone decides: the
    capability table's contact cells for the walker's kind and the scene's features, its
    ground and actuators (:func:`walkerlab.models.contact.scene.contact_setup`, as the run
    reads the scene).

    Raises
    ------
    StageError
        ``strides`` out of bounds (one line naming ``contact_sim.n_strides``).
    walkerlab.models.contact.scene.ContactSceneError
        The contact view refuses the scene (one line).
    """
    try:
        scene = with_contact_strides(scene, strides)
    except SceneError as exc:
        raise StageError(str(exc)) from None
    contact_setup(scene, periodic, plant=Plant.from_scene(scene))


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        adjust: bool = False, periodic: bool = False,
        rhs_ready: CompiledElsewhere | None = None, strides: int | None = None
        ) -> StageOutcome:
    """Simulate the contact walker (optionally after ``--adjust``) from ``fixedpoint.h5``
    (which must exist: :mod:`walkerlab.stages.pipeline` runs it first) and write the artifact.
    ``strides`` (``--strides``): ``contact_sim.n_strides`` for this run (the artifact's
    inputs, so a run of another number of strides is not reused for it).
    ``rhs_ready``: the caller's side process compiling the compiled right-hand side
    (:func:`rhs_beside`; ``walkerlab report``), else this run starts its own when cold.

    ``StageOutcome.failure`` says so when the walker did not walk (trip, fall, ...).

    Raises
    ------
    walkerlab.models.contact.scene.ContactSceneError
        The scene's walker cannot stand on contacts (a scene without a ``contact`` section
        runs on its defaults, the paper's contact law), or its
        periodic gait (``periodic``) is one the contact view does not find
        (:func:`walkerlab.models.contact.scene.contact_setup`; one line).
    StageError
        ``strides`` out of bounds (one line naming ``contact_sim.n_strides``).
    walkerlab.io.artifacts.ArtifactError
        ``fixedpoint.h5`` is missing or unreadable.
    """
    try:
        scene = with_contact_strides(scene, strides)
    except SceneError as exc:
        raise StageError(str(exc)) from None
    # asked for, the stage runs without a 'contact' section: on its defaults, the artifact
    # keyed and recorded as with 'contact: {}' (the report asks only with the section)
    scene = with_defaults(scene, "contact", CONTACT_SIM.name)
    # the scene read once, its walker described once: all the run needs, typed
    setup = contact_setup(scene, periodic, plant=Plant.from_scene(scene))
    periodic = periodic or setup.sim.periodic_gait
    up = (stage_artifact(scene, runs_root, "fixedpoint"),)
    sections = SECTIONS + (("adjust",) if adjust else ()) + (("periodic",) if periodic else ())
    with _rhs_beside(setup, rhs_ready) as run_setup:  # started now: the freshness check
        # runs meanwhile
        out = run_cached(CONTACT_SIM.name, scene, runs_root, sections, up,
                         lambda: _compute(run_setup, up[0], adjust, periodic), force)
    kind, why = run_end(out.path)
    # like simulate: a walker that does not walk fails the run (the shared run ends,
    # walkerlab.integrate.ends: trip, fall, airborne, no_heel_strike, ...)
    if kind not in CONTACT_WALKED:
        out.failure = (f"the contact walker did not complete the run: {kind}"
                       + (f" ({why})" if why else ""))
        unstable = _unstable_rigid_gait(up[0]) if kind in _LEFT_THE_GAIT else ""
        if unstable:  # the cause named first: the patches or the contact law come after it
            out.failure = f"{unstable}; {out.failure}"
    return out


#: ends of a contact run that an unstable rigid gait explains (the walk leaves the gait)
_LEFT_THE_GAIT = ("fall", "trip", "scuff", "airborne")


def _unstable_rigid_gait(fixedpoint_path: Path) -> str:
    """The rigid gait's instability in one clause ("" when it is stable or unreadable): the
    contact walk starts near it and, with a multiplier above 1, leaves it as the rigid walk
    would, whatever the patches and the contact law."""
    try:
        mu = load_fixedpoint(fixedpoint_path).max_abs_multiplier()
    except (ArtifactError, ValueError, KeyError):
        return ""
    if not mu > 1.0:
        return ""
    return (f"the rigid gait it starts from is unstable (largest |Floquet multiplier| "
            f"{mu:.3g}: a deviation grows x{mu:.2g} a step), so the contact walker, which "
            "starts a little off it, leaves it as the rigid walker would")


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
    use_for_numba()  # the same cache folder as the run's (set before numba is imported)
    return compile_run_kernels(contact_setup(scene, plant=Plant.from_scene(scene)))


def _compiled_walk(setup: ContactSetup) -> bool:
    """Whether the run integrates on the compiled right-hand side (CyRK's methods)."""
    return setup.solver.method in COMPILED_METHODS


def warm_rhs(setup: ContactSetup) -> bool:
    """Compile the compiled solvers' right-hand side of ``setup``'s walker into the user
    cache (:func:`walkerlab.analysis.contact.warm.compile_rhs_kernels`; the side process of
    a cold :func:`run`).  Returns False when nothing was compiled (numba is not installed).
    """
    use_for_numba()  # the same cache folder as the run's (set before numba is imported)
    return compile_rhs_kernels(setup)
