"""A stage's figure, built from its loaded artifact and saved (PNG 150 dpi + SVG).

Each function takes the object an ``io.schemas`` loader returned, titles the figure and
writes ``<folder>/<stem>.png`` and ``.svg`` atomically (:func:`walkerlab.plotting.figures.save`).
matplotlib is imported on the first drawing only, so importing this module is cheap.
"""

from __future__ import annotations

from pathlib import Path


def save_mfpt_figure(d, scene_name: str, folder: Path | str) -> list[Path]:
    """log MFPT against sigma (:func:`walkerlab.plotting.mfpt_figures.mfpt_figure`) as
    ``mfpt.png/.svg``.

    Parameters
    ----------
    d : walkerlab.io.schemas.mfpt.MfptData
        A loaded ``mfpt.h5``.
    scene_name : str
        Named in the title.
    folder : path
        The report's figures folder.

    Returns
    -------
    list of Path
        The PNG and SVG written.
    """
    from walkerlab.plotting.figures import save  # light
    from walkerlab.plotting.mfpt_figures import mfpt_figure  # light

    fig = mfpt_figure(d, f"Mean first-passage time - scene '{scene_name}'")
    return save(fig, Path(folder), "mfpt")


def save_basin_figure(d, scene_name: str, folder: Path | str, stem: str = "basin"
                      ) -> list[Path]:
    """Outcome and steps-to-converge maps (:func:`walkerlab.plotting.basin_figures.basin_figure`)
    as ``<stem>.png/.svg``; a map on another grid than the scene's (``stem`` not
    ``basin``) says its grid in the title.

    Parameters
    ----------
    d : walkerlab.io.schemas.basin.BasinArtifact
        A loaded ``<stem>.h5``.
    scene_name : str
    folder : path
    stem : str
        ``basin`` or ``basin_<nx>x<ny>``.
    """
    from walkerlab.plotting.basin_figures import basin_figure  # light
    from walkerlab.plotting.figures import save  # light

    title = f"Basin of attraction - scene '{scene_name}'" + (
        "" if stem == "basin" else f" ({d.x.size}x{d.y.size} cells)")
    return save(basin_figure(d, title), Path(folder), stem)


def save_bifurcation_figure(data: dict, walker_model: str, scene_name: str,
                            folder: Path | str, stem: str) -> list[Path]:
    """Bifurcation diagram (:func:`walkerlab.plotting.sweep_figures.bifurcation_figure`) as
    ``<stem>.png/.svg``, titled by the walker model (``compass_gait`` -> "compass gait") and
    the scene.

    Parameters
    ----------
    data : dict
        :func:`walkerlab.io.schemas.bifurcation.load_bifurcation`'s result.
    """
    from walkerlab.plotting.figures import save  # light
    from walkerlab.plotting.sweep_figures import bifurcation_figure  # light

    model = walker_model.replace("_", " ")
    return save(bifurcation_figure(data, f"{model}, scene {scene_name}"), Path(folder), stem)


def save_gait_map_figure(data, folder: Path | str, stem: str) -> list[Path]:
    """Stability map of the contact gait
    (:func:`walkerlab.plotting.gait_map_figure.gait_map_figure`) as ``<stem>.png/.svg``.

    Parameters
    ----------
    data : walkerlab.io.schemas.stability_map.StabilityMap
        A loaded ``stability_map_<kind>.h5``.
    """
    from walkerlab.plotting.figures import save  # light
    from walkerlab.plotting.gait_map_figure import gait_map_figure  # light

    return save(gait_map_figure(data), Path(folder), stem)
