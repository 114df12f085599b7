"""The Collins-style 3D walker of configs/collins2001.yaml (Collins, Wisse & Ruina 2001,
IJRR 20(7): feet curved in both directions, arms coupled to the opposite legs; straight
legs, the robot's height, mass and slope, the rest assumed) against the Newton-Euler
reference of ``tests/independent/torus_feet_newton.py`` (its own stride, root and central
differences), and its speed against the robot's.

Every test here needs the cold derivation of the arms' tree (~10 min on a loaded 2-core
machine; the tree of configs/toroidal_arms_3d.yaml, the same structure) and is slow.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.independent.mirror_stride import stride_against
from tests.independent.torus_feet_newton import TorusReference
from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config.schema import Scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SOLVER = Solver(method="DOP853", rtol=1e-12, atol=1e-12)
GAMMA = math.radians(3.1)
#: the scene's walker in the reference's names (SI): the leg's mass 0.35 m above its foot
WALKER = dict(g=9.81, L=0.6, gamma=GAMMA, M=1.2, m=1.5, a=0.35, I_leg=0.045, R=0.2, R_l=0.33)
ARMS = dict(h=0.25, r=2.0, m=0.3, d=0.2, I=0.004)
WIDTH = 0.15


def _gait(name: str):
    """The shipped scene's walker and its fixed point from its scene's initial guess."""
    scene = Scene.model_validate(yaml.safe_load((ROOT / "configs" / f"{name}.yaml")
                                                .read_text()))
    walker = build_walker(Plant.from_scene(scene))
    g = scene.fixedpoint.initial_guess.model_extra
    x = np.array([g[n + ("_rad" if n.endswith("_angle") else "_rad_per_s")]
                  for n in walker.state_names()])
    return walker, find_fixed_point(walker, x, SOLVER, fd_check=False)


@pytest.fixture(scope="module")
def gait():
    return _gait("collins2001")


@pytest.mark.slow
def test_collins_gait_and_multipliers_match_newton_euler(gait):
    """The generated stride's fixed point and period against the reference's own root to
    1e-8, its multipliers against the reference's central differences (h = 1e-6) to 1e-6
    relative to max(1, |mu|)."""
    _, res = gait
    ref = TorusReference(**WALKER, arms=ARMS)
    dx, dt, dmu = stride_against(ref, WIDTH, res, [0, 2, 3, 4, 5])
    assert dx < 1e-8 and dt < 1e-8 and dmu < 1e-6


@pytest.mark.slow
def test_collins_walker_walks_faster_than_the_robot_and_is_laterally_unstable(gait):
    """The gait: step period 0.62514 s, step 0.43152 m, 0.6903 m/s against the robot's
    0.51 m/s on the same 3.1 degree slope (35 % faster: straight legs, a plastic heel and
    the assumed mass distribution; the robot's knees and soft heels are not modelled), and
    the lateral mode a complex pair of modulus 1.473 a stride (the least over the lateral
    radius on this branch, at R_l = 0.33 m: not stable, as the robot was).  To 1e-5
    relative: the fixed point's tolerance is 1e-12."""
    _, res = gait
    step = res.period_s / 2
    length = res.step_lengths_m[0]
    assert abs(step - 0.6251446) < 1e-5 * step
    assert abs(length - 0.4315241) < 1e-5 * length
    speed = length / step
    assert abs(speed / 0.51 - 1.354) < 1e-3            # the robot's 0.51 m/s
    mu = np.max(np.abs(res.multipliers_variational))
    assert abs(mu - 1.473069) < 1e-5 * mu
    lead = res.multipliers_variational[np.argmax(np.abs(res.multipliers_variational))]
    assert abs(lead.imag) > 0.5                        # a complex pair: the rocking


@pytest.mark.slow
def test_arms_lower_the_collins_lateral_multiplier(gait):
    """The arms' share: their mass scaled down (0.3 kg each to 0.03, the rest moved to the
    pelvis: 4.8 kg throughout), the gait continued: the lateral pair's modulus 1.473 a
    stride with the robot's arms, 1.638 at 0.6 of their mass, 1.902 at 0.1 (the lateral
    radius moves it far more: 37.7 at R_l = 0.154 m, configs/collins2001.yaml).  To 1e-4
    relative (the fixed points' tolerance 1e-12)."""
    raw = yaml.safe_load((ROOT / "configs" / "collins2001.yaml").read_text())
    x = gait[1].x
    measured = {0.6: 1.637583, 0.1: 1.901853}
    for f in (0.8, 0.6, 0.4, 0.2, 0.1):
        arm = raw["walker"]["arms"]["bodies"][0]
        arm["mass_kg"], arm["inertia_about_com_kg_m2"] = 0.3 * f, 0.004 * f
        raw["walker"]["hip_mass_kg"] = 1.2 + 0.6 * (1 - f)
        walker = build_walker(Plant.from_scene(Scene.model_validate(raw)))
        res = find_fixed_point(walker, x, SOLVER, fd_check=False)
        x = res.x
        if f in measured:
            mu = np.max(np.abs(res.multipliers_variational))
            assert abs(mu - measured[f]) < 1e-4 * mu, (f, mu)


#: configs/collins2001_stable.yaml's walker in the reference's names: its legs' mass 0.35 m
#: above their feet, its shoulders 0.3 m apart (r hip widths)
STABLE = dict(g=9.81, L=0.6, gamma=GAMMA, M=1.2, m=1.46, a=0.35, I_leg=0.02, R=0.21,
              R_l=0.37)
STABLE_ARMS = dict(h=0.25, r=0.3 / 0.18, m=0.34, d=0.24, I=0.0046)


@pytest.fixture(scope="module")
def stable():
    return _gait("collins2001_stable")


@pytest.mark.slow
def test_the_stable_collins_gait_and_multipliers_match_newton_euler(stable):
    """configs/collins2001_stable.yaml against the reference's own stride, root and central
    differences: the fixed point and period to 1e-8, every multiplier to 1e-6 relative to
    max(1, |mu|), so the reference, which shares no code with the generator, finds the
    gait stable too."""
    _, res = stable
    ref = TorusReference(**STABLE, arms=STABLE_ARMS)
    dx, dt, dmu = stride_against(ref, 0.18, res, [0, 2, 3, 4, 5])
    assert dx < 1e-8 and dt < 1e-8 and dmu < 1e-6


@pytest.mark.slow
def test_the_stable_collins_walker_is_laterally_stable_and_returns_from_a_sideways_kick(
        stable):
    """The 4.8 kg, 0.85 m walker on the robot's 3.1 degree slope with 0.18 m of hip width:
    step period 0.513434 s, step 0.384164 m (0.748 m/s against the robot's 0.51 m/s), every
    stride multiplier inside the unit circle, the largest the rocking pair (modulus 0.88503,
    to 1e-5: the fixed point's tolerance 1e-12); and a nonlinear walk of 40 strides from
    the gait with its lean rate kicked by 0.01 rad/s (and its lean by 1 mrad) ends within
    1e-3 of the fixed point (measured 1e-4; 0.029 after the first stride)."""
    from walkerlab.analysis.gait.poincare import poincare_map

    walker, res = stable
    step = res.period_s / 2
    length = res.step_lengths_m[0]
    assert abs(step - 0.5134339) < 1e-5 * step
    assert abs(length - 0.3841643) < 1e-5 * length
    mu = res.multipliers_variational
    assert np.max(np.abs(mu)) < 1
    assert abs(np.max(np.abs(mu)) - 0.885033) < 1e-5
    lead = mu[np.argmax(np.abs(mu))]
    assert abs(lead.imag) > 0.5                        # a complex pair: the rocking
    names = walker.state_names()
    x = np.array(res.x, float)
    x[names.index("lean_rate")] += 0.01
    x[names.index("lean_angle")] += 0.001
    for _ in range(40):
        x = poincare_map(walker, x, SOLVER, 5.0)[0]
    assert np.max(np.abs(x - res.x)) < 1e-3


@pytest.mark.slow
def test_the_collins_walkers_lateral_pair_turns_stable_with_the_hip_width_before_a_fold():
    """``walkerlab continuation`` of configs/collins2001.yaml in the hip width (0.15 to
    0.21 m; the rigid model's validity checks on its 3D points, which gave a numpy error
    before): the rocking pair crosses the unit circle inward at a Neimark-Sacker point,
    0.20521 m, and the branch folds at 0.20664 m, so the gait is laterally stable between
    them (configs/collins2001_stable.yaml's parts move that window to 0.175-0.18 m); to
    1e-4 m (the located points' tolerance is far finer)."""
    from walkerlab.studies.continuation import run_continuation

    scene = Scene.model_validate(yaml.safe_load((ROOT / "configs" / "collins2001.yaml")
                                                .read_text()))
    res, _ = run_continuation(scene, "walker.hip_width_m", 0.15, 0.21,
                              plant=Plant.from_scene(scene))
    ns = [s.p for s in res.specials if s.kind == "neimark_sacker" and s.period == 1]
    folds = [s.p for s in res.specials if s.kind == "fold" and s.period == 1]
    assert len(ns) == 1 and abs(ns[0] - 0.20521) < 1e-4, res.specials
    assert len(folds) == 1 and abs(folds[0] - 0.20664) < 1e-4, res.specials
