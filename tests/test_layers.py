"""The package's layering, read from the source's own imports (every ``import`` statement,
also those inside functions), never by running it: dependencies point down.

- library packages (models, contact, integrate, analysis, sweep, io, report, plotting,
  execution, config) never import ``walkerlab.stages``, the CLI or the front doors;
- a stage never imports another stage: only the pipeline (and the report's DAG run, which
  the pipeline's plan drives) reach other stages;
- ``h5py`` is imported only under ``walkerlab/io/`` (the artifact schemas);
- the CLI opens no artifact itself (no ``h5py``, no ``open_artifact``);
- ``report/`` writes text from loaded schema objects and numbers computed before it: no
  ``h5py``, no matplotlib or ``plotting``, no ``analysis``, ``studies``, ``models``,
  ``integrate`` (its run-end names aside), no loader;
- the middle floor: ``analysis/`` never imports ``studies/``, ``bench/``, ``export/`` or
  ``comparison/``;
  ``models/``, ``integrate/``, ``codegen/`` and ``walker/`` never import ``analysis/``;
  ``io/`` never imports ``analysis/``, ``gym/`` never imports ``api/``;
  ``config/`` never imports ``io/`` (a scene opens no artifact); ``models/contact/`` never
  imports ``models/hybrid/`` (the contact view is generated from the description alone);
- no name private to a module (``_name``) is imported by another package, and no private
  module is imported from outside its package;
- no import circle among walkerlab's modules (imports inside functions count: a circle
  closed lazily is still two modules that each need the other);
- one formula, one place: one finite-difference and one complex-step Jacobian
  (:mod:`walkerlab.numerics`), no ``approx_fprime``;
- every top-level package or module stands on a floor of :data:`LAYERS` and imports no
  floor above its own;
- the structure's switches ``space``, ``hip_width``, ``hip_roll`` are read in ``walker/``
  and ``config/`` and by the listed readers only; a walker kind's name is compared only in
  ``walker/`` (today's other comparers listed, the list only shrinks);
- modules hold at most 600 lines (today's bigger ones at their sizes as ceilings);
- a function-level import of walkerlab says why in a comment (``# light``, ``# circle``):
  the unexplained ones are counted down; a ``# light`` one keeps a heavy package (or a heavy
  floor of the project) off its module, measured from the module-level imports, or it
  belongs at module level;
- package docstrings tell what the code does, not its issue history (no "issue N"), and
  cite papers, equations and the project's own files, never a path outside the project
  (a notes file, ``../shared``, a machine's absolute path).
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "walkerlab"
#: the top floor: may import stages
FRONT = ("cli", "api", "cli/bench.py")
#: stage modules that chain stages (the one place that decides order, and the report's run)
CHAINS = ("pipeline.py", "report_dag.py", "report.py")


#: the floors of the package, bottom first: a module imports (at module level or inside a
#: function) only modules of its own floor or of floors below it; every top-level package or
#: module of ``walkerlab/`` stands on one (a new one must be placed here).  The plumbing of the
#: ground floor imports nothing of the others; ``io/`` (the artifacts' schemas) lies below the
#: analysis that writes them; ``rigid_walker`` (a scene's rigid walker and its gait) below the
#: two front doors that hold one, the gym and the API.
LAYERS = (
    ("numerics", "units", "safefs", "usercache", "codestore", "extras", "freshstack", "progress",
     "published", "execution"),
    ("config",),
    ("walker",),
    ("codegen",),
    ("models",),
    ("integrate",),
    ("io",),
    ("analysis",),
    ("studies", "comparison", "export", "report"),
    ("rigid_walker",),
    ("optimal", "gym", "plotting"),
    ("bench",),
    ("stages",),
    ("cli", "api", "__init__"),
)


@functools.cache
def _tree(path: Path) -> ast.Module:
    """``path`` parsed once for every rule (the rules read the same files)."""
    return ast.parse(path.read_text(), filename=str(path))


def _package(path: Path) -> str:
    """The package ``path`` lies in, dotted (``""`` for a file outside the package: the
    rules' self-tests): what a relative import of ``path`` starts from."""
    try:
        return ".".join(path.relative_to(PKG.parent).with_suffix("").parts[:-1])
    except ValueError:
        return ""


def _node_imports(node, pkg: str) -> list[str]:
    """The modules one import statement names, absolute (``from . import x`` resolved
    from ``pkg``); [] for any other node."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    if not isinstance(node, ast.ImportFrom):
        return []
    base = node.module or ""
    if node.level:
        parts = pkg.split(".")[:len(pkg.split(".")) - node.level + 1]
        base = ".".join(parts + ([base] if base else []))
    return [base] + [f"{base}.{a.name}" for a in node.names]


def _imports(path: Path, module_level: bool = False) -> list[str]:
    """Every module ``path`` imports, absolute (``from . import x`` resolved); with
    ``module_level``, only its top-level statements' (a ``TYPE_CHECKING`` block is not
    run)."""
    tree, pkg = _tree(path), _package(path)
    nodes = tree.body if module_level else ast.walk(tree)
    return [m for node in nodes for m in _node_imports(node, pkg)]


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
              if m.startswith(("walkerlab.stages", "walkerlab.cli", "walkerlab.cli.bench"))
              or (m == "walkerlab.api" and _rel(path) != "__init__.py")]  # wl.api, lazily
        if up:
            bad[_rel(path)] = up
    assert not bad, bad


def test_a_stage_never_imports_another_stage():
    # plumbing; the places that know stages (the registry: the stages as objects)
    shared = ("common", "pipeline", "registry", "report_inputs")
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


#: report/ writes text from loaded schema objects and numbers computed before it: it imports
#: no HDF5, no drawing, no computation, and loads no artifact (the run-end names of
#: walkerlab.integrate.ends are vocabulary, allowed)
REPORT_BANNED = ("h5py", "matplotlib", "walkerlab.plotting", "walkerlab.analysis",
                 "walkerlab.studies", "walkerlab.comparison", "walkerlab.models",
                 "walkerlab.codegen",
                 "walkerlab.execution", "walkerlab.io.sweep_store", "walkerlab.io.schemas.loaders")


def _report_violations(path: Path) -> list[str]:
    return [m for m in _imports(path)
            if (m.startswith(REPORT_BANNED) or m.rsplit(".", 1)[-1].startswith("load")
                or (m.startswith("walkerlab.integrate") and not m.startswith(
                    "walkerlab.integrate.ends")))]


def test_the_report_rule_catches_computing_loading_and_drawing(tmp_path):
    """The rule below fails on each kind of violation (a rule that let them through would
    pass vacuously)."""
    bad = tmp_path / "section.py"
    bad.write_text("import h5py\nfrom walkerlab.io.sweep_store import load_sweep\n"
                   "def f():\n    from walkerlab.analysis.robustness.basin_area import basin_area\n"
                   "    from walkerlab.plotting.figures import save\n"
                   "    from walkerlab.io.schemas.basin import load_basin\n"
                   "    from walkerlab.integrate.rigid import integrate_step\n"
                   "    from walkerlab.integrate.ends import CONTACT_WALKED\n")
    got = _report_violations(bad)
    for m in ("h5py", "walkerlab.io.sweep_store", "walkerlab.analysis.robustness.basin_area",
              "walkerlab.plotting.figures", "walkerlab.io.schemas.basin.load_basin",
              "walkerlab.integrate.rigid"):
        assert m in got, m
    assert "walkerlab.integrate.ends.CONTACT_WALKED" not in got


def test_the_report_only_writes_text_from_loaded_objects():
    mods = sorted((PKG / "report").glob("*.py"))
    assert len(mods) > 5
    bad = {p.name: v for p in mods if (v := _report_violations(p))}
    assert not bad, bad


#: (importing packages, packages they must never import)
MIDDLE_FLOOR_RULES = [
    (("analysis",), ("walkerlab.studies", "walkerlab.bench", "walkerlab.export",
                     "walkerlab.comparison")),
    (("models", "integrate", "codegen", "walker"), ("walkerlab.analysis",)),
    (("config",), ("walkerlab.io",)),
    # the contact view is generated from the description alone: the facts both views read
    # (joints, the ground's landings, the torque laws) lie below both
    (("models/contact",), ("walkerlab.models.hybrid",)),
    # arrows that once pointed up: the artifacts' schemas lie below the analysis (the
    # friction verdict they store is io's record); the gym holds a walkerlab.rigid_walker,
    # not the API's walker
    (("io",), ("walkerlab.analysis",)),
    (("gym",), ("walkerlab.api",)),
]


def _floor_violations(paths, banned) -> dict:
    return {str(p): v for p in paths
            if (v := [m for m in _imports(p) if m.startswith(banned)])}


def test_the_middle_floor_rules_catch_a_violation(tmp_path):
    bad = tmp_path / "x.py"
    bad.write_text("def f():\n    from walkerlab.studies.mfpt import run\n")
    assert _floor_violations([bad], MIDDLE_FLOOR_RULES[0][1])
    up = tmp_path / "y.py"  # a module of the contact view reaching the rigid one
    up.write_text("def f():\n    from walkerlab.models.hybrid.actuators import joint_links\n")
    assert _floor_violations([up], dict(MIDDLE_FLOOR_RULES)[("models/contact",)])


def test_the_middle_floor_points_down():
    bad = {}
    for packages, banned in MIDDLE_FLOOR_RULES:
        for pkg in packages:
            paths = sorted((PKG / pkg).rglob("*.py"))
            assert paths, pkg
            bad.update(_floor_violations(paths, banned))
    assert not bad, bad


def _private_owner(parts: list[str], i: int) -> str:
    """The package that owns the private ``parts[i]``: ``parts[:i]`` when that is a package
    (``_x`` is its private module, or a private name of its ``__init__``), else the package
    of the module ``parts[:i]`` (``_x`` is a private name of that module)."""
    if PKG.parent.joinpath(*parts[:i]).is_dir():
        return ".".join(parts[:i])
    return ".".join(parts[:i - 1])


def _private_crossings(path: Path, here: str | None = None) -> list[str]:
    """Imports in ``path`` of a ``_name`` from a module of another package, or of a private
    module (``pkg._mod``) from outside ``pkg``.  ``here`` is the importing package (read
    from ``path`` when it lies in the package; the rules' self-tests pass it)."""
    if here is None:
        here = ".".join(path.relative_to(PKG.parent).with_suffix("").parts[:-1]) \
            if path.is_relative_to(PKG.parent) else ""
    out = []
    for m in _imports(path):
        if not m.startswith("walkerlab."):
            continue
        parts = m.split(".")
        for i, part in enumerate(parts):
            if part.startswith("_") and not part.startswith("__"):
                owner = _private_owner(parts, i)
                if not owner or not (here == owner or here.startswith(owner + ".")):
                    out.append(m)
                break
    return out


def test_the_private_name_rule_catches_a_crossing(tmp_path):
    bad = tmp_path / "x.py"
    bad.write_text("from walkerlab.studies.points import _Outcome\n"
                   "from walkerlab.integrate import _lsoda\n")
    assert len(_private_crossings(bad)) == 2


def test_the_private_name_rule_knows_a_package_from_a_module(tmp_path):
    """A private module named in ``from pkg import _mod`` belongs to ``pkg``, not to
    ``pkg``'s parent: imported from a sibling package it crosses (the owner read as the
    parent let ``analysis/contact`` take ``integrate._cyrk``); a private name of a module is
    owned by that module's package, and its subpackages may use it."""
    f = tmp_path / "x.py"
    f.write_text("from walkerlab.integrate import _compiled\n"
                 "import walkerlab.integrate._compiled\n"
                 "from walkerlab.integrate.rigid import _helper\n")
    assert len(_private_crossings(f, here="walkerlab.analysis.contact")) == 3
    assert _private_crossings(f, here="walkerlab.integrate") == []
    assert _private_crossings(f, here="walkerlab.integrate.sub") == []
    # a package whose name only begins like the owner's is another package
    assert len(_private_crossings(f, here="walkerlab.integrate_x")) == 3


def test_no_private_names_cross_packages():
    bad = {_rel(p): v for p in _modules() if (v := _private_crossings(p))}
    assert not bad, bad


def _module_name(path: Path) -> str:
    parts = path.relative_to(PKG.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _import_graph(paths: dict[str, Path]) -> dict[str, set[str]]:
    """``{module: the modules of paths it imports}``: ``from pkg import name`` is an arrow to
    ``pkg.name`` when that is a module, else to ``pkg``; a package's ``__init__`` is a
    module like any other (importing ``pkg.mod`` runs it, but that is no arrow of the
    importer's making)."""
    def resolve(name: str) -> str | None:
        parts = name.split(".")
        for i in range(len(parts), 0, -1):
            if (c := ".".join(parts[:i])) in paths:
                return c
        return None

    graph = {}
    for mod, path in paths.items():
        tree = _tree(path)
        pkg = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
        out = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                out |= {resolve(a.name) for a in node.names}
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = pkg.split(".")[:len(pkg.split(".")) - node.level + 1]
                    base = ".".join(parts + ([base] if base else []))
                out |= {resolve(f"{base}.{a.name}") if f"{base}.{a.name}" in paths
                        else resolve(base) for a in node.names}
        graph[mod] = out - {None, mod}
    return graph


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, on, stack, out, n = {}, {}, set(), [], [], 0
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = n
        n += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = n
                    n += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


def test_the_circle_rule_sees_a_circle_closed_inside_a_function(tmp_path):
    """A circle closed by an import inside a function, a relative import or ``from pkg
    import mod`` is found; a package's ``__init__`` importing its own module is no circle
    with that module's import of a sibling."""
    pkg = tmp_path / "walkerlab" / "fam"
    pkg.mkdir(parents=True)
    files = {"walkerlab.fam": "from . import base\n",
             "walkerlab.fam.base": "import numpy\n",
             "walkerlab.fam.dispatch": "def f():\n    from walkerlab.fam.one import g\n",
             "walkerlab.fam.one": "from .two import h\n",
             "walkerlab.fam.two": "def h():\n    from walkerlab.fam import dispatch\n",
             "walkerlab.fam.solo": "from walkerlab.fam import base\n"}
    paths = {}
    for mod, text in files.items():
        parts = mod.split(".")[1:]
        p = (tmp_path.joinpath("walkerlab", *parts, "__init__.py") if mod == "walkerlab.fam"
             else tmp_path.joinpath("walkerlab", *parts).with_suffix(".py"))
        p.write_text(text)
        paths[mod] = p
    graph = _import_graph(paths)
    assert graph["walkerlab.fam.two"] == {"walkerlab.fam.dispatch"}
    assert graph["walkerlab.fam.solo"] == {"walkerlab.fam.base"}
    assert _circles(graph) == [["walkerlab.fam.dispatch", "walkerlab.fam.one",
                                "walkerlab.fam.two"]]


def test_no_import_circles():
    """Dependencies point one way: no two walkerlab modules need each other, directly or
    through others, at module level or inside functions (a dispatcher imports its
    families; the helpers the families share live in a module of their own)."""
    paths = {_module_name(p): p for p in _modules()}
    assert _circles(_import_graph(paths)) == []


def test_one_finite_difference_jacobian():
    import re

    defs = {}
    for p in _modules():
        text = p.read_text()
        for name in re.findall(r"^def ((?:fd|complex_step)_jacobian)\b", text, re.M):
            defs.setdefault(name, []).append(_rel(p))
        assert "approx_fprime" not in text, _rel(p)
    assert defs == {"fd_jacobian": ["numerics.py"], "complex_step_jacobian": ["numerics.py"]}


def test_no_issue_numbers_in_package_docstrings():
    import re

    bad = [f"{_rel(p)}:{n}" for p in _modules()
           for n, line in enumerate(p.read_text().splitlines(), 1)
           if re.search(r"\b[Ii]ssues? \d+", line)]
    assert not bad, bad


#: a reference to something outside the project: a notes file, a path that climbs out of
#: the tree (``../``, not an ellipsis ``.../``), or an absolute path of a machine
OUTSIDE = r"NOTES\.md|(?<!\.)\.\./|\bshared/|(?<![\w./-])/(?:work|home|root|tmp|Users)/"


def _outside_references(paths) -> list[str]:
    import re

    return [f"{p}:{n}" for p in paths
            for n, line in enumerate(p.read_text(errors="replace").splitlines(), 1)
            if re.search(OUTSIDE, line)]


def test_the_outside_reference_rule_catches_each_kind(tmp_path):
    cases = ["(NOTES.md)", "see ../shared/NOTES.md", "bench, /work/notes/s3.md",
             "a copy in shared/", "cached in /tmp/x", "/home/me/paper.pdf"]
    fine = ["``ledger/work/<name>``", "<tendon tendon1=.../>", "scripts/bench_mfpt.py",
            "MSC Adams/Solver function reference, IMPACT"]
    for k, text in enumerate(cases + fine):
        (tmp_path / f"{k}.py").write_text(f'"""{text}"""\n')
    got = {int(Path(r.split(":")[0]).stem) for r in
           _outside_references(sorted(tmp_path.glob("*.py")))}
    assert got == set(range(len(cases)))


def test_the_scenes_and_scripts_point_at_nothing_outside_the_project():
    """Issue 56 item 16: shipped scenes cited the paper as a file outside the project
    (``shared/seeds/...``) and ``scripts/reliability_repro.py`` carried an absolute path of
    one machine (``PYTHONPATH=/work/wt/base``)."""
    import io
    import re
    import tokenize

    root = PKG.parent
    scenes = sorted((root / "configs").glob("*.yaml"))
    scripts = sorted((root / "scripts").glob("*.py"))
    assert len(scenes) > 20 and len(scripts) > 5
    bad = _outside_references(scenes)
    for p in scripts:  # their prose: docstring and comments (a script's hostile inputs,
        # "../evil", are its data)
        src = p.read_text()
        prose = [ast.get_docstring(ast.parse(src)) or ""] + [
            t.string for t in tokenize.generate_tokens(io.StringIO(src).readline)
            if t.type == tokenize.COMMENT]
        bad += [f"{p}: {line}" for text in prose for line in text.splitlines()
                if re.search(OUTSIDE, line)]
    assert not bad, bad


def test_the_package_points_at_nothing_outside_the_project():
    """Docstrings and comments cite the paper, an equation or a file of the project: a notes
    file or a path outside the tree means nothing to a reader of the package."""
    files = [p for p in sorted(PKG.rglob("*")) if p.is_file() and "__pycache__" not in p.parts
             and p.suffix in (".py", ".md", ".txt", ".yaml", ".json", ".html", ".j2")]
    assert len(files) > 100
    bad = _outside_references(files)
    assert not bad, bad


def test_no_top_level_package_holds_more_than_18_percent_of_the_lines():
    sizes = {}
    for p in _modules():
        top = _rel(p).split("/")[0]
        sizes[top] = sizes.get(top, 0) + len(p.read_text().splitlines())
    total = sum(sizes.values())
    big = {k: round(v / total, 3) for k, v in sizes.items() if v > 0.18 * total}
    assert not big, big


#: words that name a walker family (a walker is data: its family is a scene, never a module)
FAMILY_WORDS = ("compass", "kneed", "five_link", "fivelink", "flat", "rabbit", "rimless",
                "torso", "round_feet", "arc_feet", "simplest", "kuo")


def test_no_module_is_named_after_a_walker_family():
    """Modules are named by role (description, generated model, actuated flow and reset,
    views, optimisation), never by the walker family they were first written for."""
    pkg = Path(__file__).resolve().parents[1] / "walkerlab"
    named = [str(p.relative_to(pkg)) for p in pkg.rglob("*.py")
             if any(w in part for part in p.relative_to(pkg).with_suffix("").parts
                    for w in FAMILY_WORDS)]
    assert not named, named


def _kind_switch_reads(tree: ast.Module) -> list[int]:
    """Lines of ``tree`` that read a switch of the walker description that chooses its kind
    (:func:`walkerlab.walker.kinds.kind_of`): ``.free_knees``, ``.spokes``, ``knee.lock``,
    ``structure.knee`` / ``st.knee``, ``foot.kind``, a comparison with ``"flat"`` or
    ``"rimless_wheel"``."""
    out = []
    for n in ast.walk(tree):
        if isinstance(n, ast.Attribute) and (
                n.attr in ("free_knees", "spokes")
                or (n.attr == "lock" and getattr(n.value, "attr", "") == "knee")
                or (n.attr == "knee" and getattr(n.value, "attr", getattr(n.value, "id", ""))
                    in ("structure", "st"))
                or (n.attr == "kind" and getattr(n.value, "attr", "") == "foot")):
            out.append(n.lineno)
        elif isinstance(n, ast.Compare) and any(
                isinstance(c, ast.Constant) and c.value in ("flat", "rimless_wheel")
                for side in [n.left, *n.comparators]
                for c in (side.elts if isinstance(side, (ast.Tuple, ast.List, ast.Set))
                          else [side])):
            out.append(n.lineno)
    return out


#: modules outside walker/, codegen/ and config/ that may still read a kind switch (at most
#: three): the wheel's spoke count in its exported parameters (a number, not a branch), and a
#: check of the generated contact source whose text keys the compiled-module cache
KIND_SWITCH_READERS = {"export/spoked.py", "models/contact/generated.py"}


def test_the_walker_kind_is_chosen_once_and_the_layers_consult_it():
    """A walker's structural kind is chosen in ``walker/`` (from the description, which
    ``config/`` and ``codegen/`` also read); every other layer reaches its code for a kind
    through the kind (its table of parts) and reads its refusals from the capability table,
    never by testing the description's switches (at most three modules excepted)."""
    assert len(KIND_SWITCH_READERS) <= 3
    found = {}
    for p in sorted(PKG.rglob("*.py")):
        rel = p.relative_to(PKG)
        if rel.parts[0] in ("walker", "codegen", "config"):
            continue
        if lines := _kind_switch_reads(_tree(p)):
            found[rel.as_posix()] = lines
    assert set(found) <= KIND_SWITCH_READERS, found
    probe = ('if st.foot == "flat" or s.free_knees or leg.knee.lock: pass\nn = w.spokes\n'
             'r = f in ("arc", "flat")')
    assert sorted(_kind_switch_reads(ast.parse(probe))) == [1, 1, 1, 2, 3]  # the reader sees


def _top(rel: str) -> str:
    return rel.split("/")[0].removesuffix(".py")


def test_every_package_stands_on_a_floor_and_no_import_climbs():
    """Each top-level package or module of ``walkerlab/`` is placed in :data:`LAYERS` (a new
    one fails until it is), and no import, at module level or inside a function, reaches a
    floor above its module's."""
    floor = {name: i for i, names in enumerate(LAYERS) for name in names}
    tops = {_top(_rel(p)) for p in _modules()}
    assert tops - set(floor) == set(), f"place these in LAYERS: {sorted(tops - set(floor))}"
    up = []
    for p in _modules():
        here = floor[_top(_rel(p))]
        for m in _imports(p):
            if m.startswith("walkerlab."):
                there = floor.get(m.split(".")[1])
                if there is not None and there > here:
                    up.append(f"{_rel(p)} -> {m}")
    assert not up, up


#: the structure's switches that make a walker three-dimensional or give it a hip width or
#: hip-roll joints: read in the kinds' home (``walker/``) and ``config/``; the readers
#: outside, each with its reason (a new one fails: ask the kind, its parts or the capability
#: table instead)
SWITCH_3D_READERS = {
    "codegen/legged.py": "derives the legged walkers' equations: hip roll adds coordinates, a "
                         "hip width the heel strike's height guard",
    "export/legs_3d_mjcf.py": "writes one MJCF joint per hip roll",
    "export/legs_3d_parts.py": "the 3D legs' export roles: the pelvis on its roll with "
                               "hip-roll joints (the MJCF's, URDF's and Adams')",
    "export/adams_3d.py": "writes the Adams dataset's hip-roll joints and their law",
    "models/registry.py": "builds a 3D compass gait from its 2D scene's kind",
    "export/body_writers.py": "refuses a hip-roll walker per format (the capability table's "
                              "cell)",
    "models/contact/parts.py": "the 3D straight legs' contact part: a hip-roll law's power "
                               "is a term of the powered contact run's ledger",
}


def _switch_3d_reads(tree: ast.Module) -> list[int]:
    """Lines reading ``.space``, ``.hip_width`` or ``.hip_roll``."""
    return [n.lineno for n in ast.walk(tree) if isinstance(n, ast.Attribute)
            and n.attr in ("space", "hip_width", "hip_roll") and isinstance(n.ctx, ast.Load)]


def test_the_3d_switches_are_read_only_at_home_and_by_the_listed_readers():
    assert _switch_3d_reads(ast.parse("a = s.hip_roll or w.space == '3d'\n")) == [1, 1]
    found = {}
    for p in _modules():
        if _top(_rel(p)) in ("walker", "config"):
            continue
        if lines := _switch_3d_reads(_tree(p)):
            found[_rel(p)] = lines
    assert set(found) <= set(SWITCH_3D_READERS), found


def _kind_names() -> set[str]:
    from walkerlab.walker.kinds import KINDS

    return set(KINDS)


def _kind_compares(tree: ast.Module, kinds: set[str]) -> list[int]:
    """Lines comparing with a kind's name (``==``, ``in (...)``, a ``case``)."""
    def consts(side):
        return side.elts if isinstance(side, (ast.Tuple, ast.List, ast.Set)) else [side]

    out = [n.lineno for n in ast.walk(tree) if isinstance(n, ast.Compare)
           and any(isinstance(c, ast.Constant) and c.value in kinds
                   for s in [n.left, *n.comparators] for c in consts(s))]
    return out + [n.pattern.lineno for n in ast.walk(tree) if isinstance(n, ast.match_case)
                  and isinstance(n.pattern, ast.MatchValue)
                  and getattr(n.pattern.value, "value", None) in kinds]


def test_no_walker_kind_name_is_compared_outside_the_kinds_home():
    kinds = _kind_names()
    probe = ('if k == "flat_feet" or k in ("free_joints",): pass\n'
             'match k:\n  case "straight_legs": pass\n')
    assert len(_kind_compares(ast.parse(probe), kinds)) == 3
    # none outside walker/ (the last seven went in issue 80: ask the kind object - its
    # parts, e.g. Kind.feet_have_modes, Kind.joints_free - or its capability table instead)
    found = {_rel(p): v for p in _modules() if _top(_rel(p)) != "walker"
             and (v := _kind_compares(_tree(p), kinds))}
    assert not found, found


#: modules over 600 lines today, each with its size as a ceiling (split by role to go below)
BIG_MODULES = {"optimal/driver.py": 700}


def test_modules_stay_within_600_lines_or_their_ceiling():
    over = {}
    for p in _modules():
        n = len(p.read_text().splitlines())
        if n > BIG_MODULES.get(_rel(p), 600):
            over[_rel(p)] = n
    assert not over, over


def _unexplained_function_imports(path: Path) -> list[int]:
    """Lines of the imports of walkerlab made inside a function with no comment on their
    lines saying why (``# light``: kept off a light path; ``# circle``: at module level it
    would close an import circle)."""
    import io
    import tokenize

    src = path.read_text()
    comments = {t.start[0] for t in tokenize.generate_tokens(io.StringIO(src).readline)
                if t.type == tokenize.COMMENT}
    out = set()
    for f in ast.walk(_tree(path)):
        if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for n in ast.walk(f):
                if not isinstance(n, (ast.Import, ast.ImportFrom)):
                    continue
                mod = n.module if isinstance(n, ast.ImportFrom) else n.names[0].name
                if (getattr(n, "level", 0) or (mod or "").startswith("walkerlab")) and \
                        not comments & set(range(n.lineno, n.end_lineno + 1)):
                    out.add(n.lineno)
    return sorted(out)


#: function-level imports of walkerlab without a comment, today: the count may only fall
#: (a new one says why in a word, or moves to the top)
UNEXPLAINED_FUNCTION_IMPORTS = 360


def test_a_function_level_import_of_walkerlab_says_why(tmp_path):
    probe = tmp_path / "x.py"
    probe.write_text("def f():\n    from walkerlab.io import a\n"
                     "    from walkerlab.io import b  # light\n    import numpy\n")
    assert _unexplained_function_imports(probe) == [2]
    n = sum(len(_unexplained_function_imports(p)) for p in _modules())
    assert n <= UNEXPLAINED_FUNCTION_IMPORTS, n


#: the packages a ``# light`` import keeps off its module's import (third-party ones that
#: take tens of milliseconds or more to import, and the project's own heavy floors that the
#: command layer's start-up keeps out, tests/test_startup_imports.py)
HEAVY_PACKAGES = frozenset({
    "numpy", "scipy", "sympy", "casadi", "matplotlib", "numba", "CyRK", "h5py", "h5netcdf",
    "mujoco", "pinocchio", "pydrake", "dask", "distributed", "xarray", "gymnasium", "pandas",
    "opensim", "numbalsoda", "typer", "pydantic", "yaml"})
HEAVY_FLOORS = ("walkerlab.plotting", "walkerlab.studies", "walkerlab.optimal",
                "walkerlab.analysis.gait.poincare")


def _heavy_loaded(paths: dict[str, Path]):
    """``module -> the heavy packages importing it loads`` (through module-level imports,
    transitively; a package's ``__init__`` counted where its module is imported)."""
    tops = {m: _imports(p, module_level=True) for m, p in paths.items()}
    memo = {}

    def chain(name):
        parts = name.split(".")
        return [".".join(parts[:i]) for i in range(1, len(parts) + 1)]

    def heavy(m):
        if m not in memo:
            seen, todo, out = {m}, [m], set()
            while todo:
                x = todo.pop()
                if x.startswith(HEAVY_FLOORS):
                    out.add(x)
                for t in tops.get(x, []):
                    if t.split(".")[0] in HEAVY_PACKAGES:
                        out.add(t.split(".")[0])
                    for q in chain(t):
                        if q in paths and q not in seen:
                            seen.add(q)
                            todo.append(q)
            memo[m] = out
        return memo[m]
    return heavy, chain


def _light_claims_without_a_heavy_package(paths: dict[str, Path]) -> list[str]:
    """``module:line`` of each import of walkerlab inside a function whose comment says
    ``light`` but whose module loads no heavy package (:data:`HEAVY_PACKAGES`,
    :data:`HEAVY_FLOORS`) that the importing module does not load already: the comment
    claims a saving there is none of (the import belongs at module level)."""
    import io
    import tokenize

    heavy, chain = _heavy_loaded(paths)
    out = []
    for m, path in sorted(paths.items()):
        src = path.read_text()
        comments = {t.start[0]: t.string
                    for t in tokenize.generate_tokens(io.StringIO(src).readline)
                    if t.type == tokenize.COMMENT}
        pkg = _package(path)
        for f in ast.walk(_tree(path)):
            if not isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for n in ast.walk(f):
                if not isinstance(n, (ast.Import, ast.ImportFrom)):
                    continue
                said = " ".join(comments.get(k, "") for k in range(n.lineno, n.end_lineno + 1))
                if "light" not in said:
                    continue
                names = [x for x in _node_imports(n, pkg) if x.startswith("walkerlab")]
                if not names:
                    continue
                saved = set().union(*(heavy(q) for x in names for q in chain(x) if q in paths))
                if not saved - heavy(m):
                    out.append(f"{m}:{n.lineno}")
    return sorted(set(out))


def test_a_light_import_keeps_a_heavy_package_off_its_module():
    """A ``# light`` import inside a function is one whose module loads a heavy package
    (or one of the project's heavy floors) that its importer does not load already: the
    comment is measured, not taken on trust."""
    paths = {}
    for p in _modules():
        parts = p.relative_to(PKG.parent).with_suffix("").parts
        paths[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = p
    heavy, _ = _heavy_loaded(paths)
    assert "numpy" in heavy("walkerlab.numerics") and "sympy" in heavy("walkerlab.codegen.lagrange")
    assert _light_claims_without_a_heavy_package(paths) == []
