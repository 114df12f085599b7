"""Docstring coverage of the library packages, read with :mod:`ast` (nothing is imported).

Lists every public function and class of ``walkerlab/`` outside the front floors (``cli/``,
``api/``, ``stages/``) and private modules (``_name.py``): module-level functions and
classes whose name has no leading underscore, and the public methods (properties included)
of public classes.  ``__init__.py`` re-exports are imports, so they are not counted; only
what a module defines is.

For each definition it reports four qualities of the docstring and whether each *applies*:

- **shapes** -- an array shape (``shape``, ``(n,)``, ``(2n,)``, ``ndarray (``, ``(m, k)``,
  ...).  Applies where a parameter or the return is annotated as an array (``ndarray``,
  ``ArrayLike``, ``NDArray``), a parameter has an array-like name (``x``, ``y0``, ``state``,
  ``q``, ``qd``, ``z``, ...), or the docstring itself speaks of an array.
- **units** -- a bracketed unit (``[rad]``, ``[m/s]``, ``[-]``, ``[N m]``, ...) or the words
  "unit"/"SI"/"dimensionless".  Applies where shapes apply or a parameter names a physical
  quantity (slope, angle, time, mass, length, speed, energy, stiffness, ...).
- **errors** -- a ``Raises`` section.  Applies where the body (nested definitions excluded)
  holds a ``raise`` of an exception other than ``NotImplementedError``, or calls a helper
  that obviously raises (``_check*``, ``_require*``, ``_validate*``, ``_ensure*``,
  ``validate*``, ``check_*``, ``require*``); for a class, where its ``__init__`` or
  ``__post_init__`` does.
- **source** -- a reference (``Eq.``, ``et al.``, ``paper``, an author-year, a section of a
  book).  Applies in the physics and numerics packages (:data:`SOURCE_PACKAGES`) where the
  name or the docstring's first paragraph speaks of a model formula (impact, heel strike,
  Floquet multipliers, Jacobian, Poincaré map, MFPT, energy, contact law, fixed point, ...).

Prints the percentages over all definitions (unweighted) and over those where the quality
applies (weighted), per package, and the worst modules by missing pieces.

Usage::

    python scripts/docstring_coverage.py [--root walkerlab] [--list] [--json FILE]
        [--exclude GLOB ...] [--worst N]
"""

from __future__ import annotations

import argparse
import ast
import fnmatch
import json
import re
import sys
from dataclasses import asdict, dataclass, field
from pathlib import Path

FRONT = ("cli", "api", "stages")
QUALITIES = ("docstring", "shapes", "units", "errors", "source")

_DIM = r"\d*\s*[a-zA-Z_]*(?:\s*[-+*/]\s*\d*\s*[a-zA-Z_]*)*"  # n, 2n, 2 nq, n - 1, 2 n + 1
SHAPE_RE = re.compile(
    r"shape|ndarray\s*\(|\bscalar\b|\bn[_ ]?(rows|points|steps)\b|"
    rf"\(\s*{_DIM}\s*,\s*\)|\(\s*{_DIM}\s*,\s*{_DIM}(\s*,\s*{_DIM})*\s*\)")
UNIT_RE = re.compile(
    r"\[(-|1|rad|deg|m|mm|s|ms|kg|N|J|W|Hz|rad/s|m/s|N m|N s/m|kg m\^?2|[^\]\n]{0,20}"
    r"(rad|m|s|kg|N|J|W|Hz|g|l)\b[^\]\n]{0,12})\]|\bunits?\b|\bSI\b|dimensionless|"
    r"nondimensional", re.I)
RAISES_RE = re.compile(r"^\s*Raises\s*\n\s*-{3,}", re.M)
SOURCE_RE = re.compile(
    r"\bEqs?\.|\bet al\.|\bpaper\b|\b[A-Z][a-z]+(?: & [A-Z][a-z]+)? \(?(19|20)\d\d\b|"
    r"\bSection \d|\bsec\. \d|\bTable \d|\bFig\. \d|\bTedrake|\bStrogatz|\bHairer|"
    r"MSC Adams|Adams/(Solver|View)|NOTES\.md|module docstring", re.I)

ARRAY_ANN_RE = re.compile(r"ndarray|ArrayLike|NDArray|np\.array")
ARRAY_NAMES = {
    "x", "x0", "y", "y0", "z", "z0", "q", "qd", "qdd", "state", "states", "state0",
    "y_minus", "y_plus", "xs", "ys", "t_eval", "times", "grid", "points", "values",
    "samples", "fixed_point", "multipliers", "jacobian", "traj", "trajectory", "arr",
    "array", "vec", "w", "u", "theta", "thetas", "omegas", "q0", "qd0", "y_pre", "y_post",
}
ARRAY_WORD_RE = re.compile(r"\barray\b|\bndarray\b|\bvector\b|\bmatrix\b", re.I)
PHYS_NAME_RE = re.compile(
    r"slope|gamma|angle|theta|phi|omega|^t$|^t_|_t$|time|^dt|period|mass|length|leg|speed|"
    r"velocity|force|torque|energy|stiff|damp|height|stride|friction|^mu$|push|impulse|"
    r"rough|amplitude|radius|inertia|^g$|gravity|^k$|^c$|tol|span|duration|distance|"
    r"state|^q$|^qd$|^y0?$|^x0?$|^z0?$", re.I)
SOURCE_TOPIC_RE = re.compile(
    r"impact|heel.?strike|collision|floquet|jacobian|poincar|mfpt|first.passage|"
    r"cost.of.transport|hunt|crossley|kelvin|coulomb|friction|contact.law|ground.reaction|"
    r"penetration|gsn|gait.sensitivity|lyapunov|energ(y|ies)\b|fixed.point|multiplier|"
    r"equations? of motion|mass matrix|eigen", re.I)
#: the physics and numerics floors, where a formula has a source
SOURCE_PACKAGES = ("analysis", "models", "integrate", "numerics", "published", "studies",
                   "walker", "codegen")
RAISING_CALL_RE = re.compile(r"^_?(check|require|validate|ensure)\w*|^raise_\w+")


@dataclass
class Item:
    """One public definition and the qualities of its docstring."""

    module: str
    name: str
    kind: str
    line: int
    have: dict = field(default_factory=dict)
    needs: dict = field(default_factory=dict)

    @property
    def package(self) -> str:
        parts = self.module.split("/")
        return parts[1] if len(parts) > 2 else parts[-1].removesuffix(".py")


def _body_raises(node: ast.AST) -> bool:
    """``raise`` (not NotImplementedError) or a call to an obviously raising helper, in
    ``node``'s own body (nested functions and classes excluded)."""
    stack = list(ast.iter_child_nodes(node))
    while stack:
        n = stack.pop()
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)):
            continue
        if isinstance(n, ast.Raise) and n.exc is not None:
            exc = n.exc.func if isinstance(n.exc, ast.Call) else n.exc
            name = exc.id if isinstance(exc, ast.Name) else getattr(exc, "attr", "")
            if name != "NotImplementedError":
                return True
        if isinstance(n, ast.Call):
            f = n.func
            name = f.id if isinstance(f, ast.Name) else getattr(f, "attr", "")
            if RAISING_CALL_RE.match(name or ""):
                return True
        stack.extend(ast.iter_child_nodes(n))
    return False


def _args(fn: ast.FunctionDef) -> list[ast.arg]:
    a = fn.args
    out = [*a.posonlyargs, *a.args, *a.kwonlyargs]
    if a.vararg:
        out.append(a.vararg)
    if a.kwarg:
        out.append(a.kwarg)
    return [x for x in out if x.arg not in ("self", "cls")]


def _ann(node) -> str:
    return ast.unparse(node) if node is not None else ""


def _assess(item: Item, node, doc: str, fields: list[tuple[str, str]]) -> None:
    """Fill ``item.have`` and ``item.needs`` from the definition and its docstring."""
    arrayish = any(ARRAY_ANN_RE.search(ann) or name in ARRAY_NAMES for name, ann in fields)
    arrayish = arrayish or bool(ARRAY_WORD_RE.search(doc))
    physical = any(PHYS_NAME_RE.search(name) for name, _ in fields)
    if isinstance(node, ast.ClassDef):
        raises = any(isinstance(b, ast.FunctionDef) and b.name in ("__init__", "__post_init__")
                     and _body_raises(b) for b in node.body)
    else:
        raises = _body_raises(node)
    summary = doc.strip().split("\n\n")[0]
    topic = item.package in SOURCE_PACKAGES and item.kind != "property" and bool(
        SOURCE_TOPIC_RE.search(item.name.replace("_", " ") + " " + summary))
    item.have = {
        "docstring": bool(doc.strip()),
        "shapes": bool(SHAPE_RE.search(doc)),
        "units": bool(UNIT_RE.search(doc)),
        "errors": bool(RAISES_RE.search(doc)),
        "source": bool(SOURCE_RE.search(doc)),
    }
    item.needs = {
        "docstring": True,
        "shapes": arrayish,
        "units": arrayish or physical,
        "errors": raises,
        "source": topic,
    }


def _class_fields(cls: ast.ClassDef) -> list[tuple[str, str]]:
    """Annotated class attributes (dataclass fields) and ``__init__`` parameters."""
    out = []
    for b in cls.body:
        if isinstance(b, ast.AnnAssign) and isinstance(b.target, ast.Name):
            if not b.target.id.startswith("_"):
                out.append((b.target.id, _ann(b.annotation)))
        elif isinstance(b, ast.FunctionDef) and b.name == "__init__":
            out += [(a.arg, _ann(a.annotation)) for a in _args(b)]
    return out


def _fn_fields(fn) -> list[tuple[str, str]]:
    out = [(a.arg, _ann(a.annotation)) for a in _args(fn)]
    out.append(("return", _ann(fn.returns)))
    return out


def scan_module(path: Path, rel: str) -> list[Item]:
    tree = ast.parse(path.read_text(), filename=str(path))
    items = []
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            if node.name.startswith("_"):
                continue
            it = Item(rel, node.name, "function", node.lineno)
            _assess(it, node, ast.get_docstring(node) or "", _fn_fields(node))
            items.append(it)
        elif isinstance(node, ast.ClassDef):
            if node.name.startswith("_"):
                continue
            it = Item(rel, node.name, "class", node.lineno)
            _assess(it, node, ast.get_docstring(node) or "", _class_fields(node))
            items.append(it)
            for b in node.body:
                if isinstance(b, (ast.FunctionDef, ast.AsyncFunctionDef)) \
                        and not b.name.startswith("_"):
                    deco = {_ann(d) for d in b.decorator_list}
                    kind = "property" if "property" in deco else "method"
                    m = Item(rel, f"{node.name}.{b.name}", kind, b.lineno)
                    _assess(m, b, ast.get_docstring(b) or "", _fn_fields(b))
                    items.append(m)
    return items


def scan(root: Path, exclude: list[str]) -> list[Item]:
    items = []
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root.parent).as_posix()
        parts = path.relative_to(root).parts
        if parts[0] in FRONT or (path.name.startswith("_") and path.name != "__init__.py"):
            continue
        if any(p.startswith("_") and p != "__init__.py" for p in parts[:-1]):
            continue
        if any(fnmatch.fnmatch(rel, g) for g in exclude):
            continue
        items += scan_module(path, rel)
    return items


def _pct(num: int, den: int) -> str:
    return f"{100 * num / den:5.1f}%" if den else "   - "


def summarize(items: list[Item]) -> dict:
    """Per quality: count having it, count needing it, count needing and having it."""
    out = {}
    for q in QUALITIES:
        have = sum(it.have[q] for it in items)
        need = sum(it.needs[q] for it in items)
        ok = sum(it.have[q] and it.needs[q] for it in items)
        out[q] = {"have": have, "need": need, "ok": ok, "n": len(items)}
    return out


def _row(label: str, items: list[Item]) -> str:
    s = summarize(items)
    cells = [f"{_pct(s[q]['have'], s[q]['n'])} {_pct(s[q]['ok'], s[q]['need'])}"
             for q in QUALITIES]
    return f"{label:<34}{len(items):>5}  " + "  ".join(cells)


def missing(it: Item) -> list[str]:
    return [q for q in QUALITIES if it.needs[q] and not it.have[q]]


def report(items: list[Item], worst: int, listing: bool) -> None:
    head = f"{'':<34}{'n':>5}  " + "  ".join(f"{q:^13}" for q in QUALITIES)
    sub = f"{'(all / where it applies)':<34}{'':>5}  " + "  ".join(
        f"{'all':>6} {'appl':>6}" for _ in QUALITIES)
    print(head)
    print(sub)
    print(_row("OVERALL", items))
    s = summarize(items)
    print(f"{'  applies to':<34}{'':>5}  " + "  ".join(
        f"{'':>6} {s[q]['need']:>6}" for q in QUALITIES))
    print()
    pkgs = sorted({it.package for it in items})
    for p in pkgs:
        print(_row(p, [it for it in items if it.package == p]))
    print()
    mods: dict[str, list[Item]] = {}
    for it in items:
        mods.setdefault(it.module, []).append(it)
    ranked = sorted(mods.items(), key=lambda kv: -sum(len(missing(i)) for i in kv[1]))
    print(f"worst {worst} modules (missing pieces where they apply):")
    for mod, its in ranked[:worst]:
        miss = sum(len(missing(i)) for i in its)
        need = sum(sum(i.needs.values()) for i in its)
        print(f"  {miss:4d} / {need:4d}  {mod}")
    if listing:
        print()
        for it in items:
            m = missing(it)
            if m:
                print(f"{it.module}:{it.line}: {it.name} ({it.kind}) missing {', '.join(m)}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path,
                    default=Path(__file__).resolve().parents[1] / "walkerlab")
    ap.add_argument("--exclude", action="append", default=[],
                    help="glob of module paths (relative, e.g. 'walkerlab/config/*') to skip")
    ap.add_argument("--worst", type=int, default=15)
    ap.add_argument("--list", action="store_true", help="list every definition missing a piece")
    ap.add_argument("--json", type=Path, help="write the per-definition table as JSON")
    args = ap.parse_args(argv)
    items = scan(args.root, args.exclude)
    report(items, args.worst, args.list)
    if args.json:
        args.json.write_text(json.dumps({"summary": summarize(items),
                                         "items": [asdict(i) for i in items]}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
