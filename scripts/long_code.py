"""List the modules over a line limit and the functions over a length limit.

Usage: ``python scripts/long_code.py [PACKAGE_DIR] [--module-lines N] [--function-lines N]``
(defaults: ``walkerlab``, 400, 80). A function's length is its ``def`` line through its last
line, decorators excluded; nested functions are listed on their own as well. The last line
counts the upper floors (stages/, cli, report/, plotting/, execution/) separately.
"""

from __future__ import annotations

import argparse
import ast
from pathlib import Path

UPPER = ("stages", "cli", "report", "plotting", "execution")


def long_functions(path: Path, limit: int) -> list[tuple[str, int]]:
    """Return ``(qualified name, lines)`` of every function in ``path`` longer than ``limit``."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found: list[tuple[str, int]] = []

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                name = f"{prefix}{child.name}"
                if not isinstance(child, ast.ClassDef):
                    length = child.end_lineno - child.lineno + 1
                    if length > limit:
                        found.append((name, length))
                visit(child, name + ".")
            else:
                visit(child, prefix)

    visit(tree, "")
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("package", nargs="?", default="walkerlab")
    parser.add_argument("--module-lines", type=int, default=400)
    parser.add_argument("--function-lines", type=int, default=80)
    args = parser.parse_args()
    root = Path(args.package)
    files = sorted(root.rglob("*.py"))
    modules = [(f, len(f.read_text().splitlines())) for f in files]
    big = sorted((m for m in modules if m[1] > args.module_lines), key=lambda m: -m[1])
    print(f"modules over {args.module_lines} lines: {len(big)}")
    for f, n in big:
        print(f"  {n:5d}  {f}")
    funcs = [(f, name, n) for f in files for name, n in long_functions(f, args.function_lines)]
    funcs.sort(key=lambda t: -t[2])
    print(f"functions over {args.function_lines} lines: {len(funcs)}")
    for f, name, n in funcs:
        print(f"  {n:5d}  {f}:{name}")

    def upper(f: Path) -> bool:
        rel = f.relative_to(root).parts
        return rel[0] in UPPER or rel[0] in ("cli.py",)

    n_upper = sum(1 for f, _, _ in funcs if upper(f))
    print(f"of which in the upper floors ({', '.join(UPPER)}): {n_upper}")


if __name__ == "__main__":
    main()
