"""``bifurcation.h5`` / ``bifurcation_<field>.h5``: what the report reads of a bifurcation
diagram (:func:`load_bifurcation_summary`), its writer (:func:`bifurcation_writer`, filled
from a :class:`walkerlab.studies.bifurcation.BifurcationResult`) and its full reader
(:func:`load_bifurcation`).

Layout read here: root attribute ``parameter_path`` (the scene field of the grid; the slope
[deg] when absent); the grid coordinate (``slope``, or the field's dotted path) with its
``unit``; ``onset/onset_slope`` or ``onset/onset_value`` (period-doubling onset, in the
grid's unit); ``steady_state/attractor_period`` and ``steady_state/outcome`` per grid value.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from walkerlab.io.artifacts import artifact_loader, put, read_named
from walkerlab.io.netcdf import coordinate

STAGE = "bifurcation"
#: the grid of ``bifurcation --slopes``: its coordinate is named ``slope`` (any other
#: field's grid is named by the field's dotted path; as
#: :func:`parameter_dim` writes it)
SLOPE_PATH = "slope.angle_deg"


def parameter_dim(path: str) -> str:
    """Name of the artifact's parameter coordinate: ``slope`` for :data:`SLOPE_PATH` (the
    artifact of ``--slopes``, unchanged), else the field's dotted path."""
    return "slope" if path == SLOPE_PATH else path


def onset_name(path: str) -> str:
    """Dataset of the period-doubling onset: ``onset/onset_slope`` for the slope,
    ``onset/onset_value`` for any other field."""
    return "onset/onset_slope" if path == SLOPE_PATH else "onset/onset_value"


@dataclass
class BifurcationSummary:
    """A loaded bifurcation diagram, as far as the report uses it.

    Attributes
    ----------
    path : Path
    data : dict
        ``parameter_path``, ``parameter_unit``, the grid (ndarray (n,), under its coordinate
        name), ``onset/onset_slope`` or ``onset/onset_value`` where stored, and
        ``steady_state/outcome`` (list of str, or None in an artifact without it): the
        input of :func:`walkerlab.studies.bifurcation.onset_value` and ``fall_onset``.
    values : ndarray (n,)
        The grid, in ``data["parameter_unit"]``.
    attractor_period : ndarray (n,)
        Period of the steady state at each grid value (0: none).
    """

    path: Path
    data: dict
    values: np.ndarray
    attractor_period: np.ndarray


@artifact_loader(STAGE)
def load_bifurcation_summary(f, path: Path) -> BifurcationSummary:
    """Load what the report shows of a bifurcation artifact."""
    ppath = f.attrs.get("parameter_path", SLOPE_PATH)
    ppath = ppath.decode() if isinstance(ppath, bytes) else str(ppath)
    dim = "slope" if ppath == SLOPE_PATH else ppath
    values = f[dim][()]
    data = {"parameter_path": ppath, "parameter_unit": str(f[dim].attrs.get("unit", "deg")),
            dim: values, "steps_per_map": int(f.attrs.get("steps_per_map", 0))}
    for name in ("onset/onset_slope", "onset/onset_value"):
        if name in f:
            data[name] = f[name][()]
    data["steady_state/outcome"] = (list(f["steady_state/outcome"].asstr()[()])
                                    if "steady_state/outcome" in f else None)
    return BifurcationSummary(Path(path), data, values,
                              f["steady_state/attractor_period"][()])


def bifurcation_writer(res):  # res: walkerlab.studies.bifurcation.BifurcationResult
    """``writer(h5file)`` filling a ``bifurcation`` artifact (netCDF dimensions: the
    parameter (:func:`parameter_dim`: ``slope`` or the field's dotted path; attributes
    ``unit``, ``path``), ``multiplier``, ``heel_strike``; units on every dataset; the onset
    in ``onset/onset_slope`` for the slope, ``onset/onset_value`` otherwise)."""
    path, unit = res.param, res.unit
    dim = parameter_dim(path)
    what = "slope" if path == SLOPE_PATH else "grid value"

    def writer(f):
        c = coordinate(f, dim, res.values, unit,
                       "slope grid" if path == SLOPE_PATH else f"grid of {path}")
        c.attrs["path"] = path
        f.attrs["parameter_path"] = path
        f.attrs["parameter_dim"] = dim
        coordinate(f, "multiplier", np.arange(res.multipliers.shape[1]), "-",
                   "Floquet multiplier number (sorted by modulus)")
        coordinate(f, "heel_strike", np.arange(res.n_keep), "-",
                   f"kept heel strike (last {res.n_keep} of {res.n_transient})")
        f.attrs["state_names"] = list(res.state_names)
        s = (dim,)
        for k, (n, u) in enumerate(zip(res.state_names, res.state_units)):
            put(f, f"fixed_point/{n}", res.fixed_point[:, k], u,
                f"period-1 fixed point, {n} just after heel strike", dims=s)
        put(f, "fixed_point/interleg_angle", res.fixed_point_interleg_deg, "deg",
            "inter-leg angle of the period-1 fixed point", dims=s)
        put(f, "fixed_point/step_period", res.step_period_s, "s", "period-1 step period", dims=s)
        put(f, "fixed_point/outcome", [str(o) for o in res.fp_outcome], "-",
            "typed outcome of the fixed-point search", dims=s)
        sm = (dim, "multiplier")
        put(f, "floquet/real", res.multipliers.real, "-", "Floquet multipliers, real part",
            dims=sm)
        put(f, "floquet/imag", res.multipliers.imag, "-", "Floquet multipliers, imaginary part",
            dims=sm)
        sh = (dim, "heel_strike")
        put(f, "steady_state/interleg_angle", res.interleg_deg, "deg",
            f"inter-leg angle at the last {res.n_keep} of {res.n_transient} heel strikes",
            dims=sh)
        put(f, "steady_state/stance_angle_after_impact", res.stance_after_deg, "deg",
            "stance-leg angle just after those impacts", dims=sh)
        put(f, "steady_state/outcome", [str(o) for o in res.ss_outcome], "-",
            "'walks' or how the steady-state run ended", dims=s)
        put(f, "steady_state/attractor_period", res.attractor_period, "steps",
            "distinct kept values (1, 2, 4, ...; n_keep: no period found)", dims=s)
        onset = res.onset  # the slope's onset dict may carry only its *_deg names
        put(f, onset_name(path), onset.get("onset", onset.get("onset_deg")), unit,
            "period-doubling onset: a multiplier crosses -1 (brentq)")
        put(f, "onset/bracket", onset.get("bracket", onset.get("bracket_deg")), unit,
            "grid bracket of the onset", dims=("bracket_end",))
        put(f, "onset/multiplier_at_onset", res.onset["multiplier_at_onset"], "-",
            "most negative real multiplier at the located onset")
        put(f, "stats/wall_time", res.wall_time_s, "s", f"wall time per {what}", dims=s)
        f.attrs["n_transient"] = res.n_transient
        f.attrs["n_keep"] = res.n_keep
        # the one map every value's multipliers are of (1: a step, 2: a stride)
        f.attrs["steps_per_map"] = int(getattr(res, "steps_per_map", 1))

    return writer


@artifact_loader("bifurcation")
def load_bifurcation(f, path: Path) -> dict:
    """Arrays of a ``bifurcation`` artifact as a dict (names as in the file), with
    ``parameter_path``, ``parameter_dim`` and ``parameter_unit`` (the grid's field, its
    coordinate's name and unit; the slope in an artifact without them)."""
    out = {}
    ppath = f.attrs.get("parameter_path", SLOPE_PATH)
    ppath = ppath.decode() if isinstance(ppath, bytes) else str(ppath)
    dim = parameter_dim(ppath)
    unit = f[dim].attrs.get("unit", "deg")
    out.update(parameter_path=ppath, parameter_dim=dim,
               parameter_unit=unit.decode() if isinstance(unit, bytes) else str(unit),
               steps_per_map=int(f.attrs.get("steps_per_map", 0)))  # 0: not recorded

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            out[name] = read_named(f, name)

    f.visititems(visit)
    return out
