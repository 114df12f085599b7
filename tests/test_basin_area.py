"""The basin's area in the section as the fraction of a stated box (issue 24)."""

import math

import numpy as np

from walkerlab.analysis.robustness.basin_area import basin_area
from walkerlab.io.schemas.basin import BasinArtifact

OUTCOMES = ["converged", "other_attractor", "fell_forward", "fell_backward", "max_steps",
            "stalled", "unreachable"]


def _disk_map(n=400, r=0.3, centre=(0.1, -1.0)):
    """A basin map whose converged cells form a disk of radius r [rad, rad/s units] on the
    box [-0.5, 0.5] x [-1.5, -0.5] (cell centres n x n)."""
    h = 1.0 / n
    x = -0.5 + h * (np.arange(n) + 0.5)
    y = -1.5 + h * (np.arange(n) + 0.5)
    X, Y = np.meshgrid(x, y)
    out = np.where((X - centre[0]) ** 2 + (Y - centre[1]) ** 2 <= r * r, 0, 2)
    return BasinArtifact(x, y, out, np.zeros_like(out), np.ones_like(out), "rad", "rad/s",
                         "stance_angle", "stance_rate", OUTCOMES,
                         {"stance_angle": centre[0], "stance_rate": centre[1],
                          "swing_angle": 0.0, "swing_rate": 0.0}, 50)


def test_basin_area_is_the_converged_share_of_the_stated_box():
    """A disk of radius 0.3 in a unit box: area pi r^2 = 0.2827 to the cell size (400^2
    cells: the boundary cells err by ~ 2 pi r h = 0.005 at most); the box is the cell
    edges; the gait's cell converges (a basin exists); moving the gait outside the disk
    says none exists around it."""
    a = basin_area(_disk_map())
    np.testing.assert_allclose(a.box, (-0.5, 0.5, -1.5, -0.5), rtol=0, atol=1e-12)
    assert abs(a.area - math.pi * 0.09) < 2 * math.pi * 0.3 / 400
    assert a.fraction == a.area and a.exists and a.cells == 160000
    b = _disk_map()
    b.fixed_point["stance_angle"] = 0.45  # outside the disk
    assert not basin_area(b).exists
