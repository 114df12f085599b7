"""Actuation of the kneed walker in 3D in the rigid model (``walker.actuation`` on
``model: biped`` with ``space: 3d`` and a locking knee; the kind ``locking_knees_3d``): the
planar walkers' actuators (:class:`walkerlab.models.hybrid.actuators.Actuators`: hip and
knee torques by the virtual work of the generated leg angles, Kuo 2002's push-off along the
trailing leg) on the 3D tree's equations, the push-off and heel strike holding the locked
swing knee in the 3D extended impact system.

References, none computed by the code under test:

- the planar kneed walker (configs/kneed.yaml's own derivation, whose push-off is checked
  against ``tests/independent/kneed_reference.py`` in ``tests/test_kneed_push_off.py``):
  with zero hip width and no lean the 3D walker's actuated flows and push-off reset are its
  own, to round-off;
- the passive 3D walker: a law of zero torque and an impulse of zero give its flows and
  heel strike to round-off;
- the energy ledger (slow): over a powered stride the walker's energy change is the work
  of the torques and the push-off less the knee and heel strikes' losses.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from walkerlab.config.schema import Scene
from walkerlab.models.registry import build_walker
from walkerlab.walker.kinds import KINDS
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]
#: a hip law with every term and a knee spring-damper (N m/rad, N m s/rad, N m, rad), the
#: push-off (N s): sizes of the 1.6 kg walker's (its hip spring at 0.3 N m/rad moves its
#: swing by a few per cent)
HIP = {"stiffness_n_m_per_rad": 0.3, "damping_n_m_s_per_rad": 0.02, "constant_n_m": 0.01,
       "rest_angle_rad": 0.05}
KNEE = {"stiffness_n_m_per_rad": 0.05, "damping_n_m_s_per_rad": 0.01}
ACTUATION = {"push_off": {"impulse_n_s": 0.05},
             "torques": [{"joint": "hip", "law": HIP}, {"joint": "swing_knee", "law": KNEE}]}


def _raw(name: str, width: float | None = None, actuation: dict | None = None) -> dict:
    raw = yaml.safe_load((ROOT / "configs" / name).read_text())
    for key in ("contact", "terrain", "contact_sim", "contact_solver"):
        raw.pop(key, None)
    if width is not None:
        raw["walker"] = {**raw["walker"], "space": "3d", "hip_width_m": width}
    if actuation is not None:
        raw["walker"]["actuation"] = actuation
    return raw


def _walker(raw: dict):
    return build_walker(Plant.from_scene(Scene.model_validate(raw)))


def _states(n: int, count: int, seed: int):
    """States (2n,) near the gait: the lean first, the swing thigh and shank, the stance
    leg, then rates of order 1 rad/s."""
    rng = np.random.default_rng(seed)
    base = np.array([0.01, -0.25, -0.3, 0.2][:n])
    for _ in range(count):
        yield np.concatenate([base + 0.05 * rng.standard_normal(n), rng.standard_normal(n)])


def test_the_kneed_walker_in_3d_takes_hip_and_knee_torques_and_push_off_in_the_rigid_view():
    """The capability table: the rigid view takes the hip and knee torques and the
    push-off of a kneed walker in 3D (and the scene validates with them)."""
    kind = KINDS["locking_knees_3d"]
    for feature in ("hip_torque", "knee_torque", "push_off"):
        assert kind.supports(feature, "rigid"), feature
    Scene.model_validate(_raw("kneed_3d.yaml", actuation=ACTUATION))


@pytest.mark.slow  # ~1.5 min on a fresh cache: the driven 3D kneed derivation
def test_zero_torque_and_zero_impulse_give_the_passive_kneed_walker_in_3d():
    """A law of zero at the hip and the knee and a push-off of 0 N s: every phase's flow
    and the heel strike are the passive walker's (configs/kneed_3d.yaml, both hip sides:
    the stride's mirror step), to 1e-12 (linear solves' round-off on rates of order 1)."""
    zero = {"stiffness_n_m_per_rad": 0.0, "constant_n_m": 0.0}
    acts = {"push_off": {"impulse_n_s": 0.0},
            "torques": [{"joint": "hip", "law": zero}, {"joint": "swing_knee", "law": zero}]}
    driven, passive = _walker(_raw("kneed_3d.yaml", actuation=acts)), _walker(
        _raw("kneed_3d.yaml"))
    for wd, wp in ((driven, passive), (driven.mirror, passive.mirror)):
        for x in _states(4, 3, 5):
            for phd, php in zip(wd.phases, wp.phases):
                assert np.max(np.abs(phd.flow(0.0, x) - php.flow(0.0, x))) < 1e-12
            xl = x.copy()  # the heel strike takes place with the swing knee locked
            xl[2], xl[6] = xl[1], xl[5]
            assert np.max(np.abs(wd.reset(xl) - wp.reset(xl))) < 1e-12
            assert wd.actuators.transition(xl)["impulse"] == 0.0


@pytest.mark.slow   # ~1.5 min cold: the 3D kneed derivation of zero hip width
def test_the_kneed_walker_in_3d_of_zero_width_is_driven_as_the_planar_kneed_walker():
    """configs/kneed.yaml with the hip law, the knee spring-damper and a 0.05 N s push-off,
    against the same walker with ``space: 3d`` and ``hip_width_m: 0``: at states with no
    lean, both phases' actuated flows and the push-off + heel strike (the knee locked) are
    the planar walker's, the lean's acceleration and rate 0 (to 1e-11 on accelerations of
    order 10 rad/s^2: two derivations' round-off)."""
    flat = _walker(_raw("kneed.yaml", actuation=ACTUATION))
    w3 = _walker(_raw("kneed.yaml", width=0.0, actuation=ACTUATION))
    sagittal = [1, 2, 3, 5, 6, 7]
    for x in _states(4, 4, 7):
        x[[0, 4]] = 0.0
        x2 = x[sagittal]
        for p2, p3 in zip(flat.phases, w3.phases):
            f3 = p3.flow(0.0, x)
            assert np.max(np.abs(f3[sagittal] - p2.flow(0.0, x2))) < 1e-11
            assert abs(f3[0]) == 0.0 and abs(f3[4]) < 1e-12
        xl = x.copy()
        xl[2], xl[6] = xl[1], xl[5]
        r3 = w3.reset(xl)
        assert np.max(np.abs(r3[sagittal] - flat.reset(xl[sagittal]))) < 1e-12
        assert abs(r3[0]) == 0.0 and abs(r3[4]) < 1e-12
        t2, t3 = flat.actuators.transition(xl[sagittal]), w3.actuators.transition(xl)
        for k in ("ke_minus", "ke_push_off", "ke_plus"):
            assert abs(t2[k] - t3[k]) < 1e-12, k


@pytest.mark.slow   # ~1.5 min: the powered gait and a stride of it
def test_the_powered_kneed_walker_in_3d_walks_and_its_work_equals_its_losses():
    """configs/kneed_3d_powered.yaml: a period-1 (stride) gait whose steps mirror each
    other; over each step the energy change is the torques' and the push-off's work plus
    the slope's less the knee and heel strikes' losses, to 1e-9 J (measured ~1e-14 J); the
    push-off's impulse is the scene's and does positive work; the lateral mode is the
    passive gait's (unstable: no hip-roll joints)."""
    import walkerlab as wl
    from walkerlab.analysis.gait.energy import trajectory_ledger
    from walkerlab.integrate.rigid import simulate_steps

    w = wl.Walker.from_scene(Scene.model_validate(_raw("kneed_3d_powered.yaml")))
    g = w.fixed_point()
    assert 30.0 < g.max_abs_multiplier < 50.0          # measured 39.17 (passive 39.86)
    led = trajectory_ledger(simulate_steps(w.model, np.asarray(g.x), 2, w.solver))
    assert np.max(np.abs(led["closure"])) < 1e-9
    assert np.all(led["push_off_impulse"] == 0.02)
    assert np.all(led["push_off_work"] > 0.0)          # measured 1.5e-4 J
    assert np.all(led["internal_collision_loss"] > 0.0)  # the knee strike: 0.023 J
    assert abs(led["heel_strike_loss"][0] - led["heel_strike_loss"][1]) < 1e-9
