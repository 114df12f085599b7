"""The 3D straight-legged walker (``walker.space: 3d``, Kuo 1999) on stairs and footholds:
the ground a height along the walking direction, level across it, so the landing is the
generated swing clearance (the swing foot's height above the stance foot's plane) reaching
the landing's depth, whatever the hip width or the lean
(:mod:`walkerlab.models.hybrid.ground`).

Physics checks: a zero riser (the clearance guard and the landing section at depth 0) gives
the plane's map and gait; the stairs gait's footfalls land on the treads, each at the height
of the tread under it (from its horizontal place alone); the stairs gait matches a model
written without the generated equations (``tests/test_hip_roll_3d.py``'s Newton model with
the heel strike at the tread below and the trailing foot on the tread above).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from tests.independent.mirror_stride import stride_against, to_heel_strike
from tests.test_hip_roll_3d import STANCE, SWING, Reference, reference_of
from walkerlab.analysis.gait.poincare import find_fixed_point, poincare_map
from walkerlab.config import load_scene
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.hybrid.ground import with_clearance_guard
from walkerlab.models.registry import build_walker
from walkerlab.walker.capability_cells import CAPABILITIES
from walkerlab.walker.kinds import KINDS
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
#: the heel strike is located on the guard to the integrator's tolerance (1e-12): a
#: footfall's height to 1e-10 m
HEIGHT_TOL = 1e-10


def _guess(scene, walker) -> np.ndarray:
    g = scene.fixedpoint.initial_guess.model_extra
    return np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                     for n in walker.state_names()])


def _built(name: str):
    scene = load_scene(ROOT / "configs" / name)
    plant = Plant.from_scene(scene)
    walker = build_walker(plant)
    return scene, plant, walker, _guess(scene, walker)


@pytest.fixture(scope="module")
def stairs():
    return _built("hip_width_stairs.yaml")


@pytest.fixture(scope="module")
def plane():
    """The stabilised walker on its plane slope and the same walker whose heel strike is
    the landing's clearance guard at depth 0 (a zero riser: the landing section solved by
    Newton's method on the generated clearance)."""
    scene, plant, walker, x0 = _built("hip_width_stabilised.yaml")
    return scene, walker, with_clearance_guard(walker, plant.data), x0


def test_3d_legged_kinds_take_stairs_and_footholds_in_the_rigid_view():
    """The table's cells: the rigid view of both legged kinds in 3D walks them; a profile is
    refused in one line naming the field and the physics (the fall line turns)."""
    for name in ("straight_legs_3d", "locking_knees_3d"):
        kind = KINDS[name]
        for ground in ("stairs", "footholds"):
            assert kind.supports(ground, "rigid")
        with pytest.raises(ValueError, match=r"^terrain\.kind: profile: ") as err:
            kind.require("profile", "rigid", "terrain.kind: profile")
        assert "\n" not in str(err.value) and "fall line" in str(err.value)
    # the 3D spoked wheel lands on them in the rigid view too (tests/test_wheel_3d.py); its
    # profile is refused for the same reason (its heading and lean turn about the plane's
    # normal and fall line)
    assert CAPABILITIES["rolling_polygon_3d"][("stairs", "rigid")] is None
    assert "fall line" in CAPABILITIES["rolling_polygon_3d"][("profile", "*")]


def test_a_zero_riser_gives_the_planes_map(plane):
    """The landing at depth 0 (the clearance guard, the section solved on the post-impact
    surface by Newton) is the plane's own heel strike and section: from the same section
    coordinates the same state, and one stride of each map from it the same state and
    period, to 1e-11 (both located to the integrator's 1e-12)."""
    _scene, walker, zero, x0 = plane
    z = walker.section(x0)
    xa, xb = walker.from_section(z), zero.from_section(z)
    assert np.max(np.abs(xa - xb)) < 1e-12
    pa, ta = poincare_map(walker, xa, SOLVER)[:2]
    pb, tb = poincare_map(zero, xb, SOLVER)[:2]
    assert np.max(np.abs(pa - pb)) < 1e-11
    assert abs(ta - tb) < 1e-11


@pytest.mark.slow  # ~2 min: two fixed points of the 3D walker
def test_a_zero_riser_gives_the_planes_gait(plane):
    """The gait of the zero-riser landing is the plane's: fixed point and stride period to
    1e-9 (both searched to the scene's 1e-12)."""
    _scene, walker, zero, x0 = plane
    a = find_fixed_point(walker, x0, SOLVER, fd_check=False)
    b = find_fixed_point(zero, x0, SOLVER, fd_check=False)
    assert np.max(np.abs(np.asarray(a.x) - np.asarray(b.x))) < 1e-9
    assert abs(a.period_s - b.period_s) < 1e-9


def test_stairs_footfalls_land_on_the_treads(stairs):
    """Six steps from the shipped gait: heel strike ``k`` puts the new stance foot on tread
    ``k`` (the tread under its horizontal place ``x``, ``floor((x + D/2) / D)``, the first
    foot mid-tread) at that tread's height ``-k H``, to 1e-10 m; the feet alternate sides
    by the step's lateral offset (the hip width and the lean) and return to the same side
    every stride."""
    scene, _plant, walker, x0 = stairs
    H, D = scene.terrain.riser_m, scene.terrain.tread_m
    traj = simulate_steps(walker, x0, 6, SOLVER)
    feet = np.array([s.stance_foot_world for s in traj.segments])
    assert [s.termination for s in traj.segments] == ["heel_strike"] * 6
    for k, (x, y, _z) in enumerate(feet):
        tread = math.floor((x + D / 2) / D)
        assert tread == k
        assert abs(y - (-tread * H)) < HEIGHT_TOL
    lateral = np.diff(feet[:, 2])
    assert np.all(np.abs(lateral) > 0.1)  # 0.146 m measured
    assert np.all(lateral[:-1] * lateral[1:] < 0)
    assert abs(feet[2, 2] - feet[0, 2]) < 1e-5 and abs(feet[3, 2] - feet[1, 2]) < 1e-5


def test_footholds_footfalls_land_at_their_heights():
    """configs/hip_width_footholds.yaml (footholds 2 mm above and below the slope line in
    turn): four steps from the stabilised slope gait's start, heel strike ``k`` lands
    ``h[k mod 2]`` above the slope line through the last stance foot, along the vertical
    (``y_{k+1} = y_k - (x_{k+1} - x_k) tan(gamma) + h_k``), to 1e-10 m."""
    scene, _plant, walker, x0 = _built("hip_width_footholds.yaml")
    h = scene.terrain.foothold_heights_m
    slope = math.tan(scene.slope.angle_rad)
    traj = simulate_steps(walker, x0, 5, SOLVER)
    assert [s.termination for s in traj.segments] == ["heel_strike"] * 5
    feet = np.array([s.stance_foot_world for s in traj.segments])
    for k in range(len(feet) - 1):
        (xa, ya, _), (xb, yb, _) = feet[k], feet[k + 1]
        assert abs(yb - (ya - (xb - xa) * slope + h[k % 2])) < HEIGHT_TOL


def test_footholds_map_section_is_the_state_a_cycle_ends_in():
    """The footholds' period-2 map (one walker per step, the second the other side's): the
    state just after the cycle's last heel strike is on the map's section surface - its
    section coordinates give it back, to 1e-12 (the trailing foot on the last foothold,
    seen from step 0's walker: its swing clearance at the first walker's hip offset)."""
    scene, _plant, walker, x0 = _built("hip_width_footholds.yaml")
    traj = simulate_steps(walker, x0, 2, SOLVER)
    x = np.asarray(traj.segments[-1].x_next, float)
    assert np.max(np.abs(walker.from_section(walker.section(x)) - x)) < 1e-12


#: MuJoCo's axes (and the Adams dataset's) from walkerlab's: x, y up, z across -> x, -z, y
TO_MJ = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
#: rigid steps whose footfalls are checked against the exported patches (footfalls 0 to 11)
FOOTHOLD_STEPS = 12
#: an exported patch at its rigid footfall [m]: the layout walks one period of the fixed
#: point (1e-12) and repeats it, the check walks 12 steps (a stable gait: the walk stays on
#: it); the files write 16 significant digits
PATCH_TOL = 1e-9


@pytest.fixture(scope="module")
def footholds_walk():
    """configs/hip_width_footholds.yaml's rigid gait (searched as the export searches it),
    and its rigid walk of :data:`FOOTHOLD_STEPS` steps from it: the keyframe's trailing
    foot (the rigid ``points`` at the fixed point) and each heel strike's new stance foot
    (``simulate_steps``' world feet), in walkerlab's axes [m] - footfall ``k`` (0 the
    keyframe's stance foot, leg2's) at row ``k + 1``, the trailing foot (leg1's) at row 0."""
    from walkerlab.analysis.contact.periodic import ideal_gait

    scene, plant, walker, _x0 = _built("hip_width_footholds.yaml")
    x = np.asarray(ideal_gait(scene, plant).x, float)
    traj = simulate_steps(walker, x, FOOTHOLD_STEPS, SOLVER)
    assert [sg.termination for sg in traj.segments] == ["heel_strike"] * FOOTHOLD_STEPS
    trailing = np.ravel(walker.points(x)["swing_foot"])
    feet = np.array([trailing] + [sg.stance_foot_world for sg in traj.segments], float)
    return scene, feet


def _lanes_match_the_rigid_walk(scene, feet, lanes) -> None:
    """Each leg's patches (footfalls in MuJoCo's axes [m], leg1's from the trailing foot,
    leg2's from the keyframe's stance foot) at the rigid walk's footfalls ``feet``
    (:func:`footholds_walk`) to :data:`PATCH_TOL`, each a foothold's height
    ``h[k mod 2]`` above the slope line through the last one along the vertical; the
    walker crabs (its lateral offset changes stride by stride: the steps do not mirror
    each other)."""
    leg1, leg2 = (np.asarray(lane, float) @ TO_MJ for lane in lanes)  # walkerlab's axes
    n = FOOTHOLD_STEPS // 2
    np.testing.assert_allclose(leg1[:n + 1], feet[0::2][:n + 1], rtol=0, atol=PATCH_TOL)
    np.testing.assert_allclose(leg2[:n], feet[1::2][:n], rtol=0, atol=PATCH_TOL)
    falls = np.empty((2 * n + 1, 3))
    falls[0::2], falls[1::2] = leg1[:n + 1], leg2[:n]  # footfall -1, 0, 1, ... in turn
    h, slope = scene.terrain.foothold_heights_m, math.tan(scene.slope.angle_rad)
    for k in range(1, len(falls) - 1):  # footfall k - 1's landing: step k - 1 of the cycle
        (xa, ya, _), (xb, yb, _) = falls[k], falls[k + 1]
        assert abs(yb - (ya - (xb - xa) * slope + h[(k - 1) % 2])) < PATCH_TOL
    assert abs((falls[4, 2] - falls[2, 2]) - (falls[2, 2] - falls[0, 2])) < 1e-6
    assert abs(falls[2, 2] - falls[0, 2]) > 0.01  # 0.041 m a stride measured


def test_footholds_mjcf_patches_lie_at_the_rigid_walks_footfalls(footholds_walk, tmp_path):
    """configs/hip_width_footholds.yaml's MJCF (footholds 0.5 mm above and below the slope
    line in turn): each patch box's top centre (its centre plus its half-depth along the
    slope's normal) at the rigid walk's footfall, at its foothold's height
    (:func:`_lanes_match_the_rigid_walk`)."""
    import xml.etree.ElementTree as ET

    from walkerlab.stages import export

    scene, feet = footholds_walk
    out = export.write(scene, tmp_path, "mjcf")
    phi = scene.slope.angle_rad
    normal = np.array([math.sin(phi), 0.0, math.cos(phi)])  # the box's z, turned about y
    geoms = {g.get("name"): g for g in ET.parse(out.path).getroot().iter("geom")
             if g.get("name")}
    lanes = []
    for leg in ("leg1", "leg2"):
        boxes = sorted(((int(k.rsplit("patch", 1)[1]), g) for k, g in geoms.items()
                        if k.startswith(f"{leg}_patch")), key=lambda kg: kg[0])
        lanes.append([np.array(g.get("pos").split(), float)
                      + float(g.get("size").split()[2]) * normal for _k, g in boxes])
    _lanes_match_the_rigid_walk(scene, feet, lanes)


def test_footholds_adams_patches_lie_at_the_rigid_walks_footfalls(footholds_walk, tmp_path):
    """The Adams dataset of configs/hip_width_footholds.yaml read back: each foot's
    CONTACT patches (GRAPHICS boxes from their corner markers, their tops ``r = L / 1000``
    below the footfall along the box's normal: the foot sphere's centre at the rigid point
    foot) at the rigid walk's footfalls, at their footholds' heights
    (:func:`_lanes_match_the_rigid_walk`); leg1's foot touches leg1's lane only."""
    from walkerlab.export.adams_reader import read_adm
    from walkerlab.stages import export

    scene, feet = footholds_walk
    out = export.write(scene, tmp_path, "adm")
    model = read_adm(out.path.read_text())
    r = scene.walker.leg_length_m / 1000
    lanes = []
    for foot in (303, 403):   # leg1's and leg2's foot-sphere markers
        lane = []
        for c in model.by_kind["CONTACT"].values():
            if c.integer("IGEOM") != foot:
                continue
            g = model.get("GRAPHICS", c.integer("JGEOM"))
            o, R = model.marker_pose(g.integer("CORNER"))
            size = np.array([g.number(k) for k in "XYZ"]) * model.length
            lane.append(o + R @ (size * [0.5, 0.5, 1.0]) + r * R[:, 2])
        lanes.append(sorted(lane, key=lambda p: p[0]))
    _lanes_match_the_rigid_walk(scene, feet, lanes)


def test_footholds_osim_patches_lie_at_the_rigid_walks_footfalls(footholds_walk):
    """The OpenSim model's text (written by its writer; its walk on these footholds is the
    capability table's measured cell straight_legs_3d/footholds/osim) lays the MJCF's patches:
    each ``ContactSphere`` ``leg<i>_patch<k>``'s top (its centre plus its radius along the
    slope's normal, OpenSim's axes walkerlab's) at the rigid walk's footfall, at its
    foothold's height (:func:`_lanes_match_the_rigid_walk`)."""
    import xml.etree.ElementTree as ET

    from walkerlab.analysis.contact.periodic import ideal_gait
    from walkerlab.export.opensim_3d import osim3d_gait, osim3d_text

    scene, feet = footholds_walk
    plant = Plant.from_scene(scene)
    text = osim3d_text(plant.data, osim3d_gait(plant, ideal_gait(scene, plant)),
                       scene.name)
    phi = scene.slope.angle_rad
    normal = np.array([math.sin(phi), math.cos(phi), 0.0])  # walkerlab's axes: y up
    spheres = {c.get("name"): c for c in  # OpenSim's "::" names are no XML names
               ET.fromstring(text.replace("::", "__")).iter("ContactSphere")}
    lanes = []
    for leg in ("leg1", "leg2"):
        k = 0
        lane = []
        while f"{leg}_patch{k}" in spheres:
            c = spheres[f"{leg}_patch{k}"]
            top = np.array(c.find("location").text.split(), float) \
                + float(c.find("radius").text) * normal
            lane.append(TO_MJ @ top)  # the lanes' check reads MuJoCo's axes
            k += 1
        lanes.append(lane)
    _lanes_match_the_rigid_walk(scene, feet, lanes)


def test_kneed_3d_stairs_footfalls_land_on_the_treads():
    """configs/kneed_3d_stairs.yaml (locking knees in 3D, its two phases): four steps from
    the shipped gait, heel strike ``k`` on tread ``k`` at its height ``-k H`` to 1e-10 m
    (the lateral mode is unstable, ~40 a stride: four steps stay on the gait)."""
    scene, _plant, walker, x0 = _built("kneed_3d_stairs.yaml")
    H, D = scene.terrain.riser_m, scene.terrain.tread_m
    traj = simulate_steps(walker, x0, 4, SOLVER)
    assert [s.termination for s in traj.segments] == ["heel_strike"] * 4
    for k, s in enumerate(traj.segments):
        x, y, _z = s.stance_foot_world
        assert math.floor((x + D / 2) / D) == k
        assert abs(y + k * H) < HEIGHT_TOL


@pytest.mark.parametrize("terrain, field", [
    ({"kind": "profile", "profile_m": [[-1.0, 0.02], [0.0, 0.0], [1.0, -0.03]]},
     "terrain.kind: profile"),
    ({"kind": "footholds", "foothold_heights_m": [0.0, 0.0],
      "foothold_slopes_rad": [0.0174, 0.02]}, "terrain.foothold_slopes_rad"),
])
def test_a_ground_whose_slope_changes_is_refused_for_a_3d_walker_in_one_line(terrain, field):
    """A profile and footholds of their own slopes turn the fall line the walker's rolls are
    about from step to step: one line naming the field and the physics."""
    from walkerlab.analysis.gait.rigid_run import profile_ground
    from walkerlab.config import scene_from_dict

    d = load_scene(ROOT / "configs" / "hip_width_stabilised.yaml").model_dump(mode="json")
    d["terrain"] = terrain
    scene = scene_from_dict(d)
    plant = Plant.from_scene(scene)
    with pytest.raises(ValueError) as err:
        if terrain["kind"] == "profile":
            profile_ground(scene, plant)
        else:
            build_walker(plant)
    line = str(err.value)
    assert line.startswith(field) and "fall line" in line and "\n" not in line


class _OnStairs(Reference):
    """:class:`tests.test_hip_roll_3d.Reference` on level treads ``drop`` [m] apart: the heel
    strike when the swing foot reaches the tread below (its height above the stance foot's
    ``-drop``), and just after it the trailing foot on the tread above (``+drop``)."""

    def __init__(self, drop: float, *args):
        super().__init__(*args)
        self.drop = drop

    def step(self, w, x):
        y, t2 = to_heel_strike(self.rhs(w), x, SWING, STANCE,
                               lambda y: self.foot_height(w, y) + self.drop, 5.0)
        return self.impact(w, y), t2

    def on_surface(self, w, z):
        def h(th_sw):
            return self.foot_height(w, np.array([z[0], th_sw, *z[1:4], *np.zeros(5)])) \
                - self.drop
        g = 2 * self.gamma
        th_sw = brentq(h, -z[1] - g - 0.3, -z[1] - g + 0.05)
        return np.array([z[0], th_sw, *z[1:]])


@pytest.mark.slow  # ~2 min: the generated gait, the reference's and its central differences
def test_stairs_gait_matches_an_independent_model(stairs):
    """The stairs gait's fixed point and stride period to 1e-8 and its multipliers to 1e-6
    against the Newton model's on the same treads (hybr on its stride, central differences
    h = 1e-6), and it is stable (largest multiplier 0.519 measured)."""
    scene, _plant, walker, x0 = stairs
    res = find_fixed_point(walker, x0, SOLVER, fd_check=False)
    ref = reference_of(scene)
    ref = _OnStairs(scene.terrain.riser_m, ref.g, ref.L, ref.gamma, ref.M, ref.m, ref.a,
                    ref.I_pelvis, ref.law)
    dx, dt, dmu = stride_against(ref, scene.walker.hip_width_m, res,
                                 [0, 2, 3, 4, 5, 6, 7, 8, 9])
    assert dx < 1e-8
    assert dt < 1e-8
    assert dmu < 1e-6
    assert np.max(np.abs(res.multipliers_variational)) < 0.95


@pytest.mark.slow  # minutes: the rigid gait and five strides of the floating walker
def test_stairs_contact_walk_is_within_3_percent_of_the_rigid_step_period(tmp_path):
    """``walkerlab contact-sim`` down the stairs (patches at the rigid footfalls, each at
    its tread's height): every heel strike of five strides, and the last four steps' mean
    period within 3 % of the rigid gait's (the capability table's contact tolerance)."""
    import h5py

    from walkerlab.stages import pipeline

    scene = load_scene(ROOT / "configs" / "hip_width_stairs.yaml")
    out = pipeline.run("contact-sim", scene, tmp_path, strides=5)
    with h5py.File(out.path) as f:
        periods = np.asarray(f["steps/period"][()], float)
        strikes = int(f["summary/heel_strikes"][()])
    with h5py.File(tmp_path / scene.name / "fixedpoint.h5") as f:
        rigid = float(f["step_period"][()])
    periods = periods[np.isfinite(periods)]
    assert not out.failure
    assert strikes >= 10
    assert abs(periods[-4:].mean() / rigid - 1.0) < 0.03


@pytest.mark.slow  # ~1 min: the rigid gait and 8 s of MuJoCo stepped one timestep at a time
def test_stairs_mjcf_walks_in_mujoco_within_3_percent_of_the_rigid_step_period(tmp_path):
    """The exported MJCF (patches at the rigid footfalls, their tops at the treads'
    heights) walked by MuJoCo with the hip-roll law in the walk loop: >= 10 alternating
    heel strikes without falling, every step period within 3 % of the rigid one."""
    pytest.importorskip("mujoco")
    from walkerlab.export.mujoco_walk import walk
    from walkerlab.stages import export

    scene = load_scene(ROOT / "configs" / "hip_width_stairs.yaml")
    out = export.write(scene, tmp_path, "mjcf", walk=True)
    w = out.walk
    assert not w.fell and w.alternating and w.strikes >= 10, w.line
    run = walk(out.path, 11.3 * out.step_period_s)
    assert len(run.times_s) >= 10
    assert np.max(np.abs(run.step_periods_s / out.step_period_s - 1.0)) < 0.03


@pytest.mark.slow  # ~40 s: the rigid gait and 8 s of MuJoCo stepped one timestep at a time
def test_footholds_mjcf_walks_in_mujoco_within_3_percent_of_the_rigid_step_period(tmp_path):
    """configs/hip_width_footholds.yaml's MJCF (patches at the rigid walk's footfalls, each
    at its foothold's height: the period-2 gait's steps of 0.6958 and 0.7100 s, the walker
    crabbing 4.1 cm a stride) walked by MuJoCo with the hip-roll law in the walk loop:
    >= 10 alternating heel strikes without falling, the mean step period within 3 % of the
    rigid gait's (measured 11 strikes, 0.702884 s against 0.702897 s: -0.002 %)."""
    pytest.importorskip("mujoco")
    from walkerlab.stages import export

    scene = load_scene(ROOT / "configs" / "hip_width_footholds.yaml")
    w = export.write(scene, tmp_path, "mjcf", walk=True).walk
    assert not w.fell and w.alternating and w.strikes >= 10, w.line
    assert abs(w.period_s / w.rigid_period_s - 1.0) < 0.03, w.line


def test_a_3d_steps_dense_output_is_its_state_on_the_compiled_phases(stairs):
    """A 3D walker's phases run compiled under the default backend (``CompiledFlow.
    by_default``); their dense output must be the state's 2n rows, as the Python backends'
    (the cfunc's guard outputs, after the state, stay inside): the stairs' tread landing
    samples the swing foot from it (``walker.points(sol(t))``, which failed on the extra
    rows), and it must agree with the step's end state."""
    from walkerlab.integrate.rigid import integrate_step

    _scene, _plant, walker, x0 = stairs
    assert all(getattr(ph.compiled, "by_default", False) for ph in walker.phases)
    seg = integrate_step(walker, x0, SOLVER)
    assert seg.termination == "heel_strike"
    n = x0.size
    for _phase, sol, (ta, tb) in seg.pieces:
        t = np.linspace(ta, tb, 7)
        assert np.asarray(sol(t)).shape == (n, 7)
        assert np.asarray(sol(tb)).shape == (n,)
        walker.points(sol(t))  # the landing's read: the generated points of (2n, k) states
    _phase, sol, (_ta, tb) = seg.pieces[-1]
    assert np.allclose(sol(tb), seg.x_end, rtol=0, atol=1e-9)  # the event state, pre-reset
