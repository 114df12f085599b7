"""A powered export's motors: which joint combinations a scene's ``walker.actuation`` drives,
their names and what each turns (:func:`motors`, :func:`motor_target`).

The hip motor drives the fixed tendon :data:`HIP_ACTUATION_TENDON` (``leg1_hip - leg2_hip``);
a five-link biped's joint torques become the physical joints' motors of both legs
(``leg<i>_hip_motor`` on ``leg<i>_hip_torso``, ``leg<i>_knee_motor`` on ``leg<i>_knee``); an
ankle push-off the motors ``leg<i>_ankle_motor``.  The MJCF writes them as actuators
(:mod:`walkerlab.export.multibody`, which re-exports these names), the URDF states them in
comments (:mod:`walkerlab.export.urdf`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the io layer reads the model's data classes, it does not build them
    from walkerlab.config.actuation import Actuation


#: The fixed tendon a powered export's hip motor drives: ``leg1_hip - leg2_hip``, so a control
#: ``u`` acts ``+u`` on leg1 and ``-u`` on leg2 (the swing leg's torque when leg1 swings).
HIP_ACTUATION_TENDON = "hip_actuation"


def motors(act: Actuation | None) -> list[tuple[str, str, str]]:
    """The motors of a powered export (module docstring): ``(name, kind, target)`` with
    ``kind`` ``"tendon"`` or ``"joint"``; none without actuation or torques.  A five-link
    biped's joints (``stance_hip``, ``swing_knee``, ...) become the physical joints' motors of
    both legs (the roles swap at each heel strike); an ankle push-off the motors
    ``leg<i>_ankle_motor`` on the ankle hinges (flat feet)."""
    if act is None:
        return []
    joints = {t.joint for t in act.torques}
    out = []
    if "hip" in joints or not joints:  # (a push-off alone: the hip motor, at 0)
        out.append(("hip", "tendon", HIP_ACTUATION_TENDON))
    for kind in ("hip", "knee"):
        if joints & {f"stance_{kind}", f"swing_{kind}"}:
            out += [(f"{leg}_{kind}_motor", "tendon" if kind == "hip" else "joint",
                     f"{leg}_hip_torso" if kind == "hip" else f"{leg}_knee")
                    for leg in ("leg1", "leg2")]
    if act.ankle_push_off is not None:  # flat feet: the stance ankle's
        out += [(f"{leg}_ankle_motor", "joint", f"{leg}_ankle") for leg in ("leg1", "leg2")]
    return out


def motor_target(kind: str, target: str) -> str:
    """What a motor of :func:`motors` turns, in words."""
    if kind == "joint":
        return f"the joint {target} (+u extends the knee)"
    if target == HIP_ACTUATION_TENDON:
        return "leg1_hip - leg2_hip (+u on leg1_hip, -u on leg2_hip)"
    return f"{target[:-len('_torso')]} - torso_hip (+u on the thigh's joint, -u on torso_hip)"
