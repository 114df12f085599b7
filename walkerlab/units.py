"""The unit labels of a scene: one place that maps a physical dimension to its label.

A scene is in SI units (``units: SI``, the default) or nondimensional (``units:
nondimensional``; g = 1, lengths and masses in the units the scene's numbers are given in,
e.g. Garcia et al. 1998: l = g = M = 1, time in √(l/g)).  Code that writes or shows a
quantity names its *SI* unit (``"s"``, ``"m/s"``, ``"J"``, ``"rad/s"``, ``"mm"``) and asks
:class:`Units` for the label; a nondimensional scene then says ``√(l/g)``, ``√(g l)``,
``M g l``, ``rad/√(l/g)``, ``10⁻³ l`` instead.  Wall-clock and CPU times of a computation
are real seconds in every scene: they are not passed through :class:`Units`.

Artifacts carry the system in their ``scene_units`` attribute and their datasets' ``unit``
attributes follow it (:func:`relabel_artifact`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

SI = "SI"
NONDIMENSIONAL = "nondimensional"

#: label of each SI unit in a nondimensional scene (length unit l, mass unit M, g = 1)
NONDIMENSIONAL_LABELS = {
    "m/s^2": "g", "rad/s": "rad/√(l/g)", "m/s": "√(g l)", "kg m^2": "M l²", "mm": "10⁻³ l",
    "Hz": "√(g/l)", "J": "M g l", "kg": "M", "N": "M g", "m": "l", "s": "√(l/g)",
    "N/m^e": "M g/l^e", "N s/m": "M √(g/l)",  # IMPACT stiffness and damping
    "N s": "M √(g l)", "N m": "M g l",  # impulse (push-off), torque
    "N m/rad": "M g l/rad", "N m s/rad": "M l √(g l)/rad", "N s^2/m": "M",  # actuator laws
    "N m/kg": "g l",  # a torque per foot mass (massless legs)
}
_TOKEN = re.compile(r"(?<![\w/^])(" + "|".join(
    re.escape(k) for k in sorted(NONDIMENSIONAL_LABELS, key=len, reverse=True))
    + r")(?![\w/^²])")


def _dimension(what: str, si: str) -> property:
    """The read-only property of :class:`Units` that labels ``what`` (a dimension whose SI
    unit is ``si``): ``units(si)``, its docstring naming both systems' labels."""
    def label(self) -> str:
        return self(si)

    label.__doc__ = (f"Label of {what}: ``{si}`` in SI, ``{NONDIMENSIONAL_LABELS[si]}`` "
                     "nondimensional.")
    return property(label)


@dataclass(frozen=True)
class Units:
    """Unit labels of one unit system (``"SI"`` or ``"nondimensional"``)."""

    system: str = SI

    @property
    def nondimensional(self) -> bool:
        """True for the nondimensional system (g = 1; Garcia et al. 1998's units)."""
        return self.system == NONDIMENSIONAL

    def __call__(self, si: str) -> str:
        """Label of a quantity whose SI unit is ``si`` (composite strings such as
        ``"rad, rad/s"`` are relabelled token by token; ``"rad"``, ``"-"``, ``"deg"`` stay)."""
        if not self.nondimensional or not si:
            return si
        return _TOKEN.sub(lambda m: NONDIMENSIONAL_LABELS[m.group(1)], si)

    # the dimensions the report and the figures name most often
    time = _dimension("a time", "s")
    length = _dimension("a length", "m")
    speed = _dimension("a speed", "m/s")
    rate = _dimension("an angular rate", "rad/s")
    energy = _dimension("an energy", "J")

    @property
    def small_length(self) -> str:
        """Label of small lengths (clearances, penetration): mm in SI, l when
        nondimensional; multiply metres by :attr:`small_scale` to show them."""
        return "l" if self.nondimensional else "mm"

    @property
    def small_scale(self) -> float:
        """Factor from the scene's length unit to :attr:`small_length` (1e3 in SI)."""
        return 1.0 if self.nondimensional else 1e3

    def sentence(self) -> str:
        """One line saying what the numbers are measured in."""
        if self.nondimensional:
            return ("nondimensional scene (g = 1): lengths in units of l, masses in M, time "
                    "in √(l/g), speeds in √(g l), energies in M g l (the scene's numbers)")
        return "SI (m, kg, s)"


def for_scene(scene) -> Units:
    """:class:`Units` of a scene (``scene.units``; a scene without the field is SI)."""
    return Units(getattr(scene, "units", SI) or SI)


def for_artifact(f) -> Units:
    """:class:`Units` of an open artifact (its ``scene_units`` attribute; SI if absent)."""
    v = f.attrs.get("scene_units", SI)
    return Units(v.decode() if isinstance(v, bytes) else str(v))


def is_clock_time(name: str, attrs) -> bool:
    """Whether a dataset holds the computer's wall-clock or CPU time (real seconds)."""
    base = name.rsplit("/", 1)[-1]
    return bool(attrs.get("clock", "")) or "wall_time" in base or "cpu_time" in base


def relabel_artifact(f, units: Units) -> None:
    """Rewrite every dataset's ``unit`` (and CF ``units``) attribute of an open artifact to
    ``units``' labels, except clock times; store ``scene_units``."""
    f.attrs["scene_units"] = units.system
    if not units.nondimensional:
        return
    def visit(name, obj):
        if hasattr(obj, "shape") and "unit" in obj.attrs \
                and not is_clock_time(name, obj.attrs):
            old = obj.attrs["unit"]
            old = old.decode() if isinstance(old, bytes) else str(old)
            new = units(old)
            if new != old:
                obj.attrs["unit"] = new
                obj.attrs["units"] = "1"  # CF: dimensionless
    f.visititems(visit)


#: Unit of a config field, by the suffix of its name (longer suffixes first); the contact
#: law's fields name mm-kg-s or SI units (``stiffness_n_per_mm_pow_e``)
FIELD_SUFFIX_UNITS = (
    ("_n_m_per_rad_pow_e", "N m/rad^e"), ("_n_m_s_per_rad", "N m s/rad"),
    ("_n_m_per_rad", "N m/rad"), ("_n_per_mm_pow_e", "N/mm^e"), ("_n_per_m_pow_e", "N/m^e"),
    ("_n_s2_per_m", "N s^2/m"), ("_n_s_per_mm", "N s/mm"), ("_n_s_per_m", "N s/m"),
    ("_n_m_per_kg", "N m/kg"), ("_n_m", "N m"), ("_n_s", "N s"), ("_mm_per_s", "mm/s"),
    ("_rad_per_s", "rad/s"), ("_m_per_s2", "m/s^2"), ("_m_per_s", "m/s"),
    ("_kg_m2", "kg m^2"), ("_deg", "deg"), ("_rad", "rad"), ("_kg", "kg"), ("_mm", "mm"),
    ("_hz", "Hz"), ("_m", "m"), ("_s", "s"),
)


def field_unit(name: str) -> str | None:
    """SI unit of a config field from the suffix of its name (``mass_kg`` -> ``"kg"``,
    ``leg_length_m`` -> ``"m"``, ``angle_deg`` -> ``"deg"``, ``gravity_m_per_s2`` ->
    ``"m/s^2"``, ``stiffness_n_per_mm_pow_e`` -> ``"N/mm^e"``); a dotted path is read by
    its last part.  None when the name carries no unit (``contact.exponent``)."""
    leaf = name.rsplit(".", 1)[-1]
    for suffix, unit in FIELD_SUFFIX_UNITS:
        if leaf.endswith(suffix):
            return unit
    return None


def map_name(steps_per_map) -> str:
    """The Poincaré map of ``steps_per_map`` steps in the field's words: ``"step"`` (1),
    ``"stride"`` (2), ``"3-step cycle"`` (a ground that repeats every 3 steps); ``""`` when
    unknown (None, 0: an artifact written before the map's length was recorded)."""
    try:
        k = int(steps_per_map)
    except (TypeError, ValueError):
        return ""
    return {0: "", 1: "step", 2: "stride"}.get(k, f"{k}-step cycle" if k > 0 else "")


def per_map(steps_per_map) -> str:
    """``"per step"``, ``"per stride"``, ``"per 3-step cycle"`` (:func:`map_name`) - the
    qualifier every Floquet multiplier shown to a reader carries (a stride's multipliers
    are the step's squared, for legs that are mirror images) - or ``""`` when unknown."""
    name = map_name(steps_per_map)
    return f"per {name}" if name else ""
