"""The Monte Carlo walks' slope streams drawn for many walks at once
(:mod:`walkerlab.analysis.robustness.slope_stream`) are the per-walk NumPy streams of
``draw_slopes`` bit for bit, so the walks and the shipped MFPT numbers do not change."""

import numpy as np
import pytest

from walkerlab.analysis.robustness import mfpt as M
from walkerlab.analysis.robustness.slope_stream import slope_rows
from walkerlab.integrate.batch_step import BatchStepMap
from walkerlab.models.registry import build_walker
from walkerlab.studies.mfpt import scene_walker_at
from walkerlab.walker.plant import Plant


def test_draw_slopes_stream_is_pinned():
    """The first slopes of one walk as drawn before the change (NumPy's PCG64 and ziggurat
    on ``SeedSequence(5, spawn_key=(17,))``): a different stream fails here."""
    assert M.draw_slopes(5, 17, 3, 0.01, 0.002).tolist() == [
        0.009488771964797518, 0.004431233023424911, 0.011411737196432414]
    assert M.draw_slopes(5, 17, 3, 0.01, 0.002, "uniform").tolist() == [
        0.011831083110734286, 0.012576023418586602, 0.009520115378424806]


@pytest.mark.parametrize("seed", [0, 1, 5, 2**32 + 5, 2**70 + 3])
@pytest.mark.parametrize("distribution", ["normal", "uniform"])
def test_slope_rows_equal_draw_slopes_bit_for_bit(seed, distribution):
    walks = [0, 1, 2, 17, 499, 2**32 - 1]
    got = slope_rows(seed, walks, 7, 60, 0.01, 0.002, distribution)
    ref = np.stack([M.draw_slopes(seed, w, 67, 0.01, 0.002, distribution)[7:] for w in walks])
    np.testing.assert_array_equal(got, ref)


def test_the_streams_are_seeded_by_numpys_public_seed_sequence(monkeypatch):
    """Issue 56 item 16: the streams were seeded by a copy of NumPy's SeedSequence hashing
    and PCG64 seeding (its internals, with no upper bound on NumPy); they are seeded by
    ``np.random.SeedSequence`` itself, one per walk, and stay ``draw_slopes``' bit for bit
    (the pinned stream above)."""
    made = []
    real = np.random.SeedSequence

    def seed_sequence(*a, **k):
        made.append(k.get("spawn_key"))
        return real(*a, **k)

    monkeypatch.setattr(np.random, "SeedSequence", seed_sequence)
    got = slope_rows(5, [17, 3], 0, 3, 0.01, 0.002)
    assert made == [(17,), (3,)]
    assert got[0].tolist() == [0.009488771964797518, 0.004431233023424911,
                               0.011411737196432414]


def test_long_normal_stream_reaches_the_tails_and_stays_equal():
    """2e5 normals of one walk: the ziggurat's rejection and tail branches are taken."""
    got = slope_rows(11, [4], 0, 200_000, 0.0, 1.0)[0]
    np.testing.assert_array_equal(got, M.draw_slopes(11, 4, 200_000, 0.0, 1.0))
    assert np.abs(got).max() > 3.8


def test_bad_seed_or_walk_is_one_clear_error():
    with pytest.raises(ValueError, match="non-negative"):
        slope_rows(-1, [0], 0, 3, 0.0, 1.0)
    with pytest.raises(ValueError, match="walk numbers"):
        slope_rows(1, [2**32], 0, 3, 0.0, 1.0)


def test_monte_carlo_walks_equal_walks_on_draw_slopes(paper_scene, paper_fixed_point):
    """The compiled walks of ``monte_carlo`` equal the same walks on ``draw_slopes``' slopes
    (walk numbers not from 0), with falls (sigma 0.004 rad, MFPT ~ 32 steps) and censored walks."""
    sm = BatchStepMap(build_walker(plant := Plant.from_scene(paper_scene)),
                        scene_walker_at(paper_scene, plant), 1e-9, 1e-9)
    assert sm.can_walk
    x0 = np.asarray(paper_fixed_point.x, float)
    walks, sd, seed, cap = list(range(3, 27)), 0.004, 5, 40
    got = M.monte_carlo(sm, x0, sd, walks, cap, seed)
    slopes = np.stack([M.draw_slopes(seed, w, cap, sm.slope_rad, sd) for w in walks])
    steps, fell, _ = sm.walk(np.tile(x0, (len(walks), 1)), slopes)
    np.testing.assert_array_equal(got.steps, steps)
    np.testing.assert_array_equal(got.fell, fell)
    assert 0 < fell.sum() < len(walks)
