"""Flat feet on ankle springs (issue 22; Wisse et al. 2006): the scene schema's one-line
errors, the description's parameters, and (below) the rigid hybrid view's physics."""

from __future__ import annotations

import copy

import pytest

from walkerlab.config import SceneError, scene_from_dict
from walkerlab.models.description import walker_data

FOOT = {"kind": "flat", "heel_m": 0.05, "toe_m": 0.10,
        "ankle": {"stiffness_n_m_per_rad": 20.0, "rest_angle_rad": 0.0,
                  "damping_n_m_s_per_rad": 0.0}}
LEG = {"length_m": 1.0, "foot": FOOT,
       "bodies": [{"kind": "point_mass", "name": "mass", "mass_kg": 5.0, "from_hip_m": 0.5}]}
SCENE = {"walker": {"model": "biped", "coordinates": "absolute", "hip_mass_kg": 10.0,
                    "leg": LEG}, "slope": {"angle_rad": 0.02}}


def _scene(**walker_changes) -> dict:
    d = copy.deepcopy(SCENE)
    d["walker"].update(copy.deepcopy(walker_changes))
    return d


def _error_lines(data: dict) -> list[str]:
    with pytest.raises(SceneError) as exc:
        scene_from_dict(data, "s.yaml")
    return str(exc.value).splitlines()


# --------------------------------------------------------------------------- schema
@pytest.mark.parametrize("change, field, words", [
    ({"leg": {**LEG, "knee": {"thigh_length_m": 0.5}, "bodies": [
        {"kind": "point_mass", "name": "t", "link": "thigh", "mass_kg": 1, "from_hip_m": 0.3}]}},
     "walker.leg", "flat feet are not available with a knee"),
    ({"coordinates": "slope_relative"}, "walker", "flat feet need 'absolute'"),
    ({"leg": {**LEG, "foot": {**FOOT, "heel_m": -0.01}}}, "walker.leg.foot.heel_m",
     "greater than or equal to 0"),
    ({"leg": {**LEG, "foot": {**FOOT, "toe_m": -0.1}}}, "walker.leg.foot.toe_m",
     "greater than 0"),
    ({"leg": None, "legs": [LEG, {**LEG, "foot": {"kind": "point"}}]}, "walker",
     "both legs need the same foot kind"),
    ({"leg": {**LEG, "foot": {k: v for k, v in FOOT.items() if k != "ankle"}}},
     "walker.leg.foot.ankle", "Field required"),
])
def test_a_bad_flat_foot_is_one_line_naming_the_field(change, field, words):
    lines = _error_lines(_scene(**change))
    assert len(lines) == 1, lines
    assert f"s.yaml: {field}" in lines[0] and words in lines[0], lines[0]


def test_flat_foot_parameters_by_name():
    scene = scene_from_dict(_scene(), "s.yaml")
    w = walker_data(scene.walker, scene.slope.angle_rad)
    s = w.structure
    assert s.foot == "flat" and not s.asymmetric and w.mirror is None
    p = dict(zip(s.param_names, w.params, strict=True))
    assert {k: p[k] for k in ("heel_m", "toe_m", "k_ankle", "r_ankle", "c_ankle")} == \
        {"heel_m": 0.05, "toe_m": 0.10, "k_ankle": 20.0, "r_ankle": 0.0, "c_ankle": 0.0}


def test_legs_with_different_flat_feet_get_per_role_numbers_and_a_stride():
    other = {**LEG, "foot": {**FOOT, "toe_m": 0.12,
                             "ankle": {**FOOT["ankle"], "stiffness_n_m_per_rad": 30.0}}}
    scene = scene_from_dict(_scene(leg=None, legs=[LEG, other]), "s.yaml")
    w = walker_data(scene.walker, scene.slope.angle_rad)
    names = w.structure.param_names
    p1 = dict(zip(names, w.params, strict=True))
    p2 = dict(zip(names, w.mirror.params, strict=True))
    assert w.structure.asymmetric
    # first step: leg1 swings (toe 0.10, k 20), leg2 stands (toe 0.12, k 30); then swapped
    assert (p1["toe_sw_m"], p1["toe_st_m"], p1["k_sw_ankle"], p1["k_st_ankle"]) == \
        (0.10, 0.12, 20.0, 30.0)
    assert (p2["toe_sw_m"], p2["toe_st_m"], p2["k_sw_ankle"], p2["k_st_ankle"]) == \
        (0.12, 0.10, 30.0, 20.0)


def test_existing_structures_keep_their_cache_keys():
    """A flat foot is a new part: a point-footed walker's structure key (part of the
    generated-code cache key) does not mention it."""
    d = _scene(leg={**LEG, "foot": {"kind": "point"}})
    w = walker_data(scene_from_dict(d, "s.yaml").walker, 0.02)
    assert "flat" not in w.structure.key() and "ankle" not in w.structure.key()
    assert w.structure.key() == ('{"coordinates": "absolute", "foot": "point", "hip_mass": '
                                 'true, "variant": "derived", "knee": false, "bodies": '
                                 '[["mass", "point_mass", false, "leg"]]}')
