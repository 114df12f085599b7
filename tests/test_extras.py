"""What a light install (``pip install -e .``) has and what it says: the main job's
dependencies only, every optional part behind an extra named by its purpose, and one line
naming that extra when a command needs it and it is missing (``walkerlab optimize`` without
CasADi, ``--scheduler`` without Dask, an exported MJCF walked without MuJoCo).  The README's
two commands: one installs the main job and runs it, one installs what the tests need and
runs them, as CI does."""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

import pytest
from typer.testing import CliRunner

from walkerlab.extras import EXTRAS, MissingExtra, require

ROOT = Path(__file__).resolve().parents[1]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
#: distributions a light install must not pull in (the optional parts' heavy ones)
#: (xarray and h5netcdf are main dependencies: the documented Python API works after the
#: README's first command, issue 64)
HEAVY = ("casadi", "dask", "distributed", "mujoco", "pin", "drake",
         "nbclient", "nbformat", "ipykernel", "jupyter", "pytest", "numbalsoda")


def _name(req: str) -> str:
    return re.split(r"[\s<>=!~;\[]", req, maxsplit=1)[0].lower()


def _commands(text: str) -> list[str]:
    return re.findall(r"```bash\n(.*?)\n```", text, re.S)


def test_the_main_install_has_none_of_the_optional_parts():
    deps = {_name(r) for r in PROJECT["dependencies"]}
    assert deps and not deps & set(HEAVY), deps & set(HEAVY)


def test_the_main_install_carries_the_documented_python_api():
    """Before: ``wl.fixed_point(...)`` after ``pip install -e .`` ended in MissingExtra
    (h5netcdf)."""
    deps = {_name(r) for r in PROJECT["dependencies"]}
    assert {"xarray", "h5netcdf"} <= deps


def test_every_extra_is_named_by_its_purpose_and_the_tests_get_all_but_numbalsoda_and_docs():
    extras = PROJECT["optional-dependencies"]
    assert set(extras) == set(EXTRAS) | {"test"}
    test = set(extras["test"])
    for name, reqs in extras.items():
        if name not in ("test", "numbalsoda", "docs", "osim"):
            assert set(reqs) <= test, (name, set(reqs) - test)
    assert {_name(r) for r in extras["test"]} >= {"pytest", "pytest-xdist"}


def test_the_gym_and_test_extras_bring_gymnasiums_mujoco_part_for_walker2d():
    """``gym.make("Walker2d-v5")``, which the docs and ``scripts/bench_gym.py`` compare the
    walker against, needs mujoco and imageio: ``gymnasium[mujoco]`` (before: ``gymnasium``
    alone, and Walker2d failed on ``import imageio``)."""
    extras = PROJECT["optional-dependencies"]
    for name in ("gym", "test", "docs"):
        assert any(r.replace(" ", "").startswith("gymnasium[mujoco]") for r in extras[name]), name


def test_ci_runs_the_main_job_on_the_lowest_versions_pyproject_allows():
    """The declared versions are the tested versions: after the quick suite, .ci/run installs
    the main job with uv's lowest-direct resolution in a second venv and runs it (before:
    ``typer>=0.12`` and ``numpy>=1.26`` were declared, and the CLI did not start on them)."""
    ci = (ROOT / ".ci" / "run").read_text()
    lines = ci.splitlines()
    quick = lines.index(". .venv/bin/activate && pip install -e '.[test]' && pytest")
    rest = "\n".join(lines[quick + 1:])
    assert "pip install --quiet uv" in rest
    assert "--resolution lowest-direct -e ." in rest
    assert 'walkerlab" report --runs-dir "$lowest/runs"' in rest


def test_the_readme_installs_the_main_job_then_the_tests_and_ci_runs_that_command():
    readme = (ROOT / "README.md").read_text()
    first, second = _commands(readme)[:2]
    assert first.endswith("pip install -e . && walkerlab report"), first
    assert second.endswith("pip install -e '.[test]' && pytest"), second
    ci = (ROOT / ".ci" / "run").read_text()
    assert second in ci.splitlines(), "CI runs the README's test command"
    install = (ROOT / "docs" / "user_guide" / "installation.md").read_text()
    assert _commands(install)[:2] == [first, second], "the user guide repeats them"
    for name in EXTRAS:  # each extra is listed for what it does (in the user guide)
        assert f"| `{name}` |" in install, name
    assert len(_commands(readme)) == 2, "the README has exactly the two commands"
    docs = (ROOT / "docs" / "README.md").read_text()
    build = "python -m sphinx -W --keep-going -b html docs docs/_build/html"
    assert _commands(docs)[0].endswith(f"pip install -e '.[docs]' && {build}")
    assert f"`pip install -e '.[docs]' && {build}`" in readme, "the README names the docs build"
    assert f". .venv/bin/activate && pip install -e '.[docs]' && {build}" in ci.splitlines()


def test_require_names_the_extra_in_one_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "casadi", None)  # as if not installed
    with pytest.raises(MissingExtra) as exc:
        require("casadi", "optimize", "walkerlab optimize")
    msg = str(exc.value)
    assert msg == ("walkerlab optimize needs casadi (not installed): "
                   "pip install -e '.[optimize]'")
    assert isinstance(exc.value, ValueError) and isinstance(exc.value, ImportError)
    assert require("json", "optimize", "x") is sys.modules["json"]


def test_walkerlab_optimize_without_casadi_says_so_before_any_stage_runs(monkeypatch,
                                                                         tmp_path):
    from walkerlab.cli import app

    monkeypatch.setitem(sys.modules, "casadi", None)
    r = CliRunner().invoke(app, ["optimize", str(ROOT / "configs" / "compass_optimal.yaml"),
                                 "--runs-dir", str(tmp_path)])
    assert r.exit_code == 1
    assert r.stderr.strip() == ("error: walkerlab optimize needs casadi (not installed): "
                                "pip install -e '.[optimize]'")
    assert not any(tmp_path.rglob("*.h5"))  # refused before the fixed point ran


def test_a_scheduler_without_dask_says_which_extra(monkeypatch):
    from walkerlab.execution.executor import make_executor

    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(MissingExtra, match=r"^--scheduler needs distributed \(not "
                       r"installed\): pip install -e '\.\[dask\]'$"):
        make_executor(2, "tcp://127.0.0.1:8786")


def test_walking_an_exported_mjcf_without_mujoco_says_which_extra(monkeypatch, tmp_path):
    from walkerlab.export.mujoco_walk import walk

    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(MissingExtra, match=r"pip install -e '\.\[engines\]'$"):
        walk(tmp_path / "walker.xml", 1.0)


def test_the_python_api_without_its_datasets_says_which_extra(monkeypatch, tmp_path):
    """The API's artifact view needs xarray and h5netcdf: one line naming the missing one
    (h5netcdf was imported bare before the check, so a light install saw its traceback)."""
    from walkerlab.io.datasets import load_dataset

    monkeypatch.setitem(sys.modules, "h5netcdf", None)
    path = tmp_path / "fixedpoint.h5"
    import h5py

    with h5py.File(path, "w") as f:
        f.attrs["stage"] = "fixedpoint"
    with pytest.raises(MissingExtra, match=r"^walkerlab's Python API needs h5netcdf \(not "
                       r"installed\): pip install -e '\.\[api\]'$"):
        load_dataset(path)


def test_the_docs_name_only_extras_that_exist():
    """Issue 56 item 16: the user guide said CasADi came with "the `dev` and `optimize`
    extras"; there is no `dev` extra.  Every extra the docs name ("the `x` extra",
    "`x` and `y` extras", ``.[x]``) is one of pyproject's."""
    extras = set(PROJECT["optional-dependencies"])
    named = {}
    for f in [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]:
        text = f.read_text()
        for group in re.findall(r"((?:`[\w-]+`(?:,| and| or)? ?)+) extras?\b", text):
            for name in re.findall(r"`([\w-]+)`", group):
                named.setdefault(name, f.name)
        for group in re.findall(r"\.\[([\w,-]+)\]", text):
            for name in group.split(","):
                if name != "NAME":  # the placeholder of "pip install -e '.[NAME]'"
                    named.setdefault(name, f.name)
    assert "optimize" in named  # the patterns find the docs' mentions
    unknown = {n: where for n, where in named.items() if n not in extras}
    assert not unknown, unknown


def test_the_banner_and_the_description_say_passive_and_powered():
    """Issue 56 item 16: the CLI banner and pyproject's description said "passive-dynamic"
    though the lab powers walkers (push-off, joint torques, optimal gaits)."""
    import walkerlab
    from walkerlab.cli import app

    # rich wraps the help to the terminal's width: the words, joined again
    banner = " ".join(re.sub(r"[│╭╮╰╯─]", " ", CliRunner().invoke(app, ["--help"]).output)
                      .split())
    for text in (banner, PROJECT["description"], walkerlab.__doc__.splitlines()[0]):
        assert "passive-dynamic" not in text and "passive and powered" in text, text


def test_an_installed_module_that_fails_to_import_is_not_sent_to_pip(tmp_path, monkeypatch):
    """A module that is installed but whose import fails on something else (OpenSim's
    Moco beside another CasADi: an undefined symbol; a missing system library) was told
    ``pip install -e '.[osim]'``, which installs nothing new.  Now the line names the
    failure and no extra."""
    (tmp_path / "broken_extra_module.py").write_text(
        "raise ImportError('libosimMoco.so: undefined symbol: _ZN6casadi', name='libosimMoco')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(MissingExtra) as exc:
        require("broken_extra_module", "osim", "walking an OpenSim export")
    msg = str(exc.value)
    assert msg == ("walking an OpenSim export needs broken_extra_module, which is installed "
                   "but failed to import (libosimMoco.so: undefined symbol: _ZN6casadi); "
                   "repair that installation")
    assert "pip install" not in msg


def test_install_hints_are_spelled_one_way():
    """Before: ``pip install 'walkerlab[optimize]'`` here, ``pip install -e '.[engines]'``
    there; now every hint in the package, the docs and the README is the latter."""
    files = [*(ROOT / "walkerlab").rglob("*.py"), *(ROOT / "docs").rglob("*.md"),
             *(ROOT / "docs").rglob("*.rst"), ROOT / "README.md"]
    bad = [str(f) for f in files if "'walkerlab[" in f.read_text(errors="ignore")]
    assert not bad, bad


def test_the_package_imports_no_module_its_install_does_not_bring():
    """A fresh ``pip install -e .`` has no ``click`` (typer 0.29 vendors its own): the
    package importing it failed at ``walkerlab --help`` there, though a test environment
    that has click (through another extra) passed."""
    import ast

    bad = []
    for f in (ROOT / "walkerlab").rglob("*.py"):
        for node in ast.walk(ast.parse(f.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            if any(n.split(".")[0] == "click" for n in names):
                bad.append(str(f.relative_to(ROOT)))
    assert not bad, bad
