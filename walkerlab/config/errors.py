"""One error line per validation mistake, naming the file and the field (``<file>: <field
path>: <message>``), with the likely meant field for an unknown key and a unit hint for a
bound that looks like a unit mistake, and :class:`SceneError`, the exception those lines
travel in.  The root model is a parameter, so this module sits below the schema it
describes."""

from __future__ import annotations

import math
import re
from collections import Counter
from pathlib import Path

from pydantic import BaseModel, ValidationError


class SceneError(ValueError):
    """A scene file cannot be read or does not validate (one line per error, each naming
    the file and the field)."""


# discriminator tags of walker models and bodies: not part of a field's path
_TAGS = {"compass_gait", "biped", "rimless_wheel", "point_mass", "rod", "point", "arc", "flat",
         "toroidal"}


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


def _models_at(root: type[BaseModel], loc: tuple) -> list[type[BaseModel]]:
    """The models a validation-error location can be (several where a union leaves the
    model open)."""
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
    return current


def _fields_at(root: type[BaseModel], loc: tuple) -> list[str]:
    """Field names allowed at a validation-error location (the union of the candidate
    models' fields where a union leaves the model open); [] when it cannot be told."""
    return sorted({k for m in _models_at(root, loc) for k in m.model_fields})


def _is_list(tp) -> bool:
    """Whether a field annotation holds a list or tuple (through Optional and Annotated)."""
    import typing

    return typing.get_origin(tp) in (list, tuple) or any(_is_list(a)
                                                         for a in typing.get_args(tp))


def _one_level_down(root: type[BaseModel], loc: tuple, key: str) -> list[str]:
    """Where an unknown key is a field one section further down (``walker.knee`` ->
    ``leg.knee``, ``legs.N.knee``): the dotted paths from ``loc``."""
    out: list[str] = []
    for m in _models_at(root, loc):
        for name, f in m.model_fields.items():
            if any(key in sub.model_fields for sub in _models_in(f.annotation)):
                path = f"{name}.N.{key}" if _is_list(f.annotation) else f"{name}.{key}"
                out += [path] if path not in out else []
    return out


def _given_at(data, loc: tuple):
    """The mapping the user gave at a location (None when it cannot be followed)."""
    for p in loc:
        if isinstance(data, dict) and p in data:
            data = data[p]
        elif isinstance(data, list) and isinstance(p, int) and 0 <= p < len(data):
            data = data[p]
        elif not _loc_part(p):  # a union member's class name or a discriminator tag
            continue
        else:
            return None
    return data if isinstance(data, dict) else None


def _input_text(value) -> str:
    """``repr`` of an input value for a message; an integer too long to print (Python caps
    int-to-str at 4300 digits) or to read is described instead."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 100:
        return f"an integer of about {int(value.bit_length() * 0.30103) + 1} digits"
    return repr(value)


#: At most this many error lines for one scene; the rest are counted ("… and N more errors")
MAX_ERROR_LINES = 20


class _Suggester:
    """The field an unknown key most likely meant ([] when none is close): a close name
    at the same place, else the same name one section further down (``walker.knee`` on a
    ``legs:`` walker -> ``legs.N.knee``; the sections the scene gives first).  The allowed
    fields are looked up once per location: thousands of unknown keys in one mapping cost
    one lookup, not thousands."""

    def __init__(self, root: type[BaseModel], data=None) -> None:
        self.root, self.data = root, data
        self.fields: dict[tuple, list[str]] = {}
        self.said: dict[tuple, list[str]] = {}

    def __call__(self, e: dict) -> list[str]:
        at, key = tuple(e["loc"][:-1]), str(e["loc"][-1])
        if at not in self.fields:
            self.fields[at] = _fields_at(self.root, at)
        if (at, key) not in self.said:
            self.said[at, key] = self._close(at, key)
        return self.said[at, key]

    def _close(self, at: tuple, key: str) -> list[str]:
        import difflib

        close = difflib.get_close_matches(key, self.fields[at], n=1)
        if close:
            return close
        down = _one_level_down(self.root, at, key)
        given = _given_at(self.data, at) or {}
        return ([p for p in down if p.split(".")[0] in given] or down)[:3]


#: What a walker can be today, said by an error on an unknown walker field or kind and by
#: the user guide, docs/user_guide/walkers.md (one place: update it as the walker vocabulary grows)
WALKER_VOCABULARY = (
    "a walker today is planar but for two in 3D (space: 3d): model compass_gait (hip mass, "
    "one point mass per leg; space: 3d with hip_width_m: the walker in three dimensions, "
    "with foot_radius_m round feet, leg_inertia_kg_m2 rod legs) "
    "or biped (hip_mass_kg; one leg: or a legs: pair that may differ, each with "
    "length_m, bodies (point_mass or rod, on or off the leg axis), an optional locking knee "
    "(with an optional spring-damper) or free knees (knee.lock: free), foot "
    "kind point, arc or flat (heel, toe, ankle spring); springs: torsional springs and "
    "dampers between links at the hip; torso: an upper body on a bisecting hip mechanism, or "
    "hinged at the hip, on free knees (a five-link biped) or straight point- or arc-footed "
    "legs (a three-link walker); actuation: torques at any joint the walker has (hip, torso "
    "to leg, knees, flat feet's ankles) in the rigid model (the contact model: hip torques on "
    "straight, point-footed legs and a hinged torso's walker's joints), a push-off impulse on "
    "point feet, an ankle push-off on flat feet), or "
    "rimless_wheel (spokes, spoke_length_m, mass_kg, optional hub_inertia_kg_m2; space: 3d "
    "with diametral_inertia_kg_m2: the wheel in three dimensions)")


def _walker_vocabulary_applies(root: type[BaseModel], e: dict, suggest=None) -> bool:
    """An unknown kind, or an unknown key close to no field, inside ``walker``: the
    vocabulary's end rather than a typo."""
    if not e["loc"] or e["loc"][0] != "walker":
        return False
    suggest = suggest or _Suggester(root)
    return e["type"] == "union_tag_invalid" or (e["type"] == "extra_forbidden"
                                                 and not suggest(e))


_BOUND_ERRORS = ("less_than", "less_than_equal", "greater_than", "greater_than_equal")


def _unit_hint(root: type[BaseModel], e: dict, parts: list) -> str:
    """A likely unit mistake behind a bound error: an angle in degrees given to a ``*_rad``
    field (``3 rad = 172°; did you mean angle_deg?``), a length in millimetres given to a
    ``*_m`` field (``1000 m: a length in mm? 1000 mm = 1 m``); none for a rate per radian or
    per metre (``*_per_rad``, ``*_per_m``: a stiffness, a damping) or a torque (``*_n_m``)."""
    v = e.get("input")
    if e["type"] not in _BOUND_ERRORS or isinstance(v, bool) or not isinstance(v, int | float) \
            or not parts:
        return ""
    leaf = str(parts[-1])
    # a rate per radian or per metre (a stiffness, a damping) and a torque [N m] are no
    # angle or length: no unit hint there
    if leaf.endswith(("_per_rad", "_per_m", "_n_m")):
        return ""
    if leaf.endswith("_rad"):
        deg = leaf.removesuffix("_rad") + "_deg"
        sibling = deg in _fields_at(root, tuple(e["loc"][:-1]))
        return (f" ({v:g} rad = {math.degrees(v):.0f}°"
                + (f"; did you mean {deg}?)" if sibling else "; an angle in degrees?)"))
    if leaf.endswith("_m") and e["type"].startswith("less") and abs(v) >= 10:
        return f" ({v:g} m: a length in mm? {v:g} mm = {v / 1000:g} m)"
    return ""

#: the number forms YAML 1.2 and YAML 1.1 read alike: decimal integers, decimal floats with a
#: dot (``.inf``, ``.nan``); PyYAML (YAML 1.1) also reads hex (``0x10``), binary (``0b11``),
#: leading-zero octal (``010`` = 8), digits with underscores (``1_0.0``) and base 60
#: (``1:20`` = 80) as numbers
PLAIN_NUMBER = re.compile(r"[-+]?(0|[1-9][0-9]*)(\.[0-9]*)?([eE][-+]?[0-9]+)?|"
                           r"[-+]?\.[0-9]+([eE][-+]?[0-9]+)?|[-+]?\.(inf|Inf|INF)|\.(nan|NaN|NAN)")


def _yaml11_number(text: str) -> str:
    """The plain decimal of a YAML-1.1-only number form (``0x10`` -> ``16``, ``1_0.0`` ->
    ``10.0``; :mod:`walkerlab.config.loader` keeps those as text), "" for other text."""
    import yaml

    try:
        v = yaml.safe_load(text)  # PyYAML: YAML 1.1, which reads these forms as numbers
    except yaml.YAMLError:
        return ""
    return repr(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else ""


def _error_line(root: type[BaseModel], e: dict, suggest=None) -> str:
    """One error as ``<field path>: <message>`` (an unknown key names the likely field)."""
    parts = [p for p in e["loc"] if _loc_part(p)]
    loc = ".".join(str(p) for p in parts)
    if e["type"] == "extra_forbidden":
        close = (suggest or _Suggester(root))(e)
        return f"{loc}: unknown field" + (f" (did you mean {' or '.join(close)}?)"
                                          if close else "")
    msg = e["msg"].removeprefix("Value error, ").replace(
        " found using _walker_tag() ", " (walker.model) ") + _unit_hint(root, e, parts)
    if "input" in e and isinstance(e["input"], (bool, str, float, int)) \
            and e["type"] in ("float_type", "int_type", "finite_number", "bool_type",
                              "string_type", "float_parsing", "int_parsing"):
        msg += f" (got {_input_text(e['input'])})"
        if isinstance(e["input"], str) and PLAIN_NUMBER.fullmatch(e["input"]) \
                and _yaml11_number(e["input"]):
            # a number YAML reads as one unless quoted: it was written in quotes
            msg += (f"; {e['input']} is written in quotes, which makes it text: write it "
                    "without them")
        elif isinstance(e["input"], str) and re.fullmatch(
                r"[-+]?(\d+\.?\d*|\.\d+)[eE][-+]?\d+", e["input"].strip()):
            # YAML 1.1 (PyYAML) reads a float only with a dot and a signed exponent
            m, x = re.split("[eE]", e["input"].strip())
            x = x if x[:1] in "+-" else "+" + x
            msg += (f"; YAML reads {e['input']} as text: write "
                    f"{m if '.' in m else m + '.0'}e{x}")
        elif isinstance(e["input"], str) and (plain := _yaml11_number(e["input"])):
            msg += (f"; {e['input']} is a YAML 1.1 number form (hex, binary, octal, base 60, "
                    f"underscores), refused: write a plain decimal (YAML 1.1 reads {plain})")
    if not loc and re.match(r"^[a-z_]+(\.[a-z_]+)*: ", msg) \
            and msg.split(".", 1)[0].split(":", 1)[0] in root.model_fields:
        return msg  # a cross-field check names its field ("published: ...")
    if loc and msg.startswith(f"{loc}: "):  # the section's own check names it already
        return msg
    if loc and msg.startswith(f"{loc.rsplit('.', 1)[-1]}: "):  # "slope: give exactly one"
        return f"{loc}: {msg.split(': ', 1)[1]}"
    return f"{loc or '<scene>'}: {msg}"


def format_error(path: Path, err: ValidationError, root: type[BaseModel], data=None) -> str:
    """Every validation error, one line each, ``<file>: <field path>: <message>``.

    Unknown keys (pydantic's ``extra_forbidden``, at their own location) come first, with
    the closest allowed field name (``walker.hip_mas_kg: unknown field (did you mean
    hip_mass_kg?)``); a union (``'fixed_point' | StateSpec``) reports one error per member:
    only the members that went deepest into the mapping are kept, they name the offending
    field; the other members are alternatives, not further errors.  ``data``, the mapping
    that failed (optional), narrows a suggestion to the sections it gives.
    """
    errs = err.errors()
    locs = [tuple(p for p in x["loc"] if _loc_part(p)) for x in errs]
    # linear in the number of errors: the strict prefixes of every location, once
    prefixes = {o[:k] for o in locs for k in range(len(o))}
    count = Counter(locs)
    keep = [i for i, x in enumerate(errs)
            if not (locs[i] in prefixes or (x["type"] in ("literal_error", "none_required")
                                            and count[locs[i]] > 1))] or [0]
    suggest = _Suggester(root, data)
    # a misspelt required key is one mistake: "unknown field (did you mean X?)" says it, so
    # the "X: Field required" it causes is left out
    missing = {locs[i][:-1] for i in keep if errs[i]["type"] == "missing"}
    meant = {(*locs[i][:-1], m) for i in keep if errs[i]["type"] == "extra_forbidden"
             and locs[i][:-1] in missing for m in suggest(errs[i])}
    keep = [i for i in keep if not (errs[i]["type"] == "missing" and locs[i] in meant)]
    keep.sort(key=lambda i: errs[i]["type"] != "extra_forbidden")  # stable: file order
    return "\n".join(f"{path}: {ln}" for ln in _capped_lines(root, errs, keep, suggest))


def _capped_lines(root: type[BaseModel], errs: list[dict], keep: list[int],
                  suggest: _Suggester) -> list[str]:
    """The kept errors' lines, repeats once, at most :data:`MAX_ERROR_LINES` (the rest
    counted in a last line, not rendered: thousands of unknown keys cost no suggestions)."""
    said = False  # the walker vocabulary once, on the first line it applies to
    lines: dict[str, None] = {}
    for n, i in enumerate(keep):
        if len(lines) == MAX_ERROR_LINES - 1 and len(keep) - n > 1:
            return [*lines, f"… and {len(keep) - n} more errors"]
        line = _error_line(root, errs[i], suggest)
        if not said and _walker_vocabulary_applies(root, errs[i], suggest):
            line, said = f"{line}; {WALKER_VOCABULARY}", True
        lines[line] = None
    return list(lines)
