"""Arms coupled to the opposite legs (``walker.arms``; Collins, Wisse & Ruina 2001, IJRR
20(7)) on the 3D walker of configs/toroidal_arms_3d.yaml, against the Newton-Euler
reference of ``tests/independent/torus_feet_newton.py`` (each arm a rigid body parallel to
the opposite leg, hung from its shoulder on the rolling pelvis; no code shared with the
tree, :mod:`walkerlab.walker.arm_trees`, or its derivation).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.independent.torus_feet_newton import TorusReference
from walkerlab.config.schema import Scene
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
WALKER = dict(g=1.0, L=1.2, gamma=0.01, M=1.0, m=0.5, a=0.7, I_leg=0.02, R=0.2, R_l=0.84)
#: the scene's arms: shoulders 0.5 above the hips, 0.3 apart (3 hip widths), each arm's
#: mass 0.1 at 0.25 down it, 0.002 about it
ARMS = dict(h=0.5, r=3.0, m=0.1, d=0.25, I=0.002)
WIDTH = 0.1


def _raw() -> dict:
    return yaml.safe_load((ROOT / "configs" / "toroidal_arms_3d.yaml").read_text())


@pytest.mark.slow  # the cold derivation of this tree takes ~10 min on a loaded 2-core machine
def test_arms_flow_impact_and_points_match_newton_euler():
    """The generated flow and heel-strike map against the reference's at rolled states to
    1e-11 (roundoff of two independent evaluations; measured <= 2e-15), and each arm's
    centre of mass where the reference puts it (from the stance contact) to 1e-13."""
    walker = build_walker(Plant.from_scene(Scene.model_validate(_raw())))
    ref = TorusReference(**WALKER, arms=ARMS)
    rng = np.random.default_rng(5)
    for _ in range(4):
        x = np.array([0.05, -0.2, 0.17, 0.3, -0.2, -0.25]) + 0.05 * rng.standard_normal(6)
        assert np.max(np.abs(walker.phases[0].flow(0.0, x) - ref.rhs(WIDTH)(0.0, x))) < 1e-11
        assert np.max(np.abs(walker.reset(x) - ref.impact(WIDTH, x))) < 1e-11
        pts = walker.points(x)
        pos = ref.kinematics(WIDTH, x[:3], x[3:], np.zeros(3))[0]
        contact = np.ravel(pts["stance_contact"])
        for side in ("stance", "swing"):
            r = np.ravel(pts[f"{side}_arm_arm"]) - contact
            assert np.max(np.abs(r - pos[f"{side}_arm"])) < 1e-13


@pytest.mark.parametrize(("change", "says"), [
    ({"space": "2d", "hip_width_m": 0.0,
      "leg": {"length_m": 1.2, "foot": {"kind": "arc", "radius_m": 0.2},
              "bodies": [{"kind": "point_mass", "name": "mass", "mass_kg": 0.5,
                          "from_hip_m": 0.5}]}}, "walker.arms"),
    ({"hip_width_m": 0.0}, "walker.arms"),
])
def test_arms_refused_where_not_carried(change, says):
    """Arms on a planar walker, or shoulders apart on hips that are not, are refused in one
    line naming walker.arms."""
    raw = _raw()
    raw["walker"].update(change)
    with pytest.raises(ValueError, match=says):
        Scene.model_validate(raw)
