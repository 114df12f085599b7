"""A figure drawn after a stage is kept when it was drawn from the artifact's result as it
is now (:mod:`walkerlab.plotting.figure_cache`): the key the PNG carries ignores the run's
timings and follows every dataset and attribute of the result."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.config import load_scene
from walkerlab.io.artifacts import put, write_artifact
from walkerlab.plotting.figure_cache import drawn_from, figure_key

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def _artifact(path: Path, torque, wall_s: float, ipopt_wall_s: float) -> Path:
    def writer(f):
        f.attrs["ipopt_wall_time_s"] = ipopt_wall_s
        f.attrs["ipopt_status"] = "Solve_Succeeded"
        put(f, "torque", np.asarray(torque, float), "N m", "the torque")
        put(f, "controllers/0/wall_time_s", wall_s, "s", "a timing")

    return write_artifact(path, "optimize", load_scene(CONFIGS / "paper.yaml"), "input",
                          writer, wall_s)


def test_a_figure_drawn_from_the_same_result_is_kept_and_a_changed_result_redraws(tmp_path):
    """Two artifacts of the same result written by runs of different wall, IPOPT and
    per-controller times have one key; the PNG saved with it carries it (a PNG text chunk)
    and is kept for the second; a torque changed in its last bit, another key: redrawn."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from walkerlab.plotting.figures import save

    first = _artifact(tmp_path / "a.h5", [0.0, 1.0, 2.0], 0.5, 0.06)
    again = _artifact(tmp_path / "b.h5", [0.0, 1.0, 2.0], 0.7, 0.09)
    changed = _artifact(tmp_path / "c.h5", [0.0, 1.0, np.nextafter(2.0, 3.0)], 0.5, 0.06)
    key = figure_key(first, "optimize")
    assert key is not None and figure_key(again, "optimize") == key
    assert figure_key(changed, "optimize") != key
    assert figure_key(first, "another figure") != key
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    png = save(fig, tmp_path, "optimize", svg=False, key=key)[0]
    assert drawn_from(png, figure_key(again, "optimize"))
    assert not drawn_from(png, figure_key(changed, "optimize"))
    assert not drawn_from(png, None) and not drawn_from(tmp_path / "absent.png", key)


def test_a_png_without_a_key_or_not_a_png_is_not_taken_as_drawn_from_anything(tmp_path):
    """A figure saved without a key (``walkerlab plot``, an earlier version), a truncated
    file and a text file: never kept (drawn again)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from walkerlab.plotting.figures import save

    key = figure_key(_artifact(tmp_path / "a.h5", [1.0], 0.5, 0.06), "optimize")
    fig, ax = plt.subplots()
    png = save(fig, tmp_path, "plain", svg=False)[0]
    assert not drawn_from(png, key)
    (tmp_path / "short.png").write_bytes(png.read_bytes()[:20])
    (tmp_path / "text.png").write_text("not a png")
    assert not drawn_from(tmp_path / "short.png", key)
    assert not drawn_from(tmp_path / "text.png", key)
