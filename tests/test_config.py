"""Scenes: every shipped file loads; bad input is a one-line error naming the field."""

from pathlib import Path

import pytest
import yaml

from walkerlab.config import SceneError, load_scene

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = sorted((ROOT / "configs").glob("*.yaml"))


def test_there_are_configs():
    assert {p.name for p in CONFIGS} >= {"paper.yaml", "goswami1996.yaml"}


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.name)
def test_every_config_loads(path):
    scene = load_scene(path)
    assert scene.name == path.stem
    assert scene.source, "a published parameter set must cite its source"


def _write(tmp_path, data, name="bad.yaml"):
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data))
    return p


def _paper(tmp_path):
    return yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())


@pytest.mark.parametrize(
    ("mutate", "field"),
    [
        (lambda d: d["walker"].update(colour="red"), "walker.colour"),
        (lambda d: d["walker"].update(leg_mass_kg=-5.0), "walker.leg_mass_kg"),
        (lambda d: d["slope"].update(angle_rad=1.6), "slope.angle_rad"),
        (lambda d: d.update(slope={"angle_deg": -95}), "slope.angle_deg"),
        (lambda d: d["solver"].update(method="Euler"), "solver.method"),
        (lambda d: d.update(unknown_section={}), "unknown_section"),
    ],
)
def test_bad_field_is_one_line_error_naming_it(tmp_path, mutate, field):
    d = _paper(tmp_path)
    mutate(d)
    with pytest.raises(SceneError) as exc:
        load_scene(_write(tmp_path, d))
    msg = str(exc.value)
    assert "\n" not in msg
    assert field in msg
    assert "bad.yaml" in msg


def test_malformed_yaml_names_file(tmp_path):
    p = tmp_path / "broken.yaml"
    p.write_text("walker: [unclosed\n")
    with pytest.raises(SceneError, match="broken.yaml.*malformed YAML"):
        load_scene(p)


def test_missing_file(tmp_path):
    with pytest.raises(SceneError, match="not found"):
        load_scene(tmp_path / "nope.yaml")


def test_sections_not_used_are_absent():
    """schwab_wisse2001 declares no contact sections: they stay None, not dummies."""
    scene = load_scene(ROOT / "configs" / "schwab_wisse2001.yaml")
    assert scene.contact is None and scene.terrain is None and scene.contact_sim is None
