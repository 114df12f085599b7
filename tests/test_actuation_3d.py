"""Actuation of the 3D straight-legged walker in the rigid model (``walker.actuation`` on
``walker.space: 3d``; ``configs/hip_width_powered.yaml``): the planar walkers' hip torque and
push-off (Kuo 2002) through the same actuators, against the Newton's-law model of
``tests/test_hip_roll_3d.py`` (its own rotations, angular velocities and extended impact:
no code shared with the generator), the energy ledger, and the planar powered walker as the
3D walker of zero hip width."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

import walkerlab as wl
from tests.test_hip_roll_3d import LEAN, STANCE, SWING, SWROLL, _states, reference_of
from walkerlab.analysis.gait.energy import trajectory_ledger
from walkerlab.config.schema import Scene
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
LAW = {"constant_n_m": 1.5, "stiffness_n_m_per_rad": 20.0, "damping_n_m_s_per_rad": 0.5,
       "rest_angle_rad": 0.1}


def _walkers(actuation):
    """The stabilised 3D walker with ``actuation``, without it, and the reference."""
    raw = yaml.safe_load((ROOT / "configs" / "hip_width_stabilised.yaml").read_text())
    passive = Scene.model_validate(raw)
    raw["walker"]["actuation"] = actuation
    scene = Scene.model_validate(raw)
    return (build_walker(Plant.from_scene(scene)),
            build_walker(Plant.from_scene(passive)), reference_of(scene),
            scene.walker.hip_width_m)


def _law_torque(x):
    """The hip law of :data:`LAW` at the state ``x``: ``delta = swing - stance``."""
    d, dd = x[SWING] - x[STANCE], x[5 + SWING] - x[5 + STANCE]
    return (LAW["constant_n_m"] - LAW["stiffness_n_m_per_rad"] * (d - LAW["rest_angle_rad"])
            - LAW["damping_n_m_s_per_rad"] * dd)


def test_the_3d_hip_torque_is_the_virtual_work_of_a_torque_pair_at_the_pitch_joints():
    """The actuated flow's added acceleration, times the mass matrix, is the generalised
    force of ``+tau`` on the swing leg about its pitch axis ``R(roll_sw) z`` and ``-tau`` on
    the stance leg about its own ``R(lean) z`` (virtual work ``tau a . delta omega`` with
    each body's angular-velocity Jacobian, the reference's), on states whose rolls all
    differ, both hip sides; 1e-11 relative to max(1, |Q|) (two 5x5 solves' round-off; a
    generalised force along the rolls, or only on one leg, misses by ~tau)."""
    acts = {"torques": [{"joint": "hip", "law": LAW}]}
    walker, passive, ref, _w = _walkers(acts)
    for w_act, w_pas in ((walker, passive), (walker.mirror, passive.mirror)):
        for x in _states(11, 4):
            q = x[:5]
            tau = _law_torque(x)
            a_sw, a_st = ref._R(q[SWROLL]) @ ref.z, ref._R(q[LEAN]) @ ref.z
            Q = tau * (a_sw @ ref._omega_jacobian(SWROLL, SWING, q)
                       - a_st @ ref._omega_jacobian(LEAN, STANCE, q))
            M = np.asarray(w_pas.matrices(x)[0], float)
            got = M @ (w_act.phases[0].flow(0.0, x) - w_pas.phases[0].flow(0.0, x))[5:]
            assert np.max(np.abs(got - Q) / np.maximum(1.0, np.abs(Q))) < 1e-11
            assert np.max(np.abs(Q[[LEAN, 3, SWROLL]])) < 1e-14  # no roll moment: pitch only
            assert abs(Q[SWING]) > 0.1  # the check is not empty


def _push_off_reference(ref, w, x, P):
    """Push-off then heel strike by impulse and momentum (the reference's extended
    coordinates ``[q, p]``, ``p`` the stance foot, free): ``M_e (dq_po - dq-) = [0; P e]``
    with ``e`` the unit vector from the stance foot to the stance hip, then ``M_e (dq+ -
    dq_po) = E^T F``, ``E dq+ = 0`` (the new foot at rest), the roles swapped."""
    hip_st = ref.terms(w)[2]
    q, dq = x[:5], x[5:]
    Me = ref.extended_mass(w, q, dq)
    r = ref.kin(hip_st, q, dq)[0]
    e = r / np.linalg.norm(r)
    dqe = np.concatenate([dq, np.zeros(3)])
    dqe_po = dqe + np.linalg.solve(Me, np.concatenate([np.zeros(5), P * e]))
    sol = ref.plastic_impact(w, q, dq, dqe_po)
    order = [SWROLL, STANCE, SWING, 3, LEAN]
    return np.concatenate([q[order], sol[:5][order]]), dqe, dqe_po, Me


@pytest.mark.parametrize("P", [0.0, 1.0, 3.0])
def test_the_3d_push_off_and_heel_strike_match_impulse_and_momentum(P):
    """The actuated reset (push-off ``P`` along the trailing leg, then the plastic heel
    strike) against the reference's impulse-momentum solution, both hip sides, 1e-11 (linear
    solves' round-off); with ``P = 0`` it is the passive heel strike; the transition's
    kinetic energies are the reference's; the push-off's work is ``P e . v_foot_po`` ...
    (its energy is the reference's quadratic form: 1e-10 J)."""
    walker, passive, ref, w = _walkers({"push_off": {"impulse_n_s": P}})
    for side, wa, wp in ((w, walker, passive), (-w, walker.mirror, passive.mirror)):
        for x in _states(13, 3):
            theirs, dqe, dqe_po, Me = _push_off_reference(ref, side, x, P)
            got = wa.reset(x)
            assert np.max(np.abs(got - theirs)) < 1e-11
            if P == 0.0:
                assert np.max(np.abs(got - wp.reset(x))) < 1e-11
            tr = wa.actuators.transition(x)
            assert abs(tr["ke_push_off"] - 0.5 * dqe_po @ Me @ dqe_po) < 1e-10
            assert abs(tr["ke_minus"] - 0.5 * dqe @ Me @ dqe) < 1e-10
            assert tr["impulse"] == P


def _fixed_point(raw):
    w = wl.Walker.from_scene(Scene.model_validate(raw))
    return w, w.fixed_point()


@pytest.mark.slow  # ~30 s: the powered 3D gait and two steps of it
def test_the_3d_powered_gait_walks_and_its_ledger_closes():
    """``configs/hip_width_powered.yaml``: a stable period-1 (stride) gait; over a stride
    each step's energy change is the hip spring's and the hip-roll law's work plus the
    push-off's minus the heel strike's loss, to 1e-9 J (measured ~1e-12 J); the push-off's
    work and impulse are the scene's (1 N s) and positive."""
    raw = yaml.safe_load((ROOT / "configs" / "hip_width_powered.yaml").read_text())
    w, g = _fixed_point(raw)
    assert g.max_abs_multiplier < 0.9
    traj = simulate_steps(w.model, np.asarray(g.x), 2, w.solver)
    led = trajectory_ledger(traj)
    assert len(led["closure"]) == 2
    assert np.max(np.abs(led["closure"])) < 1e-9
    assert np.all(np.asarray(led["push_off_impulse"]) == 1.0)
    assert np.all(np.asarray(led["push_off_work"]) > 0.0)  # measured 0.0297 J
    assert np.all(np.asarray(led["heel_strike_loss"]) > 0.0)


def _as_3d(name: str) -> dict:
    """A planar compass-gait scene as a 3D walker of zero hip width, started upright."""
    raw = yaml.safe_load((ROOT / "configs" / f"{name}.yaml").read_text())
    out = {k: raw[k] for k in ("source", "slope", "solver", "fixedpoint")}
    out["walker"] = dict(raw["walker"], space="3d", hip_width_m=0.0)
    g = dict(out["fixedpoint"]["initial_guess"])
    out["fixedpoint"] = dict(out["fixedpoint"], other_gait=False, initial_guess={
        "lean_angle_rad": 0.0, "lean_rate_rad_per_s": 0.0, **g})
    return raw, out


@pytest.mark.slow  # ~40 s: two fixed points
@pytest.mark.parametrize("hip_law", [False, True])
def test_a_zero_width_3d_powered_walker_is_the_planar_one(hip_law):
    """``configs/powered_compass.yaml`` (push-off 3 N s on level ground; with ``hip_law``
    also a hip torque law, which the planar walker runs as a generated hip spring and the 3D
    one through its compiled law) as a 3D walker of zero hip width started upright: the
    same fixed point (1e-9) and step period (1e-9 s) - the planar embedding of the 3D
    actuators (Kuo 1999's planar limit)."""
    raw, raw3 = _as_3d("powered_compass")
    if hip_law:
        # a spring (with 0.1 N m s/rad of damping the planar walker has no gait near the
        # scene's guess: its search ends at the standing solution)
        law = {"stiffness_n_m_per_rad": 2.0}
        for r in (raw, raw3):
            r["walker"]["actuation"] = dict(r["walker"]["actuation"],
                                            torques=[{"joint": "hip", "law": law}])
    _w2, g2 = _fixed_point({k: raw[k] for k in ("source", "walker", "slope", "solver",
                                                "fixedpoint")})
    # the 3D search starts from the planar gait found, upright (the hip law moves the gait
    # away from the scene's guess)
    planar = dict(zip(list(_w2.model.state_names()), map(float, g2.x)))
    raw3["fixedpoint"]["initial_guess"] = {
        "lean_angle_rad": 0.0, "lean_rate_rad_per_s": 0.0,
        **{f"{k}_rad" if k.endswith("_angle") else f"{k}_rad_per_s": v
           for k, v in planar.items()}}
    w3, g3 = _fixed_point(raw3)
    names = list(w3.model.state_names())
    x3 = dict(zip(names, np.asarray(g3.x)))
    x2 = dict(zip(list(_w2.model.state_names()), np.asarray(g2.x)))
    for k, v in x2.items():
        assert abs(x3[k] - v) < 1e-9, k
    assert abs(x3["lean_angle"]) < 1e-12 and abs(x3["lean_rate"]) < 1e-12
    assert abs(g3.step_period - g2.step_period) < 1e-9


def test_the_powered_3d_scenes_report_plans_its_contact_run_and_comparison():
    """configs/hip_width_powered.yaml's actuators (a hip spring and a push-off) are taken
    by the contact view as by the rigid one, so its report plans contact-sim and compare
    beside fixedpoint and simulate (before the contact view took them, the plan left the
    two out and said why)."""
    from walkerlab.config import load_scene
    from walkerlab.stages.pipeline import report_plan

    powered = load_scene(ROOT / "configs" / "hip_width_powered.yaml")
    assert powered.contact is not None
    assert report_plan(powered) == ["fixedpoint", "simulate", "contact-sim", "compare"]
