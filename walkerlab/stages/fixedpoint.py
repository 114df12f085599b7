"""Stage ``fixedpoint``: period-1 gait of the rigid hybrid walker -> ``fixedpoint.h5``."""

from __future__ import annotations

import math
from pathlib import Path

from walkerlab.analysis.gaits import GaitNotFound, find_gaits
from walkerlab.analysis.hybrid import Solver
from walkerlab.analysis.poincare import FixedPointNotFound, find_fixed_point
from walkerlab.config import Scene
from walkerlab.io.schemas.fixedpoint import FixedPointRun, write_fixedpoint
from walkerlab.models.registry import build_walker
from walkerlab.stages.common import StageError, StageOutcome, require, run_cached

SECTIONS = ("walker", "slope", "ideal", "solver", "fixedpoint", "published")


def _variants_for(scene: Scene, compare: bool) -> tuple[str, ...]:
    """The scene's own equation variant first, then (``compare``, for a compass gait compared
    with published numbers) the other variants: they explain the difference from Eq. 11."""
    own = (scene.ideal.variant,)
    if compare and scene.walker.model == "compass_gait" and scene.published is not None:
        from walkerlab.models.compass_gait import VARIANTS

        return own + tuple(v for v in VARIANTS if v != scene.ideal.variant)
    return own


def _guess(scene: Scene, walker):
    """The scene's initial guess by state name, or None (found automatically)."""
    fp = require(scene, "fixedpoint", "fixedpoint")
    if fp.initial_guess is None:
        return None
    try:
        return fp.initial_guess.as_array(walker.state_names())
    except ValueError as exc:
        raise StageError(f"fixedpoint.initial_guess: {exc}") from None


def _with_variant(scene: Scene, variant: str) -> Scene:
    return scene.model_copy(update={"ideal": scene.ideal.model_copy(update={"variant": variant})})


def solve_scene(scene: Scene, fd_check: bool = True):
    """The period-1 gait(s) of the scene's walker, chosen by ``fixedpoint.gait``.

    Returns
    -------
    walker : HybridWalker
    search : walkerlab.analysis.gaits.GaitSearch

    Raises
    ------
    GaitNotFound
        No gait (one line: what was tried, what to try next).
    StageError
        A malformed initial guess or gait choice.
    """
    fp = require(scene, "fixedpoint", "fixedpoint")
    walker = build_walker(scene)
    try:
        search = find_gaits(walker, Solver.from_settings(scene.solver), _guess(scene, walker),
                            policy=fp.gait, other_gait=fp.other_gait, xtol=fp.tolerance,
                            fd_step=fp.fd_step, max_step_time=fp.max_step_time_s,
                            fd_check=fd_check)
    except ValueError as exc:
        raise StageError(str(exc)) from None
    return walker, search


def solve_variant(scene: Scene, variant: str, guess=None):
    """Fixed point of one equation variant of the scene's walker, from ``guess`` (default:
    the scene's initial guess) - for the comparison of printed equations (raises
    FixedPointNotFound)."""
    sc = _with_variant(scene, variant)
    walker = build_walker(sc)
    fp = require(scene, "fixedpoint", "fixedpoint")
    g = _guess(scene, walker) if guess is None else guess
    if g is None:
        raise FixedPointNotFound("no initial guess for this equation variant", math.nan)
    res = find_fixed_point(walker, g, Solver.from_settings(scene.solver),
                           xtol=fp.tolerance, fd_step=fp.fd_step, max_step_time=fp.max_step_time_s)
    return walker, res


def run(scene: Scene, runs_root: Path | str = "runs", force: bool = False,
        compare_variants: bool = True) -> StageOutcome:
    """Find the fixed point of the scene's equation variant.

    With ``compare_variants`` (the default) the other equation variants (printed Appendix A,
    ...) of a compass gait compared with published numbers are solved too (~0.1 s), for the
    report's comparison with Eq. (11): ``walkerlab fixedpoint`` then writes the very artifact
    the report needs, so the report does not recompute it (nor the contact simulation, which
    keys on its content).  ``compare_variants=False`` reuses such an artifact (a superset).

    Raises
    ------
    StageError
        No ``fixedpoint`` section, or no fixed point for the scene's own variant.
    """
    require(scene, "fixedpoint", "fixedpoint")

    def compute():
        try:
            walker, search = solve_scene(scene)
        except GaitNotFound as exc:
            raise StageError(f"fixedpoint: {exc}") from None
        main = search.result
        results = {scene.ideal.variant: (walker, main)}
        init = _guess(scene, walker)
        for variant in _variants_for(scene, compare_variants)[1:]:
            try:
                results[variant] = solve_variant(scene, variant,
                                                 main.x if init is None else init)
            except FixedPointNotFound as exc:
                results[variant] = exc
        run = FixedPointRun(walker, search, results, scene.ideal.variant,
                            main.x if init is None else init)
        summary = {"walker": walker, "result": main, "gaits": search,
                   "variants": {k: v for k, v in results.items()}}
        return (lambda f: write_fixedpoint(f, run)), summary

    return run_cached("fixedpoint", scene, runs_root, SECTIONS, (), compute, force,
                      extra_key="variants" if compare_variants else "",
                      also_accept=() if compare_variants else ("variants",))
