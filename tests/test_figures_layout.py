"""Figures a reader can read (issue 26, item 12): legends inside the image and off the data
they explain, curves told apart, text at least 8-9 pt, the contact walker's checkerboard
drawn, the animation large, the scene's own point on its stability map."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np
import pytest
import yaml
from matplotlib.colors import to_rgb

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.io.artifacts import open_artifact
from walkerlab.io.trajectory import read_samples
from walkerlab.plotting import figures as F
from walkerlab.stages import pipeline

ROOT = Path(__file__).resolve().parents[1]


def _trajectory(tmp_path, config: str):
    d = yaml.safe_load((ROOT / "configs" / config).read_text())
    d = {k: v for k, v in d.items() if k in ("walker", "slope", "solver", "fixedpoint",
                                             "units", "ideal")}
    d["name"] = config.removesuffix(".yaml")
    d["fixedpoint"] = {**d.get("fixedpoint", {}), "other_gait": False}
    d["simulate"] = {"strides": 1, "sample_rate_hz": 200}
    sc = scene_from_dict(d)
    out = pipeline.run("simulate", sc, tmp_path / "runs")
    with open_artifact(out.path, "simulate") as f:
        return sc, read_samples(f)


@pytest.fixture(scope="module")
def kneed(tmp_path_factory):
    return _trajectory(tmp_path_factory.mktemp("kneed"), "kneed.yaml")


@pytest.fixture(scope="module")
def round_feet(tmp_path_factory):
    return _trajectory(tmp_path_factory.mktemp("round"), "round_feet.yaml")


def _inside(fig, artist, margin_px: float = 2.0) -> bool:
    fig.draw_without_rendering()
    r = fig.canvas.get_renderer()
    b, f = artist.get_window_extent(r), fig.bbox
    return (b.x0 >= f.x0 + margin_px and b.y0 >= f.y0 + margin_px
            and b.x1 <= f.x1 - margin_px and b.y1 <= f.y1 - margin_px)


def test_fig7_of_the_kneed_walker_legend_inside_curves_distinct_text_readable(kneed):
    """8 curves (thigh and shank of each leg, two models): legend inside the image, every
    pair of colours at least 0.25 apart in RGB (tab:blue/tab:cyan were 0.36, red/orange 0.37
    but thigh/shank of one leg looked alike), no text below 9 pt."""
    _sc, tr = kneed
    fig = F.fig7_angles_rates({"ideal": tr, "contact": tr})
    (leg,) = fig.legends
    assert _inside(fig, leg)
    colours = {to_rgb(ln.get_color()) for ln in fig.axes[0].get_lines()}
    assert len(colours) == 4  # thigh and shank of two legs; the models by line style
    gaps = [np.linalg.norm(np.subtract(a, b)) for a in colours for b in colours if a != b]
    assert min(gaps) > 0.45
    sizes = [t.get_fontsize() for t in leg.get_texts()]
    sizes += [ax.xaxis.label.get_fontsize() for ax in fig.axes]
    sizes += [t.get_fontsize() for ax in fig.axes for t in ax.get_yticklabels()]
    assert min(sizes) >= 9
    # as the report shows it (the saved PNG: tight box at 150 dpi, shown at most 1100 px
    # wide): still >= 8 pt at 96 dpi
    saved_in = fig.get_tightbbox(fig.canvas.get_renderer()).width
    shown = min(1.0, 1100 / (saved_in * 150))
    assert min(sizes) * 150 / 72 * shown / (96 / 72) >= 8


def _terrain(tr, half_width=0.05):
    s = np.arange(-4, 12) * 0.3
    return {"lanes": {"leg1": s[1::2], "leg2": s[::2]}, "half_width": half_width,
            "continuous": False}


def test_stick_diagram_draws_the_checkerboard(round_feet):
    from matplotlib.patches import Polygon

    sc, tr = round_feet
    fig = F.stick_diagram(tr, "contact", slope_rad=sc.slope.phi_rad, terrain=_terrain(tr))
    patches = [p for p in fig.axes[0].patches if isinstance(p, Polygon)]
    assert len(patches) >= 3
    assert len({p.get_facecolor() for p in patches}) == 2  # the two lanes' shades
    bare = F.stick_diagram(tr, "ideal", slope_rad=sc.slope.phi_rad)
    assert not [p for p in bare.axes[0].patches if isinstance(p, Polygon)]


def test_animation_is_large_draws_patches_and_arc_feet(round_feet):
    from walkerlab.plotting.animation import ARC_POINTS, walker_animation

    sc, tr = round_feet
    frames = walker_animation({"ideal": tr, "contact": tr}, sc.slope.phi_rad, max_frames=3,
                              terrain={"contact": _terrain(tr)})
    fig = frames.fig
    w, h = fig.get_size_inches() * frames.dpi
    assert w >= 960 and h >= 400
    frames.draw(1)
    titles = [ax.title.get_fontsize() for ax in fig.axes]
    assert min(titles) * frames.dpi / 72 >= 16  # px: a readable clock
    assert len(fig.axes[1].patches) >= 3 and not fig.axes[0].patches
    arcs = [ln for ln in fig.axes[0].get_lines() if len(ln.get_xdata()) == ARC_POINTS]
    assert len(arcs) == 2  # one arc per foot, drawn as an arc
    assert not [ln for ln in fig.axes[0].get_lines() if ln.get_marker() == "x"]


def test_drop_test_legend_keeps_off_the_scene_stiffness():
    from walkerlab.plotting.sweep_figures import restitution_figure

    k = np.logspace(4, 9, 11)
    fig = restitution_figure(k, {"paper": np.linspace(0, 1, 11),
                                 "rigid_limit": np.full(11, 0.03)}, k_paper=1e5)
    (leg,) = fig.legends or fig.axes[0].get_legend() and [fig.axes[0].get_legend()]
    fig.draw_without_rendering()
    r = fig.canvas.get_renderer()
    ax = fig.axes[0]
    assert not leg.get_window_extent(r).overlaps(ax.get_window_extent(r))
    assert _inside(fig, leg)


def test_stability_map_marks_the_scenes_point_with_three_cells_a_side():
    """A 3x3 paper stiffness map (k = 1e3, 1e6, 1e9; slopes 0.5, 2.25, 4°) has no cell at
    the scene's k = 1e5 N/mm^2.2, φ = 0.997°: the star sits between cells, at
    log10 interpolation: y index (5 - 3) / 3 = 0.667, x index (0.997 - 0.5) / 1.75."""
    from walkerlab.io.schemas.stability_map import StabilityMap
    from walkerlab.plotting.gait_map_figure import gait_map_figure

    n = 3
    data = StabilityMap(
        attrs={"kind": "stiffness", "y_label": "contact stiffness k [N/mm^e]",
               "scene_slope_deg": 0.997, "scene_y": 1e5},
        y_values=np.array([1e3, 1e6, 1e9]), slopes_deg=np.array([0.5, 2.25, 4.0]),
        cells={"exists": np.ones((n, n)), "stable": np.ones((n, n)),
               "max_abs_multiplier": np.full((n, n), 0.5),
               "reason": np.full((n, n), "", dtype=object), "wall_time_s": np.ones((n, n))})
    fig = gait_map_figure(data)
    (star,) = [ln for ln in fig.axes[0].get_lines() if ln.get_label() == "this scene"]
    x, y = star.get_xdata()[0], star.get_ydata()[0]
    assert x == pytest.approx((0.997 - 0.5) / 1.75, rel=1e-12)
    assert y == pytest.approx(2 / 3, rel=1e-12)


# -------------------- figure captions, axes, tables; a continuation figure's stability
PAPER = ROOT / "configs" / "paper.yaml"


def _branch_data(mmax, special=None):
    from types import SimpleNamespace

    import numpy as np

    p = np.arange(len(mmax), dtype=float)
    mult = np.c_[np.asarray(mmax, float), 0.1 * np.ones(len(mmax))].astype(complex)
    b = {"period": 1, "param": p, "states": {"stance_angle": 0.2 + 0.01 * p},
         "multipliers": mult, "stable": np.asarray(mmax) < 1}
    return SimpleNamespace(branches=[b], special=special or {}, state_names=["stance_angle"],
                           unit="deg", path="slope.angle_deg", start=0.0)


# ------------------------------------------------------------------- 9: figure nits
def test_fig9_caption_does_not_promise_a_panel_per_link_of_a_straight_leg():
    from walkerlab.report.figures_section import CAPTIONS

    cap = dict(CAPTIONS)["fig9_limit_cycles"]
    assert "one panel per link" not in cap and "both legs in each panel" in cap


def test_mfpt_log_axis_ticks_are_plain_numbers():
    import matplotlib

    matplotlib.use("Agg")
    import numpy as np

    from walkerlab.plotting.mfpt_figures import mfpt_figure

    class D(dict):
        sigma_rad = np.array([0.002, 0.003, 0.004])

    d = D(mfpt_steps_montecarlo=np.array([5.5, 4.2, 3.1]),
          mfpt_steps_montecarlo_stderr=np.array([0.2, 0.2, 0.1]),
          mfpt_steps_mesh=np.array([5.4, 4.1, 3.2]), mesh_converged=np.ones(3))
    fig = mfpt_figure(d)
    fig.canvas.draw()
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_yticklabels(minor=True) + ax.get_yticklabels()]
    shown = [s for s in labels if s]
    assert shown and not any("10^" in s or "times" in s or "×" in s for s in shown), shown
    assert {"3", "4", "5"} <= set(shown)


def test_table_2_comes_before_table_3_and_headings_are_capitalised(tmp_path, monkeypatch):
    from types import SimpleNamespace

    import numpy as np

    from walkerlab.report import build, contact_sections, sections

    monkeypatch.setattr(contact_sections, "initial_states_section",
                        lambda scene, arts: ["## Table 2 — initial states", ""])
    monkeypatch.setattr(sections, "gait_section",
                        lambda scene, inputs, pub: ["## Table 3 — gait characteristics", ""])
    scene = load_scene(PAPER)
    build.write_report(scene, build.ReportInputs({}), tmp_path, tmp_path)
    md = (tmp_path / "report.md").read_text()
    assert md.index("## Table 2") < md.index("## Table 3")
    c = SimpleNamespace(initial_rate_scale=np.array([1.0, 1.0]), rate_names=["leg1", "leg2"],
                        adjust=None, samples=SimpleNamespace(coordinates={"leg1_angle": [0.2]}))
    lines = contact_sections._initial_state_lines(c, {}, None, {})
    assert lines[0] == "## Initial states (ideal vs contact model)"


def test_limit_cycle_distance_column_has_a_unit():
    from types import SimpleNamespace

    import numpy as np

    from walkerlab.report.build import ReportInputs
    from walkerlab.report.contact_sections import compare_section

    c = SimpleNamespace(errors={"leg1_angle": np.array([0.01]), "leg1_rate": np.array([0.1])},
                        limit_cycle_distance={"leg1": 0.02}, time=np.array([0.0, 1.0]),
                        metrics={})
    scene = load_scene(PAPER).model_copy(update={"published": None})
    text = "\n".join(compare_section(scene, ReportInputs({"compare": c})))
    assert "mean limit-cycle distance [rad, rad/s: in the (angle, rate) plane]" in text


def test_the_notebook_basin_panel_names_its_axes_and_colours():
    import json

    nb = json.loads((ROOT / "examples" / "walkerlab_tour.ipynb").read_text())
    cell = next("".join(c["source"]) for c in nb["cells"]
                if "basin.outcome.plot" in "".join(c["source"]))
    assert "ax[2].set_xlabel(" in cell and "ax[2].set_ylabel(" in cell  # not "cell centres"
    assert "OUTCOME_COLORS" in cell and "ax[2].legend(" in cell  # each colour named


def test_a_branch_is_drawn_stable_only_where_its_largest_multiplier_is_below_one():
    import numpy as np

    from walkerlab.plotting.continuation_figures import continuation_figure, stability_pieces

    mmax = np.array([0.8, 0.9, 1.2, 1.1, 0.95])
    pieces = stability_pieces(np.arange(5.0), np.zeros((5, 1)), mmax)
    assert [st for *_x, st in pieces] == [True, False, True]
    assert pieces[0][0][-1] == pytest.approx(1 + 0.1 / 0.3)  # |λ| = 1, linearly between
    assert pieces[1][0][0] == pieces[0][0][-1] and pieces[1][2][0] == 1.0
    fig = continuation_figure(_branch_data(mmax))
    ax2 = fig.axes[1]
    for line in ax2.get_lines():
        y = np.asarray(line.get_ydata(), float)
        if line.get_linestyle() == "-" and y.size > 1:
            assert np.all(y <= 1.0 + 1e-12), y  # solid: stable
        if line.get_linestyle() == "--":
            assert np.all(y >= 1.0 - 1e-12), y


def test_special_point_labels_stay_inside_the_axes_clear_of_their_markers():
    import numpy as np

    from walkerlab.plotting.continuation_figures import continuation_figure

    # the third label of a point at the top: stacked highest, where it left the axes
    sp = {"kind": np.array(["period_doubling", "fold", "branch_end"]),
          "param": np.array([1.0, 2.0, 4.0]), "period": np.array([1, 1, 1]),
          "states": {"stance_angle": np.array([0.21, 0.22, 0.24])}}
    fig = continuation_figure(_branch_data([0.8, 0.9, 1.2, 1.1, 1.3], sp))
    fig.canvas.draw()
    ax = fig.axes[0]
    box = ax.get_window_extent()
    from matplotlib.text import Text

    for t in ax.texts:
        bb = Text.get_window_extent(t)  # the label itself, without its leader line
        assert box.y0 - 1 <= bb.y0 and bb.y1 <= box.y1 + 1, t.get_text()  # not clipped
        assert box.x0 - 1 <= bb.x0 and bb.x1 <= box.x1 + 1, t.get_text()
        x, y = ax.transData.transform((float(t.xy[0]), float(t.xy[1])))
        assert not (bb.x0 - 4 <= x <= bb.x1 + 4 and bb.y0 - 4 <= y <= bb.y1 + 4), t.get_text()


def test_fig9_titles_a_straight_legs_panel_by_the_legs_it_holds_not_leg():
    """Issue 64 item 10: the paper walker's Fig. 9 panel was titled "leg"."""
    from types import SimpleNamespace

    t = np.linspace(0, 1, 20)
    coords = {f"{leg}_{q}": np.sin(t + k) for k, leg in enumerate(("leg1", "leg2"))
              for q in ("angle", "rate")}
    tr = SimpleNamespace(legs=("leg1", "leg2"), coordinates=coords,
                         phase_pairs=lambda: [("leg1_angle", "leg1_rate"),
                                              ("leg2_angle", "leg2_rate")])
    fig = F.fig9_limit_cycle({"ideal": tr})
    (ax,) = fig.axes
    assert ax.get_title() == "legs: leg1 and leg2"


def test_fig9_draws_a_coordinate_on_no_leg_whose_name_has_an_underscore():
    """The 3D hip-roll walker's pelvis_roll (on no leg) failed the figure ('pelvis_roll' is
    not in list: the colours are keyed by a name's first word); its own panel now."""
    from types import SimpleNamespace

    t = np.linspace(0, 1, 20)
    coords = {f"{c}_{q}": np.sin(t + k) for k, c in enumerate(("leg1", "leg2", "pelvis_roll"))
              for q in ("angle", "rate")}
    tr = SimpleNamespace(legs=("leg1", "leg2"), coordinates=coords,
                         phase_pairs=lambda: [(f"{c}_angle", f"{c}_rate")
                                              for c in ("leg1", "leg2", "pelvis_roll")])
    fig = F.fig9_limit_cycle({"ideal": tr})
    assert [ax.get_title() for ax in fig.axes] == ["legs: leg1 and leg2", "pelvis_roll"]


def test_the_optimize_figure_draws_every_controllers_outputs_against_the_phase(monkeypatch,
                                                                              tmp_path):
    """Issue 64 item 10: optimize.png of a design of two controllers had an empty panel,
    drew controller 1 of 2 and no outputs against the phase (the Bezier polynomials)."""
    from types import SimpleNamespace

    from walkerlab.plotting import figures, optimize_figure

    t = np.linspace(0.0, 0.4, 9)
    ctrl = [SimpleNamespace(target_speed_m_per_s=v, output_names=("link:swing_leg",
                                                                  "link:torso"),
                            bezier_rad=np.array([[-0.2, -0.1, 0.0, 0.1, 0.2 + k],
                                                 [0.1, 0.1, 0.1, 0.1, 0.1]]),
                            step_period_s=0.45, step_length_m=0.3, max_torque_n_m=50.0,
                            multipliers=np.array([0.5, 0.1]), status="Solve_Succeeded")
            for k, v in enumerate((0.5, 0.8))]
    d = SimpleNamespace(time=t, torque=np.zeros((9, 2)), torque_names=("u1", "u2"),
                        torque_unit="N m", terms={}, objective_name="effort", objective=1.0,
                        objective_unit="N^2 m^2 s", states={"torso": t}, state_units={
                            "torso": "rad"}, step_length_m=0.3, step_period_s=0.45,
                        replay_error=1e-6, energy={}, ipopt_history={
                            "objective": np.ones(3), "primal_infeasibility": np.ones(3),
                            "dual_infeasibility": np.ones(3)}, steps=1, phase_names=("s",),
                        phase_start=(0,), gait=True, status="Solve_Succeeded", iterations=3,
                        energy_unit="J", controllers=ctrl)
    drawn = {}
    monkeypatch.setattr(figures, "save", lambda fig, folder, name, svg, key=None:
                        drawn.setdefault("fig", fig) and [])
    optimize_figure.save_optimize_figure(d, "threelink_hzd", tmp_path)
    shown = [a for a in drawn["fig"].axes if a.axison]
    assert all(a.lines or a.texts for a in shown)  # no empty panel
    (phase,) = [a for a in shown if "against the phase" in a.get_title()]
    assert len([ln for ln in phase.lines if ln.get_linestyle() != "None"]) == 2 * 2
    assert "all 2 controllers" in phase.get_title()
