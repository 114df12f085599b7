"""Stage ``fixedpoint``: period-1 gait of the rigid hybrid walker -> ``fixedpoint.h5``."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from walkerlab.analysis.gaits import GaitNotFound, find_gaits
from walkerlab.analysis.hybrid import Solver
from walkerlab.analysis.poincare import FixedPointNotFound, find_fixed_point
from walkerlab.config import Scene
from walkerlab.io.artifacts import put
from walkerlab.io.netcdf import coordinate
from walkerlab.io.readers import load_fixed_point  # noqa: F401  (re-exported for stages)
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
        guess = fp.initial_guess.as_array(walker.state_names())
    except ValueError as exc:
        raise StageError(f"fixedpoint.initial_guess: {exc}") from None
    _check_walking_state(guess, walker, scene)
    return guess


#: largest leg angular rate of an initial guess, in units of sqrt(g/l)
MAX_GUESS_RATE = 20.0


def _check_walking_state(x, walker, scene: Scene) -> None:
    """Refuse a guess no walking gait is near, before the root finder spends minutes on it.

    A leg turning at ``omega`` needs a centripetal acceleration ``omega^2 l`` at its far end;
    above ``g`` the stance foot would leave the ground, so a walking gait has rates of the
    order of ``sqrt(g/l)`` (paper walker: 3.1 rad/s; its fixed point 0.86 rad/s).  Rates above
    :data:`MAX_GUESS_RATE` ``sqrt(g/l)`` (or angles beyond pi) send the map's integration
    into spinning legs (issue 26: 1e6 rad/s ran 74 s, then ``OverflowError``).

    Raises
    ------
    StageError
        One line naming the field, its value and the bound.
    """
    import math

    from walkerlab.units import for_scene

    g = walker.params.get("gravity_m_per_s2")
    length = walker.params.get("leg_length_m")
    if not g or not length:
        return
    units = for_scene(scene)
    max_rate = MAX_GUESS_RATE * math.sqrt(g / length)
    for name, v in zip(walker.state_names(), x, strict=True):
        if name.endswith("_rate") and abs(v) > max_rate:
            raise StageError(
                f"fixedpoint.initial_guess.{name}_rad_per_s: {v:g} is not a walking state: "
                f"give at most {max_rate:.3g} {units.rate} ({MAX_GUESS_RATE:g} sqrt(g/l); "
                "a leg this fast would leave the ground)")
        if name.endswith("_angle") and abs(v) > math.pi:
            raise StageError(f"fixedpoint.initial_guess.{name}_rad: {v:g} rad is more than "
                             "half a turn: give an angle within [-pi, pi]")


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


def _write_result(g, walker, res, guess) -> None:
    names = walker.state_names()
    units = walker.state_units()
    g.attrs["variant"] = walker.variant
    g.attrs["roles"] = list(walker.roles)
    g.attrs["legs_by_role"] = json.dumps(walker.role_to_leg("leg2"))
    for name, val, u in zip(names, res.x, units):
        put(g, f"fixed_point/{name}", float(val), u, f"{name} just after heel strike")
    for name, val, u in zip(names, guess, units):
        put(g, f"initial_guess/{name}", float(val), u, "root-finder starting point")
    put(g, "step_period", res.period_s, "s", "step period of the period-1 gait")
    put(g, "residual", res.residual, "rad or rad/s", "max |P(x*) - x*| over the state")
    for kind, ev, J in (("variational", res.multipliers_variational, res.jacobian_variational),
                        ("finite_difference", res.multipliers_fd, res.jacobian_fd)):
        put(g, f"floquet/{kind}/real", ev.real, "-", f"Floquet multipliers ({kind}), real part",
            dims=("multiplier",))
        put(g, f"floquet/{kind}/imag", ev.imag, "-", f"Floquet multipliers ({kind}), imag part",
            dims=("multiplier",))
        put(g, f"floquet/{kind}/jacobian", J, "-", "DP, rows/cols in state_names order",
            dims=("state", "state_in"), state_names=names)
    put(g, "floquet/max_difference", res.multiplier_difference, "-",
        "max |multiplier(variational) - multiplier(finite difference)|")
    put(g, "floquet/stable", res.stable, "-", "all |multipliers| < 1")
    put(g, "stats/nfev", res.nfev, "-", "right-hand-side evaluations")
    put(g, "stats/map_evaluations", res.iterations, "-", "Poincare-map calls by the root finder")
    put(g, "stats/wall_time", res.wall_time_s, "s", "fixed-point search + Jacobians")


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
        guess = search.gait.start

        def writer(f):
            f.attrs["model"] = walker.name
            f.attrs["variant"] = walker.variant
            f.attrs["state_names"] = walker.state_names()
            names = walker.state_names()
            coordinate(f, "state", names, "-", "state component (role-ordered)")
            coordinate(f, "state_in", names, "-", "state component perturbed (Jacobian column)")
            coordinate(f, "multiplier", np.arange(len(names)), "-",
                       "Floquet multiplier number (sorted by modulus)")
            _write_result(f, walker, main, guess)
            f.attrs["gait"] = search.gait.label
            f.attrs["gait_policy"] = search.policy
            f.attrs["gait_source"] = search.gait.source
            f.attrs["gaits"] = [g.label for g in search.gaits]
            f.attrs["gait_notes"] = json.dumps(search.notes)
            f.attrs["gait_search"] = json.dumps(search.tried)
            for g in search.gaits:
                grp = f.create_group(f"gaits/{g.label}")
                _write_result(grp, walker, g.result, g.start)
                grp.attrs["source"] = g.source
            for v, r in results.items():
                if isinstance(r, Exception):
                    f.create_group(f"variants/{v}").attrs["error"] = str(r)
                else:
                    _write_result(f.create_group(f"variants/{v}"), r[0], r[1],
                                  guess if v == scene.ideal.variant else
                                  (main.x if init is None else init))

        summary = {"walker": walker, "result": main, "gaits": search,
                   "variants": {k: v for k, v in results.items()}}
        return writer, summary

    return run_cached("fixedpoint", scene, runs_root, SECTIONS, (), compute, force,
                      extra_key="variants" if compare_variants else "",
                      also_accept=() if compare_variants else ("variants",))
