"""RABBIT's virtual-constraint controller (configs/rabbit_hzd.yaml) as feedback in the
contact model and in the MuJoCo export's stepping loop.

The views evaluate the rigid closed loop's computed torque at their own role state: the
unit tests check that a floating (contact) state and MuJoCo's coordinates map to the rigid
role state and give the rigid closed loop's torques to 1e-10 (the rigid walker's own
actuators, built by the rigid view; the MuJoCo mapping against the export's ``gait``
keyframe, written from the rigid fixed point by the export's own code).  The slow tests walk
both views >= 20 steps and compare the settled speed with the rigid closed loop's (3 %:
the issue's bound; measured 1.4 % on the contact model, whose regularised friction lets the
stance foot creep, and 0.6 % in MuJoCo).
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config import scene_from_dict
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SCENE = yaml.safe_load((ROOT / "configs" / "rabbit_hzd.yaml").read_text())


@pytest.fixture(scope="module")
def scene():
    return scene_from_dict(copy.deepcopy(SCENE), ROOT / "configs" / "rabbit_hzd.yaml")


def states_on_and_off_the_surface(ctrl, rng):
    """Role states (2n,) along the designed step (on the zero-dynamics surface, at a phase
    rate of -1.3 rad/s) and perturbed off it (0.05 rad, 0.5 rad/s)."""
    s = np.linspace(0.05, 0.95, 5)
    qs, tangents = ctrl.path(s)
    out = []
    for q, t in zip(qs, tangents):
        x = np.concatenate([q, -1.3 * t])
        out.append(x)
        out.append(x + np.concatenate([rng.normal(0, 0.05, q.size),
                                       rng.normal(0, 0.5, q.size)]))
    return out


def test_contact_view_torque_is_the_rigid_closed_loops(scene):
    """At any state and either stance leg, the contact view's joint torques are the rigid
    walker's (its VirtualConstraintActuators) at the role state, to 1e-10 N m, and act
    as ``B u`` on the stance leg's floating coordinates only (none on the hip's position)."""
    from walkerlab.models.contact.scene import contact_setup
    from walkerlab.models.registry import build_walker

    rigid = build_walker(Plant.from_scene(scene)).actuators
    acts = contact_setup(scene, plant=Plant.from_scene(scene)).actuators
    assert type(acts).__name__ == "VirtualConstraintJointTorques"
    rng = np.random.default_rng(59)
    n, nq = rigid.controller.n, acts.nq
    checked = 0
    for xr in states_on_and_off_the_surface(rigid.controller, rng):
        u_rigid = rigid.torques(0.0, xr)
        assert np.max(np.abs(u_rigid)) > 1.0  # the controller acts here
        for stance in (0, 1):
            x = rng.normal(0, 1, 2 * nq)  # the other coordinates: anything
            i = acts.index[stance]
            x[i], x[nq + i] = xr[:n], xr[n:]
            u = acts.torques(x, stance)
            np.testing.assert_allclose(u, u_rigid, rtol=0, atol=1e-10)
            Q, power = acts.hip_torque(x, stance)
            Br = rigid.controller.B
            np.testing.assert_allclose(Q[i], Br @ u_rigid, rtol=0, atol=1e-10)
            assert np.all(Q[list(acts.hip)] == 0.0)
            assert power == pytest.approx(float((Br @ u_rigid) @ xr[n:]), abs=1e-9)
            checked += 1
    assert checked == 20


def test_the_law_is_no_function_of_the_joint_angles_alone(scene):
    """The law object refuses the joint-angle interface (the computed torque needs the role
    state); were it called, a run would not silently use zero torques."""
    from walkerlab.models.contact.scene import contact_setup

    acts = contact_setup(scene, plant=Plant.from_scene(scene)).actuators
    with pytest.raises(TypeError, match="role state"):
        acts.joints.laws.each(np.zeros(4), np.zeros(4), 0.0, 0.0, 0.0)


def test_mujoco_loop_without_the_walkers_model_refused(tmp_path):
    """The MJCF's stepping loop needs the scene's controller: without it, one line."""
    from walkerlab.export.mujoco_walk import PoweredLoop

    mujoco = pytest.importorskip("mujoco")
    act = json_text(SCENE["walker"]["actuation"])
    xml = (f'<mujoco><worldbody><body name="hip"><joint name="hip_x" type="slide"/>'
           f'<geom type="sphere" size="0.1"/></body></worldbody><custom>'
           f'<text name="walkerlab_actuation" data={act}/></custom></mujoco>')
    model = mujoco.MjModel.from_xml_string(xml)
    with pytest.raises(ValueError) as e:
        PoweredLoop(model)
    assert "virtual constraints" in str(e.value) and len(str(e.value).splitlines()) == 1


def json_text(obj) -> str:
    import json
    from xml.sax.saxutils import quoteattr

    return quoteattr(json.dumps(obj))


def speed_of(times, x):
    """Mean speed [m/s] over the last ten steps from heel-strike times and positions."""
    return (x[-1] - x[-11]) / (times[-1] - times[-11])


@pytest.fixture(scope="module")
def rigid_gait(scene, tmp_path_factory):
    """The rigid closed loop's fixed point: ``(runs folder, step period [s], speed
    [m/s])``; the step length is the swing foot's lead at the designed heel strike (the
    outputs' end configuration ``q-``)."""
    from walkerlab.io.schemas.fixedpoint import load_fixedpoint
    from walkerlab.models.registry import build_walker
    from walkerlab.stages import fixedpoint

    runs = tmp_path_factory.mktemp("runs")
    out = fixedpoint.run(scene, runs, compare_variants=False)
    period = float(load_fixedpoint(out.path).step_period_s)
    ctrl = build_walker(Plant.from_scene(scene)).actuators.controller
    step = float(ctrl.pieces.foot(ctrl.design.q_minus)[1])
    return runs, period, step / period


@pytest.mark.slow
def test_contact_model_walks_at_the_rigid_closed_loops_speed(scene, rigid_gait):
    """22 heel strikes (11 strides) on the contact model, alternating, no fall; the settled
    speed within 3 % of the rigid closed loop's (measured -1.4 %: 0.694 against
    0.704 m/s)."""
    import h5py

    from walkerlab.stages import contact_sim

    runs, period, speed = rigid_gait
    assert period == pytest.approx(0.5591309, abs=1e-6)
    assert speed == pytest.approx(0.704, abs=5e-4)
    out = contact_sim.run(scene, runs)
    assert out.failure is None or not out.failure
    with h5py.File(out.path) as f:
        t_hs = f["events/heel_strike_times"][()]
        legs = [v.decode() if isinstance(v, bytes) else str(v)
                for v in f["events/heel_strike_legs"][()]]
        t = f["samples/time"][()]
        hip_x = f["samples/points/hip/x"][()]
    assert len(t_hs) >= 20
    assert all(a != b for a, b in zip(legs, legs[1:]))
    v = speed_of(t_hs, np.interp(t_hs, t, hip_x))
    assert abs(v / speed - 1) < 0.03, (v, speed)


@pytest.mark.slow
def test_mujoco_export_walks_at_the_rigid_closed_loops_speed(scene, rigid_gait):
    """The MJCF's keyframe is the rigid fixed point in MuJoCo's coordinates: its role state
    gives the rigid torques to 1e-10; the stepping loop walks >= 20 alternating heel
    strikes without falling, the settled speed within 3 % of the rigid closed loop's
    (measured -0.6 %: 0.700 against 0.704 m/s)."""
    mujoco = pytest.importorskip("mujoco")
    from walkerlab.export.mujoco_walk import virtual_constraint_feedback, walk
    from walkerlab.models.registry import build_walker
    from walkerlab.stages.export import write

    runs, period, speed = rigid_gait
    out = write(scene, runs, "mjcf")
    fb = virtual_constraint_feedback(scene, Plant.from_scene(scene).data)
    model = mujoco.MjModel.from_xml_path(str(out.path))
    key = model.key("gait")
    names = [model.joint(i).name for i in range(model.njnt)]
    q = {nm: float(key.qpos[model.joint(nm).qposadr[0]]) for nm in names}
    v = {nm: float(key.qvel[model.joint(nm).dofadr[0]]) for nm in names}
    xr = fb.role_state(q, v, 1)  # leg2 stands at the keyframe
    rigid = build_walker(Plant.from_scene(scene)).actuators
    np.testing.assert_allclose(fb.torques(q, v, 1), rigid.torques(0.0, xr), rtol=0, atol=1e-10)
    y, dy = rigid.controller.outputs(xr)
    assert np.max(np.abs(y)) < 1e-6 and np.max(np.abs(dy)) < 1e-5  # on the surface
    run = walk(out.path, 22 * period + 0.3, feedback=fb)
    assert not run.fell and run.alternating and len(run.times_s) >= 20
    vm = speed_of(run.times_s, run.positions_m)
    assert abs(vm / speed - 1) < 0.03, (vm, speed)
