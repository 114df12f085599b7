"""Report prose from the scene's own artifacts (issue 25 item 5): the Fig. 8 paragraph reads
its numbers from compare.h5 / contact_sim.h5, and the paper's printed error appears only for
``published: paper`` (the kneed, round-feet and rods reports showed the paper's 0.5 mm)."""

from pathlib import Path

import numpy as np
import pytest

from walkerlab.comparison.report_numbers import report_numbers
from walkerlab.config import load_scene
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
