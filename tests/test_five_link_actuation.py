"""Joint torques on the five-link biped: the generated flow with ``M^-1 B tau`` against the
independent Lagrangian with the torques as generalised forces of its relative joint
coordinates (tests/independent/five_link.py), the phase variable and the PD law by hand,
the torques' power against the energy rate, and one-line refusals."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from tests.independent import five_link as ref
from tests.test_five_link import SCENE, P, from_ref, states, to_ref
from walkerlab.config import scene_from_dict
from walkerlab.models.actuation import TorqueLaws
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

#: every test here shares the independent sympy model (tests/independent/five_link.py, ~8 s
#: of CPU to build): one worker builds it once
pytestmark = pytest.mark.xdist_group("five_link_reference")

JOINTS = ("stance_hip", "swing_hip", "stance_knee", "swing_knee")
CONSTANT = {"stance_hip": 7.0, "swing_hip": -3.0, "stance_knee": 11.0, "swing_knee": -5.0}


def scene_with(torques, push_off=None):
    cfg = copy.deepcopy(SCENE)
    cfg["walker"]["actuation"] = {"torques": torques}
    if push_off is not None:
        cfg["walker"]["actuation"]["push_off"] = push_off
    return scene_from_dict(cfg)


@pytest.fixture(scope="module")
def constant_walker():
    sc = scene_with([{"joint": j, "law": {"constant_n_m": CONSTANT[j]}}
                                    for j in JOINTS])
    return build_walker(Plant.from_scene(sc))


def test_constant_torques_match_generalised_forces_of_joint_coordinates(constant_walker):
    """+tau at a hip flexes it (thigh forward of the torso), +tau at a knee extends it: in
    the reference's relative coordinates the torques are the generalised forces."""
    Q = [0.0] + [CONSTANT[j] for j in JOINTS]
    for x in states():
        r, dr = to_ref(x)
        want = from_ref(ref.acceleration(r, dr, P, Q))
        got = constant_walker.phases[0].flow(0.0, x)[5:]
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * max(1, abs(want).max()))
        passive = from_ref(ref.acceleration(r, dr, P))
        assert np.abs(want - passive).max() > 1.0  # the torques matter at this tolerance


def test_power_is_the_energy_rate(constant_walker):
    """dE/dt along the actuated flow (complex step) = sum tau ddelta (the ledger's power)."""
    w = constant_walker
    for x in states():
        f = w.phases[0].flow(0.0, x)
        dE = np.imag(sum(w.energies(x + 1j * 1e-30 * f))) / 1e-30
        power = w.actuators.power(0.0, x)
        assert abs(power) > 1.0
        assert dE == pytest.approx(power, abs=1e-10 * max(1.0, abs(power)))


def test_pd_law_reads_the_joint_angle_and_the_virtual_stance_leg():
    """PD tracking of a linear reference of the phase variable, by hand: s is the angle of
    the line from the hip to the stance foot (atan(-hip_x / hip_y)), ds its rate."""
    K, D, a, b = 300.0, 20.0, 0.3, -0.7  # reference h(s) = a + b s
    phase = [-0.6, 0.6]
    sc = scene_with([{"joint": "stance_knee", "law": {
        "stiffness_n_m_per_rad": K, "damping_n_m_s_per_rad": D,
        "reference": {"phase_rad": phase, "angle_rad": [a + b * s for s in phase],
                      "interpolation": "linear"}}}])
    w = build_walker(Plant.from_scene(sc))
    for x in states():
        hip = w.points(x)["hip"]
        s = np.arctan(-hip[0] / hip[1])
        h = 1e-7
        xs = [x + k * h * np.concatenate([x[5:], np.zeros(5)]) for k in (-1, 1)]
        ds = np.diff([np.arctan(-w.points(z)["hip"][0] / w.points(z)["hip"][1])
                      for z in xs])[0] / (2 * h)
        knee, dknee = x[0] - x[1], x[5] - x[6]  # stance shank - stance thigh
        tau = -K * (knee - (a + b * s)) - D * (dknee - b * ds)
        assert w.actuators.torques(0.0, x)[0] == pytest.approx(tau, rel=1e-7, abs=1e-8)


def test_shared_spline_equals_each_laws_own():
    """One vector-valued spline for all four references gives each law's own numbers
    (bit for bit, complex step included)."""
    phase = [-0.4, -0.1, 0.0, 0.2, 0.4]
    torques = [{"joint": j, "max_torque_n_m": 50.0, "law": {
        "stiffness_n_m_per_rad": 500.0, "damping_n_m_s_per_rad": 30.0,
        "reference": {"phase_rad": phase, "angle_rad": [np.sin(3 * s + i) for s in phase]}}}
        for i, j in enumerate(JOINTS)]
    sc = scene_with(torques)
    w = build_walker(Plant.from_scene(sc))
    acts = w.actuators
    own = TorqueLaws(acts.spec.torques)
    for x in states():
        for z in (x, x + 1j * 1e-25 * np.arange(10)):
            args = acts.joint_angles(z)
            np.testing.assert_array_equal(acts.laws.each(*args, 0.0), own.each(*args, 0.0))


@pytest.mark.parametrize("edit, message", [
    (lambda c: c["actuation"]["torques"][0].update(joint="stance_ankle"), "torques.0.joint"),
    (lambda c: (c.pop("torso"), c["actuation"]["torques"][0].update(joint="swing_hip")),
     "torques.0.joint"),
])
def test_refusals_name_the_field(edit, message):
    cfg = copy.deepcopy(SCENE)
    cfg["walker"]["actuation"] = {"torques": [{"joint": "stance_hip", "law": {}}]}
    edit(cfg["walker"])
    with pytest.raises(ValueError) as e:
        sc = scene_from_dict(cfg)
        build_walker(Plant.from_scene(sc))
    assert message in str(e.value) and "\n" not in str(e.value)


def test_five_link_joint_on_a_straight_legged_walker_is_refused():
    cfg = {"walker": {"model": "compass_gait", "leg_length_m": 1.0, "leg_mass_kg": 5.0,
                      "hip_mass_kg": 10.0, "leg_mass_from_foot_m": 0.5,
                      "actuation": {"torques": [{"joint": "swing_knee", "law": {}}]}},
           "slope": {"angle_rad": 0.0}}
    with pytest.raises(ValueError, match=r"torques\.0\.joint: swing_knee"):
        sc = scene_from_dict(cfg)
        build_walker(Plant.from_scene(sc))


def test_reference_tables_take_angle_rad_or_hip_angle_rad_once():
    from walkerlab.config.actuation import PhaseReference

    a = PhaseReference(phase_rad=[0, 1], hip_angle_rad=[0.1, 0.2])
    assert a.model_dump() == {"phase_rad": [0.0, 1.0], "hip_angle_rad": [0.1, 0.2],
                              "interpolation": "cubic"}  # as before: no new key
    b = PhaseReference(phase_rad=[0, 1], angle_rad=[0.1, 0.2])
    assert b.values_rad == [0.1, 0.2] and "hip_angle_rad" not in b.model_dump()
    for bad in ({}, {"angle_rad": [0, 1], "hip_angle_rad": [0, 1]}, {"angle_rad": [0, 1, 2]}):
        with pytest.raises(ValueError):
            PhaseReference(phase_rad=[0, 1], **bad)


def test_push_off_matches_an_independent_impulse_and_is_the_heel_strike_at_zero():
    """Kuo's push-off on the five-link biped (issue 48 item 5: refused before): the reset
    equals the independent relative-coordinate model's push-off + heel strike
    (tests/independent/five_link.py, its own De, E) to round-off; at P = 0 it is the passive
    heel strike; the plastic heel strike after it loses kinetic energy."""
    impulse = 4.0
    sc = scene_with([], push_off={"impulse_n_s": impulse})
    w = build_walker(Plant.from_scene(sc))
    sc1 = scene_with([], push_off={"impulse_n_s": 0.0})
    w0 = build_walker(Plant.from_scene(sc1))
    sc2 = scene_from_dict(SCENE)
    passive = build_walker(Plant.from_scene(sc2))
    for x in states():
        r, dr = to_ref(x)
        r_new, dr_new = ref.push_off_heel_strike(r, dr, P, impulse)
        got = w.reset(x)
        np.testing.assert_allclose(got[:5], from_ref(r_new), atol=1e-12)
        want = from_ref(dr_new)
        np.testing.assert_allclose(got[5:], want, atol=1e-9 * max(1, abs(want).max()))
        # P = 0: the generated passive heel strike, to round-off
        np.testing.assert_allclose(w0.reset(x), passive.reset(x), rtol=0, atol=1e-12)
        tr = w.actuators.transition(x)
        assert tr["impulse"] == impulse and tr["ke_plus"] <= tr["ke_push_off"] + 1e-12

