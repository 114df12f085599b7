"""MJCF motors' control ranges from the laws' saturations
(:func:`walkerlab.export.mjcf_scene.motor_limits`): a motor's control is the sum of its
joint's present role's laws, each clipped at its ``max_torque_n_m``.  They take the typed
``walker.actuation`` (:class:`walkerlab.config.actuation.Actuation`)."""

from __future__ import annotations

from walkerlab.config.actuation import Actuation
from walkerlab.export.mjcf_scene import motor_limits
from walkerlab.export.multibody import motors


def _act(*torques, push_off=None):
    out = {"torques": [{"joint": j, "max_torque_n_m": m, "law": {}} if m is not None
                       else {"joint": j, "law": {}} for j, m in torques]}
    if push_off is not None:
        out["push_off"] = push_off
    return Actuation.model_validate(out)


def test_hip_motor_range_is_the_sum_of_its_laws_limits():
    """Two saturated hip laws (12.5 and 30 N m): the hip motor's range is 42.5 N m; one law
    without a limit leaves the motor unlimited; a push-off alone has an idle, unlimited hip
    motor; a passive walker has none."""
    act = _act(("hip", 12.5), ("hip", 30.0))
    assert [m[0] for m in motors(act)] == ["hip"]
    assert motor_limits(act) == {"hip": 42.5}
    assert motor_limits(_act(("hip", 12.5), ("hip", None))) == {}
    assert motor_limits(Actuation.model_validate({"push_off": {"impulse_n_s": 3.0}})) == {}
    assert motor_limits(None) == {}


def test_five_link_motor_range_is_the_larger_role():
    """A leg's hip motor carries the stance_hip law while the leg stands and the swing_hip
    law while it swings: its range is the larger (150 against 100 N m); the knees' own."""
    act = _act(("stance_hip", 150.0), ("swing_hip", 100.0), ("stance_knee", 80.0),
               ("swing_knee", 80.0))
    lim = motor_limits(act)
    assert lim == {"leg1_hip_motor": 150.0, "leg2_hip_motor": 150.0,
                   "leg1_knee_motor": 80.0, "leg2_knee_motor": 80.0}
    assert set(lim) == {m[0] for m in motors(act)}
    assert "leg1_knee_motor" not in motor_limits(_act(("stance_hip", 150.0),
                                                      ("swing_knee", None)))
