"""Contact-sim sweep points: the adapter runs, and slips / bounces / scuffs are classified."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np

from walkerlab.config import load_scene
from walkerlab.sweep.outcomes import OUTCOMES
from walkerlab.sweep.points import _contact_events, evaluate

SCENE = Path(__file__).resolve().parents[1] / "configs" / "goswami1996.yaml"


def test_contact_point_gives_a_typed_outcome():
    base = load_scene(SCENE).model_dump(mode="json")
    row, x = evaluate("contact-sim", base, ["slope.angle_deg", "contact.stiffness"], (1.0, 1e5),
                      0, None, {})
    assert row["outcome"] in OUTCOMES and row["outcome"] not in ("error", "invalid_config"), \
        row["message"]
    assert row["steps_expected"] == 10 and row["heel_strikes"] >= 0
    assert 0.2 < row["ideal_step_length_m"] < 0.6 and row["ideal_step_period_s"] > 0
    if row["outcome"] == "fall":
        assert row["fall_leg"] in ("leg1", "leg2") and row["fall_time_s"] > 0
    row, _ = evaluate("contact-sim", base, ["contact.mu_static", "contact.mu_dynamic"],
                      (0.1, 0.7), 1, None, {})
    assert row["outcome"] == "invalid_config" and "mu_dynamic" in row["message"]


def _foot(pen, s, td):
    return SimpleNamespace(penetration=np.asarray(pen, float), on_ground=np.ones(len(pen), bool),
                           s=np.asarray(s, float), touchdown_times=np.asarray(td, float))


def test_contact_events_slip_bounce_scuff():
    t = np.linspace(0.0, 2.0, 21)  # heel strike of leg1 at t = 1.0
    pen2 = np.where((t < 1.05) & ~((t > 0.35) & (t < 0.45)), 1e-4, -1e-3)  # leg2 bounces once
    s2 = np.where(t < 1.05, 0.01 * t, 0.0105)                             # and slides 10 mm
    pen1 = np.where((t >= 1.0) | ((t > 0.55) & (t < 0.65)), 1e-4, -1e-3)   # leg1 scuffs once
    res = SimpleNamespace(
        t=t, heel_strike_times=np.array([1.0]), heel_strike_legs=["leg1"],
        steps=[SimpleNamespace(stance_leg="leg2")],
        feet={"leg1": _foot(pen1, np.full(t.size, 0.5), [0.6, 1.0]),
              "leg2": _foot(pen2, s2, [0.0, 0.4])})
    slip, bounces, scuffs, last = _contact_events(res)
    assert abs(slip - 10.0) < 1e-9 and bounces == 1 and scuffs == 1 and last == "leg1"
