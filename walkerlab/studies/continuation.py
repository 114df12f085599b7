"""Continuation of a scene's gait over a scene field: the scene side of
:mod:`walkerlab.analysis.continuation.branch` (which knows walkers, not scenes).

- :func:`scene_family`: the walker as a function of dotted scene fields (the sweep's
  :func:`walkerlab.studies.params.apply_point`, validated per value);
- :func:`run_continuation`: from the scene's own gait at the scene's own value, both ways
  over a range, special points, period-doubling switches, and optionally the
  two-parameter curves of the special points found (fold, period doubling);
- :func:`homotopy_family` / :func:`homotopy_gait`: the straight line between two scenes'
  numeric fields, and the known gait carried along it to the new walker.
"""

from __future__ import annotations

import math

import numpy as np

from walkerlab.analysis.continuation.branch import ContinuationResult, continuation
from walkerlab.analysis.continuation.gait_map import MapFailed, WalkerFamily
from walkerlab.analysis.continuation.homotopy import homotopy
from walkerlab.analysis.continuation.two_parameter import two_parameter
from walkerlab.config import Scene, SceneError
from walkerlab.integrate.solver import Solver
from walkerlab.studies.params import ParamAxis, apply_point, axis_unit, check_axes
from walkerlab.studies.sweep_plan import base_value

__all__ = ["scene_family", "scene_value", "check_continuation", "run_continuation",
           "numeric_fields", "homotopy_family", "homotopy_gait", "known_scene",
           "homotopy_start"]

#: top-level sections that do not describe the rigid walker (left out of a homotopy)
NOT_WALKER = ("name", "source", "published", "fixedpoint", "simulate", "contact", "units",
              "contact_sim", "contact_solver", "terrain", "workprecision", "solver", "ideal")


def scene_family(scene: Scene, path: str, *, plant) -> WalkerFamily:
    """The scene's walker as a function of the field ``path`` (and any fields held fixed).

    ``plant``: the scene's, handed down; each value's is :meth:`~walkerlab.walker.plant.
    Plant.with_` of it.

    Raises
    ------
    walkerlab.studies.params.SweepError
        ``path`` names no field of the scene.
    """
    from walkerlab.models.registry import build_walker

    check_axes(scene, [ParamAxis(path, (), path)], values=False)
    base = scene.model_dump(mode="json")
    fp = scene.fixedpoint

    def make(values: dict):
        try:
            sc = apply_point(base, list(values), tuple(values.values()), "<continuation>")
        except SceneError as exc:
            raise MapFailed("parameter leaves the scene's domain",
                            str(exc).split("]: ", 1)[-1]) from None
        return build_walker(plant.with_(sc))

    return WalkerFamily(make, path, Solver.from_settings(scene.solver),
                        fp.max_step_time_s if fp is not None else 5.0)


def scene_value(scene: Scene, path: str) -> float:
    """The scene's own value of a numeric field (the slope in either unit)."""

    v = base_value(scene.model_dump(mode="json"), path)
    if v is None:  # a field the scene does not have (one line naming it), or one left unset
        check_axes(scene, [ParamAxis(path, (), path)], values=False)
        raise SceneError(f"{path}: the scene leaves it unset (no value to start from)")
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise SceneError(f"{path}: the scene's value {v!r} is not a number")
    return float(v)


def _finite(value, what: str) -> float:
    """A range bound as a float; one line when it is not a finite real number."""
    import numbers

    if isinstance(value, bool) or not isinstance(value, numbers.Real) \
            or not math.isfinite(value):
        raise SceneError(f"{what} {value!r} is not a finite number")
    return float(value)


def _field_range(scene: Scene, opt: str, path, start, stop) -> tuple[float, float]:
    """One field and its range checked (as :func:`check_continuation`)."""
    from walkerlab.studies.params import SweepError, takes_whole_numbers

    if not isinstance(path, str) or not path:
        raise SceneError(f"{opt}: give a dotted numeric scene field (e.g. slope.angle_deg), "
                         f"got {path!r}")
    a, b = _finite(start, f"{opt} {path}: start"), _finite(stop, f"{opt} {path}: stop")
    if a == b:
        raise SceneError(f"{opt} {path}: start and stop are both {a:g}; a continuation "
                         "needs a range: FIELD=START:STOP with two different numbers")
    try:
        check_axes(scene, [ParamAxis(path, (), path)], values=False)  # an unknown field
        whole = takes_whole_numbers(scene, ParamAxis(path, (), path))
    except SweepError as exc:
        raise SweepError(str(exc).replace("--param ", f"{opt} ", 1)) from None
    if whole:
        raise SceneError(f"{opt} {path}: the field takes whole numbers; a continuation "
                         "follows a real-valued field (e.g. slope.angle_deg or a body's "
                         "mass_kg)")
    return a, b


def check_continuation(scene: Scene, path, start, stop, path2=None, range2=None
                       ) -> tuple[float, float, tuple[float, float] | None]:
    """The fields and ranges of a continuation checked before anything runs (the command
    line's ``--param`` / ``--param2`` and the Python front door's arguments alike).

    Parameters
    ----------
    path, start, stop
        The continued field and its range [the field's unit].
    path2, range2
        The second field of the two-parameter curves and its (start, stop), both or neither.

    Returns
    -------
    start, stop : float
    range2 : (float, float) or None

    Raises
    ------
    SceneError
        A field that is not a string, a bound that is not a finite number, equal bounds, an
        integer field, ``path2`` without ``range2`` (or the reverse), ``range2`` not two
        numbers, or ``path2`` the same field as ``path`` (one line).
    walkerlab.studies.params.SweepError
        A field the scene does not have (one line, with the closest name).
    """
    a, b = _field_range(scene, "--param", path, start, stop)
    if path2 is None:
        if range2 is not None:
            raise SceneError("--param2: range2 given without param2 (the second field)")
        return a, b, None
    if range2 is None:
        raise SceneError(f"--param2 {path2}: no range; give FIELD2=START:STOP "
                         "(param2 with range2=(start, stop) in Python)")
    if isinstance(range2, (str, bytes)) or not hasattr(range2, "__len__") or len(range2) != 2:
        raise SceneError(f"--param2 {path2}: range2 must be two numbers (start, stop), "
                         f"got {range2!r}")
    from walkerlab.studies.params import EXCLUSIVE_FIELDS

    if path2 in (path, EXCLUSIVE_FIELDS.get(path)):
        raise SceneError(f"--param2 {path2}: the same field as --param {path}; the "
                         "two-parameter curves need a second field")
    return a, b, _field_range(scene, "--param2", path2, *range2)


def run_continuation(scene: Scene, path: str, start: float, stop: float, switch: int = 0,
                     path2: str | None = None, range2: tuple | None = None,
                     n2: int = 25, ds_max: float = 0.1, *, plant
                     ) -> tuple[ContinuationResult, list]:
    """Continue the scene's gait over ``path`` in ``[start, stop]``.

    Parameters
    ----------
    scene : Scene
        Walker, solver and ``fixedpoint`` (its gait at its own value of ``path`` starts the
        branch, chosen by ``fixedpoint.gait``).
    path : str
        Dotted numeric scene field.
    start, stop : float
        The range [the field's unit].
    switch : int
        Period doublings to switch at (0, 1: to period 2, 2: to period 4).
    path2, range2, n2
        Second field, its range and number of values: each fold and period doubling of the
        period-1 branch is continued in the plane (``path``, ``path2``).
    ds_max : float
        Largest arclength step (scaled: the range's span is 1).
    plant : walkerlab.walker.plant.Plant
        The scene's, built by the stage (each step's is its ``with_``).

    Returns
    -------
    result : ContinuationResult
    curves : list of TwoParameterCurve

    Raises
    ------
    walkerlab.studies.params.SweepError
        A field that does not exist.
    MapFailed
        No gait at the scene's own value.
    """
    from walkerlab.analysis.continuation.branch import add_gait_measures
    from walkerlab.studies.point_gait import PointOutcome, ideal_fixed_point  # light

    unit = axis_unit(scene, ParamAxis(path, (), path))
    p0 = scene_value(scene, path)
    lo, hi = min(start, stop), max(start, stop)
    # one map (step or stride) along the whole branch, even where the legs become equal
    fam = scene_family(scene, path, plant=plant).sharing_map((lo, hi, min(max(p0, lo), hi)))
    at = scene if lo <= p0 <= hi else apply_point(scene.model_dump(mode="json"), [path],
                                                  (min(max(p0, lo), hi),), "<continuation>")
    try:
        _w, gait, _src = ideal_fixed_point(at, None, plant=plant)
    except PointOutcome as exc:
        raise MapFailed("no gait at the scene's own value", exc.message) from None
    res = continuation(fam, min(max(p0, lo), hi), gait.x, (lo, hi), unit, switch=switch,
                       ds=min(0.02, ds_max), ds_max=ds_max)
    add_gait_measures(fam, res)
    curves = []
    if path2 is not None:
        unit2 = axis_unit(scene, ParamAxis(path2, (), path2))
        q0 = scene_value(scene, path2)
        vals = np.linspace(min(range2), max(range2), n2)
        scale = hi - lo
        for sp in res.specials:
            if sp.kind in ("fold", "period_doubling") and sp.period == 1:
                curves.append(two_parameter(fam.at(**{path2: q0}), sp, path2, q0, vals,
                                            scale, unit, unit2))
    return res, curves


def numeric_fields(a: dict, b: dict, prefix: str = "") -> dict:
    """Dotted paths of the numeric walker and slope fields that differ between two scene
    mappings (list items matched by ``name``, else by index): ``path -> (a, b)``.

    Raises
    ------
    ValueError
        The scenes differ in structure (a field in one only, different list lengths, or a
        non-numeric value that differs), naming the first such field.
    """
    out: dict = {}
    if isinstance(a, dict) and isinstance(b, dict):
        if not prefix and "slope" in a and "slope" in b:
            a, b = dict(a), dict(b)
            a["slope"] = {"angle_rad": _slope_rad(a["slope"])}
            b["slope"] = {"angle_rad": _slope_rad(b["slope"])}
        for k in sorted(set(a) | set(b)):
            if not prefix and k in NOT_WALKER:
                continue
            p = f"{prefix}{k}"
            if k not in a or k not in b:
                if a.get(k) is None and b.get(k) is None:
                    continue
                raise ValueError(f"{p}: given in one scene only")
            out.update(numeric_fields(a[k], b[k], p + "."))
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            raise ValueError(f"{prefix[:-1]}: {len(a)} items vs {len(b)} (a homotopy needs "
                             "the same structure in both scenes: only numbers may differ)")
        for i, (x, y) in enumerate(zip(a, b)):
            key = x.get("name") if isinstance(x, dict) and x.get("name") else str(i)
            out.update(numeric_fields(x, y, f"{prefix}{key}."))
        return out
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (a, b)):
        if float(a) != float(b):
            out[prefix[:-1]] = (float(a), float(b))
        return out
    if a != b:
        raise ValueError(f"{prefix[:-1]}: {a!r} vs {b!r} (a homotopy joins numeric fields "
                         "only)")
    return out


def _slope_rad(s: dict) -> float:
    if s.get("angle_rad") is not None:
        return float(s["angle_rad"])
    return math.radians(float(s["angle_deg"]))


def homotopy_family(known: Scene, new: Scene, *, plant):
    """``(make, fields)``: ``make({"lambda": v})`` builds the walker whose numeric fields are
    ``(1 - v) known + v new``; ``fields`` maps each differing path to ``(known, new)``.
    ``plant``: the new scene's, handed down (each walker on the way is its ``with_``).

    Raises
    ------
    ValueError
        The scenes' walkers differ in structure (one line naming the field).
    """
    from walkerlab.models.registry import build_walker

    base = known.model_dump(mode="json")
    fields = numeric_fields(base, new.model_dump(mode="json"))
    base["slope"] = {"angle_rad": _slope_rad(base["slope"])}

    def make(values: dict):
        lam = float(values["lambda"])
        vals = tuple((1 - lam) * a + lam * b for a, b in fields.values())
        try:
            sc = apply_point(base, list(fields), vals, "<homotopy>")
        except SceneError as exc:
            raise MapFailed("parameter leaves the scene's domain",
                            str(exc).split("]: ", 1)[-1]) from None
        return build_walker(plant.with_(sc))

    return make, fields


def homotopy_gait(known: Scene, new: Scene, *, plant):
    """The known scene's gait carried to the new scene's walker (see
    :func:`walkerlab.analysis.continuation.homotopy.homotopy`); ``plant``: the new scene's
    :class:`~walkerlab.walker.plant.Plant`, handed down.

    Returns
    -------
    HomotopyResult
        With ``fields`` filled.

    Raises
    ------
    ValueError
        Structures differ.
    MapFailed
        No gait for the known scene.
    """
    from walkerlab.studies.point_gait import PointOutcome, ideal_fixed_point  # light

    make, fields = homotopy_family(known, new, plant=plant)
    try:
        _w, gait, _src = ideal_fixed_point(known, None, plant=plant)
    except PointOutcome as exc:
        raise MapFailed("no gait for the known scene", exc.message) from None
    fp = new.fixedpoint or known.fixedpoint
    res = homotopy(make, gait.x, Solver.from_settings(new.solver),
                   fp.max_step_time_s if fp is not None else 5.0,
                   label=f"homotopy from scene {known.name} over {', '.join(fields)}")
    res.fields = fields
    return res


def known_scene(scene: Scene, known=None) -> Scene | None:
    """The scene of a known gait to start a homotopy from: ``known`` (a Scene or a YAML path,
    ``--from``), else the scene's ``fixedpoint.from`` (relative to the scene's folder), else
    None.

    Raises
    ------
    SceneError
        The file does not load (one line).
    """
    from pathlib import Path

    from walkerlab.config import load_scene

    fp = scene.fixedpoint
    if known is None and (fp is None or fp.from_ is None):
        return None
    if isinstance(known, Scene):
        return known
    path = Path(known if known is not None else fp.from_)
    if known is None and not path.is_absolute() and scene.origin is not None:
        path = scene.origin.parent / path
    return load_scene(path)


def homotopy_start(scene: Scene, known: Scene, *, plant):
    """The known scene's gait carried to this walker (a start for the root finder) and a
    note on the way it went; ``plant``: the scene's :class:`~walkerlab.walker.plant.Plant`,
    handed down by the front.

    Returns
    -------
    x : ndarray (2n,)
    note : str

    Raises
    ------
    ValueError
        The walkers differ in structure, the known scene has no gait, or the known gait does
        not reach this walker along the straight line (the special point where it ends
        named) - one line.
    """
    try:
        res = homotopy_gait(known, scene, plant=plant)
    except (ValueError, MapFailed) as exc:
        raise ValueError(f"fixedpoint.from {known.name}: {exc}") from None
    if not res.reached:
        # the furthest the branch got towards this walker (lambda = 1), and where it ended:
        # past a fold it turns back, so its last point may be lambda = 0 again
        far, last = max(p.p for p in res.branch.points), res.branch.points[-1].p
        why = "; ".join(f"{s.kind} at lambda {s.p:.4g}" + (f" ({s.cause})" if s.cause else "")
                        for s in res.specials) or "the branch left [0, 1]"
        back = (f", then turned back and ended at lambda = {last:.4g}"
                if abs(last - far) > 1e-12 else "")
        raise ValueError(f"fixedpoint.from {known.name}: the known gait does not reach this "
                         f"walker along the straight line (lambda from 0 to 1; it got as "
                         f"far as lambda = {far:.4g}{back}: {why})")
    on_way = ", ".join(f"{s.kind.replace('_', ' ')} at lambda {s.p:.4g}"
                       for s in res.specials) or "no special point"
    if not res.fields:  # nothing differs: the known gait is this walker's own
        note = (f"initial guess: the gait of scene {known.name}, whose walker and slope have "
                "this scene's numbers (nothing to carry by homotopy)")
    else:
        note = (f"initial guess carried from scene {known.name} by homotopy over "
                f"{', '.join(res.fields)} ({len(res.branch.points)} continuation points; "
                f"{on_way} on the way)")
    return res.x, note
