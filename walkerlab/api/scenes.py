"""Scenes for the front door (:mod:`walkerlab.api`): read one, change fields by dotted path;
and what every call of the front door shares: the runs folder it writes to, the artifact
read back as an ``xarray.Dataset``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from walkerlab.rigid_walker import scene_of
from walkerlab.safefs import RunPathError

if TYPE_CHECKING:  # pragma: no cover
    import xarray

    from walkerlab.config import Scene

__all__ = ["DEFAULT_RUNS", "as_scene", "load_scene", "read_dataset", "runs_folder",
           "scene_plant", "with_changes"]

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
    from walkerlab.config import SceneError  # light

    sc = scene_of(path_or_dict)
    if name is not None:
        from walkerlab.io.runpaths import check_name  # light

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
    from walkerlab.config import SceneError  # light
    from walkerlab.studies.params import ParamAxis, SweepError, apply_point, check_axes  # light

    base = as_scene(scene)
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



def as_scene(scene) -> Scene:
    """``scene`` itself, or the scene :func:`load_scene` reads from it."""
    from walkerlab.config import Scene  # light

    return scene if isinstance(scene, Scene) else load_scene(scene)


def scene_plant(scene: Scene, plant=None):
    """The plant of ``scene``, built at this front door: its walker described
    (:meth:`~walkerlab.walker.plant.Plant.from_scene`), or, given the ``plant`` a caller
    holds (the contact view's, a walker's before a change), that plant's
    :meth:`~walkerlab.walker.plant.Plant.with_` (the same walker section keeps its
    description).

    Returns
    -------
    walkerlab.walker.plant.Plant
    """
    from walkerlab.walker.plant import Plant  # light

    return Plant.from_scene(scene) if plant is None else plant.with_(scene)


def runs_folder(runs_dir) -> Path:
    """``runs_dir`` as a path; an empty name (which would be the current folder) or a value
    that is not a path is refused in one line, as ``--runs-dir ''`` is."""
    import os

    if not isinstance(runs_dir, (str, os.PathLike)) or isinstance(runs_dir, bytes):
        raise RunPathError(f"runs_dir={runs_dir!r}: give a folder name, e.g. runs_dir='runs'")
    if not str(runs_dir).strip():
        raise RunPathError("runs_dir='': empty folder name (it would write into the current "
                           "folder); give a folder, e.g. runs_dir='runs'")
    return Path(runs_dir)


def read_dataset(path: Path) -> xarray.Dataset:
    """The artifact at ``path`` as an ``xarray.Dataset``
    (:func:`walkerlab.io.datasets.load_dataset`).

    Raises
    ------
    ImportError
        xarray/h5netcdf missing (``pip install -e '.[api]'``).
    """
    from walkerlab.io.datasets import load_dataset  # light

    return load_dataset(path)
