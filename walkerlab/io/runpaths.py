"""The one place that builds run paths: ``<runs>/<scene name>/<file>``.

Every output of walkerlab lies inside the runs folder (``--runs-dir``, default ``runs``):

- names (a scene's ``name``, its file stem, a sweep's ``--name``) are checked: letters,
  digits and ``. _ + -`` only, no path separator, not starting with a dot (so no ``..``);
- every path is resolved (symbolic links followed) and must lie inside the resolved runs
  folder;
- a sweep cannot take the name of a stage artifact (``--name fixedpoint`` would replace
  ``fixedpoint.h5``);
- a run folder belongs to one scene file: the first scene file that writes into
  ``runs/<name>/`` records its resolved path in ``runs/<name>/.scene``; another file with the
  same name (``a/paper.yaml`` and ``b/paper.yaml``) is refused with one line (rename one, set
  ``name:`` or use another ``--runs-dir``).  When the recorded file no longer exists (the
  scene was moved or renamed), the folder passes to the new file.  Scenes built in code
  (sweeps, tests) have no file and are not checked;
- :func:`~walkerlab.io.locks.artifact_lock` serialises writers of one artifact across
  processes (``flock``; released by the kernel when a process dies, even by SIGKILL; a lock
  kept by a dead holder's descendant is taken over, never waited on);
- nothing is written through a symbolic link: lock files are opened with ``O_NOFOLLOW``,
  :func:`refuse_link` guards every other file walkerlab writes (a link in its place is a
  one-line error), and every folder written into (run, report and figure folders) must
  resolve inside the runs folder.

Raises
------
RunPathError
    One line naming the offending name, path or folder.
"""

from __future__ import annotations

import re
from pathlib import Path

from walkerlab.io.artifacts import atomic_write_all
from walkerlab.io.locks import ArtifactBusy, artifact_lock  # noqa: F401 (part of this API)
from walkerlab.io.stage_files import ARTIFACTS
from walkerlab.safefs import (  # noqa: F401 (part of this API)
    NotARegularFile,
    RunPathError,
    read_regular,
    refuse_link,
    remove_stale_temps,
)

__all__ = ["RunPathError", "ArtifactBusy", "check_name", "scene_dir", "stage_artifact",
           "named_artifact", "scene_file", "report_dir", "figures_dir", "run_cache_dir",
           "artifact_lock", "claimed", "refuse_link", "bifurcation_stem", "bifurcation_artifacts",
           "design_stem", "STAGE_FILES"]

NAME_RE = re.compile(r"^[A-Za-z0-9_+\-][A-Za-z0-9._+\-]*$")
MAX_NAME = 100

# File stems that belong to stages (a sweep or any free --name may not take them): every
# stage artifact's (walkerlab.io.stage_files.ARTIFACTS) and the other commands' names
STAGE_FILES = frozenset({a.schema for a in ARTIFACTS.values()}
                        | {"report", "plot", "sweep", "rigid_limit"})
STAGE_PREFIXES = ("stability_map", "stability-map",  # stability_map_<kind>.h5
                  "bifurcation_",                      # bifurcation_<field>.h5
                  "optimize_design")                   # optimize_design_<fields>_<measure>

ORIGIN_FILE = ".scene"
MAX_MARKER_BYTES = 8192  # a resolved path of the scene file


def check_name(name: str, what: str) -> str:
    """Return ``name`` if it is a safe single path component, else raise RunPathError.

    Parameters
    ----------
    name : str
        Candidate file or folder name.
    what : str
        What the name is, for the message (``"scene name"``, ``"--name"``).

    Raises
    ------
    RunPathError
        ``name`` is empty or is not a single safe path component (letters, digits and
        ``. _ + -`` only).
    """
    if not isinstance(name, str) or not name:
        raise RunPathError(f"{what}: empty name")
    if len(name) > MAX_NAME or not NAME_RE.match(name):
        raise RunPathError(f"{what} {name!r}: use letters, digits and . _ + - only (no path "
                           f"separators, not starting with a dot, at most {MAX_NAME} characters)")
    return name


def _inside(root: Path, path: Path, what: str) -> Path:
    root_r = root.resolve()
    path_r = path.resolve()
    if path_r != root_r and not path_r.is_relative_to(root_r):
        raise RunPathError(f"{what}: {path} resolves to {path_r}, outside the runs folder "
                           f"{root_r}")
    return path


def scene_dir(scene, runs_root: Path | str, claim: bool = False) -> Path:
    """``<runs>/<scene name>``, checked (and, with ``claim``, created and claimed).

    Parameters
    ----------
    scene : walkerlab.config.Scene
        Needs ``name`` and ``origin`` (resolved scene file or None).
    runs_root : Path or str
    claim : bool
        Create the folder and record the scene file as its owner (writers do this).

    Raises
    ------
    RunPathError
        Bad name, path outside the runs folder, or the folder belongs to another scene file.
    OSError
        The folder cannot be created (read-only runs folder, ...).
    """
    root = Path(runs_root)
    name = check_name(scene.name or "scene", "scene name")
    d = _inside(root, root / name, f"scene name {name!r}")
    origin = getattr(scene, "origin", None)
    if origin is None:
        if claim:
            _mkdir(d)
        return d
    marker = d / ORIGIN_FILE
    owner = _owner(marker)
    if owner is not None and owner != Path(origin) and owner.is_file():
        raise RunPathError(f"{d}: run folder of {owner}; {origin} has the same name "
                           f"{name!r}: set another 'name:' in one of them or use --runs-dir")
    if claim:
        _mkdir(d)
        if owner != Path(origin):
            atomic_text(marker, f"{origin}\n")
    return d


#: suffixes of walkerlab's temporary files in run folders (artifacts, figures, animation)
TEMP_SUFFIXES = (".tmp", ".gif", ".mp4")


def _owner(marker: Path) -> Path | None:
    """The scene file a run folder's marker names (None: no readable marker)."""
    try:  # a bounded regular file: a FIFO or /dev/zero in its place must not hang or fill RAM
        return Path(read_regular(marker, MAX_MARKER_BYTES, "run-folder marker")
                    .decode().strip())
    except NotARegularFile as exc:
        raise RunPathError(f"{exc}; remove it") from None
    except (OSError, UnicodeDecodeError, ValueError):
        return None


def claimed(scene, runs_root: Path | str) -> bool:
    """Whether the scene's run folder is already its own (its marker names the scene file,
    or the scene has none): a reader may then use it without claiming it (a read-only runs
    folder).

    Raises
    ------
    RunPathError
        As :func:`scene_dir`.
    """
    d = scene_dir(scene, runs_root)
    origin = getattr(scene, "origin", None)
    return origin is None or _owner(d / ORIGIN_FILE) == Path(origin)


def _mkdir(d: Path) -> None:
    """Create a run folder and remove the temporary files a killed run left in it."""
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RunPathError(f"{d}: cannot create the run folder ({exc.strerror})") from None
    remove_stale_temps(d, None, TEMP_SUFFIXES)


def stage_artifact(scene, runs_root: Path | str, stage: str, claim: bool = False) -> Path:
    """``<runs>/<scene>/<stage>.h5``: the stage's artifact file
    (:data:`walkerlab.io.stage_files.ARTIFACTS`: ``contact-sim`` -> ``contact_sim.h5``; another
    name, ``-`` as ``_``)."""
    a = ARTIFACTS.get(stage)
    return scene_dir(scene, runs_root, claim) / (
        a.file if a is not None else f"{stage.replace('-', '_')}.h5")


def bifurcation_stem(path: str) -> str:
    """File stem of a bifurcation artifact over the dotted scene field ``path``:
    ``bifurcation`` for the slope (``slope.angle_deg``, ``walkerlab bifurcation --slopes``),
    ``bifurcation_<path>`` for any other field
    (``bifurcation_walker.leg.bodies.thigh_mass.mass_kg``).

    Raises
    ------
    RunPathError
        The path does not make a safe file name.
    """
    if path == "slope.angle_deg":
        return "bifurcation"
    return check_name(f"bifurcation_{path}", "--param field")


def continuation_stem(path: str, path2: str | None = None) -> str:
    """File stem of a continuation artifact: ``continuation_<path>`` over one field (with
    or without period-doubling switches), ``continuation_<path>+<path2>`` for a run with
    the two-parameter curves over ``path2``, so neither replaces the other.

    Raises
    ------
    RunPathError
        The fields do not make a safe file name (at most 100 characters).
    """
    return check_name(f"continuation_{path}" + (f"+{path2}" if path2 else ""),
                      "--param field" + (" and --param2 field" if path2 else ""))


def design_stem(fields: list[str], objective: str, maximize: bool = False) -> str:
    """File stem of a design optimisation's artifact (``walkerlab optimize --design``), one
    per set of fields and objective, so that another design study does not replace it (as
    :func:`continuation_stem`): ``optimize_design_<field>[+<field>...]_<objective>``, with
    ``_maximize`` when maximised (``optimize_design_walker.hip_mass_kg_speed_maximize``);
    when that passes 100 characters (long or many fields) the fields are named by a hash
    (``optimize_design_<10 hex digits>_<objective>``).

    Raises
    ------
    RunPathError
        A field or the objective does not make a safe file name.
    """
    import hashlib

    tail = f"_{objective}" + ("_maximize" if maximize else "")
    stem = "optimize_design_" + "+".join(fields) + tail
    if len(stem) > MAX_NAME:
        digest = hashlib.sha256("+".join(fields).encode()).hexdigest()[:10]
        stem = f"optimize_design_{digest}{tail}"
    return check_name(stem, "--design field")


def bifurcation_artifacts(scene, runs_root: Path | str) -> dict[str, Path]:
    """``{stem: path}`` of the scene's bifurcation artifacts over fields other than the
    slope (``bifurcation_<field>.h5``), sorted by name."""
    d = scene_dir(scene, runs_root)
    return {p.stem: p for p in sorted(d.glob("bifurcation_*.h5")) if p.is_file()} \
        if d.is_dir() else {}


def named_artifact(scene, runs_root: Path | str, name: str, what: str = "--name",
                   claim: bool = False, allow_stage: str | None = None) -> Path:
    """``<runs>/<scene>/<name>.h5`` for a free-named artifact (sweep, stability map).

    Raises
    ------
    RunPathError
        Unsafe name, or a stage's artifact name (``fixedpoint``, ``simulate``, ...) other
        than ``allow_stage``.
    """
    stem = check_name(name.removesuffix(".h5"), what)
    if (stem in STAGE_FILES or stem.startswith(STAGE_PREFIXES)) and stem != allow_stage:
        raise RunPathError(f"{what} {name!r}: that is the name of the {stem!r} stage's "
                           "artifact; choose another name")
    d = scene_dir(scene, runs_root, claim)
    return _inside(Path(runs_root), d / f"{stem}.h5", f"{what} {name!r}")


def scene_file(scene, runs_root: Path | str, filename: str, claim: bool = False) -> Path:
    """``<runs>/<scene>/<filename>`` for a file that is not an HDF5 artifact (the exported
    ``walker.urdf`` / ``walker.xml``).

    Raises
    ------
    RunPathError
        Unsafe file name, or the scene's folder is not allowed (see :func:`scene_dir`).
    """
    name = check_name(filename, "file name")
    d = scene_dir(scene, runs_root, claim)
    return _inside(Path(runs_root), d / name, f"file name {filename!r}")


def report_dir(scene, runs_root: Path | str, claim: bool = False) -> Path:
    """``<runs>/<scene>/report`` (report.html, report.md); must resolve inside the runs
    folder (a ``report`` link to elsewhere is refused)."""
    d = _inside(Path(runs_root), scene_dir(scene, runs_root, claim) / "report", "report folder")
    if claim:
        _mkdir(d)
    return d


def figures_dir(scene, runs_root: Path | str, claim: bool = False) -> Path:
    """``<runs>/<scene>/report/figures`` (PNG + SVG); must resolve inside the runs folder."""
    d = _inside(Path(runs_root), report_dir(scene, runs_root, claim) / "figures",
                "figures folder")
    if claim:
        _mkdir(d)
    return d


def run_cache_dir(scene, runs_root: Path | str, name: str) -> Path:
    """``<runs>/<scene>/.cache/<name>`` (measured data such as work-precision cases; never
    code), which must resolve inside the runs folder.

    Raises
    ------
    RunPathError
        ``name`` is not a safe single path component (:func:`check_name`), or the folder
        resolves outside the runs folder (a symbolic link).
    """
    d = scene_dir(scene, runs_root) / ".cache" / check_name(name, "cache name")
    return _inside(Path(runs_root), d, f"cache folder {name!r}")


def atomic_text(path: Path, text: str) -> Path:
    """Write a text file atomically (temporary name, then rename), mode 0644."""
    from walkerlab.io.artifacts import atomic_write

    return atomic_write(path, lambda fh: fh.write(text.encode()))


def atomic_texts(items) -> list[Path]:
    """Write text files together, all or none (:func:`walkerlab.io.artifacts.
    atomic_write_all`): ``items`` is a sequence of ``(path, text)``."""
    return atomic_write_all([(p, lambda fh, t=t: fh.write(t.encode())) for p, t in items])
