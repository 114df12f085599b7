"""The Adams dataset of arc feet, flat feet (with the ankle push-off) and a bisecting torso
(issue 48 items 1 and 5: refused before, "arc feet are not exported to ADAMS yet", "flat
feet ...", "an upper body is not exported to ADAMS yet").

Read back with walkerlab's reader (:mod:`walkerlab.export.adams_reader`) against the scene:
masses, inertias, spring constants, geometry and the start; the ankle push-off's FUNCTIONs
evaluated by the evaluator of ``tests/test_export_adams_actuation.py`` against walkerlab's
own law (:class:`walkerlab.models.hybrid.ankle_push_off.AnklePushOffActuator`).  Tolerances:
numbers are written as their shortest repr in mm, kg, degrees, so they come back within a
few ulp (1e-12 relative, 1e-9 mm on positions of ~1e3 mm).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.test_export_adams_actuation import AdamsState, evaluate
from walkerlab.config import load_scene
from walkerlab.export.adams import COUPLER_ID, PIN_JOINT
from walkerlab.export.adams_actuation import ACT_VARIABLES, ANKLE_SFORCE, ANKLE_VARIABLES
from walkerlab.export.adams_feet import ANKLE_JOINT, ANKLE_SPRING, FOOT_FORCES, part_ids
from walkerlab.export.adams_reader import read_adm
from walkerlab.export.adams_statements import LINE_WIDTH, marker_id
from walkerlab.models.contact.rigid_limit import contact_si
from walkerlab.models.hybrid.ankle_push_off import AnklePushOffActuator
from walkerlab.stages import export as export_stage
from walkerlab.walker.description import walker_data
from walkerlab.walker.multibody import multibody
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
MM = 1000.0


def _export(scene, tmp_path_factory, name):
    path = export_stage.run(scene, tmp_path_factory.mktemp(f"adm_{name}"), "adm")
    data = walker_data(scene.walker, scene.slope.phi_rad)
    adm = path.read_text()
    assert all(len(ln) <= LINE_WIDTH for ln in adm.splitlines() if "IMPACT(" not in ln)
    return scene, multibody(data), data, read_adm(adm), adm


def _height(model, mid, phi):
    """A marker's height above the ground line along its normal [m]."""
    p = model.marker_pose(mid)[0]
    return float(p[0] * math.sin(phi) + p[1] * math.cos(phi))


def _contact_law_as_scene(model, scene):
    c, _ = contact_si(scene.contact)
    for cid in model.by_kind["CONTACT"]:
        got = model.contact_si(cid)
        assert got["k"] == pytest.approx(c.k, rel=1e-12) and got["e"] == c.e
        assert got["mu_s"] == c.mu_s and got["mu_d"] == c.mu_d
        assert got["cmax"] == pytest.approx(c.cmax, rel=1e-12)


@pytest.fixture(scope="module")
def arc(tmp_path_factory):
    return _export(load_scene(ROOT / "configs" / "round_feet.yaml"), tmp_path_factory, "arc")


@pytest.fixture(scope="module")
def flat(tmp_path_factory):
    return _export(load_scene(ROOT / "configs" / "flat_feet.yaml"), tmp_path_factory, "flat")


@pytest.fixture(scope="module")
def flat_push(tmp_path_factory):
    return _export(load_scene(ROOT / "configs" / "flat_feet_push_off.yaml"),
                   tmp_path_factory, "flat_push")


def test_arc_feet_are_spheres_of_radius_R_touching_the_ground(arc):
    """configs/round_feet.yaml (R = 0.2 m): each foot a sphere of diameter 2 R on the arc's
    centre (L - R = 0.8 m down the leg), the patches' top face on the ground line (no point
    foot's bevel offset), leg2's sphere touching the ground at the origin (its lowest point,
    where the contact view's rolling contact point is) and the stance pin at its centre;
    CONTACTs of each sphere against its lane's patches with the scene's contact law."""
    scene, mb, _data, model, _adm = arc
    R, phi = mb.foot_radius_m, scene.slope.phi_rad
    assert R == 0.2
    ids = part_ids(mb)
    for leg in ("leg1", "leg2"):
        foot = marker_id(ids[leg], "foot")
        g = model.get("GRAPHICS", foot)
        assert "ELLIPSOID" in g.flags and g.integer("CM") == foot
        assert all(g.number(k) == 2 * R * MM for k in ("XSCALE", "YSCALE", "ZSCALE"))
        qp = model.get("MARKER", foot).numbers("QP")
        assert qp[:2] == (0.0, -(mb.leg_length_m - R) * MM)
        assert {c.integer("JGEOM") for c in model.by_kind["CONTACT"].values()
                if c.integer("IGEOM") == foot}  # its lane's patches
    foot2 = marker_id(ids["leg2"], "foot")
    centre = model.marker_pose(foot2)[0]
    n = np.array([math.sin(phi), math.cos(phi), 0.0])
    lowest = centre - R * n
    assert np.allclose(lowest[:2], 0.0, atol=1e-12)  # the contact point at the origin
    pin = model.joints()[PIN_JOINT]
    assert pin[1] == foot2
    assert np.allclose(model.marker_pose(pin[2])[0], centre, atol=1e-12)
    for mid in (m for m in model.by_kind["MARKER"] if m > 1000):  # top faces at height 0
        o, rot = model.marker_pose(mid)
        top = o + rot @ np.array([0.0, model.get("GRAPHICS", mid).number("Y") / MM, 0.0])
        assert top[:2] @ n[:2] == pytest.approx(0.0, abs=1e-12)
    _contact_law_as_scene(model, scene)


def test_flat_feet_parts_springs_and_contacts_read_back(flat):
    """configs/flat_feet.yaml: a foot PART per leg with the contact model's 0.01 kg
    and 5e-5 kg m^2 at the ankle; an ankle REVOLUTE whose markers coincide at the start; the
    ankle spring as a rotational SPRINGDAMPER (120 N m/rad, 3 N m s/rad, rest 0) from the
    foot (I) to the leg (J); heel and toe spheres 0.05 m behind and 0.10 m ahead of the
    ankle along the sole; at the start (the rigid heel strike's double support, the MJCF
    keyframe) leg2's heel at the origin, leg1's toe on the ground and not moving; CONTACTs
    of both spheres of each foot with the scene's law."""
    scene, mb, _data, model, _adm = flat
    ids = part_ids(mb)
    phi = scene.slope.phi_rad
    joints = model.joints()
    for k, leg in enumerate(("leg1", "leg2")):
        p = ids[f"{leg}_foot"]
        assert model.part_mass(p) == 0.01
        assert model.part_inertia(p)[2, 2] == pytest.approx(5e-5, rel=1e-12)
        kind, i, j = joints[ANKLE_JOINT + k]
        assert (kind, i, j) == ("REVOLUTE", marker_id(p, "joint"), marker_id(ids[leg], "foot"))
        assert np.allclose(model.marker_pose(i)[0], model.marker_pose(j)[0], atol=1e-12)
        sd = model.get("SPRINGDAMPER", ANKLE_SPRING + k)
        assert (sd.integer("I"), sd.integer("J")) == (i, j) and "ROTATIONAL" in sd.flags
        assert (sd.number("KT"), sd.number("CT"), sd.number("ANGLE")) == (120e3, 3e3, 0.0)
        o, rot = model.part_pose(p)
        for role, along in (("foot", -0.05), ("toe", 0.10)):
            m = marker_id(p, role)
            assert np.allclose(model.marker_pose(m)[0], o + along * rot[:, 0], atol=1e-12)
            assert model.get("GRAPHICS", m).number("XSCALE") == 2 * mb.leg_length_m
            assert any(c.integer("IGEOM") == m for c in model.by_kind["CONTACT"].values())
    heel2, toe1 = marker_id(ids["leg2_foot"], "foot"), marker_id(ids["leg1_foot"], "toe")
    assert np.allclose(model.marker_pose(heel2)[0][:2], 0.0, atol=1e-12)
    assert joints[PIN_JOINT][1] == heel2
    assert _height(model, toe1, phi) == pytest.approx(0.0, abs=1e-12)
    assert _height(model, marker_id(ids["leg2_foot"], "toe"), phi) > 0.02  # heel contact
    v, w = model.part_velocity(ids["leg1_foot"])  # the trailing toe pinned: at rest
    r = model.marker_pose(toe1)[0] - model.marker_pose(marker_id(ids["leg1_foot"], "cm"))[0]
    assert np.allclose(v + np.cross(w, r), 0.0, atol=1e-9)
    _contact_law_as_scene(model, scene)


def _ankle_states(mb, rng, n=36):
    """States (leg angles, ankle angles, heel and toe normal forces) covering stance leg1 /
    leg2, heel loaded or not, toe loaded or not."""
    ids = part_ids(mb)
    out = []
    for k in range(n):
        psi = {"leg1": rng.uniform(-0.4, 0.4), "leg2": rng.uniform(-0.4, 0.4)}
        w = {"leg1": rng.uniform(-2, 2), "leg2": rng.uniform(-2, 2)}
        a = {"leg1": rng.uniform(-0.5, 0.3), "leg2": rng.uniform(-0.5, 0.3)}
        stance = ("leg1", "leg2")[k % 2]
        heel_on, toe_on = (k // 2) % 3 == 0, (k // 6) % 2 == 0
        forces = {"heel": 300.0 if heel_on else 0.0, "toe": 200.0 if toe_on else 0.0}
        st = AdamsState(mb, (10.0, 950.0), (600.0, -30.0), psi, w, {})
        for leg in ("leg1", "leg2"):
            st.part[ids[f"{leg}_foot"]] = (psi[leg] + a[leg], 0.0)
        out.append((st, stance, a, forces, (heel_on, toe_on)))
    return out


def test_ankle_push_off_function_equals_walkerlab_law(flat_push, tmp_path_factory):
    """SFORCE/15, 16 (I the foot, J the leg: a torque on the ankle angle) evaluated at 36
    states: walkerlab's AnklePushOffActuator torque [N m x 1000] on the stance ankle while
    its heel carries no normal force and its toe does, 0 otherwise and on the swing ankle;
    the scene's constant 25 N m and a released spring (80 N m/rad about -0.2 rad plus
    5 N m) alike."""
    scene0, mb, _data, model0, _adm = flat_push
    raw = yaml.safe_load((ROOT / "configs" / "flat_feet_push_off.yaml").read_text())
    raw["walker"]["actuation"]["ankle_push_off"] = {
        "stiffness_n_m_per_rad": 80.0, "rest_angle_rad": -0.2, "constant_n_m": 5.0}
    path = tmp_path_factory.mktemp("spring") / "flat_spring.yaml"
    path.write_text(yaml.safe_dump(raw))
    scene1 = load_scene(path)
    from walkerlab.export.adams import adams_start, adm_text

    start = adams_start(scene0, mb, Plant.from_scene(scene0))
    model1 = read_adm(adm_text(scene1, mb, Plant.from_scene(scene1).on_slope(0.0), "s", "t", start))
    ids = part_ids(mb)
    rng = np.random.default_rng(48)
    on_seen = 0
    for scene, model in ((scene0, model0), (scene1, model1)):
        law = AnklePushOffActuator(scene.walker.actuation, 0)
        v = model.functions()
        heel_cids = {g: [c for c, s in model.by_kind["CONTACT"].items()
                         if s.integer("IGEOM") == marker_id(ids[f"{g}_foot"], "foot")]
                     for g in ("leg1", "leg2")}
        toe_cids = {g: [c for c, s in model.by_kind["CONTACT"].items()
                        if s.integer("IGEOM") == marker_id(ids[f"{g}_foot"], "toe")]
                    for g in ("leg1", "leg2")}
        for st, stance, a, forces, (heel_on, toe_on) in _ankle_states(mb, rng):
            st.forces = {heel_cids[stance][0]: forces["heel"], toe_cids[stance][-1]:
                         forces["toe"]}
            ns = st.namespace(v)
            assert ns["VARVAL"](ACT_VARIABLES["sign"]) == (
                (1.0 if stance == "leg2" else -1.0) if heel_on or toe_on else 1.0)
            for g in ("leg1", "leg2"):
                sf = model.get("SFORCE", ANKLE_SFORCE[g])
                assert "ROTATION" in sf.flags
                assert (sf.integer("I"), sf.integer("J")) == (
                    marker_id(ids[f"{g}_foot"], "joint"), marker_id(ids[g], "foot"))
                assert ns["VARVAL"](ANKLE_VARIABLES[g]["angle"]) == pytest.approx(
                    a[g], abs=1e-12)
                got = evaluate(sf.args["FUNCTION"][0], ns)
                on = g == stance and toe_on and not heel_on
                want = law.torque(a[g]) * MM if on else 0.0
                on_seen += on
                assert math.isclose(got, want, rel_tol=1e-12, abs_tol=1e-9), (g, got, want)
            assert ns["VARVAL"](FOOT_FORCES[stance][0]) == forces["heel"]
    assert on_seen >= 8


def test_bisecting_torso_coupler(tmp_path_factory):
    """configs/torso_bhm.yaml: the torso a PART on a REVOLUTE at the hip (I the torso, J
    the hip part, fixed to leg2), its mass and inertia the scene's, held at the legs' mean
    by ``COUPLER/1, JOINTS = torso, leg1, TYPE = R:R, SCALES = 1, -0.5`` (both revolutes
    measure from leg2: torso - leg2 = (leg1 - leg2) / 2); the start satisfies it."""
    scene, mb, _data, model, adm = _export(load_scene(ROOT / "configs" / "torso_bhm.yaml"),
                                           tmp_path_factory, "torso")
    ids = part_ids(mb)
    torso = next(ln for ln in mb.links if ln.name == "torso")
    assert model.part_mass(ids["torso"]) == torso.mass_kg
    assert model.part_inertia(ids["torso"])[2, 2] == pytest.approx(torso.inertia_kg_m2,
                                                                   abs=1e-15)
    cp = model.get("COUPLER", COUPLER_ID)
    jt, j1 = (int(x) for x in cp.numbers("JOINTS"))
    assert cp.args["TYPE"] == ("R:R",) and cp.numbers("SCALES") == (1.0, -0.5)
    joints = model.joints()
    assert joints[jt][:2] == ("REVOLUTE", marker_id(ids["torso"], "joint"))
    assert joints[j1][:2] == ("REVOLUTE", marker_id(ids["leg1"], "joint"))
    assert joints[jt][2] == joints[j1][2] == marker_id(2, "cm")  # the hip, fixed to leg2

    def angle(p):
        return float(model.get("PART", p).numbers("REULER")[0])
    t, a1, a2 = angle(ids["torso"]), angle(ids["leg1"]), angle(ids["leg2"])
    assert (t - a2) - 0.5 * (a1 - a2) == pytest.approx(0.0, abs=1e-14)
    wt, w1, w2 = (float(model.get("PART", ids[n]).number("WZ")) for n in ("torso", "leg1",
                                                                            "leg2"))
    assert wt == pytest.approx(0.5 * (w1 + w2), abs=1e-14)
    assert "not exported" not in adm


def test_ankle_and_hip_torques_on_flat_feet_equal_walkerlab_laws(flat, tmp_path_factory):
    """Flat feet with a hip PD, a stance-ankle PD about -0.1 rad saturated at 20 N m and a
    swing-ankle spring-damper (refused before: "stance_hip, ... need a five-link biped"):
    SFORCE/17, 18 on each ankle (I foot, J leg) evaluated at 24 states equal walkerlab's
    laws (:meth:`TorqueLaws.each` on the role ankles' angles, the roles from the feet's
    contact forces); the hip SFORCE/10 the hip law's."""
    from walkerlab.export.adams import adams_start, adm_text
    from walkerlab.export.adams_actuation import ANKLE_TORQUE_SFORCE, HIP_SFORCE
    from walkerlab.models.actuation import TorqueLaws

    scene0, mb, data0, _model, _adm = flat
    raw = yaml.safe_load((ROOT / "configs" / "flat_feet.yaml").read_text())
    raw["walker"]["actuation"] = {"torques": [
        {"joint": "hip", "law": {"stiffness_n_m_per_rad": 10.0, "damping_n_m_s_per_rad": 1.0,
                                 "rest_angle_rad": 0.3}},
        {"joint": "stance_ankle", "max_torque_n_m": 20.0,
         "law": {"stiffness_n_m_per_rad": 60.0, "damping_n_m_s_per_rad": 2.0,
                 "rest_angle_rad": -0.1, "constant_n_m": -3.0}},
        {"joint": "swing_ankle", "law": {"stiffness_n_m_per_rad": 15.0,
                                         "damping_n_m_s_per_rad": 0.5}}]}
    path = tmp_path_factory.mktemp("ankle_t") / "flat_torques.yaml"
    path.write_text(yaml.safe_dump(raw))
    scene = load_scene(path)
    start = adams_start(scene0, mb, Plant.from_scene(scene0))
    model = read_adm(adm_text(scene, mb, Plant.from_scene(scene),
                              "t", "t", start))
    v = model.functions()
    ids = part_ids(mb)
    laws = TorqueLaws(scene.walker.actuation.torques)
    rng = np.random.default_rng(7)
    cid = {g: next(c for c, s in model.by_kind["CONTACT"].items()
                   if s.integer("IGEOM") == marker_id(ids[f"{g}_foot"], "toe"))
           for g in ("leg1", "leg2")}
    saturated = 0
    for n in range(24):
        psi = {g: rng.uniform(-0.4, 0.4) for g in ("leg1", "leg2")}
        w = {g: rng.uniform(-2, 2) for g in ("leg1", "leg2")}
        a = {g: rng.uniform(-0.6, 0.4) for g in ("leg1", "leg2")}
        da = {g: rng.uniform(-3, 3) for g in ("leg1", "leg2")}
        stance = ("leg1", "leg2")[n % 2]
        swing = "leg2" if stance == "leg1" else "leg1"
        st = AdamsState(mb, (10.0, 950.0), (600.0, -30.0), psi, w, {cid[stance]: 250.0})
        for g in ("leg1", "leg2"):
            st.part[ids[f"{g}_foot"]] = (psi[g] + a[g], w[g] + da[g])
        ns = st.namespace(v)
        deltas = [psi[swing] - psi[stance], a[stance], a[swing]]
        rates = [w[swing] - w[stance], da[stance], da[swing]]
        each = laws.each(deltas, rates, psi[stance], w[stance]) * MM
        saturated += abs(each[1]) == 20.0 * MM
        for g in ("leg1", "leg2"):
            sf = model.get("SFORCE", ANKLE_TORQUE_SFORCE[g])
            assert (sf.integer("I"), sf.integer("J")) == (
                marker_id(ids[f"{g}_foot"], "joint"), marker_id(ids[g], "foot"))
            want = each[1] if g == stance else each[2]
            got = evaluate(sf.args["FUNCTION"][0], ns)
            assert math.isclose(got, want, rel_tol=1e-12, abs_tol=1e-9), (g, got, want)
        hip = evaluate(model.get("SFORCE", HIP_SFORCE).args["FUNCTION"][0], ns)
        assert math.isclose(hip, each[0] * (1.0 if swing == "leg1" else -1.0), rel_tol=1e-12,
                            abs_tol=1e-9)
    assert 0 < saturated < 24


@pytest.mark.parametrize("name", ["stairs", "footholds"])
def test_the_adams_patches_stand_at_the_footholds_heights(name, tmp_path):
    """Issue 49's "the ADAMS dataset's patches at the footholds" (before: refused): the
    checkerboard's boxes of configs/stairs.yaml (1 cm risers) and configs/footholds.yaml
    (each footfall 5 mm lower) read back with their top faces at the footholds' heights,
    footfall k at -k drop cos(phi) along the slope normal (leg2's lane: k = 0, 2, ...;
    leg1's: -1, 1, 3, ...), the point foot's sphere radius below."""
    from walkerlab.export.mjcf_scene import point_foot_radius

    sc = load_scene(ROOT / "configs" / f"{name}.yaml")
    path = export_stage.run(sc, tmp_path, "adm")
    model = read_adm(path.read_text())
    mb = multibody(walker_data(sc.walker, sc.slope.phi_rad))
    phi = sc.slope.phi_rad
    n_hat = np.array([math.sin(phi), math.cos(phi)])
    drop = (sc.terrain.riser_m if name == "stairs" else -sc.terrain.foothold_heights_m[0]) \
        * math.cos(phi)
    boxes = {g.integer("CORNER"): g for g in model.by_kind["GRAPHICS"].values()
             if "BOX" in g.flags}
    tops = []
    for mid, g in sorted(boxes.items()):
        corner, _ = model.marker_pose(mid)  # [m]
        tops.append(float(corner[:2] @ n_hat) + g.number("Y") / 1000.0)
    half = len(tops) // 2  # leg1's lane, then leg2's
    k1 = np.arange(half) * 2 - 1
    k2 = np.arange(len(tops) - half) * 2
    want = np.concatenate([-k1 * drop, -k2 * drop]) - point_foot_radius(mb)
    assert np.allclose(tops, want, atol=1e-9)
    # continuous stairs: tests/test_export_adams_feet.py::
    # test_the_adams_ground_line_is_a_patch_per_segment_of_the_scenes_ground (issue 58)


def test_the_adams_patches_of_two_foothold_heights_stand_at_each_footholds_height(tmp_path):
    """Issue 58's "Adams: footholds of several heights" (before: refused by the table):
    configs/footholds_two.yaml's boxes (the paper walker, landings 4 mm and 6 mm below the
    stance foot in turn) read back with their top faces at the footholds' heights, footfall
    k at ``-(h_0 + ... + h_{k-1}) cos(phi)`` along the slope normal from the scene's list
    alone (leg2's lane: k = 0, 2, ...; leg1's: -1, 1, 3, ..., footfall -1 the last step's
    height above footfall 0), the point foot's sphere radius below; along the slope the
    footfalls alternate the rigid period-2 gait's two step lengths (0.4449 and 0.4325 m,
    the file's comments; to 1e-9 m, the same step each other time)."""
    from walkerlab.export.mjcf_scene import point_foot_radius

    sc = load_scene(ROOT / "configs" / "footholds_two.yaml")
    path = export_stage.run(sc, tmp_path, "adm")
    model = read_adm(path.read_text())
    mb = multibody(walker_data(sc.walker, sc.slope.phi_rad))
    phi = sc.slope.phi_rad
    n_hat = np.array([math.sin(phi), math.cos(phi)])
    t_hat = np.array([math.cos(phi), -math.sin(phi)])
    h = sc.terrain.foothold_heights_m

    def height(k):  # footfall k's height along the normal [m], footfall 0 at 0
        if k < 0:
            return -h[(k) % len(h)] * math.cos(phi)
        return sum(h[j % len(h)] for j in range(k)) * math.cos(phi)

    boxes = {g.integer("CORNER"): g for g in model.by_kind["GRAPHICS"].values()
             if "BOX" in g.flags}
    tops, starts = [], []
    for mid, g in sorted(boxes.items()):
        corner, _ = model.marker_pose(mid)  # [m]
        tops.append(float(corner[:2] @ n_hat) + g.number("Y") / 1000.0)
        starts.append(float(corner[:2] @ t_hat))
    half = len(tops) // 2  # leg1's lane, then leg2's
    ks = [*(2 * i - 1 for i in range(half)), *(2 * i for i in range(len(tops) - half))]
    want = np.array([height(k) for k in ks]) - point_foot_radius(mb)
    assert len(tops) >= 8 and np.allclose(tops, want, atol=1e-9)
    s = np.array(starts)[np.argsort(ks)]  # in walking order: footfall -1, 0, 1, ...
    steps = np.diff(s)
    assert np.allclose(steps[2::2], steps[0], atol=1e-9)
    assert np.allclose(steps[3::2], steps[1], atol=1e-9)
    assert sorted(np.round(steps[:2], 4)) == [0.4325, 0.4449]


def _box_top(model, mid, box):
    """The two ends [m] (x, y) of a GRAPHICS BOX's top face (its CORNER marker's x axis
    along the box, y across it: the face ``Y`` above the corner)."""
    origin, rot = model.marker_pose(mid)
    up = rot @ np.array([0.0, box.number("Y") / 1000.0, 0.0])
    along = rot @ np.array([box.number("X") / 1000.0, 0.0, 0.0])
    return (origin + up)[:2], (origin + up + along)[:2], rot[:2, 1]


@pytest.mark.parametrize("name", ["profile", "stairs"])
def test_the_adams_ground_line_is_a_patch_per_segment_of_the_scenes_ground(name, tmp_path):
    """Issue 58's "Adams: ... profiles" (before: "the Adams dataset carries the ground as
    patches ..., not continuous profile"): configs/profile.yaml (the kneed walker on its
    ramp with a 1 mm undulation) and configs/stairs.yaml on continuous ground are written
    as a box per segment of the ground's polyline, each box's top face, raised by the
    point foot's sphere radius along its normal, running from one vertex of the scene's
    ground to the next (the profile's own ``profile_m`` rows moved to leg2's foot at the
    origin; the stairs' treads ``tread_m`` deep and ``riser_m`` apart, level, the first
    stance foot mid-tread 0), to 1e-9 m; each foot has a CONTACT with every box."""
    from walkerlab.api.scenes import with_changes
    from walkerlab.export.mjcf_scene import point_foot_radius

    sc = load_scene(ROOT / "configs" / f"{name}.yaml")
    if name == "stairs":
        sc = with_changes(sc, {"terrain.lanes": "continuous"})
    model = read_adm(export_stage.run(sc, tmp_path, "adm").read_text())
    r = point_foot_radius(multibody(walker_data(sc.walker, sc.slope.phi_rad)))
    boxes = sorted((g.integer("CORNER"), g) for g in model.by_kind["GRAPHICS"].values()
                   if "BOX" in g.flags)
    ends = []
    for mid, g in boxes:
        a, b, nrm = _box_top(model, mid, g)
        ends.append((a + r * nrm, b + r * nrm))
    if name == "profile":
        P = np.asarray(sc.terrain.profile_m, float)
        want = P - P[0]
        inner = ends[1:1 + len(want) - 1]  # the first and last boxes run on for 100 m
        assert len(ends) == len(want) + 1
        for (a, b), p, q in zip(inner, want[:-1], want[1:]):
            assert np.allclose(a, p, atol=1e-9) and np.allclose(b, q, atol=1e-9)
    else:
        D, H = sc.terrain.tread_m, sc.terrain.riser_m
        treads = [(a, b) for a, b in ends if abs(a[1] - b[1]) < 1e-12]  # level: treads
        heights = sorted({round(-a[1] / H, 9) for a, _ in treads})
        assert heights == list(range(-3, len(heights) - 3))  # tread k at -k riser
        mid = [(a, b) for a, b in treads if abs(a[1]) < 1e-12][0]  # tread 0
        assert np.allclose([mid[0][0], mid[1][0]], [-D / 2, D / 2], atol=1e-9)
    contacts = [c for c in model.by_kind["CONTACT"].values()]
    assert len(contacts) == 2 * len(boxes)
