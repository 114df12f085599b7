"""Patches of typer's help and usage errors.

typer 0.29 with click 8.2+ shows ``<bool>`` beside ``--force`` and ``--help`` in ``--help``,
as if they took a value; :func:`flags_take_no_value` makes them show none.  typer boxes a
usage error under the title "Error" (click without rich prints ``Error: ...``) where every
other walkerlab error is one line ``error: ...``; :func:`usage_errors_in_one_spelling` makes
a usage error that line too.
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


def usage_errors_in_one_spelling() -> None:
    """A usage error (unknown option or command, a value out of range) is printed as the
    usage, the help hint and one line ``error: <message>`` on stderr, the spelling of
    every other walkerlab error (:mod:`walkerlab.cli.errors`); its exit code stays 2."""
    import typer  # typer 0.29 vendors click (typer._click): no `import click` here, which
    from typer import rich_utils  # a fresh install does not have

    if getattr(rich_utils.rich_format_error, "_walkerlab", False):
        return

    def plain_error(exc) -> None:  # a (vendored) click.ClickException
        if exc.__class__.__name__ == "NoArgsIsHelpError":  # the help is shown instead
            return
        ctx = getattr(exc, "ctx", None)
        if ctx is not None:
            typer.echo(ctx.get_usage(), err=True)
            if ctx.command.get_help_option(ctx) is not None:
                typer.echo(f"Try '{ctx.command_path} {ctx.help_option_names[0]}' for help.",
                           err=True)
        typer.echo(f"error: {exc.format_message()}", err=True)

    plain_error._walkerlab = True
    rich_utils.rich_format_error = plain_error
