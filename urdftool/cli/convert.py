"""`urdftool convert`: placeholder until its issue lands."""

from __future__ import annotations

import click


@click.command("convert", context_settings={"ignore_unknown_options": True})
@click.argument("args", nargs=-1)
def command(args):
    """Not implemented yet."""
    from urdftool.errors import ToolError

    raise ToolError("'convert' is not implemented yet")
