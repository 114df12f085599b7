"""The package's structure in numbers: each row of the structure table (per-kind tables, walker
kinds named as strings, ``"contact-sim"`` literals, ``walker_data`` callers, the modules below
the front that build a description of the walker (``Plant.from_scene`` or ``walker_data``:
the front, :data:`FRONT`, builds the plant once and hands it down), the functions below the
front that describe the walker themselves when handed no plant (a ``plant=None`` fallback
to ``Plant.from_scene``), the places that
write the Christoffel symbols, code kept as text, module and function sizes, duplicates, arrows
back up and import circles, the gym's run-time parsing and hook swapping), with its goal and
pass/fail.

Read from the source's syntax trees, never by running it: docstrings and comments do not
count.  The layer order is the one ``tests/test_layers.py`` keeps (``LAYERS``, bottom floor
first); an arrow back up is an import, at module level or inside a function, from a module of
a lower floor of one of a higher floor; a circle is a strongly connected set of modules of
the import graph (the one ``tests/test_layers.py`` checks).  The duplicate pairs are the
``duplicates`` command's count over ``walkerlab/`` (the row says ``n/a`` where that command
is not on PATH).

Usage::

    python scripts/structure_counts.py              # the table
    python scripts/structure_counts.py --json       # the numbers, as JSON
    python scripts/structure_counts.py --root DIR   # another checkout's walkerlab/
    python scripts/structure_counts.py --no-duplicates   # skip the slow duplicates row
"""

from __future__ import annotations

import argparse
import ast
import importlib.util
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]

#: the front: the top-level packages (and modules) below ``walkerlab/`` that build the plant
#: (:meth:`walkerlab.walker.plant.Plant.from_scene`) and hand it down - the walker's own
#: package, the stages, the API, the CLI, the benches - and the gym's constructor
#: (:data:`FRONT_FUNCTIONS`); everything else is below the front
FRONT = ("walker", "stages", "api", "cli", "bench")
#: functions of a package below the front that are front doors themselves: the gym's
#: constructor (``gym/``'s ``__init__``)
FRONT_FUNCTIONS = {"gym": ("__init__",)}


def _layers_module():
    """``tests/test_layers.py`` of this checkout, as a module (the layer order, the import
    graph and its circles)."""
    spec = importlib.util.spec_from_file_location("_test_layers", HERE / "tests" / "test_layers.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _kinds(root: Path) -> tuple[str, ...]:
    """The walker kinds' names: the keys of :data:`walkerlab.walker.kinds.KINDS` of the
    checkout at ``root`` (read in a child interpreter: the table is built from the kinds)."""
    import os

    code = "from walkerlab.walker.kinds import KINDS; print(' '.join(KINDS))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": str(root)}, cwd=root, timeout=120)
    if out.returncode:
        raise SystemExit(f"walkerlab.walker.kinds: {out.stderr.strip().splitlines()[-1]}")
    return tuple(out.stdout.split())


#: the words a layer's table of a kind's parts was keyed by (the kinds' part words before
#: the parts were objects: the rigid makers, landings, actuators, contact parts, exports'
#: bodies and feet, collocations): a dict keyed by two of them, or by two kind names, outside
#: ``walker/`` is a table of parts kept in a layer
PART_WORDS = frozenset({
    "legs", "kneed", "flat", "free", "wheel", "wheel_3d", "legs_3d", "five_link",
    "three_link", "hips", "latched_knees", "joints", "ankles", "clearance", "leg_ends",
    "links", "locking"})

#: attributes of a kind (:class:`walkerlab.walker.kinds.Kind`) a switch compares with a word
KIND_WORD_ATTRS = frozenset({"name", "body", "rigid", "knees", "feet", "landing", "contact",
                             "actuators", "collocation", "reaction", "scuff", "phases"})


def _is_kind_word(n, loops: bool = False) -> bool:
    """``kind.<attr>`` or ``<...>.kind.<attr>`` for a word attribute of the kind (with
    ``loops``, also ``k.<attr>``: a loop over the kinds)."""
    if not (isinstance(n, ast.Attribute) and n.attr in KIND_WORD_ATTRS):
        return False
    owner = n.value
    if loops and n.attr != "name" and isinstance(owner, ast.Name) and len(owner.id) == 1:
        return True
    return (isinstance(owner, ast.Name) and owner.id == "kind") or (
        isinstance(owner, ast.Attribute) and owner.attr == "kind")


def _kind_word_lookup(n) -> bool:
    """``TABLE[kind.<attr>]`` or ``TABLE.get(kind.<attr>, ...)``: a table of parts looked up
    by a kind's word."""
    if isinstance(n, ast.Subscript):
        return _is_kind_word(n.slice)
    return (isinstance(n, ast.Call) and _call_name(n) == "get" and bool(n.args)
            and _is_kind_word(n.args[0]))


def _kind_word_switch(n) -> bool:
    """``<...>.kind.<attr> == "word"`` (or ``!=``, ``in``/``not in`` a tuple of words), or
    ``kind.<attr>`` so compared: a switch on a kind's word."""
    if not isinstance(n, ast.Compare):
        return False
    if not _is_kind_word(n.left, loops=True):
        return False
    for c in n.comparators:
        if isinstance(c, ast.Constant) and isinstance(c.value, str):
            return True
        if isinstance(c, (ast.Tuple, ast.List, ast.Set)) and any(
                isinstance(e, ast.Constant) and isinstance(e.value, str) for e in c.elts):
            return True
    return False


def _docstrings(tree: ast.Module) -> set[int]:
    """``id`` of every docstring node (module, class, function)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
                    and isinstance(body[0].value.value, str):
                out.add(id(body[0].value))
    return out


def _strings(tree: ast.Module):
    """The string constants of ``tree`` that are not docstrings."""
    docs = _docstrings(tree)
    return [n for n in ast.walk(tree) if isinstance(n, ast.Constant)
            and isinstance(n.value, str) and id(n) not in docs]


def _is_diff(n) -> bool:
    """A derivative of a matrix entry: ``sp.diff(M[i, j], q)`` or ``dM[k][i, j]``."""
    if isinstance(n, ast.BinOp) and isinstance(n.op, ast.Mult):  # ... * dq[k]
        return _is_diff(n.left)
    if isinstance(n, ast.Call):
        f = n.func
        return (getattr(f, "attr", None) or getattr(f, "id", None)) == "diff"
    return isinstance(n, ast.Subscript) and isinstance(n.value, ast.Subscript)


def _writes_christoffel(tree: ast.Module) -> bool:
    """``(dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i)``: the symbols of the first kind, written out."""
    for n in ast.walk(tree):
        if (isinstance(n, ast.BinOp) and isinstance(n.op, ast.Sub)
                and isinstance(n.left, ast.BinOp) and isinstance(n.left.op, ast.Add)
                and all(_is_diff(x) for x in (n.left.left, n.left.right, n.right))):
            return True
    return False


def _call_name(n: ast.Call) -> str:
    return getattr(n.func, "attr", None) or getattr(n.func, "id", None) or ""


def _describes(n) -> bool:
    """``n`` builds a description of the walker: a call ``Plant.from_scene(...)`` or
    ``walker_data(...)``."""
    if not isinstance(n, ast.Call):
        return False
    name = _call_name(n)
    return name == "walker_data" or (name == "from_scene" and isinstance(n.func, ast.Attribute)
                                     and getattr(n.func.value, "id", "") == "Plant")


def _front_calls(tree: ast.Module, top: str) -> set[int]:
    """``id`` of the calls of ``tree`` (a module of package ``top``) made inside one of its
    front functions (:data:`FRONT_FUNCTIONS`)."""
    names = FRONT_FUNCTIONS.get(top, ())
    return {id(c) for f in ast.walk(tree)
            if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)) and f.name in names
            for c in ast.walk(f) if isinstance(c, ast.Call)}


def _floor(rel: str, layers) -> int | None:
    """The floor of the module at ``rel`` (a path below ``walkerlab/``)."""
    top = rel.split("/")[0].removesuffix(".py")
    for i, floor in enumerate(layers):
        if top in floor:
            return i
    return None


def measure(root: Path, duplicates: bool = True) -> list[dict]:
    """Every row of the table: ``name``, ``value`` (a number, or a tuple of numbers for a
    row of several), ``goal`` (the same shape), ``detail`` (where) and ``ok``."""
    tl = _layers_module()
    pkg = root / "walkerlab"
    kinds = set(_kinds(root))
    files = sorted(p for p in pkg.rglob("*.py") if "__pycache__" not in p.parts)
    trees, texts = {}, {}
    for p in files:
        texts[p] = p.read_text()
        trees[p] = ast.parse(texts[p], filename=str(p))

    def rel(p):
        return p.relative_to(pkg).as_posix()

    tables, kind_files, cs_files, wd_calls, christoffel = [], set(), set(), {}, []
    part_tables, kind_switches = [], []
    plant_builds = {}  # module -> ["line (plant=None default)" or "line"]
    plant_fallbacks = {}  # module -> ["function:line"]: a plant parameter defaulting to None
    described = {}  # module below the front -> lines of its Plant.from_scene / walker_data
    long_strings, gym_parse, gym_hook = [], [], []
    for p in files:
        r, tree = rel(p), trees[p]
        top = r.split("/")[0]
        below = r.removesuffix(".py").split("/")[0] not in FRONT
        front_calls = _front_calls(tree, top) if below else set()
        strings = _strings(tree)
        for n in ast.walk(tree):
            if top != "walker" and isinstance(n, ast.Dict):
                keys = {k.value for k in n.keys if isinstance(k, ast.Constant)} & kinds
                if len(keys) >= 2:
                    tables.append(f"{r}:{n.lineno}")
            if top != "walker" and isinstance(n, ast.Dict):
                keys = {k.value for k in n.keys if isinstance(k, ast.Constant)}
                if len(keys & (kinds | PART_WORDS)) >= 2:
                    part_tables.append(f"{r}:{n.lineno}")
            if top != "walker" and _kind_word_lookup(n):
                part_tables.append(f"{r}:{n.lineno} (lookup)")
            if top != "walker" and _kind_word_switch(n):
                kind_switches.append(f"{r}:{n.lineno}")
            if top != "walker" and isinstance(n, ast.Call) and _call_name(n) == "dict":
                if len({k.arg for k in n.keywords} & kinds) >= 2:
                    tables.append(f"{r}:{n.lineno}")
            if isinstance(n, ast.Call) and _call_name(n) == "walker_data":
                wd_calls.setdefault(r, []).append(n.lineno)
            if below and _describes(n) and id(n) not in front_calls:
                described.setdefault(r, []).append(n.lineno)
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)):
                a = n.args
                pos = a.posonlyargs + a.args
                defaults = dict(zip([x.arg for x in pos][len(pos) - len(a.defaults):],
                                    a.defaults))
                defaults.update({x.arg: d for x, d in zip(a.kwonlyargs, a.kw_defaults)
                                 if d is not None})
                d = defaults.get("plant")
                if isinstance(d, ast.Constant) and d.value is None:
                    plant_fallbacks.setdefault(r, []).append(f"{n.name}:{n.lineno}")
            if isinstance(n, ast.Call) and _call_name(n) == "from_scene" \
                    and getattr(n.func.value, "id", "") == "Plant":
                lines = texts[p].splitlines()  # a default: built only when none is given
                line, before = lines[n.lineno - 1], lines[n.lineno - 2].strip()
                default = " is None" in line or "plant or " in line or (
                    before.startswith("if ") and before.endswith(" is None:"))
                plant_builds.setdefault(r, []).append(
                    f"{n.lineno} (plant=None default)" if default else str(n.lineno))
            if top == "gym" and isinstance(n, ast.Call) and _call_name(n) == "parse" \
                    and getattr(n.func, "value", None) is not None \
                    and getattr(n.func.value, "id", "") == "ast":
                gym_parse.append(f"{r}:{n.lineno}")
            if top == "gym" and isinstance(n, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
                targets = n.targets if isinstance(n, ast.Assign) else [n.target]
                flat = [e for t in targets for e in (t.elts if isinstance(t, ast.Tuple) else [t])]
                if any(isinstance(e, ast.Attribute) and e.attr == "unraisablehook"
                       for e in flat):
                    gym_hook.append(f"{r}:{n.lineno}")
        if top not in ("walker", "config") and any(s.value in kinds for s in strings):
            kind_files.add(r)
        if any(s.value == "contact-sim" for s in strings):
            cs_files.add(r)
        if top != "codegen":
            long_strings += [f"{r}:{s.lineno} ({s.value.count(chr(10))} lines)"
                             for s in strings if s.value.count("\n") >= 60]
        if _writes_christoffel(tree):
            christoffel.append(r)

    sizes = {rel(p): len(texts[p].splitlines()) for p in files}
    def below_front(r):
        return r.removesuffix(".py").split("/")[0] not in FRONT

    wd_out = {r: v for r, v in wd_calls.items() if below_front(r)}
    plant_out = {r: v for r, v in plant_builds.items() if below_front(r)}
    fallback_out = {r: v for r, v in plant_fallbacks.items() if below_front(r)}

    # arrows back up, by the floors of tests/test_layers.py's LAYERS
    layers = tl.LAYERS
    arrows, unplaced = [], sorted({rel(p).split("/")[0].removesuffix(".py") for p in files
                                   if _floor(rel(p), layers) is None})
    for p in files:
        here = _floor(rel(p), layers)
        if here is None:
            continue
        for node, target in _walkerlab_imports(trees[p], p, pkg):
            there = _floor(target.replace(".", "/"), layers)
            if there is not None and there > here:
                arrows.append(f"{rel(p)}:{node.lineno} -> walkerlab.{target}")
    paths = {}
    for p in files:
        parts = p.relative_to(pkg.parent).with_suffix("").parts
        paths[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = p
    circles = tl._circles(tl._import_graph(paths))

    dup = _duplicates(root) if duplicates else None
    rows = [
        ("per-kind tables outside walker/ (dicts keyed by >= 2 kind names)", len(tables), 1,
         tables),
        ("tables keyed by part or kind words outside walker/ (dicts, lookups by kind.<part>)",
         len(part_tables), 1, part_tables),
        ("switches on a kind's word outside walker/ (kind.<part> == 'word')",
         len(kind_switches), 2, kind_switches),
        ("files naming a walker kind as a string outside walker/, config/", len(kind_files), 3,
         sorted(kind_files)),
        ('files with the literal "contact-sim"', len(cs_files), 6, sorted(cs_files)),
        ("modules calling walker_data(...) outside walker/, stages/, api/, cli/, bench/",
         len(wd_out), 0,
         {"modules": sorted(wd_out), "calls in all": sum(map(len, wd_calls.values())),
          "files in all": len(wd_calls)}),
        ("modules below the front building a description (Plant.from_scene / walker_data "
         "outside walker/, stages/, api/, cli/, bench/, the gym's constructor)",
         len(described), 4,
         {"modules": {r: v for r, v in sorted(described.items())},
          "Plant.from_scene below the front (all, the gym's constructor too)":
          {r: v for r, v in sorted(plant_out.items())}}),
        ("functions below the front describing the walker when handed no plant",
         sum(map(len, fallback_out.values())), 0,
         {"fallbacks (plant=None)": {r: v for r, v in sorted(fallback_out.items())}}),
        ("modules writing the Christoffel symbols", len(christoffel), 1, christoffel),
        ("strings of >= 60 lines outside codegen/", len(long_strings), 0, long_strings),
        ("modules > 800 lines", sum(v > 800 for v in sizes.values()), 0,
         sorted(k for k, v in sizes.items() if v > 800)),
        ("modules > 600 lines", sum(v > 600 for v in sizes.values()), 3,
         sorted(k for k, v in sizes.items() if v > 600)),
        ("lines in walkerlab/codegen/ (the derivations and their printers)",
         sum(v for k, v in sizes.items() if k.startswith("codegen/")), 6000,
         {k: v for k, v in sorted(sizes.items()) if k.startswith("codegen/")}),
        ("duplicate pairs in walkerlab/ (duplicates)", dup, 45, []),
        ("arrows back up (imports from a lower floor to a higher one)", len(arrows), 1,
         {"arrows": arrows, "packages in no floor": unplaced}),
        ("import circles", len(circles), 0, circles),
        ("gym/: ast.parse of generated code at run time", len(gym_parse), 0, gym_parse),
        ("gym/: sys.unraisablehook swapped (sites)", len(gym_hook), 0, gym_hook),
    ]
    return [{"name": n, "value": v, "goal": g, "detail": d,
             "ok": None if v is None else v <= g} for n, v, g, d in rows]


def _walkerlab_imports(tree: ast.Module, path: Path, pkg: Path):
    """``(node, "sub.module.name")`` for each walkerlab name imported, anywhere in the file
    (relative imports resolved)."""
    here = ".".join(path.relative_to(pkg.parent).with_suffix("").parts[:-1])
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("walkerlab."):
                    yield node, a.name.removeprefix("walkerlab.")
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = here.split(".")[:len(here.split(".")) - node.level + 1]
                base = ".".join(parts + ([base] if base else []))
            if base == "walkerlab":
                for a in node.names:
                    yield node, a.name
            elif base.startswith("walkerlab."):
                yield node, base.removeprefix("walkerlab.")


def _duplicates(root: Path) -> int | None:
    """The ``duplicates`` command's count of pairs over ``walkerlab/``."""
    exe = shutil.which("duplicates")
    if exe is None:
        return None
    out = subprocess.run([exe, "--repo", str(root / "walkerlab"), "--most", "1",
                          "--seconds", "300"], capture_output=True, text=True, cwd=root).stdout
    m = re.search(r"(\d+) pairs?", out)
    if m:
        return int(m.group(1))
    return 0 if "no duplicates" in out else None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, default=HERE, help="a checkout (default: this one)")
    ap.add_argument("--json", action="store_true", help="print the rows as JSON")
    ap.add_argument("--no-duplicates", action="store_true",
                    help="leave the duplicates row out (it takes a minute)")
    ap.add_argument("--details", action="store_true", help="list where, under each row")
    args = ap.parse_args(argv)
    rows = measure(args.root.resolve(), duplicates=not args.no_duplicates)
    if args.json:
        print(json.dumps(rows, indent=1, default=str))
        return 0
    width = max(len(r["name"]) for r in rows)
    for r in rows:
        mark = "n/a " if r["ok"] is None else ("pass" if r["ok"] else "FAIL")
        value = "n/a" if r["value"] is None else r["value"]
        print(f"{r['name']:<{width}}  {value!s:>5}  goal <= {r['goal']:<3}  {mark}")
        if args.details and r["detail"]:
            detail = r["detail"]
            for item in (detail if isinstance(detail, list) else
                         [f"{k}: {v}" for k, v in detail.items()]):
                print(f"    {item}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
