"""walkerlab's Python front door: scenes in, ``xarray.Dataset`` out.

Every function runs the *same* stage as the command line (:mod:`walkerlab.stages`): it
writes (or reuses, when up to date) the stage's HDF5 artifact in the runs folder
(``runs_dir``, default ``runs/``, as ``--runs-dir``), then reads the artifact back with
:func:`walkerlab.io.datasets.load_dataset`, through its netCDF-4 view.  So a notebook and
``walkerlab report`` share one code path, one cache and one set of files, and a dataset holds
exactly what the artifact holds: named dimensions (``time``, ``state``, ``step``,
``multiplier``, the swept field ``slope.angle_deg``, ``x``/``y`` of a basin ...), coordinate
variables, and ``units``/``long_name`` on every variable.

``walkerlab.sweep`` is the package :mod:`walkerlab.sweep` (sweeps, basins, maps); the sweep
of the front door is :func:`walkerlab.api.sweep` (``wl.api.sweep(scene, param, values)``).

Needs xarray and h5netcdf (``pip install 'walkerlab[api]'``; the ``dev`` extra has them).
Importing this module loads neither them nor the numeric stack: each function imports what
it uses.

Example
-------
>>> import walkerlab as wl
>>> scene = wl.load_scene("configs/kneed.yaml")
>>> gait = wl.fixed_point(scene, runs_dir="runs")        # doctest: +SKIP
>>> float(gait.step_period), gait.multipliers.values      # doctest: +SKIP
>>> run = wl.simulate(scene, strides=2)                   # doctest: +SKIP
>>> run.leg1_angle.plot()                                 # doctest: +SKIP
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    import xarray

    from walkerlab.config import Scene

__all__ = ["load_scene", "with_changes", "fixed_point", "fixed_points", "simulate",
           "contact_simulate", "compare", "sweep", "basin", "continuation", "mfpt"]

DEFAULT_RUNS = Path("runs")


def load_scene(path_or_dict: str | Path | dict[str, Any], name: str | None = None) -> Scene:
    """Read and validate a scene from a YAML file or a plain mapping.

    Parameters
    ----------
    path_or_dict : str, Path or dict
        A scene YAML file (``configs/kneed.yaml``) or the same content as a mapping
        (``{"walker": {...}, "slope": {...}, "fixedpoint": {...}}``).
    name : str, optional
        Run-folder name (``runs/<name>/``); default: the scene's ``name``, else the file
        stem, else ``"scene"`` for a mapping.

    Returns
    -------
    walkerlab.config.Scene
        The validated, frozen scene (pass it to every other function here).

    Raises
    ------
    walkerlab.config.SceneError
        File missing, malformed YAML, or fields that do not validate (every error, one line
        each, unknown keys first with the closest field name); ``name`` not a string or not
        a safe folder name (empty, path separators).
    """
    from walkerlab.config import Scene, SceneError, scene_from_dict
    from walkerlab.config import load_scene as _load

    if isinstance(path_or_dict, Scene):
        sc = path_or_dict
    elif isinstance(path_or_dict, dict):
        data = dict(path_or_dict)
        data.setdefault("name", "scene")
        sc = scene_from_dict(data)
    else:
        sc = _load(path_or_dict)
    if name is not None:
        from walkerlab.io.runpaths import check_name

        if not isinstance(name, str):
            raise SceneError(f"name={name!r}: give the run folder name as a string, e.g. "
                             "name='paper_steep'")
        try:
            check_name(name, "name")
        except ValueError as exc:
            raise SceneError(str(exc)) from None
        origin = getattr(sc, "_origin", None)
        sc = sc.model_copy(update={"name": name})
        sc._origin = origin
    return sc


def with_changes(scene: Scene | str | Path | dict, changes: dict[str, Any]) -> Scene:
    """A new scene: ``scene`` with fields set by the dotted paths of ``--param``.

    Parameters
    ----------
    scene : Scene, str, Path or dict
        The base scene (see :func:`load_scene`); it is not changed (a scene is frozen).
    changes : dict
        Dotted scene field -> value, as ``walkerlab sweep --param`` names fields:
        ``{"slope.angle_deg": 2, "walker.leg.bodies.thigh_mass.mass_kg": 0.4}`` (a list
        item by its ``name`` or index).  Setting ``slope.angle_deg`` replaces
        ``slope.angle_rad`` and vice versa, and a contact quantity's SI name its mm-kg-s
        name (``contact.stiffness_n_per_m_pow_e`` / ``_n_per_mm_pow_e``); a missing section
        is created with its defaults.

    Returns
    -------
    walkerlab.config.Scene
        Validated and frozen; same ``name`` and scene file (its artifacts go to the same
        run folder, recomputed where the change matters, as after editing the YAML file).

    Raises
    ------
    walkerlab.config.SceneError
        An unknown field (with the closest name) or a value that does not validate: one
        line naming the path.

    Examples
    --------
    >>> steeper = wl.with_changes(wl.load_scene("configs/paper.yaml"),
    ...                           {"slope.angle_deg": 2})          # doctest: +SKIP
    """
    from walkerlab.config import SceneError
    from walkerlab.sweep.params import ParamAxis, SweepError, apply_point, check_axes

    base = _scene(scene)
    if not isinstance(changes, dict) or not all(isinstance(k, str) for k in changes):
        raise SceneError("with_changes: give a mapping of dotted field paths to values, "
                         "e.g. {'slope.angle_deg': 2}")
    axes = [ParamAxis(k, (v,), f"{k}={v!r}") for k, v in changes.items()]
    try:
        check_axes(base, axes, values=False)
        out = apply_point(base.model_dump(mode="json"), list(changes), tuple(changes.values()),
                          "with_changes")
    except SweepError as exc:
        raise SceneError("with_changes: " + str(exc).removeprefix("--param ")) from None
    except SceneError as exc:
        raise SceneError(str(exc).replace("with_changes [", "with_changes: [", 1)) from None
    out._origin = base.origin
    return out


def _scene(scene) -> Scene:
    from walkerlab.config import Scene

    return scene if isinstance(scene, Scene) else load_scene(scene)


def _runs(runs_dir) -> Path:
    """``runs_dir`` as a path; an empty name (which would be the current folder) or a value
    that is not a path is refused in one line, as ``--runs-dir ''`` is."""
    import os

    from walkerlab.safefs import RunPathError

    if not isinstance(runs_dir, (str, os.PathLike)) or isinstance(runs_dir, bytes):
        raise RunPathError(f"runs_dir={runs_dir!r}: give a folder name, e.g. runs_dir='runs'")
    if not str(runs_dir).strip():
        raise RunPathError("runs_dir='': empty folder name (it would write into the current "
                           "folder); give a folder, e.g. runs_dir='runs'")
    return Path(runs_dir)


def _read(path: Path) -> xarray.Dataset:
    from walkerlab.io.datasets import load_dataset

    return load_dataset(path)


def fixed_point(scene: Scene | str | Path | dict, *, runs_dir: str | Path = DEFAULT_RUNS,
                force: bool = False) -> xarray.Dataset:
    """The period-1 gait: fixed point of the Poincaré map, step period, Floquet multipliers.

    Runs the ``fixedpoint`` stage (as ``walkerlab fixedpoint``) and reads
    ``runs/<scene>/fixedpoint.h5``.

    Parameters
    ----------
    scene : Scene, str, Path or dict
        A scene (see :func:`load_scene`); without a ``fixedpoint`` section, its defaults.
    runs_dir : str or Path
        Runs folder (``--runs-dir``); the artifact is reused when up to date.
    force : bool
        Recompute even if the artifact is up to date.

    Returns
    -------
    xarray.Dataset
        ``fixed_point`` (state,) [rad, rad/s; per-state unit in coordinate ``state_unit``],
        state just after heel strike; ``step_period`` () [s]; ``multipliers`` (multiplier,)
        complex Floquet multipliers (variational equations), ``multipliers_fd`` (finite
        differences); ``jacobian`` (state, state_in) of the Poincaré map; ``floquet_stable``
        (all |multiplier| < 1); ``residual`` () max |P(x*) - x*|; ``initial_guess``.
        Attributes: the artifact's (``scene_json``, ``input_hash``, ``variant`` ...).

    Raises
    ------
    walkerlab.stages.common.StageError
        No ``fixedpoint`` section, or no fixed point found (one line saying why).
    walkerlab.config.SceneError
        The scene does not validate.
    walkerlab.safefs.RunPathError
        ``runs_dir`` empty (it would be the current folder) or not a path.
    ImportError
        xarray/h5netcdf missing (``pip install 'walkerlab[api]'``).
    """
    from walkerlab.stages import pipeline

    return _read(pipeline.run("fixedpoint", _scene(scene), _runs(runs_dir), force).path)


def fixed_points(scene: Scene | str | Path | dict, *, runs_dir: str | Path = DEFAULT_RUNS,
                 force: bool = False) -> xarray.Dataset:
    """Every period-1 gait stored for the scene, on a ``gait`` dimension.

    The scene's own gait first (``gait`` = its equation variant), then the other equation
    variants a compass gait compared with published numbers is solved with (the report's
    comparison with Eq. 11).  Same stage and artifact as :func:`fixed_point`.

    Returns
    -------
    xarray.Dataset
        ``fixed_point`` (gait, state) [rad, rad/s], ``multipliers`` (gait, multiplier)
        complex, ``step_period`` (gait,) [s], ``residual`` (gait,), ``stable`` (gait,).

    Raises
    ------
    StageError, SceneError, ImportError
        As :func:`fixed_point`.
    """
    from walkerlab.io.datasets import load_fixed_points
    from walkerlab.stages import pipeline

    return load_fixed_points(pipeline.run("fixedpoint", _scene(scene), _runs(runs_dir),
                                          force).path)


def simulate(scene: Scene | str | Path | dict, strides: int | None = None, *,
             runs_dir: str | Path = DEFAULT_RUNS, force: bool = False) -> xarray.Dataset:
    """Simulate strides of the rigid hybrid walker from its fixed point (``simulate`` stage).

    Parameters
    ----------
    scene : Scene, str, Path or dict
    strides : int, optional
        Strides (1 stride = 2 steps); default ``simulate.strides`` of the scene (5 when the
        scene has no ``simulate`` section).  As ``walkerlab simulate --strides``.
    runs_dir : str or Path
    force : bool

    Returns
    -------
    xarray.Dataset
        On ``time`` (k,) [s]: every named coordinate (``leg1_angle`` [rad], ``leg1_rate``
        [rad/s], ...), ``energy_kinetic``/``energy_potential``/``energy_total`` [J]
        (potential from the first stance foot), ``<point>_x``/``<point>_y`` [m] (``hip``,
        ``leg1_foot`` ...), ``stance_leg``, ``step_index``, ``phase``.  On ``step``: the
        step table ``steps_period`` [s], ``steps_step_length`` [m], ``steps_hip_speed``
        [m/s], ``steps_impact_energy_loss`` [J], ``steps_termination`` ...
        Attribute ``termination``: ``heel_strike`` when every step completed; a walker
        that falls is recorded (``fall``), not raised.

    Raises
    ------
    StageError
        Upstream failure (no fixed point), or ``strides`` < 1.
    SceneError, ImportError
        As :func:`fixed_point`.
    """
    from walkerlab.stages import pipeline

    return _read(pipeline.run("simulate", _scene(scene), _runs(runs_dir), force,
                              strides=strides).path)


def contact_simulate(scene: Scene | str | Path | dict, *, adjust: bool = False,
                     periodic: bool = False, runs_dir: str | Path = DEFAULT_RUNS,
                     force: bool = False) -> xarray.Dataset:
    """Simulate the compliant-contact (MSC ADAMS style) walker (``contact-sim`` stage).

    Parameters
    ----------
    scene : Scene, str, Path or dict
        Needs a ``contact`` section.
    adjust : bool
        Search the initial rates that make the contact walker match the ideal gait
        (``--adjust``).
    periodic : bool
        Also find the contact walker's own periodic gait and its Floquet multipliers.
    runs_dir, force
        As :func:`fixed_point`.

    Returns
    -------
    xarray.Dataset
        The trajectory on ``time`` as :func:`simulate` (same names), the feet's contact
        forces ``feet_<leg>_normal_force`` / ``_friction_force`` [N], ``_penetration``
        [m], ``_slip_velocity`` [m/s] on ``time``; touchdown/lift-off times; the per-step
        table on ``step``; ``summary_*`` scalars; the drop test on ``stiffness``;
        ``periodic_gait_multipliers`` (multiplier,) complex with ``periodic``.
        Attribute ``outcome``: ``completed``, ``trip``, ``fall``, ... (recorded, not raised).

    Raises
    ------
    StageError
        No ``contact`` section, or no fixed point to start from.
    SceneError, ImportError
        As :func:`fixed_point`.
    """
    from walkerlab.stages import pipeline

    return _read(pipeline.run("contact-sim", _scene(scene), _runs(runs_dir), force, adjust=adjust,
                              periodic=periodic).path)


def compare(scene: Scene | str | Path | dict, *, runs_dir: str | Path = DEFAULT_RUNS,
            force: bool = False) -> xarray.Dataset:
    """Errors and gait metrics between the rigid and the contact walker (``compare`` stage).

    Runs (or reuses) :func:`simulate` and :func:`contact_simulate` first.

    Returns
    -------
    xarray.Dataset
        ``error_<coordinate>`` (time,) contact - ideal on the ideal sample times [rad or
        rad/s]; ``errors_max_abs_angle`` [rad], ``errors_max_abs_rate`` [rad/s];
        ``metrics_ideal_*`` / ``metrics_contact_*`` scalars (Table 3: step times [s], speed
        [m/s], mean energy [J], step length [m]); ``errors_limit_cycle_distance_*``.

    Raises
    ------
    StageError, SceneError, ImportError
        As :func:`contact_simulate`.
    """
    from walkerlab.stages import pipeline

    return _read(pipeline.run("compare", _scene(scene), _runs(runs_dir), force).path)


def _axis_spec(param: str, values: Sequence) -> str:
    """``"slope.angle_deg=1.0,1.5"`` from a field and its values (as ``--param``)."""
    import numbers

    def text(v) -> str:
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            return str(v)
        return str(int(v)) if isinstance(v, numbers.Integral) else repr(float(v))

    from walkerlab.sweep.params import SweepError

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
        :mod:`walkerlab.sweep.outcomes`), ``message``, the stage's columns (fixed point
        ``<role>_angle_rad`` ..., ``step_period_s`` [s], ``max_abs_multiplier``, ``stable``
        ...) and ``wall_time_s``.  A failed point is a row with its outcome, never an
        exception.

    Raises
    ------
    walkerlab.sweep.params.SweepError
        Unknown field, values the field refuses, ``values`` a string or a single number
        instead of a sequence, or an unknown stage.
    SceneError, ImportError
        As :func:`fixed_point`.
    """
    from walkerlab.stages import sweep as stage_mod

    path = stage_mod.run(_scene(scene), [_axis_spec(param, values)], stage=stage,
                         workers=workers, runs_root=_runs(runs_dir), name=name, progress=progress)
    return _read(path)


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
    SceneError, ImportError
        As :func:`fixed_point`.
    """
    from walkerlab.stages import pipeline

    out = pipeline.run("basin", _scene(scene), _runs(runs_dir), force,
                       grid=tuple(grid) if grid else None, workers=workers)
    return _read(out.path)


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
        ``period``, ``cause`` ...), ``curves``; read from ``continuation_<param>.h5``.

    Raises
    ------
    walkerlab.stages.common.StageError
        No ``fixedpoint`` section or no gait at the scene's own value (one line).
    walkerlab.sweep.params.SweepError
        ``param`` names no field of the scene.
    """
    from walkerlab.io.schemas.continuation import load_continuation
    from walkerlab.stages import continuation as stage

    out = stage.run(_scene(scene), param, float(start), float(stop), 2 if switch else 0,
                    param2, tuple(range2) if range2 is not None else None, _runs(runs_dir),
                    force)
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
    workers : int
        Local worker processes (1: in this process).
    runs_dir, force
        As :func:`fixed_point`.

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
    SceneError, ImportError
        As :func:`fixed_point`.
    """
    from walkerlab.stages import pipeline

    out = pipeline.run("mfpt", _scene(scene), _runs(runs_dir), force, sigma_rad=sigma_rad,
                       method=method, workers=workers)
    return _read(out.path)
