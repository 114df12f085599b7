"""The structural kind of a walker, chosen once from its description, and what each kind
can do in each view: the capability table, as data.

A walker description (:class:`~walkerlab.walker.description.Structure`) has many switches
(feet, knees, a torso, springs, legs that differ); only a few of them change the *form* of
the hybrid system - its coordinates, its phases and resets, which bodies touch the ground -
and so which code derives, integrates, optimises and exports it.  Those few decide the
walker's :class:`Kind`:

``straight_legs``
    Two straight legs on point or arc (rolling) feet, with or without an upper body held on
    the legs' bisector and springs: the compass gait family (Goswami, Thuilot & Espiau 1996;
    Garcia et al. 1998; Kuo 2002).  One phase, one heel-strike reset.
``locking_knees``
    Legs with knees that are free in early swing and lock at the knee strike (McGeer 1990,
    "Passive walking with knees"; Hsu Chen 2007): two phases, two resets.
``flat_feet``
    Straight legs on flat feet (massless, or with mass at the ankle) on ankle springs, the
    stance foot going through heel contact, foot flat and heel off (foot modes: a phase
    graph of its own).
``free_joints``
    Every joint free - hips and knees, optionally a hinged torso: the five-link biped
    (Westervelt, Grizzle & Koditschek 2003, RABBIT), driven by joint torques.
``hinged_torso``
    A torso hinged at the hip of two straight legs, every joint free: the three-link walker
    (Grizzle, Abba & Plestan 2001; Westervelt, Grizzle, Chevallereau, Choi & Morris 2007),
    driven by torques between the torso and each leg.  Its model is derived as the
    free-jointed biped's (one flow per step, every coordinate a link's absolute angle), its
    step ends as the straight legs' (the swing foot passes through the ground at mid-stance,
    ignored; the heel strike with the legs symmetric about the slope's normal).
``rolling_polygon``
    A rimless (spoked) wheel: one rigid body rolling on its spokes (McGeer 1990; Coleman,
    Chatterjee & Ruina 1997).  It has no joint, so no actuator.
``straight_legs_3d``
    Straight legs on point feet in three dimensions (``model: compass_gait`` with
    ``space: 3d``): the walker rolls about the fall line through its stance foot and its
    legs pitch; the hips may be apart (``hip_width_m``: the steps alternate sides, Kuo
    1999); an upper body on the bisecting hip (Wisse, Hobbelen & Schwab 2007) rolls with
    the pelvis, a torque between it and a leg acting on the legs' pitches.  The rigid
    model, the MJCF (a free pelvis on footfall patches: it walks in MuJoCo; its hip and
    torso torques and push-off run by walkerlab's stepping loop) and the URDF (its
    actuators left out, as the planar URDF's).  Stairs and footholds (a height along the
    walking direction, level across it) land as the planar walkers' do
    (:mod:`walkerlab.models.hybrid.ground`).
``locking_knees_3d``
    Locking knees (McGeer 1990, "Passive walking with knees") in three dimensions
    (``model: biped`` with ``space: 3d`` and a knee): the kneed walker's two phases and
    resets, its swing knee a pitch joint in the swing leg's rolled sagittal plane, the
    walker rolling about the fall line as the 3D straight legs.  The rigid model (on the
    slope, stairs and footholds), the gym's rigid view, and the MJCF and URDF on its slope.
``rolling_polygon_3d``
    The rimless wheel in three dimensions (``walker.space: 3d``): free about every axis of
    its stance foot - heading, lean and spin (Coleman, Chatterjee & Ruina 1997).  The
    rigid model, the compliant-contact model (a free body on its spoke tips), the MJCF (a
    free body: it rolls in MuJoCo), the URDF and the Adams dataset; stairs and footholds (a
    height along the fall line, level across it) in the rigid model and the MJCF, stairs in
    the contact model and the Adams dataset, landing as the planar wheel's
    (:mod:`walkerlab.models.hybrid.ground`); the other views' cells say why not.

The layers ask the kind (:func:`kind_of`, once), never the switches, and never its name:
the kind holds its parts as objects (:mod:`walkerlab.walker.parts`: :attr:`Kind.rigid`,
:attr:`Kind.landing`, :attr:`Kind.actuators`, :attr:`Kind.reaction`, :attr:`Kind.contact`,
:attr:`Kind.scuff`, :attr:`Kind.collocation`, :attr:`Kind.phases`; kinds that share a
part share its object), each given its behaviour by its layer, and a layer calls the part
it is given
(``kind.rigid.build(...)``) or asks the kind a question (:attr:`Kind.spoked`,
:attr:`Kind.in_3d`, :attr:`Kind.joints_free`, :attr:`Kind.feet_have_modes`,
:attr:`Kind.has_knees`, :attr:`Kind.knees_lock`).
Whether a kind supports a feature in a view is read from
:data:`~walkerlab.walker.capability_cells.CAPABILITIES`; a refusal is
:meth:`Kind.require`'s one line, naming the scene field and the physical or modelling
reason, so ``walkerlab capabilities``, the documentation and the refusals say the same.

Adding a kind is one :class:`Kind` here (its parts: existing objects, or new ones declared
in :mod:`walkerlab.walker.parts` and given their behaviour by their layers) and its row of
:data:`CAPABILITIES` (:mod:`walkerlab.walker.capability_cells`); a supported cell whose
part has no behaviour fails ``tests/test_capabilities.py``, naming the kind and the part.
"""

from __future__ import annotations

from dataclasses import dataclass

from walkerlab.walker import parts as P
from walkerlab.walker.capability_cells import (
    CAPABILITIES,
    CELL_NOTES,
    FEATURE_NOTES,
    STAGE_CELLS,
    STAGE_VIEWS,
)
from walkerlab.walker.parts import Part

__all__ = ["FEATURES", "KINDS", "PART_SLOTS", "VIEWS", "Kind", "KindRefused", "kind_of",
           "table_rows"]

#: the slots of a kind that hold its parts (:mod:`walkerlab.walker.parts`)
PART_SLOTS = ("rigid", "landing", "actuators", "reaction", "contact", "scuff", "collocation",
              "phases")

#: the views of one walker description: name -> what it is
VIEWS = {
    "rigid": "rigid hybrid model (fixedpoint, simulate, studies)",
    "contact": "compliant-contact model (contact-sim)",
    "mjcf": "MuJoCo export (MJCF)",
    "urdf": ("URDF export (links, joints and masses; the gait's keyframe in a sidecar; no "
             "ground, contact or actuator element)"),
    "adams": "MSC Adams dataset (.adm)",
    "osim": "OpenSim model (.osim)",
    "gym": "Gymnasium environment (walkerlab.gym)",
    "optimize": "direct collocation (walkerlab optimize)",
}

#: what a scene can ask of a walker: name -> what it is (and its scene field)
FEATURES = {
    "walk": "the walker itself, passive (walker)",
    "hip_torque": "a torque law at the hips (walker.actuation.torques: hip)",
    "knee_torque": "a torque law at the knees (walker.actuation.torques: knee)",
    "ankle_torque": "a torque law at the ankles (walker.actuation.torques: ankle)",
    "torso_torque": "a torque law between torso and legs (walker.actuation.torques: torso)",
    "push_off": "a push-off impulse before heel strike (walker.actuation.push_off)",
    "ankle_push_off": "an ankle push-off of a flat foot (walker.actuation.ankle_push_off)",
    "virtual_constraints": ("Bezier virtual constraints by output feedback "
                            "(walker.actuation.virtual_constraints)"),
    "hip_roll": ("hip-roll joints and a lateral foot-placement law (walker.hip_roll; "
                 "Kuo 1999)"),
    "round_feet_3d": ("round feet of a walker in 3D: a disc in each leg's sagittal plane, "
                      "rolling (walker.foot_radius_m; McGeer 1990; a planar walker's round "
                      "feet are its walk's walker.leg.foot.kind: arc)"),
    "stairs": "stairs (terrain.kind: stairs)",
    "footholds": "footholds of several heights or slopes (terrain.kind: footholds)",
    "profile": "a height profile (terrain.kind: profile)",
}


class KindRefused(ValueError):
    """A feature the walker's kind does not have in a view: one line naming the field."""


@dataclass(frozen=True)
class Kind:
    """One structural kind of walker (see the module docstring).

    Attributes
    ----------
    name : str
        Its key in :data:`KINDS` and in every layer's table of parts.
    title : str
        A few words for tables and messages.
    reference : str
        Where the kind's model comes from (papers).
    field : str
        The scene field a refusal of the walker itself names first (``walker``; the 3D
        kinds': ``walker.space: 3d``).
    in_3d : bool
        The walker moves in three dimensions (``walker.space: 3d``).
    spoked : bool
        The walker rolls on its spokes (its steps are spoke strikes, not two legs' heel
        strikes): one rigid body, no legs.
    has_knees : bool
        The legs have knees (locking, or free all along).
    knees_lock : bool
        The knees lock at the knee strike (free in early swing).
    feet_have_modes : bool
        The stance foot goes through foot modes (flat feet: heel contact, foot flat, heel
        off).
    rigid : Part
        The rigid model's maker (:mod:`walkerlab.models.hybrid.rigid`): straight legs
        (planar or 3D) or locking knees on one generated flow, flat feet's foot modes,
        every joint free, a spoked wheel.
    landing : Part or None
        How the rigid view lands on stairs and footholds
        (:mod:`walkerlab.models.hybrid.ground`); None, not at all (the capability table
        refuses it first).
    actuators : Part
        How the rigid model drives it (:mod:`walkerlab.models.hybrid.actuated`).
    reaction : Part
        The stance foot's reaction (:mod:`walkerlab.models.hybrid.ground_reaction`).
    contact : Part or None
        The contact view's part (:mod:`walkerlab.models.contact.parts`), None for a
        walker the contact view refuses.
    scuff : Part
        What a contact run names as the cause of the swing foot's scuffs
        (:mod:`walkerlab.analysis.contact.verdict`).
    collocation : Part or None
        Its transcription in the direct collocation (:mod:`walkerlab.optimal.driver`);
        None, not transcribed.
    phases : Part or None
        The symbolic pieces of its phases in the phased transcription
        (:mod:`walkerlab.optimal.transcription.phases`); None, none.
    scene : str
        Its shipped reference scene (:data:`walkerlab.walker.reference_cases.SCENES`).
    """

    name: str
    title: str
    reference: str
    field: str = "walker"
    in_3d: bool = False
    spoked: bool = False
    has_knees: bool = False
    knees_lock: bool = False
    feet_have_modes: bool = False
    rigid: Part = P.RIGID_STRAIGHT_LEGS
    landing: Part | None = P.LANDING_CLEARANCE
    actuators: Part = P.ACTUATORS_NONE
    reaction: Part = P.REACTION_LEG_END
    contact: Part | None = None
    scuff: Part = P.SCUFF_NONE
    collocation: Part | None = None
    phases: Part | None = None
    scene: str = ""

    @property
    def joints_free(self) -> bool:
        """Whether every joint is free, driven by torques (the five-link biped, the
        three-link walker): their models are derived alike."""
        return self.rigid is P.RIGID_FREE_JOINTS

    def parts(self) -> dict[str, Part]:
        """The kind's parts by slot (None where the kind has none)."""
        return {slot: getattr(self, slot) for slot in PART_SLOTS}

    def cell(self, feature: str, view: str) -> str | None:
        """None when the kind supports ``feature`` in ``view``, else the one-line reason
        (:data:`CAPABILITIES`; a view that refuses the walker itself, ``walk``, refuses
        each of its features for that reason, but a feature whose cell is listed as None:
        the view takes it by a set-up of its own, as ``optimize`` designs virtual
        constraints on a walker whose open-loop torques it does not transcribe).

        Raises
        ------
        KeyError
            An unknown feature or view.
        """
        if feature not in FEATURES or view not in VIEWS:
            raise KeyError(f"{feature!r} in {view!r}: features are {', '.join(FEATURES)}; "
                           f"views {', '.join(VIEWS)}")
        row = CAPABILITIES[self.name]
        if feature != "walk" and ("walk", view) in row and row.get((feature, view), "") \
                is not None:  # a view without the walker: none of its features either,
            return row[("walk", view)]  # but one listed as None (its own transcription)
        return row.get((feature, view), row.get((feature, "*")))

    def note(self, view: str, feature: str | None = None) -> str | None:
        """What the supported cell ``feature`` of the kind in ``view`` rests on beyond its
        measured agreement (:data:`FEATURE_NOTES`), else what every supported cell of the
        kind in ``view`` rests on (:data:`CELL_NOTES`), or None."""
        return FEATURE_NOTES.get((self.name, feature, view)) or CELL_NOTES.get((self.name, view))

    def supports(self, feature: str, view: str) -> bool:
        """Whether the kind has ``feature`` in ``view``."""
        return self.cell(feature, view) is None

    def require(self, feature: str, view: str, field: str) -> None:
        """Refuse ``feature`` in ``view`` if the table does.

        Parameters
        ----------
        feature, view : str
            Keys of :data:`FEATURES` and :data:`VIEWS`.
        field : str
            The scene field (or command option) the refusal names, first in its line.

        Raises
        ------
        KindRefused
            ``"<field>: <reason>"``, one line.
        """
        why = self.cell(feature, view)
        if why is not None:
            raise KindRefused(f"{field}: {why}")

    def require_stage(self, stage: str) -> None:
        """Refuse the pipeline stage ``stage`` (``walkerlab <stage>``) if the kind does not
        take it: its view's cell (:data:`STAGE_VIEWS`) or its study's (:data:`STAGE_CELLS`),
        naming :attr:`field` - asked before any work.

        Raises
        ------
        KindRefused
            ``"<field>: <reason>"``, one line.
        """
        if stage in STAGE_VIEWS:
            self.require(*STAGE_VIEWS[stage], self.field)
        why = STAGE_CELLS.get(self.name, {}).get(stage)
        if why is not None:
            raise KindRefused(f"{self.field}: {why}")


#: every kind, in the order tables list them
KINDS = {k.name: k for k in (
    Kind("straight_legs", "straight legs (point or arc feet)",
         "Goswami, Thuilot & Espiau 1996; Garcia et al. 1998; Kuo 2002",
         contact=P.CONTACT_STRAIGHT_LEGS, actuators=P.ACTUATORS_HIPS,
         scuff=P.SCUFF_STRAIGHT_LEG, collocation=P.COLLOCATION_STRAIGHT_LEGS,
         phases=P.PHASES_STRAIGHT_LEGS, scene="configs/paper_rods.yaml"),
    Kind("locking_knees", "knees that lock at the knee strike",
         "McGeer 1990 (passive walking with knees); Hsu Chen 2007", has_knees=True,
         knees_lock=True, rigid=P.RIGID_LOCKING_KNEES, contact=P.CONTACT_LOCKING_KNEES,
         actuators=P.ACTUATORS_LATCHED_KNEES, scuff=P.SCUFF_UNLATCHED_KNEE,
         collocation=P.COLLOCATION_LOCKING_KNEES, phases=P.PHASES_LOCKING_KNEES,
         scene="configs/kneed.yaml"),
    Kind("flat_feet", "flat feet on ankle springs (foot modes)",
         "McGeer 1990; Collins, Wisse & Ruina 2001", feet_have_modes=True,
         rigid=P.RIGID_FLAT_FEET,
         landing=P.LANDING_FLAT_FEET, reaction=P.REACTION_FLAT_FEET,
         contact=P.CONTACT_FLAT_FEET, actuators=P.ACTUATORS_ANKLES,
         collocation=P.COLLOCATION_FLAT_FEET, phases=P.PHASES_FLAT_FEET,
         scene="configs/flat_feet.yaml"),
    Kind("free_joints", "free hips and knees, hinged torso (five-link biped)",
         "Westervelt, Grizzle & Koditschek 2003 (RABBIT)", has_knees=True,
         rigid=P.RIGID_FREE_JOINTS, contact=P.CONTACT_FIVE_LINK,
         actuators=P.ACTUATORS_JOINTS, collocation=P.COLLOCATION_FIVE_LINK,
         scene="configs/rabbit.yaml"),
    Kind("hinged_torso", "a torso hinged on straight legs (three-link walker)",
         "Grizzle, Abba & Plestan 2001; Westervelt, Grizzle, Chevallereau, Choi & Morris "
         "2007", rigid=P.RIGID_FREE_JOINTS, contact=P.CONTACT_THREE_LINK,
         actuators=P.ACTUATORS_JOINTS, scene="configs/threelink.yaml"),
    Kind("rolling_polygon", "rimless (spoked) wheel",
         "McGeer 1990; Coleman, Chatterjee & Ruina 1997", spoked=True,
         rigid=P.RIGID_SPOKES, reaction=P.REACTION_HUB, contact=P.CONTACT_WHEEL,
         scene="configs/rimless_wheel.yaml"),
    Kind("rolling_polygon_3d", "rimless (spoked) wheel in 3D (heading, lean, spin)",
         "Coleman, Chatterjee & Ruina 1997", "walker.space: 3d", in_3d=True, spoked=True,
         rigid=P.RIGID_SPOKES, reaction=P.REACTION_HUB,
         contact=P.CONTACT_WHEEL_3D, scene="configs/rimless_wheel_3d.yaml"),
    Kind("straight_legs_3d", "straight legs in 3D with hip width (roll and pitch)",
         "Kuo 1999", "walker.space: 3d", in_3d=True, rigid=P.RIGID_STRAIGHT_LEGS_3D,
         contact=P.CONTACT_LEGS_3D, actuators=P.ACTUATORS_LEGS_3D,
         collocation=P.COLLOCATION_STRAIGHT_LEGS, phases=P.PHASES_STRAIGHT_LEGS,
         scene="configs/hip_width.yaml"),
    Kind("locking_knees_3d", "knees that lock at the knee strike, in 3D with hip width",
         "McGeer 1990 (passive walking with knees); Kuo 1999", "walker.space: 3d",
         in_3d=True, has_knees=True, knees_lock=True, rigid=P.RIGID_LOCKING_KNEES,
         actuators=P.ACTUATORS_KNEES_3D, reaction=P.REACTION_NONE,
         contact=P.CONTACT_KNEES_3D, collocation=P.COLLOCATION_LOCKING_KNEES,
         phases=P.PHASES_LOCKING_KNEES, scene="configs/kneed_3d.yaml"),
)}



def kind_of(structure) -> Kind:
    """The kind of a walker structure (:class:`~walkerlab.walker.description.Structure`):
    the one place the structure's switches choose among :data:`KINDS`.

    Parameters
    ----------
    structure : walkerlab.walker.description.Structure

    Returns
    -------
    Kind
    """
    if structure.spokes:
        return KINDS["rolling_polygon_3d" if structure.in_3d else "rolling_polygon"]
    if structure.in_3d:
        return KINDS["locking_knees_3d" if structure.knee else "straight_legs_3d"]
    if structure.free_knees:
        return KINDS["free_joints"]
    if structure.hinged_torso:
        return KINDS["hinged_torso"]
    if structure.foot == "flat":
        return KINDS["flat_feet"]
    if structure.knee:
        return KINDS["locking_knees"]
    return KINDS["straight_legs"]


def table_rows() -> list[dict]:
    """The capability table, one row per kind × feature × view: ``{"kind", "feature",
    "view", "supported", "reason"}`` (``reason`` "" when supported), and for a supported
    cell its evidence (:mod:`walkerlab.walker.capability_evidence`): ``verified`` (measured
    within its tolerance), ``case`` (its reference case), ``quantity``, ``measured``,
    ``tolerance``, ``unit``, ``detail`` (with the cell's note, :meth:`Kind.note`, when its
    kind has one in the view), ``note``, ``commit``, ``check`` (the kind of check behind
    the number: :data:`walkerlab.walker.capability_evidence.CHECK_KINDS`) and
    ``not_checked`` (a check of the view that did not run on the case: not counted as
    passed) - what ``walkerlab capabilities --json`` prints."""
    from walkerlab.walker.capability_evidence import cell_evidence, verified

    rows = []
    for kind in KINDS.values():
        for feature in FEATURES:
            for view in VIEWS:
                why = kind.cell(feature, view)
                row = {"kind": kind.name, "feature": feature, "view": view,
                       "supported": why is None, "reason": why or ""}
                if why is None:
                    e = cell_evidence(kind.name, feature, view) or {}
                    note = kind.note(view, feature) or ""
                    detail = e.get("detail", "")
                    if note and note not in detail:
                        detail = f"{detail}; {note}" if detail else note
                    row.update(verified=verified(kind.name, feature, view),
                               case=e.get("case", ""), quantity=e.get("quantity", ""),
                               measured=e.get("value"), tolerance=e.get("tolerance"),
                               unit=e.get("unit", ""), detail=detail, note=note,
                               commit=e.get("commit", ""), check=e.get("check", ""),
                               not_checked=e.get("not_checked", ""))
                rows.append(row)
    return rows
