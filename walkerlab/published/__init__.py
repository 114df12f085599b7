"""Published reference numbers, one module per source (as PyBaMM keeps one file per parameter set).

Every number is stored once, next to its citation and the place in the source where it is
printed (equation, table, figure).  Tables, tests and the report read them from here; no other
module writes a published value literally.

Modules
-------
Each module defines ``CITATION`` (str) and its values as module-level constants with the unit
in the name or in a comment, e.g. ``walkerlab.published.garcia1998``.
"""

from __future__ import annotations

import importlib
import pkgutil
from types import ModuleType


def available() -> list[str]:
    """Names of the published-number modules shipped (``paper``, ...)."""
    return sorted(m.name for m in pkgutil.iter_modules(__path__))


def for_scene(scene) -> ModuleType | None:
    """The module named by the scene's ``published`` key, or None when it names none.

    Raises
    ------
    ValueError
        The key names a module that does not exist (message names the field).
    """
    name = getattr(scene, "published", None)
    if not name:
        return None
    if name not in available():
        raise ValueError(f"published: no module walkerlab.published.{name} "
                         f"(available: {', '.join(available())})")
    return importlib.import_module(f"walkerlab.published.{name}")
