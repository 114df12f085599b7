"""Stability maps of the compliant-contact gait itself.

Each cell of a map (a parameter y against the slope) asks: *does the contact model have a
periodic gait here, is it stable, what is its largest ``|Floquet multiplier|``, or why not?*
The gait is the fixed point of the contact walker's own mid-stance step map
(:func:`walkerlab.analysis.contact.periodic.find_contact_periodic_gait`).  Along each row
(one y value, slopes ascending) every cell starts from the contact gait of its neighbour
(continuation); when that fails or there is no neighbour yet it starts again from the ideal
fixed point at that slope (placed on the contact model and iterated a few steps).

Cell results (:data:`CELL_FIELDS`): ``exists`` (converged and every loaded foot stays on its
patch), ``stable`` (all ``|multipliers|`` < 1), ``max_abs_multiplier``, ``step_period_s``,
``patch_margin_m``, ``source`` ("neighbour" / "ideal"), ``reason`` ("" when the gait
exists, else ``fall``, ``no_mid_stance``, ``solver_failure``, ``work_limit`` (the cell's
search spent its step-map integrations, :attr:`MapSpec.max_step_maps`: the same on any
machine), ``not_converged``, ``off_patch``, ``no_ideal_gait``, ``invalid_config``,
``unsupported``: the periodic-gait search has no section for this walker), ``wall_time_s``
(a record only: no cell's answer depends on the clock).

The cached stage is :mod:`walkerlab.stages.stability_map`; the figure
:func:`walkerlab.plotting.gait_map_figure.gait_map_figure`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from walkerlab.integrate.solver import Solver

__all__ = ["MAP_KINDS", "MAP_MAX_STEP_MAPS", "CELL_FIELDS", "REASONS", "MapSpec",
           "default_spec", "gait_row", "gait_map", "stable_fraction", "MAP_GAIT_OPTIONS",
           "stability_map_run"]

#: map kind -> (dotted scene path of the y axis, label); the stiffness map varies the field
#: the scene writes its stiffness in (:attr:`MapSpec.y_field`; this one by default)
MAP_KINDS = {
    "stiffness": ("contact.stiffness_n_per_mm_pow_e", "contact stiffness k [N/mm^e]"),
    "friction": ("contact.mu_static", "static friction mu_s [-] (mu_d = 7/9 mu_s)"),
    "patch_width": ("terrain.patch_width_m", "patch width [m]"),
}

REASONS = ("", "fall", "no_mid_stance", "solver_failure", "time_limit", "not_converged",
           "off_patch", "no_ideal_gait", "invalid_config", "unsupported", "error",
           "work_limit")

#: Default work bound of each periodic-gait search of a map cell [step-map integrations]
#: (:attr:`MapSpec.max_step_maps`; a cell's search on the paper's walker makes a few
#: hundred; it replaced a 60 s wall-clock limit per cell)
MAP_MAX_STEP_MAPS = 2_000

CELL_FIELDS = ("exists", "stable", "max_abs_multiplier", "step_period_s", "patch_margin_m",
               "residual", "source", "reason", "wall_time_s")

#: settings of the periodic-gait search in a map cell (odeint step map, rtol 1e-9; FD
#: Jacobian at rtol 1e-10 with step 1e-3 x scale): looser than the contact-sim stage's, the
#: map noise is then ~1e-8 (scaled) and the multipliers carry ~1e-4 absolute error.
MAP_GAIT_OPTIONS = dict(solver=Solver("odeint", 1e-9, 1e-12),
                        jacobian_solver=Solver("odeint", 1e-10, 1e-13), check_fd=False,
                        fd_step=1e-3, residual_tol=1e-6, xtol=1e-7)


@dataclass(frozen=True)
class MapSpec:
    """Axes of one map.

    Attributes
    ----------
    kind : str
        Key of :data:`MAP_KINDS`.
    y_values : tuple of float
        Values of the y parameter (scene units).
    slopes_deg : tuple of float
        Slopes [deg] (x axis).
    max_step_maps : int
        Work bound of each search of a cell (from the neighbour's gait, then from the
        ideal one): its step-map integrations [-]
        (:class:`walkerlab.analysis.contact.step_map.SearchBudget`).
    y_field : str, optional
        Contact field of a stiffness map (``stiffness_n_per_mm_pow_e`` or
        ``stiffness_n_per_m_pow_e``: the one the scene writes; None: the first).
    """

    kind: str
    y_values: tuple
    slopes_deg: tuple
    max_step_maps: int = MAP_MAX_STEP_MAPS
    y_field: str | None = None

    @property
    def y_path(self) -> str:
        """Dotted scene path of the y axis."""
        return f"contact.{self.y_field}" if self.y_field else MAP_KINDS[self.kind][0]

    @property
    def y_label(self) -> str:
        """Axis label of the y parameter, with its unit."""
        if self.kind == "stiffness" and self.y_field:
            from walkerlab.config.contact import CONTACT_QUANTITIES

            unit = dict(CONTACT_QUANTITIES["stiffness"].values())[self.y_field]
            return f"contact stiffness k [{unit}]"
        return MAP_KINDS[self.kind][1]

    def key(self) -> str:
        """Text that identifies the spec (part of the stage's input hash)."""
        return (f"{self.kind}|{','.join(f'{v:.6g}' for v in self.y_values)}|"
                f"{','.join(f'{v:.6g}' for v in self.slopes_deg)}|{self.max_step_maps}maps|"
                + ",".join(f"{k}={v}" for k, v in sorted(MAP_GAIT_OPTIONS.items())))


def default_spec(kind: str, n: int = 8, max_step_maps: int = MAP_MAX_STEP_MAPS,
                 stiffness: float = 1e5, patch_width_m: float = 0.10,
                 stiffness_field: str | None = None) -> MapSpec:
    """The default ``n x n`` grid of a map kind (slopes 0.5-4 deg), its y axis around the
    scene's own value: stiffness ``stiffness`` x 1e-2 ... 1e4 (log), patch width
    ``patch_width_m`` x 0.2 ... 2, static friction 0.1 ... 0.9.  The paper's scene (k = 1e5
    N/mm^2.2, patches 0.10 m) gets 1e3 ... 1e9 and 0.02 ... 0.20 m.

    Parameters
    ----------
    stiffness : float
        The scene's contact stiffness as written (in the unit of its field).
    patch_width_m : float
        The scene's patch width (scene length unit, ``terrain.patch_width_m``).
    stiffness_field : str, optional
        The contact field the scene writes its stiffness in (:attr:`MapSpec.y_field`).

    Raises
    ------
    ValueError
        Unknown kind.
    """
    if kind not in MAP_KINDS:
        raise ValueError(f"unknown stability-map kind {kind!r} (one of {', '.join(MAP_KINDS)})")
    slopes = tuple(float(v) for v in np.round(np.linspace(0.5, 4.0, n), 4))
    lk = np.log10(stiffness)
    ys = {"stiffness": np.logspace(lk - 2, lk + 4, n), "friction": np.linspace(0.1, 0.9, n),
          "patch_width": np.linspace(0.2 * patch_width_m, 2.0 * patch_width_m, n)}[kind]
    return MapSpec(kind, tuple(float(v) for v in np.round(ys, 6)), slopes, max_step_maps,
                   stiffness_field if kind == "stiffness" else None)


def _cell_scene(base: dict, spec: MapSpec, y: float, slope_deg: float):
    from walkerlab.studies.params import apply_point

    paths, values = ["slope.angle_deg", spec.y_path], [slope_deg, y]
    if spec.kind == "friction":  # keep the paper's ratio mu_d / mu_s = 0.7 / 0.9
        paths.append("contact.mu_dynamic")
        values.append(round(y * 7.0 / 9.0, 9))
    return apply_point(base, paths, tuple(values), "<stability-map>")


def _empty_cell() -> dict:
    return {"exists": False, "stable": False, "max_abs_multiplier": np.nan,
            "step_period_s": np.nan, "patch_margin_m": np.nan, "residual": np.nan,
            "source": "", "reason": "", "wall_time_s": np.nan}


def gait_row(base: dict, spec: MapSpec, iy: int, plant) -> list[dict]:
    """Cells of row ``iy`` (one y value), slopes ascending, with continuation.

    Never raises (every failure becomes a ``reason``).  Top-level so it pickles for a
    process pool (``plant``, the map's :class:`~walkerlab.walker.plant.Plant`, pickles with
    it; each cell's is :meth:`~walkerlab.walker.plant.Plant.with_` of it).
    """
    from walkerlab.analysis.contact.periodic import find_contact_periodic_gait  # light
    from walkerlab.analysis.contact.step_map import PeriodicGaitError
    from walkerlab.config import SceneError
    from walkerlab.models.contact.scene import build
    from walkerlab.studies.point_gait import PointOutcome, ideal_fixed_point  # light

    y = spec.y_values[iy]
    row, z_prev, x_ideal_prev = [], None, None
    for slope in spec.slopes_deg:
        cell = _empty_cell()
        t0 = time.perf_counter()  # a record only (wall_time_s)
        try:
            scene = _cell_scene(base, spec, y, slope)
            cell_plant = plant.with_(scene)  # the cell's slope and contact: the same walker
            _w, fp, _src = ideal_fixed_point(scene, x_ideal_prev, plant=cell_plant)
            x_ideal_prev = fp.x
            walker, _ = build(scene, fp.x, 2, plant=cell_plant)
            tries = ([("neighbour", z_prev, 0)] if z_prev is not None else []) \
                + [("ideal", fp.x, 6)]
            gait, why = None, ""
            for source, guess, warm in tries:
                try:
                    g = find_contact_periodic_gait(walker, guess, warmup_steps=warm,
                                                   max_step_maps=spec.max_step_maps,
                                                   **MAP_GAIT_OPTIONS)
                except PeriodicGaitError as exc:
                    why = exc.kind
                    continue
                if not g.converged:
                    why = "not_converged"
                    continue
                gait = g
                cell["source"] = source
                break
            if gait is not None:
                on_patch = gait.patch_margin_m >= 0
                cell.update(exists=bool(on_patch), stable=bool(on_patch and gait.stable),
                            max_abs_multiplier=gait.max_multiplier,
                            step_period_s=gait.period_s, patch_margin_m=gait.patch_margin_m,
                            residual=gait.residual, reason="" if on_patch else "off_patch")
                z_prev = gait.z
            else:
                cell["reason"] = why or "not_converged"
                z_prev = None
        except SceneError:
            cell["reason"] = "invalid_config"
        except PointOutcome as exc:
            cell["reason"] = "no_ideal_gait" if exc.outcome == "no_fixed_point" else "error"
        except Exception:  # noqa: BLE001 - one cell must never end the map
            cell["reason"] = "error"
        cell["wall_time_s"] = time.perf_counter() - t0
        row.append(cell)
    return row


def gait_map(scene, spec: MapSpec, workers: int = 2,
             progress: Callable[[int, int], None] | None = None, *, plant) -> dict:
    """All cells of a map; rows in parallel on ``workers`` processes.

    Parameters
    ----------
    scene : walkerlab.config.Scene
        Base scene (needs ``contact`` and ``fixedpoint``).
    spec : MapSpec
    workers : int
        Worker processes (1 = in this process; more: a local process pool of
        :func:`walkerlab.execution.executor.make_executor`, ended within about a second when
        this process dies).
    progress : callable, optional
        ``progress(rows_done, rows_total)``.
    plant : walkerlab.walker.plant.Plant
        The scene's plant, built by the stage and handed to each row.

    Returns
    -------
    dict
        ``y_values`` (ny,), ``slopes_deg`` (nx,) and one (ny, nx) array per field of
        :data:`CELL_FIELDS`.
    """
    base = scene.model_dump(mode="json")
    ny, nx = len(spec.y_values), len(spec.slopes_deg)
    rows: list = [None] * ny
    from walkerlab.execution.executor import make_executor, run_each

    # pool workers end with this process (SIGKILL, SIGTERM included) and do not inherit its
    # open files (the artifact lock): walkerlab.execution.workers
    with make_executor(workers) as ex:
        for done, (iy, row) in enumerate(run_each(ex, gait_row,
                                                  [(base, spec, iy, plant)
                                                   for iy in range(ny)]), 1):
            rows[iy] = row
            if progress:
                progress(done, ny)
    out = {"y_values": np.asarray(spec.y_values, float),
           "slopes_deg": np.asarray(spec.slopes_deg, float)}
    for f in CELL_FIELDS:
        vals = [[rows[i][j][f] for j in range(nx)] for i in range(ny)]
        out[f] = np.array(vals, dtype=object if f in ("source", "reason") else float)
    return out


def stable_fraction(cells: dict) -> dict:
    """Fractions of cells where a gait exists, and where it exists and is stable [-]."""
    ex = np.asarray(cells["exists"], float) > 0.5
    st = ex & (np.asarray(cells["stable"], float) > 0.5)
    n = ex.size
    return {"cells": int(n), "exists_fraction": float(ex.sum() / n),
            "stable_fraction": float(st.sum() / n)}


def stability_map_run(scene, spec: MapSpec, workers: int = 2,
                      progress: Callable[[int, int], None] | None = None, *, plant):
    """:func:`gait_map` with a progress bar, packed for the stability-map artifact.

    The parameters are :func:`gait_map`'s (``progress`` is called beside the terminal's
    progress bar; ``plant``: the scene's, from the stage).

    Returns
    -------
    run : walkerlab.io.schemas.stability_map.StabilityMapRun
        The cells, their :func:`stable_fraction`, and the scene's own point (slope [deg],
        y value: :func:`walkerlab.config.options.map_axis_value`).
    summary : dict
        The fractions and ``reason_<why>``: cells without a gait, per reason.
    """
    import math

    from walkerlab import progress as _progress
    from walkerlab.config.options import map_axis_value
    from walkerlab.io.schemas.stability_map import StabilityMapRun  # light

    ny = len(spec.y_values)
    with _progress.task(f"stability map {spec.kind}: {ny}x{len(spec.slopes_deg)} cells "
                        "(rows)", ny) as bar:
        def tick(done, total):
            bar.update(done)
            if progress is not None:
                progress(done, total)

        cells = gait_map(scene, spec, workers=workers, progress=tick, plant=plant)
    frac = stable_fraction(cells)
    reasons = [str(r) for r in cells["reason"].ravel() if r]
    summary = {**frac, **{f"reason_{r}": reasons.count(r) for r in sorted(set(reasons))}}
    run = StabilityMapRun(spec, cells, frac, scene.contact.stiffness_family, CELL_FIELDS,
                          spec.y_label, (math.degrees(scene.slope.phi_rad),
                                         map_axis_value(scene, spec.y_path)))
    return run, summary
