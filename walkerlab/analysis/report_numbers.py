"""The numbers a report states that no artifact stores: computed from loaded artifacts.

The report (:mod:`walkerlab.report`) only writes text; what it states beyond the stored
datasets is computed here, once, before it is written: Table 3's columns of the rigid and
contact runs, the rigid run's energy drift within a phase and swing-foot clearance, and the
basin's area in the basin map's slice.
"""

from __future__ import annotations


def report_numbers(scene, arts: dict) -> dict:
    """What the report computes from the loaded artifacts ``arts`` (``{stage: artifact}``,
    :mod:`walkerlab.io.schemas`); keys as the fields of
    :class:`walkerlab.report.build.ReportInputs`.

    Returns
    -------
    dict
        ``gait_columns``: Table 3 columns by label (:func:`walkerlab.analysis.tables.table3`),
        ``energy_drift``: [J] and relative
        (:func:`walkerlab.analysis.gait_checks.energy_drift_in_swing`),
        ``swing_clearance``: lowest swing-foot height above the slope [m] - these three when
        ``simulate`` is loaded; ``basin_area``: :class:`walkerlab.analysis.basin_area.BasinArea`
        when ``basin`` is.
    """
    out: dict = {}
    sim, contact = arts.get("simulate"), arts.get("contact-sim")
    if sim is not None:
        from walkerlab.analysis.gait_checks import energy_drift_in_swing, swing_foot_clearance
        from walkerlab.analysis.tables import table3

        out["energy_drift"] = energy_drift_in_swing(sim.samples)
        out["swing_clearance"] = swing_foot_clearance(sim.samples, scene.slope.phi_rad)
        trajs = {"ours, ideal": sim.samples} | (
            {"ours, contact": contact.samples} if contact is not None else {})
        out["gait_columns"] = table3(trajs, sim.total_mass_kg, sim.gravity_m_per_s2)
    if arts.get("basin") is not None:
        from walkerlab.analysis.basin_area import basin_area

        out["basin_area"] = basin_area(arts["basin"])
    return out
