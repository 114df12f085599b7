"""Stage ``stability-map``: where the contact model has a stable periodic gait.

One cached artifact per map kind, ``runs/<scene>/stability_map_<kind>.h5`` (input hash: the
scene's physics sections, the code and the grid), and its figure
``report/figures/stability_map_<kind>.png/.svg``, drawn from the artifact.  The computation is
:func:`walkerlab.sweep.stability.gait_map`.
"""

from __future__ import annotations

import math
from pathlib import Path

from walkerlab.config import CommandOptions, Scene, validate_option
from walkerlab.io.schemas.stability_map import (
    StabilityMapRun,
    load_stability_map,
    write_stability_map,
)
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached
from walkerlab.sweep.stability import (
    CELL_FIELDS,
    MapSpec,
    default_spec,
    gait_map,
    stable_fraction,
)

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint", "contact", "terrain")


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
    require(scene, "fixedpoint", "stability-map")
    why = not_applicable(scene, kind)
    if why:
        raise StageError(why)
    n = validate_option(CommandOptions, "stability_map_n", n, "--n")
    workers = validate_option(CommandOptions, "workers", workers, "--workers")
    time_limit_s = validate_option(CommandOptions, "stability_map_time_limit_s",
                                   float(time_limit_s), "--time-limit")
    terrain = scene.terrain
    k, _, k_field = scene.contact.written("stiffness")
    spec = spec or default_spec(kind, n, time_limit_s, stiffness=k, stiffness_field=k_field,
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

        run = StabilityMapRun(spec, cells, frac, scene.contact.stiffness_family,
                              CELL_FIELDS, spec.y_label,
                              (math.degrees(scene.slope.phi_rad),
                               _scene_value(scene, spec.y_path)))
        return (lambda f: write_stability_map(f, run)), summary

    out = run_cached(stage_name(spec.kind), scene, runs_root, SECTIONS, (), compute, force,
                     extra_key=spec.key())
    from walkerlab.io.runpaths import figures_dir

    draw(out.path, figures_dir(scene, runs_root, claim=True))
    return out


def _scene_value(scene: Scene, path: str) -> float:
    """The scene's value of a map's y field (``contact.mu_static``; a missing optional
    section at its default: ``terrain.patch_width_m`` 0.10); NaN if it has none."""
    from walkerlab.config import TerrainSettings

    d = scene.model_dump()
    d["terrain"] = d.get("terrain") or TerrainSettings().model_dump()
    for k in path.split("."):
        d = d.get(k) if isinstance(d, dict) else None
    return float(d) if isinstance(d, int | float) else float("nan")


def draw(path: Path | str, out_dir: Path | str | None = None) -> list[Path]:
    """Figure of a stability-map artifact (``<stem>.png``, ``.svg``) in ``out_dir`` (default:
    the report's figures folder next to the artifact, ``report/figures/``)."""
    from walkerlab.plotting.sweep_figures import gait_map_figure, save

    path = Path(path)
    data = load_stability_map(path)
    fig = gait_map_figure(data)
    return save(fig, Path(out_dir) if out_dir is not None else path.parent / "report" / "figures",
                path.stem)
