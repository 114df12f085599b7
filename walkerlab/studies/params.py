"""Sweep parameters: parsing ``--param`` strings, building the grid, applying a point.

A parameter is a dotted path into the scene mapping (``slope.angle_deg``,
``contact.stiffness_n_per_mm_pow_e``, ``solver.rtol``; an item of a list by its ``name`` or index:
``walker.leg.bodies.thigh_mass.mass_kg``, ``walker.leg.bodies.1.mass_kg``; one number of a
list of numbers by its index: ``walker.actuation.virtual_constraints.outputs.1.bezier_rad.5``,
a Bezier coefficient) and a list of
values, given either as an inclusive range ``start:stop:step`` or as a comma list ``a,b,c``.
A grid point is applied to the plain ``dict`` of the base scene and validated again through
the same pydantic types (:func:`walkerlab.config.scene_from_dict`): a bad value is caught per
point, and :func:`check_axes` refuses an unknown field or a bad value before a sweep starts.
"""

from __future__ import annotations

import copy
import difflib
import hashlib
import itertools
import json
import math
import typing
from dataclasses import dataclass
from typing import Any

from walkerlab.config import MAX_SWEEP_POINTS, Scene, SceneError, scene_from_dict
from walkerlab.config.contact import CONTACT_QUANTITIES, renamed_contact_field
from walkerlab.io.stage_files import CONTACT_SIM
from walkerlab.studies.scene_paths import list_item, pop_dotted, set_dotted

__all__ = ["SweepError", "ParamAxis", "parse_param", "grid_points", "apply_point",
           "check_axes", "axis_unit", "params_hash", "EXCLUSIVE_FIELDS"]


class SweepError(ValueError):
    """A sweep cannot be set up (bad ``--param``, mismatched resume file); one-line message."""


# Fields that exclude each other in the scene schema: setting one removes the other (a
# slope in degrees or radians; a contact quantity in mm-kg-s or SI, as its name says).
EXCLUSIVE_FIELDS = {"slope.angle_deg": "slope.angle_rad", "slope.angle_rad": "slope.angle_deg",
                    **{f"contact.{q[u][0]}": f"contact.{q[v][0]}"
                       for q in CONTACT_QUANTITIES.values() for u, v in (("mm", "m"), ("m", "mm"))}}


@dataclass(frozen=True)
class ParamAxis:
    """One sweep axis.

    Attributes
    ----------
    path : str
        Dotted scene field, e.g. ``"slope.angle_deg"``.
    values : tuple
        Values along the axis (floats, ints, bools, str or None), in sweep order.
    spec : str
        The text it was parsed from (``"slope.angle_deg=0.5:5:0.05"``).
    """

    path: str
    values: tuple
    spec: str

    @property
    def numeric(self) -> bool:
        """True when every value is a real number (stored as float64 columns)."""
        return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in self.values)

    def __len__(self) -> int:
        return len(self.values)


def _scalar(text: str) -> Any:
    t = text.strip()
    low = t.lower()
    if low in ("true", "false"):
        return low == "true"
    if low in ("null", "none", "~"):
        return None
    try:
        return int(t)
    except ValueError:
        pass
    try:
        v = float(t)
    except ValueError:
        return t
    return v


def _number(text: str, what: str, spec: str) -> float:
    v = _scalar(text)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise SweepError(f"--param {spec!r}: {what} {text!r} is not a finite number")
    return float(v)


def parse_param(text: str) -> ParamAxis:
    """Parse one ``--param`` string.

    Parameters
    ----------
    text : str
        ``path=start:stop:step`` (inclusive of ``stop`` within rounding: the last value is
        kept if it lies within ``1e-9 * |step|`` past ``stop``), or ``path=a,b,c`` (a comma
        list; numbers, ``true``/``false``, ``null`` or bare strings), or ``path=a``.

    Returns
    -------
    ParamAxis

    Raises
    ------
    SweepError
        Missing ``=``, empty path or values, zero step, a step pointing away from ``stop``,
        more than 1,000,000 values, or a non-numeric range bound.

    Examples
    --------
    >>> parse_param("slope.angle_deg=0.5:1:0.25").values
    (0.5, 0.75, 1.0)
    >>> parse_param("solver.method=RK45,DOP853").values
    ('RK45', 'DOP853')
    """
    if "=" not in text:
        raise SweepError(f"--param {text!r}: expected PATH=START:STOP:STEP or PATH=A,B,C")
    path, _, rhs = text.partition("=")
    path, rhs = path.strip(), rhs.strip()
    if not path or any(not (p.isidentifier() or p.isdigit()) for p in path.split(".")):
        raise SweepError(f"--param {text!r}: {path!r} is not a dotted field name (names and "
                         "list indices separated by dots, e.g. walker.hip_mass_kg or "
                         "walker.leg.bodies.thigh_mass.mass_kg)")
    if not rhs:
        raise SweepError(f"--param {text!r}: no values")
    if ":" in rhs and "," not in rhs:
        parts = rhs.split(":")
        if len(parts) != 3:
            raise SweepError(f"--param {text!r}: a range is START:STOP:STEP")
        start, stop, step = (_number(p, w, text) for p, w in zip(parts, ("start", "stop", "step")))
        if step == 0:
            raise SweepError(f"--param {text!r}: step must not be zero")
        span = (stop - start) / step
        if span < -1e-9:
            raise SweepError(f"--param {text!r}: step {step:g} does not go from {start:g} "
                             f"towards {stop:g}")
        n = int(math.floor(span + 1e-9)) + 1
        from walkerlab.config import MAX_SWEEP_POINTS

        if n > MAX_SWEEP_POINTS:
            raise SweepError(f"--param {text!r}: {n:,} values; at most {MAX_SWEEP_POINTS:,}")
        # round away binary noise (0.1 + 2*0.05 -> 0.2) to 12 significant digits; a range
        # of whole numbers written as such (1:10:1) stays whole (an integer field takes it)
        whole = all(isinstance(_scalar(p), int) and not isinstance(_scalar(p), bool)
                    for p in parts)
        vals = tuple(int(round(start + k * step)) if whole
                     else float(f"{start + k * step:.12g}") for k in range(n))
    else:
        items = [s for s in (p.strip() for p in rhs.split(",")) if s != ""]
        if not items:
            raise SweepError(f"--param {text!r}: no values")
        vals = tuple(_scalar(s) for s in items)
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals) \
                and any(isinstance(v, float) for v in vals):
            vals = tuple(float(v) for v in vals)
    return ParamAxis(path, vals, text)


def grid_points(axes: list[ParamAxis]) -> list[tuple]:
    """All grid points (tuples of values), C order: the *first* axis varies slowest.

    Returns
    -------
    list of tuple, length ``prod(len(axis))``
    """
    return list(itertools.product(*(a.values for a in axes)))


def _models_in(annotation) -> list:
    """The pydantic model classes an annotation can hold (through Optional, unions,
    Annotated and list)."""
    from pydantic import BaseModel

    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    out = []
    for a in typing.get_args(annotation):
        out += _models_in(a)
    return out


def _check_path(scene: Scene, axis: ParamAxis):
    """The axis path names a field of the scene (by the schema, lists by name or index).

    Returns
    -------
    pydantic.fields.FieldInfo or None
        The named field's schema entry (None for a state given by name).

    Raises
    ------
    SweepError
        An unknown field (with the closest name), a list item that does not exist, or a
        path that goes on below a number.
    """
    from pydantic import BaseModel

    keys = axis.path.split(".")
    obj: object = scene
    cls = type(scene)
    info = None  # the last field's schema entry (a list of numbers: the list's)
    for i, k in enumerate(keys):
        here = ".".join(keys[:i + 1])
        if isinstance(obj, (list, tuple)):
            items = [o.model_dump() if isinstance(o, BaseModel) else o for o in obj]
            if k.isdigit() and not any(isinstance(o, dict) for o in items):  # a number
                if i != len(keys) - 1:  # of a list of numbers (Bezier coefficients)
                    raise SweepError(f"--param {axis.spec!r}: {here} is a value, not a "
                                     f"section: it has no field {keys[i + 1]!r}")
                if int(k) >= len(items):
                    raise SweepError(f"--param {axis.spec!r}: {here}: index {k} is out of "
                                     f"range (the list has {len(items)} values)")
                return info
            try:
                item = list_item(items, k, axis.path)
            except SceneError as exc:
                raise SweepError(f"--param {axis.spec!r}: {exc}") from None
            obj = obj[items.index(item)]
            cls = type(obj)
            continue
        if cls is None or not (isinstance(cls, type) and issubclass(cls, BaseModel)):
            raise SweepError(f"--param {axis.spec!r}: {'.'.join(keys[:i])} is a value, not a "
                             f"section: it has no field {k!r}")
        if cls.model_config.get("extra") == "allow":  # a state given by name
            return None
        fields = cls.model_fields
        if k not in fields and renamed_contact_field(here):
            raise SweepError(f"--param {axis.spec!r}: {here} is now "
                             f"{renamed_contact_field(here)} (units in every field name)")
        if k not in fields:
            close = difflib.get_close_matches(k, list(fields), 1, 0.6)
            raise SweepError(f"--param {axis.spec!r}: unknown field {here}"
                             + (f" (did you mean {'.'.join(keys[:i] + [close[0]])}?)"
                                if close else "")
                             + f"; {'.'.join(keys[:i]) or 'a scene'} has "
                             + ", ".join(fields))
        obj = getattr(obj, k) if obj is not None else None
        if isinstance(obj, BaseModel):
            cls = type(obj)
        elif isinstance(obj, (list, tuple)):
            cls = None
        else:
            models = _models_in(fields[k].annotation)
            cls = models[0] if len(models) == 1 else None
        info = fields[k]
    return info


def takes_whole_numbers(scene: Scene, axis: ParamAxis) -> bool:
    """Whether the field an axis names is an integer field (``simulate.strides``).

    Raises
    ------
    SweepError
        The path names no field of the scene (as :func:`check_axes`).
    """
    info = _check_path(scene, axis)
    return info is not None and int in typing.get_args(info.annotation) + (info.annotation,) \
        and float not in typing.get_args(info.annotation) + (info.annotation,)


def axis_unit(scene: Scene, axis: ParamAxis) -> str:
    """Unit of the field an axis sweeps: the field's ``unit`` metadata (contact fields:
    ``stiffness_n_per_mm_pow_e`` -> ``N/mm^e``), else the suffix of its name
    (:func:`walkerlab.units.field_unit`: ``mass_kg`` -> ``kg``), else ``"-"``.

    Raises
    ------
    SweepError
        The path names no field of the scene (as :func:`check_axes`).
    """
    from walkerlab.units import field_unit

    info = _check_path(scene, axis)
    extra = getattr(info, "json_schema_extra", None)
    unit = extra.get("unit") if isinstance(extra, dict) else None
    path = axis.path
    while path.rsplit(".", 1)[-1].isdigit():  # a number of a list field (bezier_rad.3)
        path = path.rsplit(".", 1)[0]
    return unit or field_unit(path) or "-"


def check_axes(scene: Scene, axes: list[ParamAxis], values: bool = True) -> None:
    """Refuse a sweep whose axes cannot work, before anything runs: every path must name a
    field of the scene (lists by item name or index) and every value must validate.

    Each value is checked alone, on the base scene (at most 200 values per axis, evenly
    spread, the first and last included); combinations of axes are checked per point.
    ``values=False`` checks the paths only.

    Raises
    ------
    SweepError
        One line naming the ``--param``, the field and the closest known name, or the value
        and pydantic's message.
    """
    base = scene.model_dump(mode="json")
    for axis in axes:
        _check_path(scene, axis)
    for axis in axes if values else ():
        vals = axis.values
        if len(vals) > 200:
            idx = sorted({round(k * (len(vals) - 1) / 199) for k in range(200)})
            vals = tuple(vals[k] for k in idx)
        for v in vals:
            try:
                apply_point(base, [axis.path], (v,), "<sweep>")
            except SceneError as exc:
                msg = str(exc).split("]: ", 1)[-1]
                raise SweepError(f"--param {axis.spec!r}: value {v!r} is not valid: "
                                 f"{msg}") from None


def apply_point(base: dict, paths: list[str], values: tuple, origin: str = "<sweep>") -> Scene:
    """Scene of one grid point: ``base`` (a scene mapping) with the fields set and validated.

    Missing sections are created (then filled with their defaults by validation). Setting
    ``slope.angle_deg`` removes ``slope.angle_rad`` and vice versa (the schema wants exactly one).

    Raises
    ------
    SceneError
        The point's scene does not validate (one line naming the field).
    """
    d = copy.deepcopy(base)
    for p, v in zip(paths, values):
        other = EXCLUSIVE_FIELDS.get(p)
        if other is not None:
            pop_dotted(d, other)
        set_dotted(d, p, v)
    label = ", ".join(f"{p}={v!r}" for p, v in zip(paths, values))
    return scene_from_dict(d, f"{origin} [{label}]")


def params_hash(axes: list[ParamAxis], stage: str) -> str:
    """Short (10 hex digits) hash of the stage and the axes' paths and values."""
    blob = json.dumps([stage, [[a.path, list(a.values)] for a in axes]], sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:10]


def sweep_axes(scene: Scene, params: list, stage: str,
               stages: tuple[str, ...] = ("fixedpoint", "simulate", CONTACT_SIM.name)
               ) -> list[ParamAxis]:
    """The axes of a sweep of ``stage`` over ``params`` (``--param`` strings or ParamAxis),
    checked against the scene before anything runs (:func:`check_axes`; the values of a grid
    of more than ``MAX_SWEEP_POINTS`` points are left to the runner's refusal).

    Raises
    ------
    SweepError
        An unknown stage, a malformed ``--param``, a field the scene does not have or a value
        that does not validate (one line).
    """
    if stage not in stages:
        raise SweepError(f"sweep: unknown stage {stage!r}; choose from {', '.join(stages)}")
    axes = [parse_param(p) if isinstance(p, str) else p for p in params]
    check_axes(scene, axes, values=math.prod(len(a) for a in axes) <= MAX_SWEEP_POINTS)
    return axes
