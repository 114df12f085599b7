"""scripts/capability_table.py (issue 48's walker family × capability table) builds its
cells: a straight-legged walker has no knee (n/a), its push-off builds and steps (the rigid
walker of configs/paper.yaml with a 0.05 N s push-off: one step from the scene's initial
guess), and the markdown row says so."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _script():
    spec = importlib.util.spec_from_file_location(
        "capability_table", ROOT / "scripts" / "capability_table.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_one_row_of_the_table():
    mod = _script()
    scene = mod.load("straight")
    cells = {"knee": mod.rigid_cell(scene, "knee", 30.0),
             "push_off": mod.rigid_cell(scene, "push_off", 30.0)}
    assert cells["knee"]["status"] == "n/a"
    assert cells["push_off"]["status"] == "accepted", cells["push_off"]
    # a step of the paper's walker from Eq. (11): ~0.72 s (its passive gait's is 0.7194 s)
    assert cells["push_off"]["detail"].startswith("one step: period 0.7")
    row = mod.markdown({"straight": cells}, ["knee", "push_off"]).splitlines()[-1]
    assert row == "| straight | n/a | ✓ |"
