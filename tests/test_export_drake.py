"""The exported walker in Drake (the optional extra ``drake``; skipped without it).

- The URDF loads unchanged in Drake's ``MultibodyPlant`` (``Parser.AddModels`` on the file
  ``walkerlab export`` wrote): its mass matrix (``CalcMassMatrix``) and bias
  (``CalcBiasTerm - CalcGravityGeneralizedForces``) in walkerlab's floating coordinates
  (``M = T^T M_drake T``, the constant joint map of tests/test_export.py) equal walkerlab's
  generated floating view at random states.  Measured: largest |dM| 0 (paper, round_feet),
  2.8e-17 (kneed), 4.4e-16 (torso_bhm) against entries up to 1.6-25; bias 9e-16 to 2.8e-14
  against entries up to 4.4-264.  Tolerance 1e-9 absolute (the mass matrix), far above
  round-off.
- The compass walker's limit cycle against Drake's own ``CompassGait`` example
  (``drake/examples/compass_gait``: its flow, its ``FootCollision`` witness and its
  ``CollisionDynamics`` reset) at its default ``CompassGaitParams`` (hip 10 kg, legs 5 kg
  with the centre of mass 0.5 m from the hip, leg 1 m, g = 9.81 m/s^2, slope 0.0525 rad):
  Drake's state (stance, swing, stancedot, swingdot) measures each leg from the vertical,
  positive with the hip ahead of the foot, walkerlab's positive with the foot ahead, so
  Drake's post-impact state is walkerlab's (swing, stance, swing rate, stance rate) fixed
  point negated and reordered.  Drake is simulated (RK5, accuracy 1e-12) from walkerlab's
  point with the stance rate 1 % off until the hybrid system has converged (20 s, 27 steps;
  contraction ~0.58 a step); its post-impact state at the last collision (the simulator
  stopped at the witness-localised event time, the reset applied) equals walkerlab's fixed
  point.  Measured: 6.2e-9 (30 s: 5.2e-12); tolerance 1e-6.  Step period 0.734461 s.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.independent import floating_reference as ref
from tests.test_export import _joint_map, _states
from walkerlab.config import load_scene
from walkerlab.models.hybrid.floating_view import FloatingView
from walkerlab.stages import export as export_stage
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

# found, not imported: pydrake (with its own Eigen, urdfdom, ...) loads only in the worker
# that runs these tests
pytestmark = pytest.mark.skipif(importlib.util.find_spec("pydrake") is None,
                                reason="pydrake not installed (optional extra 'drake')")
ROOT = Path(__file__).resolve().parents[1]


class Drake:
    """The exported URDF in a ``MultibodyPlant``: mass matrix and bias in our coordinates."""

    def __init__(self, path, names, g, torso=False):
        from pydrake.multibody.parsing import Parser
        from pydrake.multibody.plant import MultibodyPlant

        self.plant = MultibodyPlant(0.0)
        Parser(self.plant).AddModels(str(path))  # the file as written
        self.plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -g])
        self.plant.Finalize()
        self.context = self.plant.CreateDefaultContext()
        joints = {self.plant.get_joint(j).name(): self.plant.get_joint(j)
                  for j in self.plant.GetJointIndices()}
        rows = _joint_map(names, torso)
        assert set(rows) <= set(joints)  # and the feet's fixed joints
        self.T = np.zeros((self.plant.num_velocities(), len(names)))
        self.Tq = np.zeros((self.plant.num_positions(), len(names)))
        for name, row in rows.items():
            self.T[joints[name].velocity_start()] = row
            self.Tq[joints[name].position_start()] = row

    def __call__(self, q, dq):
        p, c = self.plant, self.context
        p.SetPositions(c, self.Tq @ q)
        p.SetVelocities(c, self.T @ dq)
        bias = p.CalcBiasTerm(c) - p.CalcGravityGeneralizedForces(c)
        return self.T.T @ p.CalcMassMatrix(c) @ self.T, self.T.T @ bias


@pytest.mark.parametrize("name", ["paper", "kneed", "torso_bhm", "round_feet"])
def test_urdf_in_drake_has_walkerlabs_mass_matrix(name, tmp_path):
    """Drake's MultibodyPlant on the exported URDF: walkerlab's mass matrix (<= 1e-9) and bias
    (1e-10 relative, as Pinocchio's and MuJoCo's in tests/test_export.py) at random states;
    the paper walker, the kneed walker, the torso's bisecting hip (a free joint in the URDF,
    the coupling applied through T) and arc feet."""
    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    names = ref.coordinate_names(data)
    drake = Drake(export_stage.run(scene, tmp_path, "urdf"), names, data.gravity_m_per_s2,
                  bool(data.structure.torso))
    view = FloatingView(data)
    seen = []
    for q, dq in _states(len(names), seed=23):
        M, b = drake(q, dq)
        Mw, bw = view.dynamics(np.asarray(q, float), np.asarray(dq, float))
        bw = bw + ref.spring_force(data, q, dq)
        assert np.abs(M - Mw).max() <= 1e-9
        assert np.abs(b - bw).max() <= 1e-10 * np.abs(bw).max()
        seen.append(M)
    assert np.ptp(np.array(seen), axis=0).max() > 0.1  # the states differ: not a constant


def _drake_limit_cycle_point(x0, t_final):
    """Simulate Drake's CompassGait from ``x0`` (Drake's coordinates) to ``t_final`` [s] and
    return its post-impact state at the last collision and the slope."""
    from pydrake.examples import CompassGait, CompassGaitParams
    from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
    from pydrake.systems.framework import EventStatus

    def simulator(t_end, monitor=None):
        plant = CompassGait()
        context = plant.CreateDefaultContext()
        context.SetContinuousState(x0)
        sim = Simulator(plant, context)
        ResetIntegratorFromFlags(sim, "runge_kutta5", 0.01).set_target_accuracy(1e-12)
        sim.get_mutable_context().SetAccuracy(1e-12)
        if monitor is not None:
            sim.set_monitor(monitor)
        sim.Initialize()
        sim.AdvanceTo(t_end)
        return sim.get_context()

    steps = []  # (time, toe position) after each integration step

    def monitor(c):
        steps.append((c.get_time(), c.get_discrete_state_vector().GetAtIndex(0)))
        return EventStatus.Succeeded()

    simulator(t_final, monitor)
    toe = np.array([s[1] for s in steps])
    last = np.nonzero(np.diff(toe))[0][-1]  # the step ending at the last collision's time
    # the same run again, stopped at that collision: the witness localises it and the
    # simulator applies Drake's reset (CollisionDynamics) at the stop
    c = simulator(steps[last][0])
    # the reset is done: the toe has moved on by a step (the rerun's steps differ near the
    # stop, so its toe differs from the first run's in the last digits)
    assert c.get_discrete_state_vector().GetAtIndex(0) == pytest.approx(toe[last + 1],
                                                                         abs=1e-9)
    assert toe[last + 1] - toe[last] > 0.1
    return c.get_continuous_state_vector().CopyToVector(), CompassGaitParams().slope()


def test_compass_limit_cycle_matches_drakes_compass_gait(tmp_path):
    """walkerlab's fixed point of Drake's default compass gait equals the limit cycle of
    Drake's CompassGait system to 1e-6 (module docstring)."""
    from pydrake.examples import CompassGaitParams

    from walkerlab.analysis.contact.periodic import ideal_gait

    p = CompassGaitParams()
    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    d = {"name": "drake_compass_gait", "solver": d["solver"],
         "walker": {"model": "compass_gait", "leg_length_m": p.length_leg(),
                    "leg_mass_kg": p.mass_leg(), "hip_mass_kg": p.mass_hip(),
                    "gravity_m_per_s2": p.gravity(),
                    "leg_mass_from_foot_m": p.length_leg() - p.center_of_mass_leg()},
         "slope": {"angle_rad": p.slope()}}  # no fixedpoint section: the automatic search
    (tmp_path / "drake.yaml").write_text(yaml.safe_dump(d))
    sc = load_scene(tmp_path / "drake.yaml")
    x = ideal_gait(sc, plant=Plant.from_scene(sc)).x  # swing, stance, their rates
    ours = -np.array([x[1], x[0], x[3], x[2]])  # Drake's stance, swing, stancedot, swingdot
    start = ours * np.array([1.0, 1.0, 1.01, 1.0])
    theirs, slope = _drake_limit_cycle_point(start, 20.0)
    assert theirs[0] + theirs[1] == pytest.approx(2 * slope, abs=1e-10)  # on Drake's guard
    assert np.abs(theirs - ours).max() <= 1e-6, theirs - ours
    assert np.abs(start - ours).max() > 1e-2  # Drake walked there from elsewhere
