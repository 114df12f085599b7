"""Fixed point of the Poincaré map for the paper's scene, and Eq. (11)."""

import numpy as np
import pytest

from tests.conftest import TIGHT
from walkerlab.analysis.gait.poincare import find_fixed_point, poincare_map
from walkerlab.models.hybrid.printed_equations import make_compass_gait
from walkerlab.published import paper

EQ11 = np.array(paper.EQ11_STATE)  # role-ordered, as printed


def test_fixed_point_residual_and_stability(paper_fixed_point):
    fp = paper_fixed_point
    assert fp.residual <= 1e-10
    assert fp.stable
    # one multiplier is zero by construction (the map lands on the guard surface)
    assert np.min(np.abs(fp.multipliers_variational)) < 1e-12
    # variational and finite-difference multipliers agree (FD with h = 1e-7: ~1e-8)
    assert fp.multiplier_difference < 1e-6


def test_fixed_point_is_a_fixed_point(paper_walker, paper_fixed_point):
    x1, T, _ = poincare_map(paper_walker, paper_fixed_point.x, TIGHT)
    assert np.max(np.abs(x1 - paper_fixed_point.x)) < 1e-10
    assert pytest.approx(paper_fixed_point.period_s, abs=1e-10) == T


def test_appendix_a_reproduces_eq11():
    """Printed Appendix A at phi = 0.0174 rad gives Eq. (11) to the printed digits: angles
    to 4 decimals, dtheta1 to 2 decimals; dtheta2 = -0.8466 is printed as -0.84, i.e. the
    paper truncated it (rounding gives -0.85)."""
    w = make_compass_gait(1.0, 5.0, 10.0, 9.81, 0.5, 0.0174, "appendix_a")
    fp = find_fixed_point(w, EQ11, TIGHT)
    assert np.round(fp.x[:2], 4) == pytest.approx(EQ11[:2], abs=1e-12)
    assert np.round(fp.x[2], 2) == pytest.approx(EQ11[2], abs=1e-12)
    assert np.trunc(fp.x[3] * 100) / 100 == pytest.approx(EQ11[3], abs=1e-12)


def test_derived_fixed_point_differs_from_eq11(paper_fixed_point):
    """The energy-consistent model's gait differs from Eq. (11) by ~2e-3 rad in the angles
    and ~2e-2 rad/s in the stance rate (the A.5 sign error)."""
    d = np.abs(paper_fixed_point.x - EQ11)
    assert 1e-3 < d[0] < 5e-3
    assert d[3] > 1e-2


def test_flat_ground_has_no_passive_gait():
    from walkerlab.analysis.gait.poincare import FixedPointNotFound

    w = make_compass_gait(1.0, 5.0, 10.0, 9.81, 0.5, 0.0, "derived")
    with pytest.raises(FixedPointNotFound):
        find_fixed_point(w, EQ11, TIGHT)
