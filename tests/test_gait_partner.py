"""The second period-1 gait (the partner of the long/short-period pair) found cheaply and
exactly: a deflated search at the screening tolerance, then a polish at the scene's
tolerance (walkerlab.analysis.gait.search.find_gaits)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from walkerlab.analysis.gait.search import find_gaits
from walkerlab.analysis.gait.starts import deflation_starts, step_length
from walkerlab.config import load_scene
from walkerlab.integrate.solver import Solver
from walkerlab.models.registry import build_walker
from walkerlab.walker.plant import Plant

ROOT = Path(__file__).resolve().parents[1]


def _search(name: str):
    scene = load_scene(ROOT / "configs" / name)
    walker = build_walker(Plant.from_scene(scene))
    fp = scene.fixedpoint
    guess = fp.initial_guess.as_array(walker.state_names())
    return walker, find_gaits(walker, Solver.from_settings(scene.solver), guess,
                              xtol=fp.tolerance)


def test_partner_is_polished_at_the_scenes_tolerance():
    """The paper walker's short-period gait (Goswami et al. 1996: the unstable partner of the
    stable long-period gait) comes from the first deflated start, and it is a fixed point to
    the full tolerance: max |P(x*) - x*| below 1e-10 (the screening pass alone stops near
    1e-7, rtol 1e-7 maps), with the variational and finite-difference multipliers agreeing
    to 1e-6 (finite differences give about 9 digits, Bhounsule 2014)."""
    walker, search = _search("paper.yaml")
    assert [g.label for g in search.gaits] == ["long_period", "short_period"]
    short = search.gaits[1]
    assert short.source == "deflation" and not short.result.stable
    assert search.tried[-1] == "1 deflated starts near the first gait"
    assert short.result.residual < 1e-10
    assert np.max(np.abs(short.result.multipliers_variational
                         - short.result.multipliers_fd)) < 1e-6
    assert short.result.period_s < search.gaits[0].result.period_s - 0.05


def test_deflation_starts_head_for_the_partners_step():
    """From a stable (long-period) gait the first start shortens the step; from its
    unstable short-period partner the first start lengthens it; each start is offset along
    one section coordinate, both ways."""
    walker, search = _search("paper.yaml")
    long_, short = (g.result for g in search.gaits)
    for first, sign in ((long_, -1.0), (short, 1.0)):
        starts = deflation_starts(walker, first)
        z = walker.section(first.x)
        assert len(starts) == 2 * z.size
        moved = [np.flatnonzero(np.abs(walker.section(x) - z) > 1e-12) for x in starts]
        assert all(m.size == 1 for m in moved)
        step0 = step_length(walker, first.x)
        assert sign * (step_length(walker, starts[0]) - step0) > 1e-3
