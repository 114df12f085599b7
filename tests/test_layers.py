"""The package's layering, read from the source's own imports (every ``import`` statement,
also those inside functions), never by running it: dependencies point down.

- library packages (models, contact, integrate, analysis, sweep, io, report, plotting,
  execution, config) never import ``walkerlab.stages``, the CLI or the front doors;
- a stage never imports another stage: only the pipeline (and the report's DAG run, which
  the pipeline's plan drives) reach other stages;
- ``h5py`` is imported only under ``walkerlab/io/`` (the artifact schemas);
- the CLI opens no artifact itself (no ``h5py``, no ``open_artifact``).
"""

from __future__ import annotations

import ast
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "walkerlab"
#: the top floor: may import stages
FRONT = ("cli", "api", "bench.py")
#: stage modules that chain stages (the one place that decides order, and the report's run)
CHAINS = ("pipeline.py", "report_dag.py", "report.py")


def _imports(path: Path) -> list[str]:
    """Every module ``path`` imports, absolute (``from . import x`` resolved)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    pkg = ".".join(path.relative_to(PKG.parent).with_suffix("").parts[:-1])
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = pkg.split(".")[:len(pkg.split(".")) - node.level + 1]
                base = ".".join(parts + ([base] if base else []))
            out += [base] + [f"{base}.{a.name}" for a in node.names]
    return out


def _modules() -> list[Path]:
    return sorted(p for p in PKG.rglob("*.py") if "__pycache__" not in p.parts)


def _rel(p: Path) -> str:
    return p.relative_to(PKG).as_posix()


def test_the_import_reader_sees_function_level_and_relative_imports(tmp_path):
    """The reader the checks rely on finds imports inside functions and relative ones (a
    reader that missed them would make every check below pass vacuously)."""
    f = PKG / "stages" / "report_dag.py"
    got = _imports(f)
    assert "walkerlab.stages.plot" in got  # imported inside run_report
    assert "walkerlab.execution.background" in got  # imported inside _study


def test_library_modules_never_import_stages_or_the_front_doors():
    bad = {}
    for path in _modules():
        if _rel(path).split("/")[0] in FRONT + ("stages",):
            continue
        up = [m for m in _imports(path)
              if m.startswith(("walkerlab.stages", "walkerlab.cli", "walkerlab.bench"))
              or (m == "walkerlab.api" and _rel(path) != "__init__.py")]  # wl.api, lazily
        if up:
            bad[_rel(path)] = up
    assert not bad, bad


def test_a_stage_never_imports_another_stage():
    shared = ("common", "pipeline", "report_inputs")  # plumbing; the place that knows stages
    bad = {}
    for path in sorted((PKG / "stages").glob("*.py")):
        if path.name in CHAINS:
            continue
        others = [m for m in _imports(path) if m.startswith("walkerlab.stages.")
                  and m.split(".")[2] not in shared + (path.stem,)]
        if others:
            bad[path.name] = others
    assert not bad, bad


def test_h5py_only_under_io():
    found = [_rel(p) for p in _modules() if any(m.split(".")[0] == "h5py"
                                                 for m in _imports(p))]
    outside = [r for r in found if not r.startswith("io/")]
    assert found and not outside, outside


def test_the_cli_opens_no_artifact():
    cli = sorted((PKG / "cli").glob("*.py"))
    assert len(cli) > 3
    for p in cli:
        bad = [m for m in _imports(p) if m.split(".")[0] == "h5py"
               or m.endswith(("open_artifact", "root_attrs"))]
        assert not bad, f"cli/{p.name} imports {bad}"
