"""The Adams Solver dataset's contact (:mod:`walkerlab.export.adams`): the scene's contact law
in the file's mm-kg-s units and one ``CONTACT`` statement (IMPACT normal force, Coulomb
friction; MSC Adams Solver "CONTACT" statement) per foot sphere and ground patch."""

from __future__ import annotations

from walkerlab.config.contact import LENGTH_UNITS, ContactSettings
from walkerlab.export.adams_feet import contact_pairs
from walkerlab.export.adams_statements import MM, _f, _stmt
from walkerlab.models.contact.rigid_limit import contact_si

__all__ = ["contact_mm", "contact_statement", "contact_statements"]


def contact_mm(settings: ContactSettings) -> dict[str, float]:
    """The scene's contact law in the file's mm-kg-s units.

    A number the scene writes in mm-kg-s (``stiffness_family: paper``) is written as is;
    otherwise the SI value of :func:`walkerlab.models.contact.rigid_limit.contact_si` is
    converted (``k_mm = k_SI / 1000^e``, damping / 1000, lengths and speeds * 1000).

    Returns
    -------
    dict
        ``STIFFNESS`` [N/mm^e], ``EXPONENT``, ``DAMPING`` [N s/mm], ``DMAX`` [mm],
        ``MU_STATIC``, ``MU_DYNAMIC``, ``STICTION_TRANSITION_VELOCITY``,
        ``FRICTION_TRANSITION_VELOCITY`` [mm/s].
    """
    c, _ = contact_si(settings)
    si = {"stiffness": c.k / MM ** c.e, "max_damping": c.cmax / MM,
          "penetration_at_max_damping": c.dmax * MM, "stiction_velocity": c.v_s * MM,
          "friction_velocity": c.v_d * MM}
    out = {}
    for q, v in si.items():
        val, unit, _field = settings.written(q)
        if settings.stiffness_family == "paper" and LENGTH_UNITS[unit] == 1e-3:
            v = float(val)
        out[q] = v
    return {"STIFFNESS": out["stiffness"], "EXPONENT": float(c.e),
            "DAMPING": out["max_damping"], "DMAX": out["penetration_at_max_damping"],
            "MU_STATIC": float(c.mu_s), "MU_DYNAMIC": float(c.mu_d),
            "STICTION_TRANSITION_VELOCITY": out["stiction_velocity"],
            "FRICTION_TRANSITION_VELOCITY": out["friction_velocity"]}


def contact_statement(cid: int, igeom: int, jgeom: int, law: dict) -> list[str]:
    """``CONTACT/cid`` of the GRAPHICS ``igeom`` (a foot sphere) and ``jgeom`` (a ground
    patch): the IMPACT law ``law`` of :func:`contact_mm` with Coulomb friction."""
    return _stmt(f"CONTACT/{cid}, IGEOM={igeom}, JGEOM={jgeom}",
                 f"IMPACT, STIFFNESS={_f(law['STIFFNESS'])}, "
                 f"EXPONENT={_f(law['EXPONENT'])}",
                 f"DAMPING={_f(law['DAMPING'])}, DMAX={_f(law['DMAX'])}",
                 f"COULOMB_FRICTION=ON, MU_STATIC={_f(law['MU_STATIC'])}, "
                 f"MU_DYNAMIC={_f(law['MU_DYNAMIC'])}",
                 "STICTION_TRANSITION_VELOCITY="
                 f"{_f(law['STICTION_TRANSITION_VELOCITY'])}",
                 "FRICTION_TRANSITION_VELOCITY="
                 f"{_f(law['FRICTION_TRANSITION_VELOCITY'])}")


def contact_statements(mb, ids: dict, lanes: bool, n_patches: tuple, law: dict) -> list[str]:
    """One CONTACT per foot sphere and patch of its lane
    (:func:`walkerlab.export.adams_feet.contact_pairs`), the IMPACT law ``law`` of
    :func:`contact_mm` with Coulomb friction (:func:`contact_statement`)."""
    out = ["!", "! ---- contact: IMPACT normal force + Coulomb friction, mm-kg-s ----"]
    for cid, _leg, _role, m, g in contact_pairs(mb, ids, lanes, n_patches):
        out += contact_statement(cid, m, g, law)
    return out
