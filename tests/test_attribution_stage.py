"""The Section-5 attribution as a cached stage and report section (issue 25, item 6)."""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from walkerlab.config import load_scene

ROOT = Path(__file__).resolve().parents[1]


def _fake_run():
    from walkerlab.analysis.contact.attribution import Attribution
    from walkerlab.io.schemas.attribution import AttributionRun

    a = Attribution(7.37e-3, -10.94e-3, 6.57e-3, -10.29e-3, 0.467e-3, -0.325e-3, 0.338e-3,
                    -0.330e-3, {"normal_damping": 1.131, "friction_impact": 0.00707,
                                "friction_stance": 0.0926})
    adj = {"rate_scale": (1.0, 1.1), "adjusted_s": 0.69879, "unadjusted_s": float("nan"),
           "rigid_from_adjusted": "fall", "rigid_heel_strikes": 2}
    return AttributionRun(a, adj, 0.703597)


def test_attribution_artifact_round_trip_and_report_section(tmp_path):
    """Writer -> loader keeps every number; the section reads the loaded object, in the
    scene's units, and says the paper's x1.1 start lies outside the rigid walker's basin
    (the rigid run fell after 2 heel strikes)."""
    from walkerlab.io.artifacts import write_artifact
    from walkerlab.io.schemas.attribution import load_attribution, write_attribution
    from walkerlab.report.attribution_section import attribution_section

    run = _fake_run()
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    p = tmp_path / "attribution.h5"
    write_artifact(p, "attribution", scene, "k", lambda f: write_attribution(f, run), 0.0)
    art = load_attribution(p)
    assert art.gaps["gap"] == pytest.approx((7.37e-3, -10.94e-3))
    assert art.gaps["residual"] == pytest.approx((0.338e-3, -0.330e-3))
    assert art.energy_J["normal_damping"] == 1.131 and np.isnan(art.unadjusted_period_s)
    md = "\n".join(attribution_section(scene, {"attribution": art}))
    assert "| friction creep (stiction regularisation → 0) | 6.570 | -10.29 |" in md
    assert "outside the rigid walker's basin" in md and "after 2 heel strikes" in md
    assert "normal damping 1.131 J" in md
    assert attribution_section(scene, {}) == []


def test_report_runs_attribution_only_with_full():
    """Opt-in: the default report plan leaves it out, ``--full`` runs it (contact scenes)."""
    from walkerlab.stages.pipeline import needs, report_plan

    scene = load_scene(ROOT / "configs" / "paper.yaml")
    assert needs("attribution", scene) == ("fixedpoint",)
    assert "attribution" not in report_plan(scene)
    assert report_plan(scene, full=True)[-1] == "attribution"
    ideal_only = scene.model_copy(update={"contact": None})
    assert "attribution" not in report_plan(ideal_only, full=True)


def test_a_walker_without_the_attributions_gaits_is_left_out_of_the_full_report(tmp_path):
    """The attribution's seven periodic-gait searches need the contact periodic gait, and
    two of them a contact 1000 times stiffer and one with the stiction velocity / 100: a
    rimless wheel has no contact periodic gait, and for a walker in 3D those contacts are
    beyond the stride map's integrator (440 s a stride at 1000 times the stiffness). The
    full report leaves the stage out, and the stage asked for directly refuses in one
    line naming the scene, before any work (nothing written)."""
    from walkerlab.stages import attribution
    from walkerlab.stages.common import StageError
    from walkerlab.stages.pipeline import report_plan

    for name, why in (("hip_width_stabilised", "beyond the stride map's integrator in 3D"),
                      ("rimless_wheel", "a rimless wheel has not")):
        scene = load_scene(ROOT / "configs" / f"{name}.yaml")
        plan = report_plan(scene, full=True)
        assert "contact-sim" in plan and "attribution" not in plan
        with pytest.raises(StageError, match=f"^attribution: scene '{name}': .*{why}") as e:
            attribution.run(scene, tmp_path)
        assert "\n" not in str(e.value)
    assert not any(tmp_path.iterdir())


def test_attribution_stage_writes_and_reuses(tmp_path, monkeypatch):
    """The stage runs the analysis once from fixedpoint.h5 and reuses its artifact (the
    analysis itself, ~17 s CPU on the paper scene, is replaced by its recorded numbers:
    scripts/attribution_table.py runs it for real)."""
    from walkerlab.analysis.contact import attribution as A
    from walkerlab.stages import pipeline

    calls = []
    run = _fake_run()
    monkeypatch.setattr(A, "attribute", lambda w, ideal: calls.append(ideal) or run.attribution)
    monkeypatch.setattr(A, "adjustment_effect", lambda s, ideal, **_: run.adjustment)
    scene = load_scene(ROOT / "configs" / "paper.yaml")
    out = pipeline.run("attribution", scene, tmp_path)
    assert not out.reused and len(calls) == 1
    assert calls[0].period_s == pytest.approx(0.7036, abs=5e-5)  # from fixedpoint.h5
    assert isinstance(calls[0], SimpleNamespace)
    assert pipeline.run("attribution", scene, tmp_path).reused and len(calls) == 1


@pytest.mark.slow  # ~60 s cold: the held view's kernels, the gait, seven stride-map searches
def test_a_3d_walker_holding_its_heading_gets_the_sections_attribution(tmp_path):
    """configs/hip_width_stabilised.yaml with the rigid stance foot's assumption in its
    contact (``contact.hold_heading: true``, ``torsional_friction_m: 0``: the base does not
    turn, the foot spins freely) has no stiff torsional mode, so the attribution's creep-free
    and 1000 times stiffer contacts are affordable in 3D (measured 20 s; with the heading
    free it is refused, the test above).  Its gap to the rigid step period closes as creep +
    compliance + residual to rounding; the residual, the stiff creep-free contact's period
    against the rigid one, is under a fifth of the gap (measured: gap +0.786 ms, creep
    +0.437, compliance +0.263, residual +0.087), and the gap is the contact periodic gait's
    period less the rigid one, within 0.2 % of it."""
    import h5py
    import yaml

    from walkerlab.config.schema import Scene
    from walkerlab.stages import pipeline
    from walkerlab.stages.pipeline import report_plan

    raw = yaml.safe_load((ROOT / "configs" / "hip_width_stabilised.yaml").read_text())
    raw["contact"].update(hold_heading=True, torsional_friction_m=0.0)
    scene = Scene.model_validate(raw)
    assert report_plan(scene, full=True)[-1] == "attribution"
    out = pipeline.run("attribution", scene, tmp_path)
    with h5py.File(out.path) as f:
        gap, creep, comp, res = (float(f[k]["period"][()]) for k in
                                 ("gap", "creep", "compliance", "residual"))
        rigid = float(f.attrs["rigid_period_s"])
    assert gap == pytest.approx(creep + comp + res, abs=1e-12)
    assert 0 < abs(res) < 0.2 * abs(gap)
    assert 1e-4 < gap / rigid < 3e-3
