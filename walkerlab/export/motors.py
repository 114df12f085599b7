"""A powered export's motors: which joint combinations a scene's ``walker.actuation`` drives,
their names and what each turns (:func:`motors`, :func:`motor_target`).

The hip motor drives the fixed tendon :data:`HIP_ACTUATION_TENDON` (``leg1_hip - leg2_hip``);
a five-link biped's joint torques become the physical joints' motors of both legs
(``leg<i>_hip_motor`` on ``leg<i>_hip_torso``, ``leg<i>_knee_motor`` on ``leg<i>_knee``); an
ankle push-off the motors ``leg<i>_ankle_motor``.  The MJCF writes them as actuators
(:func:`mjcf_motor_tendons`, :func:`mjcf_actuator_lines`: the planar walker's
:mod:`walkerlab.export.multibody`, which re-exports these names, and the 3D straight legs'
:mod:`walkerlab.export.legs_3d_mjcf`, whose hinges ``leg<i>_hip`` are the legs' pitches about
their own hip axes), the URDF states them in comments (:mod:`walkerlab.export.urdf`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from walkerlab.export.mjcf_scene import motor_limits
from walkerlab.export.text import nums

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
    if kind == "joint":  # a knee, or a flat foot's ankle (its angle toe up positive)
        turn = "turns the sole toe up" if target.endswith("_ankle") else "extends the knee"
        return f"the joint {target} (+u {turn})"
    if target == HIP_ACTUATION_TENDON:
        return "leg1_hip - leg2_hip (+u on leg1_hip, -u on leg2_hip)"
    return f"{target[:-len('_torso')]} - torso_hip (+u on the thigh's joint, -u on torso_hip)"


def mjcf_motor_tendons(motor_list, torso: str = "torso_hip") -> list[str]:
    """The MJCF fixed tendons (``<fixed>`` elements, without the enclosing ``<tendon>``) a
    powered export's motors drive (``motor_list``: :func:`motors`): :data:`HIP_ACTUATION_TENDON`
    ``= leg1_hip - leg2_hip``, a five-link biped's ``leg<i>_hip_torso = leg<i>_hip -
    torso_hip`` (MuJoCo XML Reference: ``tendon/fixed``); ``torso`` the upper body's hinge
    (a 3D walker's ``torso_pitch``)."""
    out = []
    for name in (m[2] for m in motor_list if m[1] == "tendon"):
        second = "leg2_hip" if name == HIP_ACTUATION_TENDON else torso
        first = "leg1_hip" if name == HIP_ACTUATION_TENDON else name[:-len("_torso")]
        out += [f'    <fixed name="{name}">', f'      <joint joint="{first}" coef="1.0"/>',
                f'      <joint joint="{second}" coef="-1.0"/>', "    </fixed>"]
    return out


def mjcf_actuator_lines(act: Actuation | None, motor_list) -> list[str]:
    """The MJCF ``<actuator>`` block of the motors ``motor_list`` (:func:`motors` of
    ``act``), each with ``gear 1`` and, where the laws of its joint all saturate, the
    control range of :func:`walkerlab.export.mjcf_scene.motor_limits` (MuJoCo clamps the
    control there); none without motors.  The laws live in the custom text
    ``walkerlab_actuation``: a stepping loop sets the controls."""
    if not motor_list:
        return []
    rng = {n: f' ctrllimited="true" ctrlrange="{nums(-u, u)}"'
           for n, u in motor_limits(act).items()}
    return ["  <actuator>", *(f'    <motor name="{name}" {kind}="{target}" gear="1"'
                              f'{rng.get(name, "")}/>'
                              for name, kind, target in motor_list), "  </actuator>"]
