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
- :func:`artifact_lock` serialises writers of one artifact across processes (``flock``;
  released by the kernel when a process dies, even by SIGKILL).

Raises
------
RunPathError
    One line naming the offending name, path or folder.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

try:  # POSIX; elsewhere runs are not locked
    import fcntl
except ImportError:  # pragma: no cover
    fcntl = None

__all__ = ["RunPathError", "ArtifactBusy", "check_name", "scene_dir", "stage_artifact",
           "named_artifact", "report_dir", "figures_dir", "artifact_lock", "STAGE_FILES"]

NAME_RE = re.compile(r"^[A-Za-z0-9_+\-][A-Za-z0-9._+\-]*$")
MAX_NAME = 100

# File stems that belong to stages (a sweep or any free --name may not take them).
STAGE_FILES = frozenset({"fixedpoint", "simulate", "contact_sim", "compare", "workprecision",
                         "bifurcation", "basin", "report", "plot", "sweep"})
STAGE_PREFIXES = ("stability_map", "stability-map")  # stability_map_<kind>.h5

ORIGIN_FILE = ".scene"
MAX_MARKER_BYTES = 8192  # a resolved path of the scene file


class RunPathError(ValueError):
    """A name or output path is not allowed (one-line message)."""


class ArtifactBusy(RuntimeError):
    """Another process is writing the same artifact (one-line message)."""


def check_name(name: str, what: str) -> str:
    """Return ``name`` if it is a safe single path component, else raise RunPathError.

    Parameters
    ----------
    name : str
        Candidate file or folder name.
    what : str
        What the name is, for the message (``"scene name"``, ``"--name"``).
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
    from walkerlab.io.bounded import NotARegularFile, read_regular

    try:  # a bounded regular file: a FIFO or /dev/zero in its place must not hang or fill RAM
        owner = Path(read_regular(marker, MAX_MARKER_BYTES, "run-folder marker")
                     .decode().strip())
    except NotARegularFile as exc:
        raise RunPathError(f"{exc}; remove it") from None
    except (OSError, UnicodeDecodeError, ValueError):
        owner = None
    if owner is not None and owner != Path(origin) and owner.is_file():
        raise RunPathError(f"{d}: run folder of {owner}; {origin} has the same name "
                           f"{name!r}: set another 'name:' in one of them or use --runs-dir")
    if claim and owner != Path(origin):
        _mkdir(d)
        atomic_text(marker, f"{origin}\n")
    return d


def _mkdir(d: Path) -> None:
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RunPathError(f"{d}: cannot create the run folder ({exc.strerror})") from None


def stage_artifact(scene, runs_root: Path | str, stage: str, claim: bool = False) -> Path:
    """``<runs>/<scene>/<stage>.h5`` (``contact-sim`` -> ``contact_sim.h5``)."""
    return scene_dir(scene, runs_root, claim) / f"{stage.replace('-', '_')}.h5"


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


def report_dir(scene, runs_root: Path | str, claim: bool = False) -> Path:
    """``<runs>/<scene>/report`` (report.html, report.md)."""
    d = scene_dir(scene, runs_root, claim) / "report"
    if claim:
        _mkdir(d)
    return d


def figures_dir(scene, runs_root: Path | str, claim: bool = False) -> Path:
    """``<runs>/<scene>/report/figures`` (PNG + SVG)."""
    d = report_dir(scene, runs_root, claim) / "figures"
    if claim:
        _mkdir(d)
    return d


def model_cache_dir(runs_root: Path | str) -> Path:
    """``<runs>/.cache/models``: generated model code, shared by all scenes of a runs folder
    (content-keyed, see :mod:`walkerlab.models.cache`)."""
    return Path(runs_root) / ".cache" / "models"


def atomic_text(path: Path, text: str) -> Path:
    """Write a text file atomically (temporary name, then rename), mode 0644."""
    from walkerlab.io.artifacts import atomic_write

    return atomic_write(path, lambda fh: fh.write(text.encode()))


@contextmanager
def artifact_lock(path: Path, wait: bool = True,
                  on_wait: Callable[[str], None] | None = None) -> Iterator[None]:
    """Hold an exclusive lock on ``path`` (a hidden ``.<name>.lock`` next to it).

    Parameters
    ----------
    path : Path
        The artifact the caller is about to write.
    wait : bool
        Block until the other writer is done (stages: they then find its result up to date)
        or raise at once (sweeps: a second identical sweep must not run).
    on_wait : callable(str), optional
        Told once, in one line, that the caller waits.

    Raises
    ------
    ArtifactBusy
        ``wait=False`` and another process holds the lock.
    """
    path = Path(path)
    if fcntl is None:  # pragma: no cover
        yield
        return
    lock = path.with_name(f".{path.name}.lock")
    try:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as exc:
        raise RunPathError(f"{path.parent}: cannot write the run folder ({exc.strerror})") \
            from None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "?"
            msg = f"{path}: another walkerlab process (pid {holder}) is writing it"
            if not wait:
                raise ArtifactBusy(f"{msg}; wait for it to finish (or stop it) and rerun") \
                    from None
            if on_wait is not None:
                on_wait(f"{msg}; waiting")
            fcntl.flock(fd, fcntl.LOCK_EX)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield
    finally:
        os.close(fd)
