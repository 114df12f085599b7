"""Nothing outside the model layer reads a state by row or tests a walker's size against a
number (STYLE: "state by name, sized by the walker").

An AST scan of every module of walkerlab/ outside the model layer (:data:`MODEL_LAYER`) for

- a subscript of a single-state variable (``x``, ``x0``, ``x_ideal``, ``fp``, ``z``, ``q``,
  ``qd``, ...) by an integer literal, a slice with a literal bound, or a literal offset from
  a count (``x[2]``, ``x[-1]``, ``x[:4]``, ``x[n:-1]``, ``x[n + 2]``);
- a comparison of a count with a literal (``walker.nq == 4``, ``if nq == 6``,
  ``len(walker.roles) == 3``).

Arrays of many states (``X``, ``Y``: samples by rows in the contact runs, by columns in the
rigid ones) are out of its reach: a literal index there is usually a sample (``X[-1]``),
which the AST cannot tell from a row; they address states through ``walker.layout()`` /
``StateIndex`` by review.
"""

import ast
import re
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "walkerlab"
#: the model layer, before and after the package move (walker/, codegen/, models/)
MODEL_LAYER = ("models", "contact", "walker", "codegen")
SINGLE_STATE = re.compile(r"^(x|x0|x1|xp|xe|xa|xk|x_\w+|fp|state|z|z0|zp|q|qd|dq)$")
#: names of a walker's counts: any of them in a row offset (``x[n + 2]``); the unambiguous
#: ones (not a loop's ``n``) also compared with a literal (``walker.nq == 4``)
COUNT = re.compile(r"^(n|nq|NQ|nx|NX|n_coordinates|n_states)$")
WALKER_COUNT = re.compile(r"^(nq|NQ|n_coordinates|n_states)$")
#: (path relative to walkerlab/, source of the subscript): why it is not a state
ALLOWED = {("config/errors.py", "x[:1]"): "the first character of an exponent string",
           # the benchmark's plain-numba baseline is a hand-written compass gait, a model of
           # its own that shares nothing with the library (walkerlab.bench.monte_carlo_yardstick)
           **{(f"bench/{f}.py", f"x[{i}]"): "the baseline's own compass state"
              for f in ("monte_carlo_yardstick", "minimal_casadi") for i in range(4)},
           # the design benchmark's baseline: the book's three-link walker written by hand
           # in CasADi, no walkerlab import (walkerlab.bench.minimal_casadi_hzd)
           **{("bench/minimal_casadi_hzd.py", s): "the baseline's own three-link state"
              for s in ("dq[0]", "dq[1]", "dq[2]", "q[0]", "q[1]", "q[2]", "x[0]", "x[1:3]",
                        "x[1]", "x[2]", "x[3]", "x[3:]", "x[4:6]", "x[:3]", "xp[3:]",
                        "xp[:3]")}}


def _int_literal(e) -> bool:
    try:
        v = ast.literal_eval(e)
    except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
        return False
    return isinstance(v, int) and not isinstance(v, bool)


def _is_count(e, names=COUNT) -> bool:
    if isinstance(e, ast.Name):
        return bool(names.match(e.id))
    if isinstance(e, ast.Attribute):
        return bool(names.match(e.attr))
    if isinstance(e, ast.Call) and getattr(e.func, "id", "") == "len" and e.args:
        return bool(re.search(r"roles|state_names|coordinate", ast.unparse(e.args[0])))
    return False


def _literal_row(e) -> bool:
    if _int_literal(e):
        return True
    return (isinstance(e, ast.BinOp) and any(_int_literal(s) for s in (e.left, e.right))
            and any(_is_count(s) for s in (e.left, e.right)))


def _row_index(sl) -> bool:
    for part in (sl.elts if isinstance(sl, ast.Tuple) else [sl]):
        bounds = [part.lower, part.upper] if isinstance(part, ast.Slice) else [part]
        if any(b is not None and _literal_row(b) for b in bounds):
            return True
    return False


def findings(source: str) -> list[str]:
    """Source of every state-by-row subscript and count-against-literal comparison."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if (isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name)
                and SINGLE_STATE.match(node.value.id) and _row_index(node.slice)):
            out.append(ast.unparse(node))
        elif isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if (any(_int_literal(s) for s in sides)
                    and any(_is_count(s, WALKER_COUNT) for s in sides)):
                out.append(ast.unparse(node))
    return out


def test_the_scan_finds_what_it_looks_for():
    # the forms this test exists to catch (each was in the package once), and their by-name
    # or per-sample neighbours that it must let pass
    bad = ["x[2]", "x[-1]", "x_ideal[0:2]", "x[n:-1]", "x[n + 2]", "z[:, 3]",
           "walker.nq == 4", "nq == 6", "len(walker.structure.roles) == 3", "6 == w.NQ"]
    good = ["x[lay.index('stance_angle')]", "x[lay.qd_slice]", "X[-1]", "X[k - 1]",
            "x[k + 1]", "x[i]", "lay.size == guess.size"]
    assert [findings(s) for s in bad] == [[s] for s in bad]
    assert [findings(s) for s in good] == [[]] * len(good)


def test_no_state_read_by_row_outside_the_model_layer():
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel.split("/", 1)[0] in MODEL_LAYER:
            continue
        found += [f"walkerlab/{rel}: {s}" for s in findings(path.read_text())
                  if (rel, s) not in ALLOWED]
    assert not found, "address states by name (walker.layout()):\n" + "\n".join(found)
