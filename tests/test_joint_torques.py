"""Joint torques generated from the walker description (issue 48, item 1): a torque at any
joint the walker has (hip between the legs, torso to leg, knee, ankle) on every rigid
structure, with the laws of ``walker.actuation.torques``.

Independent checks, sharing no code with the generator or the actuators: each joint's
angle is read from the generated *points* (link directions, ``atan2``) and its generalised
force ``Q_k = sum_i tau_i d(delta_i)/dq_k`` by central differences of those angles (step
1e-6: truncation ~1e-12, round-off ~1e-10 rad/rad); the flow's added acceleration must be
``M^-1 Q`` (to 1e-8 relative: the difference quotient's error); the energy ledger (generated
energies, quadrature of ``tau ddelta``) must close over a step to 1e-9 of the kinetic
energy (the integrator's rtol 1e-12 and the quadrature's tolerance give ~1e-11)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import walkerlab as wl
from walkerlab.analysis.gait.energy import trajectory_ledger
from walkerlab.config import load_scene, scene_from_dict
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

CONFIGS = Path(__file__).resolve().parents[1] / "configs"


def _scene(name: str, torques: list, **changes) -> dict:
    d = load_scene(CONFIGS / f"{name}.yaml").model_dump(mode="json", exclude_none=True)
    d["walker"]["actuation"] = {"torques": torques}
    d["solver"] = {**d.get("solver", {}), "rtol": 1e-12, "atol": 1e-12}
    d.update(changes)
    return d


def _angle(u, up=False):
    """Counter-clockwise angle of a link direction ``u`` (world axes), from the downward
    vertical (``up``: from the upward one)."""
    u = -np.asarray(u) if up else np.asarray(u)
    return np.arctan2(u[0], -u[1])


#: each link's direction from the walker's points: (from point, to point, measured upwards)
LINKS = {"stance": ("hip", "stance_foot", False), "swing": ("hip", "swing_foot", False),
         "torso": ("hip", "torso_mass", True),
         "stance_thigh": ("hip", "stance_knee", False),
         "swing_thigh": ("hip", "swing_knee", False),
         "stance_shank": ("stance_knee", "stance_foot", False),
         "swing_shank": ("swing_knee", "swing_foot", False),
         "stance_foot": ("stance_heel", "stance_toe", False)}
ARC = {"stance": ("hip", "stance_foot_centre", False), "swing": ("hip", "swing_foot_centre",
                                                                   False)}
FLAT = {"stance": ("hip", "stance_ankle", False), "swing": ("hip", "swing_ankle", False)}


def _joint_angle(points, first, second, links):
    def ang(link):
        a, b, up = links.get(link, LINKS[link])
        return _angle(np.asarray(points[b], float) - np.asarray(points[a], float), up)
    return ang(second) - ang(first)


def _independent_force(walker, x, joints, taus, links=None):
    """``Q (n,)`` [N m] from central differences of the joint angles read off the points."""
    links = links or {}
    n = len(walker.roles)
    Q = np.zeros(n)
    for (first, second), tau in zip(joints, taus):
        for k in range(n):
            e = np.zeros(2 * n)
            e[k] = 1e-6
            d = [_joint_angle(walker.points(x + s * e), first, second, links) for s in (1, -1)]
            Q[k] += tau * (d[0] - d[1]) / 2e-6
    return Q


def _check_force(w, passive, x, links=None, mass_matrix=None, constraint=None, phase=0):
    acts = w.actuators
    taus = acts.torques(0.0, x)
    Q = _independent_force(w, x, [tuple(j) for j in _named(acts)], taus, links)
    np.testing.assert_allclose(acts.generalised_force(0.0, x), Q, rtol=0,
                               atol=1e-8 * (1 + np.abs(Q).max()))
    n = len(w.roles)
    M = acts.fns["matrices"](x)[0] if mass_matrix is None else mass_matrix
    want = np.linalg.solve(M, Q)
    if constraint is not None:  # through the lock: M^-1 (Q + a lam), a . qdd = 0
        a = constraint
        Ma = np.linalg.solve(M, a)
        want = want - Ma * (a @ want) / (a @ Ma)
    got = w.phases[phase].flow(0.0, x)[n:] - passive.phases[phase].flow(0.0, x)[n:]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-8 * (1 + np.abs(want).max()))
    return Q


def _named(acts):
    return acts.links


def _ledger_closes(w, x, steps=1):
    traj = simulate_steps(w.model, x, steps, w.solver, max_step_time=w.max_step_time)
    led = trajectory_ledger(traj)
    ke = np.array([w.model.for_stance(s.stance_leg).energies(s.x_start)[0]
                   for s in traj.segments])
    assert np.all(np.isfinite(led["closure"]))
    assert np.all(np.abs(led["closure"]) <= 1e-9 * ke), (led["closure"], ke)
    work = led["actuator_work_positive"] + led["actuator_work_negative"]
    assert np.all(np.abs(work) > 1e-6)  # the torque does work: the ledger is exercised
    return led


ARC_TORQUE = [{"joint": "hip", "law": {"constant_n_m": 0.02, "stiffness_n_m_per_rad": 0.5},
               "max_torque_n_m": 1.0}]  # saturated: the actuated flow, not a hip spring


def test_hip_torque_on_arc_feet():
    """configs/round_feet.yaml's walker with a hip torque (refused before: "actuators need
    point feet"): a fixed point on its slope, its generalised force that of the joint angle
    read off the hip and the foot arcs' centres, its ledger closed over a step."""
    w = wl.Walker.from_scene(scene_from_dict(_scene("round_feet", ARC_TORQUE)))
    sc = load_scene(CONFIGS / "round_feet.yaml")
    passive = build_walker(Plant.from_scene(sc))
    gait = w.fixed_point()
    assert 0.5 < gait.step_period < 5.0
    np.testing.assert_allclose(w.model.reset(simulate_steps(
        w.model, gait.x, 1, w.solver).segments[0].x_end), gait.x, atol=1e-9)
    Q = _check_force(w.model, passive, gait.x, ARC)
    assert np.abs(Q).max() > 1e-3
    _ledger_closes(w, gait.x)


def test_stance_hip_pd_on_the_torso_walker():
    """configs/torso_bhm.yaml's walker (bisecting torso) with a PD torque between the torso
    and the stance leg (refused before: "a five-link biped's joint"): a fixed point, the
    generalised force of the angle stance leg minus torso read off the points (the torso
    being the legs' mean, the torque reaches both legs: +-tau/2), the ledger closed."""
    law = {"stiffness_n_m_per_rad": 0.3, "damping_n_m_s_per_rad": 0.02}
    w = wl.Walker.from_scene(scene_from_dict(_scene(
        "torso_bhm", [{"joint": "stance_hip", "law": law}])))
    sc = load_scene(CONFIGS / "torso_bhm.yaml")
    passive = build_walker(Plant.from_scene(sc))
    assert w.model.actuators.links == [("torso", "stance")]
    np.testing.assert_array_equal(w.model.actuators.B[:, 0], [-0.5, 0.5])  # (swing, stance)
    gait = w.fixed_point()
    assert 0.5 < gait.step_period < 2.0
    Q = _check_force(w.model, passive, gait.x)
    assert np.abs(Q).max() > 1e-3
    _ledger_closes(w, gait.x)


def test_knee_torque_on_the_kneed_walker():
    """configs/kneed.yaml's walker with a swing-knee PD torque (refused before): the free
    knee's flow gains ``M^-1 Q``, the locked phase takes it through the lock (``qdd`` keeps
    the knee locked), a fixed point and its ledger closed (the knee torque's work)."""
    law = {"stiffness_n_m_per_rad": 0.05, "damping_n_m_s_per_rad": 0.01,
           "rest_angle_rad": -0.3}
    w = wl.Walker.from_scene(scene_from_dict(_scene(
        "kneed", [{"joint": "swing_knee", "law": law}])))
    sc = load_scene(CONFIGS / "kneed.yaml")
    passive = build_walker(Plant.from_scene(sc))
    x = np.array([-0.2, -0.5, 0.2, -1.0, 0.5, -1.1])  # (swing thigh, swing shank, stance)
    Q = _check_force(w.model, passive, x)
    np.testing.assert_allclose(Q, [-w.model.actuators.torques(0, x)[0],
                                   w.model.actuators.torques(0, x)[0], 0.0], atol=1e-8)
    locked = w.model.phases[-1]
    assert locked.constraint is not None
    xl = np.array([-0.2, -0.2, 0.2, -1.0, -1.0, -1.1])
    acc = locked.flow(0.0, xl)[3:] - passive.phases[-1].flow(0.0, xl)[3:]
    assert abs(acc[1] - acc[0]) < 1e-12  # the lock takes the knee torque
    gait = w.fixed_point()
    assert 0.3 < gait.step_period < 3.0
    _ledger_closes(w, gait.x)


def test_stance_knee_torque_is_taken_by_the_lock():
    """The kneed walker's stance knee is locked straight: its torque has no generalised
    force and does no work (a zero row of ``B``)."""
    sc = scene_from_dict(_scene("kneed", [{"joint": "stance_knee",
                                          "law": {"constant_n_m": 1.0}}]))
    w = build_walker(Plant.from_scene(sc))
    assert not w.actuators.B.any()
    x = np.array([-0.2, -0.5, 0.2, -1.0, 0.5, -1.1])
    assert w.actuators.power(0.0, x) == 0.0


def test_a_joint_the_walker_lacks_is_one_line():
    for name, joint, has in (("round_feet", "swing_knee", "hip"),
                             ("paper", "stance_hip", "hip"),
                             ("kneed", "stance_ankle", "hip, stance_knee, swing_knee"),
                             ("torso_bhm", "swing_ankle", "hip, stance_hip, swing_hip")):
        with pytest.raises(ValueError) as e:
            sc = scene_from_dict(_scene(name, [{"joint": joint, "law": {}}]))
            build_walker(Plant.from_scene(sc))
        assert str(e.value) == (f"walker.actuation.torques.0.joint: {joint} is not a joint "
                                f"of this walker (its joints: {has})")


def _flat_unequal(torques):
    d = _scene("flat_feet", torques)
    leg = d["walker"].pop("leg")
    # 5.05 kg: with the double support after heel strike (kept under joint torques) the
    # 5.2 kg leg's walker falls within 10 steps from flat_feet.yaml's gait (so does the
    # passive one: no gait found); 5.05 kg walks on
    other = {**leg, "bodies": [{**leg["bodies"][0], "mass_kg": 5.05}]}
    d["walker"]["legs"] = [leg, other]
    return d


@pytest.mark.slow  # flat feet's torques run in Python (no compiled flow): ~1 min a stride
def test_hip_torque_on_flat_feet_with_legs_that_differ():
    """Flat feet with legs that differ (5 and 5.05 kg) and a hip torque (refused before:
    "legs that differ are not supported on flat feet yet"): each step's walker its own
    actuators; a period-2 fixed point (a stride) and the generalised force of the joint
    angle read off the hip and ankles, in heel contact (pinned heel) and foot flat (the
    foot's lock takes its share)."""
    from walkerlab.models.hybrid.mode_torques import mode_mass_matrix

    law = {"constant_n_m": 0.3, "stiffness_n_m_per_rad": 1.0}
    w = wl.Walker.from_scene(scene_from_dict(_flat_unequal([{"joint": "hip", "law": law}])))
    d = _flat_unequal([])
    del d["walker"]["actuation"]
    sc = scene_from_dict(d)
    passive = build_walker(Plant.from_scene(sc))
    m = w.model
    assert m.mirror is not None and m.mirror.actuators is not m.actuators
    x = np.array([-0.2, 0.15, 0.05, -1.0, -0.9, 0.3])
    for walker, ref in ((m, passive), (m.mirror, passive.mirror)):
        M = mode_mass_matrix(walker.actuators.fns["energies_heel"], x)
        _check_force(walker, ref, x, FLAT, mass_matrix=M)
        flat = [p.name for p in walker.phases].index("foot_flat:early_swing")
        _check_force(walker, ref, x, FLAT, mass_matrix=M, phase=flat,
                     constraint=np.array([0.0, 1.0, 1.0]))  # the sole's angle locked
    gait = w.fixed_point()
    assert 0.3 < gait.step_period < 3.0


def test_ankle_torque_on_flat_feet():
    """A stance-ankle torque on flat feet: the ankle coordinate's row alone (``+tau`` raises
    the toe), the joint angle read off the hip, ankle, heel and toe."""
    from walkerlab.models.hybrid.mode_torques import mode_mass_matrix

    torques = [{"joint": "stance_ankle", "law": {"constant_n_m": -2.0,
                                                 "stiffness_n_m_per_rad": 5.0}}]
    sc = scene_from_dict(_scene("flat_feet", torques))
    w = build_walker(Plant.from_scene(sc))
    sc1 = load_scene(CONFIGS / "flat_feet.yaml")
    passive = build_walker(Plant.from_scene(sc1))
    x = np.array([-0.2, 0.15, 0.05, -1.0, -0.9, 0.3])
    M = mode_mass_matrix(w.actuators.fns["energies_heel"], x)
    Q = _check_force(w, passive, x, FLAT, mass_matrix=M)
    np.testing.assert_allclose(Q, [0.0, 0.0, -2.0 - 5.0 * 0.05], atol=1e-8)


@pytest.mark.slow  # the quick suite keeps to its CPU budget (a few seconds)
def test_the_flat_foot_ledger_closes_with_an_ankle_torque():
    """configs/flat_feet.yaml with a stance-ankle spring-like torque: one step from the
    scene's start, the ledger (the torque's work ``int tau da`` over every mode) closes."""
    torques = [{"joint": "stance_ankle", "law": {"constant_n_m": -1.0,
                                                 "stiffness_n_m_per_rad": 2.0}}]
    w = wl.Walker.from_scene(scene_from_dict(_scene("flat_feet", torques)))
    passive = wl.Walker.from_scene(CONFIGS / "flat_feet.yaml")
    _ledger_closes(w, passive.fixed_point().x)
