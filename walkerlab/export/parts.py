"""The export's part of a walker: what the writers (URDF, MJCF, Adams, OpenSim) do
differently for it, read from its body tree (:mod:`walkerlab.walker.tree`: its knee, its
joints' stops, its soles).

The writers never ask the description's switches (flat feet, free knees, spokes) or the
kind's words which code runs: they ask the walker's tree, :func:`export_part` (the Adams
dataset's foot statements, :func:`walkerlab.export.adams_feet.adams_feet`, the MJCF scene's
feet, :func:`walkerlab.export.scene_feet.scene_feet`, the export stage's writer of the
tree's form, :mod:`walkerlab.export.writers`).  Whether a kind is exported in a format at
all is the capability table's (:meth:`walkerlab.walker.kinds.Kind.require`).
"""

from __future__ import annotations

from dataclasses import dataclass

from walkerlab.walker.kinds import KINDS
from walkerlab.walker.tree import BodyTree

__all__ = ["ExportPart", "export_part", "tree_part"]

_HIP_SIDECAR = ("hip torques act +tau on the swing leg's hip joint and -tau on the stance "
                "leg's; the push-off is an impulse along the trailing leg at its foot at each "
                "heel strike")
_HIP_MJCF = ("Actuators (walker.actuation, in the custom text walkerlab_actuation): one "
             "motor 'hip' on the tendon leg1_hip - leg2_hip, for a controller of one's "
             "own; walkerlab's stepping loop applies the swing leg's hip torque as "
             "generalised forces (qfrc_applied: +tau on the swing leg, -tau on the "
             "stance leg) and the push-off as a force along the trailing leg at its foot for "
             "push_off_duration_s from each heel strike (walkerlab.export.mujoco_walk): "
             "one MuJoCo timestep, the rigid model's impulse as MuJoCo can apply it (the "
             "contact model's contact.push_off_duration_s pulse agrees with it only to "
             "first order in its length: -2.1 % step period with 5 ms).")


@dataclass(frozen=True)
class ExportPart:
    """What the exports write differently for one walker kind.

    Attributes
    ----------
    knee_stops : bool
        The knees have the straight-leg stop and its latch (McGeer 1990's locking knees):
        a joint limit, the contact model's IMPACT stop, a latch a stepping loop switches.
    mjcf_actuators : str
        The MJCF's note on the actuators of a powered walker.
    sidecar_actuators : str
        The URDF keyframe sidecar's ``actuation_note``.
    ankles : bool
        Each leg ends in a foot body on an ankle hinge (flat feet: the MJCF's and the
        OpenSim model's ``leg<i>_ankle`` coordinates).
    """

    knee_stops: bool = False
    mjcf_actuators: str = _HIP_MJCF
    sidecar_actuators: str = _HIP_SIDECAR
    ankles: bool = False


#: the actuator notes of a free-jointed walker
#: (:attr:`walkerlab.walker.kinds.Kind.joints_free`) on free knees (the five-link biped)
_FREE_KNEES = {
    "mjcf_actuators": (
        "Actuators (walker.actuation, in the custom text walkerlab_actuation): "
        "motors leg<i>_hip_motor on the tendons leg<i>_hip - torso_hip and "
        "leg<i>_knee_motor on the knees, for a controller of one's own; "
        "walkerlab's stepping loop applies each law's torque in its joint's present "
        "role (stance_hip, swing_knee, ...: leg2 stands at the keyframe, the roles "
        "swap at each heel strike) as generalised forces (qfrc_applied), the phase "
        "variable the virtual stance leg's angle (hip to stance foot) "
        "(walkerlab.export.mujoco_walk)."),
    "sidecar_actuators": (
        "joint torques on a five-link biped: stance_hip / swing_hip act +tau on the "
        "stance / swing leg's hip joint and -tau on torso_hip, stance_knee / swing_knee "
        "+tau on that leg's knee; leg2 stands at the keyframe, the roles swap at each "
        "heel strike; the phase variable is the angle of the line from the hip to the "
        "stance foot from the downward vertical")}

#: the actuator notes of a free-jointed walker on straight legs (the three-link walker)
_STRAIGHT_LEGS = {
    "mjcf_actuators": (
        "Actuators (walker.actuation, in the custom text walkerlab_actuation): "
        "motors leg<i>_hip_motor on the tendons leg<i>_hip - torso_hip, for a "
        "controller of one's own; walkerlab's stepping loop applies each law's torque "
        "in its joint's present role (stance_hip, swing_hip: leg2 stands at the "
        "keyframe, the roles swap at each heel strike) as generalised forces "
        "(qfrc_applied), the phase variable the stance leg's angle "
        "(walkerlab.export.mujoco_walk)."),
    "sidecar_actuators": (
        "joint torques between a hinged torso and straight legs: stance_hip / swing_hip "
        "act +tau on the stance / swing leg's hip joint and -tau on torso_hip; leg2 "
        "stands at the keyframe, the roles swap at each heel strike; the phase variable "
        "is the stance leg's angle from the downward vertical")}


def tree_part(tree: BodyTree, joints_free: bool = False) -> ExportPart:
    """The export part of the walker whose body tree is ``tree``
    (:class:`walkerlab.walker.tree.BodyTree`): knee stops where a joint has a stop
    (:attr:`~walkerlab.walker.tree.BodyTree.stopped_joints`: a locking knee's), ankles where
    it has soles (:attr:`~walkerlab.walker.tree.BodyTree.soles`: flat feet); a free-jointed
    walker's (``joints_free``, :attr:`walkerlab.walker.kinds.Kind.joints_free`) actuator
    notes, of knees where the tree has a knee (a joint ``swing_knee``), else of straight
    legs."""
    notes = {}
    if joints_free:
        notes = _FREE_KNEES if tree.has_joint("swing_knee") else _STRAIGHT_LEGS
    return ExportPart(knee_stops=bool(tree.stopped_joints), ankles=bool(tree.soles), **notes)


def export_part(mb) -> ExportPart:
    """The export part of a multibody walker (:class:`walkerlab.walker.multibody.Multibody`):
    :func:`tree_part` of its body tree (``mb.tree``)."""
    return tree_part(mb.tree, KINDS[mb.kind].joints_free)
