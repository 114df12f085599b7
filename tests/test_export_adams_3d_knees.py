"""The kneed walker in 3D (``locking_knees_3d``, configs/kneed_3d.yaml) in its Adams dataset
(:mod:`walkerlab.export.adams_3d`, :mod:`walkerlab.export.adams_3d_knees`), read back by
walkerlab's reader and set against the rigid model at a state.

References the writer does not compute: the masses are the scene's numbers; the parts'
centres of mass, the knees and the feet are the rigid model's generated ``points`` (in the
exports' axes, z up: ``X = x, Y = -z, Z = y``, written out here); the kinetic energy is the
rigid model's ``0.5 dq^T M(q) dq``; the knee angles the state's (``swing_shank -
swing_thigh``; the stance knee straight); the stop's and latch's numbers the contact
model's (:func:`walkerlab.models.contact.rigid_limit.contact_si`); the actuation's hip and
knee torques the laws ``constant - K (angle - rest) - D rate`` written out here on the
state's thigh pitches and knee angles, its push-off the rigid stance leg's line from foot to
hip (also on the stabilised powered walker, configs/kneed_3d_powered_stabilised.yaml).  The
state is not a gait (the file's statements are functions of the state): no gait search.
Tolerance 1e-9.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from tests.adams_eval import evaluate
from walkerlab.codegen.cache import functions
from walkerlab.config import load_scene
from walkerlab.config.contact import ContactSettings
from walkerlab.export.adams_3d import adams3d_start, adm3d_text
from walkerlab.export.adams_reader import read_adm
from walkerlab.models.contact.rigid_limit import contact_si
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
TOL = 1e-9
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
#: lean, swing thigh, swing shank, stance and their rates (the swing knee bent 0.085 rad)
X = [-0.006, -0.285, -0.37, 0.1868, -0.125, -0.118, -0.5, -0.9]
#: PART id -> (its body, the rigid point of its centre of mass, its mass [kg])
PARTS = {2: ("pelvis", "hip", 0.5), 3: ("leg1", "swing_thigh_mass", 0.5),
         4: ("leg1_shank", "swing_shank_mass", 0.05), 5: ("leg2", "stance_thigh_mass", 0.5),
         6: ("leg2_shank", "stance_shank_mass", 0.05)}


@pytest.fixture(scope="module", params=[False, True], ids=["stop", "latch"])
def kneed(request):
    scene = load_scene(ROOT / "configs" / "kneed_3d.yaml")
    if request.param:   # the contact model's knee latch on
        raw = scene.model_dump(exclude_none=True)
        raw["contact"] = {"knee_stop": {"latch": True}}
        scene = type(scene).model_validate(raw)
    plant = Plant.from_scene(scene)
    data = plant.data
    x = np.asarray(X, float)
    start = adams3d_start(plant, SimpleNamespace(x=x, period_s=1.0, step_lengths_m=(0.3,)), 2)
    return scene, data, x, read_adm(adm3d_text(scene, data, start, "walker"))


def test_a_kneed_3d_datasets_parts_are_the_rigid_walkers(kneed):
    """Five parts (the pelvis, each thigh and shank) of the scene's masses, each centre of
    mass at the rigid one, the kinetic energy the rigid model's (relative 1e-9)."""
    scene, data, x, model = kneed
    pts = {k: C @ np.ravel(v) for k, v in functions(data)["points"](x).items()}
    assert sorted(p for p in model.by_kind["PART"] if p != 1) == sorted(PARTS)
    for pid, (_body, point, mass) in PARTS.items():
        assert model.part_mass(pid) == pytest.approx(mass, rel=1e-15)
        cm, _ = model.marker_pose(model.get("PART", pid).integer("CM"))
        np.testing.assert_allclose(cm, pts[point], atol=TOL)
    n = x.size // 2
    M = np.asarray(functions(data)["matrices"](x)[0], float).reshape(n, n)
    got = 0.0
    for pid in PARTS:
        v, w = model.part_velocity(pid)
        got += 0.5 * model.part_mass(pid) * v @ v + 0.5 * w @ model.part_inertia(pid) @ w
    assert got == pytest.approx(0.5 * x[n:] @ M @ x[n:], rel=TOL)
    assert sum(model.part_mass(p) for p in PARTS) == pytest.approx(data.total_mass_kg,
                                                                   rel=1e-15)


def test_a_kneed_3d_datasets_knees_are_revolutes_at_the_rigid_knees(kneed):
    """Each knee a REVOLUTE (I on the shank, J on the thigh) at the rigid knee point, both
    markers' z along the leg's pitch axis; its AZ the knee angle (swing: shank - thigh;
    stance: 0, straight); the feet (each CONTACT's sphere, the pin's marker on leg2's shank)
    at the rigid feet."""
    scene, data, x, model = kneed
    pts = {k: C @ np.ravel(v) for k, v in functions(data)["points"](x).items()}
    joints = model.joints()
    knees = {402: ("swing_knee", x[2] - x[1]), 602: ("stance_knee", 0.0)}
    for i, (point, angle) in knees.items():
        (kind, j), = [(t, jj) for t, ii, jj in joints.values() if ii == i]
        assert kind == "REVOLUTE"
        (pi, Ri), (pj, Rj) = model.marker_pose(i), model.marker_pose(j)
        np.testing.assert_allclose(pi, pts[point], atol=TOL)
        np.testing.assert_allclose(pj, pts[point], atol=TOL)
        assert Ri[:, 2] @ Rj[:, 2] > 1 - TOL
        got = evaluate(model, (-1,), {-1: f"AZ({i},{j})"})[-1]
        assert got == pytest.approx(angle, abs=TOL)
    feet = {c.integer("IGEOM") for c in model.by_kind["CONTACT"].values()}
    assert feet == {403, 603}
    np.testing.assert_allclose(model.marker_pose(403)[0], pts["swing_foot"], atol=TOL)
    np.testing.assert_allclose(model.marker_pose(603)[0], pts["stance_foot"], atol=TOL)
    assert joints[99][1] == 603


def test_a_kneed_3d_datasets_knee_stop_and_latch_are_the_contact_models(kneed):
    """SFORCE/1, 2: -IMPACT of the hyperextension on each knee with the contact model's
    stop numbers; with contact.knee_stop.latch, SFORCE/3, 4 weighted by the foot's height
    above the slope (the rigid feet's: the stance foot 0, the swing foot its own) and the
    knee's flexion, the swing knee (bent past the capture) not latched at the state."""
    scene, data, x, model = kneed
    _, ks = contact_si(scene.contact or ContactSettings())
    law = f"{ks.k * 1000!r},{ks.e!r},{ks.cmax * 1000!r},{ks.dmax!r}".replace("e-05", "E-05")
    for sid, (i, j) in ((1, (402, 314)), (2, (602, 516))):
        sf = model.get("SFORCE", sid)
        assert (sf.integer("I"), sf.integer("J")) == (i, j)
        assert sf.args["FUNCTION"] == (f"-IMPACT(-AZ({i},{j}),-WZ({i},{j},{j}),0.0,{law})",)
    if not ks.latch:
        assert sorted(model.by_kind["SFORCE"]) == [1, 2]
        return
    assert sorted(model.by_kind["SFORCE"]) == [1, 2, 3, 4]
    pts = {k: C @ np.ravel(v) for k, v in functions(data)["points"](x).items()}
    phi = data.slope_rad
    n = np.array([np.sin(phi), 0.0, np.cos(phi)])
    v = evaluate(model, (371, 372, 373, 374))
    assert v[371] / 1000 == pytest.approx(n @ pts["swing_foot"], rel=TOL)
    assert v[372] == pytest.approx(0.0, abs=1e-9)
    assert v[373] == 0.0   # the swing knee bent 0.085 rad, past the 0.01 rad capture
    assert v[374] == 1.0   # the stance foot on the ground, its knee straight


# --- the actuation on knees (walkerlab.export.adams_3d_actuation) ------------------------

#: laws under test at the hip, the swing knee and the stance knee (every term nonzero)
LAWS = {"hip": {"constant_n_m": 0.03, "stiffness_n_m_per_rad": 0.5,
                "damping_n_m_s_per_rad": 0.07, "rest_angle_rad": 0.05},
        "swing_knee": {"constant_n_m": -0.02, "stiffness_n_m_per_rad": 0.3,
                       "damping_n_m_s_per_rad": 0.04, "rest_angle_rad": -0.1},
        "stance_knee": {"constant_n_m": 0.01, "stiffness_n_m_per_rad": 0.2,
                        "damping_n_m_s_per_rad": 0.03, "rest_angle_rad": 0.02}}
#: the stabilised walker's state (lean, swing thigh, swing shank, stance, pelvis roll, swing
#: roll, then the rates): its gait with the swing knee bent 0.09 rad at -0.4 rad/s
X_ROLLED = [0.0286, -0.2826, -0.3726, 0.1886, -0.0088, -0.0473,
            -0.2724, -0.3836, -0.7836, -1.1826, 1.4023, -0.2526]


def _law(law, angle, rate):
    """``constant - K (angle - rest) - D rate`` [N m] (walkerlab.config.actuation)."""
    return (law["constant_n_m"] - law["stiffness_n_m_per_rad"] * (angle - law["rest_angle_rad"])
            - law["damping_n_m_s_per_rad"] * rate)


@pytest.fixture(scope="module", params=[
    "kneed_3d", pytest.param("kneed_3d_powered_stabilised", marks=pytest.mark.slow)])
def powered(request):
    """The scene's walker with :data:`LAWS` and a push-off, its dataset at a state with the
    swing knee bent (the stabilised walker: ~3 min cold, its derivation with hip-roll
    joints)."""
    scene = load_scene(ROOT / "configs" / f"{request.param}.yaml")
    raw = scene.model_dump(exclude_none=True)
    raw["walker"]["actuation"] = {
        "torques": [{"joint": j, "law": law} for j, law in LAWS.items()],
        "push_off": {"impulse_n_s": 0.02}}
    scene = type(scene).model_validate(raw)
    plant = Plant.from_scene(scene)
    data = plant.data
    x = np.asarray(X_ROLLED if data.structure.hip_roll else X, float)
    start = adams3d_start(plant, SimpleNamespace(x=x, period_s=1.0, step_lengths_m=(0.3,)), 2)
    return scene, data, x, read_adm(adm3d_text(scene, data, start, "walker"))


def test_a_kneed_3d_datasets_knee_and_hip_torques_are_the_rigid_laws(powered):
    """Leg1 swings at the start: the legs' pitches are the thighs' (the rigid swing thigh
    and stance pitches and rates), the hip law (alone in VARIABLE/9099) is on swing thigh -
    stance, the swing knee's law on the state's knee angle ``swing_shank - swing_thigh`` and
    rate, the stance knee's on its straight knee (0, 0); SFORCE/13 on leg1's knee revolute
    (I on the shank, J on the thigh) carries the swing law, SFORCE/14 on leg2's the stance
    law [N mm]."""
    _scene, data, x, model = powered
    n = x.size // 2
    s = dict(zip(data.structure.roles, zip(x[:n], x[n:])))
    (th, dth), (sh, dsh), (st, dst) = s["swing_thigh"], s["swing_shank"], s["stance"]
    v = evaluate(model, (303, 611, 612, 613, 614, 621, 622, 623, 624, 9099, 9103, 9104))
    assert v[303] == 1
    for k, want in ((611, th), (612, st), (613, dth), (614, dst)):
        assert v[k] == pytest.approx(want, rel=TOL, abs=1e-12), k
    assert (v[621], v[622]) == pytest.approx((0.0, 0.0), abs=TOL)
    assert (v[623], v[624]) == pytest.approx((sh - th, dsh - dth), rel=TOL, abs=1e-12)
    assert v[9099] / 1000 == pytest.approx(_law(LAWS["hip"], th - st, dth - dst), rel=TOL)
    assert v[9104] / 1000 == pytest.approx(_law(LAWS["swing_knee"], sh - th, dsh - dth),
                                           rel=TOL)
    assert v[9103] / 1000 == pytest.approx(_law(LAWS["stance_knee"], 0.0, 0.0), rel=TOL,
                                           abs=1e-12)
    for sid, (i, j), total in ((13, (402, 314), 9104), (14, (602, 516), 9103)):
        sf = model.get("SFORCE", sid)
        assert "ROTATION" in sf.flags and (sf.integer("I"), sf.integer("J")) == (i, j)
        got = evaluate(model, (-1,), {-1: sf.args["FUNCTION"][0]})[-1]
        assert got == pytest.approx(v[total], rel=1e-15)


def test_a_kneed_3d_datasets_push_off_acts_at_the_shanks_foot_towards_its_hip(powered):
    """The push-off's GFORCE at the stance leg's foot (on its shank, marker 603) points
    along the rigid stance leg from its foot to its own hip; each foot's penetration is
    minus its rigid height above the slope."""
    _scene, data, x, model = powered
    pts = {k: C @ np.ravel(p) for k, p in functions(data)["points"](x).items()}
    phi = data.slope_rad
    nrm = np.array([np.sin(phi), 0.0, np.cos(phi)])
    v = evaluate(model, (641, 642))
    assert v[641] / 1000 == pytest.approx(-(nrm @ pts["swing_foot"]), rel=TOL, abs=1e-12)
    assert v[642] / 1000 == pytest.approx(0.0, abs=1e-12)
    g = model.gforce(2)
    assert (g["I"], g["RM"]) == ("603", "101")
    want = pts["stance_hip"] - pts["stance_foot"]
    got = [evaluate(model, (-1,), {-1: g[k].replace("VARVAL(662)*", "")})[-1]
           for k in ("FX", "FY", "FZ")]
    np.testing.assert_allclose(got, want / np.linalg.norm(want), atol=TOL)
