"""Stage ``fixedpoint``: period-1 gait of the rigid hybrid walker -> ``fixedpoint.h5``.

The search is :func:`walkerlab.analysis.gait.scene.fixed_point_run`; the layout
:mod:`walkerlab.io.schemas.fixedpoint`.
"""

from __future__ import annotations

import json
from pathlib import Path

from walkerlab.config import Scene, SceneError, load_scene
from walkerlab.config.loader import default_scene_path
from walkerlab.io.artifacts import root_attrs, verified_hash
from walkerlab.io.freshness import input_hash
from walkerlab.io.runpaths import RunPathError, stage_artifact
from walkerlab.io.schemas.fixedpoint import load_fixedpoint, write_fixedpoint
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached
from walkerlab.walker.description import walker_data
from walkerlab.walker.plant import Plant

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint", "published")


def _known(scene: Scene, known) -> Scene | None:
    """The scene whose gait starts this one's search by homotopy (``--from`` or
    ``fixedpoint.from``), None without one; a bad one: StageError (one line)."""
    if known is None and getattr(scene.fixedpoint, "from_", None) is None:
        return None
    from walkerlab.studies.continuation import known_scene  # only for a homotopy start

    try:
        return known_scene(scene, known)
    except SceneError as exc:
        raise StageError(f"fixedpoint.from: {exc}") from None


def _from_key(src: Scene | None) -> str:
    """The input-hash key of a homotopy start from ``src`` (its scene's digest; "": none)."""
    if src is None:
        return ""
    import hashlib

    text = json.dumps(src.model_dump(mode="json"), sort_keys=True)
    return "from:" + hashlib.sha256(text.encode()).hexdigest()


#: root attribute of a fixedpoint.h5 found from a known gait (``--from``): its
#: :func:`_from_key`, so a later run without ``--from`` reuses the gait while the scene and
#: the code are unchanged
FROM_ATTR = "homotopy_from"


def _stored_from(scene: Scene, runs_root) -> str:
    """The :func:`_from_key` the scene's ``fixedpoint.h5`` was found with ("": none, or no
    artifact)."""
    key = root_attrs(stage_artifact(scene, runs_root, "fixedpoint"), FROM_ATTR)
    return str(key.get(FROM_ATTR, ""))


def _accepted(from_key: str, stored: str, compare_variants: bool) -> tuple[str, ...]:
    """The extra keys besides the one asked for whose artifact is up to date: the superset
    with the other equation variants, and a gait found from a known one (``stored``, when
    this run has no ``--from``: the same scene's gait whichever start found it)."""
    keys = [] if compare_variants else ["variants" + from_key]
    if stored and not from_key:
        keys += ["variants" + stored] + ([] if compare_variants else [stored])
    return tuple(keys)


def fresh_artifact(scene: Scene, runs_root: Path | str = "runs") -> Path | None:
    """``runs/<scene>/fixedpoint.h5`` when it is up to date for ``scene`` (what
    :func:`run` would reuse, with or without the other equation variants), else None
    (missing, stale, edited, or the scene's ``fixedpoint.from`` cannot be read).

    Read-only: nothing is computed or written, no lock is taken.
    """
    try:
        path = stage_artifact(scene, runs_root, "fixedpoint")
        from_key = _from_key(_known(scene, None))
    except (StageError, RunPathError, ValueError):
        return None
    if not path.is_file():
        return None
    have = verified_hash(path)
    if have is None:
        return None
    keys = ("variants" + from_key, from_key, *_accepted(from_key, _stored_from(
        scene, runs_root), False))
    if any(have == input_hash("fixedpoint", scene, SECTIONS, (), k) for k in keys):
        return path
    return None


def stored_gaits(scene: Scene, runs_root: Path | str) -> list:
    """The gaits of the other ``fixedpoint.h5`` in the runs folder (up to date or not, this
    scene's own stale one too) whose walker model is the scene's, as
    :class:`walkerlab.studies.warm_start.StoredGait` (the fixed point read only when one is
    chosen); unreadable ones are passed over."""
    from walkerlab.studies.warm_start import StoredGait  # only when the guess failed

    root = Path(runs_root)
    out = []
    try:
        paths = sorted(root.glob("*/fixedpoint.h5"))
    except OSError:
        return out
    for path in paths:
        attrs = root_attrs(path, "scene_json")
        try:
            stored = Scene.model_validate(json.loads(attrs["scene_json"]))
        except (KeyError, ValueError, SceneError):
            continue
        if stored.walker.model != scene.walker.model:
            continue
        out.append(StoredGait(stored, lambda p=path: load_fixedpoint(p).x,
                              f"{path.parent.name}/{path.name}"))
    return out


def guess_owners(scene: Scene) -> list:
    """The scenes a 3D walker's initial guess was written for: the scene files beside it
    and the shipped ones (``configs/``) of the same walker model with the same
    ``fixedpoint.initial_guess`` (a scene copied, then a number changed), as
    :class:`walkerlab.studies.warm_start.StoredGait` whose gait is found from that guess
    (only when chosen); unreadable files are passed over.

    A planar walker's search has its scale-free seeds after the guess; a 3D walker's seeds
    are a planar walker's (its lateral mode is unstable): it gets none here.

    Returns
    -------
    list of StoredGait
    """
    from walkerlab.studies.warm_start import StoredGait  # only when the guess failed
    if not _may_have_guess_owner(scene):
        return []
    mine = json.dumps(scene.model_dump(mode="json")["fixedpoint"]["initial_guess"],
                      sort_keys=True)
    folders = {default_scene_path().parent}
    if scene.origin is not None:
        folders.add(scene.origin.parent)
    out = []
    for path in sorted({f.resolve() for d in folders for f in d.glob("*.yaml")}):
        if path == scene.origin:
            continue
        try:
            other = load_scene(path)
        except (SceneError, OSError, ValueError):
            continue
        if (other.walker.model != scene.walker.model or other.fixedpoint is None
                or json.dumps(other.model_dump(mode="json")["fixedpoint"]["initial_guess"],
                              sort_keys=True) != mine):
            continue
        out.append(StoredGait(other, lambda o=other: _own_gait(o), path.name,
                              f"the gait of {path.name} (the scene whose initial guess this "
                              "scene's is: found from it)"))
    return out


def _may_have_guess_owner(scene: Scene) -> bool:
    """A 3D walker with an initial guess (a planar walker's search has its scale-free
    seeds): :func:`guess_owners` may find the scene its guess was written for."""

    fp = scene.fixedpoint
    return (fp is not None and fp.initial_guess is not None
            and walker_data(scene.walker, scene.slope.phi_rad).structure.kind.in_3d)


def _own_gait(scene: Scene):
    """The gait ``scene``'s own initial guess converges to (no fallback starts: a guess
    that fails there says so); ValueError when it does not."""
    from walkerlab.analysis.gait.scene import initial_guess, solve_scene  # light
    from walkerlab.analysis.gait.search import GaitNotFound  # light
    from walkerlab.models.registry import build_walker

    plant = Plant.from_scene(scene)  # the walker described once, handed down
    walker = build_walker(plant)
    try:
        _, search = solve_scene(scene, fd_check=False, guess=initial_guess(scene, walker),
                                walker=walker, other_gait=False, plant=plant)
    except GaitNotFound as exc:
        raise ValueError(str(exc)) from None
    return search.result.x


def _nearby(scene: Scene, runs_root, plant):
    """The nearest stored gait, or the gait of the scene the initial guess was written for
    (:func:`guess_owners`), as a fallback start of the gait search (carried here), or
    None; the scene files are read only when the start is tried."""
    from walkerlab.analysis.gait.starts import FallbackStart  # only for a compute
    from walkerlab.studies.warm_start import stored_gait_start  # light

    stored = stored_gaits(scene, runs_root)
    if not _may_have_guess_owner(scene):
        return stored_gait_start(scene, stored, plant=plant) if stored else None

    def find():  # the scene files are read only when the guess has failed
        start = stored_gait_start(scene, stored + guess_owners(scene), plant=plant)
        return None if start is None else start.find()

    return FallbackStart("the nearest stored gait, or the gait of the scene the initial "
                         "guess was written for", "stored_gait", find)


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        compare_variants: bool = True, known: Scene | Path | str | None = None
        ) -> StageOutcome:
    """Find the fixed point of the scene's equation variant.

    With ``compare_variants`` (the default) the other equation variants (printed Appendix A,
    ...) of a compass gait compared with published numbers are solved too, for the
    report's comparison with Eq. (11): ``walkerlab fixedpoint`` then writes the very artifact
    the report needs.  ``compare_variants=False`` reuses such an artifact (a superset).
    ``known`` (or the scene's ``fixedpoint.from``): a scene whose gait is carried to this
    walker by homotopy and used as the initial guess (``walkerlab fixedpoint --from``);
    the artifact it writes says so (:data:`FROM_ATTR`), and a later run without one
    reuses it while the scene's sections and the code are unchanged.

    Raises
    ------
    StageError
        No ``fixedpoint`` section, or no fixed point for the scene's own variant.
    """
    require(scene, "fixedpoint", "fixedpoint")
    src = _known(scene, known)
    from_key = _from_key(src)

    def compute():
        # the rigid analysis only when the gait is computed: a run that reuses fixedpoint.h5
        # (every downstream stage's upstream check) imports none of it
        from walkerlab.analysis.gait.scene import fixed_point_run  # light
        from walkerlab.analysis.gait.search import GaitNotFound  # light

        plant = Plant.from_scene(scene)  # the walker described once, handed down
        guess = note = nearby = None
        try:
            if src is not None:  # the known gait carried here
                from walkerlab.studies.continuation import homotopy_start  # light

                guess, note = homotopy_start(scene, src, plant=plant)
            else:  # a gait stored nearby: a start should the scene's own guess fail
                nearby = _nearby(scene, runs_root, plant)
            run, summary = fixed_point_run(scene, compare_variants, guess, note, nearby,
                                           plant=plant)
        except GaitNotFound as exc:
            raise StageError(f"fixedpoint: {exc}") from None
        except ValueError as exc:  # a malformed initial guess or gait choice (one line)
            raise StageError(str(exc)) from None
        return (lambda f: write_fixedpoint(f, run)), summary

    # a gait found with --from is reused by a run without it (report, simulate, ...) while
    # the scene and the code are unchanged: the start that found it is no input of the gait
    stored = "" if force or src is not None else _stored_from(scene, runs_root)
    return run_cached("fixedpoint", scene, runs_root, SECTIONS, (), compute, force,
                      extra_attrs={FROM_ATTR: from_key} if from_key else None,
                      extra_key=("variants" if compare_variants else "") + from_key,
                      also_accept=_accepted(from_key, stored, compare_variants))
