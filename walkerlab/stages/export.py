"""Stage ``export``: the scene's walker as a URDF or MJCF file in ``runs/<scene>/``.

Not an HDF5 artifact: an exchange file for multibody libraries (Drake, Pinocchio read URDF;
MuJoCo reads MJCF), written from the scene's ``walker`` and ``slope`` sections only (no
upstream artifact), atomically (temporary name, then rename).  Formats and conventions:
:mod:`walkerlab.io.export`.
"""

from __future__ import annotations

from pathlib import Path

import walkerlab
from walkerlab.config import Scene
from walkerlab.io import runpaths
from walkerlab.io.export import FORMATS, mjcf_text, urdf_text
from walkerlab.models.description import walker_data
from walkerlab.models.multibody import multibody
from walkerlab.units import for_scene


def export_path(scene: Scene, runs_root: Path | str, fmt: str, claim: bool = False) -> Path:
    """``runs/<scene>/walker.urdf`` (``fmt="urdf"``) or ``walker.xml`` (``fmt="mjcf"``).

    Raises
    ------
    ValueError
        Unknown format (one line).
    """
    if fmt not in FORMATS:
        raise ValueError(f"--format: unknown format {fmt!r} (choose {' or '.join(FORMATS)})")
    return runpaths.scene_file(scene, runs_root, FORMATS[fmt], claim)


def run(scene: Scene, runs_root: Path | str = "runs", fmt: str = "urdf") -> Path:
    """Write the scene's walker as ``fmt`` and return the file's path.

    Parameters
    ----------
    scene : Scene
    runs_root : Path or str
        Runs folder (the file goes to ``<runs_root>/<scene name>/``).
    fmt : {"urdf", "mjcf"}

    Returns
    -------
    Path

    Raises
    ------
    ValueError
        Unknown format, or a walker with a massless link (a multibody model needs positive
        masses); one line.
    walkerlab.io.runpaths.RunPathError
        The run folder is not allowed.
    """
    path = export_path(scene, runs_root, fmt)  # check the format before building anything
    mb = multibody(walker_data(scene.walker, scene.slope.phi_rad))
    text = (urdf_text if fmt == "urdf" else mjcf_text)(mb, scene.name or "walker",
                                                      walkerlab.__version__)
    path = export_path(scene, runs_root, fmt, claim=True)
    return runpaths.atomic_text(path, _comments_in_scene_units(text, for_scene(scene)))


def _comments_in_scene_units(text: str, units) -> str:
    """The header comments' unit labels in the scene's unit system (a nondimensional scene:
    ``l``, ``g``, not ``m``, ``m/s^2``); the XML itself carries numbers only."""
    if not units.nondimensional:
        return text
    import re

    # a unit follows a number ("1.2 m") or stands in brackets ("[m]"); prose is left alone
    unit = re.compile(r"(?:(?<=\d )|(?<=\[))(m/s\^2|kg m\^2|kg|m|s)(?=[\];.,) ])")
    return "\n".join(unit.sub(lambda m: units(m.group(1)), ln)
                     if ln.lstrip().startswith("<!--") else ln for ln in text.split("\n"))
