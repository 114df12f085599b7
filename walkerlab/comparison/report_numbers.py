"""The numbers a report states that no artifact stores: computed from loaded artifacts.

The report (:mod:`walkerlab.report`) only writes text; what it states beyond the stored
datasets is computed here, once, before it is written: Table 3's columns of the rigid and
contact runs, the rigid run's energy drift within a phase and swing-foot clearance above
the scene's ground, the step
length the published fixed point implies, the phase-aligned error of the comparison, the
contact walker's mean stance-foot creep, and the basin's area in the basin map's slice.
"""

from __future__ import annotations

import numpy as np

from walkerlab.analysis.robustness.basin_area import basin_area
from walkerlab.comparison.tables import table3
from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.published import for_scene


def report_numbers(scene, arts: dict) -> dict:
    """What the report computes from the loaded artifacts ``arts`` (``{stage: artifact}``,
    :mod:`walkerlab.io.schemas`); keys as the fields of
    :class:`walkerlab.report.build.ReportInputs`.

    Returns
    -------
    dict
        With ``simulate`` loaded: ``gait_columns`` (Table 3 columns by label,
        :func:`walkerlab.comparison.tables.table3`), ``energy_drift`` ([J] and relative,
        :func:`walkerlab.analysis.gait.checks.energy_drift_in_swing`), ``swing_clearance``
        (lowest swing-foot height above the scene's ground [m],
        :func:`walkerlab.analysis.gait.checks.run_ground`) and ``clearance_ground`` (that
        ground's name) and, where the scene's published
        module prints Eq. (11) and Table 3, ``published_step_length_m``
        (:func:`published_step_length`); with ``compare``: ``phase_error``
        (:func:`phase_aligned_angle_error`); with ``contact-sim``: ``mean_stance_slip_mm``
        (:func:`mean_stance_slip`); with ``basin``: ``basin_area``
        (:class:`walkerlab.analysis.robustness.basin_area.BasinArea`).

    Raises
    ------
    ValueError
        The scene's ``published`` key names no module.
    """
    out: dict = {}
    sim, contact = arts.get("simulate"), arts.get(CONTACT_SIM.name)
    if sim is not None:
        from walkerlab.analysis.gait.checks import (  # light
            energy_drift_in_swing,
            run_ground,
            swing_foot_clearance,
        )

        out["energy_drift"] = energy_drift_in_swing(sim.samples)
        ground = run_ground(scene, sim.samples)
        out["swing_clearance"] = swing_foot_clearance(sim.samples, ground)
        out["clearance_ground"] = ground.name
        trajs = {"ours, ideal": sim.samples} | (
            {"ours, contact": contact.samples} if contact is not None else {})
        out["gait_columns"] = table3(trajs, sim.total_mass_kg, sim.gravity_m_per_s2)
        per = getattr(contact, "periodic", None)
        if per is not None and per.found:  # the contact model's own gait: no start-up steps
            out["gait_columns"]["ours, contact periodic gait"] = periodic_gait_column(per)
        pub = for_scene(scene)
        if getattr(pub, "TABLE3", None) and getattr(pub, "EQ11_STATE", None) is not None \
                and getattr(pub, "STEP_LENGTH_M", None) is not None:
            out["published_step_length_m"] = published_step_length(
                dict(zip(pub.EQ11_NAMES, pub.EQ11_STATE)), float(scene.walker.leg_length_m))
    if arts.get("compare") is not None:
        out["phase_error"] = phase_aligned_angle_error(arts["compare"])
    if contact is not None:
        out["mean_stance_slip_mm"] = mean_stance_slip(contact)
    if arts.get("basin") is not None:
        out["basin_area"] = basin_area(arts["basin"])
    return out


def periodic_gait_column(per) -> dict[str, float]:
    """Table 3 entries of the contact model's periodic gait (``per``: a loaded
    :class:`walkerlab.io.schemas.contact_sim.PeriodicGait`): both steps its step period
    [s], the cycle two of them, the speed step length / step period [m/s]; energies NaN (the
    gait is a fixed point, not a run)."""
    T, L = float(per.step_period_s), float(per.step_length_m)
    return {"t_left_s": T, "t_right_s": T, "t_cycle_s": 2 * T, "v_com_m_per_s": L / T,
            "E_avg_J": np.nan, "E_avg_stance_frame_J": np.nan, "step_length_m": L,
            "step_length_left_m": L, "step_length_right_m": L, "n_steps": np.nan}


def published_step_length(state: dict, leg_length_m: float) -> float:
    """Step length a published fixed point implies, Δx = 2 L sin((θ_stance − θ_swing)/2) [m]
    (the chord between the feet of two legs of length ``leg_length_m`` [m]; ``state``:
    ``stance_angle``, ``swing_angle`` [rad] by name, e.g. Eq. (11) of the paper)."""
    return 2 * leg_length_m * np.sin((state["stance_angle"] - state["swing_angle"]) / 2)


def phase_aligned_angle_error(c) -> tuple[float, float, int] | None:
    """Largest phase-aligned angle error of a loaded comparison ``c``
    (:class:`walkerlab.io.schemas.compare.Comparison`): over every compared step and over
    the last one [rad], and that step's number; None without phase-aligned angle errors."""
    if c.phase_errors is None or c.step_phase is None or not c.step_phase.size:
        return None
    ang = [e for n, e in c.phase_errors.items() if c.error_units.get(n) == "rad"]
    if not ang:
        return None
    sp = c.step_phase
    a = np.max(np.abs(np.vstack(ang)), axis=0)
    last = sp >= np.floor(sp[-1])
    return float(a.max()), float(a[last].max()), int(np.floor(sp[-1]))


def mean_stance_slip(c) -> float:
    """Mean magnitude of the per-step stance-foot slip [mm] of a loaded contact run ``c``
    (:class:`walkerlab.io.schemas.contact_sim.ContactSimArtifact`; steps whose phase had not
    ended are left out); NaN when no step has one."""
    slips = c.steps["stance_slip_mm"]
    if not np.isfinite(slips).any():
        return float("nan")
    return float(np.nanmean(np.abs(slips)))
