"""A stage's command-line options checked against the scene, before anything runs.

Each function validates what a command adds to a scene (``--grid``, ``--sigma-rad``,
``--strides``, ``--workers``, ...) through the pydantic field that caps the same value in
YAML (:func:`walkerlab.config.loader.validate_option`), and answers the scene questions a
stage asks before it computes (does a stability-map kind apply, what is the scene's own
value of a map axis).  Nothing here computes a gait.

Raises
------
SceneError
    One line naming the option and the scene field with the same cap.
"""

from __future__ import annotations

import math

from walkerlab.config.contact_sim import ContactSimSettings
from walkerlab.config.loader import validate_option
from walkerlab.config.schema import (
    BasinSettings,
    CommandOptions,
    MfptSettings,
    Scene,
    SceneError,
    SimulateSettings,
)
from walkerlab.config.terrain import TerrainSettings


def checked_workers(workers: int) -> int:
    """``--workers``, within :attr:`CommandOptions.workers`'s bounds.

    Raises
    ------
    SceneError
        Out of bounds (one line).
    """
    return validate_option(CommandOptions, "workers", workers, "--workers")


def _sequence(value, option: str, example: str) -> list:
    """An option given as a sequence of values (a list from Python, parsed text from the
    command line) as a list; a string or a single value refused in one line rather than
    iterated character by character.

    Raises
    ------
    SceneError
        ``value`` is a string, bytes or not iterable.
    """
    from collections.abc import Iterable

    if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        raise SceneError(f"{option} {value!r}: give a sequence of values, e.g. {example}")
    return list(value)


def mfpt_options(scene: Scene, sigma_rad: list[float] | None = None,
                 method: str | None = None, workers: int = 2) -> tuple[MfptSettings, int]:
    """The scene's ``mfpt`` section (defaults when absent) with ``--sigma-rad`` [rad] and
    ``--method`` applied, and the worker count; checked in that order.

    Raises
    ------
    SceneError
        An option out of bounds or ``sigma_rad`` not a sequence of numbers (one line, naming
        ``mfpt.sigma_rad`` / ``mfpt.method``).
    """
    st = scene.mfpt or MfptSettings()
    if sigma_rad is not None:
        sigma_rad = validate_option(MfptSettings, "sigma_rad",
                                    _sequence(sigma_rad, "--sigma-rad", "[0.002, 0.004]"),
                                    "--sigma-rad", "mfpt.sigma_rad")
    if method is not None:
        method = validate_option(MfptSettings, "method", method, "--method", "mfpt.method")
    workers = checked_workers(workers)
    st = st.model_copy(update={k: v for k, v in (("sigma_rad", sigma_rad), ("method", method))
                               if v is not None})
    return st, workers


def basin_options(scene: Scene, grid: tuple[int, int] | None = None, workers: int = 2
                  ) -> tuple[tuple[int, int], int]:
    """The basin grid (nx, ny) - ``--grid`` under the cap of ``basin.grid``, else the scene's
    (defaults when the section is absent) - and the worker count.

    Raises
    ------
    SceneError
        A grid that is not two whole numbers (a string, a single number), or a grid or
        worker count out of bounds (one line).
    """
    st = scene.basin or BasinSettings()
    if grid is not None:
        grid = validate_option(BasinSettings, "grid", tuple(_sequence(grid, "--grid", "(40, 40)")),
                               "--grid", "basin.grid")
    workers = checked_workers(workers)
    return tuple(grid or st.grid), workers


def stability_map_options(n: int, workers: int, max_step_maps: int
                          ) -> tuple[int, int, int]:
    """``--n`` (cells per axis), ``--workers`` and ``--max-step-maps`` (the work bound of a
    cell's search) of a stability map, within their :class:`CommandOptions` bounds.

    Raises
    ------
    SceneError
        An option out of bounds (one line).
    """
    n = validate_option(CommandOptions, "stability_map_n", n, "--n")
    workers = checked_workers(workers)
    max_step_maps = validate_option(CommandOptions, "stability_map_max_step_maps",
                                    int(max_step_maps), "--max-step-maps")
    return n, workers, max_step_maps


def bifurcation_options(n_transient: int, n_keep: int, workers: int) -> tuple[int, int, int]:
    """``--transient`` and ``--keep`` (steps discarded, heel strikes kept per grid value) and
    ``--workers``, within their :class:`CommandOptions` bounds.

    Raises
    ------
    SceneError
        An option out of bounds (one line).
    """
    n_transient = validate_option(CommandOptions, "bifurcation_transient", n_transient,
                                  "--transient")
    n_keep = validate_option(CommandOptions, "bifurcation_keep", n_keep, "--keep")
    return n_transient, n_keep, checked_workers(workers)


def with_terrain_seed(scene: Scene, seed: int | None) -> Scene:
    """The scene with ``simulate.terrain_seed`` set to ``seed`` (``--terrain-seed``; None
    keeps the scene's).

    Raises
    ------
    SceneError
        ``seed`` out of bounds, or no ``terrain.per_step`` to draw from (one line).
    """
    if seed is None:
        return scene
    from pydantic import ValidationError

    sim = scene.simulate or SimulateSettings()
    try:
        sim = SimulateSettings.model_validate({**sim.model_dump(), "terrain_seed": seed})
    except ValidationError as err:
        raise SceneError(f"--terrain-seed {seed}: {err.errors()[0]['msg'].lower()} "
                         "(simulate.terrain_seed)") from None
    if scene.terrain is None or scene.terrain.per_step is None:
        raise SceneError("--terrain-seed: the scene has no terrain.per_step (the "
                         "distribution of each step's slope and landing height to draw)")
    return scene.model_copy(update={"simulate": sim})


def with_strides(scene: Scene, strides: int | None) -> Scene:
    """The scene with ``simulate.strides`` set to ``strides`` (``--strides``; the section is
    created with its defaults when absent; None keeps the scene's number).

    Raises
    ------
    SceneError
        ``strides`` out of bounds: ``--strides 0: input should be ... (simulate.strides)``.
    """
    sim = scene.simulate or SimulateSettings()
    if strides is not None:
        from pydantic import ValidationError

        try:
            sim = SimulateSettings.model_validate({**sim.model_dump(), "strides": strides})
        except ValidationError as err:
            raise SceneError(f"--strides {strides}: {err.errors()[0]['msg'].lower()} "
                             "(simulate.strides)") from None
    return scene.model_copy(update={"simulate": sim})


def with_contact_strides(scene: Scene, strides: int | None) -> Scene:
    """The scene with ``contact_sim.n_strides`` set to ``strides`` (``contact-sim
    --strides``, as :func:`with_strides` for the rigid run; the section is created with its
    defaults when absent; None keeps the scene, bit for bit).

    Raises
    ------
    SceneError
        ``strides`` out of bounds: ``--strides 0: input should be ...
        (contact_sim.n_strides)``.
    """
    if strides is None:
        return scene
    n = validate_option(ContactSimSettings, "n_strides", strides, "--strides",
                        "contact_sim.n_strides")
    cs = (scene.contact_sim or ContactSimSettings()).model_copy(update={"n_strides": n})
    return scene.model_copy(update={"contact_sim": cs})


def map_not_applicable(scene: Scene, kind: str) -> str:
    """One line saying why stability-map ``kind`` does not apply to the scene, or "" if it
    does (a patch-width map needs the checkerboard terrain: on continuous ground there are
    no patches)."""
    terrain = scene.terrain
    if kind == "patch_width" and terrain is not None and terrain.lanes != "checkerboard":
        return (f"stability-map --kind patch_width does not apply to scene '{scene.name}': "
                f"its terrain is {terrain.lanes} ground, which has no patches (terrain.lanes)")
    return ""


def map_axis_value(scene: Scene, path: str) -> float:
    """The scene's value of a stability map's y field (dotted, ``contact.mu_static``; a
    missing ``terrain`` section at its defaults: ``terrain.patch_width_m`` 0.10 m); NaN
    when the scene has none (a missing ``contact`` section, a non-numeric field)."""
    d = scene.model_dump()
    d["terrain"] = d.get("terrain") or TerrainSettings().model_dump()
    for k in path.split("."):
        d = d.get(k) if isinstance(d, dict) else None
    return float(d) if isinstance(d, int | float) else math.nan
