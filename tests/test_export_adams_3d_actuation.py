"""The actuation of a 3D walker's Adams dataset (:mod:`walkerlab.export.adams_3d_actuation`):
the file read back by walkerlab's reader (:mod:`walkerlab.export.adams_reader`), its
``VARIABLE`` expressions evaluated on its own start (the parts' poses and velocities as the
reader gives them, Adams Solver function semantics written out here) and set against the
rigid model at the same state: its leg pitches and rates (the state's coordinates), the hip
torque law ``constant - K (delta - rest) - D ddelta`` of :class:`walkerlab.config.actuation.
JointTorque` evaluated here by hand, the push-off's foot heights and direction (the rigid
model's generated ``points``).

The state is not a gait: the statements are a function of the state, so any state checks
them (no gait search; a lean, rolls and rates all nonzero so that no term vanishes).
Tolerance 1e-9: the file writes 17 significant digits, positions in mm and angles in
degrees, so an angle comes back within ~1e-14 rad and a length within ~1e-12 m.
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from tests.adams_eval import evaluate as _evaluate
from tests.adams_eval import evaluate_expr as _evaluate_expr
from walkerlab.codegen.cache import functions
from walkerlab.config import Scene, load_scene
from walkerlab.config.contact import ContactSettings
from walkerlab.export.adams_3d import adams3d_start, adm3d_text
from walkerlab.export.adams_reader import read_adm
from walkerlab.walker.description import state_names
from walkerlab.walker.plant import Plant
from walkerlab.walker.reference_cases import reference_scene

ROOT = Path(__file__).resolve().parents[1]
TOL = 1e-9
#: walkerlab's world in the dataset's axes (x downhill, z up)
C = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
#: the law under test (every term nonzero)
LAW = {"constant_n_m": 0.3, "stiffness_n_m_per_rad": 5.0, "damping_n_m_s_per_rad": 0.7,
       "rest_angle_rad": 0.05}
#: states by scene (roles: lean, swing, stance[, pelvis_roll, swing_roll], then the rates)
STATES = {"paper_3d": [0.02, -0.2, 0.17, -0.1, -0.6, -0.84],
          "hip_width_powered": [0.0128, -0.2037, 0.175, -0.0105, -0.0193, -0.234, -0.7197,
                                -0.9329, 0.699, -0.2575]}


def _scene(name):
    scene = load_scene(ROOT / "configs" / f"{name}.yaml")
    act = {"torques": [{"joint": "hip", "law": LAW}], "push_off": {"impulse_n_s": 1.0}}
    w = scene.walker.model_dump(exclude_none=True)
    w["actuation"] = act
    raw = scene.model_dump(exclude_none=True)
    raw["walker"] = w
    return type(scene).model_validate(raw)


@pytest.fixture(scope="module", params=["paper_3d", "hip_width_powered"])
def case(request):
    scene = _scene(request.param)
    plant = Plant.from_scene(scene)
    data = plant.data
    x = np.asarray(STATES[request.param], float)
    ideal = SimpleNamespace(x=x, period_s=1.0, step_lengths_m=(0.4,))
    start = adams3d_start(plant, ideal, 2)
    text = adm3d_text(scene, data, start, "walker")
    return scene, data, x, read_adm(text), text


def test_a_3d_datasets_leg_pitches_and_hip_torque_are_the_rigid_models(case):
    """Each leg's pitch and rate read from the file's markers are the rigid state's (leg1
    swings at the start, leg2 stands), the law's angle is swing - stance and its torque
    [N mm] the law ``c - K (delta - rest) - D ddelta`` at the state."""
    _scene_, data, x, model, _text = case
    s = dict(zip(state_names(data.structure.roles), x))
    v = _evaluate(model, (611, 612, 613, 614, 303, 304, 305, 306, 307, 9099))
    assert v[303] == 1  # a tie of the feet's forces: leg2 stands
    for n, want in ((611, s["swing_angle"]), (612, s["stance_angle"]),
                    (613, s["swing_rate"]), (614, s["stance_rate"])):
        assert v[n] == pytest.approx(want, rel=TOL, abs=1e-12), n
    delta = s["swing_angle"] - s["stance_angle"]
    ddelta = s["swing_rate"] - s["stance_rate"]
    assert v[304] == pytest.approx(delta, rel=TOL)
    assert v[305] == pytest.approx(ddelta, rel=TOL)
    assert (v[306], v[307]) == pytest.approx((s["stance_angle"], s["stance_rate"]), rel=TOL)
    tau = (LAW["constant_n_m"] - LAW["stiffness_n_m_per_rad"] * (delta - LAW["rest_angle_rad"])
           - LAW["damping_n_m_s_per_rad"] * ddelta)
    assert v[9099] / 1000 == pytest.approx(tau, rel=TOL)


def test_a_3d_datasets_hip_torque_acts_about_each_legs_pitch_axis(case):
    """Without hip-roll joints one SFORCE/ROTATION on leg1's revolute (I on leg1 at the hip,
    J on the pelvis, both z along the one pitch axis), sign x tau; with them a GFORCE per leg
    about its own pitch axis (RM its hip marker, z along the leg's pitch axis Rot(s, roll)
    z), +sign x tau on leg1 and -sign x tau on leg2, the reaction on the pelvis."""
    _scene_, data, x, model, _text = case
    s = dict(zip(state_names(data.structure.roles), x))
    phi = data.slope_rad
    fall = np.array([math.cos(phi), -math.sin(phi), 0.0])
    K = np.array([[0, -fall[2], fall[1]], [fall[2], 0, -fall[0]], [-fall[1], fall[0], 0]])

    def pitch_axis(roll):
        R = np.eye(3) + math.sin(roll) * K + (1 - math.cos(roll)) * K @ K
        return C @ R @ np.array([0.0, 0.0, 1.0])

    if not data.structure.hip_roll:
        sf = model.get("SFORCE", 10)
        assert "ROTATION" in sf.flags and sf.args["FUNCTION"] == ("VARVAL(303)*VARVAL(9099)",)
        zi, zj = (model.marker_pose(sf.integer(k))[1][:, 2] for k in "IJ")
        assert abs(abs(zi @ pitch_axis(s["lean_angle"])) - 1) < TOL and zi @ zj > 1 - TOL
        assert model.get("MARKER", sf.integer("I")).integer("PART") == 3  # leg1
        assert model.get("MARKER", sf.integer("J")).integer("PART") == 2  # the pelvis
        return
    rolls = {"leg1": s["swing_roll_angle"], "leg2": s["lean_angle"]}
    for gid, leg, part, sign in ((41, "leg1", 3, ""), (42, "leg2", 4, "-")):
        g = model.gforce(gid)
        assert g["TZ"] == f"{sign}VARVAL(303)*VARVAL(9099)"
        assert all(g[k] == "0.0" for k in ("FX", "FY", "FZ", "TX", "TY"))
        assert g["I"] == g["RM"] and model.get("MARKER", int(g["I"])).integer("PART") == part
        z = model.marker_pose(int(g["RM"]))[1][:, 2]
        assert abs(abs(z @ pitch_axis(rolls[leg])) - 1) < TOL
        assert model.get("MARKER", int(g["JFLOAT"])).integer("PART") == 2


def test_a_3d_datasets_push_off_reads_the_rigid_feet(case):
    """The feet's penetrations are minus their heights above the slope (the rigid points:
    the stance foot at the origin, the swing foot's), the swing foot's lead along the fall
    line is the rigid one's, the pulse is off at the start, and the stance foot's GFORCE
    points along the rigid stance leg from its foot to its own hip with magnitude P / T."""
    scene, data, x, model, _text = case
    pts = {k: C @ np.ravel(v) for k, v in functions(data)["points"](x).items()}
    phi = data.slope_rad
    n = np.array([math.sin(phi), 0.0, math.cos(phi)])
    t = np.array([math.cos(phi), 0.0, -math.sin(phi)])
    v = _evaluate(model, (641, 642, 647, 661, 662, 633, 632))
    assert v[641] / 1000 == pytest.approx(-(n @ pts["swing_foot"]), rel=TOL, abs=1e-12)
    assert v[642] / 1000 == pytest.approx(-(n @ pts["stance_foot"]), abs=1e-12)
    assert v[647] / 1000 == pytest.approx(t @ (pts["stance_foot"] - pts["swing_foot"]),
                                          rel=TOL)
    assert (v[661], v[662]) == (0.0, 0.0)
    pulse = (scene.contact or ContactSettings()).push_off_pulse_s()
    assert v[633] / v[632] == pytest.approx(1.0 / pulse, rel=1e-15)
    g = model.gforce(2)
    assert g["I"] == "403" and g["RM"] == "101"
    want = pts["stance_hip"] - pts["stance_foot"]
    want = want / np.linalg.norm(want)
    got = []
    for k in ("FX", "FY", "FZ"):
        e = g[k].replace("VARVAL(662)*", "")
        got.append(_evaluate_expr(model, e))
    np.testing.assert_allclose(got, want, atol=TOL)


#: a torque between the upper body and a leg (every term nonzero)
TORSO_LAW = {"constant_n_m": 0.3, "stiffness_n_m_per_rad": 5.0, "damping_n_m_s_per_rad": 0.7,
             "rest_angle_rad": 0.05}
#: the kneed walker with an upper body and no hip-roll joints: the capability table's Adams
#: case (walkerlab.walker.reference_cases.VIEW_CASES), at a state off its gait
KNEED_TORSO_STATE = [0.01, -0.3, -0.42, 0.22, -0.12, -0.35, 0.4, -1.05]


def _torso_case(name: str, joint: str):
    if name == "kneed":
        raw = reference_scene("locking_knees_3d", "torso_torque", "adams")[1]
        raw.pop("name")
        x = KNEED_TORSO_STATE
    else:
        raw = load_scene(ROOT / "configs" / f"{name}.yaml").model_dump(exclude_none=True)
        x = STATES["paper_3d"]
    raw["walker"]["actuation"] = {"torques": [{"joint": joint, "law": TORSO_LAW}]}
    return Scene.model_validate(raw), np.asarray(x, float)


@pytest.mark.parametrize("name", ["torso_bhm_3d", pytest.param("kneed", marks=pytest.mark.slow)])
@pytest.mark.parametrize("joint, share, ids", [("stance_hip", -0.5, (625, 626)),
                                               ("swing_hip", 0.5, (627, 628))])
def test_a_3d_datasets_torso_torque_is_the_rigid_law_as_its_hip_torque(name, joint, share, ids):
    """An upper body on the bisecting hip (configs/torso_bhm_3d.yaml; the kneed walker's on
    its thighs, slow: its derivation) driven at ``joint``: the law's angle in the file is
    the rigid one, leg minus upper body, which on the bisecting hip is ``-+ delta / 2`` (the
    rigid state's, worked out here: the upper body's pitch the legs' mean, a kneed leg's
    its thigh's), and the hip torque the SFORCE carries is ``-+ tau / 2`` of the law
    ``c - K (alpha - rest) - D alpha'`` at it [N mm].  That the two do the same work in the
    rigid model is tests/test_torso_3d.py's (the flows equal to 1e-10)."""
    scene, x = _torso_case(name, joint)
    plant = Plant.from_scene(scene)
    start = adams3d_start(plant, SimpleNamespace(x=x, period_s=1.0, step_lengths_m=(0.4,)), 2)
    model = read_adm(adm3d_text(scene, plant.data, start, "walker"))
    s = dict(zip(state_names(plant.data.structure.roles), x))
    sw = "swing_thigh" if "swing_thigh_angle" in s else "swing"
    leg = {"stance": ("stance_angle", "stance_rate"), "swing": (f"{sw}_angle", f"{sw}_rate")}
    torso = (s[leg["swing"][0]] + s["stance_angle"]) / 2   # the bisecting hip
    torso_rate = (s[leg["swing"][1]] + s["stance_rate"]) / 2
    a, r = leg[joint.split("_")[0]]
    alpha, dalpha = s[a] - torso, s[r] - torso_rate
    v = _evaluate(model, (303, *ids, 9099))
    assert v[303] == 1   # leg2 stands
    assert (v[ids[0]], v[ids[1]]) == pytest.approx((alpha, dalpha), rel=TOL)
    tau = (TORSO_LAW["constant_n_m"] - TORSO_LAW["stiffness_n_m_per_rad"]
           * (alpha - TORSO_LAW["rest_angle_rad"]) - TORSO_LAW["damping_n_m_s_per_rad"] * dalpha)
    assert abs(tau) > 0.1   # the law acts
    assert v[9099] / 1000 == pytest.approx(share * tau, rel=TOL)
    assert model.get("SFORCE", 10).args["FUNCTION"] == ("VARVAL(303)*VARVAL(9099)",)
