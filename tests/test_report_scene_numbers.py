"""Report prose from the scene's own artifacts (issue 25 item 5): the Fig. 8 paragraph reads
its numbers from compare.h5 / contact_sim.h5, and the paper's printed error appears only for
``published: paper`` (the kneed, round-feet and rods reports showed the paper's 0.5 mm)."""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

from tests.cli_run import IDEAL
from tests.cli_run import run_cli as _cli
from walkerlab.comparison.report_numbers import report_numbers
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.io.schemas.compare import load_compare
from walkerlab.io.schemas.contact_sim import load_contact_sim
from walkerlab.report.build import ReportInputs
from walkerlab.report.contact_sections import compare_section
from walkerlab.report.markdown import num
from walkerlab.stages import pipeline

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_fig8_prose_from_artifacts_and_paper_sentence_only_for_published_paper(tmp_path):
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    out = pipeline.run("compare", scene, tmp_path)
    arts = {"compare": load_compare(out.path),
            "contact-sim": load_contact_sim(out.path.with_name("contact_sim.h5"))}
    slip_mm = float(np.nanmean(np.abs(arts["contact-sim"].steps["stance_slip_mm"])))
    stride = float(arts["compare"].metrics["contact"]["t_cycle_s"])
    text = "\n".join(compare_section(scene, ReportInputs(arts, **report_numbers(scene, arts))))
    assert f"creeps {num(slip_mm, 3)} mm per step" in text
    assert f"stride lasts {num(stride, 4)} s" in text
    assert "Phase-aligned" in text
    assert "The paper reports" in text
    other = scene.model_copy(update={"published": None})
    text = "\n".join(compare_section(other, ReportInputs(arts, **report_numbers(other, arts))))
    assert "paper" not in text.lower() and "0.5 mm" not in text


def test_table3_shows_the_contact_periodic_gait_beside_the_run():
    """Table 3's contact column averages the run's start-up steps; the contact model's own
    periodic gait gets its column (both steps its period, speed = step length / period)."""
    from walkerlab.comparison.report_numbers import periodic_gait_column
    from walkerlab.io.schemas.contact_sim import PeriodicGait

    col = periodic_gait_column(PeriodicGait(True, "found", step_period_s=0.711,
                                            step_length_m=0.3605))
    assert col["t_left_s"] == col["t_right_s"] == 0.711
    assert col["t_cycle_s"] == 2 * 0.711
    assert col["v_com_m_per_s"] == pytest.approx(0.3605 / 0.711)
    assert np.isnan(col["E_avg_J"])


# -------------------- the energy ledger, a section of its own
POWERED = ROOT / "configs" / "powered_compass.yaml"


def _ledger_sim():
    keys = ("push_off_work", "actuator_work_positive", "actuator_work_negative",
            "heel_strike_loss", "internal_collision_loss", "damper_work", "potential_work",
            "closure", "cost_of_transport")
    from walkerlab.units import Units

    return SimpleNamespace(ledger={k: [0.1, 0.1] for k in keys}, units=Units(), samples=None)


def test_the_energy_ledger_is_a_section_beside_the_gait_not_under_figures(tmp_path,
                                                                          monkeypatch):
    from walkerlab.report import build, contact_sections, sections

    for mod, name in ((sections, "summary_section"), (contact_sections, "sections"),
                      (contact_sections, "initial_states_section")):
        monkeypatch.setattr(mod, name, lambda *a, **k: [])
    monkeypatch.setattr(sections, "gait_section",
                        lambda scene, inputs, pub: ["## Gait characteristics", ""])
    for stem in ("energy_ledger", "fig10_energy"):
        (tmp_path / f"{stem}.png").write_bytes(b"")
    scene = load_scene(POWERED)
    build.write_report(scene, build.ReportInputs({"simulate": _ledger_sim()}), tmp_path,
                       tmp_path)
    md = (tmp_path / "report.md").read_text()
    gait, ledger = md.index("## Gait characteristics"), md.index("## Energy ledger and cost")
    figures = md.index("## Figures")
    assert gait < ledger < figures
    assert md.index("energy_ledger.png") < figures  # the figure moved with its table
    assert md.index("Cost of transport") < figures and md.count("energy_ledger.png") == 1


def test_a_spring_written_as_an_actuator_law_is_named_as_motor_work():
    from walkerlab.report.figures_section import spring_law_note

    d = yaml.safe_load(POWERED.read_text())
    d["walker"]["actuation"]["torques"] = [
        {"joint": "hip", "law": {"stiffness_n_m_per_rad": 20.0}}]
    note = spring_law_note(scene_from_dict(d))
    assert "walker.actuation.torques.0 (hip)" in note and "motor work, no regeneration" in note
    assert "walker.springs" in note
    assert spring_law_note(load_scene(POWERED)) == ""  # push-off alone
    # Kuo's spring scaled by the massless foot's mass does no work: not named
    assert spring_law_note(load_scene(ROOT / "configs" / "kuo2002.yaml")) == ""


# -------------------- the gait simulate starts from; a damper is not drift


# ------------------------------------------------------------------ 10: the gait simulate uses
@pytest.mark.slow
def test_report_of_a_scene_without_fixedpoint_section_shows_the_gait_simulate_starts_from(
        tmp_path):
    scene = tmp_path / "nofp.yaml"
    scene.write_text(yaml.safe_dump({k: v for k, v in IDEAL.items() if k != "fixedpoint"}))
    runs = tmp_path / "runs"
    code, err, _ = _cli("simulate", scene, "--runs-dir", runs)  # runs the fixed point first
    assert code == 0, err
    code, err, _ = _cli("report", scene, "--runs-dir", runs)
    assert code == 0, err
    md = (runs / "nofp" / "report" / "report.md").read_text()
    # before: left out ("an earlier standalone run: the scene has no 'fixedpoint' section")
    assert "## Fixed point of the Poincaré map" in md and "Floquet multipliers" in md
    assert "fixedpoint.h5 (an earlier standalone run" not in md


# ------------------------------------------------------------------ 11: a damper is not drift
def test_a_dampers_loss_is_named_and_the_balance_checked_with_it():
    """Hip spring 20 N m/rad with a 0.05 N m s/rad damper: the report called the damper's
    0.026 J "energy drift between impacts" (3.7e-9 J without the damper).  The energy ledger
    of the run (``simulate.h5``, ledger/) has the damper's work and the balance's closure."""
    from types import SimpleNamespace

    from walkerlab.report.sections import energy_check
    from walkerlab.units import Units

    def sim(damper):
        n = 3
        return SimpleNamespace(ledger={
            "damper_work": np.full(n, damper), "actuator_work_positive": np.zeros(n),
            "actuator_work_negative": np.zeros(n), "closure": np.array([-2e-13, 2.5e-13, 0])})

    text, rows = energy_check(sim(-0.0527), (0.026, 1.7e-4), Units())
    assert "drift" not in text and "dampers dissipate 0.0527 J per step" in text, text
    assert "closes to 2.5e-13 J" in text, text
    assert [r[0] for r in rows] == ["damper work per step (energy ledger)",
                                    "energy balance closure, largest per step (ledger)"]
    text, rows = energy_check(sim(0.0), (3.7e-9, 1e-11), Units())  # no damper: drift is the check
    assert text.startswith("energy drift between impacts 3.7e-09 J"), text


# ------------------------------------------------ a minimal scene of one's own (issue 64, 3)
#: a user's minimal contact scene: walker, slope, contact, terrain, contact_sim (no
#: fixedpoint, no simulate); every stage runs on it standalone
MINIMAL = {"walker": IDEAL["walker"], "slope": IDEAL["slope"],
           "contact": yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())["contact"],
           "terrain": {"kind": "checkerboard", "patch_width_m": 0.2},
           "contact_sim": {"n_strides": 2}}


def test_a_minimal_contact_scene_plans_the_gait_its_contact_run_starts_from():
    plan = pipeline.report_plan(scene_from_dict(MINIMAL | {"name": "mini"}))
    # before: [] (an empty report, exit 0); `walkerlab contact-sim` runs the same two
    assert plan == ["fixedpoint", "contact-sim"]


def test_a_scene_that_gives_the_report_nothing_is_refused_naming_the_sections(tmp_path):
    scene = tmp_path / "bare.yaml"
    scene.write_text(yaml.safe_dump({k: MINIMAL[k] for k in ("walker", "slope", "contact")}))
    code, err, _ = _cli("report", scene, "--runs-dir", tmp_path / "runs")
    assert code == 1 and len(err.splitlines()) == 1, err
    assert all(f"'{s}'" in err for s in ("fixedpoint", "simulate", "contact_sim")), err
    assert not (tmp_path / "runs" / "bare" / "report").exists()


def test_a_contact_artifact_left_out_is_said_why_in_the_scenes_own_terms():
    from walkerlab.stages.report_inputs import not_run

    has_contact = scene_from_dict({k: MINIMAL[k] for k in ("walker", "slope", "contact")}
                                  | {"name": "c", "simulate": IDEAL["simulate"]})
    # before: "the scene has no 'contact' section" (it has one) and "the scene has needs both"
    assert "no 'contact' section" not in not_run(has_contact, "contact-sim")
    assert "'contact_sim'" in not_run(has_contact, "contact-sim")
    assert not_run(scene_from_dict(IDEAL | {"name": "i"}), "compare") == "no 'contact' section"


@pytest.mark.slow
def test_the_report_of_a_minimal_contact_scene_shows_its_gait_and_contact_run(tmp_path):
    scene = tmp_path / "mini.yaml"
    scene.write_text(yaml.safe_dump(MINIMAL))
    runs = tmp_path / "runs"
    code, err, _ = _cli("contact-sim", scene, "--runs-dir", runs)  # the standalone run first
    assert code == 0, err
    code, err, _ = _cli("report", scene, "--runs-dir", runs)
    assert code == 0, err
    md = (runs / "mini" / "report" / "report.md").read_text()
    summary = md.split("## Summary", 1)[1].split("\n## ", 1)[0]
    assert "**Gait found**: yes" in summary and "**Contact walker walks**" in summary
    assert "leaves out" not in err


# ------------------------------------------- what the report leaves out, named in it (64, 10)
def test_an_animation_not_drawn_from_the_current_run_is_left_out_and_named(tmp_path):
    from walkerlab.io.runpaths import figures_dir
    from walkerlab.stages.report_inputs import report_artifacts

    scene = scene_from_dict(IDEAL | {"name": "anim"})
    figs = figures_dir(scene, tmp_path)
    figs.mkdir(parents=True)
    (figs / "animation.gif").write_bytes(b"GIF89a")  # an earlier `walkerlab animate`'s
    _paths, line = report_artifacts(scene, tmp_path, [])
    assert "animation.gif (not drawn from this run folder's simulate.h5" in line


def test_the_report_file_says_what_it_leaves_out(tmp_path):
    from walkerlab.report.build import write_report

    scene = scene_from_dict(IDEAL | {"name": "left"})
    inputs = ReportInputs({}, left_out="report: leaves out mfpt.h5 (computed for other "
                                       "settings: rerun `walkerlab mfpt`)", animation=False)
    write_report(scene, inputs, tmp_path / "report", tmp_path / "figures")
    md = (tmp_path / "report" / "report.md").read_text()
    assert "*Leaves out mfpt.h5 (computed for other settings: rerun `walkerlab mfpt`).*" in md


def test_a_published_value_far_from_ours_is_flagged_in_its_summary_row():
    """Issue 64 item 10: "0.5278 vs published 0.0246 m/s" stood unflagged in the summary
    (the explanation three sections later)."""
    from walkerlab.published import paper
    from walkerlab.report.sections import _gait_rows
    from walkerlab.units import Units

    ideal = {"t_cycle_s": 1.407, "v_com_m_per_s": 0.5278, "E_avg_stance_frame_J": 150.2,
             "step_length_m": 0.3714}
    rows = {r[0]: r[3] for r in _gait_rows(ideal, paper, Units())}
    speed = rows["Average velocity of robot"]
    assert speed.startswith("0.0246 ⚠ ours is 21.5× this")
    assert rows["step length"].startswith("0.0342 ⚠ ours is 10.9× this")
    assert rows["One cycle period"] == "1.39"  # 1.407 against 1.39: no flag


def test_the_contact_outcome_is_one_sentence():
    """Issue 64 item 10: "Outcome: t_final — walked: 10 heel strikes by the end time Walks
    (the verdict from its steps): yes"."""
    from walkerlab.report.contact_sections import _outcome_sentence

    said = _outcome_sentence(("t_final", "walked: 10 heel strikes by the end time"), True, "")
    assert said == ("Outcome: the run ended by **t_final** (walked: 10 heel strikes by the "
                    "end time), and by the verdict from its steps the walker walks.")
    assert _outcome_sentence(("fall", "fall"), False, "it fell in step 3").endswith(
        "the walker **does not walk** (it fell in step 3).")
