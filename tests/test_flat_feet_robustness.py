"""Robustness of the flat-footed walker (issue 24 for configs/flat_feet.yaml): its step map runs
row by row through the rigid integrator (no compiled flows), the step-down is located on the
lowered ground, and the mid-stance push restarts the step on the phase graph."""

from __future__ import annotations

import numpy as np
import pytest

from walkerlab.analysis.robustness import measures as R
from walkerlab.analysis.robustness import push
from walkerlab.config import load_scene
from walkerlab.integrate.batch_step import HEEL_STRIKE
from walkerlab.integrate.python_step import PythonStepMap, make_step_map
from walkerlab.integrate.rigid import integrate_step, simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.studies.mfpt import scene_walker_at
from walkerlab.walker.plant import Plant

#: the gait of configs/flat_feet.yaml (reports/22a.md; 10 digits on the angles, 8 on rates)
X_STAR = np.array([-0.3473790834, 0.2559008258, 0.0, -1.3354750, -1.1909763, -11.3443774])
SOLVER = Solver("DOP853", 1e-12, 1e-12, None, "scipy")


@pytest.fixture(scope="module")
def flat():
    scene = load_scene("configs/flat_feet.yaml")
    walker = build_walker(Plant.from_scene(scene))
    return walker, make_step_map(walker, scene_walker_at(scene,
            plant=Plant.from_scene(scene)), 1e-10, 1e-10)


def test_flat_feet_get_the_python_step_map_with_the_integrators_step(flat):
    walker, sm = flat
    assert isinstance(sm, PythonStepMap)
    r = sm.step(X_STAR[None, :])
    seg = integrate_step(walker, X_STAR, SOLVER)
    assert r.outcome[0] == HEEL_STRIKE
    # the gait's step: period 0.7575854986 s (22a), the same step as integrate_step's at 1e-10
    assert r.step_time_s[0] == pytest.approx(seg.period, abs=1e-8)
    assert np.allclose(r.x_next[0], seg.x_next, atol=1e-7)


def test_step_down_lands_on_the_lower_ground(flat):
    """A step-down of 1 cm: the swing heel's height at the landing is -1 cm (points of the
    model, independent of the guard's formula), later than on the level."""
    walker, sm = flat
    r = sm.step(np.tile(X_STAR, (2, 1)), None, drop_m=np.array([0.01, -0.01]))
    assert (r.outcome == HEEL_STRIKE).all()
    level = integrate_step(walker, X_STAR, SOLVER).period
    assert r.step_time_s[0] > level > r.step_time_s[1]
    for x_pre, drop in zip(r.x_pre, (0.01, -0.01)):
        p = walker.points(x_pre)
        heel = np.asarray(p["swing_heel"], float)
        # height above the slope line through the reference point (stance heel touchdown)
        g = walker.slope_rad
        height = heel[1] * np.cos(g) + heel[0] * np.sin(g)
        assert height == pytest.approx(-drop, abs=1e-9)


@pytest.mark.slow
def test_largest_step_down_against_direct_simulation(flat):
    """Bisection to 1 mm over 10 survival steps; then a direct simulation (simulate_steps of
    the level walker from the dropped step's post-impact state) survives 10 steps just below
    the bracket and falls just above it."""
    walker, sm = flat
    steps = 10
    lo, hi = R.largest_by_bisection(sm, X_STAR, "floor_height", 0.1, 1e-3, steps)
    assert 0 < lo < hi <= lo + 1e-3 + 1e-12
    for drop, survives in ((lo, True), (hi, False)):
        r = sm.step(X_STAR[None, :], None, drop_m=drop)
        if r.outcome[0] != HEEL_STRIKE:
            assert not survives
            continue
        traj = simulate_steps(walker, r.x_next[0], steps, Solver("DOP853", 1e-10, 1e-10, None,
                                                                 "scipy"))
        walked = len(traj.segments) == steps and traj.termination == "heel_strike"
        assert walked == survives, (drop, traj.termination, len(traj.segments))


def test_push_restart_follows_the_phase_graph(flat):
    """A push of 0 m/s reproduces the gait's step; the restart walker is the phase graph
    rotated to the mid-stance phase, so a restart from any phase's state finishes the step as
    the walker's own step does."""
    walker, _ = flat
    p = push.pushed_step(walker, X_STAR, np.array([0.0]), solver=SOLVER)
    seg = integrate_step(walker, X_STAR, SOLVER)
    assert p.outcome[0] == HEEL_STRIKE
    assert p.step_time_s[0] == pytest.approx(seg.period, abs=1e-9)
    assert np.allclose(p.x_next[0], seg.x_next, atol=1e-8)
    # restart in every phase the step visits (the 3rd, foot_flat:late_swing, was where
    # phases[k:] with the piece's index started in heel_off:early_swing)
    for j, (ph, dense, (ta, tb)) in enumerate(seg.pieces):
        tm = 0.5 * (ta + tb)
        rest = push.starting_at(walker, ph.name)
        s2 = integrate_step(rest, np.asarray(dense(tm), float)[:X_STAR.size], SOLVER, t0=tm)
        assert s2.termination == "heel_strike", ph.name
        assert [e[0] for e in s2.phase_log] == [e[0] for e in seg.phase_log[j:]]
        assert s2.t_end == pytest.approx(seg.t_end, abs=1e-8)
        assert np.allclose(s2.x_next, seg.x_next, atol=1e-7)


def test_push_in_foot_flat_keeps_the_foot_locked(flat):
    """In foot flat the push's impulse keeps the foot flat (stance + ankle rates sum to 0) and
    changes the hip's horizontal velocity by exactly dv."""
    walker, _ = flat
    seg = integrate_step(walker, X_STAR, SOLVER)
    ph, dense, (ta, tb) = next(pc for pc in seg.pieces if pc[0].name == "foot_flat:late_swing")
    x = np.asarray(dense(0.5 * (ta + tb)), float)
    lock = push.entry_lock(walker, ph.name)
    assert lock is not None
    assert push.entry_lock(walker, "heel_off:late_swing") is None  # heel off: no impact
    names = walker.state_names()
    i_s, i_a = names.index("stance_rate"), names.index("stance_ankle_rate")
    dv = 0.1
    xp, P = push.apply_push(walker, x, dv, lock)
    assert abs(xp[i_s] + xp[i_a]) < 1e-12
    lay = walker.layout()
    J = push.hip_jacobian(walker, x)
    v0, v1 = J @ lay.qd(x), J @ lay.qd(xp)
    assert v1[0] - v0[0] == pytest.approx(dv, abs=1e-8)
    assert P > 0
    # without the lock the foot would start turning
    free, _ = push.apply_push(walker, x, dv)
    assert abs(free[i_s] + free[i_a]) > 1e-3
