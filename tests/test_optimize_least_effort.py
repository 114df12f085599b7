"""The least-effort gait (int u^2 dt) of every walker family on a slope where it walks
passively is its passive gait: int u^2 dt = 0 there, so the optimum is it.  Arc feet
(configs/round_feet.yaml), a torso on straight legs (configs/torso_bhm.yaml), knees
(configs/kneed.yaml), flat feet (configs/flat_feet.yaml) and legs that differ
(configs/asymmetric_legs.yaml), each through ``walkerlab optimize``'s scene path
(:func:`walkerlab.optimal.driver.optimize_scene`, the CasADi functions printed from the
walker's generated model), on its shipped slope and on one not shipped; against the
passive gait of the fixedpoint stage's search (shooting on the rigid model, independent of
the collocation) of the walker the transcription optimises: flat feet without their double
support (``make_rigid_walker(data, double_support=False)``, the phased transcription has no
double-support phase; :func:`walkerlab.optimal.driver.optimize_scene` solves that walker's
fixed point as its start, 0.7576 s on configs/flat_feet.yaml against 0.8102 s with the
double support)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"

#: (scene, slope factor, intervals): Hermite-Simpson's period error is O(h^4); the
#: intervals keep it <= 1e-7 relative with a margin (seen: arc feet 7.4e-8 and the torso
#: 8.7e-8 on 40 intervals; knees 2.0e-7 on 40, 1-2e-8 on 80; flat feet 1.1e-6 on 40,
#: 2e-9 on 200 (their heel contact's fast ankle)).  The kneed and flat-footed walkers
#: have no passive period-1 gait the search finds at 0.8x their slope: 0.9x there.
CASES = [("round_feet", 1.0, 60), ("round_feet", 0.8, 60), ("torso_bhm", 1.0, 60),
         ("torso_bhm", 0.8, 60), ("kneed", 1.0, 80), ("kneed", 0.9, 80),
         ("flat_feet", 1.0, 200), ("flat_feet", 0.9, 200), ("asymmetric_legs", 1.0, 60),
         ("asymmetric_legs", 0.8, 60)]


def _scene(name: str, factor: float, intervals: int):
    """The scene at ``factor`` times its slope with the optimize section's defaults (least
    effort, the scene's push-off: none) on ``intervals``."""
    scene = load_scene(CONFIGS / f"{name}.yaml")
    d = scene.model_dump(mode="json", exclude_none=True)
    key = "angle_rad" if "angle_rad" in d["slope"] else "angle_deg"
    d["slope"][key] *= factor
    d["optimize"] = {"intervals": intervals}
    return type(scene).model_validate(d)


@pytest.mark.slow
@pytest.mark.parametrize(("name", "factor", "intervals"), CASES)
def test_the_least_effort_gait_on_a_passive_slope_is_the_passive_gait(name, factor,
                                                                      intervals):
    """objective <= 1e-8 (int u^2 dt [N^2 m^2 s]), every step's period within 1e-7
    (relative) of the passive gait's, and the optimum a gait (IPOPT converged, the replay
    on the rigid model closing to the scene's replay tolerance) (~2-20 s each)."""
    pytest.importorskip("casadi")
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.models.hybrid.rigid import make_rigid_walker
    from walkerlab.optimal.driver import optimize_scene
    from walkerlab.walker.description import walker_data

    scene = _scene(name, factor, intervals)
    data = walker_data(scene.walker, scene.slope.phi_rad)
    walker = None  # the scene's rigid model; flat feet: the optimised one, no double support
    if data.structure.foot == "flat":
        walker = make_rigid_walker(data, double_support=False)
    _, search = solve_scene(scene, walker=walker,
            plant=Plant.from_scene(scene))  # the fixedpoint stage's search (shooting)
    r = search.gaits[search.selected].result
    periods = np.asarray(r.step_periods_s, float)
    out = optimize_scene(scene, np.asarray(r.x, float), float(r.period_s) / len(periods),
                         plant=Plant.from_scene(scene))
    assert out.gait, (out.status, out.replay_error)
    assert out.objective <= 1e-8
    if len(periods) == 1:
        assert out.step_period_s == pytest.approx(periods[0], rel=1e-7)
    else:  # a stride of two different steps: its mean step
        assert out.step_period_s == pytest.approx(periods.mean(), rel=1e-7)


def test_arc_feet_and_a_torso_are_optimised():
    """The one-step transcription takes arc feet and a torso on straight legs (their
    functions printed from the generated model: the flow's ``M``, ``C``, ``G``, the
    extended heel strike); a push-off on arc feet is transcribed too
    (tests/test_optimize_arc_push_off.py)."""
    pytest.importorskip("casadi")
    from walkerlab.codegen import legged
    from walkerlab.optimal.transcription.step import step_functions
    from walkerlab.walker.description import walker_data

    for name in ("round_feet", "torso_bhm"):
        scene = load_scene(CONFIGS / f"{name}.yaml")
        data = walker_data(scene.walker, scene.slope.phi_rad)
        fns = step_functions(data, legged.derive_legged(data.structure))
        assert {"flow", "reset", "guard"} <= set(fns)
