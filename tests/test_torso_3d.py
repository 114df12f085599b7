"""An upper body in 3D with a torso torque and hip-roll joints
(``configs/torso_bhm_3d_stabilised.yaml``, ``configs/torso_powered_3d.yaml``): the upper body
on the bisecting hip (Wisse, Hobbelen & Schwab 2007, IEEE Trans. Robotics 23(1)) of the 3D
straight legs with Kuo's (1999) lateral foot placement at the hips, driven by a torque
between the upper body and the stance leg (``joint: stance_hip``).

The references: the bisecting hip's kinematics (the torso's pitch is the legs' mean, so a
torque ``tau`` between torso and stance leg is the hip torque ``-tau / 2``), the planar torso
walker (``configs/torso_powered.yaml``, its own planar equations and a hip law) as the 3D
walker of zero hip width started upright, the energy ledger, and the contact model and
MuJoCo against the rigid step period."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

import walkerlab as wl
from walkerlab.analysis.gait.energy import trajectory_ledger
from walkerlab.config.schema import Scene
from walkerlab.integrate.rigid import simulate_steps
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def _raw(name: str) -> dict:
    return yaml.safe_load((ROOT / "configs" / f"{name}.yaml").read_text())


def _built(raw: dict):
    return build_walker(Plant.from_scene(Scene.model_validate(raw)))


def _states(n: int, count: int, seed: int = 3) -> list:
    """``count`` states (2n,) about a gait of the stabilised walker: angles within 0.1 rad,
    rates within 0.5 rad/s (every roll and pitch different)."""
    rng = np.random.default_rng(seed)
    base = np.r_[0.02, -0.2, 0.18, -0.01, -0.03, -0.3, -0.65, -0.77, 0.8, -0.37][:2 * n]
    return [base + np.r_[np.full(n, 0.1), np.full(n, 0.5)] * rng.uniform(-1, 1, 2 * n)
            for _ in range(count)]


@pytest.mark.slow  # ~2-4 min on a fresh cache: three 3D torso derivations (torso, hip, none)
def test_a_torso_torque_in_3d_is_minus_half_the_hip_torque_on_the_bisecting_hip():
    """On the bisecting hip the upper body's pitch is the legs' mean, so the stance hip's
    angle (stance leg minus torso) is ``-delta / 2`` (``delta`` = swing - stance) and a
    torque ``tau_s`` there does the virtual work of a hip torque ``-tau_s / 2``: the torso
    law ``c - k (alpha - r) - d alpha'`` drives the 3D hip-roll walker's flow exactly as the
    hip law ``-(c + k r) / 2 - (k / 4) delta - (d / 4) delta'`` does, on both hip sides, at
    states whose rolls all differ (1e-10 relative: the flows' round-off; a torque applied
    to the stance leg alone, or to the whole hip angle, misses by ~tau)."""
    c, k, d, r = 1.5, 20.0, 2.0, -0.15
    raw = _raw("torso_bhm_3d_stabilised")
    torso, hip = (dict(raw, walker=dict(raw["walker"], actuation={"torques": [t]}))
                  for t in ({"joint": "stance_hip", "law": {
                      "constant_n_m": c, "stiffness_n_m_per_rad": k,
                      "damping_n_m_s_per_rad": d, "rest_angle_rad": r}},
                            {"joint": "hip", "law": {
                                "constant_n_m": -(c + k * r) / 2,
                                "stiffness_n_m_per_rad": k / 4,
                                "damping_n_m_s_per_rad": d / 4}}))
    w_t, w_h, w_p = _built(torso), _built(hip), _built(raw)
    for a, b, p in ((w_t, w_h, w_p), (w_t.mirror, w_h.mirror, w_p.mirror)):
        for x in _states(5, 4):
            ft, fh, fp = (np.asarray(m.phases[0].flow(0.0, x)) for m in (a, b, p))
            assert np.max(np.abs(ft - fp)) > 1e-2   # the law does act
            assert np.max(np.abs(ft - fh)) < 1e-10 * max(1.0, np.max(np.abs(ft)))


@pytest.mark.slow  # ~5 min on a fresh cache: the stride gait and its variational multipliers
def test_the_stabilised_3d_upper_body_walker_is_stable():
    """configs/torso_bhm_3d_stabilised.yaml: the passive walker's lateral multiplier of
    about 206 a stride (configs/torso_bhm_3d.yaml) brought inside the unit circle by the
    hip-roll law: every stride multiplier below 0.45 (measured 0.396), at the scene's step
    period 0.849683 s."""
    w = wl.Walker.from_scene(Scene.model_validate(_raw("torso_bhm_3d_stabilised")))
    g = w.fixed_point()
    assert g.max_abs_multiplier < 0.45
    assert abs(g.step_period - 0.8496827359) < 1e-8


#: configs/torso_powered.yaml's hip law ``-5 (delta - 0.3) - 0.5 delta'`` as the torso law
#: at the stance hip (angle ``alpha = -delta / 2``): ``-20 (alpha + 0.15) - 2 alpha'``
TORSO_LAW = {"joint": "stance_hip", "law": {"stiffness_n_m_per_rad": 20.0,
                                            "damping_n_m_s_per_rad": 2.0,
                                            "rest_angle_rad": -0.15}}


@pytest.mark.slow  # ~10 min on a fresh cache: the zero-width 3D torso walker's derivation
def test_a_zero_width_3d_torso_torque_walker_is_the_planar_torso_powered_walker():
    """configs/torso_powered.yaml (the planar torso walker on level ground: its push-off and
    hip law, its own planar equations) against the 3D walker of zero hip width, started
    upright, driven by the same law written as a torque between the upper body and the
    stance leg (:data:`TORSO_LAW`): the same fixed point (1e-9 rad, rad/s), the lean 0,
    and the same step period (1e-9 s; the scene's 0.838507 s) - Kuo's (1999) planar
    limit of the 3D walker, with the bisecting hip's torso torque."""
    raw = _raw("torso_powered")
    planar = {k: raw[k] for k in ("source", "walker", "slope", "solver", "fixedpoint")}
    w2 = wl.Walker.from_scene(Scene.model_validate(planar))
    g2 = w2.fixed_point()
    raw3 = dict(planar, walker=dict(raw["walker"], space="3d", hip_width_m=0.0,
                                    actuation=dict(raw["walker"]["actuation"],
                                                   torques=[TORSO_LAW])))
    x2 = dict(zip(list(w2.model.state_names()), map(float, g2.x)))
    raw3["fixedpoint"] = dict(raw["fixedpoint"], other_gait=False, initial_guess={
        "lean_angle_rad": 0.0, "lean_rate_rad_per_s": 0.0,
        **{f"{k}_rad" if k.endswith("_angle") else f"{k}_rad_per_s": v
           for k, v in x2.items()}})
    w3 = wl.Walker.from_scene(Scene.model_validate(raw3))
    g3 = w3.fixed_point()
    x3 = dict(zip(list(w3.model.state_names()), np.asarray(g3.x)))
    for k, v in x2.items():
        assert abs(x3[k] - v) < 1e-9, k
    assert abs(x3["lean_angle"]) < 1e-12 and abs(x3["lean_rate"]) < 1e-12
    assert abs(g3.step_period - g2.step_period) < 1e-9
    assert abs(g2.step_period - 0.838507) < 1e-6


def _contact_run(name: str, tmp_path, strides: int):
    """``walkerlab contact-sim configs/<name>.yaml --strides <strides>``: (its failure or
    None, the step periods [s], the heel strikes, the rigid step period [s])."""
    import h5py

    from walkerlab.config import load_scene
    from walkerlab.stages import pipeline

    out = pipeline.run("contact-sim", load_scene(ROOT / "configs" / f"{name}.yaml"),
                       tmp_path, strides=strides)
    with h5py.File(out.path) as f:
        periods = np.asarray(f["steps/period"][()], float)
        strikes = int(f["summary/heel_strikes"][()])
    with h5py.File(tmp_path / name / "fixedpoint.h5") as f:
        rigid = float(f["step_period"][()])
    return out.failure, periods[np.isfinite(periods)], strikes, rigid


@pytest.mark.slow  # ~10 min on a fresh cache (the floating tree's derivation and kernels)
@pytest.mark.parametrize("name", ["torso_bhm_3d_stabilised", "torso_powered_3d"])
def test_the_stabilised_3d_upper_body_walker_walks_in_contact_at_its_rigid_period(
        name, tmp_path):
    """The stabilised upper-body walker (passive, and driven by its torso torque and
    push-off) in the compliant-contact model (the paper's contact law): six strides, >= 10
    heel strikes, the last four steps' mean period within 1 % of the rigid gait's and every
    step within 1 % (measured on torso_bhm_3d_stabilised: 12 heel strikes, every step
    within 0.49 %, the last four -0.05 %)."""
    failure, periods, strikes, rigid = _contact_run(name, tmp_path, 6)
    assert not failure
    assert strikes >= 10
    assert abs(periods[-4:].mean() / rigid - 1.0) < 0.01
    assert np.max(np.abs(periods / rigid - 1.0)) < 0.01


@pytest.mark.slow  # ~3 min: the rigid gait and about 10 s of MuJoCo
@pytest.mark.parametrize("name", ["torso_bhm_3d_stabilised", "torso_powered_3d"])
def test_the_stabilised_3d_upper_body_walkers_mjcf_walks_at_its_rigid_period(name, tmp_path):
    """The upper-body walker's MJCF (the torso on its hinge held to the legs' mean by an
    equality, the hip-roll law and the torso torque run by walkerlab's walk loop) walked in
    MuJoCo: >= 10 alternating heel strikes without a fall, the mean step period within 1 %
    of the rigid one."""
    pytest.importorskip("mujoco")
    from walkerlab.cli.options import load
    from walkerlab.stages import export

    scene = load(str(ROOT / "configs" / f"{name}.yaml"))
    out = export.write(scene, tmp_path, "mjcf", walk=True)
    w = out.walk
    assert not w.fell and w.alternating and w.strikes >= 10, w.line
    assert abs(w.period_s / w.rigid_period_s - 1.0) < 0.01, w.line


@pytest.mark.slow  # ~5 min on a fresh cache: the gait and a stride of it
def test_the_3d_torso_torque_walkers_ledger_closes_over_a_stride():
    """configs/torso_powered_3d.yaml: a stable stride gait; over each step of a stride the
    energy change is the torso torque's work (its power ``tau alpha'`` on the stance hip's
    angle, integrated along the flow) plus the hip-roll law's, minus the heel strike's
    loss, to 1e-9 J of the step's (the flow's generalised force ``tau d(alpha)/dq``
    against the law's own power: a force on the wrong coordinates leaves ~tau x rate x
    period, ~0.1 J); the torque does work both ways."""
    w = wl.Walker.from_scene(Scene.model_validate(_raw("torso_powered_3d")))
    g = w.fixed_point()
    assert g.max_abs_multiplier < 1.0
    led = trajectory_ledger(simulate_steps(w.model, np.asarray(g.x), 2, w.solver))
    assert len(led["closure"]) == 2
    assert np.max(np.abs(led["closure"])) < 1e-9
    assert np.all(np.asarray(led["actuator_work_positive"]) > 1e-4)
    assert np.all(np.asarray(led["heel_strike_loss"]) > 0.0)
