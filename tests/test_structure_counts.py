"""``scripts/structure_counts.py`` measures the package's structure (the structure table):
it runs on the package, reports a number for every row, and the rows already at their
goal stay there."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.scripts_loader import load_file

ROOT = Path(__file__).resolve().parents[1]


def _script():
    return load_file("scripts/structure_counts.py")


@pytest.fixture(scope="module")
def rows():
    return _script().measure(ROOT, duplicates=False)


def test_the_counts_script_reports_every_row_and_the_rows_at_goal_stay_there(rows):
    rows = {r["name"]: r for r in rows}
    assert len(rows) == 18
    for name, r in rows.items():
        if "duplicate" not in name:
            assert isinstance(r["value"], int) and r["value"] >= 0, name
    assert rows["import circles"]["value"] == 0
    # the walker described once, by the front (walkerlab.walker.plant.Plant), handed down
    assert rows["modules calling walker_data(...) outside walker/, stages/, api/, cli/, bench/"][
        "value"] == 0
    below = next(r for n, r in rows.items() if n.startswith("modules below the front building"))
    assert below["value"] <= below["goal"] == 4
    assert rows["arrows back up (imports from a lower floor to a higher one)"]["value"] == 0
    assert rows["arrows back up (imports from a lower floor to a higher one)"]["detail"][
        "packages in no floor"] == []
    # rows measured > 0 today: the readers see what they count (a reader that saw nothing
    # would pass every goal vacuously)
    assert rows["modules writing the Christoffel symbols"]["value"] >= 1
    assert rows['files with the literal "contact-sim"']["value"] >= 1
    codegen = rows["lines in walkerlab/codegen/ (the derivations and their printers)"]
    assert codegen["value"] == sum(codegen["detail"].values()) > 1000
    # no function that takes a plant describes the walker itself when handed none
    fallbacks = rows["functions below the front describing the walker when handed no plant"]
    assert fallbacks["value"] == 0


def test_the_description_reader_sees_a_description_below_the_front_but_not_the_gyms_constructor():
    """``Plant.from_scene(...)`` and ``walker_data(...)`` are descriptions (another
    ``from_scene`` is not); in ``gym/`` those inside the constructor are the front's."""
    import ast

    mod = _script()
    tree = ast.parse("class Env:\n    def __init__(self, s):\n        Plant.from_scene(s)\n"
                     "    def reset(self, s):\n        walker_data(s.walker, 0.0)\n"
                     "        Walker.from_scene(s)\n")
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call)]
    described = [n for n in calls if mod._describes(n)]
    assert [mod._call_name(n) for n in described] == ["from_scene", "walker_data"]
    front = mod._front_calls(tree, "gym")
    assert [n.lineno for n in described if id(n) not in front] == [5]
    assert mod._front_calls(tree, "studies") == set()
    assert "rigid_walker" not in mod.FRONT and {"stages", "api", "cli", "bench"} <= set(mod.FRONT)


def test_the_arrow_reader_sees_an_import_that_climbs(tmp_path):
    """A module of a low floor importing a higher one, inside a function, is an arrow."""
    import ast

    mod = _script()
    pkg = tmp_path / "walkerlab"
    (pkg / "io").mkdir(parents=True)
    f = pkg / "io" / "x.py"
    f.write_text("def f():\n    from walkerlab.analysis.gait import friction\n"
                 "    from ..api import walker\n")
    got = [t for _, t in mod._walkerlab_imports(ast.parse(f.read_text()), f, pkg)]
    assert got == ["analysis.gait", "api"]
    layers = _script()._layers_module().LAYERS
    assert mod._floor("io/x.py", layers) < mod._floor("analysis/gait", layers) \
        < mod._floor("api", layers)


def test_the_counts_script_prints_json(rows, monkeypatch, capsys):
    mod = _script()
    monkeypatch.setattr(mod, "measure", lambda root, duplicates: rows)
    assert mod.main(["--json", "--no-duplicates"]) == 0
    got = json.loads(capsys.readouterr().out)
    assert [r["value"] for r in got] == [r["value"] for r in rows]
    assert {"name", "value", "goal", "ok", "detail"} <= set(got[0])
    assert mod.main(["--no-duplicates"]) == 0
    table = capsys.readouterr().out.splitlines()
    assert len(table) == len(rows) and table[-3].split()[-1] in ("pass", "FAIL")


def test_the_part_readers_see_a_table_of_parts_and_a_switch_on_a_kind_word():
    """A dict keyed by two part words, a lookup by ``kind.<part>`` and a comparison of
    ``structure.kind.knees`` with a word are each seen (the rows cannot pass vacuously)."""
    import ast

    mod = _script()
    tree = ast.parse('T = {"legs": 1, "kneed": 2}\nx = T[kind.contact]\n'
                     'y = data.structure.kind.knees != "none"\nz = kind.in_3d\n')
    nodes = list(ast.walk(tree))
    dicts = [n for n in nodes if isinstance(n, ast.Dict)]
    assert len({k.value for k in dicts[0].keys} & mod.PART_WORDS) == 2
    assert sum(mod._kind_word_lookup(n) for n in nodes) == 1
    assert sum(mod._kind_word_switch(n) for n in nodes) == 1
