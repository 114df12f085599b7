"""Actuators together on one walker, where each alone was offered (issue 48 item 5: no
walker the description allows is refused an actuator for lack of code): on flat feet, joint
torques with the ankle push-off and the push-off impulse at the toe; the ankle push-off on
legs that differ.

Tolerances: the steps integrate at rtol = atol = 1e-12 (the scene's solver); the energy
ledger's quadratures are Gauss-Legendre to 1e-12 of the kinetic energy, so it closes to
1e-9 of it (the project's ledger tolerance); two models of the same walker integrated at
1e-12 agree to ~1e-9 over a step (error growth through a step of ~0.75 s)."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene, scene_from_dict
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def _flat_push_off() -> dict:
    return load_scene(CONFIGS / "flat_feet_push_off.yaml").model_dump(exclude_none=True)


def _step(d: dict, n: int = 1, x0=None):
    scene = scene_from_dict(d)
    w = build_walker(Plant.from_scene(scene))
    if x0 is None:
        x0 = scene.fixedpoint.initial_guess.as_array(w.state_names())
    traj = simulate_steps(w, x0, n, Solver.from_settings(scene.solver), max_step_time=3.0)
    return w, traj


def test_flat_feet_take_joint_torques_with_both_push_offs_and_the_ledger_closes():
    """Flat feet with a hip torque (PD), a stance-ankle torque, the ankle push-off (25 N m
    from heel off) and a push-off impulse at the toe (refused before: "flat feet take hip
    torques alone today"): one step; the ledger's work of the joint torques + the ankle
    push-off + the impulse's work = the change of energy + collision and damper losses,
    to 1e-9 of the kinetic energy.  With zero torques the step is the push-offs' alone."""
    from walkerlab.analysis.gait.energy_modes import flat_step_ledger

    d = _flat_push_off()
    d["walker"]["actuation"]["push_off"] = {"impulse_n_s": 0.3}
    base = copy.deepcopy(d)
    d["walker"]["actuation"]["torques"] = [
        {"joint": "hip", "law": {"stiffness_n_m_per_rad": 2.0, "rest_angle_rad": 0.4,
                                 "damping_n_m_s_per_rad": 0.2}},
        # 2 N m: the torques' power keeps its sign through heel off (0.5 N m crosses 0
        # there once, and quad's split into positive and negative work misses 2.7e-5 J)
        {"joint": "stance_ankle", "law": {"constant_n_m": 2.0}}]
    w, traj = _step(d)
    seg = traj.segments[0]
    assert seg.termination == "heel_strike"
    led = flat_step_ledger(w, seg)
    ke = float(w.energies(seg.x_start)[0])
    assert abs(led["closure"]) <= 1e-9 * ke
    assert led["push_off_work"] > 0.0 and led["push_off_impulse"] == 0.3
    assert led["actuator_work_positive"] > 5.0  # the ankle push-off's ~5 J and the torques'
    # the torques at zero: the two push-offs' step (the same flows plus M^-1 B 0)
    for t in d["walker"]["actuation"]["torques"]:
        t["law"] = {"constant_n_m": 0.0}
    _w0, tz = _step(d)
    _wb, tb = _step(base)
    np.testing.assert_allclose(tz.segments[0].x_next, tb.segments[0].x_next, rtol=0,
                               atol=1e-9)
    assert tz.segments[0].t_end == pytest.approx(tb.segments[0].t_end, abs=1e-9)


def test_ankle_push_off_on_legs_that_differ_is_each_legs_own():
    """Legs that differ with an ankle push-off (refused before: "legs that differ are not
    supported yet"): leg1's ankle stiffer (150 N m/rad, leg2's 120).  Each step is the
    identical-legs walker's with the stance leg's numbers (the swing foot is massless and
    held at its rest angle: its spring does nothing): the first (leg2 in stance) the scene's
    own, the second (leg1 in stance) that of legs with 150 N m/rad ankles, from the first
    step's end - each heel off releases its own stance ankle's spring."""
    d = _flat_push_off()
    stiff = copy.deepcopy(d)
    stiff["walker"]["leg"]["foot"]["ankle"]["stiffness_n_m_per_rad"] = 150.0
    pair = copy.deepcopy(d)
    pair["walker"].pop("leg")
    pair["walker"]["legs"] = [copy.deepcopy(stiff["walker"]["leg"]),
                              copy.deepcopy(d["walker"]["leg"])]
    w, traj = _step(pair, 2)
    assert w.mirror is not None  # a stride of two different steps
    first, second = traj.segments
    _w1, ref1 = _step(d, 1)
    _w2, ref2 = _step(stiff, 1, first.x_next)
    for got, ref in ((first, ref1.segments[0]), (second, ref2.segments[0])):
        assert got.termination == ref.termination == "heel_strike"
        np.testing.assert_allclose(got.x_next, ref.x_next, rtol=0, atol=1e-9)
        assert got.t_end - got.t_start == pytest.approx(ref.t_end - ref.t_start, abs=1e-9)
    # and the stiffer ankle makes a different step (the check above is not vacuous)
    assert abs((second.t_end - second.t_start) - (first.t_end - first.t_start)) > 1e-4
    # with a hip torque and the toe's push-off as well: each step's walker its own
    pair["walker"]["actuation"]["push_off"] = {"impulse_n_s": 0.3}
    pair["walker"]["actuation"]["torques"] = [{"joint": "hip", "law": {"constant_n_m": 0.0}}]
    w3, t3 = _step(pair, 2)
    assert w3.mirror is not None and w3.mirror.actuators.torques is not None
    d["walker"]["actuation"]["push_off"] = {"impulse_n_s": 0.3}
    _w4, ref4 = _step(d, 1)
    np.testing.assert_allclose(t3.segments[0].x_next, ref4.segments[0].x_next, rtol=0,
                               atol=1e-9)


def _partly_massless(act, m_b=0.0, from_hip_a=0.5):
    """A biped whose legs carry a 5 kg point mass and a second body of ``m_b`` kg."""
    return scene_from_dict({"walker": {
        "model": "biped", "coordinates": "slope_relative", "gravity_m_per_s2": 9.81,
        "hip_mass_kg": 10.0, "actuation": act,
        "leg": {"length_m": 1.0, "bodies": [
            {"kind": "point_mass", "name": "a", "mass_kg": 5.0, "from_hip_m": from_hip_a},
            {"kind": "point_mass", "name": "b", "mass_kg": m_b, "from_hip_m": 0.9}]}},
        "slope": {"angle_rad": 0.01}})


def test_legs_with_some_massless_bodies_take_torques_and_a_push_off():
    """Legs with a massless body beside a massive one (refused before: "legs with some
    massless bodies are not supported"): the generated equations are the massless limit's
    link-angle rows, the torque's force mapped into them; flow and push-off + heel strike
    equal the walker whose second body weighs 1e-10 kg (regular equations) to O(1e-10)
    (seen: 4e-10 on accelerations of ~10 rad/s^2).  A torque across a link that carries no
    mass (the leg's only massive body at the hip: the swing leg's row is the limit's) is
    refused in one line: infinite angular acceleration; so is a push-off where a leg link
    moves no mass (the impulses leave its velocity undetermined: only Kuo's limiting rule
    for massless legs on a hip mass fixes it).  Massless legs under a torso (refused
    before: "massless legs need a hip mass and no torso") take torques likewise."""
    act = {"torques": [{"joint": "hip", "law": {"stiffness_n_m_per_rad": 3.0,
                                                "rest_angle_rad": 0.3,
                                                "damping_n_m_s_per_rad": 0.5}}],
           "push_off": {"impulse_n_s": 1.0}}
    s0, s1 = _partly_massless(act), _partly_massless(act, 1e-10)
    w0, w1 = (build_walker(Plant.from_scene(s)) for s in (s0, s1))
    rng = np.random.default_rng(7)
    for _ in range(3):
        x = np.array([0.2, 0.4, -0.9, 0.3]) + rng.normal(0.0, 0.05, 4)
        f0, f1 = w0.phases[0].flow(0.0, x), w1.phases[0].flow(0.0, x)
        np.testing.assert_allclose(f0, f1, rtol=0, atol=1e-8)
        sc = _partly_massless(None)
        assert np.max(np.abs(f0[2:] - build_walker(Plant.from_scene(sc)).phases[0].flow(
            0.0, x)[2:])) > 0.1  # the torque acts
        np.testing.assert_allclose(w0.reset(x), w1.reset(x), rtol=0, atol=1e-8)
        # the energy's rate along the flow is the torque's power (central differences of
        # step 1e-6: error ~1e-10 of the rate)
        h = 1e-6
        rate = (sum(w0.energies(x + h * f0)) - sum(w0.energies(x - h * f0))) / (2 * h)
        assert rate == pytest.approx(w0.actuators.power(0.0, x), rel=1e-7, abs=1e-9)
    # massless legs under a torso (refused before: "massless legs need a hip mass and no
    # torso"): the legs' angles move the torso, so no row is the limit's
    torso = load_scene(CONFIGS / "torso_bhm.yaml").model_dump(exclude_none=True)
    torso["walker"]["actuation"] = {"torques": act["torques"]}
    light = copy.deepcopy(torso)
    torso["walker"]["leg"]["bodies"][0]["mass_kg"] = 0.0
    light["walker"]["leg"]["bodies"][0]["mass_kg"] = 1e-10
    t0, t1 = (build_walker(Plant.from_scene(sc))
              for sc in (scene_from_dict(c) for c in (torso, light)))
    x = np.array([-0.2, 0.2, -1.0, -0.9])
    np.testing.assert_allclose(t0.phases[0].flow(0.0, x), t1.phases[0].flow(0.0, x),
                               rtol=1e-8, atol=1e-8)  # O(1e-10 kg): seen 8e-10 relative
    torso["walker"]["actuation"]["push_off"] = act["push_off"]
    with pytest.raises(ValueError, match=r"actuation\.push_off") as e:
        sc = scene_from_dict(torso)
        build_walker(Plant.from_scene(sc))
    assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match=r"torques\.0\.joint") as e:
        sc = _partly_massless({"torques": act["torques"]}, from_hip_a=0.0)
        build_walker(Plant.from_scene(sc))
    assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match=r"actuation\.push_off") as e:
        sc = _partly_massless({"push_off": act["push_off"]}, from_hip_a=0.0)
        build_walker(Plant.from_scene(sc))
    assert "\n" not in str(e.value)


def test_the_contact_view_carries_a_five_link_push_off():
    """The rigid view carries a push-off on free knees, and so does the contact view (its
    pulse at the trailing foot along the leg, as on every walker): the scene is set up with
    the push-off in its actuators, never dropped."""
    from walkerlab.models.contact.scene import contact_setup

    d = load_scene(CONFIGS / "rabbit.yaml").model_dump(exclude_none=True)
    d["walker"]["actuation"]["push_off"] = {"impulse_n_s": 1.0}
    scene = scene_from_dict(d)
    build_walker(Plant.from_scene(scene))  # the rigid view takes it
    acts = contact_setup(scene, plant=Plant.from_scene(scene)).actuators
    assert acts is not None and acts.spec.push_off.impulse_n_s == 1.0
