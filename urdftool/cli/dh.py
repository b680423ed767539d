"""`urdftool dh`: placeholder until its issue lands."""

from __future__ import annotations

import click


@click.command("dh", context_settings={"ignore_unknown_options": True})
@click.argument("args", nargs=-1)
def command(args):
    """Not implemented yet."""
    from urdftool.errors import ToolError

    raise ToolError("'dh' is not implemented yet")
