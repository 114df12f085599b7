"""Move walkerlab's unexplained function-level imports of walkerlab to the top of their
module, or say in a word why they stay (``# circle``, ``# light``).

For each import of walkerlab made inside a function with no comment on its lines (the rule
of ``tests/test_layers.py::_unexplained_function_imports``), in order:

- an import that climbs a floor (``LAYERS``) is left alone and listed (it must not exist);
- ``# light`` when the module imports the same module elsewhere inside a function with a
  reason (moving this one would load it all the same); when its run of imports carries its
  author's reason for being made inside the function (a comment in words beside one of them,
  or a comment line above them) and the module does not load the imported one anyway; when
  its module is on a light path (``import walkerlab.cli``, ``walkerlab [COMMAND] --help``,
  loading every shipped scene: each the modules it loads, a JSON list of lists given by
  ``--light``) and the imported module's module-level closure leaves it; or when importing
  the imported module loads a heavy package (numba, sympy, casadi, mujoco, matplotlib,
  scipy's integrators and optimisers, ...) that importing its module does not (measured:
  ``--loads``);
- ``# circle`` when at module level it would close an import circle as Python runs it (the
  module-level imports, with the packages a dotted import runs, but not the packages the
  importer itself lies in, which are imported first);
- else it moves to the top of the module (one top-level import for a name imported in
  several functions), unless moving would change what the name means (the module binds the
  name otherwise, the function binds it again, a test patches an attribute of that name, a
  ``try`` around it catches an ImportError, or its removal empties a block) or when it
  imports its own module: those are listed and left.

The decisions are greedy, in file order: each move adds its arrow before the next import is
judged.  ``--write`` edits the files (then ``ruff check --select I --fix`` sorts the top
imports); without it the script only prints its decisions.
"""

from __future__ import annotations

import argparse
import ast
import io
import json
import re
import sys
import tokenize
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "walkerlab"
sys.path.insert(0, str(ROOT / "tests"))

from test_layers import LAYERS  # noqa: E402

#: third-party packages (prefixes) whose import a light module avoids
HEAVY = ("numba", "llvmlite", "sympy", "casadi", "mujoco", "matplotlib", "CyRK", "gymnasium",
         "distributed", "dask", "xarray", "pandas", "h5py", "scipy.integrate", "scipy.optimize",
         "scipy.interpolate", "scipy.sparse", "scipy.stats", "scipy.signal", "scipy.spatial")
LINE = 100


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def ancestors(mod: str) -> list[str]:
    parts = mod.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


class Index:
    def __init__(self):
        self.paths = {module_name(p): p for p in sorted(PKG.rglob("*.py"))
                      if "__pycache__" not in p.parts}
        self.trees = {m: ast.parse(p.read_text()) for m, p in self.paths.items()}
        self.graph: dict[str, set[str]] = {}
        for m, tree in self.trees.items():
            edges = set()
            for node in module_level(tree):
                for base, names in import_targets(node, self.pkg_of(m)):
                    if base.startswith("walkerlab"):
                        edges |= self.edges(m, base, names)
            self.graph[m] = edges - {m}

    def pkg_of(self, m: str) -> str:
        return m if self.paths[m].name == "__init__.py" else m.rpartition(".")[0]

    def resolve(self, name: str) -> str | None:
        parts = name.split(".")
        for i in range(len(parts), 0, -1):
            if (c := ".".join(parts[:i])) in self.paths:
                return c
        return None

    def edges(self, importer: str, base: str, names: list[str]) -> set[str]:
        """The modules Python runs for ``from base import names`` (``import base`` when
        names is empty) in ``importer``, less the packages the importer lies in."""
        out = set()
        targets = [f"{base}.{n}" if f"{base}.{n}" in self.paths else base for n in names] \
            or [base]
        for t in targets:
            r = self.resolve(t)
            if r is None:
                continue
            out.add(r)
            out |= set(ancestors(r)) - set(ancestors(importer))
        if names and base in self.paths and any(f"{base}.{n}" not in self.paths for n in names):
            out.add(base)  # a name of the package's __init__
        return {o for o in out if o in self.paths}

    def closure(self, starts) -> set[str]:
        seen, todo = set(), list(starts)
        while todo:
            m = todo.pop()
            if m in seen:
                continue
            seen.add(m)
            todo += self.graph.get(m, ())
        return seen


def module_level(tree: ast.Module):
    """Import statements run when the module is imported (not inside functions, not under
    ``if TYPE_CHECKING``)."""
    todo = list(tree.body)
    while todo:
        n = todo.pop()
        if isinstance(n, (ast.Import, ast.ImportFrom)):
            yield n
        elif isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            continue
        elif isinstance(n, ast.If) and "TYPE_CHECKING" in ast.unparse(n.test):
            todo += n.orelse
        else:
            todo += [c for c in ast.iter_child_nodes(n) if isinstance(c, ast.stmt)]


def import_targets(node, pkg: str) -> list[tuple[str, list[str]]]:
    if isinstance(node, ast.Import):
        return [(a.name, []) for a in node.names]
    base = node.module or ""
    if node.level:
        parts = pkg.split(".")[:len(pkg.split(".")) - node.level + 1]
        base = ".".join(parts + ([base] if base else []))
    return [(base, [a.name for a in node.names])]


def comment_lines(src: str) -> set[int]:
    return {t.start[0] for t in tokenize.generate_tokens(io.StringIO(src).readline)
            if t.type == tokenize.COMMENT}


def bound_names(node) -> list[str]:
    if isinstance(node, ast.Import):
        return [a.asname or a.name.split(".")[0] for a in node.names]
    return [a.asname or a.name for a in node.names]


def patched_names() -> set[tuple[str | None, str]]:
    """``(module, name)`` of the attributes that the tests patch (``monkeypatch.setattr``,
    ``mock.patch``, a ``(module, "name")`` pair): a function-level import of such a name
    reads the patched attribute at call time.  ``module`` is None when the patched object's
    name does not resolve to a walkerlab module (then any import of ``name`` counts)."""
    out = set()
    for p in (ROOT / "tests").rglob("*.py"):
        text = p.read_text()
        alias = {}
        for n in ast.walk(ast.parse(text)):
            if isinstance(n, ast.Import):
                for a in n.names:
                    if a.asname:
                        alias[a.asname] = a.name
            elif isinstance(n, ast.ImportFrom) and (n.module or "").startswith("walkerlab"):
                for a in n.names:
                    alias[a.asname or a.name] = f"{n.module}.{a.name}"
        for obj, name in re.findall(r"[(,]\s*([\w.]+),\s*[\"'](\w+)[\"']", text):
            out.add((alias.get(obj, obj if obj.startswith("walkerlab.") else None), name))
        out |= {tuple(s.rsplit(".", 1)) for s in re.findall(
            r"[(,]\s*[\"']((?:walkerlab)[\w.]+)[\"']", text)}
    return out


def module_bindings(tree: ast.Module) -> dict[str, list[ast.AST]]:
    """Names bound at module level and the statements that bind them."""
    out = defaultdict(list)

    def visit(stmts):
        for s in stmts:
            if isinstance(s, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                out[s.name].append(s)
            elif isinstance(s, (ast.Import, ast.ImportFrom)):
                for n in bound_names(s):
                    out[n].append(s)
            elif isinstance(s, (ast.If, ast.Try, ast.With, ast.For, ast.While)):
                for n in ast.walk(s):
                    if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store):
                        out[n.id].append(s)
                for field in ("body", "orelse", "finalbody"):
                    visit(getattr(s, field, []))
                for h in getattr(s, "handlers", []):
                    visit(h.body)
            else:
                for n in ast.walk(s):
                    if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store):
                        out[n.id].append(s)
    visit(tree.body)
    return out


def scope_bindings(func) -> dict[str, int]:
    """How many times each name is bound in ``func``'s own scope (not nested functions)."""
    out = defaultdict(int)
    for a in func.args.posonlyargs + func.args.args + func.args.kwonlyargs:
        out[a.arg] += 1
    for a in (func.args.vararg, func.args.kwarg):
        if a:
            out[a.arg] += 1
    todo = list(func.body)
    while todo:
        n = todo.pop()
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            out[n.name] += 1
            todo += n.decorator_list
            continue
        if isinstance(n, ast.Lambda):
            continue
        if isinstance(n, (ast.Import, ast.ImportFrom)):
            for b in bound_names(n):
                out[b] += 1
        elif isinstance(n, ast.Name) and isinstance(n.ctx, (ast.Store, ast.Del)):
            out[n.id] += 1
        elif isinstance(n, ast.ExceptHandler) and n.name:
            out[n.name] += 1
        elif isinstance(n, (ast.Global, ast.Nonlocal)):
            for b in n.names:
                out[b] += 100
        todo += list(ast.iter_child_nodes(n))
    return out


def parents_map(tree):
    par = {}
    for n in ast.walk(tree):
        for c in ast.iter_child_nodes(n):
            par[c] = n
    return par


def skipped(rel: str) -> bool:
    return (rel.startswith(("gym/", "integrate/", "io/schemas/", "optimal/transcription/"))
            or rel in SKIP)


#: files other helpers edit now, and files whose text keys a cache (editing them would make
#: every user derive or compute again)
SKIP = {
    # other helpers
    "config/contact.py", "analysis/continuation/points.py", "export/adams.py",
    "studies/points.py", "walker/kinds.py", "optimal/replay/virtual_constraints.py",
    "optimal/driver.py", "analysis/gait/planar_start.py", "config/biped_parts.py",
    "bench/hzd.py", "cli/commands_families.py", "walker/plant.py", "codegen/derive_3d.py",
    "codegen/virtual_constraints.py", "bench/main_job.py", "report/text.py",
    "plotting/sweep_figures.py", "models/hybrid/actuated.py", "optimal/design/search.py",
    "export/opensim_xml.py", "models/virtual_constraints.py", "studies/params.py",
    "io/sweep_store.py", "models/hybrid/ground_reaction.py",
    # hashed into a code cache key (codegen/cache.py and the modules hashing __file__)
    "codegen/legged.py", "codegen/source.py", "walker/description.py", "codegen/cache.py",
    "codegen/equations.py", "codegen/lagrange.py",
    "codegen/compiled_source.py", "codegen/foot_modes.py", "codegen/printers.py",
    "walker/walker_trees.py", "codegen/frames.py",
    "codegen/tree_derive.py", "walker/tree.py", "walker/trees.py",
    "codegen/actuated.py", "codegen/torque_law.py", "codegen/floating.py",
    "codegen/floating_equations.py", "codegen/floating_names.py",
    "walker/floating_tree.py",
    "models/contact/generated.py", "models/contact/powered_source.py",
    "models/contact/rhs_lines.py", "models/contact/assembly.py",
    "models/contact/powered_kernels.py", "models/contact/_kernels.py",
    "codegen/contact_glue.py", "codegen/virtual_constraint_flow.py",
    "models/contact/virtual_constraints.py", "codegen/casadi_functions.py",
    "analysis/contact/drop.py", "models/contact/laws.py",
}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--light", type=Path, required=True,
                    help="JSON list of light paths, each the list of walkerlab modules it "
                         "loads (measured and written there when the file is absent)")
    ap.add_argument("--write", action="store_true")
    ap.add_argument("--only", default="", help="top-level package to edit (default: all)")
    ap.add_argument("--log", type=Path, help="write every decision here (JSON)")
    ap.add_argument("--loads", type=Path, required=True,
                    help="JSON {module: the modules importing it loads}, of the tree before "
                         "the moves (measured and written there when the file is absent)")
    args = ap.parse_args()
    if not args.light.exists():
        args.light.write_text(json.dumps(measure_light_paths()))
    paths = [set(p) for p in json.loads(args.light.read_text())]
    ix = Index()
    floor = {name: i for i, names in enumerate(LAYERS) for name in names}
    patched = patched_names()
    if not args.loads.exists():
        args.loads.write_text(json.dumps(measure_loads(sorted(ix.paths))))
    loads = {m: set(v) | {m} for m, v in json.loads(args.loads.read_text()).items()}

    def heavy(mods) -> set[str]:
        got = set().union(*(loads.get(m, {m}) for m in mods))
        return {h for h in HEAVY for x in got if x == h or x.startswith(h + ".")}

    log = []
    edits = {}
    for mod, path in ix.paths.items():
        rel = path.relative_to(PKG).as_posix()
        src = path.read_text()
        tree = ix.trees[mod]
        comments = comment_lines(src)
        said = {t.start[0]: t.string for t in tokenize.generate_tokens(
            io.StringIO(src).readline) if t.type == tokenize.COMMENT}
        par = parents_map(tree)
        lazy_here = _kept_lazy(ix, mod, tree, par, said, src.splitlines())
        top_binds = module_bindings(tree)
        here_floor = floor[rel.split("/")[0].removesuffix(".py")]
        plan = {"move": [], "light": [], "circle": [], "left": []}
        seen = set()
        for f in ast.walk(tree):
            if not isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for n in ast.walk(f):
                if not isinstance(n, (ast.Import, ast.ImportFrom)) or n in seen:
                    continue
                m = n.module if isinstance(n, ast.ImportFrom) else n.names[0].name
                if not ((getattr(n, "level", 0) or (m or "").startswith("walkerlab"))
                        and not comments & set(range(n.lineno, n.end_lineno + 1))):
                    continue
                seen.add(n)
                # the innermost function holding n
                func, p = None, par[n]
                while p is not None:
                    if isinstance(p, (ast.FunctionDef, ast.AsyncFunctionDef)):
                        func = p
                        break
                    p = par.get(p)
                entry = {"file": rel, "line": n.lineno, "import": ast.unparse(n)}
                log.append(entry)
                if skipped(rel):
                    entry["decision"] = "skipped file"
                    continue
                targets = set()
                for base, names in import_targets(n, ix.pkg_of(mod)):
                    up = floor.get(base.split(".")[1]) if "." in base else None
                    if up is not None and up > here_floor:
                        entry["decision"] = "climbs a floor"
                    targets |= ix.edges(mod, base, names)
                if mod in targets and not entry.get("decision"):
                    entry["decision"] = "left"
                    entry["why"] = "imports its own module"
                targets.discard(mod)
                if entry.get("decision"):
                    plan["left"].append((n, entry))
                    continue
                reach = ix.closure(targets)
                extra = set().union(*(reach - p for p in paths if mod in p))
                if extra:
                    entry["decision"] = "light"
                    entry["why"] = f"on a light path; would load {sorted(extra)[:3]}"
                    plan["light"].append(n)
                    continue
                more = heavy(targets) - heavy([mod])
                if more:
                    entry["decision"] = "light"
                    entry["why"] = f"would load {sorted(more)}"
                    plan["light"].append(n)
                    continue
                if not targets <= loads[mod] and _lazy_block(n, par, said, src.splitlines()):
                    entry["decision"] = "light"
                    entry["why"] = "its block is kept lazy (its author's comment says why)"
                    plan["light"].append(n)
                    continue
                direct = {r for base, names in import_targets(n, ix.pkg_of(mod))
                          for t in ([f"{base}.{x}" for x in names] or [base])
                          if (r := ix.resolve(t)) is not None}
                if direct & lazy_here - loads[mod]:
                    entry["decision"] = "light"
                    entry["why"] = f"the module keeps {sorted(direct & lazy_here)} lazy elsewhere"
                    plan["light"].append(n)
                    continue
                if mod in reach:
                    entry["decision"] = "circle"
                    plan["circle"].append(n)
                    continue
                why = None
                names = bound_names(n)
                parent = par[n]
                body = next(getattr(parent, fld) for fld in ("body", "orelse", "finalbody")
                            if n in getattr(parent, fld, []))
                if isinstance(n, ast.ImportFrom) and any(
                        (None, a.name) in patched
                        or (import_targets(n, ix.pkg_of(mod))[0][0], a.name) in patched
                        for a in n.names):
                    why = "a test patches the name"
                elif _guarded(n, par, func):
                    why = "inside a try that catches its failure"
                elif any(b in top_binds and not all(_same_import(s, n, b, ix.pkg_of(mod))
                                                    for s in top_binds[b]) for b in names):
                    why = "the module binds the name otherwise"
                elif any(scope_bindings(func)[b] > sum(1 for s in _imports_in(func)
                                                       if b in bound_names(s))
                         for b in names):
                    why = "the function binds the name again"
                elif all(s in seen_moves(plan) or s is n for s in body
                         if isinstance(s, (ast.Import, ast.ImportFrom))) and \
                        all(isinstance(s, (ast.Import, ast.ImportFrom)) for s in body):
                    why = "its removal would empty a block"
                elif any(b in scope_bindings(q) for q in _chain(par, func, None)
                         if isinstance(q, (ast.FunctionDef, ast.AsyncFunctionDef))
                         for b in names):
                    why = "an enclosing function binds the name"
                elif not _alone_on_lines(src, n):
                    why = "shares a line"
                if why:
                    entry["decision"] = "left"
                    entry["why"] = why
                    plan["left"].append((n, entry))
                    continue
                entry["decision"] = "move"
                plan["move"].append(n)
                ix.graph[mod] |= targets
        edits[rel] = plan
    counts = defaultdict(int)
    for e in log:
        counts[e["decision"]] += 1
    print(dict(counts))
    for e in log:
        if e["decision"] in ("left", "climbs a floor"):
            print(f"  {e['decision']}: {e['file']}:{e['line']} {e['import']} ({e.get('why')})")
    if args.log:
        args.log.write_text(json.dumps(log, indent=1))
    if args.write:
        for rel, plan in edits.items():
            if args.only and rel.split("/")[0].removesuffix(".py") != args.only:
                continue
            if plan["move"] or plan["light"] or plan["circle"]:
                rewrite(PKG / rel, plan)
    return 0


#: words of a comment that tells why imports are made inside a function
LAZY_WORDS = ("light", "only", "lazy", "lazily", "import", "heavy", "circle", "when", "needs",
              "compute")


def _lazy_block(n, par, said: dict[int, str], src_lines: list[str]) -> bool:
    """Whether the run of imports holding ``n`` carries its author's reason for being made
    inside the function: a comment in words on one of its imports (not a bare ``# light`` or
    ``# circle``, the words written for one import) or a comment line just above it, that
    speaks of why (:data:`LAZY_WORDS`)."""
    def tells(line: int) -> bool:
        text = said.get(line, "").lstrip("# ").lower()
        return text not in ("", "light", "circle") and not text.startswith("noqa") \
            and any(w in text for w in LAZY_WORDS)

    parent = par[n]
    body = next(getattr(parent, fld) for fld in ("body", "orelse", "finalbody")
                if n in getattr(parent, fld, []))
    i = body.index(n)
    lo = hi = i
    while lo > 0 and isinstance(body[lo - 1], (ast.Import, ast.ImportFrom)):
        lo -= 1
    while hi + 1 < len(body) and isinstance(body[hi + 1], (ast.Import, ast.ImportFrom)):
        hi += 1
    if any(tells(line) for s in body[lo:hi + 1] for line in range(s.lineno, s.end_lineno + 1)):
        return True
    above = body[lo].lineno - 1
    return tells(above) and src_lines[above - 1].lstrip().startswith("#")


def _kept_lazy(ix, mod, tree, par, said, src_lines) -> set[str]:
    """The modules that ``mod`` imports inside a function with a reason (a comment on the
    import, ``# circle`` aside, or its author's comment on its run of imports): moving another
    import of one of them to the top would load it all the same."""
    out = set()
    for f in ast.walk(tree):
        if not isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for n in ast.walk(f):
            if not isinstance(n, (ast.Import, ast.ImportFrom)):
                continue
            own = [said[line] for line in range(n.lineno, n.end_lineno + 1) if line in said]
            if (own and not all(c.strip() == "# circle" for c in own)) or \
                    _lazy_block(n, par, said, src_lines):
                for base, names in import_targets(n, ix.pkg_of(mod)):
                    for t in ([f"{base}.{x}" for x in names] or [base]):
                        if (r := ix.resolve(t)) is not None:
                            out.add(r)
    return out - {mod}


#: the light paths: the CLI's start, its help and each command's, and loading every scene
LIGHT_PATHS = [
    "import walkerlab.cli",
    *[f"import sys, walkerlab.cli\nsys.argv = ['walkerlab', *{args!r}, '--help']\n"
      "try:\n    walkerlab.cli.app()\nexcept SystemExit:\n    pass"
      for args in ([], ["fixedpoint"], ["simulate"], ["contact-sim"], ["compare"],
                   ["workprecision"], ["plot"], ["report"], ["sweep"], ["bifurcation"],
                   ["continuation"], ["target"], ["optimize"], ["basin"], ["mfpt"],
                   ["robustness"], ["stability-map"], ["animate"], ["export"], ["bench"],
                   ["capabilities"])],
    "from walkerlab.config.loader import load_scene\n"
    f"for p in sorted(__import__('pathlib').Path({str(ROOT / 'configs')!r}).glob('*.yaml')):\n"
    "    load_scene(p)",
]


def measure_light_paths() -> list[list[str]]:
    """The walkerlab modules each of :data:`LIGHT_PATHS` loads, each run in a fresh
    interpreter."""
    import subprocess

    out = []
    for code in LIGHT_PATHS:
        probe = (f"import atexit, json, sys\natexit.register(lambda: print(json.dumps(sorted("
                 f"m for m in sys.modules if m.startswith('walkerlab'))), file=sys.stderr))\n"
                 f"{code}\n")
        run = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                             cwd=ROOT, check=True)
        out.append(json.loads(run.stderr.strip().splitlines()[-1]))
    return out


def measure_loads(mods: list[str]) -> dict[str, list[str]]:
    """``{module: the modules importing it loads}``, each imported first in a child forked
    from this process (numpy, pydantic, yaml already loaded: light everywhere)."""
    import importlib
    import os

    import numpy  # noqa: F401
    import pydantic  # noqa: F401
    import yaml  # noqa: F401

    before = set(sys.modules)
    out = {}
    for m in mods:
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:  # the child: import, report, leave
            os.close(r)
            try:
                importlib.import_module(m)
                msg = json.dumps(sorted(set(sys.modules) - before))
            except BaseException as exc:  # noqa: BLE001 - reported, then fatal below
                msg = json.dumps({"error": repr(exc)})
            os.write(w, msg.encode())
            os._exit(0)
        os.close(w)
        chunks = []
        while chunk := os.read(r, 1 << 16):
            chunks.append(chunk)
        os.close(r)
        os.waitpid(pid, 0)
        got = json.loads(b"".join(chunks) or b'{"error": "no answer"}')
        if isinstance(got, dict):
            raise SystemExit(f"importing {m} failed: {got['error']}")
        out[m] = got
    return out


def _guarded(n, par, func) -> bool:
    """Whether ``n`` lies in the body of a ``try`` whose handlers catch an ImportError (a
    bare ``except``, ``ImportError``, ``ModuleNotFoundError``, ``Exception``,
    ``BaseException``): an import that may fail on purpose."""
    catching = {"ImportError", "ModuleNotFoundError", "Exception", "BaseException"}
    child = n
    for q in _chain(par, n, func):
        if isinstance(q, ast.Try) and child in q.body:
            for h in q.handlers:
                kinds = [] if h.type is None else (
                    h.type.elts if isinstance(h.type, ast.Tuple) else [h.type])
                if h.type is None or any(ast.unparse(k).split(".")[-1] in catching
                                         for k in kinds):
                    return True
        child = q
    return False


def seen_moves(plan):
    return set(plan["move"])


def _chain(par, n, func):
    p = par[n]
    while p is not func and p is not None:
        yield p
        p = par.get(p)


def _imports_in(func):
    todo = list(func.body)
    while todo:
        n = todo.pop()
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)):
            continue
        if isinstance(n, (ast.Import, ast.ImportFrom)):
            yield n
        todo += list(ast.iter_child_nodes(n))


def _same_import(stmt, n, name, pkg) -> bool:
    """Whether the module-level ``stmt`` binds ``name`` to what ``n`` binds it to."""
    if not isinstance(stmt, type(n)) or isinstance(stmt, ast.ImportFrom) and (
            import_targets(stmt, pkg)[0][0] != import_targets(n, pkg)[0][0]):
        return False
    pick = {(a.asname or (a.name if isinstance(n, ast.ImportFrom) else a.name.split(".")[0])):
            a.name for a in n.names}
    pick_s = {(a.asname or (a.name if isinstance(stmt, ast.ImportFrom)
                            else a.name.split(".")[0])): a.name for a in stmt.names}
    if isinstance(n, ast.Import):
        return name in pick_s and pick_s[name].split(".")[0] == pick[name].split(".")[0] \
            and not any(a.asname for a in n.names + stmt.names if
                        (a.asname or a.name.split(".")[0]) == name)
    return pick_s.get(name) == pick.get(name)


def _alone_on_lines(src: str, n) -> bool:
    lines = src.splitlines()
    first, last = lines[n.lineno - 1], lines[n.end_lineno - 1]
    return first[:n.col_offset].strip() == "" and last[n.end_col_offset:].strip() == ""


def rewrite(path: Path, plan) -> None:
    src = path.read_text()
    lines = src.splitlines(keepends=True)
    tree = ast.parse(src)
    drop = set()
    new_top = []
    doc_ends = {f.body[0].end_lineno for f in ast.walk(tree)
                if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))
                and isinstance(f.body[0], ast.Expr)
                and isinstance(f.body[0].value, ast.Constant)}
    for n in plan["move"]:
        drop |= set(range(n.lineno - 1, n.end_lineno))
        text = " ".join(ast.unparse(n).split())
        if text not in new_top:
            new_top.append(text)
    notes = {}
    for word in ("light", "circle"):
        for n in plan[word]:
            notes[n] = word
    for n, word in notes.items():
        i = n.lineno - 1
        line = lines[i].rstrip("\n")
        if n.end_lineno == n.lineno and len(line) + len(word) + 4 > LINE:
            # too long with its word: open parentheses (from-imports only)
            assert isinstance(n, ast.ImportFrom), (path, n.lineno)
            head, _, names = line.partition(" import ")
            indent = line[:len(line) - len(line.lstrip())]
            lines[i] = f"{head} import (  # {word}\n{indent}    {names.strip()})\n"
        elif n.end_lineno == n.lineno:
            lines[i] = f"{line}  # {word}\n"
        else:
            assert line.rstrip().endswith("("), (path, n.lineno)
            lines[i] = f"{line}  # {word}\n"
    # drop the moved lines, and the blank line that parted them from the code when they
    # followed the header, the docstring, a comment or a blank line
    out = []
    for i, line in enumerate(lines):
        if i in drop:
            continue
        if line.strip() == "" and i - 1 in drop:
            j = i - 1
            while j in drop:
                j -= 1
            prev = lines[j].rstrip() if j >= 0 else ""
            if prev.endswith(":") or prev == "" or j + 1 in doc_ends or \
                    prev.lstrip().startswith("#"):
                continue
        out.append(line)
    if new_top:
        last = _last_top_import(tree)
        existing = {" ".join(ast.unparse(s).split()) for s in tree.body
                    if isinstance(s, (ast.Import, ast.ImportFrom))}
        add = [t + "\n" for t in new_top if t not in existing]
        if add:
            # the index of the line after the last top-level import, in the new numbering
            at = last - sum(1 for d in drop if d < last)
            if at == 0:  # no top imports yet: after the docstring and __future__
                at = _after_docstring(tree) - sum(1 for d in drop if d < _after_docstring(tree))
                add = add + ["\n"] if out[at:at + 1] != ["\n"] else add
                add = (["\n"] if at and out[at - 1].strip() else []) + add
            out[at:at] = add
    path.write_text("".join(out))


def _last_top_import(tree) -> int:
    last = 0
    for s in tree.body:
        if isinstance(s, (ast.Import, ast.ImportFrom)):
            last = s.end_lineno
        elif isinstance(s, ast.If) and "TYPE_CHECKING" in ast.unparse(s.test):
            continue
        elif isinstance(s, ast.Expr) and isinstance(getattr(s, "value", None), ast.Constant):
            continue
        elif last:
            break
    return last


def _after_docstring(tree) -> int:
    s = tree.body[0] if tree.body else None
    if s is not None and isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant):
        return s.end_lineno
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
