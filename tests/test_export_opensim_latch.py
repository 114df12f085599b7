"""The OpenSim export's knee latch reads the foot's contact point (issue 58 item 3).

A kneed walker with arc feet fell at 0.34-0.43 s in OpenSim: the stepping loop's latch read
the height of the foot sphere's centre, an arc radius above the contact point, so the stance
knee's latch (release height 2 mm) never held.  The file is checked by its numbers (no
OpenSim needed), and, where OpenSim is installed, walked (a slow test).  The numbers: the
foot height the file's latch uses (the sphere centre's height above the slope line, from
the file's own coordinates, frames and sphere, less the file's offset) equals the contact
point's height in walkerlab's contact model (minus its penetration, which its latch weight
reads) on the same state, for point and arc feet.  The forward kinematics here are this
test's own (the file's PinJoint frames and coordinates); flat feet are refused by the
OpenSim export (the capability table), so only one sphere per foot occurs.
"""

from __future__ import annotations

import importlib.util
import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config import scene_from_dict

ROOT = Path(__file__).resolve().parents[1]


def _kneed(foot: dict):
    d = yaml.safe_load((ROOT / "configs" / "kneed.yaml").read_text())
    d["walker"]["leg"]["foot"] = foot
    d["name"] = "kneed_" + foot["kind"]
    return scene_from_dict(d)


def _file(scene, tmp_path) -> str:
    from walkerlab.stages import export as export_stage

    return Path(export_stage.run(scene, tmp_path, "osim")).read_text()


def _file_numbers(text: str) -> dict:
    """What the latch needs from the file: its offset and release numbers, the slope, each
    coordinate's default value, the knee frames' offsets and the foot spheres."""
    num = r"(-?[0-9.e+-]+)"
    out = {"offset": float(re.search(r"slope line less " + num + r" m \(the sphere's radius",
                                     text).group(1)),
           "release": float(re.search(r"less than " + num + r" m above the ground", text)
                            .group(1)),
           "slope": float(re.search(r"Ground: slope " + num + " rad", text).group(1))}
    out["q"] = {m.group(1): float(m.group(2)) for m in re.finditer(
        r'<Coordinate name="(\w+)">\s*<default_value>' + num, text)}
    out["knee_at"] = {m.group(1): float(m.group(2)) for m in re.finditer(
        r'<PhysicalOffsetFrame name="(leg\d)_thigh_at_leg\d_knee">\s*<socket_parent>[^<]*'
        r"</socket_parent>\s*<translation>0.0 " + num, text)}
    out["sphere"] = {m.group(1): (m.group(2), float(m.group(3))) for m in re.finditer(
        r'<ContactSphere name="(leg\d)_foot">\s*<socket_frame>/bodyset/(\w+)</socket_frame>'
        r"\s*<location>0.0 " + num, text)}
    return out


def _centre_height(f: dict, q: dict, leg: str) -> float:
    """The foot sphere's centre above the slope line [m] (this test's kinematics: a link at
    absolute angle psi hangs along (sin psi, -cos psi))."""
    phi = f["slope"]
    n = np.array([math.sin(phi), math.cos(phi)])
    p = np.array([q["hip_x"], q["hip_y"]])
    thigh = q[f"{leg}_hip"]
    body, along = f["sphere"][leg]
    if body.endswith("_shank"):
        p = p - f["knee_at"][leg] * np.array([math.sin(thigh), -math.cos(thigh)])
        psi = thigh + q[f"{leg}_knee"]
    else:
        psi = thigh
    p = p - along * np.array([math.sin(psi), -math.cos(psi)])
    return float(p @ n)


def _contact_heights(scene, q: dict) -> dict:
    """The contact point's height of each leg in walkerlab's contact model: minus its
    penetration (the latch weight's argument)."""
    from walkerlab.config.contact import ContactSettings
    from walkerlab.models.contact.model import ContactWalker
    from walkerlab.models.contact.rigid_limit import contact_si
    from walkerlab.walker.description import walker_data

    c, knee = contact_si(scene.contact or ContactSettings())
    w = ContactWalker(contact=c, data=walker_data(scene.walker, scene.slope.phi_rad),
                      knee_stop=knee)
    x = np.zeros(len(w.state_names()))
    x[:6] = (q["hip_x"], q["hip_y"], q["leg1_hip"], q["leg1_hip"] + q["leg1_knee"],
             q["leg2_hip"], q["leg2_hip"] + q["leg2_knee"])
    fq = w.foot_quantities(x[None])
    return {leg: -float(fq[leg]["penetration"][0]) for leg in ("leg1", "leg2")}


@pytest.mark.parametrize("foot, offset", [({"kind": "point"}, 0.0),
                                          ({"kind": "arc", "radius_m": 0.05}, 0.05)])
def test_opensim_latch_reads_the_contact_points_height(foot, offset, tmp_path):
    """On the file's default state (the rigid gait's heel strike: leg2's contact point at the
    origin) and on states with the swing leg lifted and its knee flexed, the file's latch
    height equals the contact model's contact-point height to 1e-12 m, for both legs; the
    file's offset is the arc's radius (point feet: 0).  With the sphere's centre instead
    (the old loop), an arc-footed stance foot stands 50 mm above the 2 mm release height:
    the latch never held."""
    scene = _kneed(foot)
    f = _file_numbers(_file(scene, tmp_path))
    assert f["offset"] == pytest.approx(offset, abs=1e-15)
    for lift, knee in ((0.0, 0.0), (0.05, -0.2), (0.15, -0.6), (-0.02, -0.005)):
        q = dict(f["q"])
        q["leg1_hip"] += lift
        q["leg1_knee"] += knee
        ref = _contact_heights(scene, q)
        for leg in ("leg1", "leg2"):
            mine = _centre_height(f, q, leg) - f["offset"]
            assert mine == pytest.approx(ref[leg], abs=1e-12), (lift, knee, leg)
    stance = _centre_height(f, f["q"], "leg2")
    assert stance - f["offset"] == pytest.approx(0.0, abs=1e-12)  # on the ground: latched
    assert (stance < f["release"]) == (offset == 0.0)  # the centre: the arc never latched


def _patches(text: str) -> dict:
    """Each lane's patch spheres from the file: ``{leg: [(x, y, radius), ...]}``."""
    num = r"(-?[0-9.e+-]+)"
    out: dict = {"leg1": [], "leg2": []}
    for m in re.finditer(r'<ContactSphere name="(leg\d)_patch\d+">\s*<socket_frame>/ground'
                         r"</socket_frame>\s*<location>" + num + " " + num + r" 0.0</location>"
                         r"\s*<radius>" + num, text):
        out[m.group(1)].append((float(m.group(2)), float(m.group(3)), float(m.group(4))))
    return out


@pytest.mark.parametrize("foot", [{"kind": "point"}, {"kind": "arc", "radius_m": 0.05}])
def test_opensim_latch_on_footholds_reads_the_patch_under_the_foot(foot, tmp_path):
    """Footholds 5 mm below each other (patches at tread heights): the loop's foot height
    (:func:`walkerlab.export.opensim_walk.contact_height` on the file's patch spheres, their
    tops and the patch width from the file) equals the contact model's contact-point height
    with the same patches (their centres and heights from the file's spheres) to 1e-12 m,
    for both legs, on states with the swing foot over its next patch, over a gap and the
    stance foot on its patch, at the first tread and 1 mm above the treads 2, 4 and 6
    risers (10-30 mm) down the footholds; against the slope line alone (the old loop) that
    stance foot reads 9-29 mm below the ground (a latch that never releases)."""
    from walkerlab.export.opensim_walk import contact_height

    d = yaml.safe_load((ROOT / "configs" / "kneed.yaml").read_text())
    d["walker"]["leg"]["foot"] = foot
    d["terrain"] = {"kind": "footholds", "foothold_heights_m": [-0.005]}
    scene = scene_from_dict(d)
    text = _file(scene, tmp_path)
    f = _file_numbers(text)
    width = float(re.search(r"a patch of width (\S+) m", text).group(1))
    phi = f["slope"]
    t_hat = np.array([math.cos(phi), -math.sin(phi)])
    n_hat = np.array([math.sin(phi), math.cos(phi)])
    spheres = _patches(text)
    r_foot = float(re.search(r'<ContactSphere name="leg1_foot">.*?<radius>(\S+)</radius>',
                             text, re.S).group(1))
    tops = {g: [(float(np.array(p[:2]) @ t_hat), float(np.array(p[:2]) @ n_hat) + p[2])
                for p in spheres[g]] for g in spheres}
    assert all(len(v) > 10 for v in tops.values())

    from walkerlab.config.contact import ContactSettings
    from walkerlab.models.contact.model import ContactWalker
    from walkerlab.models.contact.rigid_limit import contact_si
    from walkerlab.walker.description import walker_data

    c, knee = contact_si(scene.contact or ContactSettings())
    ground_offset = r_foot - f["offset"]  # the patch tops lie this far below the treads
    lane = {g: np.array([s for s, _ in tops[g]]) for g in tops}
    height = {g: np.array([top + ground_offset for _, top in tops[g]]) for g in tops}
    w = ContactWalker(contact=c, data=walker_data(scene.walker, scene.slope.phi_rad),
                      knee_stop=knee, lane1=lane["leg1"], lane2=lane["leg2"],
                      heights1=height["leg1"], heights2=height["leg2"],
                      patch_half_width=width / 2, continuous=False)
    assert np.ptp(height["leg1"]) > 0.004  # treads of several heights
    seen = set()
    # the keyframe's walker, its swing leg lifted, and moved k steps down the footholds with
    # its stance foot 1 mm above leg2's k-th patch (a tread 2 k risers below the first)
    states = [(0.0, 0.0, 0), (0.05, -0.2, 0), (0.2, -0.4, 0), (0.35, -0.1, 0), (0.45, 0.0, 0),
              (0.0, 0.0, 1), (0.1, -0.3, 2), (0.0, -0.005, 3)]
    for lift, knee_q, k in states:
        q = dict(f["q"])
        q["leg1_hip"] += lift
        q["leg1_knee"] += knee_q
        if k:
            shift = ((lane["leg2"][k] - lane["leg2"][0]) * t_hat
                     + (height["leg2"][k] - height["leg2"][0] + 0.001) * n_hat)
            q["hip_x"] += shift[0]
            q["hip_y"] += shift[1]
        x = np.zeros(len(w.state_names()))
        x[:6] = (q["hip_x"], q["hip_y"], q["leg1_hip"], q["leg1_hip"] + q["leg1_knee"],
                 q["leg2_hip"], q["leg2_hip"] + q["leg2_knee"])
        pen = w.foot_quantities(x[None])
        for g in ("leg1", "leg2"):
            centre_h = _centre_height(f, q, g)
            centre = _centre(f, q, g)
            assert float(centre @ n_hat) == pytest.approx(centre_h, abs=1e-12)
            mine = contact_height(centre, r_foot, f["offset"], tops[g], width / 2, t_hat,
                                  n_hat)
            ref = -float(pen[g]["penetration"][0])
            assert mine == pytest.approx(ref, abs=1e-12), (lift, g)
            on = bool(pen[g]["on_ground"][0] > 0.5)
            seen.add((g, on))
            if k and g == "leg2":  # above its tread, 2 k risers below the slope line
                assert mine == pytest.approx(0.001, abs=1e-9)
    assert {("leg2", True), ("leg1", False)} <= seen


def _centre(f: dict, q: dict, leg: str) -> np.ndarray:
    """The foot sphere's centre (x, y) [m] (:func:`_centre_height`'s kinematics)."""
    p = np.array([q["hip_x"], q["hip_y"]])
    thigh = q[f"{leg}_hip"]
    body, along = f["sphere"][leg]
    psi = thigh
    if body.endswith("_shank"):
        p = p - f["knee_at"][leg] * np.array([math.sin(thigh), -math.cos(thigh)])
        psi = thigh + q[f"{leg}_knee"]
    return p - along * np.array([math.sin(psi), -math.cos(psi)])


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("opensim") is None,
                    reason="opensim (the osim extra) not installed")
def test_kneed_walker_with_arc_feet_walks_ten_steps_in_opensim(tmp_path):
    """The issue's walker (configs/kneed.yaml with 50 mm arc feet), exported and walked in
    OpenSim from its default state (the rigid gait's heel strike) for 11.5 rigid periods:
    no fall, >= 11 alternating heel strikes, mean step period after the first within 3 % of
    the rigid gait's (measured: 0.5495 s against 0.54259 s, +1.3 %; the first two steps
    0.556 and 0.569 s while the compliant contact settles) and speed within 5 % (measured
    -2.8 %).  Before the latch read the contact point it fell at 0.34-0.43 s."""
    from walkerlab.export.opensim_walk import walk  # OpenSim in a child process

    text = _file(_kneed({"kind": "arc", "radius_m": 0.05}), tmp_path)
    path = next(Path(tmp_path).rglob("*.osim"))
    period = float(re.search(r"step period (\S+) s", text).group(1))
    speed = float(re.search(r"speed (\S+) m/s along", text).group(1))
    w = walk(path, 11.5 * period)
    assert not w.fell and w.alternating and len(w.times_s) >= 11
    assert w.step_periods_s[1:].mean() == pytest.approx(period, rel=0.03)
    assert w.speed_m_per_s() == pytest.approx(speed, rel=0.05)
