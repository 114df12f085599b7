"""One scene's runs from the front door (:mod:`walkerlab.api`): the gait, a rigid and a
contact simulation, their comparison.  Each runs the stage the command runs and reads its
artifact back as an ``xarray.Dataset``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    import xarray

    from walkerlab.config import Scene

from walkerlab.api.scenes import DEFAULT_RUNS, as_scene, read_dataset, runs_folder

__all__ = ["compare", "contact_simulate", "fixed_point", "fixed_points", "simulate"]


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

    return read_dataset(pipeline.run("fixedpoint", as_scene(scene), runs_folder(runs_dir),
                                     force).path)


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

    return load_fixed_points(pipeline.run("fixedpoint", as_scene(scene), runs_folder(runs_dir),
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
        [m/s], ``steps_impact_energy_loss`` [J] (the heel-strike collision's loss),
        ``steps_transition_energy_change`` [J] (net across push-off and heel strike),
        ``steps_termination`` ...
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

    return read_dataset(pipeline.run("simulate", as_scene(scene), runs_folder(runs_dir), force,
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

    return read_dataset(pipeline.run("contact-sim", as_scene(scene), runs_folder(runs_dir),
                                     force, adjust=adjust, periodic=periodic).path)


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

    return read_dataset(pipeline.run("compare", as_scene(scene), runs_folder(runs_dir), force).path)


