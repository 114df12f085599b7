"""The in-memory walker (``wl.Walker``) against hostile input, and the numbers its results
carry: a state of the wrong shape or value, strides that are not whole, a walk past the
sample cap get one ``SceneError`` line before anything is integrated; a walking step past its
CPU-time limit and a fall are one clear line; the gait and the walk carry the step length,
speed, energy ledger and cost of transport of the ``simulate`` stage's own functions."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import walkerlab as wl
from walkerlab.analysis.gait.poincare import StepFailed, poincare_map
from walkerlab.config import SceneError
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


@pytest.fixture(scope="module")
def paper():
    w = wl.Walker.from_scene(CONFIGS / "paper.yaml")
    return w, w.fixed_point()


STATES = {"3 items": np.ones(3), "5 items": np.ones(5), "2-D": np.ones((2, 4)),
          "NaN": np.array([np.nan, 0.1, 0.0, 0.0]), "inf": np.array([0.1, np.inf, 0.0, 0.0]),
          "None": None, "text": "abc", "complex": np.ones(4) * 1j}
SAYS = {"3 items": r"shape \(3,\)", "5 items": r"shape \(5,\)", "2-D": r"shape \(2, 4\)",
        "NaN": r"x\[0\] \(swing_angle\) = nan", "inf": r"x\[1\] \(stance_angle\) = inf",
        "None": "x=None", "text": "x='abc'", "complex": "not numbers"}


@pytest.mark.parametrize("method", ["step", "jacobian", "floquet", "simulate"])
@pytest.mark.parametrize("case", list(STATES))
def test_a_state_of_the_wrong_shape_or_value_is_one_scene_error(paper, method, case):
    w, _ = paper
    args = (STATES[case], 1) if method == "simulate" else (STATES[case],)
    with pytest.raises(SceneError) as err:
        getattr(w, method)(*args)
    msg = str(err.value)
    pattern = SAYS[case].replace("x", "x0", 1) if method == "simulate" else SAYS[case]
    assert "\n" not in msg and __import__("re").search(pattern, msg), msg
    assert "(swing_angle, stance_angle, swing_rate, stance_rate)" in msg or "=" in msg


def test_an_absurd_state_fails_at_once_and_a_step_has_a_work_limit(paper):
    w, gait = paper
    from walkerlab.integrate import work_limit

    with work_limit.work_bound(1e18):  # every evaluation counted, none stopped
        n0 = work_limit.done()
        for fn in (w.step, w.jacobian, lambda x: w.simulate(x, 1)):
            with pytest.raises(SceneError, match="more than half a turn"):
                fn(gait.x * 1e10)  # was 332 s of integration before failing
        x = gait.x.copy()
        x[2] = 100.0  # 100 rad/s: above 20 sqrt(g/l) = 62.6 rad/s, no walking state
        with pytest.raises(SceneError,
                           match=r"x\[2\] \(swing_rate\) = 100 rad/s is not a walking"):
            w.step(x)
        assert work_limit.done() == n0  # refused before any integration
    # the per-step work bound: a limit far below one step's cost stops the map in one line,
    # the same on any machine (evaluations, not seconds)
    tight = wl.Walker(w.scene, step_evaluations=10)
    with pytest.raises(StepFailed, match=r"^step: a walking step used up its 10 "
                                         r"right-hand-side evaluations"):
        tight.step(gait.x)
    with pytest.raises(StepFailed, match="used up"):
        tight.simulate(gait.x, 1)
    # ... and the bound does not change a map: bit for bit the library's
    x1, period, _ = poincare_map(w.model, gait.x, w.solver, w.max_step_time)
    step = w.step(gait.x)
    assert np.array_equal(step.x_next, x1) and step.period == period
    with pytest.raises(SceneError, match="step_evaluations=0: give a positive number of "
                                         "right-hand-side evaluations"):
        wl.Walker(w.scene, step_evaluations=0)


def test_a_step_from_a_falling_state_says_the_walker_fell(paper):
    w, gait = paper
    x = gait.x.copy()
    x[2:] *= 3  # rates three times the gait's: the swing leg overtakes, the walker falls
    with pytest.raises(StepFailed) as err:
        w.step(x)
    msg = str(err.value)
    assert msg.startswith("step: the walker fell at t = 0.5") and "heel strike" in msg
    assert "maximum allowed" not in msg and "Integration" not in msg  # not CyRK's words
    assert err.value.termination == "fall"


@pytest.mark.parametrize("strides, says", [
    (10 ** 9, "less than or equal to 1000"), (1.5, "whole number"), (True, "whole number"),
    ("2", "whole number"), (0, "greater than or equal to 1"), (2.0, "whole number")])
def test_simulate_takes_whole_strides_within_the_cap(paper, strides, says):
    w, gait = paper
    from walkerlab.integrate import work_limit

    with work_limit.work_bound(1e18):  # every evaluation counted
        n0 = work_limit.done()
        with pytest.raises(SceneError, match=f"simulate: strides={strides!r}: .*{says}"):
            w.simulate(gait.x, strides)
        assert work_limit.done() == n0  # refused at once (10**9 ran 280 s and on)


def test_simulate_refuses_more_samples_than_the_stage_keeps(paper):
    w, gait = paper
    # 5 strides of 2 x 0.73 s at 1 MHz: 7.3e6 samples > 5,000,000 (the simulate stage's cap)
    with pytest.raises(SceneError, match="at most 5,000,000 are kept"):
        w.simulate(gait.x, 5, sample_rate_hz=1e6)
    for bad in (0, -1.0, float("nan"), "500", True):
        with pytest.raises(SceneError, match="sample_rate_hz"):
            w.simulate(gait.x, 1, sample_rate_hz=bad)


def test_gait_and_walk_carry_the_stage_s_measures_and_ledger(paper):
    w, gait = paper
    # a passive gait: the cost of transport is sin(slope) (Collins et al. 2005), its energy
    # lost at heel strike is what gravity put in over the step, the ledger closes
    slope = w.model.params["slope_rad"]
    assert gait.cost_of_transport == pytest.approx(np.sin(slope), rel=1e-12)
    assert gait.ledger["heel_strike_loss"][0] == pytest.approx(
        gait.ledger["potential_work"][0], rel=1e-9)
    assert abs(gait.ledger["closure"][0]) < 1e-9
    assert gait.speed == pytest.approx(gait.step_length / gait.step_period, rel=1e-12)
    assert 0.3 < gait.step_length < 0.45  # paper Table 3: 0.37 m
    walk = w.simulate(gait.x, 2, sample_rate_hz=100)
    assert walk.step_length.shape == walk.speed.shape == walk.cost_of_transport.shape == (4,)
    assert np.allclose(walk.step_length, gait.step_length, rtol=1e-9)
    assert np.allclose(walk.cost_of_transport, gait.cost_of_transport, rtol=1e-9)
    assert set(walk.ledger) == set(gait.ledger) and "impact_energy_loss" in walk.steps


def test_a_powered_gait_s_ledger_is_the_simulate_stage_s_bit_for_bit():
    from walkerlab.analysis.gait.rigid_run import simulate_run
    from walkerlab.config.options import with_strides

    w = wl.Walker.from_scene(CONFIGS / "powered_compass.yaml")
    gait = w.fixed_point()
    one = with_strides(w.scene, 1)
    run = simulate_run(one, SimpleNamespace(x=gait.x, step_period_s=gait.step_period),
                       Plant.from_scene(one))
    for k, v in run.ledger.items():
        assert gait.ledger[k][0] == v[0], k
    assert gait.step_length == run.steps["step_length"][0]
    # on level ground all the energy comes from the push-off: CoT = its work / (M g d)
    m, g = w.model.total_mass_kg, w.model.params["gravity_m_per_s2"]
    assert gait.cost_of_transport == pytest.approx(
        gait.ledger["push_off_work"][0] / (m * g * gait.step_length), rel=1e-12)
