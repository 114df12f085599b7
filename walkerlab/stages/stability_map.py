"""Stage ``stability-map``: where the contact model has a stable periodic gait.

One cached artifact per map kind, ``runs/<scene>/stability_map_<kind>.h5`` (input hash: the
scene's physics sections, the code and the grid), and its figure
``report/figures/stability_map_<kind>.png/.svg``, drawn from the artifact.  The computation is
:func:`walkerlab.sweep.stability.gait_map`.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from walkerlab.config import CommandOptions, Scene, validate_option
from walkerlab.io.artifacts import open_artifact, put
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached, with_defaults
from walkerlab.sweep.stability import (
    CELL_FIELDS,
    MAP_KINDS,
    MapSpec,
    default_spec,
    gait_map,
    stable_fraction,
)

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint", "contact", "terrain")
_UNITS = {"max_abs_multiplier": "-", "step_period_s": "s", "patch_margin_m": "m",
          "residual": "-", "wall_time_s": "s", "exists": "-", "stable": "-"}


def stage_name(kind: str) -> str:
    return f"stability-map-{kind.replace('_', '-')}"


def not_applicable(scene: Scene, kind: str) -> str:
    """One line saying why map ``kind`` does not apply to the scene, or "" if it does (a
    patch-width map needs the checkerboard terrain: on continuous ground there are no
    patches)."""
    terrain = scene.terrain
    if kind == "patch_width" and terrain is not None and terrain.kind != "checkerboard":
        return (f"stability-map --kind patch_width does not apply to scene '{scene.name}': "
                f"its terrain is {terrain.kind} ground, which has no patches (terrain.kind)")
    return ""


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        kind: str = "stiffness", n: int = 8, workers: int = 2, time_limit_s: float = 60.0,
        spec: MapSpec | None = None, progress=None) -> StageOutcome:
    """Compute (or reuse) one stability map and draw its figure.

    Raises
    ------
    StageError
        The scene has no ``contact`` or ``fixedpoint`` section.
    ValueError
        Unknown ``kind``.
    """
    require(scene, "contact", "stability-map")
    scene = with_defaults(scene, "fixedpoint", "stability-map")
    why = not_applicable(scene, kind)
    if why:
        raise StageError(why)
    n = validate_option(CommandOptions, "stability_map_n", n, "--n")
    workers = validate_option(CommandOptions, "workers", workers, "--workers")
    time_limit_s = validate_option(CommandOptions, "stability_map_time_limit_s",
                                   float(time_limit_s), "--time-limit")
    terrain = scene.terrain
    spec = spec or default_spec(kind, n, time_limit_s, stiffness=scene.contact.stiffness,
                                patch_width_m=terrain.patch_width_m if terrain is not None
                                else 0.10)

    def compute():
        from walkerlab import progress as _progress

        ny = len(spec.y_values)
        with _progress.task(f"stability map {spec.kind}: {ny}x{len(spec.slopes_deg)} cells "
                            "(rows)", ny) as bar:
            def tick(done, total):
                bar.update(done)
                if progress is not None:
                    progress(done, total)

            cells = gait_map(scene, spec, workers=workers, progress=tick)
        frac = stable_fraction(cells)
        reasons = [str(r) for r in cells["reason"].ravel() if r]
        summary = {**frac, **{f"reason_{r}": reasons.count(r) for r in sorted(set(reasons))}}

        def writer(f):
            f.attrs["kind"] = spec.kind
            f.attrs["y_path"] = spec.y_path
            f.attrs["y_label"] = MAP_KINDS[spec.kind][1]
            f.attrs["stiffness_family"] = scene.contact.stiffness_family
            f.attrs["unit_system"] = scene.contact.unit_system
            f.attrs["time_limit_s"] = spec.time_limit_s
            # the scene's own point (slope, y), marked on the map wherever the grid lies
            f.attrs["scene_slope_deg"] = float(np.degrees(scene.slope.phi_rad))
            f.attrs["scene_y"] = _scene_value(scene, spec.y_path)
            f.attrs["method"] = ("each cell: fixed point of the contact walker's mid-stance "
                                 "step map, continued from its neighbour along the slope, "
                                 "else from the ideal fixed point at that slope")
            put(f, "y_values", cells["y_values"],
                {"patch_width": "m", "friction": "-"}.get(spec.kind, "scene units"),
                spec.y_path)
            put(f, "slopes_deg", cells["slopes_deg"], "deg", "slope angle")
            for fld in CELL_FIELDS:
                v = cells[fld]
                if v.dtype == object:
                    put(f, fld, np.asarray([[str(x) for x in r] for r in v],
                                           dtype=h5py.string_dtype()), "-", fld)
                else:
                    put(f, fld, np.asarray(v, float), _UNITS.get(fld, "-"), fld)
            for k, v in frac.items():
                put(f, f"summary/{k}", v, "-", k)
        return writer, summary

    out = run_cached(stage_name(spec.kind), scene, runs_root, SECTIONS, (), compute, force,
                     extra_key=spec.key())
    from walkerlab.io.runpaths import figures_dir

    draw(out.path, figures_dir(scene, runs_root, claim=True))
    return out


def _scene_value(scene: Scene, path: str) -> float:
    """The scene's value of a map's y field (``contact.stiffness``; a missing optional
    section at its default: ``terrain.patch_width_m`` 0.10); NaN if it has none."""
    from walkerlab.config import TerrainSettings

    d = scene.model_dump()
    d["terrain"] = d.get("terrain") or TerrainSettings().model_dump()
    for k in path.split("."):
        d = d.get(k) if isinstance(d, dict) else None
    return float(d) if isinstance(d, int | float) else float("nan")


def load(path: Path | str) -> dict:
    """A stability-map artifact as a dict of arrays (strings decoded)."""
    out: dict = {}
    with open_artifact(path) as f:
        out["attrs"] = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
        for k in ("y_values", "slopes_deg", *CELL_FIELDS):
            v = f[k][()]
            if v.dtype.kind in ("S", "O"):
                v = np.array([[x.decode() if isinstance(x, bytes) else str(x) for x in r]
                              for r in v], dtype=object)
            out[k] = v
    return out


def draw(path: Path | str, out_dir: Path | str | None = None) -> list[Path]:
    """Figure of a stability-map artifact (``<stem>.png``, ``.svg``) in ``out_dir`` (default:
    the report's figures folder next to the artifact, ``report/figures/``)."""
    from walkerlab.plotting.sweep_figures import gait_map_figure, save

    path = Path(path)
    data = load(path)
    fig = gait_map_figure(data)
    return save(fig, Path(out_dir) if out_dir is not None else path.parent / "report" / "figures",
                path.stem)
