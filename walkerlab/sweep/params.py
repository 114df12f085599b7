"""Sweep parameters: parsing ``--param`` strings, building the grid, applying a point.

A parameter is a dotted path into the scene mapping (``slope.angle_deg``,
``contact.stiffness``, ``solver.rtol``) and a list of values, given either as an inclusive
range ``start:stop:step`` or as a comma list ``a,b,c``.  A grid point is applied to the plain
``dict`` of the base scene and validated again through the same pydantic types
(:func:`walkerlab.config.scene_from_dict`), so a bad value is caught per point.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
from dataclasses import dataclass
from typing import Any

from walkerlab.config import Scene, SceneError, scene_from_dict

__all__ = ["SweepError", "ParamAxis", "parse_param", "grid_points", "apply_point",
           "params_hash", "EXCLUSIVE_FIELDS"]


class SweepError(ValueError):
    """A sweep cannot be set up (bad ``--param``, mismatched resume file); one-line message."""


# Fields that exclude each other in the scene schema: setting one removes the other.
EXCLUSIVE_FIELDS = {"slope.angle_deg": "slope.angle_rad", "slope.angle_rad": "slope.angle_deg"}


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
    if not path or any(not p.isidentifier() for p in path.split(".")):
        raise SweepError(f"--param {text!r}: {path!r} is not a dotted field name")
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
        # round away binary noise (0.1 + 2*0.05 -> 0.2) to 12 significant digits
        vals = tuple(float(f"{start + k * step:.12g}") for k in range(n))
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


def _set_dotted(d: dict, path: str, value) -> None:
    keys = path.split(".")
    node = d
    for k in keys[:-1]:
        nxt = node.get(k)
        if nxt is None:
            nxt = node[k] = {}
        elif not isinstance(nxt, dict):
            raise SceneError(f"{path}: '{k}' is not a section (it is {nxt!r})")
        node = nxt
    node[keys[-1]] = value


def _pop_dotted(d: dict, path: str) -> None:
    keys = path.split(".")
    node = d
    for k in keys[:-1]:
        node = node.get(k)
        if not isinstance(node, dict):
            return
    node.pop(keys[-1], None)


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
            _pop_dotted(d, other)
        _set_dotted(d, p, v)
    label = ", ".join(f"{p}={v!r}" for p, v in zip(paths, values))
    return scene_from_dict(d, f"{origin} [{label}]")


def params_hash(axes: list[ParamAxis], stage: str) -> str:
    """Short (10 hex digits) hash of the stage and the axes' paths and values."""
    blob = json.dumps([stage, [[a.path, list(a.values)] for a in axes]], sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:10]
