"""A patch of typer's help: an on/off flag is listed without a value type.

typer 0.29 with click 8.2+ shows ``<bool>`` beside ``--force`` and ``--help`` in ``--help``,
as if they took a value; :func:`flags_take_no_value` makes them show none.
"""

from __future__ import annotations


def flags_take_no_value() -> None:
    """``--help`` lists an on/off flag (``--force``, ``--help``) without a value type: typer
    0.29 with click 8.2+ shows ``<bool>`` beside it, as if it took a value."""
    from typer.core import TyperOption

    shown = TyperOption.display_type_rich
    if getattr(shown, "_walkerlab", False):
        return

    def display_type_rich(self, ctx):
        return None if self.is_flag and self.metavar is None else shown(self, ctx)

    display_type_rich._walkerlab = True
    TyperOption.display_type_rich = display_type_rich
