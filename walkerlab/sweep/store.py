"""Incremental HDF5 store of a sweep: rows appended as points finish, finalized at the end.

Layout (``stage`` attribute ``"sweep"``; every dataset has ``unit`` and ``description``)::

    /                      attrs: stage, walkerlab_version, scene_name, scene_json, input_hash,
                           created_utc, wall_time_s, sweep_stage, params_json, options_json,
                           grid_shape, n_points, complete
    /grid/<path>           values of axis i, named by the swept field (``slope.angle_deg``;
                           ``/`` -> ``_``), a netCDF coordinate variable (float64 or
                           string); attrs axis (= i), path, spec
    /points/index          (n,) int64 flat grid index, C order (first axis slowest):
                           grid position = numpy.unravel_index(index, grid_shape)
    /points/param/<path>   (n,) value of each swept field at the row
    /points/outcome        (n,) str, see walkerlab.sweep.outcomes
    /points/message, fall_leg, guess_source  (n,) str
    /points/wall_time_s    (n,) float64 [s], wall time of the point (worker side)
    /points/<column>       (n,) float64, the stage's result columns (NaN = not applicable)
    /summary/outcome_counts  (k,) int64 with attrs outcomes (after finalize)

While running, the file is ``<name>.h5.partial`` next to the final name; rows are appended
in completion order and flushed after every chunk.  :meth:`SweepStore.finalize` sorts the
rows by ``index`` and renames the file to ``<name>.h5``.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
from pathlib import Path

import h5py
import numpy as np

import walkerlab
from walkerlab.io import netcdf
from walkerlab.sweep.outcomes import OUTCOMES, STRING_COLUMNS, walker_columns
from walkerlab.sweep.params import ParamAxis, SweepError

__all__ = ["SweepStore", "partial_path", "load_sweep", "complete_sweep"]

STR = h5py.string_dtype()


def partial_path(final: Path) -> Path:
    """Name of the in-progress file of a sweep artifact."""
    final = Path(final)
    return final.with_name(final.name + ".partial")


def _param_key(path: str) -> str:
    return path.replace("/", "_")


#: unit suffixes of scene field names (units live in the names, ``slope.angle_deg``)
_UNIT_SUFFIXES = (("_kg_m2", "kg m^2"), ("_m_per_s2", "m/s^2"), ("_m_per_s", "m/s"),
                  ("_rad_per_s", "rad/s"), ("_deg", "deg"), ("_rad", "rad"), ("_kg", "kg"),
                  ("_mm", "mm"), ("_m", "m"), ("_hz", "Hz"), ("_s", "s"))


def field_unit(path: str) -> str:
    """Unit of a scene field from its name (``slope.angle_deg`` -> ``deg``; ``"-"``: none)."""
    leaf = path.rsplit(".", 1)[-1].lower()
    return next((u for suf, u in _UNIT_SUFFIXES if leaf.endswith(suf)), "-")


class SweepStore:
    """An open in-progress sweep file (use :meth:`create` or :meth:`resume`)."""

    def __init__(self, final: Path, f: h5py.File, stage: str, axes: list[ParamAxis]):
        self.final = Path(final)
        self.f = f
        self.stage = stage
        self.axes = axes

    # ------------------------------------------------------------------ open
    @classmethod
    def create(cls, final: Path, scene, stage: str, axes: list[ParamAxis], options: dict,
               input_hash: str) -> SweepStore:
        """Start a new partial file (an old one is overwritten)."""
        from walkerlab.io.artifacts import ArtifactError

        final = Path(final)
        part = partial_path(final)
        try:
            final.parent.mkdir(parents=True, exist_ok=True)
            part.unlink(missing_ok=True)  # a link in its place is removed, not followed
            f = h5py.File(part, "x")  # created exclusively (O_EXCL)
        except OSError as exc:
            reason = exc.strerror or str(exc).rpartition("error message = ")[2].strip("' )")
            raise ArtifactError(f"{part}: cannot create the sweep file ({reason})") from None
        os.chmod(part, 0o644)
        f.attrs.update({
            "stage": "sweep", "walkerlab_version": walkerlab.__version__,
            "scene_name": scene.name or "", "scene_json": scene.model_dump_json(),
            "input_hash": input_hash,
            "created_utc": _dt.datetime.now(_dt.UTC).isoformat(),
            "wall_time_s": 0.0, "sweep_stage": stage,
            "params_json": json.dumps([[a.path, list(a.values), a.spec] for a in axes]),
            "options_json": json.dumps(options, sort_keys=True, default=str),
            "grid_shape": np.array([len(a) for a in axes], dtype=np.int64),
            "n_points": int(np.prod([len(a) for a in axes])), "complete": False,
        })
        for i, a in enumerate(axes):
            data = np.asarray(a.values, float) if a.numeric else \
                np.asarray([str(v) for v in a.values], dtype=STR)
            ds = f.create_dataset(f"grid/{_param_key(a.path)}", data=data)
            ds.attrs.update(axis=i, path=a.path, spec=a.spec, unit=field_unit(a.path),
                            description=f"values of {a.path}")
        g = f.create_group("points")

        def mk(name, dtype, unit, desc):
            ds = g.create_dataset(name, shape=(0,), maxshape=(None,), dtype=dtype, chunks=(256,))
            ds.attrs.update(unit=unit, description=desc)

        mk("index", np.int64, "-", "flat grid index (C order, first axis slowest)")
        for a in axes:
            mk(f"param/{_param_key(a.path)}", np.float64 if a.numeric else STR,
               field_unit(a.path) if a.numeric else "-",
               f"value of {a.path}")
            g[f"param/{_param_key(a.path)}"].attrs["path"] = a.path
        for name, desc in STRING_COLUMNS.items():
            mk(name, STR, "-", desc)
        mk("wall_time_s", np.float64, "s", "wall time of the point on its worker")
        for name, (unit, desc) in walker_columns(stage, scene).items():
            mk(name, np.float64, unit, desc)
        f.flush()
        return cls(final, f, stage, axes)

    @classmethod
    def resume(cls, final: Path, stage: str, axes: list[ParamAxis],
               input_hash: str) -> tuple[SweepStore, set[int]]:
        """Reopen a partial file; returns the store and the indices already done.

        Raises
        ------
        SweepError
            Unreadable partial file, or one written for another sweep (other scene,
            parameters, stage, options or code).
        """
        from walkerlab.io.runpaths import refuse_link

        part = refuse_link(partial_path(final))  # never written through a link
        try:
            f = h5py.File(part, "a")
        except OSError:
            raise SweepError(f"{part}: damaged partial sweep file; rerun without --resume") \
                from None
        if f.attrs.get("input_hash") != input_hash:
            f.close()
            raise SweepError(f"{part}: partial file of a different sweep (scene, parameters, "
                             "stage, options or code changed); rerun without --resume")
        done = set(int(i) for i in f["points/index"][()])
        return cls(final, f, stage, axes), done

    # ------------------------------------------------------------------ write
    def append(self, rows: list[dict], values_of: dict[int, tuple]) -> None:
        """Append rows (dicts from :func:`walkerlab.sweep.points.evaluate`) and flush."""
        if not rows:
            return
        g = self.f["points"]
        n0 = g["index"].shape[0]
        n1 = n0 + len(rows)

        def put(name, vals):
            ds = g[name]
            ds.resize((n1,))
            ds[n0:n1] = vals

        put("index", np.array([r["index"] for r in rows], np.int64))
        for k, a in enumerate(self.axes):
            vals = [values_of[r["index"]][k] for r in rows]
            put(f"param/{_param_key(a.path)}", np.asarray(vals, float) if a.numeric
                else np.asarray([str(v) for v in vals], dtype=object))
        for name in STRING_COLUMNS:
            put(name, np.asarray([str(r.get(name, "")) for r in rows], dtype=object))
        put("wall_time_s", np.array([r["wall_time_s"] for r in rows], float))
        fixed = {"index", "wall_time_s", *STRING_COLUMNS}
        for name, ds in g.items():  # the stage's float columns, as created for this walker
            if isinstance(ds, h5py.Dataset) and name not in fixed:
                put(name, np.array([r.get(name, np.nan) for r in rows], float))
        self.f.flush()

    def add_wall_time(self, seconds: float) -> None:
        """Add elapsed sweep wall time [s] (accumulates over resumed sessions)."""
        self.f.attrs["wall_time_s"] = float(self.f.attrs["wall_time_s"]) + float(seconds)
        self.f.flush()

    def close(self) -> None:
        """Close without finalizing (the partial file stays for ``resume``)."""
        if self.f.id.valid:
            self.f.close()

    def finalize(self, n_expected: int | None = None) -> Path:
        """Sort rows by index, write the outcome summary, rename to the final name.

        Raises
        ------
        SweepError
            Fewer distinct rows than ``n_expected`` grid points (the partial file is kept
            for ``--resume``; a half-done sweep is never reported as done).
        """
        f = self.f
        g = f["points"]
        if n_expected is not None:
            n_rows = np.unique(g["index"][()]).size
            if n_rows != n_expected:
                f.close()
                raise SweepError(f"{partial_path(self.final)}: only {n_rows} of {n_expected} "
                                 "grid points have a row; rerun with --resume")
        order = np.argsort(g["index"][()], kind="stable")

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                obj[...] = obj[()][order]

        g.visititems(visit)
        outc = [o.decode() if isinstance(o, bytes) else str(o) for o in g["outcome"][()]]
        counts = np.array([outc.count(o) for o in OUTCOMES], np.int64)
        if "summary" in f:
            del f["summary"]
        netcdf.coordinate(f.create_group("summary"), "outcome_kind", list(OUTCOMES), "-",
                          "outcome of a point (walkerlab.sweep.outcomes)")
        ds = f.create_dataset("summary/outcome_counts", data=counts)
        ds.attrs.update(outcomes=list(OUTCOMES), unit="-", description="points per outcome")
        netcdf.attach(ds, ("outcome_kind",))
        f.attrs["complete"] = True
        netcdf.finish_sweep(f)
        f.close()
        os.replace(partial_path(self.final), self.final)
        return self.final


def complete_sweep(path: Path, input_hash: str) -> bool:
    """True if ``path`` is a finished sweep of this input hash with a row per grid point."""
    try:
        with h5py.File(path, "r") as f:
            return (f.attrs.get("walkerlab_version") == walkerlab.__version__
                    and f.attrs.get("input_hash") == input_hash
                    and bool(f.attrs.get("complete", False))
                    and np.unique(f["points/index"][()]).size == int(f.attrs["n_points"]))
    except (OSError, KeyError):
        return False


def load_sweep(path: Path) -> dict:
    """Read a sweep artifact (complete or partial) into plain numpy arrays.

    Returns
    -------
    dict
        ``attrs`` (dict of root attributes, ``params`` parsed), ``axes`` (list of
        ``(path, values ndarray)``), ``grid_shape`` (tuple), and ``points``: column name ->
        (n,) array (strings as ``str`` object arrays; params under ``param/<path>``).
    """
    from walkerlab.io.artifacts import ArtifactError

    path = Path(path)
    try:
        f = h5py.File(path, "r")
    except OSError:
        raise ArtifactError(f"{path}: not a readable sweep artifact") from None
    with f:
        if f.attrs.get("stage") != "sweep":
            raise ArtifactError(f"{path}: expected a 'sweep' artifact, found "
                                f"'{f.attrs.get('stage')}'")
        attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
        attrs["params"] = json.loads(attrs["params_json"])
        axes = []
        by_axis = {int(ds.attrs.get("axis", -1)): ds for ds in f["grid"].values()
                   if isinstance(ds, h5py.Dataset)}
        for i, (p, _values, _spec) in enumerate(attrs["params"]):
            ds = by_axis.get(i) or f["grid"].get(_param_key(p)) or f[f"grid/axis_{i}"]
            v = ds[()]
            if v.dtype.kind == "O":
                v = np.array([x.decode() if isinstance(x, bytes) else x for x in v], object)
            axes.append((str(ds.attrs["path"]), v))
        pts = {}

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and not obj.is_scale:  # not the 'point' dimension
                v = obj[()]
                if v.dtype.kind == "O":
                    v = np.array([x.decode() if isinstance(x, bytes) else x for x in v], object)
                key = name
                if name.startswith("param/"):
                    key = "param/" + str(obj.attrs.get("path", name[6:]))
                pts[key] = v

        f["points"].visititems(visit)
        return {"attrs": attrs, "axes": axes, "grid_shape": tuple(int(n) for n in
                                                                   attrs["grid_shape"]),
                "points": pts}
