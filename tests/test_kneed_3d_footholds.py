"""The stabilised kneed walker in 3D on footholds (``configs/kneed_3d_stabilised_footholds.yaml``:
configs/kneed_3d_stabilised.yaml's walker - locking knees, hip-roll joints and Kuo's 1999
lateral foot placement - on its slope with every foothold 2 mm below the slope line through
the stance foot, McGeer 1990; Kuo 1999).

Physics checks: the footholds change no equation (the walker's structure, and so its
generated model, is the slope walker's); the shipped footholds gait is a fixed point of the
stride map to the map's round-off, and a stable one; footholds of zero height are the slope
itself (the slope gait's stride map, state and time); the 3D MJCF refuses footholds of
several heights (its footfall patches are a stride of mirrored steps); and (slow) the
compliant-contact walk and the MuJoCo walk of its MJCF keep the rigid step period within 3 %.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.analysis.gait.poincare import poincare_map
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
FOOTHOLDS = "kneed_3d_stabilised_footholds.yaml"
SLOPE = "kneed_3d_stabilised.yaml"
#: the scene's solver (rtol = atol = 1e-10): the generated flow's round-off leaves the stride
#: map 1e-9 of noise (configs/kneed_3d_stabilised.yaml), and the shipped guess has 10 digits
MAP_TOL = 1e-8
#: the rigid gait's step period [s] (walkerlab fixedpoint on the scene, residual < 1e-10)
STEP_PERIOD_S = 0.5472503291



def _solver(scene) -> Solver:
    s = scene.solver
    return Solver(method=s.method, rtol=s.rtol, atol=s.atol)


@pytest.fixture(scope="module")
def footholds():
    scene = load_scene(ROOT / "configs" / FOOTHOLDS)
    plant = Plant.from_scene(scene)
    walker = build_walker(plant)
    x0 = scene.fixedpoint.initial_guess.as_array(walker.state_names())
    return scene, plant, walker, x0, _solver(scene)


def test_the_footholds_change_no_equation_of_the_stabilised_walker(footholds):
    """The footholds scene's walker is configs/kneed_3d_stabilised.yaml's on the same slope
    and solver (the ground is the landing's depth, not an equation), its footholds one
    height (the 3D MJCF's mirrored steps)."""
    scene, plant, _walker, _x0, solver = footholds
    slope = load_scene(ROOT / "configs" / SLOPE)
    assert plant.data.structure == Plant.from_scene(slope).data.structure
    assert scene.slope.angle_rad == slope.slope.angle_rad
    assert scene.terrain.kind == "footholds" and list(scene.terrain.foothold_heights_m) == [
        -0.002]
    assert (solver.rtol, solver.atol) == (slope.solver.rtol, slope.solver.atol)


def test_the_shipped_footholds_gait_is_a_stable_fixed_point_of_the_stride_map(footholds):
    """One stride of the rigid map (two steps, each landing 2 mm below the slope line) from
    the shipped gait returns to it within :data:`MAP_TOL` in twice the step period
    walkerlab fixedpoint printed (to 1e-8 s); the stride map's Jacobian by central
    differences (step 1e-6: its error about 1e-9 / 1e-6 = 1e-3, well inside the margin) has
    every eigenvalue inside the unit circle (fixedpoint's variational multipliers: largest
    0.6975)."""
    _scene, _plant, walker, x0, solver = footholds
    x1, t = poincare_map(walker, x0, solver)[:2]
    assert np.max(np.abs(x1 - x0)) < MAP_TOL
    assert t == pytest.approx(2 * STEP_PERIOD_S, abs=1e-8)
    assert walker.params["landing_drop_m"] == pytest.approx(0.002)
    h = 1e-6
    J = np.empty((x0.size, x0.size))
    for j in range(x0.size):
        e = np.zeros(x0.size)
        e[j] = h
        J[:, j] = (poincare_map(walker, x0 + e, solver)[0]
                   - poincare_map(walker, x0 - e, solver)[0]) / (2 * h)
    largest = np.max(np.abs(np.linalg.eigvals(J)))
    assert largest == pytest.approx(0.6975, abs=0.01)
    assert largest < 1.0


def test_footholds_of_zero_height_are_the_slope(footholds):
    """Footholds at the slope line (height 0) land where the slope does: from the slope
    gait's shipped state, one stride of the footholds map and of the slope scene's map give
    the same state and time to 1e-12 (the landing's depth 0 is the slope's heel strike)."""
    scene, _plant, _walker, _x0, solver = footholds
    slope_scene = load_scene(ROOT / "configs" / SLOPE)
    slope = build_walker(Plant.from_scene(slope_scene))
    x0 = slope_scene.fixedpoint.initial_guess.as_array(slope.state_names())
    d = scene.model_dump(mode="json")
    d["terrain"]["foothold_heights_m"] = [0.0]
    zero = build_walker(Plant.from_scene(scene_from_dict(d)))
    pa, ta = poincare_map(slope, x0, solver)[:2]
    pb, tb = poincare_map(zero, x0, solver)[:2]
    assert np.max(np.abs(pa - pb)) < 1e-12 and abs(ta - tb) < 1e-12
    assert np.max(np.abs(pa - x0)) < MAP_TOL  # ... the slope's own gait


@pytest.mark.slow  # ~1 min warm: the two-height footholds' stride gait and its MuJoCo walk
def test_the_3d_mjcf_on_footholds_of_two_heights_walks_the_rigid_step_period(tmp_path):
    """Footholds of two heights (2 mm below and level with the stance foot in turn) make
    the stride's two steps differ; the kneed walker's MJCF lays its patches at the rigid
    walk's footfalls, each at its foothold's height (walkerlab.export.legs_3d_parts.
    legs3d_lanes), and its knee latch measures each foot from the nearest patch's top:
    MuJoCo walks >= 10 alternating heel strikes without falling, its mean step period
    within 3 % of the rigid gait's (measured 14 strikes in 8 s, -0.32 %)."""
    pytest.importorskip("mujoco")
    from walkerlab.stages import export as export_stage

    d = load_scene(ROOT / "configs" / FOOTHOLDS).model_dump(mode="json")
    d["terrain"]["foothold_heights_m"] = [-0.002, 0.0]
    check = export_stage.write(scene_from_dict(d), tmp_path, "mjcf", walk=True).walk
    assert check.walked and not check.fell and check.alternating, check.line
    assert check.strikes >= 10, check.line
    assert check.period_s == pytest.approx(check.rigid_period_s, rel=0.03), check.line


@pytest.mark.slow  # ~2 min warm: the footholds gait, its contact walk and its MuJoCo walk
def test_the_contact_and_mujoco_walks_keep_the_rigid_step_period(tmp_path):
    """The compliant-contact walk (walkerlab contact-sim: 6 strides on the rigid gait's
    footfall patches, 0.2 m long, each at its foothold's height) makes 12 heel strikes; over
    steps 9-12 its mean step period and its hip's speed are within 3 % of the rigid walk's
    same steps (measured +0.62 %, -2.31 %).  The MJCF walked in MuJoCo (export --walk) makes
    >= 10 alternating heel strikes without falling, its mean step period within 3 % of the
    rigid gait's (measured 11 strikes, -0.21 %)."""
    pytest.importorskip("mujoco")
    from walkerlab.api.capabilities import _contact_against_rigid
    from walkerlab.stages import export as export_stage
    from walkerlab.stages import pipeline

    scene = load_scene(ROOT / "configs" / FOOTHOLDS)
    d = scene.model_dump(mode="json")
    d["simulate"]["strides"] = 6  # the rigid walk as long as the contact walk
    scene = scene_from_dict(d)
    cs = pipeline.run("contact-sim", scene, tmp_path).path
    fp = pipeline.run("fixedpoint", scene, tmp_path).path
    sim = pipeline.run("simulate", scene, tmp_path).path
    value, line = _contact_against_rigid(cs, fp, sim)
    assert line.startswith("12 heel strikes"), line
    assert abs(value) < 0.03, line
    check = export_stage.write(scene, tmp_path, "mjcf", walk=True).walk
    assert check.walked and not check.fell and check.alternating, check.line
    assert check.strikes >= 10, check.line
    assert check.period_s == pytest.approx(check.rigid_period_s, rel=0.03), check.line


class _Moved:
    """An Adams dataset read back with some markers moved (positions [m] by marker id)."""

    def __init__(self, model, moved: dict):
        self._model, self._moved = model, moved

    def __getattr__(self, name):
        return getattr(self._model, name)

    def marker_pose(self, m):
        pos, R = self._model.marker_pose(m)
        return (self._moved[m], R) if m in self._moved else (pos, R)


def test_the_kneed_3d_adams_latch_reads_the_foothold_under_the_foot():
    """The 3D kneed dataset on footholds (each footfall 2 mm below the last): its patches'
    tops lie at the scene's foothold heights (footfall m 2 m mm below the slope's plane,
    read from the file's patches), and each knee latch's foot height (VARIABLE 371,
    372 [mm]) is the foot's height above the tread of its lane's patch under it: 1 mm with
    the foot put 1 mm above its k-th patch (k = 1, 2: 4 and 8 mm below the slope's plane,
    where the plane's reading would release the latch, or hold it with the foot up), the
    latch's foot factor then 0.5 (half the 2 mm release height); between two patches its
    height above the slope's plane (the contact model's rule for a point over no patch)."""
    from types import SimpleNamespace

    from tests.adams_eval import evaluate
    from walkerlab.export.adams_3d import adams3d_start, adm3d_text, part_ids_3d
    from walkerlab.export.adams_reader import read_adm
    from walkerlab.export.axes_3d import slope_axes

    scene = load_scene(ROOT / "configs" / FOOTHOLDS)
    plant = Plant.from_scene(scene)
    x0 = scene.fixedpoint.initial_guess.as_array(build_walker(plant).state_names())
    start = adams3d_start(plant, SimpleNamespace(x=x0, period_s=STEP_PERIOD_S,
                                                 step_lengths_m=(0.46,)), 2)
    model = read_adm(adm3d_text(scene, plant.data, start, "walker"))
    ids = part_ids_3d(start)
    t, n = slope_axes(scene.slope.angle_rad)
    drop = -scene.terrain.foothold_heights_m[0]
    for leg, lane in zip(("leg1", "leg2"), start.lanes):
        lane = np.asarray(lane, float)  # its height above the slope's plane, up (z)
        tops = (lane[:, 2] + lane[:, 0] * np.tan(scene.slope.angle_rad)) / drop
        # to 1e-6 of a foothold (2 nm): the shipped guess's 10 digits, mirrored
        np.testing.assert_allclose(tops, (1.0 if leg == "leg1" else 0.0)
                                   - 2 * np.arange(len(tops)), atol=1e-6)
    foot = 100 * ids["leg2_shank"] + 3
    lane = np.asarray(start.lanes[1], float)
    for k in (1, 2):
        pos = lane[k] + 0.001 * n
        v = evaluate(_Moved(model, {foot: pos}), (372, 377))
        assert v[372] == pytest.approx(1.0, abs=1e-9)  # mm above its tread
        assert v[377] == pytest.approx(0.5, abs=1e-12)
        line = 0.001 + lane[k] @ n
        assert line < -0.002  # the plane's reading: 3 and 7 mm in the ground
        mid = (lane[k] + lane[k + 1]) / 2
        gap = mid + (0.001 - mid @ n) * n  # 1 mm above the plane, between two patches
        v = evaluate(_Moved(model, {foot: gap}), (372,))
        assert v[372] == pytest.approx(1.0, abs=1e-9)
    assert (lane[1] - lane[0]) @ t > 0.3  # the patches (0.2 m) leave a gap between them
