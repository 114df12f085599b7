"""typer's usage errors in walkerlab's one spelling.

typer boxes a usage error under the title "Error" (click without rich prints ``Error: ...``)
where every other walkerlab error is one line ``error: ...``;
:func:`usage_errors_in_one_spelling` makes a usage error that line too, where typer shows it
through ``typer.rich_utils.rich_format_error`` (a typer without it keeps its own box).

No private name of typer or click is read or replaced here (tests/test_config_messages.py):
the help of typer 0.2x beside click 8.2+ shows ``<bool>`` beside an on/off flag
(``--force``, ``--help``), typer's own rendering, left as it is (a patch of
``TyperOption.display_type_rich`` hid it and broke the CLI's import on typer versions
without it).
"""

from __future__ import annotations

import sys


def usage_errors_in_one_spelling() -> None:
    """A usage error (unknown option or command, a value out of range) is printed as the
    usage, the help hint and one line ``error: <message>`` on stderr, the spelling of
    every other walkerlab error (:mod:`walkerlab.cli.errors`); its exit code stays 2.

    typer imports ``typer.rich_utils`` (rich's tables, markdown and pygments) only to show
    a help or an error: the patch waits for that import (:class:`_PatchOnImport`) rather than
    making every command import it at start-up."""
    if RICH_UTILS in sys.modules:
        _one_line_usage_errors(sys.modules[RICH_UTILS])
    elif not any(isinstance(f, _PatchOnImport) for f in sys.meta_path):
        sys.meta_path.insert(0, _PatchOnImport())


#: the typer module whose ``rich_format_error`` prints a usage error
RICH_UTILS = "typer.rich_utils"


class _PatchOnImport:
    """Finds nothing itself: when ``typer.rich_utils`` is imported (by typer, to show a help
    or an error, or by anyone), patches it (:func:`_one_line_usage_errors`) as soon as its
    code has run, then leaves ``sys.meta_path`` (a finder of ``sys.meta_path``: only
    ``find_spec``)."""

    def find_spec(self, fullname, path, target=None):
        if fullname != RICH_UTILS:
            return None
        if self in sys.meta_path:
            sys.meta_path.remove(self)
        spec = None
        for finder in list(sys.meta_path):  # the finders after this one
            find = getattr(finder, "find_spec", None)
            spec = find(fullname, path, target) if find is not None else None
            if spec is not None:
                break
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        run = spec.loader.exec_module

        def exec_module(module):
            run(module)
            _one_line_usage_errors(module)

        spec.loader.exec_module = exec_module  # this spec's own loader instance
        return spec


def _one_line_usage_errors(rich_utils) -> None:
    """Patch ``rich_utils.rich_format_error`` (see :func:`usage_errors_in_one_spelling`)."""
    import typer  # typer 0.29 carries its own copy of click: no `import click` here, which
    # a fresh install does not have

    shown = getattr(rich_utils, "rich_format_error", None)
    if shown is None or getattr(shown, "_walkerlab", False):
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
