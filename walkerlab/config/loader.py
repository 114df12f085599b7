"""Reading a scene: YAML parsing (duplicate keys and deep nesting refused), validation,
and one error line per mistake naming the file and the field.

Raises
------
SceneError
    One line naming the file and the offending field, for every bad input.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Annotated, Any

import yaml
from pydantic import BaseModel, ConfigDict, ValidationError

from walkerlab.config.limits import MAX_SCENE_BYTES, MAX_YAML_DEPTH, unit_warnings
from walkerlab.config.schema import SCENE_NAME_RE, Scene, SceneError

# discriminator tags of walker models and bodies: not part of a field's path
_TAGS = {"compass_gait", "biped", "point_mass", "rod", "point", "arc"}


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


def _fields_at(loc: tuple) -> list[str]:
    """Field names allowed at a validation-error location (the union of the candidate
    models' fields where a union leaves the model open); [] when it cannot be told."""
    import typing

    current: list[type[BaseModel]] = [Scene]
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


def _suggestion(e: dict) -> list[str]:
    """The field an unknown key most likely meant ([] when none is close)."""
    import difflib

    return difflib.get_close_matches(str(e["loc"][-1]), _fields_at(tuple(e["loc"][:-1])), n=1)


#: What a walker can be today, said by an error on an unknown walker field or kind and by
#: the README (one place: update it as the walker vocabulary grows)
WALKER_VOCABULARY = (
    "a walker today is planar and passive: model compass_gait (hip mass, one point mass per "
    "leg) or biped (hip_mass_kg and two identical legs: length_m, bodies (point_mass or "
    "rod), an optional knee, foot kind point or arc); no torso, springs, ankles, flat feet "
    "or actuation yet")


def _walker_vocabulary_applies(e: dict) -> bool:
    """An unknown kind, or an unknown key close to no field, inside ``walker``: the
    vocabulary's end rather than a typo."""
    if not e["loc"] or e["loc"][0] != "walker":
        return False
    return e["type"] == "union_tag_invalid" or (e["type"] == "extra_forbidden"
                                                 and not _suggestion(e))


_BOUND_ERRORS = ("less_than", "less_than_equal", "greater_than", "greater_than_equal")


def _unit_hint(e: dict, parts: list) -> str:
    """A likely unit mistake behind a bound error (issue 26, item 9): an angle in degrees
    given to a ``*_rad`` field (``3 rad = 172°; did you mean angle_deg?``), a length in
    millimetres given to a ``*_m`` field (``1000 m: a length in mm? 1000 mm = 1 m``)."""
    v = e.get("input")
    if e["type"] not in _BOUND_ERRORS or isinstance(v, bool) or not isinstance(v, int | float) \
            or not parts:
        return ""
    leaf = str(parts[-1])
    if leaf.endswith("_rad"):
        deg = leaf.removesuffix("_rad") + "_deg"
        sibling = deg in _fields_at(tuple(e["loc"][:-1]))
        return (f" ({v:g} rad = {math.degrees(v):.0f}°"
                + (f"; did you mean {deg}?)" if sibling else "; an angle in degrees?)"))
    if leaf.endswith("_m") and e["type"].startswith("less") and abs(v) >= 10:
        return f" ({v:g} m: a length in mm? {v:g} mm = {v / 1000:g} m)"
    return ""

def _error_line(e: dict) -> str:
    """One error as ``<field path>: <message>`` (an unknown key names the likely field)."""
    parts = [p for p in e["loc"] if _loc_part(p)]
    loc = ".".join(str(p) for p in parts)
    if e["type"] == "extra_forbidden":
        close = _suggestion(e)
        return f"{loc}: unknown field" + (f" (did you mean {close[0]}?)" if close else "")
    msg = e["msg"].removeprefix("Value error, ").replace(
        " found using _walker_tag() ", " (walker.model) ") + _unit_hint(e, parts)
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
            and msg.split(".", 1)[0].split(":", 1)[0] in Scene.model_fields:
        return msg  # a cross-field check names its field ("published: ...")
    if loc and msg.startswith(f"{loc}: "):  # the section's own check names it already
        return msg
    if loc and msg.startswith(f"{loc.rsplit('.', 1)[-1]}: "):  # "slope: give exactly one"
        return f"{loc}: {msg.split(': ', 1)[1]}"
    return f"{loc or '<scene>'}: {msg}"


def format_error(path: Path, err: ValidationError) -> str:
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
             for m in _suggestion(x)}
    keep = [x for x in keep if not (x["type"] == "missing" and locs[errs.index(x)] in meant)]
    keep.sort(key=lambda x: x["type"] != "extra_forbidden")  # stable: file order otherwise
    said = next((x for x in keep if _walker_vocabulary_applies(x)), None)
    lines = list(dict.fromkeys(_error_line(x) + (f"; {WALKER_VOCABULARY}" if x is said else "")
                               for x in keep))  # the vocabulary once, on the first such line
    return "\n".join(f"{path}: {ln}" for ln in lines)


def default_scene_path() -> Path:
    """The paper's scene: ``configs/paper.yaml`` in the working folder, else the one shipped
    next to the package (an editable install)."""
    here = Path("configs/paper.yaml")
    if here.is_file():
        return here
    import walkerlab

    return Path(walkerlab.__file__).resolve().parent.parent / "configs" / "paper.yaml"


class _SceneLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses duplicate keys and nesting deeper than
    :data:`MAX_YAML_DEPTH` (the composer recurses once per level: 20000 levels would exhaust
    Python's stack)."""

    _depth = 0

    def compose_node(self, parent, index):
        self._depth += 1
        try:
            if self._depth > MAX_YAML_DEPTH:
                raise yaml.composer.ComposerError(
                    None, None, f"nesting deeper than {MAX_YAML_DEPTH} levels",
                    self.peek_event().start_mark)
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen: dict = {}
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = self.construct_object(key_node, deep=True)
                try:
                    first = seen.setdefault(key, key_node.start_mark.line)
                except TypeError:  # unhashable key: SafeConstructor reports it
                    continue
                if first != key_node.start_mark.line:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"duplicate key {key!r} (first given on line {first + 1})",
                        key_node.start_mark)
        return super().construct_mapping(node, deep=deep)


def _first_line(exc: BaseException) -> str:
    return (str(exc).strip().splitlines() or [""])[0][:200]


def parse_yaml(text: str):
    """Parse YAML text with :class:`_SceneLoader` (duplicate keys and deep nesting refused).

    Raises
    ------
    yaml.YAMLError
        Malformed YAML, a duplicate key or nesting deeper than :data:`MAX_YAML_DEPTH`.
    ValueError
        A number Python will not convert (an integer of more than 4300 digits).
    """
    return yaml.load(text, Loader=_SceneLoader)  # noqa: S506 - a SafeLoader subclass


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene YAML file.

    Parameters
    ----------
    path : str or Path
        YAML scene file.

    Returns
    -------
    Scene
        Validated, frozen scene; ``name`` defaults to the file stem.

    Raises
    ------
    SceneError
        File missing, malformed YAML, or a field that fails validation (one line, naming
        the file and the field).
    """
    from walkerlab.safefs import NotARegularFile, read_regular

    path = Path(path)
    if path.is_dir():
        raise SceneError(f"{path}: is a directory, not a scene file")
    if not path.is_file():
        if path.exists():  # a device, FIFO or socket (/dev/zero)
            raise SceneError(f"{path}: not a regular file; give a YAML scene file")
        raise SceneError(f"{path}: scene file not found")
    try:
        text = read_regular(path, MAX_SCENE_BYTES, "scene file").decode("utf-8")
    except NotARegularFile as exc:
        raise SceneError(str(exc)) from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"{path}: not a text (UTF-8) YAML file (byte {exc.start} is "
                         f"0x{exc.object[exc.start]:02x})") from None
    except OSError as exc:
        raise SceneError(f"{path}: cannot read the scene file ({exc.strerror})") from None
    try:
        data = parse_yaml(text)
    except ValueError as exc:  # int(...) of a 5000-digit number
        what = ("an integer longer than Python reads (4300 digits)" if "digits" in str(exc)
                else _first_line(exc))
        raise SceneError(f"{path}: unreadable number: {what}") from None
    except RecursionError:
        raise SceneError(f"{path}: nesting too deep (at most {MAX_YAML_DEPTH} levels)") \
            from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", exc)
        if str(problem).startswith(("duplicate key", "nesting deeper")):
            raise SceneError(f"{path}:{where} {problem}") from None
        raise SceneError(f"{path}:{where} malformed YAML ({problem})") from None
    if not isinstance(data, dict):
        raise SceneError(f"{path}: a scene must be a YAML mapping")
    if data.get("name") is None:
        data["name"] = path.stem
        if not SCENE_NAME_RE.match(path.stem):
            raise SceneError(f"{path}: the file name gives the run-folder name {path.stem!r}, "
                             "which is not allowed (letters, digits and . _ + - only, not "
                             "starting with a dot); rename the file or set 'name:' in it")
    scene = scene_from_dict(data, path)
    scene._origin = path.resolve()
    if unit_warnings(scene):
        from walkerlab import progress

        for line in unit_warnings(scene):
            progress.note(f"warning: {path}: {line}")
    return scene


def scene_from_dict(data: dict[str, Any], origin: str | Path = "<scene>") -> Scene:
    """Validate a scene given as a plain mapping (used by sweeps). Raises SceneError."""
    try:
        return Scene.model_validate(data)
    except ValidationError as err:
        raise SceneError(format_error(Path(str(origin)), err)) from None

def validate_option(model: type[BaseModel], field: str, value: Any, option: str,
                    yaml_field: str | None = None) -> Any:
    """Validate one command-line value through the pydantic field that caps it in YAML.

    Parameters
    ----------
    model : pydantic model class
        Section holding the field (``BasinSettings``, ``CommandOptions``, ...).
    field : str
        Field name (``"grid"``).
    value
        The option's value.
    option : str
        Option name for the message (``"--grid"``).
    yaml_field : str, optional
        The scene field with the same cap, named in the message (``"basin.grid"``).

    Returns
    -------
    The validated value.

    Raises
    ------
    SceneError
        One line: ``--grid 5000x5000: ... (basin.grid)``.
    """
    from pydantic import TypeAdapter

    info = model.model_fields[field]
    adapter = TypeAdapter(Annotated[info.annotation, info],
                          config=ConfigDict(strict=True, allow_inf_nan=False))
    try:
        return adapter.validate_python(value)
    except ValidationError as err:
        e = err.errors()[0]
        shown = "x".join(str(v) for v in value) if isinstance(value, tuple) else value
        also = f" (as {yaml_field})" if yaml_field else ""
        raise SceneError(f"{option} {shown}: {e['msg'][:1].lower() + e['msg'][1:]}{also}") \
            from None
