"""Stage ``optimize``: a periodic gait by direct collocation -> ``optimize.h5``.

Reads the scene's ``optimize`` section and its gait from ``fixedpoint.h5`` (the pipeline
runs ``fixedpoint`` first, :mod:`walkerlab.stages.pipeline`; the collocation starts from
one step of it; a five-link biped's from its targets, no upstream gait), optimises by
:func:`walkerlab.optimal.driver.optimize_scene` (CasADi + IPOPT; the one driver: a step, a
step of phases, a stride or a five-link biped's step, replayed on the rigid and contact
models) and writes the optimum's records (:func:`walkerlab.io.schemas.optimize.
optimize_record`).  Skipped when the scene sections, the upstream gait and the code are
unchanged.
"""

from __future__ import annotations

from pathlib import Path

from walkerlab.config import Scene
from walkerlab.io.freshness import NOT_FINAL_ATTR
from walkerlab.io.runpaths import design_stem, stage_artifact
from walkerlab.io.schemas import optimize as schema
from walkerlab.io.schemas.fixedpoint import load_fixedpoint
from walkerlab.stages.common import (
    StageError,
    StageOutcome,
    require,
    run_cached,
    with_defaults,
)
from walkerlab.walker.plant import Plant

#: the sections optimize.h5 depends on (the contact ones: its contact replay)
SECTIONS = ("walker", "slope", "ideal", "solver", "optimize", "contact", "terrain",
            "contact_solver")


def check(scene: Scene, **options) -> None:
    """Refuse, before any upstream stage runs, an optimisation CasADi is missing for.

    Raises
    ------
    walkerlab.extras.MissingExtra
        CasADi is not installed (one line naming the ``optimize`` extra).
    ValueError
        A walker kind or feature the collocation does not take (the capability table's
        line), a swing-foot clearance that cannot hold (``optimize.min_clearance_m > 0`` on
        straight legs: :func:`walkerlab.optimal.driver.check_scene`; one line).
    """
    from walkerlab.extras import require
    from walkerlab.optimal.driver import check_scene

    require("casadi", "optimize", "walkerlab optimize")
    check_scene(scene, Plant.from_scene(scene).data)


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False) -> StageOutcome:
    """Compute (or reuse) ``optimize.h5``.

    Raises
    ------
    StageError
        A walker the collocation does not handle, or the optimisation failed (one line,
        chained to its origin for the debug trace); a five-link biped without a target
        in its ``optimize`` section, or without the section (its step is built from the
        targets).  A missing ``optimize`` section of another walker runs with its
        defaults (said in one note), a missing ``fixedpoint`` section with its.  A walker
        kind the collocation does not take (the capability table's line).
    """
    from walkerlab.optimal.driver import check_targets, guess_from_targets, no_gait_of_its_own
    from walkerlab.optimal.virtual_constraints import designs_controller

    missing = getattr(scene, "optimize", None) is None
    scene = with_defaults(scene, "optimize", "optimize")  # a missing section: its defaults
    plant = Plant.from_scene(scene)  # the walker described once, handed down
    if designs_controller(scene):  # starts from the scene's own controller, no upstream
        try:
            check(scene)
        except ValueError as exc:
            raise StageError(str(exc)) from exc
        out = _run_optimum(scene, runs_root, force, None, (), plant)
        write_controller_scenes(scene, out.path)
        return out
    try:
        from_targets = guess_from_targets(scene, plant)
    except ValueError as exc:  # a kind the collocation does not take
        raise StageError(str(exc)) from exc
    if from_targets:  # a five-link biped: its guess is built from the targets
        try:
            check_targets(scene.optimize)  # at once, before the collocation is built
        except ValueError as exc:
            raise StageError((f"scene '{scene.name}' has no 'optimize' section; "
                              if missing else "optimize: ") + str(exc)) from exc
        return _run_optimum(scene, runs_root, force, None, (), plant)
    if missing:
        from walkerlab import progress

        progress.note(f"optimize: scene '{scene.name}' has no 'optimize' section: its "
                      "defaults (least effort int u^2 dt over 40 intervals, the scene's "
                      "push-off fixed, no targets or limits)")
    if no_gait_of_its_own(scene):  # no gait to start from: a step from the targets
        return _run_from_targets(scene, runs_root, force, plant)
    require(scene, "fixedpoint", "optimize")
    up = stage_artifact(scene, runs_root, "fixedpoint")

    return _run_optimum(scene, runs_root, force, up, (up,), plant)


def _run_optimum(scene: Scene, runs_root, force: bool, gait, upstream,
                 plant: Plant) -> StageOutcome:
    """``optimize.h5`` of the scene's optimum (:func:`walkerlab.optimal.driver.
    optimize_scene` of ``plant``, started from the gait of the artifact ``gait``, or from
    the targets when None), its records built here (:func:`walkerlab.io.schemas.optimize.
    optimize_record`, the energies in the scene's unit)."""
    from walkerlab.optimal.driver import optimize_scene
    from walkerlab.units import for_scene

    def compute():
        start = (None, None)
        if gait is not None:
            fp = load_fixedpoint(gait)
            start = (fp.x, fp.step_period_s)
        try:
            optimum = optimize_scene(scene, *start, plant=plant)
        except ValueError as exc:
            raise StageError(str(exc)) from exc
        data = schema.optimize_record(optimum, for_scene(scene).energy)
        cut = cpu_limited(data)

        def writer(f):
            schema.write(f, data)
            if cut:  # a user's CPU-time limit decided it: shown, never reused
                f.attrs[NOT_FINAL_ATTR] = cut
        return writer, {"data": data}

    return run_cached("optimize", scene, runs_root, SECTIONS, upstream, compute, force)


def cpu_limited(data) -> str:
    """What a user's CPU-time limit (``optimize.cpu_budget_s``) cut short in the optimum's
    records ``data``: the controllers IPOPT stopped at it (``Maximum_CpuTime_Exceeded``),
    "" when none (IPOPT's iterations, ``optimize.max_iterations``, end the same way on any
    machine: such a design is a result)."""
    cut = [str(i + 1) for i, c in enumerate(getattr(data, "controllers", None) or ())
           if getattr(c, "status", "") == "Maximum_CpuTime_Exceeded"]
    return (f"controller(s) {', '.join(cut)}: optimize.cpu_budget_s, a CPU-time limit"
            if cut else "")


def write_controller_scenes(scene: Scene, artifact: Path) -> list[Path]:
    """Write the scene of every controller ``optimize.h5`` (``artifact``) holds beside it
    (``controllers/<i>``' ``scene_file``: the scene with the optimised coefficients,
    :func:`walkerlab.optimal.virtual_constraints.controller_scene_text`; a controller IPOPT
    did not converge on says so in its header), each to a temporary name and then renamed
    (a file either old or whole), then remove the scene's other controller scenes there
    (``<scene>_controller_<i>.yaml`` of an earlier design with more target speeds): the
    run folder's controller scenes are exactly those of ``optimize.h5``.  Returns the
    paths."""
    import os
    import re

    from walkerlab.optimal.virtual_constraints import controller_scene_text
    from walkerlab.safefs import atomic_replace, refuse_link

    folder = Path(artifact).parent
    paths = []
    d = schema.load(artifact)
    for c in d.controllers:
        path = refuse_link(folder / c.scene_file)
        text = controller_scene_text(scene, c, Path(c.scene_file).stem, d.violations).encode()

        def fill(fd, _tmp, text=text):
            with os.fdopen(fd, "wb") as fh:
                fh.write(text)
        atomic_replace(path, fill, mode=0o644, suffix=".yaml.tmp", name=path.stem)
        paths.append(path)
    mine = re.compile(re.escape(scene.name) + r"_controller_\d+\.yaml")
    keep = {p.name for p in paths}
    for old in folder.iterdir():
        if mine.fullmatch(old.name) and old.name not in keep and not old.is_dir():
            old.unlink(missing_ok=True)  # one file, removed whole (unlink is atomic)
    return paths


def _run_from_targets(scene: Scene, runs_root, force: bool, plant: Plant) -> StageOutcome:
    """``optimize.h5`` of a walker with no gait of its own (a passive walker on level
    ground: :func:`walkerlab.optimal.driver.no_gait_of_its_own`): no upstream gait, the
    starting step built from the targets (:func:`walkerlab.optimal.guess.target_step`);
    refused at once without them."""
    from walkerlab.optimal.guess import has_target, stairs_targets, target_numbers

    o = stairs_targets(scene)  # on stairs the step is the tread
    try:
        if not has_target(o):
            raise ValueError("the walker has no gait of its own (passive, on level or uphill "
                             "ground): its optimal gait starts from the targets; give "
                             "optimize.target_speed_m_per_s and target_step_length_m (or a "
                             "downhill slope, or optimize.initial_guess)")
        target_numbers(o, 1.0)  # enough targets for a step: refused at once
    except ValueError as exc:
        raise StageError(f"optimize: {exc}".replace("optimize: optimize: ", "optimize: ")) \
            from exc
    return _run_optimum(scene, runs_root, force, None, (), plant)


def run_design(scene: Scene, runs_root: Path | str, force: bool, bounds: dict,
               objective: str, maximize: bool = False) -> StageOutcome:
    """Compute (or reuse) the design optimisation's artifact
    ``optimize_design_<fields>_<objective>[_maximize].h5``
    (:func:`walkerlab.io.runpaths.design_stem`: one per set of fields and objective, so
    another study does not replace it): the fields within ``bounds``
    (``{field: (lo, hi)}``) that minimise (``maximize``: maximise) the gait measure
    ``objective`` (:func:`walkerlab.optimal.design.search.design_optimize`).

    Raises
    ------
    StageError
        An unknown objective or field, or no gait along the way (one line).
    """
    from walkerlab.analysis.gait.poincare import FixedPointNotFound
    from walkerlab.optimal.design.search import design_optimize

    require(scene, "fixedpoint", "optimize")
    up = stage_artifact(scene, runs_root, "fixedpoint")

    def compute():
        try:
            r = design_optimize(scene, bounds, objective, load_fixedpoint(up).x, maximize,
                                plant=Plant.from_scene(scene))  # described once, handed down
        except (ValueError, FixedPointNotFound) as exc:
            msg = str(exc)
            raise StageError(msg if msg.startswith("optimize --design")
                             else f"optimize --design: {msg}") from exc
        return (lambda f: schema.write_design(f, r)), {"design": r}

    key = repr((sorted(bounds.items()), objective, maximize))
    return run_cached(schema.DESIGN_STAGE, scene, runs_root, ("walker", "slope", "ideal",
                                                              "solver"), (up,), compute,
                      force, extra_key=key,
                      artifact=design_stem(list(bounds), objective, maximize))


def draw(scene: Scene, runs_root: Path | str = "runs", svg: bool = True,
         keep_current: bool = False) -> list[Path]:
    """Draw ``optimize.png`` (PNG + SVG; ``svg`` False: the PNG alone) from
    ``optimize.h5``; the PNG carries the key of what it was drawn from
    (:mod:`walkerlab.plotting.figure_cache`).  ``keep_current`` (the PNG alone): keep a PNG
    drawn from the artifact's result as it is now (the same result, code and matplotlib)
    instead of drawing it again: the figure it would draw (``walkerlab optimize`` rerun on
    a fresh artifact, or recomputed to the same result)."""
    from walkerlab.io.runpaths import figures_dir
    from walkerlab.plotting.figure_cache import drawn_from, figure_key

    art = stage_artifact(scene, runs_root, "optimize")
    folder = figures_dir(scene, runs_root)
    key = figure_key(art, "optimize")  # stored in the PNG drawn
    if keep_current and not svg and drawn_from(folder / "optimize.png", key):
        (folder / "optimize.svg").unlink(missing_ok=True)  # as a PNG-only draw does
        return [folder / "optimize.png"]
    from walkerlab.plotting.optimize_figure import save_optimize_figure

    d = schema.load(art)
    sticks = None
    # a five-link biped's open-loop step: its stop action
    if d.torque_names != ("hip",) and not d.controllers:
        from walkerlab.optimal.free_joints import stick_figures

        sticks = stick_figures(Plant.from_scene(scene).data, d)
    return save_optimize_figure(d, scene.name, folder, sticks, svg, key)


def draw_design(scene: Scene, runs_root: Path | str, fields: list[str], objective: str,
                maximize: bool = False) -> list[Path]:
    """Draw the design optimisation's figure ``<stem>.png`` (PNG + SVG) from its artifact
    ``<stem>.h5`` (``stem``: :func:`walkerlab.io.runpaths.design_stem` of ``fields``,
    ``objective`` and ``maximize``)."""
    from walkerlab.io.runpaths import figures_dir
    from walkerlab.plotting.design_figure import save_design_figure

    stem = design_stem(list(fields), objective, maximize)
    d = schema.load_design(stage_artifact(scene, runs_root, stem))
    return save_design_figure(d, scene.name, figures_dir(scene, runs_root), stem)
