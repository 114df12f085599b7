"""The 3D straight-legged walker's MJCF (``walkerlab export --format mjcf`` of a ``model:
compass_gait`` with ``space: 3d``; :mod:`walkerlab.export.legs_3d_mjcf`) in MuJoCo:
its bodies and masses against the walker description, its ``gait`` keyframe against the
rigid gait's state (MuJoCo's own kinematics: ``mj_kinematics``, ``mj_integratePos``), its
footfall lanes, and its walk against the rigid step period."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from walkerlab.cli.options import load
from walkerlab.stages import export
from walkerlab.walker.plant import Plant

mujoco = pytest.importorskip("mujoco")

ROOT = Path(__file__).resolve().parents[1]
#: the rigid step period of configs/paper_3d.yaml [s] (configs/paper.yaml's: the planar
#: embedding, tests/test_walker_3d.py)
PAPER_STEP_S = 0.7035968805


def _scene(name: str):
    return load(str(ROOT / "configs" / f"{name}.yaml"))


@pytest.fixture(scope="module")
def paper_3d(tmp_path_factory):
    """configs/paper_3d.yaml exported with its gait: (scene, path, Exported)."""
    scene = _scene("paper_3d")
    out = export.write(scene, tmp_path_factory.mktemp("paper_3d"), "mjcf")
    return scene, out.path, out


@pytest.mark.parametrize("name, width", [("paper_3d", 0.0), ("hip_width", 0.1)])
def test_the_3d_walkers_mjcf_has_the_walkers_bodies_masses_and_hips(name, width, tmp_path):
    """The MJCF loads in MuJoCo: a free pelvis (7 + 2 coordinates, no plane constraint), the
    hip mass on it, each leg's 5 kg point mass 0.5 m below its hip (L - a), the hips
    ``w / 2`` either side (leg1 on -y), total 20 kg (exact: the file's numbers read back).
    The point masses' inertias are the export's floor, 1e-12 kg m^2 (the URDF's)."""
    path = export.write(_scene(name), tmp_path, "mjcf", walker_only=True).path
    model = mujoco.MjModel.from_xml_path(str(path))
    assert (model.nq, model.nv) == (9, 8)
    assert model.jnt_type[model.joint("free").id] == mujoco.mjtJoint.mjJNT_FREE
    mass = {model.body(i).name: float(model.body_mass[i]) for i in range(1, model.nbody)}
    assert mass == {"pelvis": 10.0, "leg1": 5.0, "leg2": 5.0}
    assert float(model.body_mass.sum()) == 20.0
    for leg, side in (("leg1", -1.0), ("leg2", 1.0)):
        b = model.body(leg)
        assert np.array_equal(b.pos, [0.0, side * width / 2, 0.0])
        assert np.array_equal(b.ipos, [0.0, 0.0, -0.5])
        assert np.all(b.inertia == 1e-12)
        assert np.array_equal(model.joint(f"{leg}_hip").axis, [0.0, -1.0, 0.0])
    assert np.all(model.body("pelvis").inertia == 1e-12)


def test_the_3d_walkers_keyframe_is_the_rigid_gait_on_its_foot_sphere(paper_3d):
    """The ``gait`` keyframe put through MuJoCo's kinematics is the rigid gait's state: the
    hinge angles are the leg angles and the pelvis unrolled (exactly: zero hip width), the
    leg masses where the rigid model has them to the foot sphere's radius r = 1 mm (the
    walker is moved so that the sphere, not the point foot, touches the slope at the
    origin: ``r (e + n)``, at most 2 r), and their velocities (MuJoCo's, by
    ``mj_integratePos`` over 1e-7 s) to 2 r |omega| (the sphere's roll, |omega| < 1.5
    rad/s); the stance sphere's contact point at the origin (1e-12) and at rest (1e-6: the
    finite difference; the keyframe turns the stance leg about it), the trailing sphere
    on the slope to r theta^2 (its centre 1 mm up the leg)."""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.codegen.cache import functions
    from walkerlab.export.spoked import TO_MUJOCO
    from walkerlab.walker.description import walker_data

    scene, path, out = paper_3d
    assert out.step_period_s == pytest.approx(PAPER_STEP_S, rel=1e-9)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("gait").id)
    mujoco.mj_kinematics(model, data)
    x = ideal_gait(scene, plant=Plant.from_scene(scene)).x
    f = functions(walker_data(scene.walker, scene.slope.phi_rad))
    C = np.array(TO_MUJOCO)
    pts = {k: C @ np.ravel(v) for k, v in f["points"](x).items()}
    vel = {k: C @ np.ravel(v) for k, v in f["point_velocities"](x).items()}
    assert data.qpos[7] == x[1] and data.qpos[8] == x[2]       # leg1 swings, leg2 stands
    assert np.max(np.abs(data.qpos[3:7] - [1, 0, 0, 0])) < 1e-15
    r, phi = 1e-3, scene.slope.phi_rad
    n = np.array([math.sin(phi), 0.0, math.cos(phi)])
    mass_at = {"leg1": "swing_mass", "leg2": "stance_mass", "pelvis": "hip"}
    for body, point in mass_at.items():
        assert np.linalg.norm(data.xipos[model.body(body).id] - pts[point]) < 2 * r
    foot = data.geom_xpos[model.geom("leg2_foot").id] - r * n      # the contact point
    assert np.max(np.abs(foot)) < 1e-12
    trailing = data.geom_xpos[model.geom("leg1_foot").id] - r * n
    assert abs(trailing @ n) < r * x[1] ** 2
    h = 1e-7
    q1 = data.qpos.copy()
    mujoco.mj_integratePos(model, q1, data.qvel, h)
    d1 = mujoco.MjData(model)
    d1.qpos[:] = q1
    mujoco.mj_kinematics(model, d1)
    for body, point in mass_at.items():
        i = model.body(body).id
        v = (d1.xipos[i] - data.xipos[i]) / h
        assert np.linalg.norm(v - vel[point]) < 2 * r * 1.5
    g = model.geom("leg2_foot").id
    v_centre = (d1.geom_xpos[g] - data.geom_xpos[g]) / h
    w_leg = C @ np.array([0.0, 0.0, x[5]])             # the stance leg's rate (no lean)
    assert np.linalg.norm(v_centre + np.cross(w_leg, -r * n)) < 1e-6  # rolls, no slip


def test_the_hip_width_walkers_lanes_lie_apart_through_each_legs_footfalls(tmp_path):
    """With 10 cm of hip width the footfall patches lie in two lanes 0.1 m apart laterally
    (leg1's at the rigid trailing foot's side, -y; leg2's through the origin), each patch
    on the slope, its footfalls a rigid stride (two steps of 0.3718 m, 0.1 m across each,
    their lateral parts cancelling) apart, each
    lane touched by its own foot only (contact bits 2 and 4)."""
    path = export.write(_scene("hip_width"), tmp_path, "mjcf").path
    model = mujoco.MjModel.from_xml_path(str(path))
    lanes = {}
    for i in range(model.ngeom):
        name = model.geom(i).name
        if "_patch" in name:
            lanes.setdefault(name.split("_")[0], []).append(i)
    assert set(lanes) == {"leg1", "leg2"} and len(lanes["leg2"]) >= 11
    y1 = model.geom_pos[lanes["leg1"], 1]
    y2 = model.geom_pos[lanes["leg2"], 1]
    assert np.ptp(y1) < 1e-12 and np.ptp(y2) < 1e-12
    assert abs(y2[0]) < 1e-12 and y1[0] == pytest.approx(-0.1, abs=1e-5)
    # a stride: two rigid steps of 0.37181516 m, each 0.1 m across (they cancel), the
    # rest along the slope (its horizontal part: cos(slope))
    stride = 2 * math.sqrt(0.37181516 ** 2 - 0.1 ** 2) * math.cos(0.0174)
    assert np.diff(model.geom_pos[lanes["leg2"], 0]) == pytest.approx(stride, rel=1e-5)
    assert set(model.geom_contype[lanes["leg1"]]) == {2}
    assert set(model.geom_contype[lanes["leg2"]]) == {4}
    assert model.geom_conaffinity[model.geom("leg1_foot").id] == 2
    assert model.geom_conaffinity[model.geom("leg2_foot").id] == 4


@pytest.mark.slow  # ~3 s: 8 s of a 44 us timestep (the gait search besides)
def test_the_paper_3d_mjcf_walks_ten_heel_strikes_at_the_rigid_period_and_stays_upright(
        paper_3d):
    """configs/paper_3d.yaml's MJCF, the free pelvis started from the rigid gait, makes >= 10
    alternating heel strikes in MuJoCo, each step period within 3 % of the rigid one (the
    capability table's MJCF tolerance: MuJoCo's contact is soft and linear; measured: each
    within 0.07 %, the heel strikes read every 5 timesteps, 0.22 ms), and its lean stays
    below 1e-6 rad: started exactly upright the walker is mirror-symmetric and so is
    MuJoCo's elliptic friction cone, so the only seeds of the unstable roll (x 11.2 a step)
    are the rigid gait's ~1e-35 rad (measured: < 1e-23 rad over 11 strikes; the pyramidal
    cone's roundoff grew to 1e-6 rad by the tenth)."""
    from walkerlab.export.legs_3d_mjcf import pelvis_lean_rad
    from walkerlab.export.mujoco_walk import walk

    scene, path, out = paper_3d
    leans = []
    run = walk(path, 11.3 * out.step_period_s, each=lambda m, d: leans.append(
        pelvis_lean_rad(m, d, scene.slope.phi_rad)))
    assert not run.fell and run.alternating and len(run.times_s) >= 10
    assert np.max(np.abs(run.step_periods_s / PAPER_STEP_S - 1.0)) < 0.03
    assert np.max(np.abs(leans)) < 1e-6


@pytest.mark.slow  # ~3 s: the hip_width gait search and its MuJoCo walk
def test_the_hip_width_mjcf_makes_three_heel_strikes_before_its_lateral_mode_falls(tmp_path):
    """configs/hip_width.yaml's rigid gait has an unstable lateral mode (x 99.9 a stride):
    its MJCF follows the rigid first step (the lean to 1.4 mrad) and then the mode takes it,
    as the rigid model predicts: 3 alternating heel strikes, then the fall (measured: the
    first step 0.7109 s against the rigid 0.7035 s)."""
    out = export.write(_scene("hip_width"), tmp_path, "mjcf", walk=True)
    w = out.walk
    assert w.fell and w.alternating and w.strikes == 3, w.line


def test_the_3d_walkers_mjcf_on_continuous_ground_is_refused_in_one_line(tmp_path):
    """The swing foot passes through the ground at mid-stance (the rigid model's): the MJCF
    lays footfall patches, so ``terrain.lanes: continuous`` is refused, one line naming it,
    nothing written."""
    scene = _scene("paper_3d")
    scene = scene.model_copy(update={"terrain": scene.terrain_or_default().model_copy(
        update={"lanes": "continuous"})})
    with pytest.raises(ValueError) as err:
        export.write(scene, tmp_path, "mjcf")
    assert "terrain.lanes" in str(err.value) and "\n" not in str(err.value)
    assert not list(tmp_path.rglob("walker.*"))


# ---- the stabilised walker: hip-roll joints and their foot-placement law -----------------

@pytest.fixture(scope="module")
def stabilised(tmp_path_factory):
    """configs/hip_width_stabilised.yaml exported with its gait and walked in MuJoCo:
    (scene, path, Exported)."""
    scene = _scene("hip_width_stabilised")
    out = export.write(scene, tmp_path_factory.mktemp("stabilised"), "mjcf", walk=True)
    return scene, out.path, out


@pytest.mark.slow  # ~15 s: the rigid gait's search (shared with the walk below)
def test_the_stabilised_walkers_keyframe_has_the_rigid_gaits_rolls(stabilised):
    """The hip-roll walker's MJCF: the pelvis on three slides and a roll hinge (no pitch, no
    yaw, as the rigid model's), each leg on a roll hinge then its pitch hinge (8
    coordinates), the pelvis' roll inertia the scene's; at the ``gait`` keyframe the rolls
    of the pelvis and the legs and their rates as the walk loop reads them from MuJoCo's
    bodies (:class:`~walkerlab.export.mujoco_walk.HipRollLoop`: pitch axes and angular
    velocities) are the rigid gait's state's, to 1e-12 (roundoff of the rotations)."""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.export.mujoco_walk import HipRollLoop

    scene, path, _out = stabilised
    model = mujoco.MjModel.from_xml_path(str(path))
    assert (model.nq, model.nv) == (8, 8)
    assert [model.joint(i).name for i in range(model.njnt)] == [
        "pelvis_x", "pelvis_y", "pelvis_z", "pelvis_roll", "leg1_roll", "leg1_hip",
        "leg2_roll", "leg2_hip"]
    assert model.body("pelvis").inertia[0] == scene.walker.hip_roll.pelvis_roll_inertia_kg_m2
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("gait").id)
    mujoco.mj_forward(model, data)
    phi, dphi = HipRollLoop(model).rolls(data)
    # lean (leg2's), swing, stance, pelvis, swing (leg1's) roll
    x = ideal_gait(scene, plant=Plant.from_scene(scene)).x
    assert np.max(np.abs(phi - x[[3, 4, 0]])) < 1e-12
    assert np.max(np.abs(dphi - x[[8, 9, 5]])) < 1e-12


@pytest.mark.slow  # ~20 s: the gait search and 7.9 s of MuJoCo stepped one timestep at a time
def test_the_stabilised_mjcf_walks_ten_heel_strikes_at_the_rigid_period(stabilised):
    """configs/hip_width_stabilised.yaml's MJCF, its law run by the walk loop, makes >= 10
    alternating heel strikes without falling (its passive twin, configs/hip_width.yaml,
    falls after 3), the mean step period within 3 % of the rigid one (the capability
    table's MJCF tolerance; measured +0.001 %) and every step within 3 %."""
    from walkerlab.export.mujoco_walk import walk

    _scene_, path, out = stabilised
    w = out.walk
    assert not w.fell and w.alternating and w.strikes >= 10, w.line
    run = walk(path, 11.3 * out.step_period_s)
    assert len(run.times_s) >= 10
    assert np.max(np.abs(run.step_periods_s / out.step_period_s - 1.0)) < 0.03


@pytest.mark.slow  # ~30 s: the gait search and four walks of 8.6 s in MuJoCo
@pytest.mark.parametrize("push_at_steps", [0.0, 2.5])
@pytest.mark.parametrize("factor", [1.05, 0.95])
def test_the_stabilised_mjcf_walks_ten_steps_after_a_5_percent_lateral_push(
        stabilised, push_at_steps, factor):
    """The pelvis' lateral velocity scaled by ``factor`` (+-5 %) at the keyframe or at the
    third step's mid-stance: the pushed gait settles up to 9.3 cm sideways of its nominal
    footfalls (off the 8 cm patches the file had, where it fell at its first or second
    heel strike), so its patches are 0.30 m across (said in the file's comment) and it
    makes >= 10 alternating heel strikes without falling."""
    from walkerlab.export.mujoco_walk import walk

    _scene_, path, out = stabilised
    text = Path(path).read_text()
    assert "0.3 m across: the stabilised gait pushed by +-5 %" in text
    model = mujoco.MjModel.from_xml_path(str(path))
    lateral = model.jnt_dofadr[model.joint("pelvis_y").id]
    pushed = []

    def push(_model, data):
        if not pushed and data.time >= push_at_steps * out.step_period_s:
            data.qvel[lateral] *= factor
            pushed.append(data.time)

    run = walk(path, 12.3 * out.step_period_s, each=push)
    assert pushed and not run.fell and run.alternating and len(run.times_s) >= 10, (
        len(run.times_s), run.fell)


#: the window [s] a MuJoCo contact force is averaged over (about 110 timesteps)
WINDOW_S = 0.005


@pytest.mark.slow  # ~20 s: the gait search, the floating view, 0.7 s of MuJoCo
def test_the_3d_stance_foots_force_and_twist_are_mujocos_contact_force_and_torsion(tmp_path):
    """configs/hip_width.yaml's first step in MuJoCo (its MJCF from the gait keyframe; feet
    ``condim 4``: the torsional friction holds the foot from turning, as the rigid model's
    stance joint does): the stance foot's contact force and its torque about the slope's
    normal (``mj_contactForce``) against the rigid model's ground reaction and twist
    (:class:`~walkerlab.models.hybrid.ground_reaction.StanceReaction`, from the walker's
    floating view) at the same times of the step - an engine's soft contact against the
    rigid model (measured: force within 0.09 N of a 196 N weight, twist within 0.009 N m of
    a 1.0 N m peak; the twist changes sign at mid-stance in both)."""
    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.hybrid.ground_reaction import StanceReaction
    from walkerlab.models.registry import build_walker

    scene = _scene("hip_width")
    out = export.write(scene, tmp_path, "mjcf")
    model = mujoco.MjModel.from_xml_path(str(out.path))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("gait").id)
    phi = scene.slope.phi_rad
    up = np.array([math.sin(phi), 0.0, math.cos(phi)])   # the slope's normal, MuJoCo axes
    foot, f6 = model.geom("leg2_foot").id, np.zeros(6)
    times = 0.7034879 * np.array([0.1, 0.3, 0.5, 0.7, 0.9])
    rows = []   # per timestep: time, the force on the foot (our axes), its torque about n
    while data.time < times[-1] + WINDOW_S:
        mujoco.mj_step(model, data)
        F, torque = np.zeros(3), 0.0
        for i in range(data.ncon):
            c = data.contact[i]
            if foot in (c.geom1, c.geom2):
                mujoco.mj_contactForce(model, data, i, f6)
                frame = c.frame.reshape(3, 3)
                sign = 1.0 if c.geom2 == foot else -1.0   # the force on the foot
                F += sign * frame.T @ f6[:3]
                torque += sign * f6[3] * float(frame[0] @ up)
        rows.append((data.time, F[0], F[2], -F[1], torque))   # ours: y up, z = -MuJoCo's y
    rows = np.array(rows)
    # the soft contact chatters at ~1e-9 m of penetration (a one-step spike of +50 %): the
    # mean over a window of WINDOW_S about each time, where the rigid force is a line
    seen = {k: rows[np.abs(rows[:, 0] - t) < WINDOW_S / 2, 1:].mean(axis=0)
            for k, t in enumerate(times)}
    plant = Plant.from_scene(scene)
    walker = build_walker(plant)
    reaction = StanceReaction(walker, plant.data)
    x0 = ideal_gait(scene, plant=plant).x
    seg = simulate_steps(walker, x0, 1, Solver(method="DOP853", rtol=1e-12, atol=1e-12)
                         ).segments[0]
    weight = float(plant.data.total_mass_kg) * float(plant.data.gravity_m_per_s2)
    twists = []
    for k, t in enumerate(times):
        phase, sol, _ = next(p for p in seg.pieces if p[2][0] <= t <= p[2][1])
        F, twist = reaction.force_and_twist(t, np.ravel(sol(t))[:x0.size], phase.flow)
        F_mj, twist_mj = seen[k][:3], seen[k][3]
        assert np.max(np.abs(F - F_mj)) < 0.002 * weight, (t, F, F_mj)
        assert abs(twist - twist_mj) < 0.02, (t, twist, twist_mj)
        twists.append(twist)
    assert twists[0] > 0.5 and twists[-1] < -0.5   # it turns the other way late in stance
