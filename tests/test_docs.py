"""The documentation's generated and hand-written reference pages against the code: the
artifact reference lists every dataset the writers write, the layout page names every
package (no Sphinx build: the pages' generators and texts are checked directly)."""

from __future__ import annotations

import importlib.util
import pkgutil
import re
import sys
from pathlib import Path

import h5py
import pytest
import yaml

import walkerlab
from walkerlab.config import load_scene

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


@pytest.fixture(scope="module")
def reference():
    """``docs/_ext/artifact_reference.py`` (plain Python; its directive needs docutils only
    when Sphinx loads it)."""
    spec = importlib.util.spec_from_file_location(
        "artifact_reference", DOCS / "_ext" / "artifact_reference.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up by name
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        sys.modules.pop(spec.name, None)


def _datasets(path: Path) -> dict[str, bool]:
    """Every dataset of an artifact: whether it is a netCDF dimension scale."""
    out: dict[str, bool] = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda n, o: out.update({n: o.is_scale})
                     if isinstance(o, h5py.Dataset) else None)
    return out


def test_the_artifact_reference_covers_every_artifact_schema(reference):
    arts = {a.module: a for a in reference.catalogue()}
    schemas = {f"walkerlab.io.schemas.{m.name}" for m in
               pkgutil.iter_modules([str(ROOT / "walkerlab" / "io" / "schemas")])}
    assert schemas - {"walkerlab.io.schemas.loaders"} == set(arts)  # loaders: no writer
    for a in arts.values():
        assert a.rows, f"{a.module}: no dataset found in its writer"
        # a unit on every row: a literal one or the expression the writer takes it from
        assert all(r.unit for r in a.rows if r.path != "terrain/continuous"), a.module


def test_the_artifact_reference_lists_every_dataset_the_writers_write(reference, tmp_path):
    """fixedpoint.h5, simulate.h5 and contact_sim.h5 of the paper's walker, written by the
    stages: every dataset in them is a row of the generated reference."""
    from walkerlab.stages import contact_sim, fixedpoint, simulate

    d = yaml.safe_load((ROOT / "configs" / "paper.yaml").read_text())
    d.pop("workprecision", None)
    d["simulate"]["strides"] = 1
    d["contact_sim"].update(n_strides=1, periodic_gait=False)
    p = tmp_path / "paper.yaml"
    p.write_text(yaml.safe_dump(d))
    scene = load_scene(p)
    runs = tmp_path / "runs"
    paths = [fixedpoint.run(scene, runs).path, simulate.run(scene, runs).path,
             contact_sim.run(scene, runs).path]
    rows = {a.stage: a.rows for a in reference.catalogue()}
    for path in paths:
        with h5py.File(path, "r") as f:
            stage = str(f.attrs["stage"])
        names = _datasets(path)
        assert len(names) > 20, path
        missing = [n for n, scale in names.items()
                   if not reference.path_is_listed(n, rows[stage], scale)]
        assert not missing, f"{path.name}: not in the artifact reference: {missing}"
    # a dataset no writer names is caught (the check is not vacuous)
    assert not reference.path_is_listed("samples/unlisted_series", rows["simulate"])
    assert not reference.path_is_listed("floquet/variational/unlisted", rows["fixedpoint"])
    assert not reference.path_is_listed("floquet/unlisted", rows["fixedpoint"], True)


def test_the_artifact_reference_reads_units_from_the_writers(reference):
    """Rows unrolled from the writers' tables carry those tables' units (SI)."""
    from walkerlab.io.schemas import simulate

    rows = {r.path: r for a in reference.catalogue() if a.stage == "simulate"
            for r in a.rows}
    for name, unit in simulate.LEDGER_UNITS.items():
        assert rows[f"ledger/{name}"].unit == unit
    assert rows["samples/energy/total"].unit == "J"
    assert rows["samples/points/<name>/x"].unit == "m"
    contact = {r.path: r for a in reference.catalogue() if a.stage == "contact-sim"
               for r in a.rows}
    assert contact["contact_params_si/friction_velocity"].unit == "m/s"
    assert contact["feet/<leg>/normal_force"].dims == ("time",)


def test_the_layout_page_names_every_package_and_top_level_module():
    text = (DOCS / "user_guide" / "layout.md").read_text()
    root = Path(walkerlab.__file__).parent
    packages = sorted(p.name for p in root.iterdir() if (p / "__init__.py").is_file())
    modules = sorted(p.name for p in root.glob("*.py") if p.name != "__init__.py")
    assert "optimal" in packages and "gym" in packages
    missing = [f"walkerlab/{p}/" for p in packages if f"walkerlab/{p}/" not in text] + \
        [m for m in modules if not re.search(rf"\b{re.escape(m)}\b", text)]
    assert not missing, f"docs/user_guide/layout.md does not name {missing}"


def test_the_equations_chapter_and_the_artifact_page_are_in_the_tables_of_contents():
    guide = (DOCS / "user_guide" / "index.rst").read_text()
    ref = (DOCS / "reference" / "index.rst").read_text()
    assert re.search(r"^\s+equations$", guide, re.M)
    assert re.search(r"^\s+artifacts$", ref, re.M)
    conf = (DOCS / "conf.py").read_text()
    assert '"artifact_reference"' in conf
    eq = (DOCS / "user_guide" / "equations.md").read_text()
    for topic in ("Rigid", "heel strike", "contact law", "energy ledger", "Sources"):
        assert topic.lower() in eq.lower(), topic


# -------------------- the README names every API function
# ------------------------------------------------------------------- 8: README drift
def test_the_readme_names_every_api_function_and_the_basin_file_a_grid_writes():
    import walkerlab as wl
    from walkerlab.stages.basin import stem

    guide = ROOT / "docs" / "user_guide"  # the README's tables and API section live there
    text = " ".join((guide / "python_api.md").read_text().split())
    api = text[text.index("# Python API"):text.index("examples/walkerlab_tour.ipynb")]
    for name in wl.api.__all__:
        if name != "DEFAULT_RUNS":
            assert f"`{name}`" in api, name
    sc = load_scene(ROOT / "configs" / "paper.yaml")
    assert stem(sc, (40, 40)) == "basin_40x40" and stem(sc, None) == "basin"
    row = next(ln for ln in (guide / "commands.md").read_text().splitlines()
               if ln.startswith("| `walkerlab basin"))
    assert "`basin_<NX>x<NY>.h5`" in row and "`basin_40x40.h5`" in row


def _first_sentence(doc: str) -> str:
    """The summary autosummary takes from a docstring: its first paragraph joined by spaces,
    cut at the first period followed by a space (``sphinx.ext.autosummary.extract_summary``
    checks its markup on the whole paragraph, not on the cut it keeps)."""
    stanza = []
    for line in doc.strip().splitlines():
        if not line.strip():
            break
        stanza.append(line.strip())
    return re.split(r"\.\s+", " ".join(stanza), maxsplit=1)[0]


def test_every_module_summary_keeps_its_inline_markup_whole():
    """A module's autosummary line is its first sentence: a reference split after a dot at a
    line's end (``:func:`a.b.`` then ``c``` on the next line) is cut there and the fresh
    autosummary of a clean build fails Sphinx -W (it did in CI)."""
    import ast

    broken = []
    for path in sorted((ROOT / "walkerlab").rglob("*.py")):
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
        if doc and _first_sentence(doc).count("`") % 2:
            broken.append(f"{path.relative_to(ROOT)}: {_first_sentence(doc)[:90]}")
    assert not broken, "\n".join(broken)
