"""The optional parts of walkerlab, each an extra named by its purpose, and the one line a
command says when the extra it needs is not installed.

``pip install -e .`` installs the main job (fixed point, simulation, the contact model,
the comparison, the report); ``pip install -e '.[test]'`` what the tests need (every extra
below but ``numbalsoda`` and ``docs``).  The extras are those of ``pyproject.toml``
(``[project.optional-dependencies]``; a test checks the two agree).

Imports nothing of walkerlab.
"""

from __future__ import annotations

import importlib
from types import ModuleType

__all__ = ["EXTRAS", "MissingExtra", "require", "require_installed"]

#: extra -> what it is for (the commands and functions that need it)
EXTRAS = {
    "optimize": "walkerlab optimize: direct collocation with CasADi and IPOPT",
    "dask": "--scheduler: studies on a Dask cluster",
    "engines": "the exported models in other engines (MuJoCo, Pinocchio, Drake)",
    "api": "the Python API's datasets (xarray, h5netcdf)",
    "notebook": "examples/walkerlab_tour.ipynb (Jupyter)",
    "numbalsoda": "contact_solver.method numbalsoda (builds with cmake, g++, gfortran)",
    "gym": "walkerlab.gym: the walker as a Gymnasium environment",
    "osim": "the OpenSim export walked in OpenSim (walkerlab.export.opensim_walk; tests)",
    "docs": "the documentation site: Sphinx, numpydoc, sphinx-gallery (docs/README.md)",
}


class MissingExtra(ValueError, ImportError):
    """An optional dependency is not installed: one line naming the extra to install (a
    ValueError, so a command prints it as its one-line error; an ImportError, as what it
    is)."""


def require(module: str, extra: str, what: str) -> ModuleType:
    """Import ``module``, or say in one line which extra installs it.

    Parameters
    ----------
    module : str
        The importable name (``"casadi"``, ``"distributed"``, ``"mujoco"``).
    extra : str
        A key of :data:`EXTRAS`.
    what : str
        What needs it, as the user asked for it (``"walkerlab optimize"``,
        ``"--scheduler"``).

    Returns
    -------
    module
        The imported module.

    Raises
    ------
    MissingExtra
        ``"<what> needs <module> (not installed): pip install -e '.[<extra>]'"``; a
        module that is installed but fails to import names that failure and no extra
        (installing it again would not help: OpenSim's Moco beside another CasADi, a
        missing system library).
    KeyError
        ``extra`` is not one of :data:`EXTRAS` (a programming error).
    """
    EXTRAS[extra]  # noqa: B018 - an unknown extra is a bug, not the user's
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        top = (exc.name or "").split(".")[0]
        if top == module.split(".")[0]:
            raise MissingExtra(_missing(module, extra, what)) from None
        # installed, but its import failed (a library it links is missing or conflicts):
        # installing the extra again would not help, the reason is what to act on
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise MissingExtra(f"{what} needs {module}, which is installed but failed to "
                           f"import ({first}); repair that installation") from None


def _missing(module: str, extra: str, what: str) -> str:
    return f"{what} needs {module} (not installed): pip install -e '.[{extra}]'"


def require_installed(module: str, extra: str, what: str) -> None:
    """Check that ``module`` is installed without importing it (``importlib.util.
    find_spec``: for a module imported in a child process only), or say in one line which
    extra installs it.

    Raises
    ------
    MissingExtra
        ``"<what> needs <module> (not installed): pip install -e '.[<extra>]'"``.
    KeyError
        ``extra`` is not one of :data:`EXTRAS` (a programming error).
    """
    import importlib.util

    EXTRAS[extra]  # noqa: B018 - an unknown extra is a bug, not the user's
    if importlib.util.find_spec(module) is None:
        raise MissingExtra(_missing(module, extra, what))
