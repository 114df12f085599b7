"""The flat-footed walker's contact gait steps 5-11 % slower than its rigid gait, alternating
between the legs (configs/flat_feet.yaml, its contact section's note): a difference of the
two models' heel strikes, not an asymmetry.  The rigid view releases the trailing foot at heel
strike (its massless foot snaps to rest; its ankle spring's ~1 J is lost); in the contact
model that foot stays on its toe for ~18 ms and its spring pushes the trailing leg off.  Run
with the rigid view's rule at each heel strike (scripts/flat_feet_contact_gap.py), the contact
walker settles within 3 steps on one period (no alternation) at the rigid one plus the
regularising foot mass's share."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene

ROOT = Path(__file__).resolve().parents[1]
STEPS = 6


def _script():
    spec = importlib.util.spec_from_file_location(
        "flat_feet_contact_gap", ROOT / "scripts" / "flat_feet_contact_gap.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def gap():
    mod = _script()
    scene = load_scene(ROOT / "configs" / "flat_feet.yaml")
    x_ideal, period = mod.rigid_gait(scene)
    runs = {(rule, scale): mod.step_periods(scene, x_ideal, STEPS, rule, scale)
            for rule, scale in ((False, 1.0), (True, 1.0), (True, 0.1))}
    return period, runs


def test_the_contact_gait_alternates_and_is_slower(gap):
    # the shipped contact run's steps (contact_sim.h5: 0.794, 0.842, 0.800, 0.837 s): the
    # step-to-step difference decays by ~0.88 a step, so it is > 30 ms on steps 2-3
    period, runs = gap
    p = runs[(False, 1.0)]
    assert len(p) == STEPS
    assert abs(p[2] - p[3]) > 0.030
    assert np.mean(p[2:]) / period > 1.05


def test_with_the_rigid_heel_strike_it_settles_on_one_period(gap):
    # measured: 0.7795, 0.7790, 0.7797, 0.7794 s (1.029 x rigid); the 0.1 kg foot at the end
    # of each 1 m leg adds ~8 % to the swing leg's inertia about the hip, ~2 % to its
    # pendulum period
    period, runs = gap
    p = runs[(True, 1.0)]
    assert len(p) == STEPS
    assert np.max(np.abs(np.diff(p[2:]))) < 1e-3
    assert 1.015 < np.mean(p[2:]) / period < 1.04


def test_with_light_feet_and_the_rigid_heel_strike_it_is_the_rigid_gait(gap):
    # a tenth of the foot mass: 0.7624-0.7628 s, 1.0064 x rigid - within the ~1 % the
    # point- and arc-footed walkers' contact models reach (their compliance's share)
    period, runs = gap
    p = runs[(True, 0.1)]
    assert len(p) == STEPS
    assert abs(np.mean(p[2:]) / period - 1.0) < 0.01
