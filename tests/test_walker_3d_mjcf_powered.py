"""The powered 3D straight-legged walker's MJCF (``configs/hip_width_powered.yaml``: a hip
spring between the legs' pitch joints and Kuo 2002's push-off, on the stabilised walker's
hip-roll joints; :mod:`walkerlab.export.legs_3d_mjcf`, walked by
:class:`walkerlab.export.mujoco_walk.PoweredLoop` with
:class:`~walkerlab.export.mujoco_walk.HipRollLoop`): the file's motor and custom text, the
loop's hip torque against the rigid model's generalised force, the push-off's velocity
change in MuJoCo against the rigid model's extended impulse, and the walk against the rigid
step period."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from walkerlab.cli.options import load
from walkerlab.stages import export
from walkerlab.walker.plant import Plant

mujoco = pytest.importorskip("mujoco")
#: every test shares the gait search and the rigid walker's build (~70 s)
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def powered(tmp_path_factory):
    """configs/hip_width_powered.yaml exported with its gait, its rigid walker and gait:
    (scene, path, Exported, rigid walker, gait state x (10,))."""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.models.registry import build_walker

    scene = load(str(ROOT / "configs" / "hip_width_powered.yaml"))
    out = export.write(scene, tmp_path_factory.mktemp("powered_3d"), "mjcf")
    plant = Plant.from_scene(scene)
    walker = build_walker(plant)
    x = np.asarray(ideal_gait(scene, plant=plant).x, float)
    return scene, out.path, out, walker, x


def _states(x, count: int, seed: int) -> list:
    """The gait state ``x`` (10,) and ``count`` states about it (angles +-0.05 rad, rates
    +-0.3 rad/s), whose rolls and pitches all differ."""
    rng = np.random.default_rng(seed)
    scale = np.r_[np.full(5, 0.05), np.full(5, 0.3)]
    return [x] + [x + scale * rng.uniform(-1, 1, 10) for _ in range(count)]


def _at(path, scene, x, contact: bool = True):
    """MuJoCo's model and data of the file at ``path`` set to the rigid state ``x`` (leg2 in
    stance, leg1 swinging: :func:`walkerlab.export.legs_3d_mjcf.legs3d_keyframe`)."""
    from walkerlab.codegen.cache import functions
    from walkerlab.export.legs_3d_mjcf import legs3d_keyframe
    from walkerlab.walker.description import walker_data

    model = mujoco.MjModel.from_xml_path(str(path))
    if not contact:
        model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    data = mujoco.MjData(model)
    d = walker_data(scene.walker, scene.slope.phi_rad)
    f = functions(d)
    qpos, qvel = legs3d_keyframe(f["points"], f["point_velocities"], x, d.slope_rad,
                                 scene.walker.leg_length_m / 1000)
    data.qpos[:], data.qvel[:] = qpos, qvel
    mujoco.mj_forward(model, data)
    return model, data


def _loop(model):
    from walkerlab.export.mujoco_walk import LEGS, PoweredLoop

    loop = PoweredLoop(model)
    loop.bind(model, [model.site(f"{g}_foot").id for g in LEGS])
    return loop


def test_the_powered_3d_mjcf_has_the_planar_hip_motor_and_the_scenes_actuation(powered):
    """The file carries the planar MJCF's actuators: one motor ``hip`` on the fixed tendon
    ``hip_actuation = leg1_hip - leg2_hip`` (the legs' pitch hinges), the scene's
    ``walker.actuation`` in the custom text ``walkerlab_actuation`` (read back equal), the
    push-off pulse one timestep long, and the hip-roll law's text beside them; the
    stepping loop's items are listed as left out."""
    scene, path, out, _w, _x = powered
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.nu == 1 and model.actuator(0).name == "hip"
    assert model.actuator_trntype[0] == mujoco.mjtTrn.mjTRN_TENDON
    t = model.tendon("hip_actuation")
    adr = int(model.tendon_adr[t.id])
    joints = [model.joint(int(model.wrap_objid[adr + k])).name for k in range(2)]
    assert joints == ["leg1_hip", "leg2_hip"]
    assert list(model.wrap_prm[adr:adr + 2]) == [1.0, -1.0]
    i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, "walkerlab_actuation")
    adr, size = int(model.text_adr[i]), int(model.text_size[i])
    text = json.loads(bytes(model.text_data[adr:adr + size - 1]).decode())
    assert text == scene.walker.actuation.model_dump(mode="json", exclude_none=True)
    k = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, "push_off_duration_s")
    assert model.numeric_data[model.numeric_adr[k]] == model.opt.timestep
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, "walkerlab_hip_roll") >= 0
    assert any("push-off" in ln for ln in out.left_out)
    assert any("torque laws" in ln for ln in out.left_out)


def test_the_loops_hip_torque_is_the_rigid_models_generalised_force(powered):
    """At the gait state and states about it (every roll and pitch different), the loop's
    generalised forces on MuJoCo's coordinates, pulled back to the rigid model's (``lean``,
    ``swing``, ``stance``, ``pelvis_roll``, ``swing_roll``; MuJoCo's ``leg1_roll =
    swing_roll - pelvis_roll``, ``leg2_roll = lean - pelvis_roll``, ``leg<i>_hip`` the
    pitches) by the transpose of that map's Jacobian, are the rigid model's ``B tau`` (its
    actuators' own law and ``B``), to 1e-12 N m (round-off of one law); no force on the
    rolls or the pelvis' slides (a pitch torque pair)."""
    scene, path, _out, walker, x0 = powered
    acts = walker.actuators
    for x in _states(x0, 4, 7):
        model, data = _at(path, scene, x)
        _loop(model).control(data)
        Q = {model.joint(j).name: float(data.qfrc_applied[model.jnt_dofadr[j]])
             for j in range(model.njnt)}
        rigid = np.array([Q["leg2_roll"], Q["leg1_hip"], Q["leg2_hip"],
                          Q["pelvis_roll"] - Q["leg1_roll"] - Q["leg2_roll"], Q["leg1_roll"]])
        want = np.real(np.asarray(acts.generalised_force(0.0, x), float))
        assert np.max(np.abs(rigid - want)) < 1e-12, (rigid, want)
        assert abs(want[1]) > 0.01  # the check is not empty (5 N m/rad x ~0.4 rad)
        assert all(Q[c] == 0.0 for c in ("pelvis_x", "pelvis_y", "pelvis_z", "leg1_roll",
                                          "leg2_roll", "pelvis_roll"))


def test_the_push_off_mujoco_applies_is_the_rigid_models_impulse(powered):
    """At the gait state and states about it, leg2 (the stance leg, trailing at leg1's heel
    strike) pushes: the velocity change MuJoCo's step takes from the loop's pulse (contact
    off; the difference of the step with and without it, so gravity and the laws cancel) is
    the rigid model's push-off in its extended system (the stance foot free: ``De (dqe_po
    - dqe-) = E_f^T P e``, ``e`` from the trailing foot to its own hip, 1 N s): the legs'
    pitch and roll rates, the pelvis' roll rate and the pelvis' velocity (the rigid hip's,
    in MuJoCo's axes) to 1e-9 (the two systems are the same 8 degrees of freedom; MuJoCo's
    inertia floor of 1e-12 kg m^2 and round-off).  A push towards the pelvis instead of the
    leg's own hip would miss the pelvis' lateral velocity by about P (w/2) / L / (20 kg),
    ~2e-3 m/s (an estimate: the lines differ by w/2 / L = 0.05 rad)."""
    from walkerlab.export.axes_3d import TO_MUJOCO

    scene, path, _out, walker, x0 = powered
    push = walker.actuators.push
    C = np.array(TO_MUJOCO)
    n = 5
    for x in _states(x0, 3, 11):
        got = []
        for pushing in (True, False):
            model, data = _at(path, scene, x, contact=False)
            loop = _loop(model)
            loop.heel_strike(data, 0)  # leg1 strikes: leg2 pushes off
            if not pushing:
                loop.push = None
            loop.control(data)
            mujoco.mj_step(model, data)
            got.append(np.array(data.qvel))
        dv = got[0] - got[1]
        # the rigid extended impulse (walkerlab.models.hybrid.push_off.PushOffTransition)
        q = x[:n]
        De, _E = (np.asarray(m, float) for m in push.fns["impact_matrices"](q))
        P, e = float(push.impulse(x)), np.asarray(push.direction(x), float)
        assert P == 1.0
        rhs = np.zeros(n + 3)
        rhs[n:] = P * e
        ddqe = np.linalg.solve(De, rhs)
        ddq, dv_foot = ddqe[:n], ddqe[n:]
        dv_hip = np.asarray(push.fns["point_velocities"](np.r_[q, ddq])["hip"], float).ravel()
        dv_hip = C @ (dv_hip + dv_foot)
        lean, sw, st, pr, swr = ddq
        want = np.r_[dv_hip, pr, swr - pr, sw, lean - pr, st]  # MuJoCo's qvel order
        assert np.max(np.abs(dv - want)) < 1e-9, (dv, want)
        assert np.max(np.abs(want)) > 0.01  # the check is not empty


def test_the_powered_3d_mjcf_walks_ten_heel_strikes_at_the_rigid_period(powered):
    """configs/hip_width_powered.yaml's MJCF, its hip spring, push-off and hip-roll law run
    by the walk loop, makes >= 10 alternating heel strikes without falling, the mean step
    period within 0.1 % of the rigid one (measured -0.004 %: the push-off over one MuJoCo
    timestep instead of an impulse before the strike, the soft contact) and every step
    within 1 %; its passive twin (configs/hip_width_stabilised.yaml) walks at 0.7032 s, so
    the actuators are in the walk (-8.4 %)."""
    from walkerlab.export.mujoco_walk import walk

    _scene, path, out, _w, _x = powered
    run = walk(path, 11.3 * out.step_period_s)
    assert len(run.times_s) >= 11 and not run.fell and run.alternating
    periods = run.step_periods_s
    assert abs(np.mean(periods) / out.step_period_s - 1.0) < 1e-3
    assert np.max(np.abs(periods / out.step_period_s - 1.0)) < 0.01
    assert abs(out.step_period_s - 0.6445) < 1e-3  # the rigid powered gait, not the passive
