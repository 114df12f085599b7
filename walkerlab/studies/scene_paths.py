"""Dotted paths into a scene mapping (``walker.leg.bodies.thigh_mass.mass_kg``: sections by
name, an item of a list by its ``name`` field or its index, one number of a list of numbers
by its index): the item of a list (:func:`list_item`), and a field read, set or removed in
the plain ``dict`` of a scene (:func:`get_dotted`, :func:`set_dotted`, :func:`pop_dotted`),
as a sweep point (:func:`walkerlab.studies.params.apply_point`) and a sweep's plan
(:mod:`walkerlab.studies.sweep_plan`) use them.
"""

from __future__ import annotations

import difflib
from typing import Any

from walkerlab.config import SceneError

__all__ = ["get_dotted", "list_item", "pop_dotted", "set_dotted"]


def list_item(items: list, key: str, path: str):
    """The item of a scene list (e.g. ``walker.leg.bodies``) named ``key`` (its ``name``
    field) or at index ``key``.

    Raises
    ------
    SceneError
        No such item (the message lists the names and the index range).
    """
    names = [it.get("name") for it in items if isinstance(it, dict)]
    named = ", ".join(str(n) for n in names if n is not None)
    if key.isdigit():
        if int(key) < len(items):
            return items[int(key)]
        raise SceneError(f"{path}: index {key} is out of range (the list has {len(items)} "
                         + (f"items, indices 0-{len(items) - 1}" if items else "items")
                         + (f": {named})" if named else ")"))
    hits = [it for it in items if isinstance(it, dict) and it.get("name") == key]
    if len(hits) == 1:
        return hits[0]
    close = difflib.get_close_matches(key, [str(n) for n in names], 1)
    raise SceneError(f"{path}: no item named {key!r}"
                     + (f" (did you mean {close[0]!r}?)" if close else "")
                     + f"; items: {named or 'none named'} "
                     f"(or by index 0-{max(len(items) - 1, 0)})")


def set_dotted(d: dict, path: str, value) -> None:
    """Set the field at ``path`` of the scene mapping ``d`` to ``value`` (in place): missing
    sections are created, list items found by name or index, one number of a list of
    numbers replaced by its index.

    Raises
    ------
    SceneError
        A section on the path is a value, a list item does not exist, or the path ends at
        a list item rather than one of its fields (one line naming the path).
    """
    keys = path.split(".")
    node = d
    for k in keys[:-1]:
        if isinstance(node, list):
            node = list_item(node, k, path)
            continue
        nxt = node.get(k)
        if nxt is None:
            nxt = node[k] = {}
        elif not isinstance(nxt, (dict, list)):
            raise SceneError(f"{path}: '{k}' is not a section (it is {nxt!r})")
        node = nxt
    if isinstance(node, list) and keys[-1].isdigit() and int(keys[-1]) < len(node) \
            and not isinstance(node[int(keys[-1])], dict):  # one number of a list of them
        node[int(keys[-1])] = value
        return
    if isinstance(node, list):
        raise SceneError(f"{path}: '{keys[-1]}' is a list item, not a field: name the item's "
                         f"field ({path}.mass_kg, ...)")
    node[keys[-1]] = value


def pop_dotted(d: dict, path: str) -> None:
    """Remove the field at ``path`` of the scene mapping ``d`` (in place), if it is there
    (sections only, as the fields that exclude each other are:
    :data:`walkerlab.studies.params.EXCLUSIVE_FIELDS`)."""
    keys = path.split(".")
    node = d
    for k in keys[:-1]:
        node = node.get(k)
        if not isinstance(node, dict):
            return
    node.pop(keys[-1], None)


def get_dotted(d: dict, path: str):
    """Value at a dotted path of a scene mapping (list items by name or index); None if
    absent."""
    node: Any = d
    for k in path.split("."):
        if isinstance(node, list):
            try:
                node = list_item(node, k, path)
            except SceneError:
                return None
            continue
        if not isinstance(node, dict) or k not in node:
            return None
        node = node[k]
    return node
