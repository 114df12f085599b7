"""Virtual constraints designed by ``walkerlab optimize`` (``optimize.design:
virtual_constraints``; walkerlab.optimal.transcription.virtual_constraints): the collocation's
``delta^2`` expression against the restricted Poincare map's (walkerlab.analysis.gait.
zero_dynamics, numpy on the generated model: another code path), the stability bound met at
the optimum, the written scene's full-order multipliers containing ``delta^2``, and the bad
inputs refused in one line.

The end-to-end design of the three-link walker (configs/threelink_hzd.yaml's controller as
the start, 0.8 m/s, ``delta^2 <= 0.6``) takes ~10 s: marked slow.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.scripts_loader import load_file
from walkerlab.config import SceneError, scene_from_dict
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
THREELINK = yaml.safe_load((ROOT / "configs" / "threelink_hzd.yaml").read_text())
RABBIT = yaml.safe_load((ROOT / "configs" / "rabbit_hzd.yaml").read_text())
#: the three-link design: 0.8 m/s, delta^2 <= 0.6 (the scene's own controller: 0.889)
DESIGN = {"design": "virtual_constraints", "max_multiplier": 0.6, "target_speed_m_per_s": 0.8,
          "intervals": 20, "max_torque_n_m": 150.0, "friction_coefficient": 0.8}


def one_line(e) -> str:
    text = str(e.value)
    assert len(text.strip().splitlines()) == 1, text
    return text


@pytest.mark.parametrize("cfg", [THREELINK, RABBIT], ids=["threelink", "rabbit"])
def test_collocation_delta2_is_the_restricted_maps(cfg):
    """The CasADi ``delta^2(q-, alpha)`` (the symbolic derivation, CasADi's linear solve)
    equals :func:`impact_multiplier` (numpy on the generated flow's matrices and reset) at
    the scene's controller; round-off only (1e-12: both are a few 5x5 solves)."""
    import casadi as ca

    from walkerlab.analysis.gait.zero_dynamics import impact_multiplier
    from walkerlab.models.registry import build_walker
    from walkerlab.optimal.transcription.virtual_constraints import hzd_functions
    from walkerlab.walker.description import walker_data

    sc = scene_from_dict(copy.deepcopy(cfg))
    ctrl = build_walker(Plant.from_scene(sc)).actuators.controller
    fns = hzd_functions(walker_data(sc.walker, sc.slope.phi_rad),
                        sc.walker.actuation.virtual_constraints)
    d = ctrl.design
    got = float(fns.delta2(ca.DM(d.q_minus), ca.DM(d.alpha)))
    assert abs(got - impact_multiplier(ctrl)) < 1e-12
    # and the outputs vanish on the controller's surface at its ends (y = 0 at q-)
    y, _dy = fns.outputs(ca.DM(np.concatenate([d.q_minus, np.zeros(ctrl.n)])),
                         ca.DM(d.alpha), d.theta_plus, d.theta_minus)
    assert np.max(np.abs(np.array(y))) < 1e-10


@pytest.mark.parametrize("shift", [0.0, 0.03, -0.05])
def test_collocation_delta2_matches_the_hand_written_three_link_model(shift):
    """Against tests/independent/three_link.py (the book's closed forms of D and the heel
    strike, numpy, no walkerlab code): delta^2 of the swing leg's c_M moved by ``shift``
    [rad] (the heel strike at q1 = -c_M, q2 = c_M; q'- = (1, M (c_M - c_{M-1}) / (theta- -
    theta+)), theta+ = c_M).  Round-off only: 1e-12."""
    import casadi as ca

    from tests.independent import three_link as ref
    from walkerlab.optimal.transcription.virtual_constraints import hzd_functions
    from walkerlab.walker.description import walker_data

    sc = scene_from_dict(copy.deepcopy(THREELINK))
    fns = hzd_functions(walker_data(sc.walker, sc.slope.phi_rad),
                        sc.walker.actuation.virtual_constraints)
    alpha = np.array([o["bezier_rad"] for o in
                      THREELINK["walker"]["actuation"]["virtual_constraints"]["outputs"]])
    alpha[0, -1] += shift
    M = alpha.shape[1] - 1
    p = {"g": 9.8, "r": 1.0, "m": 5.0, "d": 0.5, "MH": 15.0, "MT": 10.0, "l": 0.5}
    q_m = np.array([-alpha[0, -1], alpha[0, -1], alpha[1, -1]])
    dth = q_m[0] - q_m[1]
    qd_m = np.array([1.0, *(M * (alpha[:, -1] - alpha[:, -2]) / dth)])
    xp = ref.impact(np.concatenate([q_m, qd_m]), p)
    b = np.ones(3)
    want = ((b @ ref.mass_matrix(xp[:3], p) @ xp[3:])
            / (b @ ref.mass_matrix(q_m, p) @ qd_m)) ** 2
    got = float(fns.delta2(ca.DM(q_m), ca.DM(alpha)))
    assert abs(got - want) < 1e-12


def _scene(base, optimize, name="design"):
    cfg = copy.deepcopy(base)
    cfg["name"] = name
    cfg["optimize"] = dict(optimize)
    return cfg


@pytest.mark.parametrize("value", [0.0, 1.0, 1.5])
def test_max_multiplier_outside_the_unit_interval_refused(value):
    with pytest.raises(SceneError) as e:
        scene_from_dict(_scene(THREELINK, {**DESIGN, "max_multiplier": value}))
    assert "optimize.max_multiplier" in one_line(e)


def test_max_multiplier_without_design_refused():
    opt = {k: v for k, v in DESIGN.items() if k != "design"}
    with pytest.raises(SceneError) as e:
        scene_from_dict(_scene(THREELINK, opt))
    assert "optimize.max_multiplier" in one_line(e)


@pytest.mark.parametrize("change, key", [
    ({"target_speeds_m_per_s": [0.5, 0.8]}, "optimize.target_speeds_m_per_s"),
    ({"objective": "peak_torque"}, "optimize.objective"),
    ({"push_off": "free"}, "optimize.push_off"),
])
def test_design_options_it_does_not_take_refused(change, key):
    """A speed list beside a single speed target, another objective, a push-off: one line
    naming the key."""
    with pytest.raises(SceneError) as e:
        scene_from_dict(_scene(THREELINK, {**DESIGN, **change}))
    assert key in one_line(e)


def test_design_on_a_walker_without_virtual_constraints_refused():
    from walkerlab.optimal.driver import check_scene

    cfg = yaml.safe_load((ROOT / "configs" / "threelink.yaml").read_text())
    sc = scene_from_dict(_scene(cfg, DESIGN))
    with pytest.raises(ValueError) as e:
        check_scene(sc, Plant.from_scene(sc).data)
    assert one_line(e).startswith("optimize.design")


def test_virtual_constraints_without_design_refused():
    """Open-loop torques would replace the controller: optimize asks for the design."""
    from walkerlab.optimal.driver import check_scene

    sc = scene_from_dict(_scene(RABBIT, {"target_speed_m_per_s": 0.6}))
    with pytest.raises(ValueError) as e:
        check_scene(sc, Plant.from_scene(sc).data)
    assert one_line(e).startswith("optimize.design")


def test_design_refused_where_the_table_refuses_it():
    """Straight legs without a torso (one actuator): the capability table's line."""
    from walkerlab.optimal.driver import check_scene
    from walkerlab.walker.kinds import KINDS

    cfg = yaml.safe_load((ROOT / "configs" / "powered_compass.yaml").read_text())
    cfg["walker"]["actuation"] = {"virtual_constraints": {
        "phase": {"link": "stance_leg"}, "outputs": [
            {"link": "swing_leg", "bezier_rad": [-0.2, -0.1, 0.0, 0.1, 0.2]}],
        "feedback": {"kind": "input_output_linearization", "kp_per_s2": 100, "kd_per_s": 20}}}
    sc = scene_from_dict(_scene(cfg, DESIGN))
    with pytest.raises(ValueError) as e:
        check_scene(sc, Plant.from_scene(sc).data)
    assert KINDS["straight_legs"].cell("virtual_constraints", "optimize") in one_line(e)


# -- the three-link walker designed end to end (slow) ------------------------------------

@pytest.fixture(scope="module")
def designed(tmp_path_factory):
    from walkerlab.io.schemas.optimize import load
    from walkerlab.stages import pipeline

    runs = tmp_path_factory.mktemp("runs")
    sc = scene_from_dict(_scene(THREELINK, DESIGN, "threelink_design"))
    out = pipeline.run("optimize", sc, runs, False)
    return load(out.path), out.path.parent


@pytest.mark.slow
def test_design_meets_the_stability_bound_and_the_target(designed):
    d, _folder = designed
    c = d.controllers[0]
    assert c.status == "Solve_Succeeded" and d.gait
    assert c.delta2 <= 0.6 + 1e-9  # active: the scene's own controller has 0.889
    assert abs(c.step_length_m / c.step_period_s - 0.8) < 1e-9
    assert c.max_torque_n_m <= 150.0 + 1e-6


@pytest.mark.slow
def test_collocated_delta2_is_the_written_controllers_restricted_map(designed):
    """The optimum's delta^2 (the collocation's expression at its q- of alpha) and the
    restricted map of the written scene's controller (its own q- found from c_M, its c_0,
    c_1 recomputed by invariant: true): 1e-8."""
    d, folder = designed
    from walkerlab.analysis.gait.zero_dynamics import zero_dynamics
    from walkerlab.config import load_scene
    from walkerlab.models.registry import build_walker

    c = d.controllers[0]
    sc = load_scene(folder / c.scene_file)
    zd = zero_dynamics(build_walker(Plant.from_scene(sc)).actuators.controller)
    assert abs(zd.delta2 - c.delta2) < 1e-8
    assert zd.exists
    np.testing.assert_allclose(
        [o.bezier_rad[2:] for o in sc.walker.actuation.virtual_constraints.outputs],
        np.asarray(c.bezier_rad)[:, 2:], rtol=0, atol=1e-15)


@pytest.mark.slow
def test_written_scene_full_order_multipliers_contain_delta2(designed):
    """``walkerlab fixedpoint``'s search on the written scene: one variational Floquet
    multiplier is delta^2 (1e-6), <= 0.6; the others are the feedback's (kd = 100/s over
    a 0.83 s step: exp(-50 T) ~ 1e-18, at the fixed point's tolerance)."""
    d, folder = designed
    from walkerlab.analysis.gait.scene import solve_scene
    from walkerlab.config import load_scene

    c = d.controllers[0]
    sc = load_scene(folder / c.scene_file)
    gait = solve_scene(sc, False, plant=Plant.from_scene(sc))[1].gait.result
    mu = np.asarray(gait.multipliers_variational)
    j = int(np.argmin(np.abs(mu - c.delta2)))
    assert abs(mu[j] - c.delta2) < 1e-6
    assert abs(mu[j]) <= 0.6 + 1e-6
    assert np.max(np.abs(np.delete(mu, j))) < 1e-6


@pytest.mark.slow
def test_written_scene_holds_the_coefficients_in_force(designed):
    """The written ``bezier_rad`` are the coefficients the checked controller runs (c_0,
    c_1 the impact map's, not the collocation's, which missed them by its transcription
    error, 2e-5 rad): rebuilt with ``invariant: true`` they come back bit for bit, and
    with ``invariant: false`` (the file taken as written) the controller is the same: its
    invariance residuals at round-off and the same zero-dynamics step period (1e-12 s;
    the collocation's c_0, c_1 gave one 2.4e-6 s off)."""
    d, folder = designed
    from walkerlab.analysis.gait.zero_dynamics import zero_dynamics
    from walkerlab.config import load_scene
    from walkerlab.models.registry import build_walker

    c = d.controllers[0]
    sc = load_scene(folder / c.scene_file)
    written = np.array([o.bezier_rad for o in sc.walker.actuation.virtual_constraints.outputs])
    ctrl = build_walker(Plant.from_scene(sc)).actuators.controller
    assert np.array_equal(ctrl.design.alpha, written)
    assert np.array_equal(np.asarray(c.bezier_rad), written)
    cfg = yaml.safe_load((folder / c.scene_file).read_text())
    cfg["walker"]["actuation"]["virtual_constraints"]["invariant"] = False
    sc1 = scene_from_dict(cfg)
    as_written = build_walker(Plant.from_scene(sc1)).actuators.controller
    assert as_written.design.residual_position < 1e-12
    assert as_written.design.residual_rate < 1e-9
    assert abs(zero_dynamics(as_written).step_period_s
               - zero_dynamics(ctrl).step_period_s) < 1e-12


@pytest.mark.slow
def test_the_design_says_its_collocated_and_its_closed_loop_speed(designed):
    """0.8 m/s is the collocated step's (its target, to IPOPT's tolerance); the closed loop
    of the written coefficients walks within 1e-3 of it (the transcription's error), and
    the header says both."""
    d, folder = designed
    c = d.controllers[0]
    loop = c.full_order_step_length_m / c.full_order_step_period_s
    assert abs(c.step_length_m / c.step_period_s - 0.8) < 1e-9
    assert 0 < abs(loop - 0.8) < 1e-3
    text = (folder / c.scene_file).read_text()
    assert f"({loop:.6g} m/s)" in text and "(0.8 m/s)" in text


@pytest.mark.slow
def test_an_impossible_design_is_recorded_as_failed_not_blamed_on_the_scene(tmp_path):
    """delta^2 <= 0.01 at 5 m/s with 1 N m and mu 0.01 cannot hold: IPOPT stops (here after
    60 iterations, optimize.max_iterations: the same on any machine) and optimize.h5
    records it; its last iterate's
    coefficients make no controller, which is said as the design's failure (not as an
    error naming the scene's outputs); the written scene's first line says it failed;
    the reason names the optimize fields to relax."""
    from walkerlab.io.schemas.optimize import load
    from walkerlab.report.figures_section import not_a_gait_reason
    from walkerlab.stages import pipeline

    sc = scene_from_dict(_scene(THREELINK, {
        "design": "virtual_constraints", "max_multiplier": 0.01, "target_speed_m_per_s": 5.0,
        "max_torque_n_m": 1.0, "friction_coefficient": 0.01, "max_iterations": 60}, "imp"))
    out = pipeline.run("optimize", sc, tmp_path, False)
    d = load(out.path)
    c = d.controllers[0]
    assert c.status != "Solve_Succeeded" and not d.gait
    assert (out.path.parent / c.scene_file).read_text().startswith("# FAILED: IPOPT ")
    why = not_a_gait_reason(d)
    assert why.startswith("the design is ") and "optimize.max_multiplier" in why
    assert "controller 1 (5 m/s): IPOPT" in why


# -- the shipped RABBIT design (configs/rabbit_hzd_optimal.yaml; slow: ~2 min) -----------

@pytest.fixture(scope="module")
def rabbit_designed(tmp_path_factory):
    from walkerlab.config import load_scene
    from walkerlab.io.schemas.optimize import load
    from walkerlab.stages import pipeline

    runs = tmp_path_factory.mktemp("runs")
    sc = load_scene(ROOT / "configs" / "rabbit_hzd_optimal.yaml")
    out = pipeline.run("optimize", sc, runs, False)
    return load(out.path), out.path.parent, runs


@pytest.mark.slow
def test_rabbit_controllers_at_two_speeds_are_stable(rabbit_designed):
    """Two controllers, one per target speed, each with delta^2 <= 0.6 met, the written
    scene's restricted map equal to the collocation's (1e-8) and its full-order closed
    loop's multipliers containing delta^2 (1e-6), the rest the feedback's."""
    d, folder, _runs = rabbit_designed
    assert [c.target_speed_m_per_s for c in d.controllers] == [0.5, 0.8]
    for c in d.controllers:
        assert c.status == "Solve_Succeeded"
        assert c.delta2 <= 0.6 + 1e-9
        assert abs(c.delta2_restricted - c.delta2) < 1e-8
        assert abs(c.delta2_multiplier - c.delta2_restricted) < 1e-6
        others = np.delete(c.multipliers, int(np.argmin(np.abs(c.multipliers - c.delta2))))
        assert np.max(np.abs(others)) < 1e-6
        assert abs(c.step_length_m / c.step_period_s - c.target_speed_m_per_s) < 1e-9
        assert (folder / c.scene_file).is_file()


@pytest.mark.slow
def test_rabbit_controller_walks_in_the_contact_model(rabbit_designed):
    """The 0.5 m/s controller's written scene in ``walkerlab contact-sim`` (the computed
    torque at the contact walker's role state, 11 strides): >= 20 heel strikes, the mean
    speed of the last 10 steps within 3 % of the rigid closed loop's (measured -1.0 %: the
    regularised friction lets the stance foot creep ~0.4 mm a step)."""
    import h5py

    from walkerlab.config import load_scene
    from walkerlab.stages import pipeline

    d, folder, runs = rabbit_designed
    c = d.controllers[0]
    out = pipeline.run("contact-sim", load_scene(folder / c.scene_file), runs, False)
    with h5py.File(out.path, "r") as f:
        t = f["events/heel_strike_times"][()]
        dist = f["ledger/steps/distance"][()]
    assert len(t) >= 20
    speed = np.mean(dist[-10:]) / np.mean(np.diff(t)[-10:])
    rigid = c.step_length_m / c.full_order_step_period_s
    assert abs(speed / rigid - 1) < 0.03


@pytest.mark.slow
def test_rabbit_controllers_heel_strike_impulse_inside_the_friction_cone(rabbit_designed):
    """The rigid heel strike of each written controller (scripts/hzd_heel_strike.py): its
    impulse on the new stance foot from the generated extended impact equals the momentum
    balance (1e-9 N s), lies inside the design's friction cone (|Lambda_t / Lambda_n| <=
    optimize.friction_coefficient 0.6; measured 0.278, 0.383: the cone the design puts on
    the stance force holds the strike's impulse too, unconstrained) and the trailing foot
    lifts off (measured 0.56, 0.51 m/s).  The stance force along the written controller's
    step stays in the cone to the transcription's error (2e-3; measured 0.446, 0.6003)."""

    from walkerlab.config import load_scene

    mod = load_file("scripts/hzd_heel_strike.py")
    d, folder, _runs = rabbit_designed
    for c in d.controllers:
        r = mod.rigid(load_scene(folder / c.scene_file))
        np.testing.assert_allclose(r["impulse_momentum"], r["impulse_world"], atol=1e-9)
        assert r["impulse_n"] > 0
        assert abs(r["impulse_t"] / r["impulse_n"]) <= 0.6
        assert r["trailing_normal"] > 0
        # the stance force's cone holds on the closed loop to the transcription's error
        # (the collocation bounds it at its points; 0.6003 measured at the 0.8 m/s step's end)
        assert np.max(r["stance_ratio"]) <= 0.6 + 2e-3


@pytest.mark.slow
@pytest.mark.parametrize("i", [0, 1])
def test_rabbit_controller_walks_in_mujoco(rabbit_designed, i, tmp_path):
    """Each written controller's MJCF export walks in MuJoCo under the export's stepping
    loop with the scene's feedback: >= 20 heel strikes in 21.5 rigid periods, the speed
    after the first strike within 3 % of the rigid closed loop's.  The export's contact
    time constant is the linearised IMPACT law's shrunk 4 times with the timestep
    (walkerlab.export.mjcf_scene.MJCF_CONTACT_SHRINK): the step period -0.03 % at 0.5 m/s,
    +1.26 % at 0.8 m/s (at the linearised one: -3.6 % at 0.8 m/s, MuJoCo's soft heel
    strike)."""
    pytest.importorskip("mujoco")
    from walkerlab.config import load_scene
    from walkerlab.export.mujoco_walk import virtual_constraint_feedback, walk
    from walkerlab.stages import export as export_stage

    d, folder, _runs = rabbit_designed
    c = d.controllers[i]
    sc = load_scene(folder / c.scene_file)
    out = export_stage.write(sc, tmp_path, "mjcf")
    run = walk(out.path, 21.5 * c.full_order_step_period_s,
               feedback=virtual_constraint_feedback(sc, Plant.from_scene(sc).data))
    assert not run.fell
    assert len(run.times_s) >= 20
    speed = (run.positions_m[-1] - run.positions_m[1]) / (run.times_s[-1] - run.times_s[1])
    rigid = c.step_length_m / c.full_order_step_period_s
    assert abs(speed / rigid - 1) < 0.03


# -- the swing foot's clearance and the contact views of a design -----------------------

def test_the_straight_legs_clearance_bound_holds_outside_the_mid_stance_window_only():
    """The bound is the clearance c wherever the swing foot is at least W = 2 sqrt(2 c l)
    from the stance foot along the ground, and drops (continuously) below any real dip at
    the stance foot, where straight legs pass the ground line: W = 0.2 m for 5 mm on a
    1 m leg."""
    from walkerlab.optimal.transcription.virtual_constraints import (
        MID_STANCE_DIP_M,
        clearance_bound,
        mid_stance_window,
    )

    W = mid_stance_window(0.005, 1.0)
    assert W == pytest.approx(0.2, rel=1e-12)
    d = np.array([-0.5, -W, -0.9 * W, 0.0, 0.5 * W, W, 0.3])
    b = np.array([float(clearance_bound(v, 0.005, W)) for v in d])
    assert np.all(b[[0, 1, 5, 6]] == 0.005)
    assert b[3] == pytest.approx(-MID_STANCE_DIP_M, abs=1e-15)
    assert b[3] < b[4] < b[2] < 0.0  # lifted towards the stance foot


def test_a_design_scene_without_contact_gets_the_controllers_contact_law():
    """The written controller scene of a design scene without a contact section carries
    the paper's law with friction 10 times nearer Coulomb's (10 and 100 mm/s) and a
    contact_sim section (contact-sim runs it); a scene with its own sections keeps them."""
    from walkerlab.config import load_scene
    from walkerlab.optimal.virtual_constraints import contact_scene

    sc = contact_scene(scene_from_dict(_scene(THREELINK, DESIGN)))
    assert sc.contact is not None and sc.contact_sim is not None
    assert sc.contact.stiction_velocity_mm_per_s == 10.0
    assert sc.contact.friction_velocity_mm_per_s == 100.0
    rabbit = load_scene(ROOT / "configs" / "rabbit_hzd_optimal.yaml")
    assert contact_scene(rabbit) is rabbit


#: the issue's three-link design: 0.6 m/s, delta^2 <= 0.7, 25 intervals, 120 N m, mu 0.6,
#: the swing foot 5 mm clear outside the mid-stance pass
SLOW_DESIGN = {"design": "virtual_constraints", "max_multiplier": 0.7,
               "target_speed_m_per_s": 0.6, "intervals": 25, "max_torque_n_m": 120.0,
               "friction_coefficient": 0.6, "min_clearance_m": 0.005}


@pytest.fixture(scope="module")
def slow_designed(tmp_path_factory):
    from walkerlab.io.schemas.optimize import load
    from walkerlab.stages import pipeline

    runs = tmp_path_factory.mktemp("runs")
    sc = scene_from_dict(_scene(THREELINK, SLOW_DESIGN, "threelink_slow"))
    out = pipeline.run("optimize", sc, runs, False)
    return load(out.path), out.path.parent, runs


@pytest.mark.slow
def test_a_slow_three_link_design_clears_the_ground_outside_mid_stance(slow_designed):
    """The swing foot >= 5 mm above the ground at every interior collocation point farther
    than W = 0.2 m from the stance foot (the transcription's tolerance 1e-9); inside, the
    straight legs' pass (measured: 0.05 mm below the ground line).  The friction ratio
    within a third of the contact model's mu_s 0.9 (the design's 0.6 tightened)."""
    d, _folder, _runs = slow_designed
    c = d.controllers[0]
    assert c.status == "Solve_Succeeded" and d.gait
    assert c.mid_stance_window_m == pytest.approx(0.2, rel=1e-12)
    assert c.min_clearance_m >= 0.005 - 1e-9
    assert c.mid_stance_low_m < 0.005  # the pass the window exempts
    assert c.friction_ratio <= 0.3 + 1e-6


@pytest.mark.slow
def test_a_slow_three_link_design_walks_steadily_in_contact_within_3_percent(slow_designed):
    """optimize.h5's contact replay (the written scene's contact law, from the rigid fixed
    point, 6 strides): >= 10 heel strikes, steps that settle, the last 4 steps' period and
    speed within 3 % of the rigid closed loop's (measured +1.27 %, -1.27 %; with the
    contact defaults' 100 mm/s stiction and mu 0.6 the steps lengthened 0.908 -> 1.10 s)."""
    d, _folder, _runs = slow_designed
    c = d.controllers[0]
    assert c.contact_heel_strikes >= 10 and c.contact_steady == 1.0, d.contact_outcome
    assert c.contact_step_period_s == pytest.approx(c.full_order_step_period_s, rel=0.03)
    assert c.contact_speed_m_per_s == pytest.approx(
        c.step_length_m / c.full_order_step_period_s, rel=0.03)


@pytest.mark.slow
def test_a_slow_three_link_design_walks_in_mujoco_within_3_percent(slow_designed, tmp_path):
    """The written scene's MJCF (fixedpoint, then export) walks 20 heel strikes in MuJoCo
    with its step period and speed within 3 % of the rigid closed loop's (measured period
    -1.12 %; +11 % before the design's friction cone was tightened to a third of mu_s)."""
    pytest.importorskip("mujoco")
    from walkerlab.config import load_scene
    from walkerlab.export.mujoco_walk import virtual_constraint_feedback, walk
    from walkerlab.stages import export as export_stage
    from walkerlab.stages import pipeline

    d, folder, runs = slow_designed
    c = d.controllers[0]
    sc = load_scene(folder / c.scene_file)
    pipeline.run("fixedpoint", sc, runs, False)
    out = export_stage.write(sc, runs, "mjcf")
    run = walk(out.path, 21.5 * c.full_order_step_period_s,
               feedback=virtual_constraint_feedback(sc, Plant.from_scene(sc).data))
    assert not run.fell and len(run.times_s) >= 20
    T = np.mean(np.diff(run.times_s[1:]))
    assert T == pytest.approx(c.full_order_step_period_s, rel=0.03)
    speed = (run.positions_m[-1] - run.positions_m[1]) / (run.times_s[-1] - run.times_s[1])
    assert speed == pytest.approx(c.step_length_m / c.full_order_step_period_s, rel=0.03)


# -- what a design writes into the run folder ---------------------------------------------

def _controller(scene_file, status="Solve_Succeeded", length=0.5, loop_length=0.499992):
    """A designed controller's record (the three-link scene's own coefficients)."""
    from walkerlab.io.schemas.optimize import ControllerData

    return ControllerData(
        target_speed_m_per_s=0.5, bezier_rad=GIVEN_ALPHA, output_names=("swing_leg", "torso"),
        step_period_s=1.0, step_length_m=length, objective=1.0, effort=1.0, delta2=0.6,
        delta2_restricted=0.6, existence_margin=-1.0, restricted_step_period_s=1.0,
        full_order_step_period_s=1.0, orbit_shift=0.0, multipliers=np.zeros(6, complex),
        delta2_multiplier=0.6, max_torque_n_m=10.0, max_output=0.0, max_output_rate=0.0,
        status=status, iterations=10, wall_time_s=1.0, build_time_s=1.0,
        scene_file=scene_file, full_order_step_length_m=loop_length)


GIVEN_ALPHA = np.array([o["bezier_rad"] for o in
                        THREELINK["walker"]["actuation"]["virtual_constraints"]["outputs"]])


def test_a_rerun_with_fewer_speeds_leaves_exactly_the_artifacts_controller_scenes(
        tmp_path, monkeypatch):
    """An earlier design's ``<scene>_controller_2.yaml`` is removed when ``optimize.h5``
    holds one controller; another scene's and other files stay."""
    from types import SimpleNamespace

    from walkerlab.stages import optimize as stage

    sc = scene_from_dict(_scene(THREELINK, DESIGN, "s"))
    for name in ("s_controller_1.yaml", "s_controller_2.yaml", "t_controller_2.yaml",
                 "s_controller_2.yaml.bak"):
        (tmp_path / name).write_text("old\n")
    art = tmp_path / "optimize.h5"
    monkeypatch.setattr(stage.schema, "load", lambda p: SimpleNamespace(
        controllers=(_controller("s_controller_1.yaml"),), violations=""))
    stage.write_controller_scenes(sc, art)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "s_controller_1.yaml", "s_controller_2.yaml.bak", "t_controller_2.yaml"]
    assert (tmp_path / "s_controller_1.yaml").read_text().startswith("# Written by")


def test_the_written_scene_says_which_speed_is_the_collocations_and_which_it_walks():
    """The 0.5 m/s of a design is the collocated step's (its target); the coefficients
    written walk 0.499992 m/s on the rigid model: the header and the source say both."""
    from walkerlab.optimal.virtual_constraints import controller_scene_text

    sc = scene_from_dict(_scene(THREELINK, DESIGN, "s"))
    text = controller_scene_text(sc, _controller("s_controller_1.yaml"), "s_controller_1")
    head = [ln for ln in text.splitlines() if ln.startswith("#")]
    assert any("Collocated step (the design's targets hold here)" in ln and "(0.5 m/s)" in ln
               for ln in head)
    assert any("Closed loop of the coefficients below" in ln and "(0.499992 m/s)" in ln
               for ln in head)
    body = yaml.safe_load(text)
    assert "collocated 0.5 m/s, the closed loop walks 0.499992 m/s" in body["source"]
    assert "FAILED" not in text


def test_a_failed_designs_scene_says_it_failed_in_its_first_line():
    from walkerlab.optimal.virtual_constraints import controller_scene_text

    sc = scene_from_dict(_scene(THREELINK, DESIGN, "s"))
    c = _controller("s_controller_1.yaml", status="Restoration_Failed", loop_length=np.nan)
    text = controller_scene_text(sc, c, "s_controller_1", "controller 1 (0.5 m/s): IPOPT "
                                 "Restoration_Failed, largest violations the friction cone 0.3")
    first = text.splitlines()[0]
    assert first.startswith("# FAILED: IPOPT Restoration_Failed, not a designed controller")
    assert "the friction cone 0.3" in text.splitlines()[1]
    assert yaml.safe_load(text)["source"].startswith("FAILED: IPOPT Restoration_Failed")


@pytest.mark.parametrize("change, says", [
    ({"max_iterations": 0}, "optimize.max_iterations"),
    ({"max_iterations": 2.5}, "optimize.max_iterations"),
])
def test_a_design_is_bounded_by_iterations_given_as_a_whole_number(change, says):
    """IPOPT's bound is its iterations (work, the same on any machine): a positive whole
    number, refused in one line otherwise; given, it reaches IPOPT's ``max_iter``."""
    with pytest.raises(SceneError) as e:
        scene_from_dict(_scene(THREELINK, {**DESIGN, **change}))
    assert says in one_line(e)
    sc = scene_from_dict(_scene(THREELINK, {**DESIGN, "max_iterations": 7}))
    assert sc.optimize.max_iterations == 7 and sc.optimize.cpu_budget_s is None


def test_iterations_without_design_refused():
    opt = {**{k: v for k, v in DESIGN.items() if k not in ("design", "max_multiplier")},
           "max_iterations": 10}
    with pytest.raises(SceneError) as e:
        scene_from_dict(_scene(THREELINK, opt))
    assert "optimize.max_iterations" in one_line(e)


def test_a_design_a_cpu_limit_stopped_is_marked_never_reused():
    """A controller IPOPT stopped at the user's CPU-time limit depends on the machine:
    optimize.h5 is marked not_final (never reused); one stopped by its iterations is a
    result."""
    from types import SimpleNamespace as NS

    from walkerlab.stages.optimize import cpu_limited

    data = NS(controllers=[NS(status="Solve_Succeeded"), NS(status="Maximum_CpuTime_Exceeded")])
    assert cpu_limited(data) == "controller(s) 2: optimize.cpu_budget_s, a CPU-time limit"
    assert cpu_limited(NS(controllers=[NS(status="Maximum_Iterations_Exceeded")])) == ""
    assert cpu_limited(NS(controllers=None)) == ""
