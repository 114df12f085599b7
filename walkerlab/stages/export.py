"""Stage ``export``: the scene's walker as a URDF or MJCF file in ``runs/<scene>/``.

Not an HDF5 artifact: an exchange file for multibody libraries (Drake, Pinocchio read URDF;
MuJoCo reads MJCF), written from the scene's ``walker`` and ``slope`` sections only (no
upstream artifact), atomically (temporary name, then rename).  Formats and conventions:
:mod:`walkerlab.export.multibody`.
"""

from __future__ import annotations

from pathlib import Path

import walkerlab
from walkerlab.config import Scene
from walkerlab.export.multibody import (
    FORMATS,
    SIDECAR,
    comments_in_scene_units,
    keyframe_json,
    mjcf_text,
    urdf_text,
)
from walkerlab.export.scene import check_exportable, mjcf_scene
from walkerlab.io import runpaths
from walkerlab.units import for_scene
from walkerlab.walker.description import walker_data
from walkerlab.walker.multibody import multibody


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
    """Write the scene's walker as ``fmt`` ("urdf" or "mjcf") into
    ``<runs_root>/<scene name>/`` and return the file's path.

    Raises
    ------
    ValueError
        Unknown format, or a walker with a massless link (a multibody model needs positive
        masses); one line.
    walkerlab.io.runpaths.RunPathError
        The run folder is not allowed.
    """
    path = export_path(scene, runs_root, fmt)  # check the format before building anything
    check_exportable(scene)
    data = walker_data(scene.walker, scene.slope.phi_rad)
    mb = multibody(data)
    name = scene.name or "walker"
    extra = mjcf_scene(scene, mb, data) if scene.fixedpoint is not None else None
    if fmt == "urdf":
        text = urdf_text(mb, name, walkerlab.__version__)
    else:
        text = mjcf_text(mb, name, walkerlab.__version__, extra)
    path = export_path(scene, runs_root, fmt, claim=True)
    if fmt == "urdf" and extra is not None:  # URDF has no state: the keyframe beside it
        runpaths.atomic_text(runpaths.scene_file(scene, runs_root, SIDECAR, claim=True),
                             keyframe_json(mb, extra))
    return runpaths.atomic_text(path, comments_in_scene_units(text, for_scene(scene)))
