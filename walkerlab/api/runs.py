"""One scene's runs from the front door (:mod:`walkerlab.api`): the gait, a rigid and a
contact simulation, their comparison, the optimal gait or design, the robustness measures
and the exported model.  Each runs the stage the command runs and reads its artifact back as
an ``xarray.Dataset`` (the export: the written file's path)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    import xarray

    from walkerlab.config import Scene

from walkerlab.api.scenes import DEFAULT_RUNS, as_scene, read_dataset, runs_folder

__all__ = ["compare", "contact_simulate", "export_scene", "fixed_point", "fixed_points",
           "optimize", "robustness", "simulate"]


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
        (all ``|multiplier|`` < 1); ``residual`` () max ``|P(x*) - x*|``; ``initial_guess``.
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
        xarray/h5netcdf missing (``pip install -e '.[api]'``).
    """
    from walkerlab.stages import pipeline  # light

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
    from walkerlab.io.datasets import load_fixed_points  # light
    from walkerlab.stages import pipeline  # light

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
    from walkerlab.stages import pipeline  # light

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
    from walkerlab.io.stage_files import CONTACT_SIM  # light: as the pipeline below
    from walkerlab.stages import pipeline  # light

    return read_dataset(pipeline.run(CONTACT_SIM.name, as_scene(scene), runs_folder(runs_dir),
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
    from walkerlab.stages import pipeline  # light

    return read_dataset(pipeline.run("compare", as_scene(scene), runs_folder(runs_dir), force).path)




def _design_bounds(design) -> dict:
    """``{field: (lo, hi)}`` of :func:`optimize`'s ``design`` checked as ``--design``
    (``FIELD=LO:HI``) is: a mapping of field names to two finite numbers, LO < HI."""
    import math
    import numbers

    from walkerlab.config import SceneError  # light

    if not isinstance(design, dict) or not design:
        raise SceneError(f"optimize: design={design!r}: give a mapping of fields to bounds, "
                         "e.g. {'walker.hip_mass_kg': (5, 20)} (as --design FIELD=LO:HI)")
    out = {}
    for field, rng in design.items():
        if not isinstance(field, str) or not field.strip():
            raise SceneError(f"optimize: design field {field!r}: give a dotted scene field")
        ok = (not isinstance(rng, (str, bytes)) and hasattr(rng, "__len__") and len(rng) == 2
              and all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in rng))
        if not ok or not all(math.isfinite(v) for v in rng) or not rng[0] < rng[1]:
            raise SceneError(f"optimize: design {field}={rng!r}: give (LO, HI), two finite "
                             "numbers with LO < HI, in the field's unit (as --design "
                             "FIELD=LO:HI)")
        out[field.strip()] = (float(rng[0]), float(rng[1]))
    return out


def optimize(scene: Scene | str | Path | dict, *, design: dict | None = None,
             objective: str = "max_abs_multiplier", maximize: bool = False,
             runs_dir: str | Path = DEFAULT_RUNS, force: bool = False) -> xarray.Dataset:
    """An optimal periodic gait by direct collocation, or an optimal design
    (``walkerlab optimize``, ``walkerlab optimize --design``).

    Without ``design``: the ``optimize`` stage (CasADi + IPOPT; the scene's ``optimize``
    section, its defaults when absent): least int u^2 dt under the targets and limits given,
    replayed on the rigid model; reads ``runs/<scene>/optimize.h5``.  With ``design``: the
    fields within their bounds that minimise (``maximize``: maximise) a measure of the
    scene's own gait, followed from the scene's values; reads its artifact
    ``optimize_design_<fields>_<objective>[_maximize].h5``.

    Parameters
    ----------
    scene : Scene, str, Path or dict
    design : dict, optional
        ``{field: (lo, hi)}``: dotted numeric scene fields and their bounds in the fields'
        units (``{"walker.hip_mass_kg": (5, 20)}``), as ``--design FIELD=LO:HI``.
    objective : str
        With ``design``: a measure of :data:`walkerlab.optimal.design.search.MEASURES`
        (``step_period``, ``step_length``, ``speed``, ``cost_of_transport``,
        ``max_abs_multiplier``, ``gait_sensitivity_norm``, ``basin_share``, ``mfpt``).
    maximize : bool
        With ``design``: maximise the objective.
    runs_dir, force
        As :func:`fixed_point`.

    Returns
    -------
    xarray.Dataset
        ``optimize.h5``: the collocated step on ``time`` (states [rad, rad/s], ``torque``
        [N m]), ``step_period`` [s], ``step_length`` [m], ``objective``, the replay's
        ``multipliers``, the contact replay ...; the design's artifact: the fields'
        optimal values, the objective and its gradient.

    Raises
    ------
    walkerlab.config.SceneError
        ``design`` not a mapping of fields to (LO, HI) with finite LO < HI, an unknown
        ``objective``, or ``objective``/``maximize`` given without ``design``; checked
        before anything runs (one line).
    walkerlab.studies.params.SweepError
        A ``design`` field the scene does not have (with the closest name), before anything
        runs.
    walkerlab.stages.common.StageError
        A walker the collocation does not handle, or no gait on the way (one line).
    ImportError
        CasADi missing (``pip install -e '.[optimize]'``), or as :func:`fixed_point`.
    """
    from walkerlab.config import SceneError  # light
    from walkerlab.optimal.design.search import MEASURES  # light
    from walkerlab.stages import pipeline  # light

    sc, runs = as_scene(scene), runs_folder(runs_dir)
    if design is None:
        if objective != "max_abs_multiplier" or maximize:
            raise SceneError("optimize: objective and maximize choose a design's measure; "
                             "give design={field: (lo, hi)} too (the gait's own objective "
                             "is the scene's optimize section)")
        return read_dataset(pipeline.run("optimize", sc, runs, force).path)
    bounds = _design_bounds(design)
    if objective not in MEASURES:
        raise SceneError(f"optimize: objective={objective!r}: one of {', '.join(MEASURES)}")
    if not isinstance(maximize, bool):
        raise SceneError(f"optimize: maximize={maximize!r}: give True or False")
    from walkerlab.studies.params import ParamAxis, SweepError, check_axes  # light

    try:
        check_axes(sc, [ParamAxis(f, (), f) for f in bounds], values=False)  # before any run
    except SweepError as exc:
        raise SweepError(str(exc).replace("--param ", "optimize: design field ", 1)) from None
    from walkerlab.stages import optimize as stage  # light

    pipeline.run_upstream("optimize", sc, runs)
    return read_dataset(stage.run_design(sc, runs, force, bounds, objective, maximize).path)


def robustness(scene: Scene | str | Path | dict, *, workers: int = 1,
               runs_dir: str | Path = DEFAULT_RUNS, force: bool = False) -> xarray.Dataset:
    """Robustness of the gait beyond ``|multiplier|`` (``walkerlab robustness``): gait
    sensitivity norms, the largest step-down/up and mid-stance push, and the Monte Carlo
    mean first-passage time at the scene's sigma (the scene's ``robustness`` section, its
    defaults when absent).  Runs the ``robustness`` stage and reads ``robustness.h5``.

    Parameters
    ----------
    scene : Scene, str, Path or dict
        Needs a ``fixedpoint`` section.
    workers : int
        Local worker processes of the Monte Carlo (1: in this process), as ``--workers``.
    runs_dir, force
        As :func:`fixed_point`.

    Returns
    -------
    xarray.Dataset
        The gait sensitivity norms per disturbance (``gsn_<disturbance>``) [per unit of the
        disturbance], ``step_down_m``/``step_up_m`` brackets [m], ``push_forward_m_per_s``
        / ``push_backward_m_per_s`` [m/s], ``mfpt_steps`` and its standard error
        (:mod:`walkerlab.io.schemas.robustness`).

    Raises
    ------
    walkerlab.stages.common.StageError
        No ``fixedpoint`` section, a bad worker count (``0``, ``True``, ``"2"``), or a walker
        the batched step map cannot carry (one line).
    SceneError, ImportError
        As :func:`fixed_point`.
    """
    from walkerlab.stages import pipeline  # light
    from walkerlab.stages.robustness import check  # light

    sc = as_scene(scene)
    check(sc, workers)  # before the upstream gait search
    return read_dataset(pipeline.run("robustness", sc, runs_folder(runs_dir), force,
                                     workers=workers).path)


def export_scene(scene: Scene | str | Path | dict, fmt: str = "urdf", *,
                 walker_only: bool = False, runs_dir: str | Path = DEFAULT_RUNS) -> Path:
    """Write the scene's walker as a multibody model file (``walkerlab export``):
    ``runs/<scene>/walker.urdf`` (Drake, Pinocchio; with the gait's keyframe beside it,
    ``walker.gait.json``), ``walker.xml`` (MuJoCo MJCF, the gait as its ``gait`` keyframe)
    or ``walker.adm`` + ``walker.acf`` (MSC Adams Solver).  The files of one export are
    written together: all or none.

    Parameters
    ----------
    scene : Scene, str, Path or dict
    fmt : {"urdf", "mjcf", "adm"}
    walker_only : bool
        URDF/MJCF: the walker alone, no gait search (no keyframe; the MJCF on a plane).
    runs_dir : str or Path
        Runs folder (``--runs-dir``).

    Returns
    -------
    Path
        The written file (``walker.adm`` for ``adm``).

    Raises
    ------
    walkerlab.config.SceneError
        ``fmt`` not one of the formats, ``walker_only`` not a bool (one line).
    ValueError
        A walker the format cannot carry (a massless link, feet), or no rigid gait for the
        keyframe (one line).
    walkerlab.io.artifacts.ArtifactError
        A file cannot be written (disk full, a folder in a file's place): nothing replaced.
    """
    from walkerlab.config import SceneError  # light
    from walkerlab.export.multibody import FORMATS  # light
    from walkerlab.stages import export as stage  # light

    if not isinstance(fmt, str) or fmt not in (*FORMATS, "adm"):
        raise SceneError(f"export: fmt={fmt!r}: one of {', '.join(FORMATS)}, adm")
    if not isinstance(walker_only, bool):
        raise SceneError(f"export: walker_only={walker_only!r}: give True or False")
    return stage.run(as_scene(scene), runs_folder(runs_dir), fmt, walker_only=walker_only)
