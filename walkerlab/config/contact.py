"""Validated settings of the compliant-contact model and its runs (pydantic v2).

The scene section ``contact`` (read through :mod:`walkerlab.config`; ``contact_sim`` is
:mod:`walkerlab.config.contact_sim`'s, ``contact_solver`` a
:class:`walkerlab.config.solver.SolverSettings` as ``solver`` is, the ``terrain`` section
:mod:`walkerlab.config.terrain`'s).  The contact model package imports its settings from
here and there; this module imports no model (settings lie under the models, not beside
them).

Every dimensional number of :class:`ContactSettings` carries its unit in its name, in
ADAMS's default mm-kg-s units (``stiffness_n_per_mm_pow_e``) or in SI
(``stiffness_n_per_m_pow_e``); the contact model converts them to SI once per run
(:func:`walkerlab.models.contact.laws.contact_params_si`: ``k_SI = k_mm 1000^e``, so a
stiffness read in the wrong system is off by ``1000^e``, ~4e6 for the paper's e = 2.2).
"""

from __future__ import annotations

from typing import Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    model_serializer,
    model_validator,
)

from walkerlab.config.base import drop_unset

__all__ = ["CONTACT_QUANTITIES", "LENGTH_UNITS", "ContactSettings", "KneeStopSettings",
           "renamed_contact_field"]


# Numbers are strict and finite: no bool or string as a number, no inf/NaN;
# a YAML int still validates as a float.  Same rules as walkerlab.config.base.Strict.
_STRICT = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False)

#: Metres per length unit of a contact field's name (``..._mm``: ADAMS's default mm-kg-s
#: units, as the paper's numbers are read; ``..._m``: SI).
LENGTH_UNITS = {"mm": 1e-3, "m": 1.0}

#: The dimensional quantities of :class:`ContactSettings`: each is written in exactly one of
#: two fields, its mm-kg-s name or its SI name, ``{quantity: {length unit: (field, unit)}}``.
CONTACT_QUANTITIES = {
    "stiffness": {"mm": ("stiffness_n_per_mm_pow_e", "N/mm^e"),
                  "m": ("stiffness_n_per_m_pow_e", "N/m^e")},
    "max_damping": {"mm": ("max_damping_n_s_per_mm", "N s/mm"),
                    "m": ("max_damping_n_s_per_m", "N s/m")},
    "penetration_at_max_damping": {"mm": ("penetration_at_max_damping_mm", "mm"),
                                   "m": ("penetration_at_max_damping_m", "m")},
    "stiction_velocity": {"mm": ("stiction_velocity_mm_per_s", "mm/s"),
                          "m": ("stiction_velocity_m_per_s", "m/s")},
    "friction_velocity": {"mm": ("friction_velocity_mm_per_s", "mm/s"),
                          "m": ("friction_velocity_m_per_s", "m/s")},
    "reference_stiffness": {"mm": ("reference_stiffness_n_per_mm_pow_e", "N/mm^e"),
                            "m": ("reference_stiffness_n_per_m_pow_e", "N/m^e")},
}

#: Default of each quantity (the paper's values read in mm-kg-s, ADAMS View defaults for the
#: rest), used when neither of its two fields is given.
_CONTACT_DEFAULTS_MM = {"stiffness": 1e5, "max_damping": 90.0,
                        "penetration_at_max_damping": 0.1, "stiction_velocity": 100.0,
                        "friction_velocity": 1000.0, "reference_stiffness": 1e5}

#: Field names of the knee stop before its units were in every name -> today's names.
_KNEE_STOP_RENAMED = {"stiffness_N_m_per_rad": "stiffness_n_m_per_rad_pow_e",
                      "max_damping_N_m_s_per_rad": "max_damping_n_m_s_per_rad"}


def renamed_contact_field(path: str) -> str | None:
    """Migration hint for a contact field name used before units were in every name
    (``contact.stiffness`` -> ``"contact.stiffness_n_per_mm_pow_e (mm-kg-s) or
    contact.stiffness_n_per_m_pow_e (SI)"``); None for any other path."""
    head, _, leaf = path.rpartition(".")
    prefix = head + "." if head else ""
    if head.endswith("knee_stop") and leaf in _KNEE_STOP_RENAMED:
        return prefix + _KNEE_STOP_RENAMED[leaf]
    if head.endswith("contact") and leaf in CONTACT_QUANTITIES:
        mm, si = (CONTACT_QUANTITIES[leaf][u][0] for u in ("mm", "m"))
        return f"{prefix}{mm} (mm-kg-s) or {prefix}{si} (SI)"
    if head.endswith("contact") and leaf == "unit_system":
        return f"the unit in each field's name ({prefix}stiffness_n_per_mm_pow_e, ...)"
    return None


def _written_field(quantity: str, length_unit: str):
    """The pydantic field of ``quantity`` written in ``length_unit`` ("mm" or "m")."""
    _name, unit = CONTACT_QUANTITIES[quantity][length_unit]
    bounds = {"ge": 0} if quantity == "max_damping" else {"gt": 0}
    if quantity == "stiffness":
        bounds["le"] = 1e12
    return Field(None, **bounds, json_schema_extra={"unit": unit},
                 description=f"{_DESCRIPTIONS[quantity]} [{unit}]; give this or "
                 f"{CONTACT_QUANTITIES[quantity]['m' if length_unit == 'mm' else 'mm'][0]}, "
                 f"not both (neither: {_CONTACT_DEFAULTS_MM[quantity]:g} "
                 f"{CONTACT_QUANTITIES[quantity]['mm'][1]}).")


_DESCRIPTIONS = {
    "stiffness": "IMPACT stiffness k (paper: 'stiffness 1e5'; at most 1e12 as written)",
    "max_damping": "IMPACT maximum damping cmax (paper: 'damping 90')",
    "penetration_at_max_damping": "IMPACT penetration dmax at which full damping is "
                                  "reached (ADAMS default 0.1 mm)",
    "stiction_velocity": "Stiction transition velocity vs (ADAMS default 100 mm/s)",
    "friction_velocity": "Friction transition velocity vd, > vs (ADAMS default 1000 mm/s)",
    "reference_stiffness": "Stiffness at which the damping, dmax and transition velocities "
                           "hold in the 'rigid_limit' family (paper: 1e5 N/mm^2.2)",
}


class KneeStopSettings(BaseModel):
    """The knee's stop (straight leg) as a one-sided compliant rotational contact: the IMPACT
    law of the feet applied to the hyperextension angle ``shank - thigh`` (> 0 past
    straight), torque ``k ext^e + STEP(ext, 0, 0, dmax, cmax) ext'`` pushing the knee back
    (MSC ADAMS models joint stops this way).  Used by kneed walkers only; SI units.

    Defaults (chosen on the walker of ``configs/kneed.yaml``, Hsu Chen 2007, standing on one
    leg): the stop holds the knee within ~5e-6 rad of straight under ~0.05 N m; full damping
    is reached at 1e-5 rad so the stop is overdamped from the first micro-radians (stiffness
    there ~1.5 k sqrt(delta) ~ 5e2 N m/rad against ~0.3 kg m^2 above the knee: critical
    damping ~25 N m s/rad < 200) and a knee strike is nearly plastic, like the rigid model's.
    A less damped stop rebounds, and a free knee that rebounds into flexion under load buckles.
    """

    model_config = _STRICT

    stiffness_n_m_per_rad_pow_e: float = Field(
        1e5, gt=0, le=1e12, description="Stop stiffness k [N m/rad^e].",
        json_schema_extra={"unit": "N m/rad^e"})
    exponent: float = Field(1.5, ge=1.0, le=10.0, description="Stop force exponent e [-].",
                            json_schema_extra={"unit": "-"})
    max_damping_n_m_s_per_rad: float = Field(
        200.0, ge=0, description="Stop maximum damping cmax [N m s/rad].",
        json_schema_extra={"unit": "N m s/rad"})
    penetration_at_max_damping_rad: float = Field(
        1e-5, gt=0, description="Hyperextension dmax at which full damping is reached [rad].",
        json_schema_extra={"unit": "rad"})

    latch: bool = Field(
        False, description="Knee latch: while a leg's foot is on the ground the stop also "
        "acts in flexion (the same law mirrored), so the stance knee is held straight both "
        "ways, as the suction cups / magnets of real kneed passive walkers (McGeer 1990; "
        "Cornell) and the rigid model's locked knee do; it holds through the other leg's "
        "heel strike and releases as its foot rises above latch_release_height_m.")
    latch_release_height_m: float = Field(
        0.002, gt=0, le=0.1, description="Height of the foot above the ground at which its "
        "knee's latch has released (engagement STEP(penetration, -h, 0, 0, 1)) [m].",
        json_schema_extra={"unit": "m"})
    latch_capture_rad: float = Field(
        0.01, gt=0, le=0.5, description="Flexion within which the latch captures the knee "
        "(full hold within half of it) [rad]: a knee bent farther when its foot touches down "
        "is not snapped straight.", json_schema_extra={"unit": "rad"})

    @model_validator(mode="before")
    @classmethod
    def _renamed(cls, data):
        old = [k for k in _KNEE_STOP_RENAMED if isinstance(data, dict) and k in data]
        if old:
            raise ValueError("knee_stop: " + "; ".join(
                f"{k} is now {_KNEE_STOP_RENAMED[k]} (the exponent's unit in the name)"
                for k in old))
        return data


class ContactSettings(BaseModel):
    """IMPACT normal force + Coulomb friction of the feet.

    Every dimensional quantity is written with its unit in its name, in ADAMS's default
    mm-kg-s units (``stiffness_n_per_mm_pow_e``, as the paper's numbers are read) or in SI
    (``stiffness_n_per_m_pow_e``): exactly one of the two names per quantity
    (:data:`CONTACT_QUANTITIES`; neither: the paper's value in mm-kg-s).  The contact model
    converts them to SI once per run (:func:`walkerlab.models.contact.laws.contact_params_si`).
    Defaults are the paper's values (k = 1e5, damping 90, mu_s = 0.9, mu_d = 0.7) read in
    mm-kg-s, with the Adams/View contact defaults for the rest (exponent 2.2, penetration
    depth 0.1 mm, stiction and friction transition velocities 100 and 1000 mm/s).
    """

    model_config = _STRICT

    stiffness_n_per_mm_pow_e: float | None = _written_field("stiffness", "mm")
    stiffness_n_per_m_pow_e: float | None = _written_field("stiffness", "m")
    exponent: float = Field(
        2.2, ge=1.0, le=10.0, description="IMPACT force exponent e (ADAMS default 2.2) [-].",
        json_schema_extra={"unit": "-"},
    )
    max_damping_n_s_per_mm: float | None = _written_field("max_damping", "mm")
    max_damping_n_s_per_m: float | None = _written_field("max_damping", "m")
    penetration_at_max_damping_mm: float | None = _written_field(
        "penetration_at_max_damping", "mm")
    penetration_at_max_damping_m: float | None = _written_field(
        "penetration_at_max_damping", "m")
    mu_static: float = Field(0.9, ge=0, description="Static friction coefficient [-].",
                             json_schema_extra={"unit": "-"})
    mu_dynamic: float = Field(0.7, ge=0, description="Dynamic friction coefficient [-].",
                              json_schema_extra={"unit": "-"})
    stiction_velocity_mm_per_s: float | None = _written_field("stiction_velocity", "mm")
    stiction_velocity_m_per_s: float | None = _written_field("stiction_velocity", "m")
    friction_velocity_mm_per_s: float | None = _written_field("friction_velocity", "mm")
    friction_velocity_m_per_s: float | None = _written_field("friction_velocity", "m")

    stiffness_family: Literal["paper", "rigid_limit"] = Field(
        "paper", description="How damping and dmax follow the stiffness: 'paper' keeps "
        "the maximum damping and the penetration at maximum damping as given (a stiffer "
        "contact is then more elastic); 'rigid_limit' reads them, the transition velocities "
        "and the knee latch's release height as holding at the reference stiffness and "
        "follows the one rigid-limit family (walkerlab.models.contact.rigid_limit) with kappa = "
        "stiffness / reference stiffness: cmax * kappa^(1/(e+1)), dmax and latch height * "
        "kappa^(-1/(e+1)), vs and vd * kappa^(-1/2), so a drop impact keeps its "
        "(near-plastic) restitution and the periodic gait converges to the rigid one as k "
        "grows.")
    reference_stiffness_n_per_mm_pow_e: float | None = _written_field(
        "reference_stiffness", "mm")
    reference_stiffness_n_per_m_pow_e: float | None = _written_field(
        "reference_stiffness", "m")
    knee_stop: KneeStopSettings = Field(
        default_factory=KneeStopSettings, description="Knee stops of a kneed walker (SI): "
        "stiffness_n_m_per_rad_pow_e, exponent, max_damping_n_m_s_per_rad, "
        "penetration_at_max_damping_rad, latch, latch_release_height_m, latch_capture_rad.")

    @model_validator(mode="before")
    @classmethod
    def _one_name_per_quantity(cls, data):
        if not isinstance(data, dict):
            return data
        old = [k for k in ("unit_system", *CONTACT_QUANTITIES) if k in data]
        if old:
            u = "m" if data.get("unit_system") == "SI" else "mm"
            new = [CONTACT_QUANTITIES[k][u][0] for k in old if k != "unit_system"]
            raise ValueError(
                f"contact: {', '.join(old)}: each contact field now carries its unit in its "
                f"name and unit_system is gone: write {', '.join(new) or 'the fields'} "
                f"({'SI' if u == 'm' else 'mm-kg-s'}; the other system: "
                f"{'..._mm, ..._n_per_mm_pow_e' if u == 'm' else '..._m, ..._n_per_m_pow_e'})")
        data = dict(data)
        for q, names in CONTACT_QUANTITIES.items():
            mm, si = names["mm"][0], names["m"][0]
            given = [n for n in (mm, si) if data.get(n) is not None]
            if len(given) == 2:
                raise ValueError(f"contact: give {mm} (mm-kg-s) or {si} (SI), not both")
            if not given:
                data[mm] = _CONTACT_DEFAULTS_MM[q]
        return data

    flat_foot_mass_kg: float | None = Field(
        None, gt=0, le=100, description="Flat feet only: "
        "each foot's mass [kg], at its ankle.  A massless flat foot in the walker "
        "description (the rigid view's limit) is regularised in the floating contact model "
        "(and the MJCF and Adams exports) with this small mass, a contact-model setting like "
        "the stiffness (with zero mass the foot's angle would have no dynamics of its own); "
        "its share shows as the views' difference.  Feet with mass in the description "
        "(walker.leg.foot.mass_kg) are every view's: this is then refused.",
        json_schema_extra={"unit": "kg"})
    flat_foot_inertia_kg_m2: float | None = Field(
        None, gt=0, le=100, description="Flat feet only (SI): each foot's moment of inertia "
        "about its ankle [kg m^2] (regularisation, see flat_foot_mass_kg).",
        json_schema_extra={"unit": "kg m^2"})

    hub_inertia_kg_m2: float | None = Field(
        None, gt=0, le=100, description="Rimless wheels with a point-mass hub only (SI): the "
        "hub's moment of inertia about its centre [kg m^2] in the contact model.  The rigid "
        "view's point-mass hub has none (it rolls about a pinned spoke); once no spoke is "
        "pinned its angle would have no dynamics, so the floating contact model regularises "
        "it with this small inertia (its share of the inertia about a spoke tip, I / "
        "(M L^2 + I), is the relative change of the rolling dynamics).  Ignored when "
        "walker.hub_inertia_kg_m2 is given.",
        json_schema_extra={"unit": "kg m^2"})

    torsional_friction_m: float | None = Field(
        None, ge=0, le=1, description="Walkers in 3D only: the largest moment about the "
        "ground's normal a foot's contact holds per newton of normal force [m] (MuJoCo's "
        "torsional friction coefficient; an evenly pressed round patch of radius r has "
        "2 mu_static r / 3).  A point foot holds none, and a 3D walker on it spins about "
        "its stance foot: the contact model gives each foot this torsional friction, the "
        "ADAMS Coulomb law on the patch's slip speed (rho |omega_n|, rho = this / "
        "mu_static).  Default (null) 0.05 leg lengths, the MJCF export's.",
        json_schema_extra={"unit": "m"})

    hold_heading: bool = Field(False, description=(
        "3D legged walkers: hold the heading (no turn about the ground's normal), as the "
        "rigid stance foot does, which spins with its leg instead (Kuo 1999); with "
        "torsional_friction_m: 0 the contact makes the rigid model's assumptions"))

    push_off_duration_s: float | None = Field(
        None, ge=0, le=0.5, description="Powered walkers only: the duration [s] of the "
        "push-off pulse, a constant force P / duration along the trailing leg (from its foot "
        "towards the hip) at its foot, ending at the leading foot's touchdown (started when "
        "the swing foot's height, extrapolated at its rate, predicts the touchdown that far "
        "ahead: the rigid model's push-off comes immediately before heel strike); 0 applies "
        "the impulse P at once at the touchdown.  Default (null) 0.0001 s.  As it shortens "
        "the pulse converges to the impulse (first order: a longer pulse takes over the "
        "stance foot's weight support, its work falls short, 13 mJ per ms on "
        "configs/powered_compass.yaml).",
        json_schema_extra={"unit": "s"})

    def push_off_pulse_s(self) -> float:
        """The push-off pulse's duration [s] (``push_off_duration_s``, default 0.0001 s)."""
        return 1e-4 if self.push_off_duration_s is None else float(self.push_off_duration_s)

    def flat_foot(self) -> tuple[float, float] | None:
        """``(flat_foot_mass_kg, flat_foot_inertia_kg_m2)`` or None if either is unset."""
        if self.flat_foot_mass_kg is None or self.flat_foot_inertia_kg_m2 is None:
            return None
        return float(self.flat_foot_mass_kg), float(self.flat_foot_inertia_kg_m2)

    @model_validator(mode="after")
    def _check_relations(self) -> ContactSettings:
        if self.mu_dynamic > self.mu_static:
            raise ValueError(
                f"mu_dynamic ({self.mu_dynamic}) must be <= mu_static ({self.mu_static})"
            )
        vs, vd = self.written("stiction_velocity"), self.written("friction_velocity")
        if not vs[0] * LENGTH_UNITS[vs[1]] < vd[0] * LENGTH_UNITS[vd[1]]:
            raise ValueError(f"{vs[2]} ({vs[0]:g}) must be < {vd[2]} ({vd[0]:g})")
        return self

    @model_serializer(mode="wrap")
    def _written_names_only(self, handler):
        # the name not used of each pair is not part of the scene (nor of its content hash)
        # and a scene without flat feet serialises as before (same content hashes)
        return drop_unset(handler(self), [
            *(name for names in CONTACT_QUANTITIES.values() for name, _unit in names.values()),
            "flat_foot_mass_kg", "flat_foot_inertia_kg_m2", "push_off_duration_s",
            "hub_inertia_kg_m2", "hold_heading"])

    def written(self, quantity: str) -> tuple[float, str, str]:
        """A dimensional quantity as the scene writes it.

        Parameters
        ----------
        quantity : str
            A key of :data:`CONTACT_QUANTITIES` (``"stiffness"``, ``"max_damping"``, ...).

        Returns
        -------
        (value, length_unit, field)
            The number, its length unit (``"mm"`` or ``"m"``, :data:`LENGTH_UNITS`) and the
            name of the field that holds it.
        """
        for u, (name, _unit) in CONTACT_QUANTITIES[quantity].items():
            v = getattr(self, name)
            if v is not None:
                return v, u, name
        raise AssertionError(f"contact.{quantity}: no value (validation fills a default)")

    def with_written(self, quantity: str, value: float, length_unit: str) -> ContactSettings:
        """A copy with ``quantity`` set to ``value`` in ``length_unit`` ("mm" or "m"; the
        other field of the pair cleared).  Not validated again, as pydantic's
        ``model_copy``: the drop test's stiffnesses go past a scene's caps."""
        return self.model_copy(update={
            name: float(value) if u == length_unit else None
            for u, (name, _unit) in CONTACT_QUANTITIES[quantity].items()})
