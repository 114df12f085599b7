"""The base of every scene section: strict, frozen, finite numbers, unknown keys rejected."""

from __future__ import annotations

from pydantic import BaseModel, BeforeValidator, ConfigDict


class Strict(BaseModel):
    """Base of every config section: unknown keys rejected, frozen, strict finite numbers.

    ``strict=True``: a bool is not a number (``leg_mass_kg: true`` is rejected, not read as
    1 kg) and a string is not a number (``"5"``); a YAML int still validates as a float.
    ``allow_inf_nan=False``: every float field must be finite (``.inf``/``.nan`` rejected)
    unless a field says otherwise.  Nested sections still validate from plain mappings.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


def _list_to_tuple(v):
    return tuple(v) if isinstance(v, list) else v


# A fixed-length tuple given as a YAML list (strict mode alone would want a Python tuple).
AsTuple = BeforeValidator(_list_to_tuple)
