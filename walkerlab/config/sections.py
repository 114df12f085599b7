"""A scene section left out, as its defaults."""

from __future__ import annotations

import typing

from pydantic import BaseModel, ValidationError


def default_section(scene: BaseModel, section: str) -> BaseModel | None:
    """The section's settings with every field at its default, or None when the section has
    a required field (``contact``'s defaults are the paper's contact law)."""
    ann = type(scene).model_fields[section].annotation  # ``FixedPointSettings | None``
    models = [m for m in typing.get_args(ann) or (ann,)
              if isinstance(m, type) and issubclass(m, BaseModel)]
    if len(models) != 1:
        return None
    try:
        return models[0]()
    except ValidationError:
        return None


def section_or_default(scene: BaseModel, section: str) -> BaseModel | None:
    """The scene's ``section``; left out, its defaults when every field of it is optional
    (``fixedpoint:`` left out runs as ``fixedpoint: {}``); None when it is left out and has
    a required field."""
    val = getattr(scene, section)
    return val if val is not None else default_section(scene, section)


def with_default_section(scene, section: str):
    """``scene`` (a :class:`walkerlab.config.Scene`) with ``section`` filled with its
    defaults when it is left out (:func:`section_or_default`); the scene's file
    (``origin``) is kept.  A section with a required field stays None."""
    if getattr(scene, section) is not None:
        return scene
    out = scene.model_copy(update={section: default_section(scene, section)})
    out._origin = scene.origin
    return out
