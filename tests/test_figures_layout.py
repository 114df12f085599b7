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

from walkerlab.config import scene_from_dict
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
    from walkerlab.plotting.sweep_figures import gait_map_figure

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
