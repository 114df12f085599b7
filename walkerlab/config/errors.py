"""One error line per validation mistake, naming the file and the field (``<file>: <field
path>: <message>``), with the likely meant field for an unknown key and a unit hint for a
bound that looks like a unit mistake, and :class:`SceneError`, the exception those lines
travel in.  The root model is a parameter, so this module sits below the schema it
describes."""

from __future__ import annotations

import math
import re
from pathlib import Path

from pydantic import BaseModel, ValidationError


class SceneError(ValueError):
    """A scene file cannot be read or does not validate (one line per error, each naming
    the file and the field)."""


# discriminator tags of walker models and bodies: not part of a field's path
_TAGS = {"compass_gait", "biped", "point_mass", "rod", "point", "arc", "flat"}


def _loc_part(p) -> bool:
    """Keep a location element that is a field name or index (not a union/type tag)."""
    s = str(p)
    if s.startswith(("function-after", "function-before", "literal[", "tuple[", "list[")):
        return False
    # union members appear as their class name (``StateSpec``) or a discriminator tag
    return not (s[:1].isupper() and s.isidentifier()) and s not in _TAGS


def _models_in(tp) -> list[type[BaseModel]]:
    """The pydantic models a field annotation can hold (through Optional, unions, lists,
    tuples, dict values and ``Annotated``)."""
    import typing

    if isinstance(tp, type) and issubclass(tp, BaseModel):
        return [tp]
    out: list[type[BaseModel]] = []
    for a in typing.get_args(tp):
        out += [m for m in _models_in(a) if m not in out]
    return out


def _fields_at(root: type[BaseModel], loc: tuple) -> list[str]:
    """Field names allowed at a validation-error location (the union of the candidate
    models' fields where a union leaves the model open); [] when it cannot be told."""
    import typing

    current: list[type[BaseModel]] = [root]
    for p in loc:
        here = [m for m in current if isinstance(p, str) and p in m.model_fields]
        if here:
            nxt: list[type[BaseModel]] = []
            for m in here:
                nxt += [x for x in _models_in(m.model_fields[p].annotation) if x not in nxt]
            current = nxt
            continue
        # a list index, a union member's class name or discriminator tag: narrow, or keep
        tagged = [m for m in current if m.__name__ == p or any(
            typing.get_args(f.annotation) == (p,) for f in m.model_fields.values())]
        current = tagged or current
    return sorted({k for m in current for k in m.model_fields})


def _input_text(value) -> str:
    """``repr`` of an input value for a message; an integer too long to print (Python caps
    int-to-str at 4300 digits) or to read is described instead."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 100:
        return f"an integer of about {int(value.bit_length() * 0.30103) + 1} digits"
    return repr(value)


def _suggestion(root: type[BaseModel], e: dict) -> list[str]:
    """The field an unknown key most likely meant ([] when none is close)."""
    import difflib

    return difflib.get_close_matches(str(e["loc"][-1]), _fields_at(root, tuple(e["loc"][:-1])), n=1)


#: What a walker can be today, said by an error on an unknown walker field or kind and by
#: the README (one place: update it as the walker vocabulary grows)
WALKER_VOCABULARY = (
    "a walker today is planar: model compass_gait (hip mass, one point mass per "
    "leg) or biped (hip_mass_kg; one leg: or a legs: pair that may differ, each with "
    "length_m, bodies (point_mass or rod, on or off the leg axis), an optional locking knee "
    "or free knees (knee.lock: free, rigid model), foot kind point, arc or flat (heel, toe, "
    "ankle spring); springs: torsional springs and dampers between links at the hip; torso: "
    "an upper body on a bisecting hip mechanism, or hinged at the hip with free knees (a "
    "five-link biped); actuation: a push-off impulse and hip torques on straight, "
    "point-footed legs, hip and knee torques on a five-link biped, rigid model); no elastic "
    "knees or ankle actuators yet")


def _walker_vocabulary_applies(root: type[BaseModel], e: dict) -> bool:
    """An unknown kind, or an unknown key close to no field, inside ``walker``: the
    vocabulary's end rather than a typo."""
    if not e["loc"] or e["loc"][0] != "walker":
        return False
    return e["type"] == "union_tag_invalid" or (e["type"] == "extra_forbidden"
                                                 and not _suggestion(root, e))


_BOUND_ERRORS = ("less_than", "less_than_equal", "greater_than", "greater_than_equal")


def _unit_hint(root: type[BaseModel], e: dict, parts: list) -> str:
    """A likely unit mistake behind a bound error: an angle in degrees
    given to a ``*_rad`` field (``3 rad = 172°; did you mean angle_deg?``), a length in
    millimetres given to a ``*_m`` field (``1000 m: a length in mm? 1000 mm = 1 m``)."""
    v = e.get("input")
    if e["type"] not in _BOUND_ERRORS or isinstance(v, bool) or not isinstance(v, int | float) \
            or not parts:
        return ""
    leaf = str(parts[-1])
    if leaf.endswith("_rad"):
        deg = leaf.removesuffix("_rad") + "_deg"
        sibling = deg in _fields_at(root, tuple(e["loc"][:-1]))
        return (f" ({v:g} rad = {math.degrees(v):.0f}°"
                + (f"; did you mean {deg}?)" if sibling else "; an angle in degrees?)"))
    if leaf.endswith("_m") and e["type"].startswith("less") and abs(v) >= 10:
        return f" ({v:g} m: a length in mm? {v:g} mm = {v / 1000:g} m)"
    return ""

def _error_line(root: type[BaseModel], e: dict) -> str:
    """One error as ``<field path>: <message>`` (an unknown key names the likely field)."""
    parts = [p for p in e["loc"] if _loc_part(p)]
    loc = ".".join(str(p) for p in parts)
    if e["type"] == "extra_forbidden":
        close = _suggestion(root, e)
        return f"{loc}: unknown field" + (f" (did you mean {close[0]}?)" if close else "")
    msg = e["msg"].removeprefix("Value error, ").replace(
        " found using _walker_tag() ", " (walker.model) ") + _unit_hint(root, e, parts)
    if "input" in e and isinstance(e["input"], (bool, str, float, int)) \
            and e["type"] in ("float_type", "int_type", "finite_number", "bool_type",
                              "string_type", "float_parsing", "int_parsing"):
        msg += f" (got {_input_text(e['input'])})"
        if isinstance(e["input"], str) and re.fullmatch(
                r"[-+]?(\d+\.?\d*|\.\d+)[eE][-+]?\d+", e["input"].strip()):
            # YAML 1.1 (PyYAML) reads a float only with a dot and a signed exponent
            m, x = re.split("[eE]", e["input"].strip())
            x = x if x[:1] in "+-" else "+" + x
            msg += (f"; YAML reads {e['input']} as text: write "
                    f"{m if '.' in m else m + '.0'}e{x}")
    if not loc and re.match(r"^[a-z_]+(\.[a-z_]+)*: ", msg) \
            and msg.split(".", 1)[0].split(":", 1)[0] in root.model_fields:
        return msg  # a cross-field check names its field ("published: ...")
    if loc and msg.startswith(f"{loc}: "):  # the section's own check names it already
        return msg
    if loc and msg.startswith(f"{loc.rsplit('.', 1)[-1]}: "):  # "slope: give exactly one"
        return f"{loc}: {msg.split(': ', 1)[1]}"
    return f"{loc or '<scene>'}: {msg}"


def format_error(path: Path, err: ValidationError, root: type[BaseModel]) -> str:
    """Every validation error, one line each, ``<file>: <field path>: <message>``.

    Unknown keys (pydantic's ``extra_forbidden``, at their own location) come first, with
    the closest allowed field name (``walker.hip_mas_kg: unknown field (did you mean
    hip_mass_kg?)``); a union (``'fixed_point' | StateSpec``) reports one error per member:
    only the members that went deepest into the mapping are kept, they name the offending
    field; the other members are alternatives, not further errors.
    """
    errs = err.errors()
    locs = [tuple(p for p in x["loc"] if _loc_part(p)) for x in errs]
    keep = []
    for i, x in enumerate(errs):
        deeper = any(len(o) > len(locs[i]) and o[:len(locs[i])] == locs[i] for o in locs)
        if deeper or (x["type"] in ("literal_error", "none_required")
                      and sum(o == locs[i] for o in locs) > 1):
            continue
        keep.append(x)
    keep = keep or errs[:1]
    # a misspelt required key is one mistake: "unknown field (did you mean X?)" says it, so
    # the "X: Field required" it causes is left out
    meant = {(*locs[errs.index(x)][:-1], m) for x in keep if x["type"] == "extra_forbidden"
             for m in _suggestion(root, x)}
    keep = [x for x in keep if not (x["type"] == "missing" and locs[errs.index(x)] in meant)]
    keep.sort(key=lambda x: x["type"] != "extra_forbidden")  # stable: file order otherwise
    said = next((x for x in keep if _walker_vocabulary_applies(root, x)), None)
    lines = list(dict.fromkeys(_error_line(root, x)
                               + (f"; {WALKER_VOCABULARY}" if x is said else "")
                               for x in keep))  # the vocabulary once, on the first such line
    return "\n".join(f"{path}: {ln}" for ln in lines)
