"""Powered walking on the rigid model (``walker.actuation``), against numbers that share no
code with the generator: the independent actuated compass gait
(``tests/independent/actuated_compass.py``: Lagrange by hand, push-off and heel strike in
floating coordinates) and Kuo's (2002) closed forms for the simplest walker; the energy
ledger's closure and the cost of transport of every shipped scene."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import walkerlab as wl
from tests.independent import actuated_compass as ref
from walkerlab.analysis.gait.energy import trajectory_ledger
from walkerlab.config import SceneError, load_scene, scene_from_dict
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
#: scenes without actuators or a control law of any kind (a 3D walker's hip-roll law acts
#: inside its flow: tests/test_hip_roll_3d.py closes that walker's ledger)
PASSIVE = sorted(p.stem for p in CONFIGS.glob("*.yaml")
                 if load_scene(p).walker.actuation is None
                 and getattr(load_scene(p).walker, "hip_roll", None) is None)
POWERED = sorted(p.stem for p in CONFIGS.glob("*.yaml")
                 if load_scene(p).walker.actuation is not None)


def _compass(actuation: dict, slope: float = 0.0) -> dict:
    return {"name": "t", "walker": {"model": "compass_gait", "leg_length_m": 1.0,
                                    "leg_mass_kg": 5.0, "hip_mass_kg": 10.0,
                                    "gravity_m_per_s2": 9.81, "leg_mass_from_foot_m": 0.5,
                                    "actuation": actuation},
            "slope": {"angle_rad": slope},
            "solver": {"method": "DOP853", "rtol": 1e-12, "atol": 1e-12},
            "fixedpoint": {"tolerance": 1e-12}}


LAW = {"constant_n_m": 1.5, "stiffness_n_m_per_rad": 20.0, "damping_n_m_s_per_rad": 0.5,
       "rest_angle_rad": 0.1}


@pytest.mark.parametrize("slope", [0.0, 0.0174, -0.01])
def test_actuated_flow_equals_the_independent_derivation(slope):
    sc = scene_from_dict(_compass({"torques": [{"joint": "hip", "law": LAW,
                                                "max_torque_n_m": 2.0}]}, slope))
    w = build_walker(Plant.from_scene(sc))
    law = ref.spring_torque(1.5, 20.0, 0.5, 0.1, tau_max=2.0)
    rng = np.random.default_rng(1)
    for _ in range(20):
        x = rng.normal(0.0, [0.2, 0.2, 1.0, 1.0])
        got = w.phases[0].flow(0.0, x)
        want = ref.flow(x, ref.PAPER, slope, tau=law(0.0, x))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
        # the flow's Jacobian (the variational equations') against central differences
        J = w.phases[0].jacobian(0.0, x)
        h = 1e-6
        Jfd = np.stack([(w.phases[0].flow(0, x + h * e) - w.phases[0].flow(0, x - h * e))
                        / (2 * h) for e in np.eye(4)], axis=1)
        np.testing.assert_allclose(J, Jfd, rtol=0, atol=1e-6 * (1 + np.abs(J).max()))


@pytest.mark.parametrize("P", [0.0, 1.0, 3.0])
def test_push_off_and_heel_strike_equal_the_independent_derivation(P):
    sc = scene_from_dict(_compass({"push_off": {"impulse_n_s": P}}))
    w = build_walker(Plant.from_scene(sc))
    for xm in ([-0.17, 0.17, -0.77, -0.87], [-0.2, 0.2, -0.5, -0.9], [-0.1, 0.1, -0.9, -0.6]):
        xm = np.array(xm)
        want, info = ref.push_off_heel_strike(xm, ref.PAPER, 0.0, P)
        tr = w.actuators.transition(xm)
        np.testing.assert_allclose(tr["x_plus"], want, rtol=0, atol=1e-12)
        assert tr["ke_push_off"] - tr["ke_minus"] == pytest.approx(info["pushoff_work"],
                                                                  abs=1e-12)
        assert tr["ke_push_off"] - tr["ke_plus"] == pytest.approx(info["collision_loss"],
                                                                 abs=1e-12)
    if P == 0.0:  # the push-off form with P = 0 is the generated passive impact
        sc = load_scene(CONFIGS / "paper.yaml")
        passive = build_walker(Plant.from_scene(sc))
        xm = np.array([-0.2, 0.1652, -0.6, -0.85])
        np.testing.assert_allclose(w.reset(xm), passive.reset(xm), rtol=0, atol=1e-13)


def test_powered_compass_fixed_point_equals_the_independent_one():
    """configs/powered_compass.yaml: level ground, push-off 3 N s; and the same walker with a
    spring-like hip torque: fixed point, step period and multipliers to <= 1e-9."""
    gait = wl.Walker.from_scene(CONFIGS / "powered_compass.yaml").fixed_point()
    x, T, mu = ref.fixed_point(ref.PAPER, 0.0, P=3.0, guess=gait.x)
    np.testing.assert_allclose(gait.x, x, rtol=0, atol=1e-9)
    assert gait.step_period == pytest.approx(T, abs=1e-9)
    np.testing.assert_allclose(np.sort(np.abs(gait.multipliers))[1:],
                               np.sort(np.abs(mu))[1:], atol=1e-6)  # reference: FD Jacobian
    assert gait.stable and 0.69 < gait.step_period < 0.70
    sc = _compass({"push_off": {"impulse_n_s": 3.0},
                   "torques": [{"joint": "hip", "law": {"constant_n_m": 0.5,
                                                        "stiffness_n_m_per_rad": 1.0,
                                                        "damping_n_m_s_per_rad": 0.2}}]})
    sc["fixedpoint"]["initial_guess"] = dict(zip(
        ["swing_angle_rad", "stance_angle_rad", "swing_rate_rad_per_s",
         "stance_rate_rad_per_s"], [-0.181, 0.181, -0.72, -0.88]))
    g2 = wl.Walker.from_scene(sc).fixed_point()
    x2, T2, _ = ref.fixed_point(ref.PAPER, 0.0, P=3.0, guess=g2.x,
                                torque_law=ref.spring_torque(0.5, 1.0, 0.2))
    np.testing.assert_allclose(g2.x, x2, rtol=0, atol=1e-9)
    assert g2.step_period == pytest.approx(T2, abs=1e-9)


@pytest.fixture(scope="module")
def kuo():
    return wl.Walker.from_scene(CONFIGS / "kuo2002.yaml")


@pytest.mark.parametrize("alpha", [0.15, 0.2, 0.35])
def test_kuo_closed_forms_on_the_generated_reset(kuo, alpha):
    """Kuo (2002): theta+ = -theta, dtheta+ = cos 2a dtheta + sin 2a P (the generated
    transition's sign: forward rates are negative); the steady push-off P = v tan(a) keeps
    the speed; the collision loss of stance-torque powering (P = 0, same pre-transition
    speed) is 4 cos^4(a) times that of push-off."""
    v = 0.4
    x = np.array([-alpha, -2 * alpha, -v, -0.05])  # on the heel-strike surface phi = 2 theta
    P = v * math.tan(alpha)
    w = kuo.with_changes({"walker.actuation.push_off.impulse_n_s": P}).model
    tr = w.actuators.transition(x)
    th, dth, ph, dph = ref.kuo_transition(-alpha, -v, P)
    np.testing.assert_allclose(tr["x_plus"], [th, ph, -dth if dth > 0 else dth, dph],
                               atol=1e-14)
    assert tr["x_plus"][2] == pytest.approx(-v, abs=1e-14)  # the speed is kept
    loss_push = tr["ke_push_off"] - tr["ke_plus"]
    w0 = kuo.with_changes({"walker.actuation.push_off.impulse_n_s": 0.0}).model
    tr0 = w0.actuators.transition(x)
    loss_stance = tr0["ke_minus"] - tr0["ke_plus"]
    assert loss_stance / loss_push == pytest.approx(4 * math.cos(alpha) ** 4, rel=1e-12)
    assert loss_push == pytest.approx(0.5 * v ** 2 * math.tan(alpha) ** 2, rel=1e-12)


def test_kuo_hip_torque_is_the_swing_equation_term(kuo):
    """The per-foot-mass hip torque adds -k (psi_sw - psi_st) to the swing leg's equation
    (Kuo 2002: phi'' = ... - k phi), nothing to the stance leg's (the hip mass's)."""
    sc = load_scene(CONFIGS / "simplest.yaml").model_copy(
        update={"slope": load_scene(CONFIGS / "kuo2002.yaml").slope})
    passive = build_walker(Plant.from_scene(sc))
    x = np.array([0.1, 0.3, -0.2, 0.05])
    d = kuo.model.phases[0].flow(0, x) - passive.phases[0].flow(0, x)
    # coordinates (theta, phi = theta - psi_sw): theta'' unchanged, phi'' gains -k phi
    assert d[2] == pytest.approx(0.0, abs=1e-15)
    assert d[3] == pytest.approx(-0.08 * x[1], rel=1e-12)


def _ledger(name: str):
    w = wl.Walker.from_scene(CONFIGS / f"{name}.yaml")
    g = w.fixed_point()
    traj = simulate_steps(w.model, g.x, 2 * w.model.steps_per_map, w.solver,
                          max_step_time=w.max_step_time)
    ke = np.array([w.model.for_stance(s_.stance_leg).energies(s_.x_start)[0]
                   for s_ in traj.segments])
    return w, trajectory_ledger(traj), ke


# rabbit: its fixed point takes ~2 min (ten coordinates, high-gain PD); tests/test_rabbit.py
# closes its ledger on one step from the fixed point its scene stores; flat feet (passive
# and with an ankle push-off): walkerlab.analysis.gait.energy_modes; rabbit_optimal: no gait
# of its own (its step is optimised: tests/test_optimize_five_link.py)
@pytest.mark.parametrize("name", [n for n in PASSIVE + POWERED
                                  if n not in ("rabbit", "rabbit_optimal")])
@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_the_energy_ledger_closes_and_cost_of_transport(name):
    w, led, ke = _ledger(name)
    assert np.all(np.isfinite(led["closure"]))
    assert np.max(np.abs(led["closure"]) / ke) <= 1e-9
    phi = w.model.slope_rad
    if name in PASSIVE and "landing_drop_m" in w.model.params:
        # stairs, footholds: the collisions take gravity's work over each step's descent h
        # (the stance foot's height minus the landing swing foot's: a riser down level
        # treads), so the cost of transport is h / d, d the step's length
        m, g = w.model.total_mass_kg, w.model.params["gravity_m_per_s2"]
        feet = [w.model.for_stance(s.stance_leg).points(s.x_end)["swing_foot"]
                for s in simulate_steps(w.model, w.fixed_point().x, 2 * w.model.steps_per_map,
                                        w.solver, max_step_time=w.max_step_time).segments]
        h = np.array([-f[1] for f in feet])
        assert np.all(h > 0)  # down the stairs, down onto the footholds
        np.testing.assert_allclose(led["slope_energy"], m * g * h, rtol=1e-12)
        np.testing.assert_allclose(led["cost_of_transport"],
                                   h / np.array([np.hypot(f[0], f[1]) for f in feet]),
                                   rtol=1e-12)  # along the ground (a 3D foot: its width apart)
    elif name in PASSIVE:
        # a passive gait: the collisions (and dampers) take what the slope releases, so the
        # cost of transport is sin(slope)
        np.testing.assert_allclose(led["cost_of_transport"], math.sin(phi), rtol=1e-12)
    if name in PASSIVE:
        sinks = led["heel_strike_loss"] + led["internal_collision_loss"] - led["damper_work"]
        np.testing.assert_allclose(sinks.sum(), led["slope_energy"].sum(),
                                   rtol=1e-7 if w.model.steps_per_map == 1 else 1e-6)
        assert not np.any(led["push_off_work"]) and not np.any(led["actuator_work_positive"])
    elif phi != 0.0:  # a powered walker on a slope (hip_width_powered: a 3D walker's
        # push-off and hip spring): the ground releases m g h over each step's descent h
        # (the landing swing foot's depth below the stance foot), on top of the actuators
        m, g = w.model.total_mass_kg, w.model.params["gravity_m_per_s2"]
        feet = [w.model.for_stance(s.stance_leg).points(s.x_end)["swing_foot"]
                for s in simulate_steps(w.model, w.fixed_point().x, len(led["closure"]),
                                        w.solver, max_step_time=w.max_step_time).segments]
        h = np.array([-f[1] for f in feet])
        assert np.all(h > 0) and np.all(led["push_off_work"] + led["actuator_work_positive"] > 0)
        np.testing.assert_allclose(led["slope_energy"], m * g * h, rtol=1e-12)
    else:  # level ground: the actuators' share alone (footholds of alternating heights: a
        # step's gravity work m g dh, summing to 0 over the period of footholds)
        if "landing_drop_m" in w.model.params:
            assert abs(led["slope_energy"].sum()) < 1e-12 * np.abs(led["slope_energy"]).sum()
        else:
            assert np.all(led["slope_energy"] == 0.0)
        m, g = w.model.total_mass_kg, w.model.params["gravity_m_per_s2"]
        n = len(led["cost_of_transport"])  # the steps of a map (footholds: its period)
        steps = np.array([np.hypot(*w.model.for_stance(s.stance_leg).points(s.x_end)[
            "swing_foot"]) for s in simulate_steps(w.model, w.fixed_point().x, n, w.solver,
                                                   max_step_time=w.max_step_time).segments])
        if "landing_drop_m" in w.model.params:
            return  # footholds of alternating heights: each step's cost carries its
            # gravity share too (the closure above holds; the per-step form is not this one)
        np.testing.assert_allclose(led["cost_of_transport"],
                                   (led["push_off_work"] + led["actuator_work_positive"])
                                   / (m * g * steps), rtol=1e-12)


@pytest.mark.parametrize("name", ["powered_compass", "paper"])
def test_the_step_table_names_the_collision_loss_and_the_net_transition(name):
    """``simulate.h5``'s ``steps/``: ``impact_energy_loss`` is the heel-strike collision's loss
    (the ledger's ``heel_strike_loss``: 0.2346 J on powered_compass, where it held the net
    change across push-off and heel strike, ~2e-11 J), ``transition_energy_change`` the net
    change (push-off work minus the collision's loss; passive: minus the loss itself)."""
    from walkerlab.analysis.gait.metrics import step_table

    w = wl.Walker.from_scene(CONFIGS / f"{name}.yaml")
    traj = simulate_steps(w.model, w.fixed_point().x, 2, w.solver,
                          max_step_time=w.max_step_time)
    steps, led = step_table(traj), trajectory_ledger(traj)
    np.testing.assert_allclose(steps["impact_energy_loss"], led["heel_strike_loss"],
                               rtol=1e-12)
    np.testing.assert_allclose(steps["transition_energy_change"],
                               led["push_off_work"] - led["heel_strike_loss"],
                               rtol=1e-9, atol=1e-9 * led["heel_strike_loss"].max())
    assert np.all(steps["impact_energy_loss"] > 0.1)
    if name == "paper":
        assert np.array_equal(steps["transition_energy_change"], -steps["impact_energy_loss"])


def _in_3d(name: str) -> bool:
    return getattr(load_scene(CONFIGS / f"{name}.yaml").walker, "space", None) == "3d"


def test_a_passive_scene_is_serialised_as_before():
    """No ``actuation`` key in a passive scene's JSON: its input hashes, hence its
    artifacts, are those of before actuation existed; a planar passive scene's walker
    carries no actuators (the 3D scenes' walkers: the slow test below)."""
    for name in PASSIVE:
        sc = load_scene(CONFIGS / f"{name}.yaml")
        assert '"actuation"' not in sc.model_dump_json()
        if getattr(sc.walker, "space", None) != "3d":
            assert build_walker(Plant.from_scene(sc)).actuators is None


@pytest.mark.slow  # ~15 min on a fresh cache: every passive 3D scene's derivation
@pytest.mark.parametrize("name", [n for n in PASSIVE if _in_3d(n)])
def test_a_passive_3d_scenes_walker_carries_no_actuators(name):
    assert build_walker(Plant.from_scene(load_scene(CONFIGS / f"{name}.yaml"))).actuators is None


@pytest.mark.parametrize("bad, msg", [
    ({"push_off": {}}, "impulse_n_s"),
    ({}, "give push_off, torques or ankle_push_off"),
    ({"torques": [{"joint": "knee", "law": {}}]}, "joint"),
    ({"push_off": {"impulse_n_s": -1.0}}, "impulse_n_s"),
])
def test_bad_actuation_is_one_clear_line(bad, msg):
    with pytest.raises(SceneError, match=msg) as e:
        scene_from_dict(_compass(bad))
    assert "actuation" in str(e.value)


def test_actuators_the_walker_cannot_carry_are_refused():
    kneed = load_scene(CONFIGS / "kneed.yaml").model_dump(mode="json", exclude_none=True)
    kneed["walker"]["actuation"] = {"push_off": {"impulse_n_s": 1.0}}
    # a kneed walker takes a push-off now (tests/test_kneed_push_off.py)
    sc1 = scene_from_dict(kneed)
    assert build_walker(Plant.from_scene(sc1)).actuators is not None
    simplest = load_scene(CONFIGS / "simplest.yaml").model_dump(mode="json", exclude_none=True)
    simplest["walker"]["actuation"] = {"torques": [{"joint": "hip", "law": {}}]}
    with pytest.raises(ValueError, match="scaled_by: foot_mass"):
        sc = scene_from_dict(simplest)
        build_walker(Plant.from_scene(sc))


def test_the_ledger_names_the_dampers_work():
    """A damped hip spring (hip_spring.yaml with 0.05 N m s/rad): the damper's work is
    negative and the ledger still closes; the cost of transport stays sin(slope) (passive)."""
    d = load_scene(CONFIGS / "hip_spring.yaml").model_dump(mode="json", exclude_none=True)
    d["walker"]["springs"][0]["damping_n_m_s_per_rad"] = 0.05
    w = wl.Walker.from_scene(d)
    g = w.fixed_point()
    traj = simulate_steps(w.model, g.x, 2, w.solver)
    led = trajectory_ledger(traj)
    ke = w.model.energies(g.x)[0]
    assert np.all(led["damper_work"] < -1e-3)
    assert np.max(np.abs(led["closure"])) / ke <= 1e-9
    sinks = led["heel_strike_loss"] - led["damper_work"]
    np.testing.assert_allclose(sinks, led["slope_energy"], rtol=1e-7)


def test_gait_target_recovers_the_push_off_of_a_known_gait():
    """Kuo's findgait(target=speed, varying=P): the speed of the gait at P = 2 N s, asked as
    a target from the scene's P = 3 N s, gives back P = 2 N s; and a step-period target."""
    from walkerlab.analysis.gait.energy import gait_measures

    w = wl.Walker.from_scene(CONFIGS / "powered_compass.yaml")
    at2 = w.with_changes({"walker.actuation.push_off.impulse_n_s": 2.0})
    g2 = gait_measures(at2.model, at2.fixed_point().x, 1, at2.solver)
    found, gait = w.find_gait_for("walker.actuation.push_off.impulse_n_s",
                                  speed_m_per_s=g2["speed"])
    assert found.scene.walker.actuation.push_off.impulse_n_s == pytest.approx(2.0, abs=1e-8)
    assert gait_measures(found.model, gait.x, 1, found.solver)["speed"] == pytest.approx(
        g2["speed"], rel=1e-10)
    _, g3 = w.find_gait_for("walker.actuation.push_off.impulse_n_s", step_period_s=0.69)
    assert g3.step_period == pytest.approx(0.69, abs=1e-9)
    with pytest.raises(ValueError, match="exactly one"):
        w.find_gait_for("walker.actuation.push_off.impulse_n_s", speed_m_per_s=0.4,
                        step_period_s=0.7)


def test_target_command_prints_the_value_or_one_line():
    from typer.testing import CliRunner

    from walkerlab.cli import app

    scene = str(CONFIGS / "powered_compass.yaml")
    r = CliRunner().invoke(app, ["target", scene, "--vary",
                                 "walker.actuation.push_off.impulse_n_s",
                                 "--speed-m-per-s", "0.45"])
    assert r.exit_code == 0, r.output
    assert "impulse_n_s = 2.4434" in r.output and "N s gives speed = 0.45 m/s" in r.output
    r = CliRunner().invoke(app, ["target", scene, "--vary",
                                 "walker.actuation.push_off.impulse_n_s",
                                 "--speed-m-per-s", "3"])
    assert r.exit_code == 1 and "Traceback" not in r.output
    assert "error: target: no gait with speed = 3" in r.output


def test_the_export_carries_an_ankle_push_off(tmp_path):
    """Not silently passive: the MJCF of a flat-footed walker with an ankle push-off has a
    motor on each ankle hinge and the law in its custom text (it walks:
    tests/test_export_flat_feet.py); the URDF (soles on ankle hinges, no actuator element)
    names each ankle motor it leaves out, its law in the keyframe sidecar."""
    import yaml
    from typer.testing import CliRunner

    from walkerlab.cli import app

    f = load_scene(CONFIGS / "flat_feet.yaml").model_dump(mode="json", exclude_none=True)
    f["walker"]["actuation"] = {"ankle_push_off": {"constant_n_m": 5.0}}
    f["name"] = "ankle_flat"
    scene = tmp_path / "ankle_flat.yaml"
    scene.write_text(yaml.safe_dump(f))
    r = CliRunner().invoke(app, ["export", "--format", "mjcf", str(scene), "--runs-dir",
                                 str(tmp_path / "runs")])
    assert r.exit_code == 0, r.output
    text = (tmp_path / "runs" / "ankle_flat" / "walker.xml").read_text()
    for leg in ("leg1", "leg2"):
        assert f'<motor name="{leg}_ankle_motor" joint="{leg}_ankle" gear="1"/>' in text
    assert '"constant_n_m": 5.0' in text
    r = CliRunner().invoke(app, ["export", "--format", "urdf", str(scene), "--runs-dir",
                                 str(tmp_path / "urdf")])
    assert r.exit_code == 0 and "Traceback" not in r.output, r.output
    assert (tmp_path / "urdf" / "ankle_flat" / "walker.urdf").is_file()
    for leg in ("leg1", "leg2"):
        assert (f"left out of walker.urdf: motor {leg}_ankle_motor: URDF has no actuator "
                f"element for a torque u on the joint {leg}_ankle") in r.output
    assert '"constant_n_m": 5.0' in (tmp_path / "urdf" / "ankle_flat" /
                                     "walker.gait.json").read_text()


@pytest.mark.parametrize("name", ["powered_compass", "kuo2002"])
@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_the_automatic_gait_search_walks_on_level_ground(name):
    """No initial guess: the scale-free seeds sized by the slope the push-off stands for
    find the scene's gait (the one its guess names, or its partner)."""
    d = load_scene(CONFIGS / f"{name}.yaml").model_dump(mode="json", exclude_none=True)
    guessed = wl.Walker.from_scene(d).fixed_point()
    d["fixedpoint"].pop("initial_guess")
    found = wl.Walker.from_scene(d).fixed_point()
    assert found.residual < 1e-10
    # the stable gait is selected (Kuo's: the long-period one, |lambda| 0.695; it was
    # called unstable from a wrong reset Jacobian, tests/test_multiplier_agreement.py)
    assert np.allclose(found.x, guessed.x, atol=1e-8) and found.stable


def test_a_push_off_law_of_the_pre_impact_speed():
    """P = P0 + k (v_ref - v), v the hip's speed before heel strike, never negative; the
    hip speed from the compass gait's own kinematics, hip = foot + L (-sin th2, cos th2)."""
    law = {"impulse_n_s": 3.0, "speed_gain_n_s2_per_m": 10.0, "reference_speed_m_per_s": 0.5}
    sc1 = scene_from_dict(_compass({"push_off": law}))
    w = build_walker(Plant.from_scene(sc1))
    for xm in ([-0.17, 0.17, -0.77, -0.87], [-0.2, 0.2, -0.5, -0.6], [-0.1, 0.1, -2.0, -2.0]):
        xm = np.array(xm)
        v = abs(xm[3]) * 1.0  # |d hip / dt| = L |dtheta2|
        want = max(0.0, 3.0 + 10.0 * (0.5 - v))
        tr = w.actuators.transition(xm)
        assert tr["impulse"] == pytest.approx(want, abs=1e-12)
        ref_plus, _ = ref.push_off_heel_strike(xm, ref.PAPER, 0.0, want)
        np.testing.assert_allclose(tr["x_plus"], ref_plus, atol=1e-12)
    # a speed-regulated gait: the same fixed point as the fixed push-off it settles to
    sc = _compass({"push_off": law})
    sc["fixedpoint"]["initial_guess"] = dict(zip(
        ["swing_angle_rad", "stance_angle_rad", "swing_rate_rad_per_s",
         "stance_rate_rad_per_s"], [-0.1735, 0.1735, -0.7654, -0.8690]))
    walker = wl.Walker.from_scene(sc)
    g = walker.fixed_point()
    pre = simulate_steps(walker.model, g.x, 1, walker.solver).segments[0].x_end
    P = max(0.0, 3.0 + 10.0 * (0.5 - abs(pre[3])))  # the impulse the law gives on the gait
    x, T, _ = ref.fixed_point(ref.PAPER, 0.0, P=P, guess=g.x)
    np.testing.assert_allclose(g.x, x, atol=1e-8)


@pytest.mark.parametrize("interpolation", ["linear", "cubic"])
def test_pd_tracking_of_a_phase_reference(interpolation):
    """A virtual constraint: tau = -k (delta - h(s)) - c (ddelta - h'(s) ds), s the stance
    angle, delta = swing - stance angle; against the independent flow with the torque
    computed here (numpy's interp / scipy's spline), and the flow's Jacobian (complex step
    through the table) against central differences."""
    from scipy.interpolate import CubicSpline

    phase = [-0.3, -0.1, 0.1, 0.3]
    hip = [0.35, 0.1, -0.15, -0.3]
    law = {"stiffness_n_m_per_rad": 40.0, "damping_n_m_s_per_rad": 2.0,
           "reference": {"phase_rad": phase, "hip_angle_rad": hip,
                         "interpolation": interpolation}}
    sc = scene_from_dict(_compass({"torques": [{"joint": "hip", "law": law}]}))
    w = build_walker(Plant.from_scene(sc))
    if interpolation == "linear":
        def h(s):
            return np.interp(s, phase, hip)

        def dh(s):
            k = np.clip(np.searchsorted(phase, s) - 1, 0, 2)
            return (hip[k + 1] - hip[k]) / (phase[k + 1] - phase[k])
    else:
        cs = CubicSpline(phase, hip, bc_type="not-a-knot")
        h, dh = cs, cs.derivative()
    rng = np.random.default_rng(3)
    for _ in range(10):
        x = np.array([rng.uniform(-0.25, 0.25), rng.uniform(-0.25, 0.25),
                      rng.normal(0, 1), rng.normal(0, 1)])
        s, ds = x[1], x[3]
        tau = -40.0 * ((x[0] - x[1]) - h(s)) - 2.0 * ((x[2] - x[3]) - dh(s) * ds)
        np.testing.assert_allclose(w.phases[0].flow(0.0, x), ref.flow(x, ref.PAPER, 0.0, tau),
                                   rtol=0, atol=1e-11)
        J = w.phases[0].jacobian(0.0, x)
        hh = 1e-6
        Jfd = np.stack([(w.phases[0].flow(0, x + hh * e) - w.phases[0].flow(0, x - hh * e))
                        / (2 * hh) for e in np.eye(4)], axis=1)
        np.testing.assert_allclose(J, Jfd, rtol=0, atol=1e-5 * (1 + np.abs(J).max()))


@pytest.mark.parametrize("interpolation", ["linear", "cubic"])
def test_pd_tracking_of_a_time_table_counts_from_each_step(interpolation):
    """``time_reference``: tau = -k (delta - h(t)) - c (ddelta - h'(t)), t the time since
    the step's heel strike; two steps of the rigid model (the second starts at the first's
    end, so the table must restart) against the independent step with the law computed here
    (numpy's interp / scipy's spline, t from 0 each step)."""
    from scipy.interpolate import CubicSpline

    times = [0.0, 0.2, 0.4, 0.6]
    hip = [-0.35, -0.1, 0.15, 0.35]
    law = {"stiffness_n_m_per_rad": 30.0, "damping_n_m_s_per_rad": 1.0,
           "time_reference": {"time_s": times, "hip_angle_rad": hip,
                              "interpolation": interpolation}}
    sc = _compass({"push_off": {"impulse_n_s": 3.0},
                   "torques": [{"joint": "hip", "law": law}]})
    sc1 = scene_from_dict(sc)
    w = build_walker(Plant.from_scene(sc1))
    if interpolation == "linear":
        slopes = np.diff(hip) / np.diff(times)

        def h(t):
            return np.interp(t, times, hip)

        def dh(t):
            return slopes[min(max(np.searchsorted(times, t) - 1, 0), 2)] if t < times[-1] \
                else 0.0
    else:
        cs = CubicSpline(times, hip, bc_type="not-a-knot")

        def h(t):
            return cs(min(t, times[-1]))

        def dh(t):
            return cs(t, 1) if t < times[-1] else 0.0

    def torque(t, x):
        return -30.0 * ((x[0] - x[1]) - h(t)) - 1.0 * ((x[2] - x[3]) - dh(t))

    x0 = np.array([-0.1735, 0.1735, -0.7654, -0.869])
    traj = simulate_steps(w, x0, 2, wl.Walker.from_scene(sc).solver)
    x = x0
    for seg in traj.segments:
        x, T, _ = ref.step(x, ref.PAPER, 0.0, P=3.0, torque_law=torque)
        assert seg.t_end - seg.t_start == pytest.approx(T, abs=1e-8)
        np.testing.assert_allclose(seg.x_next, x, rtol=0, atol=1e-8)


def test_ankle_push_off_on_flat_feet_is_the_released_spring_in_heel_off():
    """``ankle_push_off`` on flat feet: the heel-off mode runs on the walker's own generated
    equations with the ankle numbers (k + k_po, r_eff); its flow equals the passive flow
    plus the push-off torque on the ankle coordinate, -k_po (a - r_po) - tau_0, through
    M^-1 (checked against the passive heel-off flow, the other modes unchanged); the shipped
    scene's gait puts the push-off's work into the ledger (its positive and negative parts
    apart)."""
    from walkerlab.models.hybrid.ankle_push_off import ankle_push_off_work

    d = load_scene(CONFIGS / "flat_feet.yaml").model_dump(mode="json", exclude_none=True)
    sc = scene_from_dict(d)
    passive = build_walker(Plant.from_scene(sc))
    d["walker"]["actuation"] = {"ankle_push_off": {"stiffness_n_m_per_rad": 40.0,
                                                   "rest_angle_rad": -0.2,
                                                   "constant_n_m": 7.0}}
    sc1 = scene_from_dict(d)
    powered = build_walker(Plant.from_scene(sc1))
    x = np.array([-0.3, 0.2, 0.05, -1.2, -1.1, -3.0])
    a = x[2]
    for ph0, ph1 in zip(passive.phases, powered.phases):
        f0, f1 = np.asarray(ph0.flow(0.0, x)), np.asarray(ph1.flow(0.0, x))
        if not ph0.name.startswith("heel_off"):
            np.testing.assert_array_equal(f0, f1)
            continue
        tau = -40.0 * (a + 0.2) - 7.0
        # the added acceleration is linear in the torque: tau times the response to a unit
        # torque, which two spring settings give (the ankle row of M^-1 scaled)
        d2 = dict(d, walker=dict(d["walker"], actuation={"ankle_push_off": {
            "constant_n_m": -1.0}}))
        sc = scene_from_dict(d2)
        unit = np.asarray(build_walker(Plant.from_scene(sc)).phases[
            [p.name for p in powered.phases].index(ph1.name)].flow(0.0, x)) - f0
        np.testing.assert_allclose(f1 - f0, tau * unit, rtol=1e-10, atol=1e-10)
    w = wl.Walker.from_scene(CONFIGS / "flat_feet_push_off.yaml")
    g = w.fixed_point()
    assert g.stable
    seg = simulate_steps(w.model, g.x, 1, w.solver).segments[0]
    led = trajectory_ledger(simulate_steps(w.model, g.x, 2, w.solver))
    # the ledger's ankle torque work (positive and negative parts, adaptive quadrature) is
    # the push-off's work (Gauss-Legendre on the heel-off pieces)
    np.testing.assert_allclose(led["actuator_work_positive"] + led["actuator_work_negative"],
                               ankle_push_off_work(w.model, seg), rtol=1e-9)


def test_linear_hip_torques_run_on_the_compiled_flows():
    """A hip torque linear in the hip angle and rate is a generated hip spring-damper (with
    its rest angle shifted by the constant): its flows are the compiled ones (the powered
    fixed point at the passive one's cost, scripts/bench_powered.py) and equal the Python
    flow of the same law; a phase-reference law runs the Python flow (the law in Python) or
    its own compiled flows (the law in the cfunc)."""
    from walkerlab.models.hybrid.actuated import Actuators

    sc = scene_from_dict(_compass({"torques": [{"joint": "hip", "law": LAW}]}))
    w = build_walker(Plant.from_scene(sc))
    assert all(ph.compiled is not None for ph in w.phases)
    acts = w.actuators
    assert isinstance(acts, Actuators)
    rng = np.random.default_rng(7)
    sc1 = scene_from_dict(_compass({"push_off": {"impulse_n_s": 0.0}}))
    passive = build_walker(Plant.from_scene(sc1))
    for _ in range(5):
        x = rng.normal(0, 0.3, 4)
        expect = np.asarray(passive.phases[0].flow(0.0, x), float)
        expect[2:] += acts.added_acceleration(0.0, x)
        np.testing.assert_allclose(w.phases[0].flow(0.0, x), expect, rtol=1e-12, atol=1e-12)
    ref = {"stiffness_n_m_per_rad": 40.0, "reference": {"phase_rad": [-0.3, 0.3],
                                                        "hip_angle_rad": [0.3, -0.3]}}
    sc2 = scene_from_dict(_compass({"torques": [{"joint": "hip", "law": ref}]}))
    # a phase-reference law: the Python flow, and compiled flows that evaluate the law
    # (tests/test_compiled_laws.py)
    assert all(ph.compiled is not None and not ph.compiled.batchable
               for ph in build_walker(Plant.from_scene(sc2)).phases)


def test_the_flat_footed_ankle_push_off_walks_on_level_ground():
    """configs/flat_feet_push_off.yaml (short toes, 25 N m from heel off to heel strike): a
    stable period-1 gait on level ground from the stored guess, with the numbers its header
    states (step period 0.7524 s, step length 0.4130 m, cost of transport 0.0637); the flat
    foot's ledger closes to 1e-9 of the step's kinetic energy (measured ~3e-11) and names
    where the push-off's work goes: the ankle damper, the heel strike (with the trailing
    ankle spring's release) and the foot slap; the cost of transport is the push-off's
    positive work over m g d (level ground)."""
    from walkerlab.analysis.gait.metrics import step_length

    w = wl.Walker.from_scene(CONFIGS / "flat_feet_push_off.yaml")
    assert w.model.slope_rad == 0.0
    g = w.fixed_point()
    assert g.residual < 1e-10 and g.stable
    assert g.step_period == pytest.approx(0.75238, abs=1e-5)
    assert max(abs(g.multipliers)) == pytest.approx(0.5234, abs=1e-3)
    traj = simulate_steps(w.model, g.x, 2, w.solver)
    led = trajectory_ledger(traj)
    ke = w.model.energies(g.x)[0]
    assert np.max(np.abs(led["closure"])) <= 1e-9 * ke
    d = step_length(w.model, traj.segments[0])
    assert d == pytest.approx(0.41298, abs=1e-5)
    np.testing.assert_allclose(led["energy_change"], 0.0, atol=1e-9 * ke)  # periodic
    assert np.all(led["damper_work"] < 0) and np.all(led["heel_strike_loss"] > 0)
    assert np.all(led["internal_collision_loss"] > 0)
    np.testing.assert_allclose(led["actuator_work_positive"], 5.164, rtol=1e-3)
    m, gr = w.model.total_mass_kg, w.model.params["gravity_m_per_s2"]
    np.testing.assert_allclose(led["cost_of_transport"],
                               led["actuator_work_positive"] / (m * gr * d), rtol=1e-12)
    assert led["cost_of_transport"][0] == pytest.approx(0.0637, abs=1e-4)


def test_table3_step_length_of_flat_feet_is_heel_to_heel():
    """Table 3's step length of a flat-footed walker: from the stance heel's touchdown point
    to the swing heel's, the rigid step (walkerlab.analysis.gait.metrics.step_length,
    0.4130 m for flat_feet_push_off.yaml); the stance ankle, heeled off at heel strike, read
    0.361 m before."""
    from walkerlab.analysis.gait.metrics import sample_trajectory, step_length
    from walkerlab.comparison.tables import gait_metrics

    w = wl.Walker.from_scene(CONFIGS / "flat_feet_push_off.yaml")
    traj = simulate_steps(w.model, w.fixed_point().x, 3, w.solver)
    m = gait_metrics(sample_trajectory(traj, 200.0))
    d = step_length(w.model, traj.segments[0])
    assert m["step_length_m"] == pytest.approx(d, abs=1e-9)
    assert m["step_length_left_m"] == pytest.approx(d, abs=1e-9)
    assert m["step_length_right_m"] == pytest.approx(d, abs=1e-9)
