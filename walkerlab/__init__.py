"""walkerlab: a command-line lab for biped walkers (planar, and in 3D), passive and powered.

The package is split by role (lower layers first; the documentation, docs/, describes
the product):

- :mod:`walkerlab.walker`   the walker as data: description, state layout, link tree
- :mod:`walkerlab.config`   typed YAML scenes (pydantic, ``extra="forbid"``)
- :mod:`walkerlab.codegen`  the generated code of a walker's rigid and floating views (sympy)
- :mod:`walkerlab.models`   walker models: ``models.hybrid`` (rigid) and ``models.contact``
  (the compliant-contact, MSC ADAMS style, walker)
- :mod:`walkerlab.integrate` the one solver layer of both models (settings, run ends, events)
- :mod:`walkerlab.analysis` Poincaré map, fixed points, gait metrics, robustness measures
- :mod:`walkerlab.studies`    many-point studies: sweeps, bifurcation, basins, maps, MFPT
- :mod:`walkerlab.execution` the one executor protocol (inline, process pool, Dask)
- :mod:`walkerlab.io`       HDF5 artifacts (one schema module per artifact, atomic writes)
- :mod:`walkerlab.report`   markdown/HTML from loaded artifacts only
- :mod:`walkerlab.plotting` figures drawn from loaded artifacts only
- :mod:`walkerlab.stages`   one module per stage: config + upstream artifacts -> one artifact;
  ``stages.pipeline`` chains them
- :mod:`walkerlab.cli`      thin typer front end (parse, run a stage, print)
- :mod:`walkerlab.cli.bench`    ``walkerlab bench``: the benchmarks by name
- :mod:`walkerlab.api`      the Python front door: ``walkerlab.load_scene``,
  ``with_changes``, ``fixed_point``, ``fixed_points``, ``simulate``, ``contact_simulate``,
  ``compare``, ``basin`` and ``api.sweep`` (each returns an ``xarray.Dataset`` read from the
  stage's artifact; ``walkerlab.studies`` is the package of sweeps, basins and maps),
  ``continuation`` (the loaded continuation artifact), ``mfpt`` (mean first-passage time),
  ``optimize`` (optimal gait or design), ``robustness``, ``export_scene`` (the model file's
  path; also ``walkerlab.api.export``; ``walkerlab.export`` is the package of exchange
  formats), ``target`` (in memory: the field value whose gait meets a target), ``Walker`` and
  ``ContactWalker`` (the walker in memory: rigid and contact views)

Importing the package has no side effects and loads no heavy optional package: the API's
names are looked up on first use (PEP 562).
"""

__version__ = "0.1.0"

_API = ("load_scene", "with_changes", "fixed_point", "fixed_points", "simulate",
        "contact_simulate", "compare", "basin", "continuation", "mfpt", "optimize",
        "robustness", "export_scene", "target", "Walker", "ContactWalker")
__all__ = ["__version__", "api", *_API]


def __getattr__(name: str):
    if name in _API or name == "api":
        import importlib

        api = importlib.import_module("walkerlab.api")
        return api if name == "api" else getattr(api, name)
    if name == "export":  # the subpackage, once imported, is a plain attribute
        raise AttributeError("module 'walkerlab' has no attribute 'export': the model file "
                             "is written by walkerlab.export_scene (walkerlab.api.export); "
                             "the exchange formats are the package walkerlab.export "
                             "(import walkerlab.export)")
    raise AttributeError(f"module 'walkerlab' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
