"""Rough edges and reliability, round four: messages and the front door (one line naming
the field or file, and no more than a reader can use), the API making the CLI's checks,
figures and artifacts that say what they hold."""

from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from walkerlab.cli import app
from walkerlab.config import SceneError, load_scene, scene_from_dict

ROOT = Path(__file__).resolve().parents[1]
SIMPLEST = yaml.safe_load((ROOT / "configs" / "simplest.yaml").read_text())


def _cli(*args):
    r = CliRunner().invoke(app, [str(a) for a in args])
    return r.exit_code, r.stderr.strip(), r.stdout


# ------------------------------------------------------- 1: thousands of unknown keys
def test_thousands_of_unknown_keys_give_a_capped_list_and_few_suggestions(monkeypatch):
    import difflib

    from walkerlab.config import errors

    calls = []
    real = difflib.get_close_matches
    monkeypatch.setattr(difflib, "get_close_matches",
                        lambda *a, **k: calls.append(a[0]) or real(*a, **k))
    data = dict(SIMPLEST, **{f"zzunknown{i}": 1 for i in range(3000)})
    with pytest.raises(SceneError) as exc:
        scene_from_dict(data, "s.yaml")
    lines = str(exc.value).splitlines()
    assert len(lines) == errors.MAX_ERROR_LINES
    assert lines[0] == "s.yaml: zzunknown0: unknown field"
    assert lines[-1] == f"s.yaml: … and {3000 - errors.MAX_ERROR_LINES + 1} more errors"
    # a suggestion only for the lines printed: the work does not grow with the keys
    assert len(calls) <= errors.MAX_ERROR_LINES


def test_a_few_unknown_keys_are_all_listed_with_their_suggestion():
    data = dict(SIMPLEST, slop=SIMPLEST["slope"], zzz=1)
    del data["slope"]
    lines = str(pytest.raises(SceneError, scene_from_dict, data, "s.yaml").value).splitlines()
    assert lines == ["s.yaml: slop: unknown field (did you mean slope?)",
                     "s.yaml: zzz: unknown field"]


# ------------------------------------------------------------- 2: a NUL byte in a scene
def test_a_nul_byte_in_a_scene_is_one_line_naming_the_file_and_line(tmp_path):
    f = tmp_path / "nul.yaml"
    f.write_bytes((ROOT / "configs" / "simplest.yaml").read_bytes() + b"\nextra: 1\x00\n")
    code, err, _ = _cli("fixedpoint", f, "--runs-dir", tmp_path / "runs")
    assert code == 1
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"error: {f}: line ") and "0x00" in lines[0]
    with pytest.raises(SceneError, match=r"nul.yaml: line \d+: character 0x00 "):
        load_scene(f)
