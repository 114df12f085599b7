"""The compass walker against Drake's ``CompassGait`` (Tedrake, Underactuated Robotics; the
RobotLocomotion/drake example, an independent implementation): at Drake's default
parameters (hip 10 kg, legs 5 kg with the mass at 0.5 m, length 1 m, slope 0.0525 rad,
g 9.81 - configs/compass_optimal.yaml is the same walker) the least-effort gait by
collocation is Drake's limit cycle.  Skipped without pydrake (the engines extra)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import walkerlab as wl
from walkerlab.codegen import legged
from walkerlab.config import load_scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.optimal.guess import simulated_step
from walkerlab.optimal.transcription.mode_sequence import collocate_step
from walkerlab.optimal.transcription.step import CollocationSpec
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

drake = pytest.importorskip("pydrake.examples")
pytest.importorskip("casadi")
CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def test_least_effort_gait_is_drakes_compass_gait_limit_cycle():
    """Drake's angles are the legs' from the vertical, counter-clockwise: ours negated,
    ``(stance, swing, stancedot, swingdot) = -(stance_angle, swing_angle, stance_rate,
    swing_rate)``.  Started on walkerlab's fixed point just after heel strike, Drake's
    simulator (RK5, accuracy 1e-12, its own witness-located foot collision and reset) is
    back there one step period later (1e-9 s after, our flow's 1e-9 s added) to 1e-7;
    the collocated gait's start is Drake's to 1e-6 in every state, its toe moved by the
    collocated step length; Drake's parameters are checked to be the scene's."""
    from pydrake.examples import CompassGaitParams

    p = CompassGaitParams()
    assert (p.mass_hip(), p.mass_leg(), p.length_leg(), p.center_of_mass_leg(), p.gravity(),
            p.slope()) == (10.0, 5.0, 1.0, 0.5, 9.81, 0.0525)
    scene = load_scene(CONFIGS / "compass_optimal.yaml")
    w = wl.Walker.from_scene(scene)
    g = w.fixed_point()
    data = walker_data(scene.walker, scene.slope.phi_rad)
    t, x = simulated_step(build_walker(Plant.from_scene(scene)), g.x, g.step_period,
                          Solver("DOP853", 1e-12, 1e-12))
    res = collocate_step(data, legged.derive_legged(data.structure), CollocationSpec(intervals=60),
                         t, x)
    assert res.status == "Solve_Succeeded" and res.objective <= 1e-10
    names = list(w.model.state_names())
    order = [names.index(n) for n in ("stance_angle", "swing_angle", "stance_rate",
                                      "swing_rate")]
    got, moved = _drake_step(-g.x[order], g.step_period)
    after = -(g.x + DT * np.asarray(w.model.phases[0].flow(0.0, g.x)))[order]
    np.testing.assert_allclose(got, after, rtol=0, atol=1e-7)  # shooting: 2e-9 seen
    # the collocated gait (Hermite-Simpson, 60 intervals) and Drake's, started from it
    np.testing.assert_allclose(-res.x[0][order], got, rtol=0, atol=1e-6)
    assert res.step_period_s == pytest.approx(g.step_period, abs=1e-7)
    assert moved == pytest.approx(res.step_length_m, abs=1e-6)


DT = 1e-9


def _drake_step(start, period):
    """Drake's compass gait from ``start`` (its state order) for ``period + DT`` [s]: its
    continuous state then and how far its toe moved [m]."""
    from pydrake.examples import CompassGait
    from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator

    sim = Simulator(CompassGait())
    ctx = sim.get_mutable_context()
    ctx.SetContinuousState(start)
    ResetIntegratorFromFlags(sim, "runge_kutta5", 0.01)
    ctx.SetAccuracy(1e-12)
    sim.Initialize()
    toe = ctx.get_discrete_state_vector().CopyToVector()[0]
    sim.AdvanceTo(period + DT)
    return (ctx.get_continuous_state_vector().CopyToVector(),
            ctx.get_discrete_state_vector().CopyToVector()[0] - toe)
