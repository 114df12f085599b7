"""What an exported file leaves out of the scene: one list per writer, written into the file
as comments and printed by ``walkerlab export``, one line per item.

Each writer (URDF and MJCF: :mod:`walkerlab.export.multibody`, a spoked wheel's:
:mod:`walkerlab.export.spoked`; the Adams dataset: :mod:`walkerlab.export.adams`; the OpenSim
model: :mod:`walkerlab.export.opensim`) builds a tuple of :class:`Omission` with its own
function (``urdf_omissions``, ``mjcf_omissions``, ``adams_omissions``, ``osim_omissions``)
and writes each item as one comment that starts with :data:`PREFIX` (the Adams dataset: a
``!`` comment wrapped into its 80 columns, continued by ``!`` lines indented by
:data:`ADAMS_CONTINUATION`); the export stage returns the same items and the command prints
them.  An item is something of the scene the format has no element for (a spring in a URDF)
or that needs a stepping loop outside the file (a contact-switched knee latch in MuJoCo and
OpenSim); approximations of a law the file does carry (IMPACT as MuJoCo's linear contact or
Hunt-Crossley's Hertz law) are stated in the file's notes, not here.
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass

from walkerlab.export.text import comment

__all__ = ["ADAMS_CONTINUATION", "ENGINE_ACTUATION", "MJCF_KNEE_LATCH", "OSIM_KNEE_LATCH",
           "PREFIX", "URDF_GROUND", "URDF_GROUND_3D", "URDF_KNEE_LATCH",
           "Omission", "actuation_omissions", "adams_comments", "lines", "xml_comments"]

#: The text every omission comment starts with (after an XML comment's opening or an Adams
#: comment's exclamation mark and a space).
PREFIX = "Left out: "
#: The indent of an Adams omission comment's continuation lines (after ``!``).
ADAMS_CONTINUATION = "   "


@dataclass(frozen=True)
class Omission:
    """One thing of the scene an exported file does not carry.

    Attributes
    ----------
    what : str
        The scene's item (a field's name or the model's part: "spring hip_spring", "the
        knee latch's switching").
    why : str
        Why the format does not carry it, and where it is instead (a comment, the keyframe
        sidecar, a stepping loop).
    """

    what: str
    why: str

    @property
    def line(self) -> str:
        """The item as one line: ``what: why``."""
        return f"{self.what}: {self.why}"


#: A URDF's ground (it has no world): the first item of every URDF's list (a tree of links:
#: :func:`walkerlab.export.multibody.urdf_omissions`; a spoked wheel).
URDF_GROUND = Omission(
    "the ground (slope, terrain and contact law)",
    "URDF has no world or contact element; the slope is stated in the header, the rigid "
    "gait in the keyframe sidecar (the MJCF export carries ground and contact)")
#: The ground a 3D walker's URDF leaves out (no keyframe sidecar: the MJCF carries the gait).
URDF_GROUND_3D = Omission(
    "the ground (slope, terrain and contact law)",
    "URDF has no world or contact element; the slope is stated in the header (the MJCF "
    "export carries ground, contact and the rigid gait)")
#: A kneed walker's MJCF with its gait (planar, :func:`walkerlab.export.multibody.
#: mjcf_omissions`; in 3D, :func:`walkerlab.export.legs_3d_mjcf.legs3d_mjcf`): the knee
#: latch's equalities are switched outside the file.
MJCF_KNEE_LATCH = Omission(
    "the knee latch's switching", "MuJoCo has no contact-switched lock: the equalities "
    "leg<i>_latch are switched by a stepping loop (walkerlab.export.mujoco_walk.latch_rule)")
#: A kneed walker's OpenSim model (planar, :func:`walkerlab.export.opensim.osim_omissions`; in
#: 3D, :func:`walkerlab.export.opensim_3d.osim3d_omissions`): the latch force is switched
#: outside the file.
OSIM_KNEE_LATCH = Omission(
    "the knee latch's switching", "OpenSim has no contact-switched force: leg<i>_knee_latch "
    "applies no force by default, a stepping loop switches it (walkerlab.export.opensim_walk)")
#: A kneed walker's URDF (planar, :func:`walkerlab.export.urdf_omitted.urdf_omissions`; in 3D,
#: :func:`walkerlab.export.urdf_omitted.legs_urdf_omissions`): no latch, the stop its joint limit.
URDF_KNEE_LATCH = Omission(
    "the knee latch (contact.knee_stop.latch)", "URDF has no contact-switched lock (the "
    "joint limit at 0 is the straight-leg stop)")


#: What an engine's file (``"mjcf"``, ``"osim"``) leaves of ``walker.actuation`` to its stepping
#: loop (:mod:`walkerlab.export.mujoco_walk`, :mod:`walkerlab.export.opensim_walk`):
#: ``(the joint torque laws, the push-off)``, planar and in 3D alike.
ENGINE_ACTUATION = {
    "mjcf": (Omission("the joint torque laws (walker.actuation.torques)", "MJCF has no "
                      "state-dependent torque law: the laws are in the custom text "
                      "walkerlab_actuation, applied by a stepping loop "
                      "(walkerlab.export.mujoco_walk)"),
             Omission("the push-off (walker.actuation.push_off)", "MJCF has no event-switched "
                      "force: a stepping loop applies it from each heel strike "
                      "(walkerlab.export.mujoco_walk)")),
    "osim": (Omission("the joint torque laws (walker.actuation.torques)", "OpenSim has no "
                      "state-dependent torque law: the laws are in the comment "
                      "walkerlab_actuation, a stepping loop sets the CoordinateActuators' "
                      "controls (walkerlab.export.opensim_walk)"),
             Omission("the push-off's switching (walker.actuation.push_off)", "OpenSim has "
                      "no event-switched force: leg<i>_push_off applies no force by default, "
                      "a stepping loop switches it from each heel strike "
                      "(walkerlab.export.opensim_walk)")),
}


def actuation_omissions(engine: str, torques: bool, push_off: bool) -> list[Omission]:
    """What ``engine``'s file leaves of the actuation to its stepping loop
    (:data:`ENGINE_ACTUATION`).

    Parameters
    ----------
    engine : {"mjcf", "osim"}
        The format.
    torques, push_off : bool
        The scene has joint torque laws (``walker.actuation.torques``), a push-off
        (``walker.actuation.push_off``).

    Returns
    -------
    list of Omission
        The torque laws' item, then the push-off's, each where the scene has it.

    Raises
    ------
    KeyError
        An engine without a stepping loop.
    """
    laws, push = ENGINE_ACTUATION[engine]
    return [item for item, has in ((laws, torques), (push, push_off)) if has]


def lines(items) -> tuple[str, ...]:
    """Each item's :attr:`Omission.line`, prefixed by :data:`PREFIX` (the text of its
    comment in the file)."""
    return tuple(PREFIX + o.line for o in items)


def xml_comments(items) -> list[str]:
    """One XML comment per item (:func:`walkerlab.export.text.comment`)."""
    return [comment(text) for text in lines(items)]


def adams_comments(items, width: int = 80) -> list[str]:
    """One ``!`` comment per item, wrapped into ``width`` columns: the first line ``! Left
    out: ...``, the rest ``!`` + :data:`ADAMS_CONTINUATION` + the text (an item's words are
    kept whole; a word longer than a line is not broken)."""
    out = []
    for text in lines(items):
        out += textwrap.wrap(text, width=width, initial_indent="! ",
                             subsequent_indent="!" + ADAMS_CONTINUATION,
                             break_long_words=False, break_on_hyphens=False)
    return out
