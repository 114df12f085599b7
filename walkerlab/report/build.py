"""Assemble ``report.md`` and the self-contained ``report.html`` from loaded artifacts.

:func:`write_report` is all the report stage calls after it has run what the scene needs
and loaded its artifacts (:class:`ReportInputs`): it opens no artifact, draws no figure
and computes no result; it never runs a stage.
"""

from __future__ import annotations

import datetime as _dt
import json
import platform
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import walkerlab
from walkerlab.io.runpaths import atomic_text
from walkerlab.published import for_scene
from walkerlab.report import contact_sections, sections, study_sections
from walkerlab.report.attribution_section import attribution_section
from walkerlab.report.figures_section import figures_section, ledger_section
from walkerlab.report.markdown import details, num, table, text, to_html
from walkerlab.report.robustness_section import mfpt_section, robustness_section
from walkerlab.report.workprecision_section import workprecision_summary
from walkerlab.units import for_scene as units_for_scene


@dataclass
class ReportInputs:
    """What the report shows: loaded artifacts and the numbers computed from them.

    Attributes
    ----------
    artifacts : dict[str, object]
        Loaded artifacts (:mod:`walkerlab.io.schemas`) by stage name: ``fixedpoint``,
        ``simulate``, ``contact-sim``, ``compare``, ``workprecision``, ``basin``,
        ``bifurcation`` and ``bifurcation_<field>``, ``stability_map_<kind>``; an absent
        stage gives no section.
    gait_columns : dict[str, dict[str, float]]
        Table 3 columns (:func:`walkerlab.comparison.tables.table3`) by label ("ours, ideal",
        "ours, contact").
    energy_drift : (float, float)
        Largest energy change within a phase of the rigid run [J] and relative [-]
        (:func:`walkerlab.analysis.gait.checks.energy_drift_in_swing`).
    swing_clearance : float
        Lowest swing-foot height above the scene's ground [m] (NaN: none;
        :func:`walkerlab.analysis.gait.checks.swing_foot_clearance`).
    clearance_ground : str
        What that ground is (:attr:`walkerlab.models.ground.Ground.name`: ``slope``,
        ``treads``, ``footholds``, ``profile``, ``ground``).
    basin_area : BasinArea or None
        The basin's area in the basin map's slice
        (:func:`walkerlab.analysis.robustness.basin_area.basin_area`; None: no basin).
    published_step_length_m : float
        Step length the published fixed point (Eq. (11)) implies [m] (NaN: none printed).
    phase_error : (float, float, int) or None
        Largest phase-aligned angle error of the comparison [rad], over its last step, and
        that step's number (None: no comparison).
    mean_stance_slip_mm : float
        Mean stance-foot slip per step of the contact run [mm] (NaN: none).
    animation : bool
        Whether ``animation.gif`` in the figures folder was drawn from the report's current
        artifacts (shown only then).
    left_out : str
        The one line on the run folder's artifacts (and animation) the report leaves out,
        and why ('' when none); written into the report under its summary.
    bifurcation_onsets : dict[str, (float, float)]
        Period-doubling onset and fall onset (NaN: none on the grid) in the grid's unit by
        bifurcation artifact key (:func:`walkerlab.studies.bifurcation.onset_value`,
        :func:`walkerlab.studies.bifurcation.fall_onset`).

    The stage computes them before the report is written
    (:func:`walkerlab.stages.report.load_inputs`), mostly through
    :func:`walkerlab.comparison.report_numbers.report_numbers`.
    """

    artifacts: dict
    gait_columns: dict = field(default_factory=dict)
    energy_drift: tuple = (float("nan"), float("nan"))
    swing_clearance: float = float("nan")
    clearance_ground: str = "slope"
    basin_area: object = None
    published_step_length_m: float = float("nan")
    phase_error: tuple | None = None
    mean_stance_slip_mm: float = float("nan")
    bifurcation_onsets: dict = field(default_factory=dict)
    animation: bool = True
    left_out: str = ""


def _header(scene) -> list[str]:
    import scipy

    return [f"# walkerlab report — scene `{scene.name}`", "",
            f"- source: {text(scene.source) if scene.source else '—'}",
            f"- walkerlab {walkerlab.__version__}, Python {platform.python_version()}, "
            f"numpy {np.__version__}, scipy {scipy.__version__}, machine {platform.machine()} "
            f"({platform.processor() or platform.system()})",
            f"- generated {_dt.datetime.now(_dt.UTC).strftime('%Y-%m-%d %H:%M UTC')}",
            f"- units: {units_for_scene(scene).sentence()}",
            f"- slope φ = {num(scene.slope.phi_rad)} rad ({num(np.degrees(scene.slope.phi_rad))}°);"
            f" ideal equations: `{scene.ideal.variant}`; solver {scene.solver.method} "
            f"rtol {scene.solver.rtol:g} atol {scene.solver.atol:g}", ""]


def write_report(scene, inputs: ReportInputs, report_dir: Path, figures_dir: Path,
                 done: Iterable = ()) -> Path:
    """Write ``report.md`` and ``report.html`` into ``report_dir``.

    Parameters
    ----------
    scene : Scene
    inputs : ReportInputs
        The loaded artifacts and the numbers computed from them.
    report_dir, figures_dir : Path
        Output folder and the folder of the figures (PNG) to embed.
    done : iterable of StageOutcome-like objects
        ``stage``, ``path``, ``reused``, ``wall_time_s`` of what the report stage ran.

    Returns
    -------
    Path
        The HTML report.

    Raises
    ------
    ValueError
        The scene's ``published`` key names no module.
    """
    report_dir = Path(report_dir)
    report_dir.mkdir(parents=True, exist_ok=True)
    pub = for_scene(scene)

    md = _header(scene)
    arts = inputs.artifacts
    md += sections.summary_section(scene, inputs, pub)
    if inputs.left_out:
        said = inputs.left_out.removeprefix("report: ")
        md += [f"*{text(said[:1].upper() + said[1:])}.*", ""]
    done = list(done)
    if done:
        md += details("What ran (stages, artifacts, compute time)",
                      table(["stage", "artifact", "status", "compute [s]"],
                            [[o.stage, f"`{o.path}`", "reused" if o.reused else "computed",
                              num(float(o.wall_time_s), 3)] for o in done]))
    if "fixedpoint" in arts:
        md += sections.fixedpoint_section(arts["fixedpoint"], pub)
    md += contact_sections.initial_states_section(scene, arts)  # Table 2, then Table 3
    md += sections.gait_section(scene, inputs, pub)
    rel = Path(figures_dir).relative_to(report_dir) if Path(figures_dir).is_relative_to(
        report_dir) else Path(figures_dir)
    md += ledger_section(scene, Path(figures_dir), str(rel), arts)  # beside the gait
    md += contact_sections.sections(scene, inputs)
    md += attribution_section(scene, arts)
    md += workprecision_summary(scene, arts)
    md += study_sections.bifurcation_section(arts, inputs.bifurcation_onsets, pub)
    md += study_sections.basin_section(arts)
    md += robustness_section(arts, inputs.basin_area)
    md += mfpt_section(arts)
    md += figures_section(Path(figures_dir), str(rel), arts, units_for_scene(scene),
                          inputs.animation)
    md += ["## Scene", ""]
    md += details("Resolved scene (JSON)", "\n".join(
        ["```json", json.dumps(scene.model_dump(mode="json", exclude_none=True), indent=1),
         "```"]))
    body = "\n".join(md)
    atomic_text(report_dir / "report.md", body)
    html_path = report_dir / "report.html"
    atomic_text(html_path, to_html(body, report_dir))
    return html_path
