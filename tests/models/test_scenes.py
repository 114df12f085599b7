"""Shipped walker scenes against published numbers (where they exist) and the model contract."""

from pathlib import Path

import numpy as np
import pytest

from tests.conftest import TIGHT
from walkerlab.analysis.gait.poincare import find_fixed_point
from walkerlab.config import load_scene
from walkerlab.integrate.rigid import integrate_step
from walkerlab.models.registry import build_walker
from walkerlab.published import garcia1998 as G
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


def _fixed_point(name, slope_rad=None, guess=None):
    sc = load_scene(CONFIGS / f"{name}.yaml")
    if slope_rad is not None:
        sc = sc.model_copy(update={"slope": sc.slope.model_copy(update={"angle_rad": slope_rad})})
    w = build_walker(Plant.from_scene(sc))
    fp = sc.fixedpoint
    if guess is None:
        guess = fp.initial_guess.as_array(w.state_names())
    res = find_fixed_point(w, guess, TIGHT,
                           max_step_time=fp.max_step_time_s)
    return w, res


@pytest.fixture(scope="module")
def simplest():
    return _fixed_point("simplest")


def test_paper_scene_fixed_point_unchanged(paper_fixed_point):
    """configs/paper.yaml (now on the generic path) gives the fixed point of the hand-derived
    model it replaced, to 1e-9 (values recorded before the change)."""
    before = [-0.2041996085, 0.1693996085, -0.6058190001, -0.8610407200]
    np.testing.assert_allclose(paper_fixed_point.x, before, rtol=0, atol=1e-9)
    assert abs(paper_fixed_point.period_s - 0.7035968805) < 1e-9


def test_simplest_walker_long_period_gait_matches_garcia(simplest):
    """Garcia et al. (1998), gamma = 0.009: theta* = 0.20031090049483, theta_dot* =
    -0.19983247291764 (given to 1e-10); the hip angle is 2 theta* on the section."""
    w, res = simplest
    x = dict(zip(w.state_names(), res.x))
    assert abs(x["stance_angle"] - G.LONG_THETA_RAD) < 1e-9
    assert abs(x["stance_rate"] - G.LONG_THETA_DOT) < 1e-9
    assert abs(x["hip_angle"] - 2 * x["stance_angle"]) < 1e-12
    assert res.stable
    # two non-zero multipliers, a complex pair; |lambda| = 0.5891 (Garcia's finite-difference
    # value 0.5883 differs by 1e-3, see walkerlab.published.garcia1998)
    lam = res.multipliers_variational[:2]
    assert abs(abs(lam[0]) - abs(G.LONG_MULTIPLIERS[0])) < 2e-3 and abs(lam[0].imag) > 0.5


def test_simplest_walker_loses_stability_by_period_doubling_past_0_015(simplest):
    """The long-period gait is stable for 0 < gamma < 0.015 (Garcia et al., abstract); at
    gamma = 0.016 (followed from 0.009 by continuation, so that the root finder stays on the
    long-period branch) a real multiplier has left the unit circle through -1."""
    _, res = _fixed_point("simplest", 0.0125, simplest[1].x)
    assert res.stable
    _, res = _fixed_point("simplest", 0.016, res.x)
    lam = res.multipliers_variational[0]
    assert abs(lam.imag) < 1e-9 and lam.real < -1.0


def test_simplest_leg_coordinates_are_absolute_leg_angles(simplest):
    """leg_coordinates maps (theta from the slope normal, phi between the legs) to absolute
    leg angles from the vertical: stance = theta - gamma, swing = theta - phi - gamma."""
    w, res = simplest
    x = dict(zip(w.state_names(), res.x))
    lc = w.leg_coordinates(res.x, "leg2")
    assert set(lc) == set(w.coordinate_units) == {"leg1_angle", "leg2_angle", "leg1_rate",
                                                  "leg2_rate"}
    assert lc["leg2_angle"] == pytest.approx(x["stance_angle"] - G.SLOPE_RAD, abs=1e-15)
    assert lc["leg1_angle"] == pytest.approx(x["stance_angle"] - x["hip_angle"] - G.SLOPE_RAD,
                                             abs=1e-15)
    assert lc["leg1_rate"] == pytest.approx(x["stance_rate"] - x["hip_rate"], abs=1e-15)
    X = np.stack([res.x, res.x], axis=1)
    assert set(w.leg_coordinates(X, "leg1")) == set(lc)
    assert w.leg_coordinates(X, "leg1")["leg1_angle"].shape == (2,)


def test_rod_legs_gait_conserves_energy_in_swing_and_is_stable():
    """Rod legs (I = m l^2/12): the long-period gait of configs/paper_rods.yaml is stable; the
    energy of a step is constant to the solver tolerance (|E| ~ 150 J, rtol 1e-12)."""
    w, res = _fixed_point("paper_rods")
    assert res.stable and res.residual < 1e-10
    seg = integrate_step(w, res.x, TIGHT)
    ke, pe = w.energies(seg.sample(np.linspace(seg.t_start, seg.t_end, 50)))
    e = ke + pe
    assert np.ptp(e) / abs(e[0]) < 1e-10
    # the contract: points(x_end)["swing_foot"] lies on the slope, downhill
    foot = w.points(seg.x_end)["swing_foot"]
    assert foot[0] > 0 and abs(foot[1] + foot[0] * np.tan(w.slope_rad)) < 1e-9
