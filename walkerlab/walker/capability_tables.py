"""The capability table (:data:`walkerlab.walker.kinds.CAPABILITIES`) laid out for reading:
one grid per walker kind, a row per feature and a column per view, each cell ``✓`` or a
numbered refusal whose one-line reason is listed under the grid.  ``walkerlab
capabilities`` prints it as text, the documentation's capability page shows it (the
``capability-table`` directive, ``docs/_ext/capability_table.py``) and
``walkerlab capabilities --json`` prints :func:`walkerlab.walker.kinds.table_rows`.
Nothing here builds a model.
"""

from __future__ import annotations

from dataclasses import dataclass

from walkerlab.walker.capability_cells import STAGE_CELLS
from walkerlab.walker.capability_evidence import (
    CHECK_KINDS,
    UNVERIFIED,
    cell_evidence,
    check_of,
    evidence,
    not_checked,
    number,
    stage_evidence,
    stage_verified,
    unverified_reason,
    verified,
)
from walkerlab.walker.kinds import FEATURES, KINDS, VIEWS, Kind

__all__ = ["SUPPORTED", "KindGrid", "grids", "kind_grid", "markdown", "text"]

#: the mark of a supported cell
SUPPORTED = "✓"
#: the studies (pipeline stages beyond the grid's cells) whose measurement on a kind the
#: evidence file may hold (:func:`walkerlab.walker.capability_evidence.stage_evidence`)
STAGE_STUDIES = ("robustness",)


@dataclass(frozen=True)
class KindGrid:
    """One kind's cells: ``rows[i][j]`` is feature ``i`` in view ``j``: ``"✓ <number>
    <check>"`` (supported and measured within its tolerance, the number measured and the
    kind of check behind it: :mod:`walkerlab.walker.capability_evidence`), ``"~ n"``
    (the view runs it, but its measurement is outside its tolerance or missing) or
    ``"✗ n"`` (refused), ``n`` the 1-based index into ``reasons``; a supported cell may
    end in ``" (m)"``, ``reasons[m - 1]`` the note it rests on (``"note: ..."``) or a
    check of its view that did not run on its case (``"... not checked: ... (not part of
    the ✓)"``)."""

    kind: Kind
    features: tuple[str, ...]
    views: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    reasons: tuple[str, ...]


def kind_grid(kind: Kind) -> KindGrid:
    """The grid of one kind, its reasons numbered in the order they first appear (row by
    row), each listed once; a supported cell whose kind has a note in its view
    (:meth:`walkerlab.walker.kinds.Kind.note`) carries the note's number in brackets
    (``✓ +0.52 % (3)``), the note listed with the reasons (``note: ...``)."""
    reasons: list[str] = []
    rows = []

    def numbered(text: str) -> int:
        if text not in reasons:
            reasons.append(text)
        return reasons.index(text) + 1

    for feature in FEATURES:
        row = []
        for view in VIEWS:
            why = kind.cell(feature, view)
            note = kind.note(view, feature) if why is None else None
            mark = "✗"
            if why is None and verified(kind.name, feature, view):
                e = cell_evidence(kind.name, feature, view)
                cell = f"{SUPPORTED} {number(e)} {check_of(e)}".rstrip()
                if not_checked(e):  # said beside the tick: never counted as passed
                    cell += f" ({numbered(f'{not_checked(e)} (not part of the ✓)')})"
            else:
                if why is None:
                    why, mark = unverified_reason(kind.name, feature, view), UNVERIFIED
                cell = f"{mark} {numbered(why)}"
            if note:
                cell += f" ({numbered(f'note: {note}')})"
            row.append(cell)
        rows.append(tuple(row))
    return KindGrid(kind, tuple(FEATURES), tuple(VIEWS), tuple(rows), tuple(reasons))


def grids() -> list[KindGrid]:
    """Every kind's grid, in :data:`walkerlab.walker.kinds.KINDS`' order."""
    return [kind_grid(k) for k in KINDS.values()]


def _legend() -> list[str]:
    return ["views: " + "; ".join(f"{v}: {what}" for v, what in VIEWS.items()),
            "features: " + "; ".join(f"{f}: {what}" for f, what in FEATURES.items()),
            "checks (the word after a ✓'s number): "
            + "; ".join(f"{c}: {what}" for c, what in CHECK_KINDS.items())]


def _tolerances() -> str:
    tol = evidence().get("tolerances", {})
    return "tolerances: " + "; ".join(f"{v}: {t}" for v, t in tol.items()) if tol else ""


def _stage_lines(kind: str) -> list[str]:
    """The studies measured on a kind beyond its grid (:func:`stage_evidence`): ``✓`` with
    the number and its check when verified, else ``~``, with the case and what was
    measured."""
    out = []
    for stage in STAGE_STUDIES:
        e = stage_evidence(kind, stage)
        if e is None:
            continue
        mark = (f"{SUPPORTED} {number(e)} {check_of(e)}".rstrip()
                if stage_verified(kind, stage) else f"{UNVERIFIED} {number(e)}")
        out.append(f"  walkerlab {stage}: {mark}: {e['case']}: {e['detail']}")
    return out


def text() -> str:
    """The table as plain text (``walkerlab capabilities``): per kind its title, the grid
    (columns padded) and its numbered reasons; the views and features explained first."""
    out = ["walker kind x feature x view: ✓ supported, with the agreement measured on its "
           "reference case (within its view's tolerance) and the kind of check behind it; "
           "~ n runs, not verified; ✗ n refused (reason n below the kind's grid)",
           *_legend(), _tolerances(), ""]
    for g in grids():
        head = ("feature", *g.views)
        rows = [(f, *r) for f, r in zip(g.features, g.rows)]
        width = [max(len(r[i]) for r in (head, *rows)) for i in range(len(head))]
        out.append(f"{g.kind.name}: {g.kind.title} ({g.kind.reference})")
        for r in (head, *rows):
            out.append("  " + "  ".join(c.ljust(w) for c, w in zip(r, width)).rstrip())
        out += [f"  {i}. {why}" for i, why in enumerate(g.reasons, 1)]
        out += [f"  walkerlab {stage}: refused: {why}"
                for stage, why in STAGE_CELLS.get(g.kind.name, {}).items()]
        out += _stage_lines(g.kind.name)
        out.append("")
    return "\n".join(out).rstrip() + "\n"


def markdown() -> str:
    """The table as Markdown: per kind a heading, the grid and its numbered reasons."""
    out = []
    for g in grids():
        out += [f"### {g.kind.name}: {g.kind.title}", "", f"{g.kind.reference}.", "",
                "| feature | " + " | ".join(g.views) + " |",
                "|---|" + "---|" * len(g.views)]
        out += [f"| {f} | " + " | ".join(r) + " |" for f, r in zip(g.features, g.rows)]
        out.append("")
        out += [f"{i}. {why}" for i, why in enumerate(g.reasons, 1)]
        out.append("")
    return "\n".join(out).rstrip() + "\n"
