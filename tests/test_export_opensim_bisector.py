"""The 3D OpenSim model's bisecting hip (issue 98): the upper body's pitch the legs' mean
(Wisse, Hobbelen & Schwab 2007), written as a bisector body on a hinge of half one leg's
pitch carrying the upper body on half the other's, each a ``CoordinateCouplerConstraint``
with a ``LinearFunction`` (:func:`walkerlab.export.opensim_tree.bisected_tree`).

OpenSim 4.6's ``MultivariatePolynomialFunction`` (the coupler of two coordinates the
writers used before) returns its first derivative when asked for its second, so Simbody's
coupler adds ``(u1 + u2)^2 / 2`` to the upper body's acceleration: the OpenSim check below
measures it on the old coupler (the check can fail) and its absence on the new one.
OpenSim runs in a child process (its CasADi clashes with walkerlab's:
tests/test_export_opensim.py); the checks skip without it.
"""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene
from walkerlab.export import opensim_tree
from walkerlab.export.opensim_3d import osim3d_bodies
from walkerlab.export.opensim_tree import (
    BISECTOR_FRACTION,
    bisected_state,
    bisected_tree,
    tree_body_set,
    tree_constraint_set,
    tree_coordinates,
    tree_joint_set,
)
from walkerlab.walker.description import walker_data

needs_opensim = pytest.mark.skipif(importlib.util.find_spec("opensim") is None,
                                   reason="opensim (the osim extra) not installed")

ROOT = Path(__file__).resolve().parents[1]


def _tree(name: str):
    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    return osim3d_bodies(walker_data(scene.walker, scene.slope.phi_rad))


@pytest.mark.parametrize("name", ["torso_powered_3d", "kneed_torso_powered_3d"])
def test_the_bisecting_hip_is_a_bisector_body_on_two_one_coordinate_couplers(name):
    """The upper body (on the pelvis, its pitch coupled to the legs' hips: the thighs' on
    knees) moves onto a body ``torso_bisector`` at its origin turning about its axis by
    ``torso_pitch_half1 = leg1_hip / 2``, itself on ``torso_pitch_half2 = leg2_hip / 2``;
    the bisector carries a millionth of its mass, the default state sums to the legs' mean."""
    root, couplings = _tree(name)
    torso = next(b for b in root.walk() if b.name == "torso")
    new, linear = bisected_tree(root, couplings)
    assert linear == [("torso_pitch_half1", "leg1_hip", 0.5),
                      ("torso_pitch_half2", "leg2_hip", 0.5)]
    bis = next(b for b in new.walk() if b.name == "torso_bisector")
    (upper,) = bis.children
    assert [j.name for j in bis.joints] == ["torso_pitch_half1"]
    assert [j.name for j in upper.joints] == ["torso_pitch_half2"]
    assert bis.joints[0].axis == upper.joints[0].axis == torso.joints[0].axis
    np.testing.assert_array_equal(bis.pos_m, torso.pos_m)
    assert upper.mass_kg == torso.mass_kg and bis.mass_kg == BISECTOR_FRACTION * torso.mass_kg
    coords = tree_coordinates(new)
    assert "torso_pitch" not in coords
    q, v = bisected_state({"leg1_hip": 0.3, "leg2_hip": -0.1, "torso_pitch": 0.1},
                          {"leg1_hip": -1.0, "leg2_hip": 2.0, "torso_pitch": 0.5}, linear)
    assert q == {"leg1_hip": 0.3, "leg2_hip": -0.1, "torso_pitch_half1": 0.15,
                 "torso_pitch_half2": -0.05}
    assert v["torso_pitch_half1"] + v["torso_pitch_half2"] == 0.5


_OLD = """\t\t<ConstraintSet name="constraintset"><objects>
<CoordinateCouplerConstraint name="torso_pitch_coupling"><isEnforced>true</isEnforced>
<coupled_coordinates_function><MultivariatePolynomialFunction><coefficients>0 0.5 0.5
</coefficients><dimension>2</dimension><order>1</order></MultivariatePolynomialFunction>
</coupled_coordinates_function><independent_coordinate_names>leg1_hip leg2_hip
</independent_coordinate_names><dependent_coordinate_name>torso_pitch
</dependent_coordinate_name><scale_factor>1</scale_factor></CoordinateCouplerConstraint>
</objects></ConstraintSet>"""

_ACCELERATIONS = """
import json, sys
import numpy as np
import opensim as osim
osim.Logger.removeFileSink()
model = osim.Model(sys.argv[1])
s = model.initSystem()
model.realizeAcceleration(s)
cs, bs = model.getCoordinateSet(), model.getBodySet()
a = {cs.get(i).getName(): cs.get(i).getAccelerationValue(s) for i in range(cs.getSize())}
u = {cs.get(i).getName(): cs.get(i).getSpeedValue(s) for i in range(cs.getSize())}
pel, tor = bs.get("pelvis"), bs.get("torso")
z = pel.expressVectorInGround(s, osim.Vec3(0, 0, 1)).to_numpy()
wp, wt = (b.getAngularVelocityInGround(s).to_numpy() for b in (pel, tor))
ap, at = (b.getAngularAccelerationInGround(s).to_numpy() for b in (pel, tor))
# the upper body's pitch acceleration relative to the pelvis about the pelvis' pitch axis
rel = float((at - ap) @ z + (wt - wp) @ np.cross(wp, z))
print(json.dumps({"rel": rel, "a": a, "u": u}))
"""


def _accelerations(tmp_path, root, q0, v0, constraints, tag) -> dict:
    """OpenSim's accelerations of the tree ``root`` (no forces but gravity) at ``q0``,
    ``v0`` with the ``constraints`` text."""
    text = "\n".join(['<?xml version="1.0" encoding="UTF-8" ?>',
                      '<OpenSimDocument Version="40600">', '\t<Model name="bisector">',
                      "\t\t<gravity>0 -9.81 0</gravity>", *tree_body_set(root),
                      *tree_joint_set(root, q0, v0), constraints, "\t</Model>",
                      "</OpenSimDocument>", ""])
    path = tmp_path / f"{tag}.osim"
    path.write_text(text)
    out = subprocess.run([sys.executable, "-c", _ACCELERATIONS, str(path)], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


@needs_opensim
def test_opensims_upper_body_accelerates_at_the_legs_mean_on_the_bisector(tmp_path,
                                                                         monkeypatch):
    """configs/torso_powered_3d.yaml's tree in OpenSim at a state of swinging legs
    (``u1 + u2 = 1.4`` rad/s, rolls and the pelvis moving): the upper body's pitch
    acceleration relative to the pelvis (read from the bodies' angular accelerations) is
    the legs' mean pitch acceleration (the bisecting hip's second derivative) to 1e-9
    rad/s^2 on the bisector; on the old two-coordinate coupler it is off by
    ``(u1 + u2)^2 / 2`` = 0.98 rad/s^2 (to 1e-9: OpenSim's fault, so this check fails on the
    old export).  The bisector's millionth of mass moves the legs' accelerations by less
    than 1e-5 of their size (measured against the same tree with a bisector of 1e-4: the
    change is linear in it).  OpenSim is never imported here (``needs_opensim`` finds it
    without importing: in a session that imported CasADi, OpenSim's Moco fails to load)."""
    root, couplings = _tree("torso_powered_3d")
    q0 = {"pelvis_x": 0.0, "pelvis_y": 1.0, "pelvis_z": 0.0, "pelvis_roll": 0.02,
          "leg1_roll": -0.03, "leg1_hip": -0.25, "leg2_roll": 0.01, "leg2_hip": 0.2}
    v0 = {"pelvis_x": 0.9, "pelvis_y": 0.1, "pelvis_z": 0.0, "pelvis_roll": 0.3,
          "leg1_roll": -0.2, "leg1_hip": 2.1, "leg2_roll": 0.1, "leg2_hip": -0.7}
    q0["torso_pitch"] = (q0["leg1_hip"] + q0["leg2_hip"]) / 2
    v0["torso_pitch"] = (v0["leg1_hip"] + v0["leg2_hip"]) / 2
    old = _accelerations(tmp_path, root, q0, v0, _OLD, "old")
    new_root, linear = bisected_tree(root, couplings)
    q, v = bisected_state(q0, v0, linear)
    new = _accelerations(tmp_path, new_root, q, v, "\n".join(tree_constraint_set(linear)),
                         "new")

    def gap(r):
        return r["rel"] - (r["a"]["leg1_hip"] + r["a"]["leg2_hip"]) / 2

    assert abs(gap(new)) < 1e-9
    fault = (v0["leg1_hip"] + v0["leg2_hip"]) ** 2 / 2
    assert gap(old) == pytest.approx(fault, abs=1e-9)
    # the bisector's own inertia, 1e-4 of the upper body's against 1e-6: the legs'
    # accelerations move in proportion, so at 1e-6 they are 1/99 of this gap from none
    monkeypatch.setattr(opensim_tree, "BISECTOR_FRACTION", 1e-4)
    heavy_root, _ = bisected_tree(root, couplings)
    heavy = _accelerations(tmp_path, heavy_root, q, v,
                           "\n".join(tree_constraint_set(linear)), "heavy")
    legs = [c for c in q0 if c != "torso_pitch"]
    a_new = np.array([new["a"][c] for c in legs])
    a_heavy = np.array([heavy["a"][c] for c in legs])
    assert np.max(np.abs(a_heavy - a_new)) / 99 < 1e-5 * np.max(np.abs(a_new))
