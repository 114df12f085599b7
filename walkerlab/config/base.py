"""The base of every scene section: strict, frozen, finite numbers, unknown keys rejected."""

from __future__ import annotations

from pydantic import BaseModel, BeforeValidator, ConfigDict, model_validator


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


def drop_unset(d, keys):
    """A section's serialised form without the optional fields it leaves unset.

    A scene that leaves a field added later unset serialises as before the field existed
    (the same scene JSON and content hashes): each of ``keys`` whose value is None is
    dropped (a missing key is left alone).  The one rule every section's wrap serialiser
    applies.

    Parameters
    ----------
    d : dict or object
        What the section's pydantic handler returned (a dict is changed in place).
    keys : iterable of str
        The optional fields.

    Returns
    -------
    dict or object
        ``d`` (not a dict: unchanged).
    """
    if isinstance(d, dict):
        for k in keys:
            if d.get(k, 0) is None:
                d.pop(k)
    return d


def check_one_of(model, first: str, second: str, message: str):
    """``model``, of whose fields ``first`` and ``second`` exactly one is given (not None).

    The rule of a section that takes one quantity in either of two fields (a slope in
    radians or in degrees, an output on a link or on a joint, a leg given once or a pair).

    Parameters
    ----------
    model : pydantic.BaseModel
        A validated section.
    first, second : str
        Its two fields' names.
    message : str
        The error's one line (naming the fields).

    Returns
    -------
    pydantic.BaseModel
        ``model`` itself.

    Raises
    ------
    ValueError
        Both fields given, or neither: ``message``.
    """
    if (getattr(model, first) is None) == (getattr(model, second) is None):
        raise ValueError(message)
    return model


def one_of(first: str, second: str, message: str):
    """:func:`check_one_of` as a section's after-validator, assigned in its class body
    (``_one = one_of("link", "joint", "give link or joint (one of them)")``).

    Parameters
    ----------
    first, second, message : str
        As :func:`check_one_of`'s.

    Returns
    -------
    object
        The validator (pydantic's decorator proxy), collected by the class.
    """
    def check(self):
        return check_one_of(self, first, second, message)

    return model_validator(mode="after")(check)
