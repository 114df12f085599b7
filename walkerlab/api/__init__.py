"""walkerlab's Python front door: scenes in, ``xarray.Dataset`` out.

Every function runs the *same* stage as the command line (:mod:`walkerlab.stages`): it
writes (or reuses, when up to date) the stage's HDF5 artifact in the runs folder
(``runs_dir``, default ``runs/``, as ``--runs-dir``), then reads the artifact back with
:func:`walkerlab.io.datasets.load_dataset`, through its netCDF-4 view.  So a notebook and
``walkerlab report`` share one code path, one cache and one set of files, and a dataset holds
exactly what the artifact holds: named dimensions (``time``, ``state``, ``step``,
``multiplier``, the swept field ``slope.angle_deg``, ``x``/``y`` of a basin ...), coordinate
variables, and ``units``/``long_name`` on every variable.

``walkerlab.studies`` is the package :mod:`walkerlab.studies` (sweeps, basins, maps); the sweep
of the front door is :func:`walkerlab.api.sweep` (``wl.api.sweep(scene, param, values)``).

Modules: :mod:`~walkerlab.api.scenes` (:func:`load_scene`, :func:`with_changes`),
:mod:`~walkerlab.api.runs` (one scene: :func:`fixed_point`, :func:`fixed_points`,
:func:`simulate`, :func:`contact_simulate`, :func:`compare`, :func:`optimize` (optimal gait
or design), :func:`robustness`, :func:`export_scene` (the written model file's path; here
also named ``export``, ``wl.api.export``: the package ``walkerlab.export`` holds the exchange
formats, so the top level names the function ``wl.export_scene``)),
:mod:`~walkerlab.api.studies` (many points: :func:`sweep`, :func:`basin`,
:func:`continuation`, :func:`mfpt`) and :mod:`~walkerlab.api.walker` (:class:`Walker`: the
walker in memory, its map, Jacobian, fixed point and walks, no artifact;
:class:`ContactWalker` (``Walker.contact()``): its contact view in memory, the walks and
periodic gait of ``walkerlab contact-sim``), :mod:`~walkerlab.api.walks` (the records of
their runs) and :mod:`~walkerlab.api.targets` (:func:`target`: the field value whose gait
meets a target speed, step length or period, in memory as ``walkerlab target``); this
module only gathers their public names.

Needs xarray and h5netcdf (main dependencies: ``pip install -e .`` installs them).
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

from walkerlab.api.runs import (
    compare,
    contact_simulate,
    export_scene,
    fixed_point,
    fixed_points,
    optimize,
    robustness,
    simulate,
)
from walkerlab.api.scenes import DEFAULT_RUNS, load_scene, with_changes
from walkerlab.api.studies import basin, continuation, mfpt, sweep
from walkerlab.api.targets import target
from walkerlab.api.walker import ContactWalker, Walker

export = export_scene  # ``wl.api.export``: this package has no subpackage of that name

__all__ = ["DEFAULT_RUNS", "load_scene", "with_changes", "fixed_point", "fixed_points",
           "simulate", "contact_simulate", "compare", "sweep", "basin", "continuation", "mfpt",
           "optimize", "robustness", "export", "export_scene", "target", "Walker", "ContactWalker"]
