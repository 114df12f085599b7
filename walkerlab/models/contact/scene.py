"""The contact model of a validated scene: :func:`contact_setup` turns the scene once into
the typed objects a contact run needs (:class:`ContactSetup`), which builds the walker
(running it is :mod:`walkerlab.analysis.contact.sim`).

The ``contact-sim`` stage, the adjustment, :mod:`walkerlab.analysis.contact.periodic`, the
stability maps and the sweep points all build their walker here, so a scene means the same
contact model everywhere.  This module imports settings only (:mod:`walkerlab.config`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from walkerlab.codegen.floating import check_masses, coordinate_names
from walkerlab.config import (
    ContactSettings,
    ContactSimSettings,
    Scene,
    SolverSettings,
    TerrainSettings,
)
from walkerlab.config.actuation import Actuation
from walkerlab.config.sections import with_default_section
from walkerlab.walker.kinds import KindRefused
from walkerlab.walker.layout import StateLayout
from walkerlab.walker.plant import Plant

from .actuation import ContactActuators
from .joint_torques import JointTorqueActuators
from .laws import ContactParamsSI, KneeStopSI, torsional_friction_m
from .model import ContactWalker
from .parts import contact_part
from .rigid_limit import contact_si
from .terrain import check_ground, ground_drops

if TYPE_CHECKING:
    from walkerlab.execution.pending import CompiledElsewhere
    from walkerlab.walker.description import WalkerData

__all__ = ["ContactSceneError", "ContactSetup", "build", "contact_setup", "ideal_step_length",
           "patches_holding_the_roll"]


#: why the contact periodic gait refuses a ground whose steps differ
SEVERAL_STEPS_PERIODIC = (
    "contact_sim.start / periodic_gait: the contact periodic gait is one step's map; footholds "
    "of several heights have a gait of several steps: start from the rigid gait (start: "
    "ideal, periodic_gait: false)")
#: the periodic gait's outcome on such a ground (``contact_sim.periodic_gait: true``)
SEVERAL_STEPS_OUTCOME = "several_steps"


class ContactSceneError(ValueError):
    """The scene lacks a section the contact model needs (one-line message)."""


def ideal_step_length(walker: ContactWalker, x_ideal, along_slope: bool = False) -> float:
    """Advance [m] of the ideal gait per step, from its post-impact state ``x_ideal`` (role
    order of the rigid model): the distance between the two feet's contact points with the
    stance leg placed by :meth:`ContactWalker.link_state_from_ideal` (the foot-to-foot chord
    at heel strike; compass gait ``2 L sin((th_st - th_sw) / 2)``), plus, for arc feet of
    radius R, the roll ``R (th_st - th_sw)`` of the stance arc over the step (on the periodic
    gait the stance leg turns from the post-impact stance angle to the post-impact swing
    angle).  For flat feet, from the trailing foot's heel touchdown point to the new stance
    heel (the rigid view's reference points): at heel strike the trailing foot stands on its
    toe (heel off; flat if its ankle is on the slope), so its toe lies on the slope at
    ``toe`` from its ankle, ``s_toe = s_ankle + sqrt(toe^2 - h_ankle^2)``, and its heel
    touched down at ``s_toe - (heel + toe)`` (the post-impact state keeps the legs' angles;
    only the trailing foot's angle is lost, snapped to rest).  The checkerboard patches are
    spaced by it.  ``along_slope``: the chord's component along the slope instead (stairs
    and footholds, where the feet at heel strike stand a riser apart: the footholds'
    spacing)."""
    return contact_part(walker.structure).step_length(walker, x_ideal, along_slope)


@dataclass(frozen=True)
class ContactSetup:
    """A scene read once for the contact model (:func:`contact_setup`): everything a contact
    run needs, typed; the contact law is in SI (its conversion runs here only).

    Attributes
    ----------
    name : str
        The scene's name (for one-line messages).
    law : ContactSettings
        The contact section as written (units of the scene; the drop test and the stiffness
        family read it).
    law_si : ContactParamsSI
        The contact law in SI with its ``stiffness_family`` applied.
    knee_stop : KneeStopSI
        The knee stop in SI.
    walker : WalkerData
        The walker's structure and parameters on the scene's slope.
    terrain : TerrainSettings
    sim : ContactSimSettings
        Run options (``contact_sim``; defaults when the scene has none).
    solver : SolverSettings
        ``contact_solver`` (default :meth:`SolverSettings.for_contact`).
    actuators : ContactActuators or JointTorqueActuators or None
        The walker's actuators as forces (:mod:`walkerlab.models.contact.actuation`; a
        free-jointed biped's joint torques :mod:`walkerlab.models.contact.joint_torques`);
        None for a passive walker.
    rhs_ready : walkerlab.execution.pending.CompiledElsewhere or None
        A side process compiling the walker's compiled right-hand side (the stage's hand-off:
        the walkers :meth:`build` makes carry it to the compiled backend); None: none.
    scene : Scene or None
        The scene read (its rigid walker lays footholds of several heights at the rigid
        gait's footfalls: :mod:`walkerlab.analysis.contact.footfalls`); None: not kept.
    plant : walkerlab.walker.plant.Plant or None
        The scene's walker described once (``walker`` is its ``data``), for the rigid
        walker built from it; None: not kept.
    """

    name: str
    law: ContactSettings
    law_si: ContactParamsSI
    knee_stop: KneeStopSI
    walker: WalkerData
    terrain: TerrainSettings
    sim: ContactSimSettings
    solver: SolverSettings
    actuators: ContactActuators | JointTorqueActuators | None = None
    rhs_ready: CompiledElsewhere | None = None
    scene: Scene | None = None
    plant: Plant | None = None

    @property
    def steps_differ(self) -> bool:
        """The ground's steps differ (footholds of several heights): its patches lie at the
        rigid gait's footfalls step by step (``step_lengths_m`` of :meth:`build`)."""
        return not self.terrain.is_slope and len(ground_drops(self.terrain)) > 1

    @property
    def patches_follow_feet(self) -> bool:
        """The ground is footholds on checkerboard lanes: each step's landing is where the
        foot lands (``h_k`` below the stance foot's level, wherever that is), so a run whose
        footfalls drift off the patches laid at the rigid gait's may lay them at its own
        (:func:`walkerlab.analysis.contact.sim.simulate_from`); stairs' treads stay where
        they are."""
        return self.terrain.kind == "footholds" and self.terrain.lanes == "checkerboard"

    def model(self) -> ContactWalker:
        """The setup's contact walker on no terrain: its law, knee stop, flat feet,
        actuators, a wheel's regularising hub inertia (``contact.hub_inertia_kg_m2``) and
        the compiled right-hand side's hand-off, the one construction :meth:`build` and the
        in-memory :class:`walkerlab.api.walker.ContactWalker` share.

        Returns
        -------
        ContactWalker
        """
        st = self.walker.structure
        return ContactWalker(contact=self.law_si, data=self.walker, knee_stop=self.knee_stop,
                             flat_foot=self.law.flat_foot(), actuators=self.actuators,
                             rhs_ready=self.rhs_ready, hub_inertia=self.law.hub_inertia_kg_m2,
                             torsion=torsional_friction_m(self.law, self.walker.leg_length_m,
                                                          st.in_3d),
                             hold_heading=self.law.hold_heading)

    def held_actuators(self):
        """Actuators with no law of the scene's (an empty actuation): what a run that holds a
        force from outside (a Gymnasium action) carries on a passive walker; the kind's own
        class (:func:`walkerlab.models.contact.parts.contact_part`).

        Returns
        -------
        ContactActuators or JointTorqueActuators
        """
        st = self.walker.structure
        empty = Actuation.model_construct(torques=[], push_off=None, ankle_push_off=None)
        return contact_part(st).actuators(self.walker, empty,
                                          coordinate_names(st, self.law.hold_heading), 0.0)

    def build(self, x_ideal: np.ndarray, n_steps: int, step_length_m: float | None = None,
              step_lengths_m: tuple | None = None):
        """ContactWalker of the setup with checkerboard patches from the ideal step length.

        Parameters
        ----------
        x_ideal : ndarray (2n,)
            Ideal fixed point (role order of the rigid walker, leg2 = stance) [rad, rad/s].
        n_steps : int
            Steps the run may take (sets how many patches are laid out).
        step_length_m : float, optional
            Patch spacing [m] instead of the ideal step length (a run started on the contact
            model's own periodic gait lays its patches at that gait's footfalls).
        step_lengths_m : tuple of float, optional
            Each step's advance along the slope [m] in turn, from the first step of
            ``x_ideal`` on (footholds of several heights: the rigid period-n gait's steps,
            :func:`walkerlab.analysis.contact.footfalls.rigid_step_lengths`); replaces the
            spacing.

        Returns
        -------
        walker : ContactWalker
        step_length : float
            Ideal step length [m] (the patch spacing unless ``step_length_m`` is given; with
            ``step_lengths_m`` their mean).

        Raises
        ------
        ValueError
            Footholds of several heights without ``step_lengths_m`` (one line).
        """
        probe = self.model()
        shift = contact_part(probe.structure).patch_shift(probe, x_ideal)  # a disc's roll
        terrain = self._holding_the_roll(shift)
        if step_lengths_m is not None:
            return (probe.on_terrain(terrain, step_length=float(np.mean(step_lengths_m)),
                                     n_steps=n_steps + 4, step_lengths=tuple(step_lengths_m),
                                     shift=shift),
                    float(np.mean(step_lengths_m)))
        step_length = ideal_step_length(probe, x_ideal, along_slope=not self.terrain.is_slope)
        return probe.on_terrain(terrain, step_length=step_length_m or step_length,
                                n_steps=n_steps + 4, shift=shift), step_length

    def _holding_the_roll(self, shift: float) -> TerrainSettings:
        """The ground's patches, long enough to hold a rolling foot
        (:func:`patches_holding_the_roll`, ``shift`` from
        :meth:`walkerlab.models.contact.parts.Legs3DPart.patch_shift`)."""
        try:
            return patches_holding_the_roll(self.terrain, shift, self.scene is not None
                                            and self.scene.terrain is not None)
        except ValueError as err:
            raise ContactSceneError(f"scene '{self.name}': {err}") from None


def patches_holding_the_roll(terrain: TerrainSettings, shift: float, own: bool
                             ) -> TerrainSettings:
    """The ground's patches, long enough to hold a rolling foot: a 3D walker's round foot
    touches down ``shift`` [m] behind its patch's centre (the middle of its roll over the
    stance: the contact model's and the MJCF's patches are centred there).  A default
    ground (``own`` False: no ``terrain`` section) whose patch would leave the touchdown off
    it is lengthened by the roll, keeping the default's margin at either end (``2 (|shift|
    + w / 2)``; configs/collins2001_stable.yaml's feet, 0.21 m fore-aft, roll 0.145 m a
    stance on the 0.10 m default); a scene's own patches are kept.

    Parameters
    ----------
    terrain : TerrainSettings
    shift : float
        [m].
    own : bool
        The scene gives its ``terrain`` section.

    Returns
    -------
    TerrainSettings
        ``terrain`` itself when its patches hold the touchdown.

    Raises
    ------
    ValueError
        The scene's ``terrain.patch_width_m`` leaves the touchdown off its patch (one line,
        the width that holds it).
    """
    half = 0.5 * terrain.patch_width_m
    if abs(shift) < half:
        return terrain
    wide = 2.0 * (abs(shift) + half)
    if own:
        raise ValueError(
            f"terrain.patch_width_m: {terrain.patch_width_m:g} m patches do not hold the "
            f"rolling foot, which touches down {abs(shift):.3g} m behind its patch's centre "
            f"(its roll over a stance about {2 * abs(shift):.3g} m): give at least "
            f"{2 * abs(shift) + 0.02:.2g} m ({wide:.2g} m keeps the margin of the default's)")
    return terrain.model_copy(update={"patch_width_m": wide})


def contact_setup(scene: Scene, periodic: bool = False, *, plant) -> ContactSetup:
    """The scene turned once into what a contact run needs (any walker with positive leg
    masses): its walker data, the contact law and knee stop in SI, terrain, run options and
    solver settings.

    Parameters
    ----------
    scene : Scene
    periodic : bool
        The run also finds the contact periodic gait (``contact-sim --periodic``,
        :meth:`walkerlab.api.walker.ContactWalker.periodic_gait`): the scene is checked as
        with ``contact_sim.periodic_gait: true``.
    plant : walkerlab.walker.plant.Plant
        The scene's walker described once, by the caller that holds it (a stage, the API).

    A scene without a ``contact`` section runs on the section's defaults (the paper's
    contact law: :class:`walkerlab.config.ContactSettings`), as ``contact: {}`` does: the
    section configures the contact model, the stage the user asks for runs it.

    Raises
    ------
    ContactSceneError
        Actuators with a pinned or non-ideal start (or a time law
        with the contact periodic gait), a joint the walker does not have, a walker with a
        massless body, flat feet without
        ``contact.flat_foot_mass_kg`` / ``flat_foot_inertia_kg_m2``, a pinned stance foot
        that is not a point, a ground the contact model does not build (a height profile,
        footholds of their own slopes, footholds on continuous ground), or the periodic gait
        (``contact_sim.start: periodic_gait``, ``periodic_gait: true`` or ``periodic``) of a
        walker whose step map it does not carry (a rimless wheel), or a start from it
        (``contact_sim.start: periodic_gait``) on footholds of several heights
        (:data:`SEVERAL_STEPS_PERIODIC`; ``periodic_gait: true`` there records the gait as
        not found, with that reason) (one line).
    """
    scene = with_default_section(scene, "contact")  # left out: its defaults (contact: {})
    if scene.contact is None:  # a section with a required field has no defaults
        raise ContactSceneError(f"scene '{scene.name}' has no 'contact' section, which the "
                                "contact model needs")
    contact = scene.contact
    try:
        check_ground(scene.terrain)
    except ValueError as err:
        raise ContactSceneError(f"scene '{scene.name}': {err}") from None
    cs = scene.contact_sim or ContactSimSettings()
    # checked as the run uses it: with its periodic gait when the caller asks for one
    checked = cs.model_copy(update={"periodic_gait": True}) if periodic else cs
    data = plant.data
    ground = "slope" if scene.terrain is None else scene.terrain.kind
    if ground in ("stairs", "footholds", "profile"):  # the kind's cell of that ground

        try:
            data.structure.kind.require(ground, "contact", f"terrain.kind: {ground}")
        except KindRefused as err:
            raise ContactSceneError(f"scene '{scene.name}': {err}") from None
    actuators = _actuators(scene, data, checked)
    if cs.pin_stance_until != "none" and data.structure.foot != "point":
        raise ContactSceneError(f"scene '{scene.name}': contact_sim.pin_stance_until: pinning "
                                f"the stance foot needs point feet (this walker's are "
                                f"{data.structure.foot})")
    try:
        check_masses(data.structure)
    except ValueError as err:
        raise ContactSceneError(f"scene '{scene.name}': {err}") from None
    part = contact_part(data.structure)
    cs = _start_of(scene, part, cs)
    why = part.check(scene, data, checked)
    if why is not None:  # the kind's own refusal (a flat foot's mass, a wheel's ground)
        raise ContactSceneError(f"scene '{scene.name}': {why}")
    if cs.start == "periodic_gait" and len(ground_drops(scene.terrain)) > 1:
        # the run cannot start there (periodic_gait: true records the gait as not found)
        raise ContactSceneError(f"scene '{scene.name}': {SEVERAL_STEPS_PERIODIC}")
    _check_start_offset(scene, data.structure, cs)
    si, knee = contact_si(contact)  # the contact law in SI: once per run
    return ContactSetup(scene.name, contact, si, knee, data, scene.terrain_or_default(),
                        cs, scene.contact_solver or SolverSettings.for_contact(), actuators,
                        scene=scene, plant=plant)


def _check_start_offset(scene: Scene, structure, cs: ContactSimSettings) -> None:
    """Refuse, before any search, a ``contact_sim.start_offset`` naming a state the walker
    does not have (its rigid states, :meth:`walkerlab.walker.layout.StateLayout.rigid` of
    the structure's roles: what the run adds the offset to), in one line listing every
    valid name.

    Raises
    ------
    ContactSceneError
    """
    if cs.start_offset is None:
        return

    try:
        cs.start_offset.as_array(list(StateLayout.rigid(structure.roles).names))
    except ValueError as exc:
        raise ContactSceneError(f"scene '{scene.name}': contact_sim.start_offset.{exc}"
                                ) from None


def _start_of(scene: Scene, part, cs: ContactSimSettings) -> ContactSimSettings:
    """The run's settings ``cs`` with its start decided (:func:`contact_setup`): a passive
    walker whose contact part starts at mid-stance (``part.mid_stance_start``: flat feet)
    on its slope starts there unless the scene says otherwise.

    Raises
    ------
    ContactSceneError
        ``contact_sim.start: mid_stance`` for a walker without flat feet (one line).
    """
    if part.mid_stance_start and "start" not in cs.model_fields_set \
            and scene.walker.actuation is None and scene.terrain_or_default().is_slope:
        # a passive flat-footed walker on its slope starts at the rigid gait's mid-stance
        # unless the scene says otherwise (walkerlab.analysis.contact.sim.rigid_mid_stance:
        # from the post-impact state its first steps are 8-9 % short and it trips off its
        # patches)
        cs = cs.model_copy(update={"start": "mid_stance"})
    if cs.start == "mid_stance" and not part.mid_stance_start:
        raise ContactSceneError(f"scene '{scene.name}': contact_sim.start: mid_stance starts "
                                "a flat foot flat on the ground (this walker has no flat "
                                "feet): use start: ideal")
    return cs


def _actuators(scene: Scene, data, cs: ContactSimSettings
               ) -> ContactActuators | JointTorqueActuators | None:
    """The scene's actuators in the contact view, or None; one-line refusals."""
    spec = scene.walker.actuation
    if spec is None:
        return None

    st = data.structure
    if getattr(spec, "virtual_constraints", None) is not None:
        try:
            st.kind.require("virtual_constraints", "contact",
                            "walker.actuation.virtual_constraints")
        except KindRefused as err:
            raise ContactSceneError(f"scene '{scene.name}': {err}") from None
    part = contact_part(st)
    why = part.actuators_refusal(scene, data)
    if why is not None:
        raise ContactSceneError(f"scene '{scene.name}': {why}")
    if cs.pin_stance_until != "none":
        raise ContactSceneError(f"scene '{scene.name}': contact_sim.pin_stance_until: the "
                                "pinned start phase carries no actuators: leave it 'none'")
    if cs.start not in ("ideal", "periodic_gait"):
        raise ContactSceneError(f"scene '{scene.name}': contact_sim.start: {cs.start}: a "
                                "powered walker's contact run starts from the rigid gait "
                                "(start: ideal) or its own periodic gait (periodic_gait)")
    if cs.start == "periodic_gait" or cs.periodic_gait:
        if part.periodic_actuators is not None:
            raise ContactSceneError(f"scene '{scene.name}': {part.periodic_actuators}")
        tr = [t.law.time_reference for t in getattr(spec, "torques", None) or ()]
        if any(r is not None for r in tr):
            raise ContactSceneError(f"scene '{scene.name}': walker.actuation: a torque law on "
                                    "time since the heel strike has no contact periodic gait "
                                    "(contact_sim.start / periodic_gait): use a phase law")
        if getattr(spec, "ankle_push_off", None) is not None:
            raise ContactSceneError(f"scene '{scene.name}': contact_sim.start: the contact "
                                    "periodic gait's step map does not switch an ankle "
                                    "push-off on at heel off: start from the rigid gait "
                                    "(start: ideal, periodic_gait: false)")
    pulse = scene.contact.push_off_pulse_s()
    try:  # the kind's actuators (a five-link biped's: the rigid view's joint torques)
        return part.actuators(data, spec, coordinate_names(st, scene.contact.hold_heading),
                              pulse)
    except ValueError as err:
        raise ContactSceneError(f"scene '{scene.name}': {err}") from None


def build(scene: Scene, x_ideal: np.ndarray, n_steps: int, step_length_m: float | None = None,
          *, plant: Plant):
    """ContactWalker of the scene (:func:`contact_setup`, then :meth:`ContactSetup.build`)
    with checkerboard patches from the ideal step length.

    Parameters
    ----------
    scene : Scene
    x_ideal, n_steps, step_length_m
        As :meth:`ContactSetup.build`'s: the ideal fixed point (2n,) [rad, rad/s], the
        steps the run may take, the patch spacing [m] instead of the ideal step length.
    plant : walkerlab.walker.plant.Plant, optional
        As :func:`contact_setup`'s (the scene's walker described once, by the caller).

    Returns
    -------
    walker : ContactWalker
    step_length : float
        As :meth:`ContactSetup.build`'s (the ideal step length [m]).

    Raises
    ------
    ContactSceneError
        As :func:`contact_setup` (a scene the contact model does not take; one line).
    """
    return contact_setup(scene, plant=plant).build(x_ideal, n_steps, step_length_m)
