"""Incremental HDF5 store of a sweep: rows appended as points finish, finalized at the end.

The sweep package (:mod:`walkerlab.studies.runner`) decides what a row holds
(:class:`SweepColumns`) and what a continuation is; this module only reads and writes the
file (no ``h5py`` outside :mod:`walkerlab.io`).

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
    /points/outcome        (n,) str, see walkerlab.studies.outcomes
    /points/message, fall_leg, guess_source  (n,) str
    /points/wall_time_s    (n,) float64 [s], wall time of the point (worker side)
    /points/<column>       (n,) float64, the stage's result columns (NaN = not applicable)
    /summary/outcome_counts  (k,) int64 with attrs outcomes (after finalize)

While running, the file is ``<name>.h5.partial`` next to the final name; rows are appended
in completion order and flushed after every chunk.  :meth:`SweepStore.finalize` sorts the
rows by ``index``, drops the resume bookkeeping, stores the ``content_hash`` (as every
artifact, :func:`walkerlab.io.artifacts.content_hash_of`) and renames the file to
``<name>.h5``.

Resume bookkeeping of the partial file (row and chain-checkpoint hashes, which rows a resumed
sweep keeps): :mod:`walkerlab.io.sweep_resume`.
"""

from __future__ import annotations

import datetime as _dt
import json
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

import walkerlab
from walkerlab.io import netcdf
from walkerlab.io.artifacts import READ_ERRORS
from walkerlab.io.sweep_resume import (
    STR,
    chain_check,
    datasets,
    keep_intact,
    read_rows,
    row_hashes,
    write_plan,
)
from walkerlab.units import field_unit

__all__ = ["SweepColumns", "SweepFileError", "SweepStore", "complete_sweep", "load_sweep",
           "partial_path"]


#: what a "disk full" error while the sweep runs says is left
KEPT = "the rows saved before are kept for --resume"


class SweepFileError(ValueError):
    """A partial sweep file cannot be resumed or finalized (one-line message)."""


@dataclass(frozen=True)
class SweepColumns:
    """The row layout of a sweep file, as the sweep package defines it
    (:mod:`walkerlab.studies.outcomes`).

    Attributes
    ----------
    strings : dict
        String column name -> description (``outcome``, ``message``, ...).
    floats : dict
        Float column name -> ``(unit, description)`` (the stage's result columns).
    outcomes : tuple of str
        Outcome kinds counted in ``/summary/outcome_counts``.
    """

    strings: dict
    floats: dict
    outcomes: tuple


def partial_path(final: Path) -> Path:
    """Name of the in-progress file of a sweep artifact."""
    final = Path(final)
    return final.with_name(final.name + ".partial")


def _param_key(path: str) -> str:
    return path.replace("/", "_")


def _unit(path: str) -> str:
    """Unit of a swept scene field from its name (``slope.angle_deg`` -> ``deg``; ``-``)."""
    return field_unit(path) or "-"


class SweepStore:
    """An open in-progress sweep file (use :meth:`create` or :meth:`resume`).

    ``axes`` are the sweep's axes (:class:`walkerlab.studies.params.ParamAxis`: ``path``,
    ``values``, ``spec``, ``numeric``, ``len``); ``columns`` its row layout."""

    def __init__(self, final: Path, img, axes: list, columns: SweepColumns):
        self.final = Path(final)
        self._img = img  # walkerlab.io.h5image.H5Image of the partial file
        self.f = img.f
        self.axes = axes
        self.columns = columns

    # ------------------------------------------------------------------ open
    @classmethod
    def create(cls, final: Path, scene, stage: str, axes: list, columns: SweepColumns,
               options: dict, input_hash: str,
               plan: list[list[int]] | None = None,
               steps_per_map: int | None = None) -> SweepStore:
        """Start a new partial file (an old one is overwritten).

        ``scene`` (a :class:`walkerlab.config.Scene`) is stored as JSON; ``stage`` names the
        stage each point runs; ``plan``: the chains of grid indices, in evaluation order
        (stored for resume); ``steps_per_map``: steps of the one Poincaré map every point's
        Floquet multipliers are of (1: a step, 2: a stride;
        :func:`walkerlab.studies.map_length.study_steps_per_map`), the root attribute
        ``steps_per_map`` the summary and figures label them with (none: not written).

        Raises
        ------
        walkerlab.io.artifacts.ArtifactError
            The partial file cannot be created (one line).
        """
        from walkerlab.io.artifacts import ArtifactError
        from walkerlab.io.h5image import H5Image

        final = Path(final)
        part = partial_path(final)
        try:
            final.parent.mkdir(parents=True, exist_ok=True)
            part.unlink(missing_ok=True)  # a link in its place is removed, not followed
        except OSError as exc:
            raise ArtifactError(f"{part}: cannot create the sweep file ({exc.strerror})") \
                from None
        # edited in memory, saved as one image (a full disk: one line)
        img = H5Image(part, kept=KEPT)
        f = img.f
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
        if steps_per_map is not None:
            f.attrs["steps_per_map"] = int(steps_per_map)
        for i, a in enumerate(axes):
            data = np.asarray(a.values, float) if a.numeric else \
                np.asarray([str(v) for v in a.values], dtype=STR)
            ds = f.create_dataset(f"grid/{_param_key(a.path)}", data=data)
            ds.attrs.update(axis=i, path=a.path, spec=a.spec, unit=_unit(a.path),
                            description=f"values of {a.path}")
        g = f.create_group("points")

        def mk(name, dtype, unit, desc):
            ds = g.create_dataset(name, shape=(0,), maxshape=(None,), dtype=dtype, chunks=(256,))
            ds.attrs.update(unit=unit, description=desc)

        mk("index", np.int64, "-", "flat grid index (C order, first axis slowest)")
        for a in axes:
            mk(f"param/{_param_key(a.path)}", np.float64 if a.numeric else STR,
               _unit(a.path) if a.numeric else "-",
               f"value of {a.path}")
            g[f"param/{_param_key(a.path)}"].attrs["path"] = a.path
        for name, desc in columns.strings.items():
            mk(name, STR, "-", desc)
        mk("wall_time_s", np.float64, "s", "wall time of the point on its worker")
        for name, (unit, desc) in columns.floats.items():
            mk(name, np.float64, unit, desc)
        mk("row_hash", STR, "-", "SHA-256 of the row and the input hash (resume check)")
        from walkerlab.units import for_scene, relabel_artifact

        relabel_artifact(f, for_scene(scene))  # unit labels follow the scene's system
        write_plan(f, plan if plan is not None else [], input_hash)
        store = cls(final, img, axes, columns)
        try:
            store.flush()
        except BaseException:
            img.close()
            raise
        return store

    @classmethod
    def resume(cls, final: Path, axes: list, columns: SweepColumns, input_hash: str,
               parse_guess, tell=None) -> tuple[SweepStore, list[list[int]], dict]:
        """Reopen a partial file after checking every row and chain checkpoint.

        ``parse_guess`` reads a checkpoint's continuation JSON (a chain whose continuation
        does not parse starts again); ``tell`` receives a one-line note of dropped rows.

        Returns
        -------
        store : SweepStore
        plan : list of list of int
            The chains as planned when the sweep started.
        start : dict
            Chain number -> ``(points done, continuation)`` for every chain that continues
            from its checkpoint; the other chains start again (their rows were dropped).

        Raises
        ------
        SweepFileError
            Unreadable partial file, or one written for another sweep (other scene,
            parameters, stage, options or code).
        """
        from walkerlab.io.h5image import H5Image
        from walkerlab.io.runpaths import refuse_link

        part = refuse_link(partial_path(final))  # never written through a link
        try:
            img = H5Image.load(part, kept=KEPT)
        except (OSError, RuntimeError):
            raise SweepFileError(f"{part}: damaged partial sweep file; rerun without --resume") \
                from None
        f = img.f
        if f.attrs.get("input_hash") != input_hash:
            f.close()
            raise SweepFileError(f"{part}: partial file of a different sweep (scene, parameters, "
                             "stage, options or code changed); rerun without --resume")
        try:
            dsets, cols, idx, plan = read_rows(f)
        except (KeyError, ValueError, OSError):
            f.close()
            raise SweepFileError(f"{part}: damaged partial sweep file; rerun without --resume") \
                from None
        start = keep_intact(f, dsets, cols, idx, plan, input_hash, parse_guess, part, tell)
        store = cls(final, img, axes, columns)
        store.flush()
        return store, plan, start

    def checkpoint(self, chain: int, done: int, text: str, key: str) -> None:
        """Record that the first ``done`` points of ``chain`` are written and the
        continuation after them as JSON ``text`` (call after :meth:`append` of those rows)."""
        self.f["plan/done"][chain] = done
        self.f["plan/guess"][chain] = text
        self.f["plan/check"][chain] = chain_check(chain, done, text, key)

    def flush(self) -> None:
        """Save the file (rows and checkpoints together) as one image.

        Raises
        ------
        walkerlab.io.artifacts.ArtifactError
            The disk is full ("disk full", one line; the file saved before is kept).
        """
        self._img.save()

    # ------------------------------------------------------------------ write
    def append(self, rows: list[dict], values_of: dict[int, tuple], flush: bool = True) -> None:
        """Append rows (dicts from :func:`walkerlab.studies.points.evaluate`; ``values_of``:
        grid index -> the point's axis values) and flush."""
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
        for name in self.columns.strings:
            put(name, np.asarray([str(r.get(name, "")) for r in rows], dtype=object))
        put("wall_time_s", np.array([r["wall_time_s"] for r in rows], float))
        fixed = {"index", "wall_time_s", "row_hash", *self.columns.strings}
        for name, ds in g.items():  # the stage's float columns, as created for this walker
            if isinstance(ds, h5py.Dataset) and name not in fixed:
                put(name, np.array([r.get(name, np.nan) for r in rows], float))
        if "row_hash" in g:  # hashed as read back, so resume recomputes the same bytes
            cols = {name: ds[n0:n1] for name, ds in datasets(g).items()
                    if name != "row_hash"}
            put("row_hash", np.asarray(row_hashes(cols, str(self.f.attrs["input_hash"])),
                                       dtype=object))
        if flush:
            self.flush()

    def add_wall_time(self, seconds: float) -> None:
        """Add elapsed sweep wall time [s] (accumulates over resumed sessions)."""
        self.f.attrs["wall_time_s"] = float(self.f.attrs["wall_time_s"]) + float(seconds)
        self.flush()

    @property
    def is_open(self) -> bool:
        """Whether the partial file is still open."""
        return bool(self.f.id.valid)

    def close(self) -> None:
        """Close without finalizing (the partial file, as last saved, stays for
        ``resume``)."""
        self._img.close()

    def finalize(self, n_expected: int | None = None) -> Path:
        """Sort rows by index, write the outcome summary, rename to the final name.

        Raises
        ------
        SweepFileError
            Fewer distinct rows than ``n_expected`` grid points (the partial file is kept
            for ``--resume``; a half-done sweep is never reported as done).
        """
        f = self.f
        g = f["points"]
        if n_expected is not None:
            n_rows = np.unique(g["index"][()]).size
            if n_rows != n_expected:
                f.close()
                raise SweepFileError(f"{partial_path(self.final)}: only {n_rows} of {n_expected} "
                                 "grid points have a row; rerun with --resume")
        order = np.argsort(g["index"][()], kind="stable")

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                obj[...] = obj[()][order]

        g.visititems(visit)
        outc = [o.decode() if isinstance(o, bytes) else str(o) for o in g["outcome"][()]]
        outcomes = list(self.columns.outcomes)
        counts = np.array([outc.count(o) for o in outcomes], np.int64)
        if "summary" in f:
            del f["summary"]
        netcdf.coordinate(f.create_group("summary"), "outcome_kind", outcomes, "-",
                          "outcome of a point (walkerlab.studies.outcomes)")
        ds = f.create_dataset("summary/outcome_counts", data=counts)
        ds.attrs.update(outcomes=outcomes, unit="-", description="points per outcome")
        netcdf.attach(ds, ("outcome_kind",))
        f.attrs["complete"] = True
        for name in ("plan", "points/row_hash"):  # resume bookkeeping
            if name in f:
                del f[name]
        netcdf.finish_sweep(f)
        from walkerlab.io.artifacts import content_hash_of

        f.attrs["content_hash"] = content_hash_of(f)
        img = self._img
        img.path, img.kept = self.final, "the partial file is kept for --resume"
        try:
            img.save()
        finally:
            img.close()
        partial_path(self.final).unlink(missing_ok=True)
        return self.final


def complete_sweep(path: Path, input_hash: str) -> bool:
    """True if ``path`` is a finished sweep of this input hash with a row per grid point."""
    from walkerlab.io.artifacts import content_hash_of

    try:
        with h5py.File(path, "r") as f:
            return (f.attrs.get("walkerlab_version") == walkerlab.__version__
                    and f.attrs.get("input_hash") == input_hash
                    and bool(f.attrs.get("complete", False))
                    and np.unique(f["points/index"][()]).size == int(f.attrs["n_points"])
                    and str(f.attrs.get("content_hash")) == content_hash_of(f))
    except READ_ERRORS:  # absent, truncated or damaged inside: not complete
        return False


def load_sweep(path: Path) -> dict:
    """Read a sweep artifact (complete or partial) into plain numpy arrays.

    Returns
    -------
    dict
        ``attrs`` (dict of root attributes, ``params`` parsed), ``axes`` (list of
        ``(path, values ndarray)``), ``grid_shape`` (tuple), and ``points``: column name ->
        (n,) array (strings as ``str`` object arrays; params under ``param/<path>``).  Each
        value is in the unit its column's name ends in (``_s``, ``_m``, ``_rad``, ...) or its
        parameter path names.

    Raises
    ------
    ArtifactError
        ``path`` is not a readable sweep artifact, or it is an artifact of another kind.
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
            # not the 'point' dimension, nor the swept values' copy (a coordinate of the rows)
            if isinstance(obj, h5py.Dataset) and not obj.is_scale and "swept" not in obj.attrs:
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
