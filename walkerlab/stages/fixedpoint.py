"""Stage ``fixedpoint``: period-1 gait of the rigid hybrid walker -> ``fixedpoint.h5``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

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


def solve_variant(scene: Scene, variant: str):
    """Fixed point of one equation variant of the scene's walker (raises FixedPointNotFound)."""
    sc = scene.model_copy(update={"ideal": scene.ideal.model_copy(update={"variant": variant})})
    walker = build_walker(sc)
    fp = require(scene, "fixedpoint", "fixedpoint")
    try:
        guess = fp.initial_guess.as_array(walker.state_names())
    except ValueError as exc:
        raise StageError(f"fixedpoint.initial_guess: {exc}") from None
    res = find_fixed_point(walker, guess, Solver.from_settings(scene.solver),
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
    fp_cfg = require(scene, "fixedpoint", "fixedpoint")

    def compute():
        results = {}
        for variant in _variants_for(scene, compare_variants):
            try:
                results[variant] = solve_variant(scene, variant)
            except FixedPointNotFound as exc:
                if variant == scene.ideal.variant:
                    hint = ("; a passive walker needs a downhill slope (slope > 0), level or "
                            "uphill ground has no passive gait") if scene.slope.phi_rad <= 0 else ""
                    raise StageError(f"fixedpoint: {exc}{hint}") from None
                results[variant] = exc
        walker, main = results[scene.ideal.variant]
        guess = fp_cfg.initial_guess.as_array(walker.state_names())

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
            for v, r in results.items():
                if isinstance(r, Exception):
                    f.create_group(f"variants/{v}").attrs["error"] = str(r)
                else:
                    _write_result(f.create_group(f"variants/{v}"), r[0], r[1], guess)

        summary = {"walker": walker, "result": main,
                   "variants": {k: v for k, v in results.items()}}
        return writer, summary

    return run_cached("fixedpoint", scene, runs_root, SECTIONS, (), compute, force,
                      extra_key="variants" if compare_variants else "",
                      also_accept=() if compare_variants else ("variants",))
