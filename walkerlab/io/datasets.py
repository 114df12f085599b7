"""Every stage artifact as one ``xarray.Dataset``, read through its netCDF-4 view.

:func:`load_dataset` is the one reader behind :mod:`walkerlab.api`: it opens each group of
an artifact with ``xarray.open_dataset(path, engine="h5netcdf", group=...)`` - the view any
netCDF tool gets (named dimensions, coordinate variables, ``units``/``long_name``) - and
merges the groups into one dataset, so nothing is read in a way other tools could not.

Names
-----
A variable's name is its path in the artifact with ``/`` -> ``_``, shortened for the
trajectory layout (:mod:`walkerlab.io.trajectory`): ``samples/coordinates/leg1_angle`` ->
``leg1_angle``, ``samples/points/hip/x`` -> ``hip_x``, ``samples/energy/total`` ->
``energy_total``, ``errors/coordinates/leg1_angle`` -> ``error_leg1_angle``.  Dimensions shared
across groups keep their names (``time``, ``step``, ``state``, ``multiplier``, ``x``, ``y``,
...); a dimension of one group only is prefixed like its variables
(``feet/leg1`` ``touchdown`` -> ``feet_leg1_touchdown``).  Root attributes (stage, scene,
input hash, version, run time) become the dataset's attributes; a group's attributes are
kept with the group prefix.

Stage-specific views
--------------------
- ``fixedpoint``: ``fixed_point`` and ``initial_guess`` on ``state`` (per-state units in the
  ``state_unit`` coordinate), complex ``multipliers`` on ``multiplier``, ``jacobian`` on
  ``(state, state_in)``; the equation variants of a compared compass gait stay as
  ``variants_<variant>_...`` variables (:func:`load_fixed_points` stacks them on ``gait``);
- ``sweep``: the rows reshaped onto the grid, one dimension per swept field named by its
  path (``slope.angle_deg``), when every grid point has its row; else on ``point``.

Raises ``ArtifactError`` (missing or not an artifact) and ``ImportError`` with the install
hint when xarray/h5netcdf are missing (``pip install -e '.[api]'``).
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from walkerlab.extras import require
from walkerlab.io.artifacts import READ_ERRORS, ArtifactError
from walkerlab.io.stage_files import CONTACT_SIM

__all__ = ["load_dataset", "load_fixed_points", "xarray"]

#: dimensions that mean the same thing in every group of an artifact
SHARED_DIMS = frozenset({"time", "step", "state", "state_in", "contact_state", "rate",
                         "multiplier", "x", "y", "point", "outcome_kind", "stiffness",
                         "heel_strike"})
#: group-path prefixes shortened in variable names (first match wins)
_SHORT = (("samples/coordinates/", ""), ("samples/points/", ""), ("samples/", ""),
          ("errors/coordinates/", "error_"), ("grid/", ""))


def xarray():
    """Import xarray (and check h5netcdf), or raise ImportError with the install hint.

    Raises
    ------
    walkerlab.extras.MissingExtra
        xarray or h5netcdf is not installed (an ImportError; one line naming the missing one
        and the ``api`` extra).
    """
    require("h5netcdf", "api", "walkerlab's Python API")
    return require("xarray", "api", "walkerlab's Python API")


def _prefix(group: str) -> str:
    g = group.strip("/") + "/" if group.strip("/") else ""
    for long, short in _SHORT:
        if g.startswith(long):
            rest = g[len(long):]
            return short + rest.replace("/", "_")
    return g.replace("/", "_")


def _groups(path: Path) -> list[str]:
    """Every group holding at least one dataset, root first (``steps/states/*``: no data)."""
    out: list[str] = []

    def visit(name, obj):
        if isinstance(obj, h5py.Group) and any(isinstance(v, h5py.Dataset)
                                               for v in obj.values()):
            out.append(name)

    with h5py.File(path, "r") as f:
        if any(isinstance(v, h5py.Dataset) for v in f.values()):
            out.append("/")
        f.visititems(visit)
    return out


def _open(nc, group: str):
    """``xarray.open_dataset(path, engine="h5netcdf", group=group)``, on the already open
    h5netcdf file ``nc`` (one open per artifact instead of one per group)."""
    xr = xarray()
    store = xr.backends.H5NetCDFStore(nc if group == "/" else nc[group])
    return xr.open_dataset(store, decode_times=False, decode_timedelta=False).load()


def _group_view(nc, group: str):
    """One group's netCDF view with walkerlab's flat names."""
    ds = _open(nc, group)
    pre = _prefix(group)
    dims = {d: f"{pre}{d}" for d in ds.dims if d not in SHARED_DIMS and pre}
    names = {v: f"{pre}{v}" for v in ds.variables if v not in ds.dims and pre}
    ds = ds.rename({**names, **dims})
    ds.attrs = {f"{pre}{k}": v for k, v in ds.attrs.items()} if pre else ds.attrs
    return ds


def _segment_states(path: Path):
    """``steps/states/<i>`` (start/end state of every trajectory segment, as attributes)
    as ``segment_start_state`` / ``segment_end_state`` on ``(segment, state)``."""
    xr = xarray()
    with h5py.File(path, "r") as f:
        if "steps/states" not in f or "state" not in f:
            return None
        names = [s.decode() if isinstance(s, bytes) else str(s) for s in f["state"][()]]
        segs = sorted(f["steps/states"])
        a = {k: np.array([[float(f[f"steps/states/{s}"].attrs[f"{k}_{n}"]) for n in names]
                          for s in segs]) for k in ("start", "end")}
    return xr.Dataset({f"segment_{k}_state": (("segment", "state"), v,
                                              {"units": "rad, rad/s",
                                               "long_name": f"state at the {k} of a "
                                               "trajectory segment"})
                       for k, v in a.items()},
                      coords={"segment": np.arange(len(segs))})


def _stage(path: Path) -> str:
    try:
        with h5py.File(path, "r") as f:
            stage = f.attrs.get("stage")
    except READ_ERRORS:  # absent, not HDF5, or damaged inside
        raise ArtifactError(f"{path}: missing or not an HDF5 artifact") from None
    if stage is None:
        raise ArtifactError(f"{path}: not a walkerlab artifact (no 'stage' attribute)")
    return stage.decode() if isinstance(stage, bytes) else str(stage)


def _merge(parts, attrs: dict):
    xr = xarray()
    try:
        ds = xr.merge(parts, join="exact", compat="no_conflicts", combine_attrs="override")
    except ValueError as exc:
        raise ArtifactError(f"artifact groups do not line up: {exc}") from None
    ds.attrs = attrs
    return ds


def _complex(ds, prefix: str, name: str, dim_like: str):
    re_, im = f"{prefix}real", f"{prefix}imag"
    if re_ in ds and im in ds:
        z = ds[re_] + 1j * ds[im]
        z.attrs = {"units": "1", "long_name": ds[re_].attrs.get("long_name", name)
                   .replace(", real part", "")}
        ds = ds.drop_vars([re_, im]).assign({name: z})
    return ds


def _fixedpoint_view(ds):
    """Per-state scalars on ``state``; complex multipliers."""
    xr = xarray()
    states = [str(s) for s in ds["state"].values]
    pres = [""] + sorted({v.split("fixed_point_")[0] for v in ds.data_vars
                          if v.startswith("variants_") and "_fixed_point_" in v})
    for pre in pres:
        for what in ("fixed_point", "initial_guess"):
            keys = [f"{pre}{what}_{n}" for n in states]
            if not all(k in ds for k in keys):
                continue
            units = [str(ds[k].attrs.get("units", "")) for k in keys]
            da = xr.DataArray([float(ds[k]) for k in keys], dims=("state",),
                              attrs={"units": ", ".join(dict.fromkeys(units)),
                                     "long_name": "state just after heel strike"
                                     if what == "fixed_point" else "root-finder starting point"})
            ds = ds.drop_vars(keys).assign({f"{pre}{what}": da})
            if not pre:
                ds = ds.assign_coords(state_unit=("state", units))
        for kind, name in (("variational", "multipliers"), ("finite_difference",
                                                            "multipliers_fd")):
            ds = _complex(ds, f"{pre}floquet_{kind}_", f"{pre}{name}", "multiplier")
        for kind, name in (("variational", "jacobian"), ("finite_difference", "jacobian_fd")):
            if f"{pre}floquet_{kind}_jacobian" in ds:
                ds = ds.rename({f"{pre}floquet_{kind}_jacobian": f"{pre}{name}"})
    return ds


def _sweep_view(ds):
    """Rows on the grid (one dimension per swept field) when every grid point has a row."""
    xr = xarray()
    import json

    params = json.loads(str(ds.attrs["params_json"]))
    shape = tuple(int(n) for n in np.atleast_1d(ds.attrs["grid_shape"]))
    axes = [p[0] for p in params]
    if "points_index" not in ds or ds.sizes.get("point") != int(np.prod(shape)) or not \
            np.array_equal(ds["points_index"].values, np.arange(int(np.prod(shape)))):
        return ds  # partial or resumed-out-of-order: rows on 'point'
    out = {}
    for name, v in ds.data_vars.items():
        if v.dims == ("point",):
            key = name.removeprefix("points_")
            if key.startswith("param_"):
                continue  # the grid coordinates themselves
            out[key] = (axes, v.values.reshape(shape), v.attrs)
        elif "point" not in v.dims:
            out[name] = v
    coords = {a: ds[a] for a in axes if a in ds}
    res = xr.Dataset(out, coords=coords, attrs=ds.attrs)
    return res


def load_dataset(path: str | Path):
    """Read a stage artifact into one ``xarray.Dataset`` (see the module docstring).

    Parameters
    ----------
    path : str or Path
        ``fixedpoint.h5``, ``simulate.h5``, ``contact_sim.h5``, ``compare.h5``,
        ``basin.h5``, a sweep, ... (any artifact written by a walkerlab stage).

    Returns
    -------
    xarray.Dataset
        Named dimensions with coordinate variables; every variable keeps ``units``,
        ``long_name`` (and walkerlab's ``unit``/``description``); root attributes include
        ``stage``, ``scene_name``, ``scene_json``, ``input_hash``, ``walkerlab_version``.

    Raises
    ------
    ArtifactError
        Missing file, not a walkerlab artifact, or groups whose dimensions disagree.
    ImportError
        xarray or h5netcdf not installed (``pip install -e '.[api]'``).
    """
    path = Path(path)
    stage = _stage(path)
    with h5py.File(path, "r") as f:
        attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
    xarray()  # both installed, or one line naming the extra
    import h5netcdf

    with h5netcdf.File(path, "r") as nc:
        parts = [_group_view(nc, g) for g in _groups(path)]
    seg = _segment_states(path) if stage == "simulate" else None
    if seg is not None:
        parts.append(seg)
    group_attrs = {}
    for p in parts:
        group_attrs.update(p.attrs)
    ds = _merge(parts, {**group_attrs, **attrs})
    if stage == "fixedpoint":
        ds = _fixedpoint_view(ds)
    elif stage == "sweep":
        ds = _sweep_view(ds)
    elif stage == CONTACT_SIM.name:
        ds = _complex(ds, "periodic_gait_multipliers_", "periodic_gait_multipliers",
                      "multiplier")
    return ds


def load_fixed_points(path: str | Path):
    """Every period-1 gait stored in ``fixedpoint.h5``, stacked on a ``gait`` dimension.

    The scene's own gait comes first (``gait`` = its equation variant); the other equation
    variants a compared compass gait is solved with follow.  Variables: ``fixed_point``
    (gait, state), ``multipliers`` (gait, multiplier, complex), ``step_period`` (gait) [s],
    ``residual``, ``stable``; a variant whose root finder failed is left out.

    Raises
    ------
    ArtifactError, ImportError
        As :func:`load_dataset`.
    """
    xr = xarray()
    ds = load_dataset(path)
    own = str(ds.attrs.get("variant", "own"))
    keep = ("fixed_point", "multipliers", "step_period", "residual", "floquet_stable")
    rows, labels = [], []
    for pre, label in [("", own)] + [
            (f"variants_{v}_", v) for v in sorted({n.split("_fixed_point")[0][9:]
                                                    for n in ds.data_vars
                                                    if n.startswith("variants_")
                                                    and n.endswith("_fixed_point")})
            if v != own]:
        if f"{pre}fixed_point" not in ds:
            continue
        rows.append(xr.Dataset({k if k != "floquet_stable" else "stable": ds[f"{pre}{k}"]
                                for k in keep if f"{pre}{k}" in ds}))
        labels.append(label)
    out = xr.concat(rows, dim="gait", join="exact", coords="minimal", compat="override")
    out = out.assign_coords(gait=("gait", labels))
    out.attrs = {k: v for k, v in ds.attrs.items() if not k.startswith("variants_")}
    return out
