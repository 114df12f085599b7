"""A walker kind's parts as objects: each carries its behaviour in each layer that has one.

A kind (:class:`walkerlab.walker.kinds.Kind`) is made of parts - the rigid model's maker,
the landing on stairs and footholds, the actuators, the stance reaction, the contact view's
part, the contact run's scuff cause, the collocation's transcription and its phases' symbolic
pieces - and kinds that share
a part share its object (the planar and 3D straight legs share one rigid maker).  A part is
declared here, at the walker's floor, with its slot and name; the layer that gives the part
its behaviour provides it on the part object (:meth:`Part.provide`, once, in the module that
defines the behaviour), as Drake attaches force elements to its ``MultibodyPlant``: the
part's behaviour lives in its layer (the rigid makers with the rigid model, the contact
parts with the contact model, the transcriptions with the collocation), the kind holds the
part, and a layer calls the part it is given (``kind.rigid.build(...)``) - no layer keeps a
table keyed by part or kind words, none switches on a kind's name.

The dependencies still point down: this module imports nothing of the layers; a layer
imports the parts it gives behaviour to.  A part whose layer has not provided its behaviour
names the kind's part and the layer in one line (:class:`PartMissing`); the capability
table's supported cells each need their parts' behaviours
(``tests/test_capabilities.py``).
"""

from __future__ import annotations

__all__ = ["PARTS", "Part", "PartMissing", "part"]


class PartMissing(LookupError):
    """A part whose layer has not given it its behaviour: one line, naming the part."""


class Part:
    """One part of one or more walker kinds, and its behaviour in its layer.

    Parameters
    ----------
    slot : str
        The layer's slot the part fills (``rigid``, ``landing``, ``actuators``,
        ``reaction``, ``contact``, ``scuff``, ``collocation``, ``phases``): the kind's
        attribute of the same name holds it.
    name : str
        What the part is, in a few words (``straight or locking-knee legs``).
    **facts
        What a layer below the behaviour's own may ask of the part (``one_step=True``: the
        collocation transcribes one step of one phase), read as attributes.

    Notes
    -----
    The behaviour is an object (or a function) of the part's layer; attributes not found
    on the part are read from it, so that ``kind.rigid.build(...)`` calls the rigid
    model's maker of the kind.  Parts are pickled by their slot and name (a worker process
    finds the same object, its behaviour provided when its layer is imported there).
    """

    __slots__ = ("slot", "name", "facts", "_behaviour")

    def __init__(self, slot: str, name: str, **facts):
        self.slot, self.name, self.facts = slot, name, facts
        self._behaviour = None
        PARTS[(slot, name)] = self

    def provide(self, behaviour):
        """Give the part its behaviour in its layer (once; the layer's module does it at
        import).  Returns ``behaviour``.

        Raises
        ------
        ValueError
            The part already has a behaviour (two layers claiming one part).
        """
        if self._behaviour is not None and self._behaviour is not behaviour:
            raise ValueError(f"{self}: its behaviour is already provided")
        self._behaviour = behaviour
        return behaviour

    @property
    def provided(self) -> bool:
        """Whether the part's layer has given it its behaviour."""
        return self._behaviour is not None

    @property
    def behaviour(self):
        """The part's behaviour in its layer.

        Raises
        ------
        PartMissing
            Its layer has not provided it (one line naming the part).
        """
        if self._behaviour is None:
            raise PartMissing(f"{self}: no behaviour provided by its layer")
        return self._behaviour

    def __call__(self, *args, **kwargs):
        return self.behaviour(*args, **kwargs)

    def __getattr__(self, attr: str):
        if attr.startswith("_"):
            raise AttributeError(attr)
        if attr in self.facts:
            return self.facts[attr]
        return getattr(self.behaviour, attr)

    def __reduce__(self):
        return (part, (self.slot, self.name))

    def __repr__(self) -> str:
        return f"{self.slot} part {self.name!r}"


#: every part declared, by (slot, name)
PARTS: dict[tuple[str, str], Part] = {}


def part(slot: str, name: str) -> Part:
    """The declared part of ``slot`` named ``name`` (how a pickled part is found again).

    Raises
    ------
    KeyError
        No such part.
    """
    return PARTS[(slot, name)]


# ------------------------------------------------------------ the parts of the kinds
# the rigid model's makers (walkerlab.models.hybrid.rigid)
RIGID_STRAIGHT_LEGS = Part("rigid", "straight legs: one generated flow, the heel strike")
RIGID_LOCKING_KNEES = Part("rigid", "locking knees: free swing knee, knee strike, heel strike")
RIGID_STRAIGHT_LEGS_3D = Part("rigid", "straight legs in 3D: roll and pitch, the heel strike")
RIGID_FLAT_FEET = Part("rigid", "flat feet: the stance foot's modes")
RIGID_FREE_JOINTS = Part("rigid", "every joint free: one flow per step")
RIGID_SPOKES = Part("rigid", "a spoked wheel rolling on its spokes")

# the landing on stairs and footholds (walkerlab.models.hybrid.ground)
LANDING_CLEARANCE = Part("landing", "the swing foot's generated clearance")
LANDING_FLAT_FEET = Part("landing", "a guard per stance foot mode")

# the rigid model's actuators (walkerlab.models.hybrid.actuated)
ACTUATORS_HIPS = Part("actuators", "hip torques and push-off of straight legs")
ACTUATORS_LATCHED_KNEES = Part("actuators", "hip and knee torques of latching knees")
ACTUATORS_JOINTS = Part("actuators", "a torque at every free joint")
ACTUATORS_ANKLES = Part("actuators", "hip and ankle torques of flat feet")
ACTUATORS_LEGS_3D = Part("actuators", "hip pitch torques, push-off and hip roll in 3D")
ACTUATORS_KNEES_3D = Part("actuators", "hip and knee pitch torques and push-off of "
                          "locking knees in 3D")
ACTUATORS_NONE = Part("actuators", "none: a passive walker")

# the stance foot's reaction (walkerlab.models.hybrid.ground_reaction)
REACTION_LEG_END = Part("reaction", "at the stance leg's end")
REACTION_FLAT_FEET = Part("reaction", "flat feet: the heel's and toe's")
REACTION_HUB = Part("reaction", "at the stance spoke's tip, the hub's")
REACTION_NONE = Part("reaction", "none: the rigid state not mapped to the floating view")

# the contact view's parts (walkerlab.models.contact.parts)
CONTACT_STRAIGHT_LEGS = Part("contact", "straight legs")
CONTACT_LOCKING_KNEES = Part("contact", "locking knees")
CONTACT_FLAT_FEET = Part("contact", "flat feet")
CONTACT_FIVE_LINK = Part("contact", "five-link biped")
CONTACT_THREE_LINK = Part("contact", "three-link walker")
CONTACT_WHEEL = Part("contact", "spoked wheel")
CONTACT_WHEEL_3D = Part("contact", "spoked wheel in 3D")
CONTACT_LEGS_3D = Part("contact", "straight legs in 3D")
CONTACT_KNEES_3D = Part("contact", "locking knees in 3D")

# what a contact run names as the cause of a swing foot's scuffs
# (walkerlab.analysis.contact.verdict)
SCUFF_STRAIGHT_LEG = Part("scuff", "the straight swing leg's toe at mid-stance")
SCUFF_UNLATCHED_KNEE = Part("scuff", "a knee that did not latch")
SCUFF_NONE = Part("scuff", "none named")

# the direct collocation's transcriptions (walkerlab.optimal.driver)
COLLOCATION_STRAIGHT_LEGS = Part("collocation", "one step of straight legs", one_step=True)
COLLOCATION_LOCKING_KNEES = Part("collocation", "the kneed walker's phases", one_step=False)
COLLOCATION_FLAT_FEET = Part("collocation", "the flat feet's foot modes", one_step=False)
COLLOCATION_FIVE_LINK = Part("collocation", "the five-link biped's step", one_step=False)

# the phased transcription's symbolic pieces (walkerlab.optimal.transcription.phases)
PHASES_STRAIGHT_LEGS = Part("phases", "straight legs: one phase")
PHASES_LOCKING_KNEES = Part("phases", "locking knees: unlocked and locked swing")
PHASES_FLAT_FEET = Part("phases", "flat feet: the stance foot's modes")
