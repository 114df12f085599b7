"""The three-link walker (a torso hinged on straight legs: the ``hinged_torso`` kind,
configs/threelink.yaml) against an independent reference written from the book's closed-form
model (tests/independent/three_link.py: no walkerlab code): the generated mass matrix, bias,
torque columns and heel strike at random states, the closed loop's flow and the Poincaré map
of the scene's PD law; the shipped scene's gait; its contact run and MuJoCo export; the
refusals of what it does not have."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.independent import three_link as ref
from walkerlab.codegen.cache import functions
from walkerlab.config import SceneError, load_scene, scene_from_dict
from walkerlab.models.registry import build_walker
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "configs" / "threelink.yaml"
#: the book's numbers (configs/threelink.yaml)
BOOK = {"g": 9.8, "r": 1.0, "m": 5.0, "d": 0.5, "MH": 15.0, "MT": 10.0, "l": 0.5}
#: a walker whose every number differs (the leg mass off mid-leg, a slope): each term of the
#: generator is exercised
ODD = {"g": 9.81, "r": 0.9, "m": 3.0, "d": 0.35, "MH": 7.0, "MT": 12.0, "l": 0.4}
TOL = 1e-12


def _scene(p, slope=0.0, actuation=True) -> dict:
    d = yaml.safe_load(SCENE.read_text())
    w = d["walker"]
    w.update(gravity_m_per_s2=p["g"], hip_mass_kg=p["MH"])
    w["leg"]["length_m"] = p["r"]
    w["leg"]["bodies"][0].update(mass_kg=p["m"], from_hip_m=p["d"])
    w["torso"]["bodies"][0].update(mass_kg=p["MT"], from_hip_m=p["l"])
    if not actuation:
        del w["actuation"]
    d["slope"] = {"angle_rad": slope}
    return d


def _states(seed, k=6):
    rng = np.random.default_rng(seed)
    for _ in range(k):
        yield np.concatenate([rng.uniform(-1.2, 1.2, 3), rng.uniform(-3, 3, 3)])


@pytest.mark.parametrize("p, slope", [(BOOK, 0.0), (ODD, 0.04)])
def test_mass_matrix_bias_and_heel_strike_are_the_books(p, slope):
    """The generated ``M``, ``h = C q' + G`` and heel strike (plastic impact and the legs'
    swap) equal the book's closed forms at random states, to 1e-12 of their size."""
    data = walker_data(scene_from_dict(_scene(p, slope, actuation=False)).walker, slope)
    assert data.structure.kind.name == "hinged_torso"
    assert data.structure.roles == ("stance", "swing", "torso")
    f = functions(data)
    for x in _states(3):
        q, dq = x[:3], x[3:]
        M, C, G = f["matrices"](x)
        Mr, hr = ref.mass_matrix(q, p), ref.bias(q, dq, p)
        np.testing.assert_allclose(M, Mr, rtol=0, atol=TOL * np.abs(Mr).max())
        h = C @ dq + G
        np.testing.assert_allclose(h, hr, rtol=0, atol=TOL * np.abs(hr).max())
        De, _ = f["impact_matrices"](q)
        Der = ref.extended_mass_matrix(q, p)
        np.testing.assert_allclose(De, Der, rtol=0, atol=TOL * np.abs(Der).max())
        xp, xr = f["reset"](x), ref.impact(x, p)
        np.testing.assert_allclose(xp, xr, rtol=0, atol=TOL * np.abs(xr).max())
        np.testing.assert_allclose(f["energies"](x)[0] + f["energies"](x)[1],
                                   ref.energy(x, p), rtol=TOL)


@pytest.mark.parametrize("p, slope", [(BOOK, 0.0), (ODD, 0.04)])
def test_arc_feet_roll_as_the_reference(p, slope):
    """On arc feet (R = 0.3 m; McGeer 1990) the stance arc rolls and the heel strike is about
    the swing arc's material contact point: the generated ``M``, ``h``, ``De`` and heel
    strike equal the reference's (its hand-written Jacobians with the rolling offset, the
    Coriolis and gravity terms by the complex step, exact to round-off) to 1e-12; with
    R = 0 that reference is the closed forms'."""
    R = 0.3
    d = _scene(p, slope, actuation=False)
    d["walker"]["leg"]["foot"] = {"kind": "arc", "radius_m": R}
    data = walker_data(scene_from_dict(d).walker, slope)
    assert data.structure.kind.name == "hinged_torso"
    f = functions(data)
    for x in _states(11):
        q, dq = x[:3], x[3:]
        M0, h0 = ref.rolling_dynamics(q, dq, p)
        np.testing.assert_allclose(M0, ref.mass_matrix(q, p), rtol=0,
                                   atol=TOL * np.abs(M0).max())
        np.testing.assert_allclose(h0, ref.bias(q, dq, p), rtol=0,
                                   atol=TOL * np.abs(h0).max())
        M, C, G = f["matrices"](x)
        Mr, hr = ref.rolling_dynamics(q, dq, p, slope, R)
        np.testing.assert_allclose(M, Mr, rtol=0, atol=TOL * np.abs(Mr).max())
        np.testing.assert_allclose(C @ dq + G, hr, rtol=0, atol=TOL * np.abs(hr).max())
        De, _ = f["impact_matrices"](q)
        Der = ref.extended_mass_matrix(q, p, slope, R)
        np.testing.assert_allclose(De, Der, rtol=0, atol=TOL * np.abs(Der).max())
        xr = ref.impact(x, p, slope, R)
        np.testing.assert_allclose(f["reset"](x), xr, rtol=0, atol=TOL * np.abs(xr).max())


def _law(scene: dict):
    """The reference's PD law from the scene's tables and gains (stance_hip, swing_hip)."""
    torques = {t["joint"]: t["law"] for t in scene["walker"]["actuation"]["torques"]}
    laws = [torques["stance_hip"], torques["swing_hip"]]
    return ref.pd_phase_law(
        [(law["reference"]["phase_rad"], law["reference"]["angle_rad"]) for law in laws],
        [(law["stiffness_n_m_per_rad"], law["damping_n_m_s_per_rad"]) for law in laws])


@pytest.mark.parametrize("p, slope", [(BOOK, 0.0), (ODD, 0.04)])
def test_torque_columns_and_the_closed_loop_flow_are_the_books(p, slope):
    """The actuators' ``B`` is the book's torso-to-leg columns, and the closed loop's flow
    (the scene's PD law to phase references at the stance and swing hips) is
    ``D^-1 (B u - h)`` of the reference with its own spline of the same tables, at random
    states inside the tables, to 1e-9 of the accelerations."""
    d = _scene(p, slope)
    sc = scene_from_dict(d)
    walker = build_walker(Plant.from_scene(sc))
    np.testing.assert_array_equal(walker.actuators.B, ref.B)
    law = _law(d)
    rng = np.random.default_rng(5)
    for _ in range(6):
        x = np.concatenate([rng.uniform(-0.35, 0.35, 3), rng.uniform(-2, 2, 3)])
        want = ref.acceleration(x[:3], x[3:], law(x), p)
        got = walker.phases[0].flow(0.0, x)
        np.testing.assert_array_equal(got[:3], x[3:])
        np.testing.assert_allclose(got[3:], want, rtol=0, atol=1e-9 * np.abs(want).max())


def test_the_poincare_map_is_the_books():
    """walkerlab's step of the shipped scene (its PD law, its LSODA at 1e-11) from a state
    near its gait equals the reference's step (its own flow, spline, heel strike and impact;
    scipy's DOP853 at 1e-12) to 1e-8 in the state and the duration."""
    from walkerlab.api.walker import Walker

    d = yaml.safe_load(SCENE.read_text())
    w = Walker.from_scene(SCENE)
    x0 = load_scene(SCENE).fixedpoint.initial_guess.as_array(w.state_names()) + np.array(
        [0.0, 0.0, 0.01, 0.05, -0.05, 0.1])  # off the gait (the swing foot on the ground)
    st = w.step(x0)
    xr, tr = ref.step(x0, _law(d), BOOK)
    np.testing.assert_allclose(st.x_next, xr, rtol=0, atol=1e-8)
    assert st.period == pytest.approx(tr, abs=1e-8)


def test_the_shipped_gait_is_a_stable_fixed_point():
    """configs/threelink.yaml's initial guess is its gait: the map returns it to 1e-9; period
    0.46301 s, multipliers 0.792, 0.161, -0.119, 0.004 (and two zeros); speed 0.774 m/s."""
    from walkerlab.api.walker import Walker

    w = Walker.from_scene(SCENE)
    x = load_scene(SCENE).fixedpoint.initial_guess.as_array(w.state_names())
    st = w.step(x)
    np.testing.assert_allclose(st.x_next, x, rtol=0, atol=1e-9)
    assert st.period == pytest.approx(0.4630145360, abs=1e-9)
    mult = np.sort(np.abs(w.floquet(x)))[::-1]
    np.testing.assert_allclose(mult[:4], [0.792350, 0.160922, 0.118536, 0.004124],
                               atol=2e-6)
    assert mult[4:].max() < 1e-6


def _x_gait():
    scene = load_scene(SCENE)
    names = build_walker(Plant.from_scene(scene)).state_names()
    return scene, scene.fixedpoint.initial_guess.as_array(names)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_the_contact_view_walks_it():
    """contact-sim's walker (the same PD laws as forces, the stance leg switched at each
    touchdown; checkerboard lanes: the straight swing foot passes over the gap at
    mid-stance) walks 2 strides from the rigid gait: 5 heel strikes, alternating, each step
    within 1 % of the rigid 0.46301 s (measured 0.4628-0.4639 s, -0.05 to +0.2 %, at the
    scene's 10 mm/s stiction velocity; 0.4655-0.4657 s, +0.5 %, at ADAMS's 100 mm/s)."""
    from walkerlab.api.walker import ContactWalker

    scene, x = _x_gait()
    walk = ContactWalker.from_scene(SCENE).simulate(x, strides=2, period_s=0.4630145360)
    assert walk.walks, walk.message
    assert len(walk.heel_strikes) >= 4
    legs = walk.heel_strike_legs
    assert all(a != b for a, b in zip(legs, legs[1:])), legs
    np.testing.assert_allclose(np.diff(walk.heel_strikes), 0.46301, rtol=0.01)


@pytest.fixture(scope="module")
def mjcf(tmp_path_factory):
    """configs/threelink.yaml exported to MJCF, its keyframe the scene's gait (the export's
    own gait search replaced by the known fixed point, as tests/test_export_five_link.py)."""
    from types import SimpleNamespace

    from walkerlab.stages import export as export_stage

    scene, x = _x_gait()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr("walkerlab.analysis.contact.periodic.ideal_gait",
                   lambda sc, plant=None: SimpleNamespace(x=x, period_s=0.4630145360))
        return export_stage.run(scene, tmp_path_factory.mktemp("mjcf"), "mjcf")


def test_the_mjcf_mass_matrix_is_the_books(mjcf):
    """MuJoCo's mass matrix of the exported walker, carried to the reference's extended
    coordinates ``(q1, q2, q3, x_f, y_f)`` (leg2 in stance), is the book's ``De`` at random
    states, to 1e-10 of its size (plus MuJoCo's 1e-12 kg m^2 inertia floor)."""
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    data = mujoco.MjData(model)
    names = {model.joint(i).name for i in range(model.njnt)}
    assert names == {"hip_x", "hip_z", "leg1_hip", "leg2_hip", "torso_hip"}
    col = {j: model.joint(j).dofadr[0] for j in names}
    adr = {j: model.joint(j).qposadr[0] for j in names}
    r = BOOK["r"]
    for x in _states(8, k=4):
        q1, q2, q3 = x[:3]
        data.qpos[:] = 0.0
        data.qpos[adr["hip_x"]], data.qpos[adr["hip_z"]] = -r * np.sin(q1), r * np.cos(q1)
        data.qpos[adr["leg2_hip"]], data.qpos[adr["leg1_hip"]] = q1, q2
        data.qpos[adr["torso_hip"]] = q3
        mujoco.mj_forward(model, data)
        M = np.zeros((model.nv, model.nv))
        try:
            mujoco.mj_fullM(model, data, M)
        except TypeError:  # MuJoCo before 3.3: (model, M, qM)
            mujoco.mj_fullM(model, M, data.qM)
        J = np.zeros((model.nv, 5))  # d(MuJoCo coordinates) / d(q1, q2, q3, x_f, y_f)
        J[col["hip_x"]] = [-r * np.cos(q1), 0, 0, 1, 0]
        J[col["hip_z"]] = [-r * np.sin(q1), 0, 0, 0, 1]
        J[col["leg2_hip"], 0] = J[col["leg1_hip"], 1] = J[col["torso_hip"], 2] = 1.0
        De = ref.extended_mass_matrix(x[:3], BOOK)
        np.testing.assert_allclose(J.T @ M @ J, De, rtol=0,
                                   atol=1e-10 * np.abs(De).max() + 4e-12)


@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_the_mjcf_export_walks_in_mujoco(mjcf):
    """The exported walker steps in MuJoCo from its ``gait`` keyframe under walkerlab's
    stepping loop (the scene's laws at the hips): 5 alternating heel strikes in 2.5 s, steps
    within 1 % of the rigid 0.46301 s and 0.35849 m (measured 0.4643-0.4659 s, 0.3588-0.3594
    m)."""
    pytest.importorskip("mujoco")
    from walkerlab.export.mujoco_walk import walk

    run = walk(mjcf, 2.5)
    assert not run.fell
    assert len(run.times_s) >= 5 and run.alternating, run.legs
    np.testing.assert_allclose(run.step_periods_s, 0.46301, rtol=0.01)
    np.testing.assert_allclose(run.step_lengths_m, 0.35849, rtol=0.01)


def _refusal(change) -> str:
    d = yaml.safe_load(SCENE.read_text())
    change(d["walker"])
    with pytest.raises((SceneError, ValueError)) as exc:
        sc = scene_from_dict(d)
        build_walker(Plant.from_scene(sc))
    line = str(exc.value)
    assert "\n" not in line
    return line


@pytest.mark.parametrize("change, said", [
    (lambda w: w["leg"].update(knee={"thigh_length_m": 0.5}, bodies=[
        {"kind": "point_mass", "name": "thigh", "link": "thigh", "mass_kg": 2.5,
         "from_hip_m": 0.25},
        {"kind": "point_mass", "name": "shank", "link": "shank", "mass_kg": 2.5,
         "from_hip_m": 0.75}]),
     "torso.coupling: 'hinged' needs straight legs or free knees"),
    (lambda w: w["leg"].update(foot={"kind": "flat", "heel_m": 0.05, "toe_m": 0.1,
                                     "ankle": {"stiffness_n_m_per_rad": 10.0}}),
     "a hinged torso on straight legs needs leg.foot.kind: point or arc"),
    (lambda w: w.update(springs=[{"between": ["leg1", "leg2"],
                                  "stiffness_n_m_per_rad": 1.0}]),
     "needs no springs"),
    (lambda w: w["leg"]["bodies"][0].update(mass_kg=0.0),
     "needs massive leg bodies"),
    (lambda w: w["actuation"]["torques"].append(
        {"joint": "swing_knee", "law": {"stiffness_n_m_per_rad": 1.0}}),
     "swing_knee is not a joint of this walker (its joints: hip, stance_hip, swing_hip)"),
])
def test_what_it_does_not_have_is_refused_in_one_line(change, said):
    assert said in _refusal(change)


def test_optimize_refuses_it_with_the_tables_reason():
    from walkerlab.walker.kinds import KINDS, KindRefused

    kind = walker_data(load_scene(SCENE).walker, 0.0).structure.kind
    with pytest.raises(KindRefused, match="^walker: open-loop torques of a torso hinged on "
                                          "straight legs are not transcribed"):
        kind.require("walk", "optimize", "walker")
    assert KINDS["hinged_torso"].cell("knee_torque", "mjcf") == \
        "the legs are straight: there is no knee"


def test_the_adams_hip_torques_equal_walkerlab_laws():
    """The Adams dataset of configs/threelink.yaml: SFORCE/11 and /12 on each leg's hip
    against the torso (no knee SFORCE: straight legs), evaluated at 20 states, equal
    walkerlab's laws in the role the contact forces give (stance_hip = stance leg - torso,
    swing_hip = swing leg - torso), the phase variable the hip -> stance foot line's
    ``atan2(dx, -dy)`` (the stance leg's angle)."""
    from tests.test_export_adams_actuation import AdamsState, evaluate
    from walkerlab.export.adams import adm_text
    from walkerlab.export.adams_actuation import ACT_VARIABLES, JOINT_SFORCE
    from walkerlab.export.adams_feet import part_ids
    from walkerlab.export.adams_reader import AdmReadError, read_adm
    from walkerlab.export.adams_statements import LINE_WIDTH, MM, AdamsStart, marker_id
    from walkerlab.models.actuation import TorqueLaws
    from walkerlab.walker.multibody import multibody

    scene = load_scene(SCENE)
    data = walker_data(scene.walker, scene.slope.phi_rad)
    mb = multibody(data)
    names = [ln.name for ln in mb.links]
    assert names == ["leg1", "leg2", "torso"]
    start = AdamsStart((0.1, 0.95), (0.7, 0.0), dict.fromkeys(names, 0.1),
                       dict.fromkeys(names, 0.0), None, 0.1, 0.46, (1.0, 1.0))
    adm = adm_text(scene, mb, Plant.from_scene(scene), "threelink", "test", start)
    assert all(len(ln) <= LINE_WIDTH for ln in adm.splitlines())
    model = read_adm(adm)
    v = model.functions()
    ids = part_ids(mb)
    laws = TorqueLaws(scene.walker.actuation.torques)
    rng = np.random.default_rng(9)
    for n in range(20):
        psi = {"leg1": rng.uniform(-0.35, 0.35), "leg2": rng.uniform(-0.35, 0.35),
               "torso": rng.uniform(-0.3, 0.3)}
        w = {k: rng.uniform(-3, 3) for k in psi}
        stance = "leg1" if n % 2 else "leg2"
        swing = "leg2" if stance == "leg1" else "leg1"
        st = AdamsState(mb, (0.0, 950.0), (700.0, 10.0), psi, w,
                        {1: 300.0} if stance == "leg1" else {2: 300.0})
        ns = st.namespace(v)
        assert ns["VARVAL"](ACT_VARIABLES["phase"]) == pytest.approx(psi[stance], abs=1e-12)
        deltas = [psi[stance] - psi["torso"], psi[swing] - psi["torso"]]
        rates = [w[stance] - w["torso"], w[swing] - w["torso"]]
        taus = laws.each(deltas, rates, psi[stance], w[stance]) * MM
        for (kind, g), sid in JOINT_SFORCE.items():
            if kind == "knee":
                with pytest.raises(AdmReadError):
                    model.get("SFORCE", sid)
                continue
            sf = model.get("SFORCE", sid)
            want = taus[0] if g == stance else taus[1]
            got = evaluate(sf.args["FUNCTION"][0], ns)
            assert math.isclose(got, want, rel_tol=1e-9, abs_tol=5e-3), (g, got, want)
            assert sf.integer("I") == marker_id(ids[g], "joint")
            assert sf.integer("J") == marker_id(ids["torso"], "joint")
