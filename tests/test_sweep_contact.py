"""Contact-sim sweep points: the adapter runs, and the contact run's typed outcome is the row's."""

from __future__ import annotations

from pathlib import Path

import pytest

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.studies.outcomes import OUTCOMES
from walkerlab.studies.points import _CONTACT_OUTCOME, evaluate
from walkerlab.walker.plant import Plant

SCENE = Path(__file__).resolve().parents[1] / "configs" / "goswami1996.yaml"


def _plant(base: dict) -> Plant:
    """The plant of a scene mapping (the study's, as its stage builds it)."""
    return Plant.from_scene(scene_from_dict(base))


def test_contact_point_gives_a_typed_outcome():
    base = load_scene(SCENE).model_dump(mode="json")
    row, x = evaluate("contact-sim", base, ["slope.angle_deg", "contact.stiffness_n_per_mm_pow_e"],
                      (1.0, 1e5), 0, None, {}, plant=_plant(base))
    assert row["outcome"] in OUTCOMES and row["outcome"] not in ("error", "invalid_config"), \
        row["message"]
    assert row["steps_expected"] == 10 and row["heel_strikes"] >= 0
    assert 0.2 < row["ideal_step_length_m"] < 0.6 and row["ideal_step_period_s"] > 0
    if row["outcome"] in ("fall", "trip"):
        assert row["fall_leg"] in ("leg1", "leg2") and row["fall_time_s"] > 0
    row, _ = evaluate("contact-sim", base, ["contact.mu_static", "contact.mu_dynamic"],
                      (0.1, 0.7), 1, None, {}, plant=_plant(base))
    assert row["outcome"] == "invalid_config" and "mu_dynamic" in row["message"]


def test_contact_outcomes_map_onto_sweep_outcomes():
    """Every typed outcome of a contact run has a sweep outcome of its own (trip and fall
    apart, time limit apart from solver failure); the two ends of a run that walked
    (heel_strike: strides cap, t_final: end time) are both 'ok'."""
    from walkerlab.analysis.contact.verdict import CONTACT_OUTCOMES

    assert set(_CONTACT_OUTCOME) == set(CONTACT_OUTCOMES)
    assert set(_CONTACT_OUTCOME.values()) <= set(OUTCOMES)
    assert _CONTACT_OUTCOME["heel_strike"] == _CONTACT_OUTCOME["t_final"] == "ok"
    assert len(set(_CONTACT_OUTCOME.values())) == len(CONTACT_OUTCOMES) - 1


def test_contact_fields_are_swept_by_their_unit_bearing_names():
    """An old contact name in a sweep spec is one line naming the new ones; the SI name of a
    quantity the scene writes in mm-kg-s replaces the scene's value (the pair excludes each
    other, as slope.angle_deg / angle_rad)."""
    from walkerlab.models.contact.laws import contact_params_si
    from walkerlab.studies.params import SweepError, apply_point, check_axes, parse_param

    scene = load_scene(SCENE)
    with pytest.raises(SweepError, match=r"contact\.stiffness is now "
                       r"contact\.stiffness_n_per_mm_pow_e \(mm-kg-s\) or "
                       r"contact\.stiffness_n_per_m_pow_e \(SI\)"):
        check_axes(scene, [parse_param("contact.stiffness=1e5,1e6")])
    k_si = contact_params_si(scene.contact).k
    check_axes(scene, [parse_param(f"contact.stiffness_n_per_m_pow_e={k_si!r}")])
    point = apply_point(scene.model_dump(mode="json"), ["contact.stiffness_n_per_m_pow_e"],
                        (k_si,))
    assert point.contact.stiffness_n_per_mm_pow_e is None
    assert contact_params_si(point.contact) == contact_params_si(scene.contact)
