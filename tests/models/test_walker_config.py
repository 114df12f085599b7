"""The `walker` section as data: bad input is one clear line naming the field."""

from pathlib import Path

import pytest
import yaml

from walkerlab.config import SceneError, scene_from_dict
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[2]


def _simplest():
    return yaml.safe_load((ROOT / "configs" / "simplest.yaml").read_text())


@pytest.mark.parametrize(("edit", "field"), [
    (lambda d: d["walker"]["leg"]["bodies"][0].update(from_hip_m=1.5), "foot_mass"),
    (lambda d: d["walker"]["leg"]["bodies"][0].update(kind="cube"), "kind"),
    (lambda d: d["walker"]["leg"]["bodies"][0].update(name="foot"), "reserved"),
    (lambda d: d["walker"].update(coordinates="polar"), "coordinates"),
    (lambda d: d["walker"]["leg"].update(length_m=-1.0), "length_m"),
    (lambda d: d["fixedpoint"]["initial_guess"].update(hip_angle=0.4), "hip_angle"),
])
def test_bad_walker_field_is_named_in_one_line(edit, field):
    d = _simplest()
    edit(d)
    with pytest.raises(SceneError) as exc:
        scene_from_dict(d, "simplest.yaml")
    msg = str(exc.value)
    assert field in msg and "\n" not in msg


def test_state_by_name_must_match_the_walker():
    from walkerlab.models.registry import build_walker

    sc = scene_from_dict(_simplest())
    w = build_walker(Plant.from_scene(sc))
    assert sc.fixedpoint.initial_guess.as_array(w.state_names()).shape == (4,)
    with pytest.raises(ValueError, match="swing_angle_rad"):
        sc.fixedpoint.initial_guess.as_array()  # the compass gait's names: not this walker's


def test_leg_without_a_body_below_the_hip_is_refused():
    """Without a body below the hip the swing leg has no equation (singular mass matrix)."""
    d = _simplest()
    d["walker"]["leg"]["bodies"] = []
    with pytest.raises(SceneError, match="walker.leg: bodies: the swing leg needs a body"):
        scene_from_dict(d, "simplest.yaml")
