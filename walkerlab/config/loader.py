"""Reading a scene: YAML parsing (duplicate keys and deep nesting refused), validation,
and one error line per mistake naming the file and the field.

Raises
------
SceneError
    One line naming the file and the offending field, for every bad input.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any

import yaml
from pydantic import BaseModel, ConfigDict, ValidationError

import walkerlab
from walkerlab import progress
from walkerlab.config.errors import PLAIN_NUMBER, SceneError, format_error
from walkerlab.config.limits import MAX_SCENE_BYTES, MAX_YAML_DEPTH, SMALL_SLOPE_DEG
from walkerlab.config.schema import SCENE_NAME_RE, Scene
from walkerlab.safefs import NotARegularFile, read_regular


def default_scene_path() -> Path:
    """The paper's scene: ``configs/paper.yaml`` in the working folder, else the one shipped
    next to the package (an editable install)."""
    here = Path("configs/paper.yaml")
    if here.is_file():
        return here

    return Path(walkerlab.__file__).resolve().parent.parent / "configs" / "paper.yaml"


def shipped_scene_path(name: str | Path) -> Path | None:
    """A shipped scene by name (``paper``, ``kneed``, ``rabbit.yaml``) or by its path in the
    repository (``configs/paper.yaml``): the file in the ``configs`` folder next to the
    package (an editable install), or None when there is none."""
    configs = Path(walkerlab.__file__).resolve().parent.parent / "configs"
    p = Path(name)
    if len(p.parts) == 2 and p.parts[0] == "configs":
        p = Path(p.name)
    if len(p.parts) != 1 or p.name in ("", ".", ".."):
        return None
    f = configs / (p.name if p.suffix in (".yaml", ".yml") else f"{p.name}.yaml")
    return f if f.is_file() else None


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


def _number_or_text(construct):
    """A constructor that keeps a YAML-1.1-only number form (:data:`PLAIN_NUMBER`) as the
    text it is, so the field that receives it refuses it (one line naming the field and
    the form, :func:`walkerlab.config.errors.format_error`)."""
    def build(loader, node):
        if not PLAIN_NUMBER.fullmatch(str(node.value)):
            return loader.construct_scalar(node)
        return construct(loader, node)
    return build


_SceneLoader.add_constructor("tag:yaml.org,2002:int",
                             _number_or_text(yaml.SafeLoader.construct_yaml_int))
_SceneLoader.add_constructor("tag:yaml.org,2002:float",
                             _number_or_text(yaml.SafeLoader.construct_yaml_float))


def _first_line(exc: BaseException) -> str:
    return (str(exc).strip().splitlines() or [""])[0][:200]


def parse_yaml(text: str):
    """Parse YAML text with :class:`_SceneLoader` (duplicate keys and deep nesting refused;
    YAML-1.1-only number forms kept as text, :data:`PLAIN_NUMBER`).

    Raises
    ------
    yaml.YAMLError
        Malformed YAML, a duplicate key or nesting deeper than :data:`MAX_YAML_DEPTH`.
    ValueError
        A number Python will not convert (an integer of more than 4300 digits).
    """
    return yaml.load(text, Loader=_SceneLoader)  # noqa: S506 - a SafeLoader subclass


def _read_scene_text(path: Path) -> str:
    """The scene file's text (at most :data:`MAX_SCENE_BYTES`, UTF-8).

    Raises
    ------
    SceneError
        Not a regular file, not UTF-8 text, or unreadable (one line naming the file).
    """
    try:
        text = read_regular(path, MAX_SCENE_BYTES, "scene file").decode("utf-8")
    except NotARegularFile as exc:
        raise SceneError(str(exc)) from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"{path}: not a text (UTF-8) YAML file (byte {exc.start} is "
                         f"0x{exc.object[exc.start]:02x})") from None
    except OSError as exc:
        raise SceneError(f"{path}: cannot read the scene file ({exc.strerror})") from None
    return text


def _parse_scene_yaml(text: str, path: Path):
    """The scene file's YAML ``text`` parsed (:func:`parse_yaml`).

    Raises
    ------
    SceneError
        An unreadable number, nesting too deep, a control character, a duplicate key or
        malformed YAML (one line naming the file and the line).
    """
    try:
        data = parse_yaml(text)
    except ValueError as exc:  # int(...) of a 5000-digit number
        what = ("an integer longer than Python reads (4300 digits)" if "digits" in str(exc)
                else _first_line(exc))
        raise SceneError(f"{path}: unreadable number: {what}") from None
    except RecursionError:
        raise SceneError(f"{path}: nesting too deep (at most {MAX_YAML_DEPTH} levels)") \
            from None
    except yaml.reader.ReaderError as exc:  # a control character: say where, in one line
        line = text.count("\n", 0, exc.position) + 1
        code = exc.character if isinstance(exc.character, int) else ord(exc.character)
        raise SceneError(f"{path}: line {line}: character 0x{code:02x} is not allowed in a "
                         "YAML file (a binary or damaged file?)") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", exc)
        if str(problem).startswith(("duplicate key", "nesting deeper")):
            raise SceneError(f"{path}:{where} {problem}") from None
        raise SceneError(f"{path}:{where} malformed YAML ({problem})") from None
    return data


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene YAML file.

    Parameters
    ----------
    path : str or Path
        YAML scene file; one not found in the working folder may name a shipped scene
        (``"paper"``, ``"kneed"``, ``"configs/rabbit.yaml"``: :func:`shipped_scene_path`).

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
    path = Path(path)
    if not path.exists() and (shipped := shipped_scene_path(path)) is not None:
        path = shipped
    if path.is_dir():
        raise SceneError(f"{path}: is a directory, not a scene file")
    if not path.is_file():
        if path.exists():  # a device, FIFO or socket (/dev/zero)
            raise SceneError(f"{path}: not a regular file; give a YAML scene file")
        raise SceneError(f"{path}: scene file not found")
    text = _read_scene_text(path)
    data = _parse_scene_yaml(text, path)
    if not isinstance(data, dict):
        raise SceneError(f"{path}: a scene must be a YAML mapping")
    if data.get("name") is None:
        data["name"] = path.stem
        if not SCENE_NAME_RE.match(path.stem):
            raise SceneError(f"{path}: the file name gives the run-folder name {path.stem!r}, "
                             "which is not allowed (letters, digits and . _ + - only, not "
                             "starting with a dot); rename the file or set 'name:' in it")
    terrain = data.get("terrain")
    if isinstance(terrain, dict) and isinstance(terrain.get("profile_csv"), str) \
            and terrain.get("profile_m") is None:
        data = {**data, "terrain": _profile_from_csv(terrain, path)}
    scene = scene_from_dict(data, path)
    scene._origin = path.resolve()
    if unit_warnings(scene):

        for line in unit_warnings(scene):
            progress.note(f"warning: {path}: {line}")
    return scene


def _profile_from_csv(terrain: dict, scene_path: Path) -> dict:
    """``terrain`` with ``profile_csv`` read into ``profile_m``: a CSV of ``x, y`` rows [m]
    (a first row that is not two numbers is a header; blank lines and ``#`` comments are
    skipped), relative to the scene's folder.  The points then stand in the scene (its
    content hash follows the profile's numbers, not the file's name).

    Raises
    ------
    SceneError
        The file is missing or unreadable, or a row is not two numbers (one line naming
        the scene, the field and the file's line).
    """
    import csv
    import io

    name = terrain["profile_csv"]
    where = f"{scene_path}: terrain.profile_csv: {name}"
    f = scene_path.parent / name
    if not f.is_file():
        raise SceneError(f"{where}: file not found (relative to the scene's folder)")
    try:
        text = read_regular(f, MAX_SCENE_BYTES, "profile file").decode("utf-8")
    except (NotARegularFile, OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"{where}: unreadable ({_first_line(exc)})") from None
    rows = []
    for line_no, row in enumerate(csv.reader(io.StringIO(text)), start=1):
        cells = [c.strip() for c in row]
        if not any(cells) or cells[0].startswith("#"):
            continue
        try:
            if len(cells) != 2:
                raise ValueError
            rows.append([float(cells[0]), float(cells[1])])
        except ValueError:
            if not rows and line_no == 1:  # a header row
                continue
            raise SceneError(f"{where}: line {line_no}: give two numbers x, y [m] "
                             f"(got {','.join(cells)[:60]!r})") from None
    out = {k: v for k, v in terrain.items() if k != "profile_csv"}
    out["profile_m"] = rows
    return out


def scene_from_dict(data: dict[str, Any], origin: str | Path = "<scene>") -> Scene:
    """Validate a scene given as a plain mapping (used by sweeps). Raises SceneError."""
    try:
        return Scene.model_validate(data)
    except ValidationError as err:
        raise SceneError(format_error(Path(str(origin)), err, Scene, data)) from None

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


def unit_warnings(scene: Scene) -> list[str]:
    """Values that validate but look like a unit mistake (one line each, naming the field):
    ``slope.angle_deg`` below :data:`SMALL_SLOPE_DEG` (radians given as degrees?)."""
    out = []
    d = scene.slope.angle_deg
    if d is not None and 0 < abs(d) < SMALL_SLOPE_DEG:
        out.append(f"slope.angle_deg: {d:g}° is a very small slope; it looks like radians "
                   f"({d:g} rad = {math.degrees(d):.3g}°): if so, write angle_rad: {d:g}")
    return out
