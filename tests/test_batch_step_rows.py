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
    """``reset_rows`` of the generated compiled module (same expressions as the Python
    ``reset``) gives the walker's heel-strike reset bit for bit, on two slopes."""
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
        mod.reset_rows(X, D, out)
        np.testing.assert_array_equal(out, np.array([wg.reset(x) for x in X]))
