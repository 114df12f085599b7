"""Footholds of several heights in the contact model and the MJCF export (issue 58): the
patches lie at the rigid period-n gait's footfalls, step by step, each at its foothold's
height, and both views walk the rigid gait.

Physics checks:

* the contact model's patch centres and heights are the rigid gait's footfalls, read from
  the rigid model's own swing-foot points (:func:`walkerlab.integrate.rigid.simulate_steps`,
  the hybrid model's kinematics, sharing no code with the contact view's floating
  kinematics that lay the patches), to 1e-9 m;
* the contact walker on footholds of two heights (``configs/footholds_two.yaml``,
  [-0.004, -0.006]) and of three ([-0.005, -0.005, -0.003]) makes >= 10 heel strikes, and
  the mean period of each step of the cycle is within 2 % of the rigid period-n gait's
  (issue 58's bound);
* MuJoCo walks the MJCF export of both grounds (>= 10 alternating heel strikes, no fall),
  each step of the cycle within 1 % of the rigid gait's (measured <= 0.18 %);
* a contact run whose footfalls drift off the patches at the rigid footfalls (its steps
  ~9 mm shorter) walks the 15 strides asked for on patches at its own footfalls, each
  keeping its height.

The issue's first heights, [-0.005, -0.01] and [0, -0.01, -0.004], give unstable rigid gaits
(|lambda|max 1.44 and 18.6): these stable ones (0.53, 0.48) are the ones tested.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config import scene_from_dict
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[2]
TWO = yaml.safe_load((ROOT / "configs" / "footholds_two.yaml").read_text())


#: the ADAMS View friction defaults (stiction and friction transition velocities, mm/s):
#: the stance foot creeps and the contact steps fall ~9 mm short of the rigid ones
#: (configs/footholds_two.yaml itself uses 10 and 100 mm/s)
ADAMS_FRICTION = {"stiction_velocity_mm_per_s": 100.0, "friction_velocity_mm_per_s": 1000.0}


def _scene(heights=None, contact=None, **contact_sim):
    d = {**copy.deepcopy(TWO), "name": "footholds"}
    if heights is not None:
        d["terrain"]["foothold_heights_m"] = heights
    d["contact"].update(contact or {})
    d["contact_sim"].update(contact_sim)
    return scene_from_dict(d)


def _rigid(sc):
    """The rigid period-n gait: (fixed point, each step's period [s])."""
    from walkerlab.analysis.gait.scene import solve_scene

    _, search = solve_scene(sc, plant=Plant.from_scene(sc))
    res = search.result
    assert res.stable
    return res.x, np.asarray(res.step_periods_s)


def _per_step_of_cycle(strike_times, p: int) -> np.ndarray:
    """Mean period [s] of each step of the cycle (p,) from heel-strike times: the period
    between strikes j - 1 and j is step j's (step 0 ends at the first strike), of cycle step
    ``j mod p``."""
    T = np.diff(np.asarray(strike_times, float))
    j = np.arange(1, T.size + 1)
    return np.array([T[j % p == k].mean() for k in range(p)])


@pytest.mark.parametrize("heights", [[-0.004, -0.006], [-0.005, -0.005, -0.003]])
def test_the_patches_lie_at_the_rigid_gaits_footfalls_at_their_heights(heights):
    from walkerlab.analysis.contact.sim import scene_start
    from walkerlab.config.solver import SolverSettings
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.contact.scene import contact_setup
    from walkerlab.models.registry import build_walker

    sc = _scene(heights)
    x, _ = _rigid(sc)
    walker, _, _, _ = scene_start(contact_setup(sc, plant=Plant.from_scene(sc)), x, 3)
    # the reference: the rigid model's own footfalls (its swing foot at each heel strike)
    rigid = build_walker(Plant.from_scene(sc))
    n = 2 * walker.lane1.size
    traj = simulate_steps(rigid, x, n - 1, Solver.from_settings(
        SolverSettings(method="DOP853", rtol=1e-12, atol=1e-12)))
    feet = [np.zeros(2)]
    for k, seg in enumerate(traj.segments):
        step = rigid.cycle[k % len(rigid.cycle)]
        feet.append(feet[-1] + np.asarray(step.points(seg.x_end)["swing_foot"], float).ravel())
    feet = np.array(feet)
    phi = sc.slope.phi_rad
    s = feet @ np.array([math.cos(phi), -math.sin(phi)])  # along the slope, downhill
    h = feet @ np.array([math.sin(phi), math.cos(phi)])   # along its outward normal
    assert np.allclose(walker.lane2, s[0::2][:walker.lane2.size], atol=1e-9, rtol=0)
    assert np.allclose(walker.lane1, s[1::2][:walker.lane1.size], atol=1e-9, rtol=0)
    assert np.allclose(walker.heights2, h[0::2][:walker.lane2.size], atol=1e-9, rtol=0)
    assert np.allclose(walker.heights1, h[1::2][:walker.lane1.size], atol=1e-9, rtol=0)
    # the steps differ from step to step (a uniform spacing would miss them by ~1 cm)
    assert np.ptp(np.diff(s[:len(heights) + 1])) > 5e-3


@pytest.mark.slow
@pytest.mark.parametrize("heights", [None, [-0.005, -0.005, -0.003]])
def test_the_contact_walker_keeps_the_rigid_period_n_gait_on_footholds(heights):
    """configs/footholds_two.yaml (and three heights): >= 10 heel strikes, each step of the
    cycle within 2 % of the rigid gait's.  Measured (12 heel strikes): two heights +0.24 %,
    +1.41 %; three heights +1.69 %, -0.01 %, +0.81 %."""
    from walkerlab.analysis.contact.sim import simulate_from
    from walkerlab.models.contact.scene import contact_setup

    sc = _scene(heights)
    x, T = _rigid(sc)
    _, res, _, _ = simulate_from(contact_setup(sc, plant=Plant.from_scene(sc)), x, float(T.mean()))
    assert str(res.outcome.kind) in ("t_final", "heel_strike"), res.message
    assert len(res.heel_strike_times) >= 10
    got = _per_step_of_cycle(res.heel_strike_times, T.size)
    assert np.allclose(got, T, rtol=0.02), (got / T - 1) * 100


@pytest.mark.parametrize("heights", [None, [-0.005, -0.005, -0.003]])
def test_the_mjcf_export_walks_footholds_of_several_heights_in_mujoco(heights, tmp_path):
    pytest.importorskip("mujoco")
    from walkerlab.export.mujoco_walk import walk
    from walkerlab.stages import export as export_stage

    sc = _scene(heights)
    _, T = _rigid(sc)
    path = export_stage.run(sc, tmp_path, "mjcf")
    assert "Footholds of several heights" in path.read_text()
    w = walk(path, 9.0)
    assert not w.fell and w.alternating and len(w.times_s) >= 10
    got = _per_step_of_cycle(w.times_s, T.size)
    assert np.allclose(got, T, rtol=0.01), (got / T - 1) * 100


@pytest.mark.slow
@pytest.mark.parametrize("heights", [None, [-0.005]])
def test_a_contact_run_that_drifts_off_the_rigid_footfalls_walks_on_its_own(heights):
    """At ADAMS's friction defaults (ADAMS_FRICTION) the contact steps are ~9 mm shorter
    than the rigid ones: on the paper's 0.1 m patches at the rigid footfalls the walker
    trips after 6 heel strikes.  The run then lays the
    patches at its own footfalls (each footfall's patch keeps its height) and walks the 15
    strides asked for (30 heel strikes; measured two heights +0.32 % and +1.32 % per step of
    the cycle), every heel strike near its patch's centre; footholds of one height
    (configs/footholds.yaml's) alike."""
    from walkerlab.analysis.contact.sim import scene_start, simulate_from
    from walkerlab.analysis.contact.terrain_fit import patch_fit
    from walkerlab.models.contact.scene import contact_setup

    sc = _scene(heights, contact=ADAMS_FRICTION, n_strides=15)
    assert sc.terrain.patch_width_m == 0.10
    x, T = _rigid(sc)
    setup = contact_setup(sc, plant=Plant.from_scene(sc))
    rigid_laid, _, _, _ = scene_start(setup, x, 15)
    walker, res, _, _ = simulate_from(setup, x, float(T.mean()))
    assert str(res.outcome.kind) in ("t_final", "heel_strike"), res.message
    assert len(res.heel_strike_times) >= 30
    got = _per_step_of_cycle(res.heel_strike_times, T.size)
    assert np.allclose(got, T, rtol=0.02), (got / T - 1) * 100
    # the patches moved to the footfalls: those of the run that tripped at their centres (to
    # the integration's rounding), the later ones within 10 mm (measured +9.0 mm at heel
    # strike 30: the steps extrapolated from the run that tripped), where the rigid ones
    # would be 9 mm a step away (0.25 m at heel strike 30)
    fit = patch_fit(walker, res.t, res.feet, res.heel_strike_times, res.heel_strike_legs)
    assert np.max(np.abs(fit.offsets_m[:6])) < 1e-9
    assert np.max(np.abs(fit.offsets_m)) < 0.01
    assert abs(walker.lane2[-1] - rigid_laid.lane2[-1]) > 0.1
    # ... each keeping its footfall's height
    assert np.array_equal(walker.heights1, rigid_laid.heights1)
    assert np.array_equal(walker.heights2, rigid_laid.heights2)
