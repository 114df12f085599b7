"""Commands that print what walkerlab can do, without building a model."""

from __future__ import annotations

import json

import typer

from walkerlab.cli.errors import guard
from walkerlab.walker.capability_tables import text
from walkerlab.walker.kinds import table_rows


@guard
def capabilities(as_json: bool = typer.Option(False, "--json", help="print every cell as "
                                              "JSON: kind, feature, view, supported, "
                                              "reason; a supported cell's evidence: "
                                              "verified, case, quantity, measured, "
                                              "tolerance, unit, detail, commit")) -> None:
    """The capability table: for each walker kind, which features (actuators, grounds)
    each view (rigid, contact, exports, gym, optimize) supports, each supported cell with
    the agreement measured on its reference case (✓ -0.4 %; ~ n: runs, not verified), and
    the one-line reason of each refusal (no model is built)."""
    if as_json:
        typer.echo(json.dumps(table_rows(), indent=1, ensure_ascii=False))
        return
    typer.echo(text(), nl=False)
