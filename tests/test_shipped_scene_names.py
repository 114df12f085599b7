"""A shipped scene by its name (``"paper"``, ``"kneed"``) or its repository path
(``"configs/rabbit.yaml"``) from any working folder: ``load_scene``, the Python API, the
Gymnasium environment (``gym.make("walkerlab/Walker-v0", scene="paper")``) and the CLI.  A file
in the working folder wins; a name that is neither gets the one line it always got."""

from __future__ import annotations

from pathlib import Path

import pytest

from walkerlab.config import SceneError, load_scene

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("name, expected", [("paper", "paper"), ("kneed.yaml", "kneed"),
                                            ("configs/rabbit.yaml", "rabbit")])
def test_a_shipped_scene_loads_by_name_from_any_folder(name, expected, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    sc = load_scene(name)
    assert sc.name == expected
    assert sc == load_scene(ROOT / "configs" / f"{expected}.yaml")


def test_a_file_in_the_working_folder_wins(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "configs").mkdir()
    text = (ROOT / "configs" / "paper.yaml").read_text().replace("angle_rad: 0.0174",
                                                                   "angle_rad: 0.02", 1)
    (tmp_path / "configs" / "paper.yaml").write_text(text)
    assert load_scene("configs/paper.yaml").slope.angle_rad == 0.02
    assert load_scene("paper").slope.angle_rad == pytest.approx(0.0174)  # no local "paper"


@pytest.mark.parametrize("name", ["nope", "configs/nope.yaml", "../paper", "a/b/paper.yaml"])
def test_a_name_that_is_no_scene_gets_one_line(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneError, match=r"^" + name.replace(".", r"\.") + ": scene file not "
                       "found$"):
        load_scene(name)


def test_the_gymnasium_environment_takes_a_shipped_name(tmp_path, monkeypatch):
    gym = pytest.importorskip("gymnasium")
    import walkerlab.gym  # noqa: F401 - registers walkerlab/Walker-v0

    monkeypatch.chdir(tmp_path)
    env = gym.make("walkerlab/Walker-v0", scene="paper")
    obs, info = env.reset(seed=0)
    assert obs.shape == env.observation_space.shape
    env.close()


def test_shipped_scenes_cite_the_paper_by_its_title_not_a_path_outside_the_project():
    """Issue 56 item 16: four shipped scenes cited the paper as
    ``shared/seeds/000_cba74126b2033523.txt``, a file outside the project; they cite its
    title (comments only: the scenes' numbers are unchanged)."""
    import re

    from walkerlab.published.paper import TITLE

    for f in sorted((ROOT / "configs").glob("*.yaml")):
        text = f.read_text()
        assert "shared/" not in text and not re.search(r"(^|[\s(\"'])/(work|home|tmp)/", text), f
        if "The compass-gait walker of the paper" in text or "The paper's compass-gait" in text:
            assert " ".join(TITLE.split()) in " ".join(text.replace("#", " ").split()), f
