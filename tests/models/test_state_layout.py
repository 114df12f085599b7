"""A sweep names its columns from the walker's description (no walker built): the names and
units must be those of the built walker, for every shipped scene."""

from pathlib import Path

import pytest

from walkerlab.config import load_scene
from walkerlab.models.registry import build_walker, state_layout
from walkerlab.walker.plant import Plant

CONFIGS = sorted((Path(__file__).resolve().parents[2] / "configs").glob("*.yaml"))


@pytest.mark.parametrize("path", CONFIGS, ids=[p.stem for p in CONFIGS])
@pytest.mark.slow  # in `pytest -m slow`: the quick suite keeps to its CPU budget
def test_state_layout_is_the_built_walkers(path):
    scene = load_scene(path)
    walker = build_walker(Plant.from_scene(scene))
    assert state_layout(Plant.from_scene(scene)) == (walker.state_names(), walker.state_units())
