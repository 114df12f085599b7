"""The batched step map integrates every row on its own (compiled DOP853,
:mod:`walkerlab.integrate.rows_dop853`) and resets heel strikes with the generated module's
compiled reset: a row's step does not depend on the other rows of its batch, and the
compiled reset is the walker's reset bit for bit."""

from pathlib import Path

import numpy as np
import pytest

from walkerlab.codegen.compiled import compiled_module
from walkerlab.config import load_scene
from walkerlab.integrate.batch_step import HEEL_STRIKE, BatchStepMap
from walkerlab.integrate.rows_dop853 import reset_rows
from walkerlab.models.registry import build_walker
from walkerlab.studies.mfpt import scene_walker_at

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def paper_map(paper_scene):
    return BatchStepMap(build_walker(paper_scene), scene_walker_at(paper_scene), 1e-9, 1e-9)


def test_a_rows_step_does_not_depend_on_its_batch(paper_scene, paper_map, paper_fixed_point):
    """Each row alone gives the same numbers, bit for bit, as inside a batch of 6 (a stacked
    integrator shares step sizes among rows, so its rows differed at ~1e-10; Monte Carlo walks
    and mesh images must not depend on how rows are grouped into tasks)."""
    rng = np.random.default_rng(5)
    X = paper_fixed_point.x + 0.005 * rng.standard_normal((6, 4))
    gam = paper_scene.slope.phi_rad + 0.003 * rng.standard_normal(6)
    r = paper_map.step(X, gam)
    assert (r.outcome == HEEL_STRIKE).sum() >= 4
    for i in range(6):
        one = paper_map.step(X[i:i + 1], gam[i:i + 1])
        assert one.outcome[0] == r.outcome[i]
        np.testing.assert_array_equal(one.x_next[0], r.x_next[i])
        np.testing.assert_array_equal(one.step_time_s[0], r.step_time_s[i])


@pytest.mark.parametrize("scene", ["paper.yaml", "kneed.yaml"])
def test_compiled_reset_is_the_walkers_reset(scene):
    """``reset_flow`` of the generated compiled module (a cfunc, same expressions as the
    Python ``reset``), applied row by row by ``rows_dop853.reset_rows``, gives the walker's
    heel-strike reset bit for bit, on two slopes."""
    sc = load_scene(ROOT / "configs" / scene)
    w = build_walker(sc)
    cf = w.phases[-1].compiled
    mod = compiled_module(cf.structure)
    n = w.layout().size
    X = 0.3 * np.random.default_rng(1).standard_normal((5, n))
    for gamma in (w.slope_rad, w.slope_rad + 0.02):
        wg = scene_walker_at(sc)(gamma)
        D = np.tile(wg.phases[-1].compiled.data(), (5, 1))
        out = np.empty_like(X)
        reset_rows(mod.reset_flow(), X, D, out)
        np.testing.assert_array_equal(out, np.array([wg.reset(x) for x in X]))


def test_compiled_walks_equal_step_after_step(paper_scene, paper_map, paper_fixed_point):
    """A whole walk in compiled code (``BatchStepMap.walk``: each step integrated through
    its phases without a restart at midstance) gives the same heel strikes and falls as
    ``step`` called step after step on the same slopes (sigma 0.01 rad: most walks fall
    within 12 steps, so both branches are met), its last states within 5e-8 of theirs
    (tolerances 1e-9; after up to 12 steps near a fall, 1.1e-8 seen) and about as close as
    theirs to the walks at 1e-12 (1.8e-8 against 1.0e-8 seen: the same accuracy; 3x
    allowed)."""
    rng = np.random.default_rng(11)
    W, S = 40, 12
    gam = paper_scene.slope.phi_rad + 0.01 * rng.standard_normal((W, S))
    assert paper_map.can_walk
    steps, fell, X_end = paper_map.walk(np.tile(paper_fixed_point.x, (W, 1)), gam)

    def by_steps(sm):
        X = np.tile(paper_fixed_point.x, (W, 1))
        alive = np.arange(W)
        ref = np.zeros(W, int)
        for s in range(S):
            r = sm.step(X[alive], gam[alive, s])
            ok = r.outcome == HEEL_STRIKE
            ref[alive[ok]] += 1
            X[alive[ok]] = r.x_next[ok]
            alive = alive[ok]
        return ref, alive, X
    ref, alive, X = by_steps(paper_map)
    np.testing.assert_array_equal(steps, ref)
    np.testing.assert_array_equal(fell, ~np.isin(np.arange(W), alive))
    assert 0 < fell.sum() < W
    np.testing.assert_allclose(X_end, X, rtol=0, atol=5e-8)  # (1.1e-8 seen)
    tight = BatchStepMap(build_walker(paper_scene), scene_walker_at(paper_scene), 1e-12, 1e-12)
    X_tight = by_steps(tight)[2]
    err_walk, err_steps = np.abs(X_end - X_tight).max(), np.abs(X - X_tight).max()
    assert err_walk < 3 * max(err_steps, 1e-9), (err_walk, err_steps)


def _toy_rows(direction_after: int, offset_after: float, column_after: int = 1):
    """``_step_row`` on the oscillator y'' = -y from (1, 0) (cfunc outputs: y, y', then the
    guards y and y'): phase 0 ends when y crosses 0 downwards (next phase, t = pi/2), phase
    1 at its guard: guard ``column_after`` (0: y, 1: y') + ``offset_after`` crossing in
    ``direction_after`` (heel strike)."""
    from numba import cfunc, types

    from walkerlab.integrate.rows_dop853 import _step_row, _work

    sig = types.void(types.CPointer(types.float64), types.float64,
                     types.CPointer(types.float64), types.CPointer(types.float64))

    @cfunc(sig)
    def osc(dy, t, y, d):  # pragma: no cover - compiled
        dy[0] = y[1]
        dy[1] = -y[0]
        dy[2] = y[0]
        dy[3] = y[1]

    f = osc
    gstart = np.array([0, 1, 2], np.int64)
    gcols = np.array([0, column_after], np.int64)
    goffs = np.array([0.0, offset_after])
    dirs = np.array([-1, direction_after], np.int64)
    gout = np.array([9, 0], np.int64)
    y, yev = np.array([1.0, 0.0]), np.empty(2)
    which, te = _step_row(f, y, np.zeros(1), 10.0, gstart, gcols, goffs, dirs, gout, 1e-10,
                          1e-10, yev, _work(2, 4, 1))
    return which, te, yev


@pytest.mark.parametrize("direction", [1, 0])
def test_a_step_switches_phase_inside_one_integration(direction):
    """The next phase's guard y' crossing 0 upwards (t = pi): with a direction (+1) the
    switch at t = pi/2 is taken without locating it (the guard's end value rules out a
    crossing), with none (0) it is located first; both end at t = pi, y = (-1, 0) to the
    tolerance.  A guard y + 0.01 crossing downwards is crossed just after the switch,
    inside the same integrator step: located from the switch on (t = pi/2 + asin 0.01)."""
    import math

    which, te, yev = _toy_rows(direction, 0.0)
    assert which == 1 and abs(te - math.pi) < 1e-8
    np.testing.assert_allclose(yev, [-1.0, 0.0], atol=1e-8)
    which, te, yev = _toy_rows(-1, 0.01, 0)
    assert which == 1 and abs(te - (math.pi / 2 + math.asin(0.01))) < 1e-8


def test_kneed_walker_keeps_the_step_by_step_walks():
    """A kneed walker (two flows, the knee strike's reset between phases) is not walked in
    one compiled call: ``can_walk`` is False and ``walk`` says why in one line."""
    sc = load_scene(ROOT / "configs" / "kneed.yaml")
    sm = BatchStepMap(build_walker(sc), scene_walker_at(sc), 1e-9, 1e-9)
    assert not sm.can_walk
    with pytest.raises(ValueError, match="compiled walks need"):
        sm.walk(np.zeros((1, sm.n)), np.zeros((1, 1)))
