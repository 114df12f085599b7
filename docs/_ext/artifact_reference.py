"""``.. artifact-reference:: walkerlab.io.schemas``: every artifact's datasets, units and
descriptions, read from the writers themselves, so the reference cannot go stale.

Each module of the package holds one artifact's writer (``write`` or ``write_<stage>``). The
writers name every dataset with :func:`walkerlab.io.artifacts.put` or
:func:`walkerlab.io.netcdf.coordinate` (``put(group, name, data, unit, description)``): this
extension reads their source (no artifact is computed) and follows each writer through its
helper functions, its groups (``create_group``/``require_group``) and its loops. A loop over a
table of the module (a dict or a tuple of literals: ``STEP_UNITS``, ``GROUND_FIELDS``, a
``for name, val, unit in ((...), ...)``) is unrolled into one row per entry; a name known only
at run time (a state's or a leg's) is shown as ``<name>``, the variable that holds it, and a
unit known only at run time as ``(at run time: expr)``: the artifact's own ``unit`` attribute
holds it.

:func:`catalogue` is plain Python (no docutils): the tests check that every dataset a
writer writes matches a row (``tests/test_docs.py``).
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import re
import textwrap
from dataclasses import dataclass, field

#: the dataset-writing helpers and the position of (group, name, unit, description)
_WRITERS = {"put": (0, 1, 3, 4), "coordinate": (0, 1, 3, 4)}


@dataclass(frozen=True)
class Row:
    """One dataset of an artifact: its path (``<x>``: named at run time), unit, description
    and dimensions (None: a scalar or not named)."""

    path: str
    unit: str
    description: str
    dims: tuple | None = None
    coordinate: bool = False

    def pattern(self) -> re.Pattern:
        """The paths this row stands for (each ``<x>`` one or more path components)."""
        parts = re.split(r"<[^<>]*>", self.path)
        return re.compile("(?:.+)".join(re.escape(p) for p in parts) + r"\Z")


@dataclass
class Artifact:
    """One artifact module: its name, docstring and rows in writing order."""

    module: str
    title: str
    doc: str
    rows: list = field(default_factory=list)
    stage: str = ""


@dataclass(frozen=True)
class Unknown:
    """A value known only at run time; ``text`` is how it is shown (``<name>``)."""

    text: str


@dataclass(frozen=True)
class Group:
    """An HDF5 group: its path prefix ('' for the root, else ending with '/')."""

    prefix: str


def _show(value) -> str:
    if isinstance(value, Unknown):
        return value.text
    return str(value)


class _Writer:
    """Interprets a writer's source just far enough to name its datasets."""

    def __init__(self, module):
        self.module = module
        self.rows: list[Row] = []
        self._depth = 0

    # -- expressions ---------------------------------------------------------------------
    def value(self, node, env):
        if node is None:
            return None
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            if node.id in env:
                return env[node.id]
            g = getattr(self.module, node.id, None)
            if isinstance(g, (str, int, float, tuple, list, dict, frozenset)):
                return g
            return Unknown(f"<{node.id}>")
        if isinstance(node, ast.JoinedStr):
            out = []
            for part in node.values:
                if isinstance(part, ast.Constant):
                    out.append(str(part.value))
                    continue
                v = self.value(part.value, env)
                if isinstance(v, (str, int, float)) and not isinstance(v, bool) \
                        and part.format_spec is None:
                    out.append(str(v))
                else:
                    out.append(v.text if isinstance(v, Unknown) and v.text.startswith("<")
                               else f"<{_short(part.value)}>")
            return "".join(out)
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
            a, b = self.value(node.left, env), self.value(node.right, env)
            if isinstance(a, str) and isinstance(b, str):
                return a + b
            return Unknown(ast.unparse(node))
        if isinstance(node, (ast.Tuple, ast.List)):
            return tuple(self.value(e, env) for e in node.elts)
        if isinstance(node, ast.Dict):
            keys = [self.value(k, env) for k in node.keys]
            if all(isinstance(k, (str, int)) for k in keys):
                return dict(zip(keys, (self.value(v, env) for v in node.values)))
            return Unknown(ast.unparse(node))
        if isinstance(node, ast.Subscript):
            base, key = self.value(node.value, env), self.value(node.slice, env)
            if isinstance(base, Group) and isinstance(key, (str, Unknown)):
                return Group(base.prefix + _show(key).strip("/") + "/")
            if isinstance(base, dict) and not isinstance(key, Unknown) and key in base:
                return base[key]
            return Unknown(ast.unparse(node))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            base = self.value(node.func.value, env)
            args = [self.value(a, env) for a in node.args]
            meth = node.func.attr
            if isinstance(base, Group) and meth in ("create_group", "require_group") \
                    and args:
                return Group(base.prefix + _show(args[0]).strip("/") + "/")
            if isinstance(base, dict) and meth == "get" and args:
                if not isinstance(args[0], Unknown):
                    return base.get(args[0], args[1] if len(args) > 1 else None)
                if len(args) > 1:  # any key but the table's: the default
                    return args[1]
            if isinstance(base, dict) and meth in ("items", "keys", "values"):
                return tuple(getattr(base, meth)())
            if isinstance(base, str) and meth == "join" and args \
                    and isinstance(args[0], tuple) and all(isinstance(a, str) for a in args[0]):
                return base.join(args[0])
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            args = [self.value(a, env) for a in node.args]
            known = all(isinstance(a, (tuple, list)) for a in args)
            if node.func.id == "zip" and args and known:
                return tuple(zip(*args))
            if node.func.id == "enumerate" and len(args) == 1 and known:
                return tuple(enumerate(args[0]))
        if isinstance(node, ast.Attribute):
            return Unknown(f"<{node.attr}>")
        return Unknown(ast.unparse(node))

    # -- statements ----------------------------------------------------------------------
    def run(self, func, args: list, env: dict | None = None) -> dict:
        """Interpret ``func`` (an ``ast.FunctionDef``) with its first parameters bound;
        returns its local names (a local function: its ``ast.FunctionDef``)."""
        env = dict(env or {})
        if self._depth > 8:
            return env
        self._depth += 1
        params = [a.arg for a in func.args.posonlyargs + func.args.args]
        for i, p in enumerate(params):
            env[p] = args[i] if i < len(args) else Unknown(f"<{p}>")
        self.block(func.body, env)
        self._depth -= 1
        return env

    def block(self, body, env) -> None:
        for st in body:
            self.statement(st, env)

    def statement(self, st, env) -> None:
        if isinstance(st, ast.FunctionDef):  # a local helper or a factory's writer
            env[st.name] = st
            return
        if isinstance(st, (ast.AsyncFunctionDef, ast.ClassDef)):
            return
        if isinstance(st, ast.If):
            self.calls(st.test, env)
            self.block(st.body, env)
            self.block(st.orelse, env)
            return
        if isinstance(st, (ast.With, ast.AsyncWith)):
            self.block(st.body, env)
            return
        if isinstance(st, ast.Try):
            for part in (st.body, *[h.body for h in st.handlers], st.orelse, st.finalbody):
                self.block(part, env)
            return
        if isinstance(st, ast.While):
            self.block(st.body, env)
            return
        if isinstance(st, ast.For):
            items = self.value(st.iter, env)
            if isinstance(items, (tuple, list)) and items:
                for item in items:
                    inner = dict(env)
                    _bind(st.target, item, inner)
                    self.block(st.body, inner)
                    env.update({k: v for k, v in inner.items() if isinstance(v, Group)})
            else:
                inner = dict(env)
                _bind(st.target, None, inner)
                self.block(st.body, inner)
            return
        self.calls(st, env)
        if isinstance(st, ast.Assign):
            v = self.value(st.value, env)
            for t in st.targets:
                _bind(t, v, env)
        elif isinstance(st, ast.AnnAssign) and st.value is not None:
            _bind(st.target, self.value(st.value, env), env)

    def calls(self, node, env) -> None:
        """Every call in ``node`` (not in nested functions), in source order."""
        found = [n for n in ast.walk(node) if isinstance(n, ast.Call)]
        for call in sorted(found, key=lambda n: (n.lineno, n.col_offset)):
            self.call(call, env)

    def call(self, call, env) -> None:
        func = call.func
        name = func.id if isinstance(func, ast.Name) else \
            func.attr if isinstance(func, ast.Attribute) else None
        if name in _WRITERS and len(call.args) >= 2:
            self.dataset(call, name, env)
            return
        if isinstance(func, ast.Name) and isinstance(env.get(func.id), ast.FunctionDef):
            self.run(env[func.id], [self.value(a, env) for a in call.args], env)
            return
        if isinstance(func, ast.Name) and call.args:
            target = getattr(self.module, func.id, None)
            first = self.value(call.args[0], env)
            if isinstance(first, Group) and inspect.isfunction(target) \
                    and target.__module__.startswith("walkerlab.io"):
                tree = _function_ast(target)
                if tree is not None:
                    sub = _Writer(importlib.import_module(target.__module__))
                    sub._depth = self._depth
                    sub.run(tree, [self.value(a, env) for a in call.args])
                    self.rows += sub.rows

    def dataset(self, call, kind, env) -> None:
        ig, iname, iunit, idesc = _WRITERS[kind]
        kw = {k.arg: k.value for k in call.keywords if k.arg}
        nodes_ = {
            "group": call.args[ig],
            "name": call.args[iname],
            "unit": call.args[iunit] if len(call.args) > iunit else kw.get(
                "unit", kw.get("units")),
            "desc": call.args[idesc] if len(call.args) > idesc else kw.get(
                "description", kw.get("long_name")),
            "dims": kw.get("dims"),
        }
        group = self.value(nodes_["group"], env)
        if not isinstance(group, Group):
            return
        # a run-time key into a table of the module or function: one row per entry
        for var, table, has_default in _lookups(nodes_, env, self):
            entries = list(table)
            if not entries:
                continue
            for key in entries:
                inner = dict(env)
                inner[var] = key
                self.emit(group, nodes_, inner, kind)
            if not has_default:
                return
            break
        self.emit(group, nodes_, env, kind)

    def emit(self, group, nodes_, env, kind) -> None:
        name = self.value(nodes_["name"], env)
        if isinstance(name, Unknown):
            name = name.text if name.text.startswith("<") else f"<{name.text}>"
        unit = self.value(nodes_["unit"], env)
        if unit is None or isinstance(unit, Unknown):
            unit = f"(at run time: {_short(nodes_['unit'])})" if nodes_["unit"] is not None \
                else ""
        desc = self.value(nodes_["desc"], env)
        if isinstance(desc, Unknown) or desc is None:
            desc = "" if nodes_["desc"] is None else f"({_short(nodes_['desc'])})"
        dims = self.value(nodes_["dims"], env) if nodes_["dims"] is not None else None
        if isinstance(dims, tuple):
            dims = tuple(_show(d) for d in dims)
        else:
            dims = None
        if kind == "coordinate":
            dims = (str(name),)
        row = Row(group.prefix + str(name), str(unit), " ".join(str(desc).split()), dims,
                  kind == "coordinate")
        if row not in self.rows:
            self.rows.append(row)


def _short(node) -> str:
    text = ast.unparse(node)
    return text if len(text) <= 40 else text[:37] + "..."


def _bind(target, value, env) -> None:
    if isinstance(target, ast.Name):
        env[target.id] = value if value is not None else Unknown(f"<{target.id}>")
    elif isinstance(target, (ast.Tuple, ast.List)):
        vals = value if isinstance(value, (tuple, list)) and len(value) == len(target.elts) \
            else [None] * len(target.elts)
        for t, v in zip(target.elts, vals):
            _bind(t, v, env)


def _lookups(nodes_, env, writer):
    """``(variable, keys, has_default)`` for each ``TABLE[var]`` or ``TABLE.get(var, d)`` in
    the name, unit or description whose key is a run-time variable the name contains."""
    out = []
    for part in ("unit", "desc"):
        node = nodes_[part]
        if node is None:
            continue
        for n in ast.walk(node):
            table = key = None
            has_default = False
            if isinstance(n, ast.Subscript):
                table, key = n.value, n.slice
            elif isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) \
                    and n.func.attr == "get" and n.args:
                table, key, has_default = n.func.value, n.args[0], len(n.args) > 1
            if not isinstance(key, ast.Name) or not isinstance(env.get(key.id, Unknown("")),
                                                                 Unknown):
                continue
            t = writer.value(table, env)
            if isinstance(t, dict) and key.id in ast.unparse(nodes_["name"]):
                out.append((key.id, t, has_default))
    return out


def _function_ast(func):
    try:
        source = textwrap.dedent(inspect.getsource(func))
    except (OSError, TypeError):
        return None
    tree = ast.parse(source)
    return tree.body[0] if tree.body and isinstance(tree.body[0], ast.FunctionDef) else None


def writers_of(module) -> list:
    """The module's own public writers: functions named ``write`` or ``write_<stage>``, and
    factories ``<stage>_writer`` that return their ``writer(f)``."""
    return [f for n, f in vars(module).items()
            if inspect.isfunction(f) and f.__module__ == module.__name__
            and (n == "write" or n.startswith("write_") or n.endswith("_writer"))]


def catalogue(package: str = "walkerlab.io.schemas") -> list[Artifact]:
    """One :class:`Artifact` per module of ``package`` that has a writer, in name order.

    The writer's first argument is the file's root; every ``put``/``coordinate`` it reaches
    (through helpers of ``walkerlab.io``) is a row.  A plain module (no package) is one
    :class:`Artifact` without rows: its docstring documents its layout.
    """
    pkg = importlib.import_module(package)
    if not hasattr(pkg, "__path__"):
        doc = inspect.getdoc(pkg) or ""
        return [Artifact(pkg.__name__, _title(doc, pkg.__name__), doc)]
    out = []
    for info in sorted(pkgutil.iter_modules(pkg.__path__), key=lambda i: i.name):
        module = importlib.import_module(f"{package}.{info.name}")
        funcs = writers_of(module)
        if not funcs:
            continue
        doc = inspect.getdoc(module) or ""
        art = Artifact(module.__name__, _title(doc, info.name), doc,
                       stage=str(getattr(module, "STAGE", info.name)))
        for func in funcs:
            w = _Writer(module)
            if func.__name__.endswith("_writer"):  # a factory: run its nested writer(f)
                env = w.run(_function_ast(func), [])
                if isinstance(env.get("writer"), ast.FunctionDef):
                    w.run(env["writer"], [Group("")], env)
            else:
                w.run(_function_ast(func), [Group("")])
            art.rows += [r for r in w.rows if r not in art.rows]
        out.append(art)
    return out


def _title(doc: str, fallback: str) -> str:
    """The docstring's first line up to its colon, without markup."""
    return doc.split("\n", 1)[0].split(":", 1)[0].replace("``", "").strip() or fallback


def layout_block(doc: str) -> str:
    """The literal block after a docstring's ``::`` (a module's layout), dedented."""
    if "::\n" not in doc:
        return ""
    lines = doc.split("::\n", 1)[1].split("\n")
    block = []
    for line in lines:
        if line.strip() and not line.startswith(" "):
            break
        block.append(line)
    return textwrap.dedent("\n".join(block)).strip("\n")


def _plain(text: str) -> str:
    """A docstring paragraph as plain text: roles and literals without their markup."""
    text = re.sub(r":[\w:]+:`~?([^`]*)`", r"\1", text)
    return " ".join(text.replace("``", "").split())


def path_is_listed(path: str, rows, is_scale: bool = False) -> bool:
    """True when the dataset ``path`` (no leading '/') matches a row's pattern.

    A netCDF dimension scale (``is_scale``) is listed too when it is one of the rows'
    dimensions or coordinates (:func:`walkerlab.io.netcdf.attach` copies a coordinate
    variable into each group that uses it, and makes a bare dimension where there is none)
    or a listed dataset's fallback ``<name>_dim<i>`` (:func:`walkerlab.io.netcdf.finish`).
    """
    if any(r.pattern().match(path) for r in rows):
        return True
    if not is_scale:
        return False
    base = path.rsplit("/", 1)[-1]
    dims = {d for r in rows for d in (r.dims or ())}
    if base in dims:
        return True
    m = re.fullmatch(r"(.+)_dim\d+", path)
    return bool(m) and any(r.pattern().match(m.group(1)) for r in rows)


# -- the Sphinx directive -----------------------------------------------------------------

def _directive():
    from docutils import nodes
    from docutils.parsers.rst import Directive, directives

    def entry(*children):
        e = nodes.entry()
        e += nodes.paragraph("", "", *children)
        return e

    class ArtifactReference(Directive):
        required_arguments = 1
        has_content = False
        option_spec = {"title": directives.unchanged}

        def run(self):
            arts = catalogue(self.arguments[0])
            if "title" in self.options:
                for a in arts:
                    a.title = self.options["title"]
            return [self._section(a) for a in arts]

        def _layout(self, art: Artifact, section):
            """A writer without ``put`` calls (the sweep's store): its docstring's layout."""
            section += nodes.paragraph(text=_plain(art.doc.split("\n\n")[0]))
            section += nodes.paragraph("", "", nodes.Text("writer: "),
                                       nodes.literal(text=art.module))
            block = layout_block(art.doc)
            section += nodes.literal_block(block, block)
            return section

        def _section(self, art: Artifact):
            section = nodes.section(ids=[nodes.make_id(f"artifact-{art.module}")])
            section += nodes.title(text=art.title)
            if not art.rows:
                return self._layout(art, section)
            # the module docstring's layout paragraph(s), as plain text (never parsed)
            for para in art.doc.split("\n\n")[:2]:
                section += nodes.paragraph(text=_plain(para))
            section += nodes.paragraph("", "", nodes.Text("writer: "),
                                       nodes.literal(text=art.module))
            table = nodes.table()
            group = nodes.tgroup(cols=4)
            table += group
            for width in (34, 14, 16, 36):
                group += nodes.colspec(colwidth=width)
            head = nodes.thead()
            row = nodes.row()
            for label in ("dataset", "unit", "dimensions", "description"):
                row += entry(nodes.Text(label))
            head += row
            group += head
            body = nodes.tbody()
            for r in art.rows:
                row = nodes.row()
                row += entry(nodes.literal(text=r.path))
                row += entry(nodes.Text(r.unit))
                dims = "(coordinate)" if r.coordinate else ", ".join(r.dims or ())
                row += entry(nodes.Text(dims))
                row += entry(nodes.Text(r.description))
                body += row
            group += body
            section += table
            return section

    return ArtifactReference


def setup(app):
    app.add_directive("artifact-reference", _directive())
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
