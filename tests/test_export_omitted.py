"""What an export leaves out is printed by ``walkerlab export``, one line per item, and the
lines are the file's own ``Left out:`` comments (issue 58 item 3).

The file's comments are read here with a regular expression of this test's own (an XML
comment ``<!-- Left out: ... -->``; an Adams ``! Left out: ...`` comment and its ``!   ``
continuation lines joined by spaces), not with the writers' code.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.cli_run import ROOT, run_cli

FILES = {"urdf": "walker.urdf", "mjcf": "walker.xml", "adm": "walker.adm",
         "osim": "walker.osim"}


def _file_items(path: Path) -> list[str]:
    """The ``Left out:`` comments of an exported file, one string per item."""
    text = path.read_text()
    if path.suffix != ".adm":
        return re.findall(r"<!-- Left out: (.*?) -->", text)
    items: list[str] = []
    current = None
    for line in text.splitlines():
        if line.startswith("! Left out: "):
            current = line[len("! Left out: "):]
            items.append(current)
        elif current is not None and line.startswith("!   "):
            items[-1] += " " + line[len("!   "):]
        else:
            current = None
    return items


def _export(name: str, fmt: str, runs: Path) -> tuple[list[str], list[str]]:
    """``walkerlab export configs/<name>.yaml --format fmt``: (printed items, file items)."""
    code, err, out = run_cli("export", ROOT / "configs" / f"{name}.yaml", "--format", fmt,
                             "--runs-dir", runs)
    assert code == 0, err
    lead = f"left out of {FILES[fmt]}: "
    printed = [ln[len(lead):] for ln in out.splitlines() if ln.startswith(lead)]
    assert len(printed) == sum("left out" in ln for ln in out.splitlines())  # one line each
    return printed, _file_items(runs / name / FILES[fmt])


#: (scene, format) -> the items' ``what`` parts expected, in order
CASES = {
    ("kneed", "urdf"): ["the ground (slope, terrain and contact law)",
                        "the knee latch (contact.knee_stop.latch)"],
    ("kneed", "mjcf"): ["the knee latch's switching"],
    ("kneed", "adm"): [],
    ("kneed", "osim"): ["the knee latch's switching"],
    ("hip_spring", "urdf"): ["the ground (slope, terrain and contact law)",
                             "spring spring0"],
    ("torso_powered", "urdf"): ["the ground (slope, terrain and contact law)",
                                "coupling bisecting_hip", "motor hip",
                                "the push-off (walker.actuation.push_off)"],
    ("powered_compass", "mjcf"): ["the push-off (walker.actuation.push_off)"],
    ("powered_compass", "adm"): ["contact_sim.start = periodic_gait"],
    ("powered_compass", "osim"): ["the push-off's switching (walker.actuation.push_off)"],
    ("paper", "mjcf"): [],
    ("paper", "osim"): [],
    ("paper", "adm"): [],
}


@pytest.mark.parametrize("name, fmt", sorted(CASES))
def test_export_prints_the_files_left_out_items_one_line_each(name, fmt, tmp_path):
    """The printed lines equal the file's ``Left out:`` comments, item for item and in
    order; each item names what is left out (its ``what`` before the first ": "), as expected
    for the scene's walker and format; a scene the file carries whole (the paper's passive
    compass gait in MuJoCo, OpenSim, Adams) prints none and its file has none."""
    printed, in_file = _export(name, fmt, tmp_path)
    assert printed == in_file
    hips = [ln.split(": ")[0] for ln in printed]
    # a spring's or a motor's item names it after its kind: "spring spring0: ..."
    assert hips == CASES[(name, fmt)], printed
    assert all(": " in ln and ln.split(": ", 1)[1] for ln in printed)


def test_adams_left_out_comments_keep_80_columns(tmp_path):
    """An Adams item is wrapped into the dataset's 80 columns (the statements' width) and
    read back whole."""
    printed, in_file = _export("powered_compass", "adm", tmp_path)
    text = (tmp_path / "powered_compass" / "walker.adm").read_text()
    assert all(len(ln) <= 80 for ln in text.splitlines() if ln.startswith("!"))
    assert printed == in_file and len(in_file) == 1
