"""``.. scene-schema:: dotted.path.Model``: the scene's sections as tables, from the pydantic
models themselves (field, type, default, description), one section per model, reached from
the root model through its fields' types; a field whose type is a model links to its table.

Built from docutils nodes (no reStructuredText is parsed), so a description's characters
can never make the build warn.
"""

from __future__ import annotations

import importlib
import types
import typing
from collections import deque

from docutils import nodes
from docutils.parsers.rst import Directive
from pydantic import BaseModel
from pydantic_core import PydanticUndefined


def _import(path: str):
    module, _, name = path.rpartition(".")
    return getattr(importlib.import_module(module), name)


def _models_in(annotation) -> list[type[BaseModel]]:
    """Every pydantic model an annotation names (through unions, lists, dicts, Annotated)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    out: list[type[BaseModel]] = []
    for arg in typing.get_args(annotation):
        out += _models_in(arg)
    return out


def _type_text(annotation) -> str:
    if annotation is type(None):
        return "None"
    if isinstance(annotation, type):
        return annotation.__name__
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin is typing.Annotated:
        return _type_text(args[0])
    if origin in (typing.Union, types.UnionType):
        return " | ".join(_type_text(a) for a in args)
    if origin is typing.Literal:
        return " | ".join(repr(a) for a in args)
    if origin is not None:
        name = getattr(origin, "__name__", str(origin))
        return f"{name}[{', '.join(_type_text(a) for a in args)}]"
    return str(annotation).replace("typing.", "")


def _default_text(field) -> str:
    if field.is_required():
        return "required"
    if field.default_factory is not None:
        try:
            value = field.default_factory()
        except TypeError:
            return "(computed)"
    else:
        value = field.default
    if value is PydanticUndefined:
        return "required"
    if isinstance(value, BaseModel):
        return "(section defaults)"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _anchor(model: type) -> str:
    return nodes.make_id(f"scene-{model.__module__}-{model.__qualname__}")


def _entry(*children) -> nodes.entry:
    entry = nodes.entry()
    entry += nodes.paragraph("", "", *children)
    return entry


class SceneSchema(Directive):
    required_arguments = 1
    has_content = False

    def run(self):
        root = _import(self.arguments[0])
        order: list[type[BaseModel]] = []
        queue = deque([root])
        while queue:
            model = queue.popleft()
            if model in order:
                continue
            order.append(model)
            for field in model.model_fields.values():
                queue.extend(m for m in _models_in(field.annotation) if m not in order)
        return [self._section(model, set(order)) for model in order]

    def _section(self, model: type[BaseModel], documented: set) -> nodes.section:
        section = nodes.section(ids=[_anchor(model)])
        section += nodes.title(text=model.__name__)
        doc = (model.__doc__ or "").strip().split("\n\n")[0]
        if doc:
            section += nodes.paragraph(text=" ".join(doc.split()))
        section += nodes.paragraph(text=f"{model.__module__}.{model.__qualname__}")
        table = nodes.table()
        group = nodes.tgroup(cols=4)
        table += group
        for width in (22, 22, 14, 42):
            group += nodes.colspec(colwidth=width)
        head = nodes.thead()
        row = nodes.row()
        for label in ("field", "type", "default", "description"):
            row += _entry(nodes.Text(label))
        head += row
        group += head
        body = nodes.tbody()
        for name, field in model.model_fields.items():
            row = nodes.row()
            key = field.alias or name
            row += _entry(nodes.literal(text=key))
            type_nodes: list[nodes.Node] = [nodes.literal(text=_type_text(field.annotation))]
            links = [m for m in _models_in(field.annotation) if m in documented]
            for m in dict.fromkeys(links):
                ref = nodes.reference("", m.__name__, internal=True, refid=_anchor(m))
                type_nodes += [nodes.Text(" → "), ref]
            row += _entry(*type_nodes)
            row += _entry(nodes.Text(_default_text(field)))
            description = " ".join((field.description or "").split())
            row += _entry(nodes.Text(description))
            body += row
        group += body
        section += table
        return section


def setup(app):
    app.add_directive("scene-schema", SceneSchema)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
