"""The rimless wheel's MJCF on stairs and on a height profile (issue 58; before: "a spoked
wheel's MJCF carries the slope's plane only"): the ground is laid as the wheel's contact
model lays it (continuous treads, a height field), the first stance spoke's tip at the
origin.  The reference heights are the scene's own numbers (the stairs' risers, the
profile's vertices), measured in the written file by MuJoCo's ray cast."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml
from cli_run import ROOT

from walkerlab.config import scene_from_dict
from walkerlab.walker.plant import Plant

mujoco = pytest.importorskip("mujoco")

RISER, TREAD = 0.0611, 0.7629  # [m]: a 0.08 rad ramp's drop per 8-spoke step


def _wheel(terrain, slope=0.08):
    d = yaml.safe_load((ROOT / "configs" / "rimless_wheel.yaml").read_text())
    for k in ("basin", "mfpt"):
        d.pop(k, None)
    d["name"] = "wheel_ground"
    d["slope"] = {"angle_rad": slope}
    d["terrain"] = terrain
    return scene_from_dict(d)


def _profile():
    x = np.arange(0.0, 16.01, 0.5)
    y = -math.tan(0.08) * x + 0.005 * np.sin(2 * np.pi * x / 3.0)
    return x, y


def _ground_height(xml: str, x: float) -> float:
    """The ground's height [m] under ``x`` in the MJCF ``xml``, by a ray cast down onto the
    world body's geoms (the wheel excluded)."""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geomid = np.zeros(1, np.int32)
    hub = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "hub")
    d = mujoco.mj_ray(model, data, np.array([x, 0.0, 5.0]), np.array([0.0, 0.0, -1.0]),
                      None, 1, hub, geomid)
    assert d >= 0
    return 5.0 - d


def _xml(scene):
    from walkerlab.export.mjcf_ground import wheel_ground
    from walkerlab.export.spoked import wheel_chord_m, wheel_mjcf_text
    from walkerlab.walker.description import walker_data

    data = walker_data(scene.walker, scene.slope.phi_rad)
    ground = wheel_ground(scene.terrain, scene.walker.spoke_length_m,
                          chord_m=wheel_chord_m(data), slope_rad=scene.slope.phi_rad)
    return wheel_mjcf_text(data, "w", hub_inertia_kg_m2=1e-3, ground=ground)


def test_the_wheels_mjcf_stairs_are_treads_a_riser_below_each_other():
    scene = _wheel({"kind": "stairs", "riser_m": RISER, "tread_m": TREAD,
                    "direction": "down", "lanes": "continuous"}, slope=0.0)
    xml = _xml(scene)
    assert 'name="ground" type="plane"' not in xml
    for k in range(-2, 12):  # mid-tread k: the first stance tip stands mid-tread 0
        assert _ground_height(xml, k * TREAD) == pytest.approx(-k * RISER, abs=1e-9)


def test_the_wheels_mjcf_profile_is_a_height_field_through_the_profiles_vertices():
    """MuJoCo's height field is linear between samples 5 mm apart; the profile's vertices
    are 0.5 m apart, so at a vertex the field is the profile's height to its float32
    elevation (range 1.3 m: 1e-6 m)."""
    x, y = _profile()
    scene = _wheel({"kind": "profile", "lanes": "continuous",
                    "profile_m": [[float(a), float(b)] for a, b in zip(x, y)]})
    xml = _xml(scene)
    for xi, yi in list(zip(x, y))[1:-1:3]:
        assert _ground_height(xml, xi) == pytest.approx(yi, abs=1e-5)


def test_a_wheel_on_stairs_footholds_or_a_profile_is_no_longer_refused_by_its_mjcf():
    from walkerlab.walker.kinds import KINDS

    wheel = KINDS["rolling_polygon"]
    assert all(wheel.supports(f, "mjcf") for f in ("stairs", "footholds", "profile"))


@pytest.mark.slow  # ~15 s: the rigid gait and 12 s of MuJoCo
def test_the_wheel_rolls_its_profile_in_mujoco(tmp_path):
    """The wheel on a 0.08 rad ramp with a 5 mm, 3 m undulation: 11 spoke strikes in
    MuJoCo, the mean step period within 1 % of the rigid slope gait's 1.03455 s (measured
    +0.20 %; the undulation changes each step by less)."""
    from walkerlab.stages import export as export_stage

    x, y = _profile()
    scene = _wheel({"kind": "profile", "lanes": "continuous",
                    "profile_m": [[float(a), float(b)] for a, b in zip(x, y)]})
    check = export_stage.write(scene, tmp_path, "mjcf", walk=True).walk
    assert check.walked and not check.fell, check.line
    assert check.strikes >= 10 and check.alternating, check.line
    assert check.period_s == pytest.approx(check.rigid_period_s, rel=0.01), check.line


def test_the_wheels_post_impact_section_on_stairs_stands_the_spoke_behind_a_riser_up():
    """The rigid wheel on stairs (a landing a riser below each step): just after a spoke
    strike the old stance spoke stands on the tread behind, a riser up, so the stance
    spoke's angle is ``alpha - asin(riser / (2 L sin alpha))`` (``alpha = pi / spokes``;
    two spoke tips a chord apart).  Before, the section solved the clearance of the spoke
    ahead and returned the mirror image, ``-0.3128`` rad, and ``fixedpoint`` found no gait;
    the step from the section lands on the next tread (same angle, to the event's 1e-9)."""
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    scene = _wheel({"kind": "stairs", "riser_m": RISER, "tread_m": TREAD,
                    "direction": "down", "lanes": "continuous"}, slope=0.0)
    walker = build_walker(Plant.from_scene(scene))
    alpha, L = math.pi / scene.walker.spokes, scene.walker.spoke_length_m
    want = alpha - math.asin(RISER / (2 * L * math.sin(alpha)))
    x0 = walker.from_section(np.array([-1.0953]))
    assert x0[0] == pytest.approx(want, abs=1e-12)
    seg = simulate_steps(walker, x0, 1, Solver.from_settings(scene.solver)).segments[0]
    assert seg.termination == "heel_strike"
    assert seg.x_next[0] == pytest.approx(want, abs=1e-9)


def test_the_wheels_footholds_lie_a_chord_apart_at_their_heights_on_the_slope():
    """The wheel on its 0.08 rad slope with footholds 1 cm above and below the stance
    tip's level in turn: the rigid post-impact angle from the vertical after each landing
    is ``alpha - asin(h cos(phi) / c) - phi`` (the spoke behind stands ``h cos(phi)`` along
    the normal above the stance tip, a chord ``c = 2 L sin(alpha)`` away; to 1e-12 rad), and
    the MJCF's patches are where the tips land: MuJoCo's ray cast finds each footfall's
    patch top at the heights summed along the normal from the stance tip (1e-9 m)."""
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    h = (0.01, -0.01)
    scene = _wheel({"kind": "footholds", "foothold_heights_m": list(h),
                    "lanes": "checkerboard", "patch_width_m": 0.2})
    phi, alpha, L = 0.08, math.pi / scene.walker.spokes, scene.walker.spoke_length_m
    c = 2 * L * math.sin(alpha)

    def after(k):  # the stance angle just after landing k (height h[k mod 2])
        return alpha + math.asin(h[k % 2] * math.cos(phi) / c) - phi

    walker = build_walker(Plant.from_scene(scene))
    x0 = walker.from_section(np.array([-1.09]))
    assert x0[0] == pytest.approx(after(1), abs=1e-12)  # the map's section: step 1's
    segs = simulate_steps(walker, x0, 4, Solver.from_settings(scene.solver)).segments
    assert [s.termination for s in segs] == ["heel_strike"] * 4
    for k, s in enumerate(segs):
        assert s.x_next[0] == pytest.approx(after(k), abs=1e-9)
    xml = _xml(scene)
    t = np.array([math.cos(phi), -math.sin(phi)])
    n = np.array([math.sin(phi), math.cos(phi)])
    p = np.zeros(2)
    for k in range(8):  # footfall k + 1 from footfall k: up h_k along n, the chord's rest along t
        up = h[k % 2] * math.cos(phi)
        p = p + math.sqrt(c * c - up * up) * t + up * n
        assert _ground_height(xml, p[0]) == pytest.approx(p[1], abs=1e-9)
