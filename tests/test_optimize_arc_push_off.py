"""``walkerlab optimize`` with a push-off on arc feet (issue 48 item 5; refused before: "a
push-off on arc feet ... is not in the rigid model yet"): the one-step transcription's
reset is the extended impact printed from the generated ``De, E`` with the impulse at the
trailing arc's rolling contact point, as the rigid view's
(:mod:`walkerlab.models.hybrid.push_off`).

With the push-off fixed, the least-effort gait (int u^2 dt) on a slope where the pushed
walker walks with no hip torque is that walker's passive pushed gait, found independently
by shooting on the rigid model (the fixedpoint stage's search): objective 0, the same step
period.  Tolerances: Hermite-Simpson's period error on 60 intervals is ~1e-7 relative for
the round-foot walker (tests/test_optimize_least_effort.py: 7.4e-8 unpushed)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
GAMMA, P = 0.005, 0.04  # rad, N s: tests/test_push_off_feet.py's pushed round-foot gait
GUESS = (-0.1888, 0.1788, -0.1987, -0.2371)


def test_least_effort_with_an_arc_foot_push_off_is_the_rigid_pushed_gait():
    pytest.importorskip("casadi")
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.optimal.driver import optimize_scene

    scene = load_scene(CONFIGS / "round_feet.yaml")
    d = scene.model_dump(mode="json", exclude_none=True)
    d["walker"]["actuation"] = {"push_off": {"impulse_n_s": P}}
    d["slope"] = {"angle_rad": GAMMA}
    d["fixedpoint"]["initial_guess"] = dict(zip(d["fixedpoint"]["initial_guess"], GUESS))
    d["optimize"] = {"intervals": 60}
    scene = type(scene).model_validate(d)
    _, search = solve_scene(scene,
            plant=Plant.from_scene(scene))  # shooting on the rigid model with its push-off
    r = search.gaits[search.selected].result
    out = optimize_scene(scene, np.asarray(r.x, float), float(r.period_s),
                         plant=Plant.from_scene(scene))
    assert out.gait, (out.status, out.replay_error)  # its replay with the push-off closes
    assert out.objective <= 1e-8
    assert out.step_period_s == pytest.approx(float(r.period_s), rel=2e-7)
