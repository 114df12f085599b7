"""Issue 49, the rigid model on ground that differs from step to step: footholds of several
heights (a period-p Poincaré map, one walker per step), per-step random landing heights in
the MFPT study, and a replayable per-step ground (``simulate --terrain-seed``).

Physics checks against independent models (tests/independent/stairs_compass.py: its own
equations, impact map and heel-strike event, no walkerlab code).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from walkerlab.config import load_scene, scene_from_dict

ROOT = Path(__file__).resolve().parents[1]
INDEPENDENT = 1e-8  # the "fixed points and multipliers ... to 1e-8"


def _independent():
    sys.path.insert(0, str(ROOT / "tests" / "independent"))
    try:
        import stairs_compass
    finally:
        sys.path.pop(0)
    return stairs_compass


def _on_footholds(scene, heights, slope_rad=0.0, **extra):
    d = scene.model_dump(mode="json")
    d["slope"] = {"angle_rad": slope_rad}
    d["terrain"] = {"kind": "footholds", "foothold_heights_m": list(heights), **extra}
    return scene_from_dict(d)


def test_periodic_two_height_footholds_give_a_period_2_gait_of_an_independent_model(
        paper_scene):
    """Level ground, landings 8 mm and 12 mm below in turn (1 cm a step on average, as the
    shipped stairs): the period-2 gait's fixed point, map period and multipliers match the
    independent compass walker stepping down the same list (to 1e-8)."""
    from walkerlab.analysis.gait.scene import solve_scene

    sc = _on_footholds(paper_scene, [-0.008, -0.012])
    walker, search = solve_scene(sc)
    r = search.result
    assert walker.steps_per_map == 2 and r.residual < 1e-10
    ref = _independent().FootholdsCompass([0.008, 0.012])
    x = ref.fixed_point(r.x)
    assert np.max(np.abs(x - r.x)) < INDEPENDENT
    assert abs(ref.period(x) - r.period_s) < INDEPENDENT
    mu = np.sort_complex(ref.multipliers(x))
    assert np.max(np.abs(mu - np.sort_complex(r.multipliers_variational))) < INDEPENDENT
    # a period-2 orbit, not the stairs' period-1 gait run twice: the two steps differ
    assert abs(r.step_periods_s[0] - r.step_periods_s[1]) > 1e-3


def test_a_finite_foothold_list_ends_the_walk(paper_scene, paper_fixed_point):
    """``periodic: false``: a walk stops after the list's steps (here 3 of the 10 asked);
    footholds at the slope's own line reproduce the slope walk bit for bit."""
    from walkerlab.integrate.rigid import simulate_steps
    from walkerlab.integrate.solver import Solver
    from walkerlab.models.registry import build_walker

    phi = paper_scene.slope.phi_rad
    solver = Solver.from_settings(paper_scene.solver)
    sc = _on_footholds(paper_scene, [0.0, 0.0, 0.0], phi, periodic=False,
                       foothold_slopes_rad=[phi] * 3)
    w = build_walker(sc)
    tr = simulate_steps(w, paper_fixed_point.x, 10, solver)
    ref = simulate_steps(build_walker(paper_scene), paper_fixed_point.x, 3, solver)
    assert len(tr.segments) == 3 and tr.termination == "heel_strike"
    for a, b in zip(tr.segments, ref.segments):
        np.testing.assert_array_equal(a.x_next, b.x_next)
