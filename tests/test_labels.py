"""Labels, numbers, figures and report text without rough edges (issue 18, part 5).

Each test asserts on produced text, figure objects or artifacts: units follow the scene
(a nondimensional scene says so everywhere), one number formatter, the paper cited by
title rather than a file path, figures in paper order with colour bars and the right
geometry, work-precision choices that respect the timing noise, help texts with units.
"""

from __future__ import annotations

import re

import h5py
import numpy as np
import pytest

from walkerlab.config import SceneError, load_scene, scene_from_dict
from walkerlab.io.trajectory import NamedTrajectory
from walkerlab.report.markdown import num
from walkerlab.units import Units

NONDIM = Units("nondimensional")
SI_U = Units("SI")


# --------------------------------------------------------------------------- units
def test_nondimensional_scene_is_explicit_and_validated():
    """configs/simplest.yaml and round_feet.yaml say ``units: nondimensional``; a
    nondimensional scene with g != 1 is refused, naming the field."""
    assert load_scene("configs/simplest.yaml").units == "nondimensional"
    assert load_scene("configs/round_feet.yaml").units == "nondimensional"
    assert load_scene("configs/paper.yaml").units == "SI"
    d = load_scene("configs/simplest.yaml").model_dump(mode="json", exclude_none=True)
    d["walker"]["gravity_m_per_s2"] = 9.81
    with pytest.raises(SceneError, match="units.*gravity_m_per_s2 must be 1"):
        scene_from_dict(d)
    d["units"] = "furlongs"
    with pytest.raises(SceneError, match="units"):
        scene_from_dict(d)


def test_unit_labels_map_every_dimension_once():
    """SI labels pass through; nondimensional ones name the scene's units, token by token
    (``rad`` stays, ``rad/s`` is not read as ``rad`` + ``s``)."""
    assert SI_U("rad, rad/s") == "rad, rad/s" and SI_U.time == "s"
    assert NONDIM("s") == "√(l/g)"
    assert NONDIM("m/s") == "√(g l)"
    assert NONDIM("J") == "M g l"
    assert NONDIM("mm") == "10⁻³ l"  # artifacts store such lengths ×1e3
    assert (NONDIM.small_length, NONDIM.small_scale) == ("l", 1.0)
    assert (SI_U.small_length, SI_U.small_scale) == ("mm", 1e3)
    assert NONDIM("rad, rad/s") == "rad, rad/√(l/g)"
    assert NONDIM("rad") == "rad" and NONDIM("-") == "-" and NONDIM("deg") == "deg"
    assert NONDIM("rad, rad/s (, s)") == "rad, rad/√(l/g) (, √(l/g))"


def test_nondimensional_section_hash_differs_only_for_nondimensional_scenes():
    """Switching a scene to nondimensional changes every stage's input (its artifacts'
    labels change); an SI scene's hashes are the same as before the field existed."""
    sc = load_scene("configs/simplest.yaml")
    si = scene_from_dict({**sc.model_dump(mode="json", exclude_none=True), "units": "SI"})
    assert '"units"' not in si.section_json("walker")
    assert sc.section_json("walker") != si.section_json("walker")


@pytest.fixture(scope="module")
def simplest_run(tmp_path_factory):
    """simulate + fixedpoint of the simplest walker (nondimensional), one stride."""
    from walkerlab.stages import pipeline

    root = tmp_path_factory.mktemp("runs")
    d = load_scene("configs/simplest.yaml").model_dump(mode="json", exclude_none=True)
    d["simulate"]["strides"] = 1
    sc = scene_from_dict(d)
    out = pipeline.run("simulate", sc, root)
    return sc, root, out.path


def test_nondimensional_artifact_units_and_cli_text(simplest_run):
    """The artifact's unit attributes follow the scene (clock times stay seconds) and the
    CLI summary prints no SI unit for a nondimensional scene."""
    from walkerlab.io.runpaths import stage_artifact
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.io.schemas.simulate import load_simulate
    from walkerlab.report.text import fixedpoint_text, simulate_text

    sc, root, path = simplest_run
    with h5py.File(path, "r") as f:
        assert f.attrs["scene_units"] == "nondimensional"
        assert f["summary/mean_period_s"].attrs["unit"] == "√(l/g)"
        assert f["summary/mean_hip_speed_m_per_s"].attrs["unit"] == "√(g l)"
        assert f["summary/wall_time_s"].attrs["unit"] == "s"  # the computer's seconds
    text = simulate_text(load_simulate(path))
    assert "√(l/g)" in text and "M g l" in text and "nondimensional" in text
    assert not re.search(r"\d (s|m|m/s|J)\b(?! \(wall)", text), text
    fp = fixedpoint_text(load_fixedpoint(stage_artifact(sc, root, "fixedpoint")))
    assert "step period" in fp and "√(l/g)" in fp and "rad/√(l/g)" in fp
    assert not re.search(r"\d (s|rad/s)$", fp, re.M), fp


def test_a_walk_that_runs_off_its_profile_says_so_not_the_strides_asked():
    """Issue 56 item 16: a walk that left its profile after one heel strike said "simulated
    5 strides: 1 heel strikes"."""
    from types import SimpleNamespace

    from walkerlab.report.text import simulate_text

    s = {"mean_period_s": 0.7, "mean_step_length_m": 0.3, "mean_hip_speed_m_per_s": 0.4,
         "mean_total_energy_J": 10.0, "nfev": 100, "wall_time_s": 0.1}
    sim = SimpleNamespace(termination="heel_strike", strides_requested=5, summary=s,
                          units=SI_U, heel_strike_count=lambda: 1)
    first = simulate_text(sim).splitlines()[0]
    assert "simulated 5 strides" not in first
    assert "ended at the end of its terrain" in first and "after 1 heel strike " in first
    assert "0.5 strides of the 5 asked" in first
    sim.heel_strike_count = lambda: 10
    assert simulate_text(sim).startswith("simulated 5 strides: 10 heel strikes")


def test_nondimensional_report_and_figures_follow_the_scene(simplest_run):
    """Report summary, gait table and the figures' axis labels of a nondimensional scene."""
    from walkerlab.io.runpaths import stage_artifact
    from walkerlab.io.schemas.simulate import load_simulate
    from walkerlab.plotting import figures as F
    from walkerlab.report import sections
    from walkerlab.stages.report import load_inputs
    from walkerlab.stages.report_inputs import existing_artifacts
    from walkerlab.units import for_scene

    sc, root, _ = simplest_run
    inputs = load_inputs(sc, existing_artifacts(sc, root), root)
    md = "\n".join(sections.summary_section(sc, inputs, None)
                   + sections.gait_section(sc, inputs, None))
    assert "√(l/g)" in md and "M g l" in md
    assert not re.search(r"\| (s|J|m|m/s|mm) \|", md), md
    assert not re.search(r"\d (s|J|mm)\b", md), md
    u = for_scene(sc)
    trajs = {"ideal": load_simulate(stage_artifact(sc, root, "simulate")).samples}
    fig7 = F.fig7_angles_rates(trajs, units=u)
    assert fig7.axes[1].get_xlabel() == "time [√(l/g)]"
    assert fig7.axes[1].get_ylabel() == "angular rate [rad/√(l/g)]"
    assert fig7.axes[1].get_lines(), "rates drawn (rate names found by their unit)"
    fig10 = F.fig10_energy(trajs, units=u)
    assert fig10.axes[0].get_ylabel() == "kinetic energy [M g l]"
    tr = next(iter(trajs.values()))
    stick = F.stick_diagram(tr, "ideal", slope_rad=sc.slope.phi_rad, units=u)
    assert stick.axes[0].get_xlabel().startswith("x [l]")
    for fig in (fig7, fig10, stick):
        F.plt.close(fig)


# --------------------------------------------------------------------------- numbers
@pytest.mark.parametrize("value, text", [
    (0.9576663533079621, "0.9577"), (0.0, "0"), (-0.0, "0"), (3.0, "3"),
    (np.int64(7), "7"), (np.array(5), "5"), (np.float64(26054.0), "26054"),
    (1.5e-5, "1.500e-05"), (float("nan"), "—"), (True, "yes"), (0.364, "0.3640")])
def test_one_number_formatter(value, text):
    assert num(value) == text


def test_contact_text_counts_integers_no_repeated_outcome(tmp_path):
    """contact-sim's printout: 4 significant digits, counts as integers, the outcome once,
    and the walking run's integration told apart from the stage's 11 s."""
    from walkerlab.io.schemas.contact_sim import ContactSimArtifact
    from walkerlab.report.text import contact_text

    art = ContactSimArtifact(
        tmp_path / "contact_sim.h5", SI_U, "t_final", "completed", "completed",
        summary={"heel_strikes": (np.int64(10), "-"),
                 "max_abs_stance_slip_mm": (np.float64(0.9576663533079621), "mm"),
                 "total_bounces": (np.int64(0), "-"), "wall_time_s": (np.float64(0.124), "s")},
        stage_wall_time_s=11.0)
    text = contact_text(art)
    assert "outcome completed" in text and "(completed)" not in text
    assert "0.9577 mm" in text and not re.search(r"\d{6,}", text)
    assert re.search(r"total_bounces\s+0$", text, re.M)
    assert "whole stage took 11 s" in text


def test_contact_report_summary_rows():
    """The report's contact summary: counts as integers, no "0.000", the run's integration
    time labelled as such next to the stage's compute time."""
    from walkerlab.report.contact_sections import _summary_rows

    rows = _summary_rows({"total_bounces": (np.float64(0.0), "-"),
                          "heel_strikes": (np.int64(10), "-"),
                          "wall_time_s": (np.float64(0.124), "s")}, 11.02)
    assert rows[0][1] == "0" and rows[1][1] == "10"
    assert "integration" in rows[2][0] and "took 11.0 s" in rows[2][0]


def test_the_contact_report_shows_the_slip_path_and_the_friction_work_beside_the_push_off():
    """Issue 56 item 15: the report's contact section gives the stance foot's slip path and
    friction work per step, and the friction work against the push-off's."""
    from types import SimpleNamespace

    from walkerlab.report.contact_sections import _slip_path_lines

    c = SimpleNamespace(steps={"stance_slip_mm": np.array([0.13, np.nan]),
                               "stance_slip_path_mm": np.array([3.97, np.nan]),
                               "friction_work_j": np.array([0.087, np.nan])},
                        ledger_steps={"push_off_work": np.array([0.1758])})
    text = " ".join(_slip_path_lines(c))
    assert "Slip path of the stance foot per step [mm]" in text and "3.97" in text
    assert "friction work per stance [J]" in text and "0.087" in text
    assert "49 % of the push-off" in text  # 0.087 / 0.1758


def test_clearance_says_below_for_penetration():
    from walkerlab.report.sections import clearance_text

    neg = clearance_text(-0.000364, SI_U)
    assert "0.364 mm below the slope" in neg and "penetration" in neg and "above" not in neg
    assert "0.500 mm above the slope" in clearance_text(0.0005, SI_U)
    assert "3.64e-04 l below" in clearance_text(-0.000364, NONDIM)


def test_compare_text_prints_the_key_errors(tmp_path):
    """``walkerlab compare`` shows the errors it computed, not only the file it wrote."""
    from walkerlab.io.schemas.compare import Comparison
    from walkerlab.report.text import compare_text

    c = Comparison(
        legs=["leg1", "leg2"], time=np.linspace(0, 3.5, 8),
        errors={"leg1_angle": np.linspace(0, 2.5e-3, 8), "leg1_rate": -np.linspace(0, 4e-2, 8)},
        error_units={"leg1_angle": "rad", "leg1_rate": "rad/s"},
        limit_cycle_distance={"leg1": 1.2e-3}, max_abs_angle_rad=2.5e-3,
        max_abs_rate_rad_per_s=4e-2,
        metrics={"ideal": {"t_cycle_s": 1.3841}, "contact": {"t_cycle_s": 1.4213}},
        metric_units={"t_cycle_s": "s"}, path=tmp_path / "compare.h5", units=SI_U)
    text = compare_text(c)
    assert "max |angle error| 0.00250 rad" in text and "0.0400 rad/s" in text
    assert re.search(r"t_cycle_s\s+1.384\s+1.421 s", text), text
    assert "leg1 0.00120" in text


# --------------------------------------------------------------------------- citation
def test_report_cites_the_paper_not_a_path(tmp_path):
    from walkerlab.published import paper
    from walkerlab.report.build import ReportInputs
    from walkerlab.report.sections import summary_section

    assert paper.TITLE in paper.CITATION
    assert not re.search(r"seeds|\.txt|/", paper.CITATION), paper.CITATION
    sc = load_scene("configs/paper.yaml")
    md = "\n".join(summary_section(sc, ReportInputs({}), paper))
    assert "seeds" not in md


# --------------------------------------------------------------------------- figures
def test_figures_in_paper_order(tmp_path, monkeypatch):
    from walkerlab.report import figures_section as module
    from walkerlab.report.figures_section import CAPTIONS, figures_section

    monkeypatch.setattr(module, "steps_table", lambda path: "")  # no artifact read here

    stems = [s for s, _ in CAPTIONS]
    assert stems[:6] == ["fig2_stick_ideal", "fig6_stick_contact", "fig7_angles_rates",
                         "fig8_errors", "fig9_limit_cycles", "fig10_energy"]
    for s in stems[:6]:
        (tmp_path / f"{s}.png").write_bytes(b"")
    # every figure's artifacts are among the report's (figures of left-out artifacts are dropped)
    paths = {k: tmp_path / f"{k}.h5" for k in ("simulate", "contact-sim", "compare")}
    md = "\n".join(figures_section(tmp_path, "figures", paths))
    pos = [md.index(f"figures/{s}.png") for s in stems[:6]]
    assert pos == sorted(pos)
    # a figure drawn from an artifact the report leaves out is not shown
    md = "\n".join(figures_section(tmp_path, "figures", {"simulate": paths["simulate"]}))
    assert "figures/fig2_stick_ideal.png" in md and "fig6_stick_contact" not in md


def _walker_trajectory(round_feet: bool = False, knee: bool = False) -> NamedTrajectory:
    """Two steps of a synthetic walker with named points (geometry only)."""
    k = 40
    t = np.linspace(0.0, 2.0, k)
    th = 0.3 * np.sin(np.pi * t)
    hip = np.vstack([0.5 * t, np.full(k, 1.0)])
    pts = {"hip": hip}
    coords, units = {}, {}
    for i, leg in enumerate(("leg1", "leg2")):
        a = th if i == 0 else -th
        axis = np.vstack([np.sin(a), -np.cos(a)])
        if round_feet:
            pts[f"{leg}_foot_centre"] = hip + 0.8 * axis
            pts[f"{leg}_foot"] = hip + 1.0 * axis
            pts[f"{leg}_contact"] = pts[f"{leg}_foot_centre"] + np.vstack([0 * a, -0.2 + 0 * a])
        else:
            pts[f"{leg}_foot"] = hip + axis
        parts = ("thigh", "shank") if knee else ("",)
        for p in parts:
            stem = f"{leg}_{p}" if p else leg
            coords[f"{stem}_angle"], units[f"{stem}_angle"] = a, "rad"
            coords[f"{stem}_rate"], units[f"{stem}_rate"] = np.gradient(a, t), "rad/s"
    z = np.zeros(k)
    return NamedTrajectory(t, ["leg1", "leg2"], coords, units, z.astype(int),
                           (t > 1).astype(int), z, z, pts)


def test_stick_diagram_has_a_time_colour_bar():
    from walkerlab.plotting import figures as F

    fig = F.stick_diagram(_walker_trajectory(), "ideal", slope_rad=0.01)
    assert len(fig.axes) == 2
    assert fig.axes[1].get_ylabel() == "time [s]"
    assert "colour: time" not in fig.axes[0].get_title()
    F.plt.close(fig)


def test_round_feet_stick_diagram_draws_the_arc_not_a_stub():
    """Each leg runs straight to its arc centre and on to the arc (no segment to the off-axis
    contact point); the arc lies at radius R = |contact - centre| around the centre."""
    from walkerlab.plotting import figures as F
    from walkerlab.plotting import stick

    tr = _walker_trajectory(round_feet=True)
    chains = dict(stick._chains(tr))
    assert chains["leg1"][-1] == "leg1_foot_centre"
    assert not any(n.endswith("_contact") for c in chains.values() for n in c)
    arcs = stick._arc_feet(tr, 5)
    assert len(arcs) == 2
    c = tr.points["leg1_foot_centre"][:, 5]
    arc = arcs[0][:, 3:]  # after the spoke and its break
    assert np.allclose(np.hypot(*(arc - c[:, None])), 0.2)
    spoke_end = arcs[0][:, 1]
    hip = tr.points["hip"][:, 5]
    # the spoke continues the leg axis hip -> centre
    u, v = c - hip, spoke_end - hip
    assert abs(u[0] * v[1] - u[1] * v[0]) < 1e-12
    fig = F.stick_diagram(tr, "ideal")
    n_lines = len(fig.axes[0].get_lines())
    F.plt.close(fig)
    fig = F.stick_diagram(_walker_trajectory(), "ideal")
    assert n_lines > len(fig.axes[0].get_lines())  # the arcs are drawn
    F.plt.close(fig)


def test_fig9_one_panel_per_link_both_legs_no_empty_panels():
    from walkerlab.plotting import figures as F

    fig = F.fig9_limit_cycle({"ideal": _walker_trajectory(knee=True)})
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert len(axes) == len(fig.axes) == 2
    assert [ax.get_title() for ax in axes] == ["thighs: leg1 and leg2", "shanks: leg1 and leg2"]
    for ax in axes:
        assert sorted(ln.get_label().split(" - ")[0] for ln in ax.get_lines()) == \
            ["leg1", "leg2"]
    F.plt.close(fig)
    fig = F.fig9_limit_cycle({"ideal": _walker_trajectory()})
    assert [ax.get_title() for ax in fig.axes] == ["legs: leg1 and leg2"]
    F.plt.close(fig)


def test_work_precision_labels_do_not_overlap():
    """Crowded tolerance labels: the ones placed never overlap each other."""
    from walkerlab.plotting import figures as F

    rtols = np.array([1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8])
    rows = {m: {"time": 1e-3 * (1 + 0.02 * np.arange(6) + 0.001 * i),
                "time_min": 1e-3 * np.ones(6), "time_max": 2e-3 * np.ones(6),
                "error": rtols * (1 + 0.01 * i), "rtol": rtols} for i, m in enumerate("ABCDEF")}
    fig = F.work_precision(rows, "wp")
    ax = fig.axes[0]
    r = fig.canvas.get_renderer()
    boxes = [t.get_window_extent(r) for t in ax.texts]
    assert 6 <= len(boxes) < 36  # some labels had to go
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])
    F.plt.close(fig)


def _wp_rows(times: dict) -> dict:
    """{method: (rtols, [[repeat times] per rtol], errors)} -> rows_from_cases output."""
    from walkerlab.bench.workprecision_results import rows_from_cases

    cases, methods, rtols = {}, list(times), [1e-6, 1e-8]
    for m, per in times.items():
        for r, ts in zip(rtols, per):
            cases[(m, r)] = {"vec": [r], "times": [9.0] * len(ts), "cpu_times": ts,
                             "nfev": 1}  # the CPU times rank, not the wall times
    return rows_from_cases(cases, methods, rtols, np.zeros(1))


def test_work_precision_choice_respects_timing_noise():
    """Overlapping repeat ranges: no setting is named fastest, the tied ones are listed;
    clearly separated: the fastest is named with its spread."""
    from walkerlab.bench.workprecision_results import summarize
    from walkerlab.report.workprecision_section import workprecision_choice

    noisy = summarize(_wp_rows({"DOP853": [[1.0, 1.4, 2.0], [0.9, 1.3, 1.8]],
                                "RK45": [[5.0, 5.1, 5.2], [1.2, 1.5, 2.2]]}), 1e-5)
    assert noisy["best"][:2] == ("DOP853", 1e-8) and not noisy["separated"]
    assert {c[:2] for c in noisy["tied"]} == {("DOP853", 1e-8), ("DOP853", 1e-6),
                                               ("RK45", 1e-8)}
    clear = summarize(_wp_rows({"DOP853": [[1.0, 1.1, 1.05], [0.5, 0.52, 0.51]],
                                "RK45": [[5.0, 5.1, 5.2], [2.0, 2.1, 2.2]]}), 1e-5)
    assert clear["separated"] and clear["best"][:2] == ("DOP853", 1e-8)
    once = summarize(_wp_rows({"A": [[3.0], [1.0]], "B": [[4.0], [2.0]]}), 1e-5)
    assert not once["separated"]  # one run each: no spread, no claim

    def attrs(s):
        b = s["best_spread"]
        return {"target_error": 1e-5, "best_method": b[0], "best_rtol": b[1],
                "best_time": b[3], "best_time_min": b[2], "best_time_max": b[4],
                "best_repeats": b[5], "best_separated": s["separated"],
                "tied_methods": [c[0] for c in s["tied"]] or [""],
                "tied_rtol": [c[1] for c in s["tied"]] or [np.nan],
                "tied_time_min": [c[2] for c in s["tied"]] or [np.nan],
                "tied_time_max": [c[4] for c in s["tied"]] or [np.nan]}
    t = workprecision_choice(attrs(noisy))
    assert "cannot separate" in t and "RK45 rtol 1e-08" in t and "Pareto-best" not in t
    t = workprecision_choice(attrs(clear))
    assert "**DOP853 rtol 1e-08**" in t and "over 3 runs" in t and "500 ms" in t


def test_bifurcation_figure_marks_falls_and_keeps_labels_inside():
    from walkerlab.plotting.sweep_figures import bifurcation_figure, plt
    from walkerlab.studies.bifurcation import fall_onset

    s = np.linspace(1.0, 5.0, 9)
    walks = s < 4.2
    data = {"slope": s, "steady_state/interleg_angle": np.where(walks, 20.0, np.nan)[:, None],
            "fixed_point/interleg_angle": np.full(9, 20.0),
            "floquet/real": np.tile([-0.5, 0.2], (9, 1)), "floquet/imag": np.zeros((9, 2)),
            "onset/onset_slope": 2.7,
            "steady_state/outcome": np.where(walks, "walks", "fall").astype(object)}
    assert fall_onset(data) == pytest.approx(4.5)
    fig = bifurcation_figure(data)
    labels = fig.axes[0].get_legend_handles_labels()[1]
    assert "period doubling at 2.700°" in labels
    assert any(lab.startswith("walker falls") and "4.5°" in lab for lab in labels)
    assert not fig.axes[0].texts  # no free text running over the frame
    plt.close(fig)
    assert np.isnan(fall_onset({**data, "steady_state/outcome": ["walks"] * 9}))


def test_stability_map_figure_whole_words_one_panel():
    from walkerlab.io.schemas.stability_map import StabilityMap
    from walkerlab.plotting.gait_map_figure import gait_map_figure, plt

    reason = np.array([["", "solver_failure"], ["not_converged", ""]], dtype=object)
    d = StabilityMap(
        attrs={"kind": "friction"}, y_values=np.array([1e4, 1e5]),
        slopes_deg=np.array([1.0, 2.0]),
        cells={"exists": np.array([[1, 0], [0, 1]]), "stable": np.array([[1, 0], [0, 0]]),
               "max_abs_multiplier": np.array([[0.5, np.nan], [np.nan, 1.2]]),
               "reason": reason, "wall_time_s": np.array([[1.0, 2.0], [3.0, 4.0]])})
    fig = gait_map_figure(d)
    texts = [t.get_text() for t in fig.axes[0].texts]
    assert "solver\nfailure" in texts and "no con-\nvergence" in texts
    assert len(fig.axes) == 1  # no wall-time panel and colour bar
    assert "wall time per cell: median 2.5 s" in fig.axes[0].get_title()
    plt.close(fig)


def test_stability_map_figure_lands_in_report_figures(tmp_path, monkeypatch):
    from walkerlab.io.schemas.stability_map import StabilityMap
    from walkerlab.stages import stability_map

    monkeypatch.setattr(stability_map, "load_stability_map", lambda p: StabilityMap(
        attrs={}, y_values=np.array([1e4, 1e5]), slopes_deg=np.array([1.0, 2.0]),
        cells={"exists": np.ones((2, 2)), "stable": np.ones((2, 2)),
               "max_abs_multiplier": np.full((2, 2), 0.5),
               "reason": np.full((2, 2), "", object), "wall_time_s": np.ones((2, 2))}))
    out = stability_map.draw(tmp_path / "stability_map_friction.h5")
    assert {p.parent for p in out} == {tmp_path / "report" / "figures"}


# --------------------------------------------------------------------------- help texts
def test_help_texts_show_their_units():
    """typer's rich help drops "[deg]"-style text as markup: units must survive."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    def helptext(cmd):
        r = CliRunner().invoke(app, [cmd, "--help"], env={"COLUMNS": "200"})
        assert r.exit_code == 0
        return " ".join(r.output.split())
    assert "slope grid in degrees" in helptext("bifurcation")
    assert "work bound of each search of a cell: its step-map integrations" in helptext(
        "stability-map")
    sim = helptext("simulate")
    assert "simulate.initial_state" in sim and "a given state" not in sim


def test_no_option_help_loses_bracketed_text():
    """Every option help with ``[...]`` in it shows the brackets' content."""
    import typer.main
    from typer.testing import CliRunner

    from walkerlab.cli import app

    cmd = typer.main.get_command(app)
    for name, sub in cmd.commands.items():
        for p in sub.params:
            h = getattr(p, "help", None) or ""
            for inner in re.findall(r"\[([^\]]+)\]", h):
                r = CliRunner().invoke(app, [name, "--help"], env={"COLUMNS": "300"})
                assert f"[{inner}]" in " ".join(r.output.split()), (name, p.name, inner)
