"""Footholds of several heights for actuated walkers (issue 58): every step's walker of the
footholds' cycle carries the scene's actuators (before: "footholds of several heights or
slopes are built for passive walkers only" in every view of the torso walkers, and the rigid
model refused a powered straight-legged walker despite its table cell)."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from cli_run import ROOT

from walkerlab.config import scene_from_dict
from walkerlab.walker.kinds import KINDS
from walkerlab.walker.plant import Plant

#: the two heights [m] of the landings above the stance foot's level (up, then down)
HEIGHTS = (0.001, -0.001)


def _powered_compass_on_footholds():
    d = yaml.safe_load((ROOT / "configs" / "powered_compass.yaml").read_text())
    d["name"] = "powered_footholds"
    d["terrain"] = {"kind": "footholds", "foothold_heights_m": list(HEIGHTS),
                    "lanes": "checkerboard", "patch_width_m": 0.3}
    return scene_from_dict(d)


def test_the_torso_walkers_take_footholds_where_the_ground_is_laid_at_their_footfalls():
    for kind in ("hinged_torso", "free_joints"):
        for view in ("rigid", "contact", "mjcf", "adams", "gym"):
            assert KINDS[kind].supports("footholds", view), (kind, view)
    # OpenSim walks the three-link walker on them (tests/test_export_opensim.py); the
    # five-link biped's OpenSim walk on footholds is not checked yet
    assert KINDS["hinged_torso"].supports("footholds", "osim")
    assert "no OpenSim walk has checked them yet" in KINDS["free_joints"].cell("footholds",
                                                                             "osim")


def test_a_pushed_off_compass_walker_lands_each_step_at_its_footholds_height():
    """The powered compass gait (push-off 3 N s on level ground, Kuo 2002) on footholds 1 mm
    up and 1 mm down in turn: each step's walker has the push-off, and ten steps from the
    level gait's start land at the heights in turn.  The reference is the geometry of two
    straight legs of length L with point feet, the swing foot L (cos q_st - cos q_sw) above
    the stance foot, not the generated guard; 1e-9 m is the event location's tolerance at
    rtol 1e-12 (a passive walker on level ground, the push-off dropped, loses energy at
    every heel strike and falls before ten steps)."""
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    scene = _powered_compass_on_footholds()
    walker = build_walker(Plant.from_scene(scene))
    assert walker.cycle is not None and len(walker.cycle) == 2
    assert all(w.actuators is not None for w in walker.cycle)
    g = scene.fixedpoint.initial_guess
    x0 = np.array([g.swing_angle_rad, g.stance_angle_rad, g.swing_rate_rad_per_s,
                   g.stance_rate_rad_per_s])
    traj = simulate_steps(walker, x0, 10, Solver.from_settings(scene.solver))
    segs = list(traj.segments)
    assert [s.termination for s in segs] == ["heel_strike"] * 10
    L = scene.walker.leg_length_m
    for k, s in enumerate(segs):
        q_sw, q_st = s.x_end[0], s.x_end[1]
        assert abs(L * (np.cos(q_st) - np.cos(q_sw)) - HEIGHTS[k % 2]) < 1e-9


def test_the_exports_walk_check_knows_every_kind():
    """``export --walk`` picks heel strikes or spoke strikes by the walker's kind (its
    ``spoked``), and every kind's body tree has a URDF and an MJCF writer of its form (the
    three-link walker's entry was missing from a table keyed by kind name: a KeyError on
    its walk; the writers now ask the tree)."""
    from walkerlab.config import load_scene
    from walkerlab.export.body_writers import MJCF, URDF, TreeWriter
    from walkerlab.walker.plant import Plant
    from walkerlab.walker.walker_trees import walker_tree

    for kind in KINDS.values():
        tree, _ = walker_tree(Plant.from_scene(load_scene(kind.scene)).structure)
        form = ("wheel" if tree.in_plane else "wheel_3d") if tree.one_body else (
            "legs" if tree.in_plane else "legs_3d")
        for writer in (URDF, MJCF):
            assert getattr(type(writer), form) is not getattr(TreeWriter, form), (kind, form)
        assert tree.one_body == kind.spoked, kind.name
    assert [k.name for k in KINDS.values() if k.spoked] == ["rolling_polygon",
                                                            "rolling_polygon_3d"]


@pytest.mark.slow  # ~25 s: simulate and 500 control periods of the rigid view
def test_the_gyms_rigid_view_walks_the_three_link_footholds_as_simulate_does(tmp_path):
    """configs/threelink_footholds.yaml (the three-link walker's PD law on footholds 1 mm
    up and down in turn) in the gym's rigid view under a zero action (the scene's torques
    act as in simulate): each of simulate's 10 heel strikes at the same time to 1e-7 s
    (measured 1.7e-8 s: the gym restarts the integrator at each control period's bound,
    where the PD law's torque is evaluated again), the two steps of the period-2 gait in
    turn (0.45145 and 0.46370 s, the scene's comment)."""
    from test_gym import _env, _stage_heel_strikes, _zero_walk

    ref = _stage_heel_strikes("simulate", "threelink_footholds", tmp_path)
    assert ref.size == 10
    strikes, info = _zero_walk(_env("threelink_footholds", max_episode_steps=500))
    assert info["termination"] == "" and strikes.size == ref.size, (strikes, info)
    np.testing.assert_allclose(strikes, ref, rtol=0.0, atol=1e-7)
    T = np.diff(strikes, prepend=0.0)
    np.testing.assert_allclose(T[0::2], 0.45145, atol=1e-5)
    np.testing.assert_allclose(T[1::2], 0.46370, atol=1e-5)


@pytest.mark.slow  # ~40 s: the contact run
def test_the_contact_model_walks_the_three_link_footholds_within_2_percent(tmp_path):
    """Issue 58's "contact >= 10 heel strikes within 2 % of the rigid period-n gait" for an
    actuated walker: configs/threelink_footholds.yaml's contact run (patches at the rigid
    period-2 gait's footfalls) makes at least 10 alternating heel strikes, and each step of
    the cycle (after the first two: the start's transient) is within 2 % of the rigid
    step's 0.45145 and 0.46370 s (measured +0.12 % and +0.34 % on average at the scene's
    10 mm/s stiction velocity; +0.40 % and +0.56 % at ADAMS's 100 mm/s)."""
    from test_gym import _stage_heel_strikes

    t = _stage_heel_strikes("contact-sim", "threelink_footholds", tmp_path)
    assert t.size >= 10
    T = np.diff(t)  # step k + 1 of the run: onto footfall k + 2 (cycle step (k + 1) mod 2)
    rigid = np.array([0.45145, 0.46370])
    k = np.arange(1, T.size + 1) % 2
    assert np.all(np.abs(T[1:] / rigid[k[1:]] - 1.0) < 0.02), T
