"""``walkerlab animate``: the walker walking as a GIF, drawn from the artifacts with every
walker's geometry (knees, arc feet) right."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from walkerlab.config import load_scene
from walkerlab.io.artifacts import open_artifact
from walkerlab.io.trajectory import read_samples
from walkerlab.stages import pipeline

ROOT = Path(__file__).resolve().parents[1]
FRAMES = 12  # enough to see the walker move, quick to write


def _frames(path):
    out = []
    with Image.open(path) as im:
        for k in range(im.n_frames):
            im.seek(k)
            out.append(np.asarray(im.convert("RGB"), dtype=np.int16))
    return out


def _animate(name, tmp_path):
    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    out = pipeline.run("animate", scene, tmp_path, max_frames=FRAMES)
    gif = tmp_path / name / "report" / "figures" / "animation.gif"
    return scene, out, gif


def test_paper_gif_moves(tmp_path):
    """The paper walker's GIF: several frames that differ from each other (the walker
    moves), a sane size, no temporary file left, and the MP4 written or its absence said."""
    _, out, gif = _animate("paper", tmp_path)
    assert gif in out.paths and gif.is_file()
    assert 10_000 < gif.stat().st_size < 5_000_000
    frames = _frames(gif)
    assert len(frames) == FRAMES
    changed = [np.abs(a - b).max() > 0 for a, b in zip(frames, frames[1:])]
    assert all(changed)
    assert not list(gif.parent.glob(".animation*"))
    assert out.note.startswith("ffmpeg not found") or gif.with_suffix(".mp4").is_file()


def _drawn(frames, panel=0):
    """Drawn lines of one panel of a WalkerFrames figure, as (n, 2) point arrays."""
    ax = frames.fig.axes[panel]
    return [np.column_stack(line.get_data()) for line in ax.lines]


@pytest.mark.parametrize("name", ["kneed", "round_feet"])
@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_kneed_and_arc_feet_animate(name, tmp_path):
    """A kneed and an arc-foot scene animate without error into a multi-frame GIF."""
    _, out, gif = _animate(name, tmp_path)
    assert len(_frames(gif)) == FRAMES


def _trajectory(name, tmp_path):

    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    path = pipeline.run("simulate", scene, tmp_path).path
    with open_artifact(path, "simulate") as f:
        return scene, read_samples(f)


def test_knee_bends_in_the_drawing(tmp_path):
    """Kneed walker: each leg is drawn hip -> knee -> foot, and the swing knee is drawn bent
    (angle between thigh and shank segments above 0.2 rad in some frame) while the stance
    leg is drawn straight."""
    from walkerlab.plotting.animation import leg_parts, walker_animation

    scene, tr = _trajectory("kneed", tmp_path)
    assert leg_parts(tr, "leg1")["chain"] == ["hip", "leg1_knee", "leg1_foot"]
    frames = walker_animation({"rigid": tr}, scene.slope.phi_rad, max_frames=40)
    bends = []
    for j in range(len(frames.times)):
        frames.draw(j)
        legs = [xy for xy in _drawn(frames) if len(xy) == 3]  # the two leg chains
        assert len(legs) == 2
        ang = []
        for xy in legs:
            a, b = xy[1] - xy[0], xy[2] - xy[1]
            ang.append(abs(np.arctan2(a[0] * b[1] - a[1] * b[0], a @ b)))
        bends.append(sorted(ang))
    bends = np.array(bends)
    assert bends[:, 0].max() < 1e-9  # the stance leg is straight throughout
    assert bends[:, 1].max() > 0.2  # the swing knee bends


def test_arc_feet_drawn_on_the_slope(tmp_path):
    """Arc feet: each foot is an arc of radius R = 0.2 about its centre, the leg runs on to it,
    and the stance foot's marked contact point lies on the slope line."""
    from walkerlab.plotting.animation import ARC_POINTS, walker_animation

    scene, tr = _trajectory("round_feet", tmp_path)
    phi = scene.slope.phi_rad
    frames = walker_animation({"rigid": tr}, phi, max_frames=10)
    for j in range(len(frames.times)):
        frames.draw(j)
        i = np.clip(np.searchsorted(tr.time, frames.times[j]), 0, tr.time.size - 1)
        stance = tr.legs[int(tr.stance_leg[i])]
        centre = tr.points[f"{stance}_foot_centre"][:, i]
        lines = _drawn(frames)
        arcs = [xy for xy in lines if len(xy) == ARC_POINTS]
        assert len(arcs) == 2
        radii = [np.hypot(*(xy - centre).T) for xy in arcs]
        assert any(np.allclose(r, 0.2, rtol=0, atol=1e-12) for r in radii)
        contact = tr.points[f"{stance}_contact"][:, i]
        assert abs(contact[1] + np.tan(phi) * contact[0]) < 1e-9
        marks = [xy[0] for xy in lines if len(xy) == 1]
        assert any(np.allclose(m, contact) for m in marks)


def test_side_by_side_panels(tmp_path):
    """Two trajectories (rigid and contact) give two panels at the same frame times."""
    from walkerlab.plotting.animation import walker_animation

    scene, tr = _trajectory("paper", tmp_path)
    frames = walker_animation({"rigid": tr, "contact": tr}, scene.slope.phi_rad, max_frames=5)
    assert len(frames.fig.axes) == 2 and len(frames.times) == 5


def test_animate_cli_one_line_error(tmp_path):
    """A scene file that does not exist: one line naming it, exit code 1."""
    from typer.testing import CliRunner

    from walkerlab.cli import app

    r = CliRunner().invoke(app, ["animate", str(tmp_path / "nope.yaml"), "--runs-dir",
                                 str(tmp_path)])
    assert r.exit_code == 1, r.output
    assert r.output.strip().count("\n") == 0 and "nope.yaml" in r.output


def test_report_embeds_the_gif(tmp_path):
    """The report's figures section shows animation.gif when it exists, and the HTML embeds
    it as a GIF."""
    from walkerlab.report.figures_section import figures_section
    from walkerlab.report.markdown import to_html

    figs = tmp_path / "figures"
    figs.mkdir()
    assert figures_section(figs, "figures", {}) == []
    Image.new("RGB", (4, 4), "white").save(figs / "animation.gif")
    md = figures_section(figs, "figures", {})
    assert any(line.startswith("![") and "figures/animation.gif" in line for line in md)
    assert "data:image/gif;base64," in to_html("\n".join(md), tmp_path)


# -------------------- the upper body drawn
# ------------------------------------------------------------------ 12: the upper body drawn
def test_animation_draws_the_upper_body(tmp_path):
    """torso_bhm: a 5 kg upper body 0.2 m above the hip on a bisecting hip.  Every frame
    draws a line from the hip to it (before: only the legs and the hip were drawn)."""
    from walkerlab.config import load_scene
    from walkerlab.io.artifacts import open_artifact
    from walkerlab.io.trajectory import read_samples
    from walkerlab.plotting.animation import walker_animation
    from walkerlab.stages import pipeline

    scene = load_scene(ROOT / "configs" / "torso_bhm.yaml")
    with open_artifact(pipeline.run("simulate", scene, tmp_path).path, "simulate") as f:
        tr = read_samples(f)
    frames = walker_animation({"rigid": tr}, scene.slope.phi_rad, max_frames=8)
    try:
        for j in range(len(frames.times)):
            frames.draw(j)
            i = np.clip(np.searchsorted(tr.time, frames.times[j]), 0, tr.time.size - 1)
            hip, body = tr.points["hip"][:, i], tr.points["torso_mass"][:, i]
            assert body[1] > hip[1] and abs(np.hypot(*(body - hip)) - 0.2) < 1e-9
            lines = [np.column_stack(ln.get_data()) for ln in frames.fig.axes[0].lines]
            assert any(len(xy) == 2 and np.allclose(xy, [hip, body], atol=1e-12)
                       for xy in lines), "no line from the hip to the upper body"
    finally:
        import matplotlib.pyplot as plt

        plt.close(frames.fig)
