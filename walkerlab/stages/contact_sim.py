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

import numpy as np

from walkerlab.analysis import contact_sim as contact_run
from walkerlab.analysis.contact_record import (
    DROP_SPEED,
    LEGS,
    drop_test,
    rate_states,
    run_summary,
)
from walkerlab.config import Scene
from walkerlab.contact import scene as contact_scene
from walkerlab.integrate.ends import CONTACT_WALKED
from walkerlab.io.schemas.contact_sim import ContactSimRun, run_end, write_contact_sim
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.stages.common import (
    StageError,
    StageOutcome,
    artifact_path,
    require,
    run_cached,
)

SECTIONS = ("walker", "slope", "contact", "terrain", "contact_sim", "contact_solver")


def _compute(scene: Scene, fixedpoint: Path, adjust: bool, periodic: bool):
    fp = load_fixedpoint(fixedpoint)
    law, _terrain, cs = contact_scene.settings(scene)[:3]
    adj = scale = None
    gait = gait_error = None
    adjust = adjust or cs.start == "adjusted"
    if adjust:
        from walkerlab.analysis.contact_adjust import adjust_rates, better_start

        adj = adjust_rates(scene, fp.x, fp.step_period_s)
        scale = adj["scale"]
    if cs.start == "periodic_gait":  # steady state: the contact model's own periodic gait
        from walkerlab.analysis.contact_periodic import (
            PeriodicGaitError,
            simulate_from_periodic_gait,
        )

        try:
            walker, res, x0, step_length, gait = simulate_from_periodic_gait(
                scene, fp.x)
        except PeriodicGaitError as exc:
            raise StageError(f"scene '{scene.name}': contact_sim.start: periodic_gait: the "
                             f"contact walker's periodic gait was not found ({exc})") from None
        scale = (1.0, 1.0)  # the start is the gait's state, not scaled rates
    else:
        run = contact_run.simulate_from(scene, fp.x, fp.step_period_s, scale)
        if adjust:  # the adjusted start must walk at least as well as the scene's own
            plain = contact_run.simulate_from(scene, fp.x, fp.step_period_s, None)
            adj["kept"], adj["kept_reason"] = better_start(plain[1], run[1])
            if adj["kept"] == "scene":
                run, scale = plain, None
        walker, res, x0, step_length = run
    if periodic and gait is None:
        from walkerlab.analysis.contact_periodic import (
            PeriodicGaitError,
            find_contact_periodic_gait,
        )

        try:
            gait = find_contact_periodic_gait(walker, fp.x, time_limit_s=cs.periodic_time_limit_s)
        except PeriodicGaitError as exc:
            gait_error = exc
    run = ContactSimRun(
        walker=walker, result=res, samples=contact_run.named_trajectory(walker, res, LEGS),
        initial_state=x0, step_length_m=step_length, fixed_point=fp.x,
        fixed_point_names=fp.state_names, legs=LEGS,
        rate_names=[" ".join(rate_states(walker, leg)) for leg in LEGS],
        initial_rate_scale=np.asarray(scale if scale is not None else cs.initial_rate_scale),
        stiffness_family=law.stiffness_family,
        drop=drop_test(scene, walker.total_mass), drop_speed_m_per_s=DROP_SPEED,
        summary=run_summary(res), gait=gait, gait_error=gait_error, adjust=adj)
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
    up = (artifact_path(scene, runs_root, "fixedpoint"),)
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
