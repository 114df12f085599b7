"""A scene section left out, as its defaults."""

from __future__ import annotations

import typing

from pydantic import BaseModel, ValidationError


def default_section(scene: BaseModel, section: str) -> BaseModel | None:
    """The section's settings with every field at its default, or None when the section has
    a required field (``contact``: a contact law must be chosen)."""
    ann = type(scene).model_fields[section].annotation  # ``FixedPointSettings | None``
    models = [m for m in typing.get_args(ann) or (ann,)
              if isinstance(m, type) and issubclass(m, BaseModel)]
    if len(models) != 1:
        return None
    try:
        return models[0]()
    except ValidationError:
        return None
