"""netCDF-4 conventions on top of h5py, so other tools open walkerlab's artifacts.

A netCDF-4 file is an HDF5 file in which every array is attached to named *dimension scales*
and carries ``units`` and ``long_name`` attributes.  Following them makes
``xarray.open_dataset(path, engine="h5netcdf", group="samples/coordinates")`` return named
dimensions (``time``, ``state``, ``slope``, ``point`` ...) and units, while h5py stays the
writer and walkerlab's own ``unit``/``description`` attributes stay as they are.

- :func:`coordinate` writes a coordinate variable (a dataset that is its own dimension
  scale, e.g. ``samples/time``);
- :func:`attach` attaches named dimensions to a dataset, looking for the scale in the
  dataset's group and its ancestors (netCDF scoping).  A coordinate variable found in an
  ancestor is copied into the dataset's own group, so that every group opened on its own
  (``group="samples/coordinates"``) shows its coordinates (xarray reads one group's
  variables only); a dimension without a coordinate variable is created when there is no
  scale of the right length;
- :func:`finish` runs once before a file is closed: it adds ``units``/``long_name`` where
  missing and attaches a fallback dimension ``<name>_dim<i>`` to any axis still without one,
  so no reader ever sees an anonymous ("phony") dimension.

Nested groups open with ``group="a/b"``; dimensions defined in a parent group are visible in
its children, as in netCDF.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import h5py
import numpy as np

# netCDF-C's marker for a dimension that has no coordinate variable.
_NOVAR = "This is a netCDF dimension but not a netCDF variable."


def cf_units(unit: str) -> str:
    """netCDF/UDUNITS spelling of a walkerlab unit string (``"-"`` or ``""`` -> ``"1"``)."""
    return "1" if unit in ("", "-") else unit


@lru_cache(maxsize=1)
def _text_types() -> tuple:
    """The numpy dtype and the HDF5 types (file, memory) and scalar dataspace of a text
    attribute, as h5py's ``attrs[name] = "..."`` makes them (a variable-length UTF-8
    string)."""
    dt = h5py.string_dtype()
    return (dt, h5py.h5t.py_create(dt, logical=True), h5py.h5t.py_create(dt),
            h5py.h5s.create_simple(()))


def set_attrs(obj, attrs: dict) -> None:
    """``obj.attrs[k] = v`` for each item in order: the same attributes, a new text one
    (``str``, most of an artifact's: units, descriptions) written through h5py's low-level
    interface with the types h5py's ``attrs[k] = v`` gives it, at about half the cost."""
    oid = obj.id
    for k, v in attrs.items():
        key = k.encode()
        if type(v) is not str or h5py.h5a.exists(oid, key):
            obj.attrs[k] = v
            continue
        dt, ftype, mtype, space = _text_types()
        attr = h5py.h5a.create(oid, key, ftype, space)
        try:
            attr.write(np.asarray(v, dtype=dt), mtype=mtype)
        except BaseException:
            attr.close()
            h5py.h5a.delete(oid, key)
            raise
        attr.close()


def coordinate(group: h5py.Group, name: str, values, unit: str, long_name: str) -> h5py.Dataset:
    """Write a coordinate variable ``name`` that is the dimension scale ``name``.

    Parameters
    ----------
    values : array_like, shape (k,)
        Numbers or strings (stored as UTF-8 variable-length strings).
    unit : str
        walkerlab unit (stored as ``unit`` and, netCDF spelling, ``units``).
    """
    values = np.asarray(values)
    if values.dtype.kind in "UO":
        values = np.asarray([v.decode() if isinstance(v, bytes) else str(v) for v in values],
                            dtype=h5py.string_dtype())
    ds = group.create_dataset(name, data=values)
    ds.make_scale(name)
    set_attrs(ds, {"unit": unit, "units": cf_units(unit), "description": long_name,
                   "long_name": long_name})
    return ds


def _find_scale(group: h5py.Group, name: str, size: int) -> h5py.Dataset | None:
    """The scale ``name`` of length ``size`` in ``group`` or the nearest ancestor holding
    one, else None (the ancestors looked up by path from the file: h5py's ``parent`` opens
    a file object and a group for each step)."""
    root = group.file
    path = group.name
    while True:
        obj = root.get(f"{path.rstrip('/')}/{name}")
        if isinstance(obj, h5py.Dataset) and obj.is_scale and obj.shape[:1] == (size,):
            return obj
        if path == "/":
            return None
        path = path.rsplit("/", 1)[0] or "/"


def _is_coordinate_variable(ds: h5py.Dataset) -> bool:
    name = ds.attrs.get("NAME", b"")
    name = name.decode() if isinstance(name, bytes) else str(name)
    return ds.is_scale and _NOVAR not in name


def attach(ds: h5py.Dataset, dims: Sequence[str | None]) -> None:
    """Attach dimension ``dims[i]`` to axis ``i`` of ``ds`` (None: leave the axis alone).

    A scale of that name and length in the dataset's group is used; one in an ancestor group
    is copied into the dataset's group when it is a coordinate variable (values, units and
    long name; the group then opens with its coordinates in xarray) and used as it is when
    it is a bare dimension; otherwise a dimension without a coordinate variable is created
    in the dataset's group.

    Raises
    ------
    ValueError
        ``dims`` has the wrong length, or the name is taken by a dataset of another length
        in the dataset's own group.
    """
    if len(dims) != ds.ndim:
        raise ValueError(f"{ds.name}: {len(dims)} dimension names for a {ds.ndim}-D dataset")
    parent = None  # the dataset's group, opened once (h5py's ``parent`` opens it anew)
    for i, name in enumerate(dims):
        if name is None:
            continue
        if parent is None:
            parent = ds.parent
        n = ds.shape[i]
        sc = _find_scale(parent, name, n)
        if (sc is not None and sc.name.rsplit("/", 1)[0] != parent.name.rstrip("/")
                and name not in parent and _is_coordinate_variable(sc)):
            sc = coordinate(parent, name, sc[()], str(sc.attrs.get("unit", "-")),
                            str(sc.attrs.get("long_name", name)))
        if sc is None:
            if name in parent:
                raise ValueError(f"{ds.name}: dimension '{name}' exists with another length")
            maxshape = (None,) if ds.maxshape[i] is None else (n,)
            sc = parent.create_dataset(name, shape=(n,), maxshape=maxshape, dtype="f4",
                                       chunks=(max(1, min(n, 256)),) if maxshape[0] is None
                                       else None)
            sc.make_scale(f"{_NOVAR}{n:10d}")
        ds.dims[i].attach_scale(sc)


def finish(f: h5py.File) -> None:
    """Add ``units``/``long_name`` where missing and name every still anonymous axis."""
    todo: list[h5py.Dataset] = []

    def visit(_name, obj):
        if isinstance(obj, h5py.Dataset):
            todo.append(obj)

    f.visititems(visit)
    for ds in todo:
        if ds.is_scale and str(ds.attrs.get("NAME", b"")).find(_NOVAR) >= 0:
            continue
        if "units" not in ds.attrs and "unit" in ds.attrs:
            ds.attrs["units"] = cf_units(str(ds.attrs["unit"]))
        if "long_name" not in ds.attrs:
            ds.attrs["long_name"] = str(ds.attrs.get("description", "")) or ds.name.rsplit(
                "/", 1)[-1]
        if ds.is_scale or ds.ndim == 0:
            continue
        base = ds.name.rsplit("/", 1)[-1]
        missing = [None if len(ds.dims[i]) else f"{base}_dim{i}" for i in range(ds.ndim)]
        if any(missing):
            attach(ds, missing)


def finish_sweep(f: h5py.File) -> None:
    """netCDF dimensions of a finalized sweep file: ``point`` (rows) and the grid axes.

    Every dataset under ``points/`` is one value per row, so it gets dimension ``point``, a
    coordinate variable holding the flat grid index of each row; each ``grid/<path>`` (named
    by the swept field, e.g. ``slope.angle_deg``) becomes its own coordinate variable.
    """
    g = f["points"]
    if "point" not in g:
        coordinate(g, "point", g["index"][()], "-",
                   "flat grid index of the row (C order, first axis slowest)")
    rows: list[h5py.Dataset] = []
    g.visititems(lambda _n, o: rows.append(o) if isinstance(o, h5py.Dataset)
                 and not o.is_scale and o.ndim == 1 else None)
    for ds in rows:
        if not len(ds.dims[0]):
            ds.dims[0].attach_scale(g["point"])
    # the swept values as coordinates of the rows (CF ``coordinates``): opened alone, the
    # ``points`` group shows each row's slope.angle_deg beside its results
    swept = []
    for ds in (g["param"].values() if "param" in g else ()):
        path = str(ds.attrs.get("path", ds.name.rsplit("/", 1)[-1]))
        if isinstance(ds, h5py.Dataset) and path not in g:
            aux = g.create_dataset(path, data=ds[()])
            aux.attrs.update({k: v for k, v in ds.attrs.items() if k != "DIMENSION_LIST"})
            aux.attrs["swept"] = 1
            aux.dims[0].attach_scale(g["point"])
        swept.append(path)
    for ds in g.values():
        if swept and isinstance(ds, h5py.Dataset) and not ds.is_scale \
                and "swept" not in ds.attrs:
            ds.attrs["coordinates"] = " ".join(swept)
    if "grid" in f:
        for name, ds in f["grid"].items():
            if isinstance(ds, h5py.Dataset) and not ds.is_scale:
                ds.make_scale(name)
    finish(f)
