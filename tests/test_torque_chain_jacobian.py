"""The actuated flow's Jacobian from the torques' closed-form state derivative
(:func:`walkerlab.models.hybrid.actuated.torque_chain_jacobian`: ``M^-1 (B dtau/dx - dM/dq
acc)``, what the optimised step's replay uses for its Floquet multipliers) against the
complex step through the whole torque law (the default, exact to round-off: Squire & Trapp
1998).  Both are exact up to round-off in the generated expressions (entries of order 1-100
here), so they agree to ~1e-12 relative to the largest entry."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"

COMPASS = {"name": "t", "walker": {"model": "compass_gait", "leg_length_m": 1.0,
                                   "leg_mass_kg": 5.0, "hip_mass_kg": 10.0,
                                   "gravity_m_per_s2": 9.81, "leg_mass_from_foot_m": 0.5,
                                   "actuation": {"torques": [{"joint": "hip", "law": {},
                                                              "max_torque_n_m": 1e6}]}},
           "slope": {"angle_rad": 0.01},
           "solver": {"method": "DOP853", "rtol": 1e-12, "atol": 1e-12}}


def _walkers():
    sc = scene_from_dict(COMPASS)
    sc1 = load_scene(CONFIGS / "kuo2002.yaml")
    return {"compass": build_walker(Plant.from_scene(sc)),  # massive legs
            "kuo2002": build_walker(Plant.from_scene(sc1))}  # massless legs


@pytest.fixture(scope="module")
def walkers():
    return _walkers()


def _check(w, torques, torque_jacobian):
    """The phase Jacobian with ``torque_jacobian`` set equals the complex step's."""
    acts, phase = w.actuators, w.phases[0]
    acts.torques = torques
    rng = np.random.default_rng(3)
    for _ in range(10):
        x = rng.normal(0.0, [0.2, 0.3, 1.0, 1.0])
        t = float(rng.uniform(0.0, 1.0))
        acts.torque_jacobian = None
        want = phase.jacobian(t, x)
        acts.torque_jacobian = torque_jacobian
        got = phase.jacobian(t, x)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
    acts.torque_jacobian = None


@pytest.mark.parametrize("name", ["compass", "kuo2002"])
def test_a_torque_of_time_alone_needs_only_the_mass_matrix_derivative(walkers, name):
    _check(walkers[name], lambda t, x: np.array([0.7 * np.sin(3.0 * np.real(t)) + 0.2]),
           lambda t, x: np.zeros((1, 4)))


@pytest.mark.parametrize("name", ["compass", "kuo2002"])
def test_a_state_feedback_torque_enters_through_b_dtau_dx(walkers, name):
    k = np.array([1.5, -2.0, 0.3, 0.8])  # tau = k . x + t: dtau/dx = k

    _check(walkers[name], lambda t, x: np.array([k @ x + np.real(t)]),
           lambda t, x: k[None, :])
