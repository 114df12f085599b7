"""Scene schema: the :class:`Scene` that holds a scene's sections (YAML -> pydantic v2), the
slope and model-variant sections, and the sizes typed on the command line.

The walker sections live in :mod:`walkerlab.config.walker`, the analyses' sections in
:mod:`walkerlab.config.studies`, the compliant-contact ones in
:mod:`walkerlab.config.contact`.  Every numeric field carries its unit in its name
(``leg_length_m``) and a description; unknown keys are rejected (``extra="forbid"``).  The
caps the fields use live in :mod:`walkerlab.config.limits`, the file reading and error
lines in :mod:`walkerlab.config.loader`; everything is importable from
:mod:`walkerlab.config`.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    Field,
    PrivateAttr,
    ValidationError,
    field_validator,
    model_serializer,
    model_validator,
)

from walkerlab.config.base import Strict, drop_unset, one_of
from walkerlab.config.contact import ContactSettings
from walkerlab.config.contact_sim import ContactSimSettings
from walkerlab.config.errors import SceneError, format_error
from walkerlab.config.limits import (
    MAX_BIFURCATION_KEEP,
    MAX_BIFURCATION_TRANSIENT,
    MAX_SOURCE_CHARS,
    MAX_STABILITY_MAP_N,
    MAX_STEPS_PER_WALKING_STEP,
    MAX_WORKERS,
)
from walkerlab.config.optimize import OptimizeSettings
from walkerlab.config.solver import (
    SolverSettings,
    check_contact,
    check_rigid,
    with_contact_defaults,
)
from walkerlab.config.studies import (
    BasinSettings,
    FixedPointSettings,
    MfptSettings,
    RobustnessSettings,
    SimulateSettings,
    WorkPrecisionSettings,
)
from walkerlab.config.terrain import TerrainSettings
from walkerlab.config.walker import WalkerParams
from walkerlab.published import available

#: The default ground's patch width for flat feet, in soles (heel to toe): see
#: :meth:`Scene.terrain_or_default`.
FLAT_FOOT_PATCH_SOLES = 4.0


class SlopeSettings(Strict):
    """Ramp angle phi (the walker walks downhill in +x). Give exactly one of the two fields."""

    angle_rad: float | None = Field(None, gt=-math.pi / 2, lt=math.pi / 2,
                                    description="slope [rad]")
    angle_deg: float | None = Field(None, gt=-90, lt=90, description="slope [deg]")

    _exactly_one = one_of("angle_rad", "angle_deg",
                          "slope: give exactly one of angle_rad or angle_deg")

    @property
    def phi_rad(self) -> float:
        """Slope angle [rad]."""
        return self.angle_rad if self.angle_rad is not None else math.radians(self.angle_deg)


class IdealModelSettings(Strict):
    """Which equations the rigid hybrid model uses."""

    variant: Literal["derived", "appendix_a"] = Field(
        "derived",
        description="'derived': equations derived with sympy (default, energy-consistent); "
        "'appendix_a': the paper's printed Appendix A, signs included (reproduces Eq. 11)",
    )


class Scene(Strict):
    """A complete scene. Only ``walker`` and ``slope`` are mandatory."""

    name: str | None = Field(None, description="run folder name (runs/<name>/); default: "
                             "YAML file stem. Letters, digits and . _ + - only, no path "
                             "separators, not starting with a dot", max_length=100)
    source: str | None = Field(None, max_length=MAX_SOURCE_CHARS,
                               description="citation of the parameter set (at most "
                               f"{MAX_SOURCE_CHARS} characters)")
    published: str | None = Field(
        None, description="walkerlab.published module whose printed numbers the report sets "
        "next to ours (e.g. 'paper'); null: no published comparison")
    units: Literal["SI", "nondimensional"] = Field(
        "SI", description="'SI': the *_m, *_kg, *_s fields are metres, kilograms, seconds; "
        "'nondimensional': g = 1 and the numbers are in the walker's own units (length l, "
        "mass M, time sqrt(l/g); Garcia et al. 1998), and every label says so")
    walker: WalkerParams
    slope: SlopeSettings
    ideal: IdealModelSettings = IdealModelSettings()
    solver: SolverSettings = SolverSettings()
    fixedpoint: FixedPointSettings | None = None
    simulate: SimulateSettings | None = None
    contact: ContactSettings | None = None
    terrain: TerrainSettings | None = None
    contact_sim: ContactSimSettings | None = None
    contact_solver: Annotated[SolverSettings | None,
                              BeforeValidator(with_contact_defaults)] = None
    workprecision: WorkPrecisionSettings | None = None
    # Resolved path of the YAML file the scene was read from (None when built in code);
    # not part of the scene's content: it decides which file owns runs/<name>/.
    _origin: Path | None = PrivateAttr(None)

    @property
    def origin(self) -> Path | None:
        """Resolved path of the scene file, or None for a scene built in code."""
        return self._origin
    basin: BasinSettings | None = None
    mfpt: MfptSettings | None = None
    robustness: RobustnessSettings | None = None
    optimize: OptimizeSettings | None = None

    @model_serializer(mode="wrap")
    def _drop_unused_optimize(self, handler):
        # a scene without an optimize section serialises as before (same scene JSON)
        return drop_unset(handler(self), ("optimize",))

    @model_validator(mode="after")
    def _units_consistent(self) -> Scene:
        if self.units == "nondimensional" and self.walker.gravity_m_per_s2 != 1.0:
            raise ValueError("units: a nondimensional scene measures accelerations in g, so "
                             "walker.gravity_m_per_s2 must be 1 (got "
                             f"{self.walker.gravity_m_per_s2:g})")
        return self

    @model_validator(mode="after")
    def _solvers_fit_their_models(self) -> Scene:
        why = check_rigid(self.solver) or (self.contact_solver is not None
                                           and check_contact(self.contact_solver))
        if why:
            raise ValueError(why)
        return self

    def _legs(self) -> tuple:
        """The walker's two legs (a biped's ``leg_pair``: its ``legs``, or ``leg`` twice), or
        ``()`` for a walker without legs (the rimless wheels)."""
        pair = getattr(self.walker, "leg_pair", None)
        return pair() if pair is not None else ()

    @model_validator(mode="after")
    def _contact_fits_the_walker(self) -> Scene:
        # a contact number that cannot act is a mistake, as an unknown key is: an error, not
        # a warning, so a number the user counts on is never silently absent (the stop's
        # other numbers have defaults and are dumped with every scene: not checked)
        c = self.contact
        if c is None:
            return self
        legs = self._legs()
        if c.knee_stop.latch and (not legs or legs[0].knee is None):
            raise ValueError("contact.knee_stop.latch: the walker's legs are straight (no "
                             "walker.leg.knee), so there is no knee to latch: remove it or "
                             "give the leg a knee")
        # a planar walker's feet turn in its plane only, and its contact carries no moment
        # about the normal
        if c.torsional_friction_m is not None and getattr(self.walker, "space", "2d") != "3d":
            raise ValueError("contact.torsional_friction_m: a planar walker's feet hold no "
                             "moment about the ground's normal (they turn in its plane "
                             "only): remove it, or give the walker walker.space: 3d")
        # a heading is a legged walker's in 3D (a 3D spoked wheel's is its rigid state's)
        if c.hold_heading and (getattr(self.walker, "space", "2d") != "3d"
                               or getattr(self.walker, "model", "") == "rimless_wheel"):
            raise ValueError("contact.hold_heading: a legged walker in 3D's option (walker."
                             "space: 3d; a planar walker has no heading, a 3D spoked "
                             "wheel's heading is a coordinate of its rigid state)")
        # feet with mass (walker.leg.foot.mass_kg) are the same feet in every view: the
        # contact section's regularising foot mass would be a second, different foot
        foot = legs[0].foot if legs else None
        if (getattr(foot, "kind", "") == "flat" and foot.mass() is not None
                and (c.flat_foot_mass_kg is not None or c.flat_foot_inertia_kg_m2 is not None)):
            raise ValueError("contact.flat_foot_mass_kg, contact.flat_foot_inertia_kg_m2: the "
                             "walker's feet carry their own mass (walker.leg.foot.mass_kg, "
                             "inertia_about_ankle_kg_m2), used by every view: remove these")
        return self

    def terrain_or_default(self) -> TerrainSettings:
        """The ground every view walks on: the ``terrain`` section, or without one the
        default ground, the scene's slope with checkerboard lanes of
        :attr:`TerrainSettings.patch_width_m` (0.10 m), or for flat feet
        :data:`FLAT_FOOT_PATCH_SOLES` times the sole's length (heel to toe).

        A flat foot lands on its heel and rolls its load to its toe, one sole's length
        ahead of the heel's footfall on which its patch is centred: the 0.10 m of a point
        foot's default is shorter than the sole (configs/flat_feet.yaml's 0.15 m) and the
        walker trips on its first step.  Four soles (0.6 m there, its terrain section's
        width) hold the sole with a sole's length to spare at either end for the footfalls'
        scatter and still leave the swing foot a gap in its lane at mid-stance (the lanes'
        patches lie a stride apart; the swing foot passes half a stride from them).

        Returns
        -------
        TerrainSettings
            The section itself when the scene has one (never changed).
        """
        if self.terrain is not None:
            return self.terrain
        feet = [getattr(leg, "foot", None) for leg in self._legs()]
        soles = [f.heel_m + f.toe_m for f in feet if getattr(f, "kind", "") == "flat"]
        if soles:
            return TerrainSettings(patch_width_m=FLAT_FOOT_PATCH_SOLES * max(soles))
        return TerrainSettings()

    @model_validator(mode="after")
    def _ground_fits_the_walker(self) -> Scene:
        t = self.terrain
        if t is None or t.kind != "stairs":
            return self
        if self.slope.phi_rad != 0:
            raise ValueError(f"slope: terrain.kind: stairs has level treads; the slope must "
                             f"be 0 (is {self.slope.phi_rad:g} rad)")
        foot = getattr(getattr(self.walker, "leg", None), "foot", None)
        length = (foot.heel_m + foot.toe_m) if getattr(foot, "kind", "") == "flat" else 0.0
        if not t.tread_m > length:
            raise ValueError(f"terrain.tread_m: {t.tread_m:g} m is shorter than the walker's "
                             f"foot ({length:g} m heel to toe)")
        return self

    @model_validator(mode="after")
    def _published_exists(self) -> Scene:
        if self.published is not None:
            if self.published not in available():
                raise ValueError(f"published: no module walkerlab.published.{self.published} "
                                 f"(available: {', '.join(available())})")
        return self

    @model_validator(mode="after")
    def _bounded_integrator_steps(self) -> Scene:
        # a tiny max_step_s runs for minutes without output: bound the steps it implies for
        # the longest walking step the scene allows
        if self.solver.max_step_s is None:
            return self
        longest = max([5.0] + [s.max_step_time_s for s in (self.fixedpoint, self.simulate,
                                                            self.basin)
                               if s is not None and s.max_step_time_s is not None])
        n = longest / self.solver.max_step_s
        if n > MAX_STEPS_PER_WALKING_STEP:
            raise ValueError(
                f"solver.max_step_s: {self.solver.max_step_s:g} s would allow "
                f"{n:.3g} integrator steps in a walking step of up to {longest:g} s "
                f"(max_step_time_s); at most {MAX_STEPS_PER_WALKING_STEP:,} are allowed, so "
                f"use max_step_s >= {longest / MAX_STEPS_PER_WALKING_STEP:g} s")
        return self

    @field_validator("name")
    @classmethod
    def _plain_name(cls, v: str | None) -> str | None:
        if v is not None and not SCENE_NAME_RE.match(v):
            raise ValueError(f"{v!r} is not a plain folder name: use letters, digits and "
                             ". _ + - only (no path separators, not starting with a dot)")
        return v

    def model_copy(self, *, update: dict[str, Any] | None = None, deep: bool = False) -> Scene:
        """A copy; with an ``update`` that gives a section as a mapping or a list, the
        changed scene validated again (pydantic's own ``model_copy`` stores an update
        unchecked: the section would stay a ``dict``).  The scene file (``origin``) is
        kept.  To change fields by dotted path, use :func:`walkerlab.api.with_changes`.

        Raises
        ------
        SceneError
            The updated scene does not validate (one line per error).
        """
        if not update or not any(isinstance(v, dict | list) for v in update.values()):
            # model instances (walkerlab's own copies: a section's settings, a name) as
            # pydantic copies them
            return super().model_copy(update=update, deep=deep)
        data = self.model_dump()
        data.update({k: v.model_dump() if isinstance(v, BaseModel) else v
                     for k, v in update.items()})
        try:
            out = type(self).model_validate(data)
        except ValidationError as err:
            raise SceneError(format_error(Path("model_copy"), err, Scene)) from None
        out._origin = self._origin
        return out

    def section_json(self, *names: str) -> str:
        """Canonical JSON of the named sections (for content hashes)."""
        d = self.model_dump(mode="json")
        out = {n: d.get(n) for n in names}
        if self.units != "SI":  # labels of every artifact follow the unit system
            out["units"] = self.units
        if "slope" in names and self.terrain is not None and not self.terrain.is_slope:
            out["ground"] = self.terrain.ground()  # the rigid model walks on it
        return json.dumps(out, sort_keys=True)

    def section_hash(self, *names: str) -> str:
        return hashlib.sha256(self.section_json(*names).encode()).hexdigest()


SCENE_NAME_RE = re.compile(r"^[A-Za-z0-9_+\-][A-Za-z0-9._+\-]*$")


class CommandOptions(Strict):
    """Sizes typed on the command line only (each with the one cap defined above)."""

    workers: int = Field(2, ge=1, le=MAX_WORKERS,
                         description=f"local worker processes (at most {MAX_WORKERS}: 4 per core)")
    stability_map_n: int = Field(8, ge=2, le=MAX_STABILITY_MAP_N,
                                 description="stability-map grid size n x n")
    stability_map_max_step_maps: int = Field(
        2_000, ge=1, le=1_000_000, description="work bound of each periodic-gait search of "
        "a map cell: its step-map integrations [-]")
    bifurcation_transient: int = Field(100, ge=1, le=MAX_BIFURCATION_TRANSIENT,
                                       description="steps discarded before sampling")
    bifurcation_keep: int = Field(30, ge=1, le=MAX_BIFURCATION_KEEP,
                                  description="heel strikes kept per slope")
