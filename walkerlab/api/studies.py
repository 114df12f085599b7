"""Many-point studies from the front door (:mod:`walkerlab.api`): a sweep over one field,
the basin of attraction, continuation of the gait, the mean first-passage time.  Each runs
the stage the command runs and reads its artifact back."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    import xarray

    from walkerlab.config import Scene

from walkerlab.api.scenes import DEFAULT_RUNS, as_scene, read_dataset, runs_folder

__all__ = ["basin", "continuation", "mfpt", "sweep"]


def _axis_spec(param: str, values: Sequence) -> str:
    """``"slope.angle_deg=1.0,1.5"`` from a field and its values (as ``--param``)."""
    import numbers

    def text(v) -> str:
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            return str(v)
        return str(int(v)) if isinstance(v, numbers.Integral) else repr(float(v))

    from walkerlab.studies.params import SweepError  # light

    if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
        raise SweepError(f"sweep {param}: values={values!r}: give a sequence of values, e.g. "
                         f"[{values if isinstance(values, (int, float)) else 10}] or "
                         "[8, 10, 12] (a string would be swept character by character)")
    vals = list(values)
    if not vals:
        raise ValueError(f"sweep {param}: no values given")
    return f"{param}=" + ",".join(text(v) for v in vals)


def sweep(scene: Scene | str | Path | dict, param: str, values: Sequence, *,
          stage: str = "fixedpoint", workers: int = 1, name: str | None = None,
          runs_dir: str | Path = DEFAULT_RUNS, progress: bool = False) -> xarray.Dataset:
    """Run a stage over values of one scene field (``walkerlab sweep``).

    Parameters
    ----------
    scene : Scene, str, Path or dict
    param : str
        Dotted scene field, e.g. ``"slope.angle_deg"`` or ``"walker.hip_mass_kg"``.
    values : sequence
        Values of the field, in sweep order (continuation runs along them: each point
        starts from its neighbour's fixed point).
    stage : {"fixedpoint", "simulate", "contact-sim"}
    workers : int
        Local worker processes (1: in this process).
    name : str, optional
        Artifact name (``runs/<scene>/<name>.h5``); default ``sweep_<stage>_<hash>``.
    runs_dir : str or Path
    progress : bool
        Show the progress bar.

    Returns
    -------
    xarray.Dataset
        One dimension named by the swept field (``slope.angle_deg``, its coordinate with the
        field's unit); per point: ``outcome`` (``ok``, ``no_fixed_point``, ``fell`` ... see
        :mod:`walkerlab.studies.outcomes`), ``message``, the stage's columns (fixed point
        ``<role>_angle_rad`` ..., ``step_period_s`` [s], ``max_abs_multiplier``, ``stable``
        ...) and ``wall_time_s``.  A failed point is a row with its outcome, never an
        exception.

    Raises
    ------
    walkerlab.studies.params.SweepError
        Unknown field, values the field refuses, ``values`` a string or a single number
        instead of a sequence, or an unknown stage.
    SceneError, ImportError
        As :func:`fixed_point`.
    """
    from walkerlab.stages import sweep as stage_mod  # light

    path = stage_mod.run(as_scene(scene), [_axis_spec(param, values)], stage=stage,
                         workers=workers, runs_root=runs_folder(runs_dir), name=name,
                         progress=progress)
    return read_dataset(path)


def basin(scene: Scene | str | Path | dict, grid: tuple[int, int] | None = None, *,
          workers: int = 1, runs_dir: str | Path = DEFAULT_RUNS,
          force: bool = False) -> xarray.Dataset:
    """Basin of attraction of the period-1 gait over a 2-D slice of the Poincaré section.

    Parameters
    ----------
    scene : Scene, str, Path or dict
        The ``fixedpoint`` and ``basin`` sections (axes, ranges, start) are optional
        (defaults: :class:`walkerlab.config.FixedPointSettings`, ``BasinSettings``).
    grid : (nx, ny), optional
        Cells along x and y (default ``basin.grid``, 200 x 200; use e.g. (20, 20) to look);
        a grid other than the scene's is written to its own ``basin_<nx>x<ny>.h5``.
    workers : int
        Local worker processes (1: in this process).
    runs_dir, force
        As :func:`fixed_point`.

    Returns
    -------
    xarray.Dataset
        ``outcome`` (y, x): index into attribute ``outcomes`` (``converged`` = reaches the
        period-1 gait, other attractor, fell forward/backward ...); ``steps`` (y, x) steps
        until decided; ``period`` (y, x); coordinates ``x``, ``y`` (cell centres, in the
        units of the state components named by attributes ``x_axis``/``y_axis``);
        ``counts_<outcome>`` cells per outcome; ``fixed_point_<state>``.

    Raises
    ------
    StageError
        No ``fixedpoint`` section or bad basin settings.
    SceneError
        ``grid`` not two whole numbers (a string such as ``"10x10"``, a single number) or
        out of bounds, or as :func:`fixed_point`.
    ImportError
        As :func:`fixed_point`.
    """
    from walkerlab.stages import pipeline  # light

    out = pipeline.run("basin", as_scene(scene), runs_folder(runs_dir), force,
                       grid=grid, workers=workers)
    return read_dataset(out.path)


def continuation(scene: Scene | str | Path | dict, param: str, start: float, stop: float, *,
                 switch: bool = False, param2: str | None = None,
                 range2: tuple[float, float] | None = None,
                 runs_dir: str | Path = DEFAULT_RUNS, force: bool = False):
    """Pseudo-arclength continuation of the scene's gait over a numeric scene field
    (``walkerlab continuation``): folds, period doublings, Neimark-Sacker points and branch
    ends located; with ``switch`` the period-2 and period-4 branches; with ``param2`` the
    fold / period-doubling curves in the plane of both fields.

    Parameters
    ----------
    scene : Scene, str, Path or dict
        Needs a ``fixedpoint`` section (its gait at its own value of ``param`` starts).
    param : str
        Dotted scene field (``"slope.angle_deg"``, ``"walker.leg.bodies.rod.mass_kg"``).
    start, stop : float
        The range, in the field's unit.
    switch : bool
        Switch at period doublings (period 2, then period 4).
    param2, range2
        Second field and its range for the two-parameter curves.
    runs_dir, force
        As :func:`fixed_point`.

    Returns
    -------
    walkerlab.io.schemas.continuation.ContinuationData
        ``branches`` (list: ``period``, ``param`` (N,) [unit], ``states`` by name, ``step_period``
        [s], ``multipliers`` (N, 2n), ``stable``), ``special`` (``kind``, ``param``,
        ``period``, ``cause`` ...), ``curves``; read from ``continuation_<param>.h5``
        (``continuation_<param>+<param2>.h5`` with ``param2``).

    Raises
    ------
    walkerlab.stages.common.StageError
        No ``fixedpoint`` section or no gait at the scene's own value (one line).
    SceneError
        The checks of ``walkerlab continuation``
        (:func:`walkerlab.studies.continuation.check_continuation`): ``param`` not a field
        name, a bound not a finite number, ``start == stop``, a whole-number field,
        ``param2`` without ``range2`` (or the reverse), ``range2`` not two numbers,
        ``param2`` the same field as ``param`` (one line).
    walkerlab.studies.params.SweepError
        ``param`` names no field of the scene.
    """
    from walkerlab.io.schemas.continuation import load_continuation  # light
    from walkerlab.stages import continuation as stage  # light

    out = stage.run(as_scene(scene), param, start, stop, 2 if switch else 0, param2, range2,
                    runs_folder(runs_dir), force)
    return load_continuation(out.path)


def mfpt(scene: Scene | str | Path | dict, sigma_rad: list[float] | None = None, *,
         method: str | None = None, workers: int = 1, runs_dir: str | Path = DEFAULT_RUNS,
         force: bool = False) -> xarray.Dataset:
    """Mean first-passage time (heel strikes before the fall) on per-step random slopes
    (Byl & Tedrake 2009), by Monte Carlo and/or the mesh of the post-impact section.

    Parameters
    ----------
    scene : Scene, str, Path or dict
        Needs a ``fixedpoint`` section; ``mfpt`` (walks, step cap, mesh settings) and
        ``terrain.per_step`` (distribution, seed) are optional.
    sigma_rad : list of float, optional
        Standard deviations of the per-step slope [rad] (default ``mfpt.sigma_rad``).
    method : {"mesh", "montecarlo", "both"}, optional
        Default ``mfpt.method`` (both).
    workers, runs_dir, force
        As :func:`basin`.

    Returns
    -------
    xarray.Dataset
        On the coordinate ``sigma_rad`` [rad]: ``mfpt_steps_montecarlo`` and its
        ``mfpt_steps_montecarlo_stderr``, ``mfpt_steps_mesh``, ``mesh_cells``,
        ``mesh_change``, ``mesh_converged`` ... (:mod:`walkerlab.io.schemas.mfpt`).

    Raises
    ------
    StageError
        No ``fixedpoint`` section, bad settings, or a walker whose state coordinates are
        measured from the slope.
    SceneError
        ``sigma_rad`` not a list of positive numbers (a string, a single number), or as
        :func:`fixed_point`.
    ImportError
        As :func:`fixed_point`.
    """
    from walkerlab.stages import pipeline  # light

    out = pipeline.run("mfpt", as_scene(scene), runs_folder(runs_dir), force, sigma_rad=sigma_rad,
                       method=method, workers=workers)
    return read_dataset(out.path)
