"""The swing foot's clearance above the scene's ground (issue 58): the report measures it
against the ground the scene has (treads, footholds, a profile), with the quantity the fixed
point's stair check measures (:meth:`walkerlab.models.ground.Ground.clearance`), not
against the slope line through the first stance foot (which put the stairs' swing foot
190 mm "below the slope" after 20 steps of 10 mm)."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.io.trajectory import NamedTrajectory
from walkerlab.models.ground import scene_ground
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
#: the report samples the run at simulate.sample_rate_hz (500 Hz) where the fixed point's
#: check samples each phase 4001 times: near the mid-stance minimum the foot's height is
#: quadratic in time, so the sampled minimum lies above the dense one by at most
#: (half a sample's travel, ~1.2 mm)^2 over twice the foot path's radius (~0.3 m), ~2.4 um
SAMPLED_MINIMUM = 3e-6


def _run(scene, strides: int):
    """The scene's rigid gait and a run of ``strides`` strides from it."""
    from walkerlab.analysis.gait.rigid_run import simulate_scene
    from walkerlab.analysis.gait.scene import solve_scene

    walker, search = solve_scene(scene, plant=Plant.from_scene(scene))
    d = scene.model_dump(mode="json")
    d["simulate"] = {**d["simulate"], "strides": strides}
    sc = scene_from_dict(d)
    return walker, search.result, simulate_scene(sc, walker, search.result.x,
                                                 plant=Plant.from_scene(sc))


def _report_clearance(scene, run) -> tuple[float, str]:
    """What the report states (:func:`walkerlab.comparison.report_numbers.report_numbers`)."""
    from walkerlab.comparison.report_numbers import report_numbers

    sim = SimpleNamespace(samples=run.samples, total_mass_kg=20.0, gravity_m_per_s2=9.81)
    out = report_numbers(scene, {"simulate": sim})
    return out["swing_clearance"], out["clearance_ground"]


def test_stairs_report_states_the_fixed_points_stance_tread_clearance():
    from walkerlab.analysis.gait.treads import tread_landing
    from walkerlab.integrate.solver import Solver

    sc = load_scene(ROOT / "configs" / "stairs.yaml")
    walker, r, run = _run(sc, 3)
    fh = tread_landing(walker, r.x, sc.terrain, Solver.from_settings(sc.solver))
    lowest, ground = _report_clearance(sc, run)
    assert ground == "treads"
    # six steps down 10 mm each: measured from the first tread this was -50 mm and more;
    # above the tread under the foot it is the mid-stance foot-through, tens of microns
    assert fh.midstance_clearance_m < 0
    assert lowest == pytest.approx(fh.midstance_clearance_m, abs=SAMPLED_MINIMUM)


@pytest.mark.parametrize("heights", [[-0.005], [-0.005, -0.01], [0.0, -0.01, -0.004]])
def test_footholds_clearance_is_the_mid_stance_foot_through_at_every_length(heights):
    sc = load_scene(ROOT / "configs" / "footholds.yaml")
    d = sc.model_dump(mode="json")
    d["terrain"]["foothold_heights_m"] = heights
    sc = scene_from_dict(d)
    _, _, short = _run(sc, 2)  # 4 steps: every foothold of the list under a stance foot
    _, _, long = _run(sc, 5)
    phi = sc.slope.phi_rad
    lowest, ground = _report_clearance(sc, long)
    assert ground == "footholds"
    # the gait is periodic: the lowest clearance does not grow with the steps walked (above
    # the first stance foot's line it grew by the drop of every step)
    assert lowest == pytest.approx(_report_clearance(sc, short)[0], abs=1e-12)
    # and it is the foot's depth below the stance foothold's line at mid-stance, measured
    # here on its own: over the stance foothold (half-way to either neighbour), the swing
    # foot's height above the line of slope phi through the stance foot
    tr, own = long.samples, np.inf
    for k in np.unique(tr.step_index):
        m = np.flatnonzero(tr.step_index == k)
        st, sw = tr.legs[tr.stance_leg[m[0]]], tr.legs[1 - tr.stance_leg[m[0]]]
        s, f = tr.points[f"{st}_foot"][:, m[0]], tr.points[f"{sw}_foot"][:, m]
        reach = np.abs(f[0, -1] - f[0, 0]) / 4  # half-way to each neighbouring footfall
        over = np.abs(f[0] - s[0]) < reach
        h = (f[1] - s[1]) * np.cos(phi) + (f[0] - s[0]) * np.sin(phi)
        own = min(own, float(h[over].min()))
    assert -2e-3 < own < 0
    assert lowest == pytest.approx(own, abs=SAMPLED_MINIMUM)


def test_ground_pieces_measure_along_their_own_normal():
    from walkerlab.config.terrain import TerrainSettings

    # a slope: the line through the origin, as the report always measured
    g = scene_ground(None, 0.1)
    x, y = np.array([0.3, -2.0]), np.array([0.05, 0.4])
    assert g.clearance(x, y) == pytest.approx(y * np.cos(0.1) + x * np.sin(0.1), abs=1e-15)
    # stairs down 10 mm, treads 0.4 m, the stance foot 0.1 m into tread 0 at (1, 2)
    t = TerrainSettings(kind="stairs", riser_m=0.01, tread_m=0.4, first_foothold_m=0.1)
    g = scene_ground(t, 0.0, footfalls=np.array([[0.6, 2.01], [1.0, 2.0], [1.4, 1.99]]))
    assert g.name == "treads"
    assert g.clearance([0.85, 0.95, 1.25, 1.35], [2.0] * 4) == pytest.approx(
        [-0.01, 0.0, 0.0, 0.01], abs=1e-15)
    # footholds: each footfall's piece, half-way to its neighbours, at its step's slope
    f = np.array([[-0.4, 0.01], [0.0, 0.0], [0.4, 0.02]])
    g = scene_ground(SimpleNamespace(kind="footholds"), 0.0, f, [0.0, 0.2])
    assert g.clearance([-0.21, -0.19, 0.19, 0.21], [0.0] * 4) == pytest.approx(
        [-0.01, 0.0, 0.0, -0.02 * np.cos(0.2) + (0.21 - 0.4) * np.sin(0.2)], abs=1e-15)
    # a profile: the segment under the point, along that segment's normal
    P = ((0.0, 0.0), (1.0, -0.1), (2.0, -0.1))
    g = scene_ground(TerrainSettings(kind="profile", profile_m=P), 0.05)
    a = np.arctan(0.1)
    assert g.clearance([0.5, 1.5, 3.0], [0.0, 0.0, -0.05]) == pytest.approx(
        [0.05 * np.cos(a), 0.1, 0.05], abs=1e-15)


def test_a_run_stands_its_feet_in_walking_order():
    from walkerlab.analysis.gait.checks import footfalls

    t = np.linspace(0.0, 2.0, 5)
    legs = {"leg1_foot": np.array([[-1, 0, 1, 1, 1], [0.1, 0.2, 0.0, 0.0, 0.0]], float),
            "leg2_foot": np.array([[0, 0, 0, 1, 2], [0.0, 0.0, 0.0, 0.1, -0.1]], float)}
    tr = NamedTrajectory(t, ["leg1", "leg2"], {}, {}, np.array([1, 1, 1, 0, 0]),
                         np.array([0, 0, 0, 1, 1]), t * 0, t * 0, legs)
    assert footfalls(tr).tolist() == [[-1.0, 0.1], [0.0, 0.0], [1.0, 0.0], [2.0, -0.1]]
