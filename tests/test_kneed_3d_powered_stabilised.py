"""The powered stabilised kneed walker in 3D (``configs/kneed_3d_powered_stabilised.yaml``):
configs/kneed_3d_stabilised.yaml's walker (locking knees, McGeer 1990; hip-roll joints and
Kuo's 1999 lateral foot placement) with configs/kneed_3d_powered.yaml's push-off (Kuo 2002),
hip and swing-knee spring-dampers - the reference case of the kneed 3D walker's hip torque,
knee torque and push-off cells in every view (:data:`walkerlab.walker.reference_cases.
SHIPPED`).

Quick: the scene is the stabilised walker's structure (the torque laws and the push-off add
no equation: the same generated model) with the three actuators; its shipped gait is a fixed
point of the rigid stride map whose every Floquet multiplier lies inside the unit circle
(the same laws on the walker without hip-roll joints keep its lateral multiplier of 39), and
the actuators change the gait (the powered step is 0.58 % quicker than the passive one's).

Slow: the compliant-contact walk (walkerlab contact-sim) and the MuJoCo walk of its MJCF
against the rigid walk - references the contact model and MuJoCo do not compute.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.contact_walks import contact_period_against_rigid
from walkerlab.analysis.gait.poincare import poincare_map
from walkerlab.config import load_scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.kinds import kind_of
from walkerlab.walker.plant import Plant
from walkerlab.walker.reference_cases import reference_scene

ROOT = Path(__file__).resolve().parents[1]
SCENE = "kneed_3d_powered_stabilised"
#: the rigid gait's step period [s] (walkerlab fixedpoint on the scene, residual 2.1e-11)
STEP_PERIOD_S = 0.5363434860
#: configs/kneed_3d_stabilised.yaml's passive step period [s] (its header)
PASSIVE_STEP_PERIOD_S = 0.539454
#: the scene's solver (rtol = atol = 1e-10): the generated flow's round-off leaves the stride
#: map 1e-9 of noise (configs/kneed_3d_stabilised.yaml), and the shipped guess has 10 digits
MAP_TOL = 1e-8



@pytest.fixture(scope="module")
def powered():
    scene = load_scene(ROOT / "configs" / f"{SCENE}.yaml")
    plant = Plant.from_scene(scene)
    return scene, plant, build_walker(plant)


def test_the_powered_walker_is_the_stabilised_structure_with_three_actuators(powered):
    """Its structure (the key of the generated equations) is configs/kneed_3d_stabilised.yaml's
    - the torque laws and the push-off are evaluated outside the generated flow - and it
    carries a hip law, a swing-knee law and a push-off; it is the reference case of the
    kind's hip torque, knee torque and push-off cells in every view but optimize, each of
    which the table now supports."""
    scene, plant, _walker = powered
    passive = load_scene(ROOT / "configs" / "kneed_3d_stabilised.yaml")
    assert plant.data.structure == Plant.from_scene(passive).data.structure
    act = scene.walker.actuation
    assert [t.joint for t in act.torques] == ["hip", "swing_knee"]
    assert act.push_off.impulse_n_s == 0.02
    kind = kind_of(plant.data.structure)
    assert kind.name == "locking_knees_3d"
    for feature in ("hip_torque", "knee_torque", "push_off"):
        for view in ("rigid", "gym", "contact", "mjcf", "urdf", "adams", "osim"):
            assert kind.supports(feature, view), (feature, view)
            assert reference_scene(kind.name, feature, view)[0] == f"configs/{SCENE}.yaml"


def test_the_powered_gait_is_a_stable_fixed_point_and_quicker_than_the_passive(powered):
    """One stride of the rigid map (a knee strike and a heel strike per step, the push-off
    before each heel strike) from the shipped gait returns to it within :data:`MAP_TOL`
    (measured 1.8e-10) in twice the step period walkerlab fixedpoint printed (to 1e-8 s);
    the map's Jacobian (variational equations with saltation) has every multiplier inside
    the unit circle (measured largest 0.7956, then |0.3358 +- 0.6803j| = 0.7586, 0.7037: the
    passive stabilised walker's 0.7661, 0.7238, 0.6995; configs/kneed_3d_powered.yaml, the
    same laws without hip-roll joints: 39.17).  The actuators change the gait: its step is
    0.58 % quicker than the passive stabilised walker's 0.539454 s (the check fails if they
    were dropped)."""
    scene, _plant, walker = powered
    s = scene.solver
    x0 = scene.fixedpoint.initial_guess.as_array(walker.state_names())
    x1, period, DP, _ = poincare_map(walker, x0, Solver(method=s.method, rtol=s.rtol,
                                                        atol=s.atol), jacobian=True)
    assert np.max(np.abs(x1 - x0)) < MAP_TOL
    assert period == pytest.approx(2 * STEP_PERIOD_S, abs=1e-8)
    mu = np.abs(np.linalg.eigvals(DP))
    assert mu.max() < 0.85, np.sort(mu)[::-1][:4]
    assert period / 2 < PASSIVE_STEP_PERIOD_S * (1 - 0.004)


@pytest.mark.slow  # ~8 min: the contact walk (6 strides), the MJCF's two MuJoCo walks
def test_the_contact_and_mujoco_walks_keep_the_powered_rigid_step_period(tmp_path):
    """The compliant-contact walk (walkerlab contact-sim: 6 strides on the rigid gait's
    footfall patches, the push-off a pulse ending at the heel strike) makes >= 10 heel
    strikes, its mean step period over steps 9-12 within 1 % of the rigid walk's same steps
    (measured +0.68 %, speed -1.61 %; the passive stabilised walker's contact gait, 0.5437 s,
    is 1.4 % off this rigid one: a contact model that dropped the actuators would fail).  The
    MJCF walked in MuJoCo (export --walk: the laws and the push-off applied by walkerlab's
    stepping loop beside the hip-roll law) makes >= 10 alternating heel strikes without
    falling, its mean step period within 1 % of the rigid gait's (measured -0.63 %); the same
    file with its actuation text renamed (MuJoCo then walks it passively, from the powered
    gait's keyframe) steps slower: the actuators' effect on MuJoCo's mean step period lies
    within a factor 2 of the rigid model's -0.58 % (measured -0.85 %: MuJoCo's soft contact
    and the passive walk's transient from the powered keyframe; dropped actuators: 0)."""

    pytest.importorskip("mujoco")
    from walkerlab.export.mujoco_walk import walk
    from walkerlab.stages import export as export_stage

    scene = load_scene(ROOT / "configs" / f"{SCENE}.yaml")
    period = contact_period_against_rigid(scene, tmp_path)
    assert abs(period) < 0.01, period
    out = export_stage.write(scene, tmp_path, "mjcf", walk=True)
    check = out.walk
    assert check.walked and not check.fell and check.alternating, check.line
    assert check.strikes >= 10, check.line
    assert check.rigid_period_s == pytest.approx(STEP_PERIOD_S, abs=1e-8)
    assert check.period_s == pytest.approx(STEP_PERIOD_S, rel=0.01), check.line
    text = Path(out.path).read_text()
    passive = tmp_path / "passive.xml"
    passive.write_text(text.replace('<text name="walkerlab_actuation"', '<text name="off"'))
    run = walk(passive, 11.3 * STEP_PERIOD_S)
    assert not run.fell and len(run.times_s) >= 10
    effect = check.period_s / float(np.mean(run.step_periods_s)) - 1.0
    rigid_effect = STEP_PERIOD_S / PASSIVE_STEP_PERIOD_S - 1.0
    assert 2.0 * rigid_effect < effect < 0.5 * rigid_effect, (effect, rigid_effect)
