"""``.. capability-table::``: the walker kinds' capability table, read from
:data:`walkerlab.walker.kinds.CAPABILITIES` at build time (the grids of
:mod:`walkerlab.walker.capability_tables`), so the page cannot go stale: per kind a
section with a row per feature, a column per view, ``✓`` (its number and the kind of
check behind it) or a numbered refusal, and the
refusals' one-line reasons listed below it.

:func:`rst` is plain Python (no docutils): ``tests/test_capabilities.py`` checks it.
"""

from __future__ import annotations


def _cell(text: str) -> str:
    return text.replace("*", r"\*").replace("|", r"\|")


def rst() -> str:
    """The page's body as reStructuredText: the views and features, then per kind a
    section (title, reference, list-table, numbered reasons)."""
    from walkerlab.walker.capability_evidence import CHECK_KINDS
    from walkerlab.walker.capability_tables import grids
    from walkerlab.walker.kinds import FEATURES, VIEWS

    out = ["Views:", ""]
    out += [f"- ``{v}``: {_cell(what)}" for v, what in VIEWS.items()]
    out += ["", "Features:", ""]
    out += [f"- ``{f}``: {_cell(what)}" for f, what in FEATURES.items()]
    out += ["", "Checks (the word after a ✓'s number):", ""]
    out += [f"- ``{c}``: {_cell(what)}" for c, what in CHECK_KINDS.items()]
    out.append("")
    for g in grids():
        title = f"{g.kind.name}: {g.kind.title}"
        out += [title, "-" * len(title), "", f"{_cell(g.kind.reference)}.", "",
                ".. list-table::", "   :header-rows: 1", "   :stub-columns: 1", ""]
        for row in (("feature", *g.views), *((f, *r) for f, r in zip(g.features, g.rows))):
            out.append(f"   * - {_cell(row[0])}")
            out += [f"     - {_cell(c)}" for c in row[1:]]
        out.append("")
        out += [f"{i}. {_cell(why)}" for i, why in enumerate(g.reasons, 1)]
        out.append("")
    return "\n".join(out)


def _directive():
    from docutils import nodes
    from docutils.parsers.rst import Directive
    from docutils.statemachine import StringList
    from sphinx.util.nodes import nested_parse_with_titles

    class CapabilityTable(Directive):
        has_content = False

        def run(self):
            node = nodes.section()
            node.document = self.state.document
            nested_parse_with_titles(self.state, StringList(rst().splitlines(),
                                                            "<capability-table>"), node)
            return node.children

    return CapabilityTable


def setup(app):
    app.add_directive("capability-table", _directive())
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
